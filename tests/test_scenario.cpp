// Scenario loading (TOML -> definition structs), its error messages, particle insertion and the counter-based RNG.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/particles.hpp"
#include "core/rng.hpp"
#include "scenario/insert.hpp"
#include "scenario/loader.hpp"
#include "scenario_text.hpp"

namespace fs = std::filesystem;
using namespace haet;

namespace {

// A valid 3D scenario using every section. Materials are deliberately not in alphabetical order: they must be
// numbered in file order.
const std::string kBox3d = R"(# falling grains on a floor
name = "box3d"
dimension = 3
method = "tdm"
duration = 1.0
seed = 42

[domain]
lo = [0, 0, 0]
hi = [0.1, 0.1, 0.2]
periodic = [true, true, false]
gravity = [0, 0, -9.81]

[materials.glass]
density = 2500
young = 6.3e10
poisson = 0.2
restitution = 0.9
friction = 0.5
tangential_restitution = 0.4

[materials.brass]
density = 8500
restitution = 0.8
friction = 0.3
dissipation_time = 2e-7

[contact]
normal = "linear"
duration = 1e-5
tangential = "spring"
kt_ratio = 0.2857
gamma_t = 0
attraction = false
impact_velocity = 1.0

[tdm]
integrator = "verlet"
dt = "auto"
steps_per_contact = 50
skin = 1e-4
max_overlap = 0.5
sort_every = 1000

[[walls]]
point = [0, 0, 0]
normal = [0, 0, 2]
material = "brass"

[[insert]]
arrangement = "lattice"
count = 100
radius = 0.001
material = "glass"
spacing = 0.0021
region = { lo = [0, 0, 0], hi = [0.1, 0.1, 0.05] }

[[insert]]
arrangement = "random"
count = 200
radius = [0.0008, 0.0012]
material = "brass"
region = { lo = [0, 0, 0.1], hi = [0.1, 0.1, 0.2] }
velocity = [0, 0, -1]
temperature = 0.01

[output]
directory = "out"
series_period = 0.01
snapshot_period = 0.1
)";

const std::string kDisk2d = R"(name = "disks"
dimension = 2
method = "haet"
duration = 0.5

[domain]
lo = [-0.05, 0]
hi = [0.05, 0.2]
gravity = [0, -9.81]

[materials.steel]
density = 7.8
restitution = 0.95
friction = 0.2

[contact]
kn = 2e5
gamma_n = 50
tangential = "none"

[tdm]
integrator = "gear5"
dt = 1e-6
sort_every = 0

[[walls]]
point = [0, 0]
normal = [0, 1]
material = "steel"
velocity = [0.1, 0]

[[insert]]
arrangement = "lattice"
count = 100
radius = 0.001
material = "steel"
spacing = 0.0025
region = { lo = [-0.005, 0], hi = [0.005, 0.01] }
frozen = true

[output]
snapshot_period = -1
)";

using haet::testing::lineOf;
using haet::testing::replaced;

class ScenarioTest : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("haet_scenario_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path write(const std::string& name, const std::string& text) const {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }

    Scenario load(const std::string& text, const std::string& name = "scenario.toml") const {
        return loadScenario(write(name, text));
    }

    /// Loads `text` expecting a ScenarioError that names the file, `line` and `key`; returns its message.
    std::string expectError(const std::string& text, int line, const std::string& key) const {
        const fs::path p = write("bad.toml", text);
        try {
            loadScenario(p);
        } catch (const ScenarioError& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(p.string() + ":" + std::to_string(line) + ": "), std::string::npos) << msg;
            EXPECT_EQ(e.pos().line, line) << msg;
            EXPECT_EQ(e.pos().file, p.string()) << msg;
            if (!key.empty()) {
                EXPECT_EQ(e.key(), key) << msg;
                EXPECT_NE(msg.find(": " + key + ": "), std::string::npos) << msg;
            }
            return msg;
        }
        ADD_FAILURE() << "no ScenarioError for key " << key;
        return {};
    }

    fs::path dir_;
};

template <int D>
void expectNoOverlaps(const Particles<D>& p) {
    for (std::size_t i = 0; i < p.size(); ++i)
        for (std::size_t j = i + 1; j < p.size(); ++j) {
            const double reach = p.radius[i] + p.radius[j];
            ASSERT_GE(norm(p.x[i] - p.x[j]), reach * (1 - 1e-9)) << "particles " << i << " and " << j;
        }
}

template <int D>
void expectInside(const Particles<D>& p, std::size_t from, std::size_t to, const Vec3d& lo, const Vec3d& hi) {
    for (std::size_t i = from; i < to; ++i)
        for (int k = 0; k < D; ++k) {
            ASSERT_GE(p.x[i][k] - p.radius[i], lo[std::size_t(k)] - 1e-12) << "particle " << i;
            ASSERT_LE(p.x[i][k] + p.radius[i], hi[std::size_t(k)] + 1e-12) << "particle " << i;
        }
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// Valid scenarios

TEST_F(ScenarioTest, Loads3dWithAllSections) {
    const Scenario s = load(kBox3d);
    EXPECT_EQ(s.name, "box3d");
    EXPECT_EQ(s.dimension, 3);
    EXPECT_EQ(s.method, Method::Tdm);
    EXPECT_DOUBLE_EQ(s.duration, 1.0);
    EXPECT_EQ(s.seed, 42u);
    EXPECT_EQ(s.domain.hi, (Vec3d{0.1, 0.1, 0.2}));
    EXPECT_EQ(s.domain.periodic, (std::array<bool, 3>{true, true, false}));
    EXPECT_DOUBLE_EQ(s.domain.gravity[2], -9.81);

    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.materials[0].name, "glass");  // file order, not alphabetical
    EXPECT_EQ(s.materials[1].name, "brass");
    EXPECT_DOUBLE_EQ(s.materials[0].young, 6.3e10);
    EXPECT_DOUBLE_EQ(s.materials[0].poisson, 0.2);
    EXPECT_DOUBLE_EQ(s.materials[0].tangentialRestitution, 0.4);
    EXPECT_FALSE(s.materials[0].dissipationTime);
    EXPECT_DOUBLE_EQ(s.materials[1].young, 1e7);  // default
    EXPECT_DOUBLE_EQ(s.materials[1].restitution, 0.8);
    EXPECT_DOUBLE_EQ(*s.materials[1].dissipationTime, 2e-7);
    EXPECT_EQ(s.materials[1].pos.line, lineOf(kBox3d, "[materials.brass]"));

    EXPECT_EQ(s.contact.normal, NormalLaw::Linear);
    EXPECT_DOUBLE_EQ(*s.contact.duration, 1e-5);
    EXPECT_FALSE(s.contact.kn);
    EXPECT_DOUBLE_EQ(*s.contact.ktRatio, 0.2857);
    EXPECT_EQ(s.contact.tangential, TangentialLaw::Spring);

    EXPECT_EQ(s.tdm.integrator, IntegratorKind::Verlet);
    EXPECT_FALSE(s.tdm.dt);  // "auto"
    EXPECT_DOUBLE_EQ(s.tdm.stepsPerContact, 50);
    EXPECT_DOUBLE_EQ(*s.tdm.skin, 1e-4);
    EXPECT_EQ(s.tdm.sortEvery, 1000);

    ASSERT_EQ(s.walls.size(), 1u);
    EXPECT_EQ(s.walls[0].normal, (Vec3d{0, 0, 1}));  // normalised
    EXPECT_EQ(s.walls[0].material, 1);

    ASSERT_EQ(s.inserts.size(), 2u);
    EXPECT_EQ(s.inserts[0].arrangement, Arrangement::Lattice);
    EXPECT_EQ(s.inserts[0].count, 100u);
    EXPECT_DOUBLE_EQ(s.inserts[0].radiusMin, 0.001);
    EXPECT_DOUBLE_EQ(s.inserts[0].radiusMax, 0.001);
    EXPECT_DOUBLE_EQ(*s.inserts[0].spacing, 0.0021);
    EXPECT_EQ(s.inserts[0].regionHi, (Vec3d{0.1, 0.1, 0.05}));
    EXPECT_EQ(s.inserts[1].arrangement, Arrangement::Random);
    EXPECT_EQ(s.inserts[1].material, 1);
    EXPECT_DOUBLE_EQ(s.inserts[1].radiusMin, 0.0008);
    EXPECT_DOUBLE_EQ(s.inserts[1].radiusMax, 0.0012);
    EXPECT_DOUBLE_EQ(s.inserts[1].velocity[2], -1);
    EXPECT_DOUBLE_EQ(s.inserts[1].temperature, 0.01);
    EXPECT_EQ(s.inserts[1].pos.line, lineOf(kBox3d, "arrangement = \"random\"") - 1);

    EXPECT_EQ(s.output.directory, "out");
    EXPECT_DOUBLE_EQ(s.output.seriesPeriod, 0.01);
    EXPECT_DOUBLE_EQ(s.output.snapshotPeriod, 0.1);

    EXPECT_EQ(s.hash, fnv1a64Hex(kBox3d));
    EXPECT_EQ(s.hash.size(), 16u);
}

TEST_F(ScenarioTest, Loads2dWithDefaults) {
    const Scenario s = load(kDisk2d);
    EXPECT_EQ(s.dimension, 2);
    EXPECT_EQ(s.method, Method::Haet);
    EXPECT_EQ(s.seed, 1u);  // default
    EXPECT_EQ(s.domain.lo, (Vec3d{-0.05, 0, 0}));
    EXPECT_EQ(s.domain.hi, (Vec3d{0.05, 0.2, 0}));
    EXPECT_EQ(s.domain.periodic, (std::array<bool, 3>{false, false, false}));
    EXPECT_DOUBLE_EQ(s.domain.gravity[1], -9.81);
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_DOUBLE_EQ(s.materials[0].poisson, 0.3);                // default
    EXPECT_DOUBLE_EQ(s.materials[0].tangentialRestitution, 1.0);  // default
    EXPECT_FALSE(s.contact.duration);
    EXPECT_DOUBLE_EQ(*s.contact.kn, 2e5);
    EXPECT_DOUBLE_EQ(*s.contact.gammaN, 50);
    EXPECT_EQ(s.contact.tangential, TangentialLaw::None);
    EXPECT_EQ(s.tdm.integrator, IntegratorKind::Gear5);
    EXPECT_DOUBLE_EQ(*s.tdm.dt, 1e-6);
    EXPECT_EQ(s.tdm.sortEvery, 0);
    EXPECT_DOUBLE_EQ(s.tdm.maxOverlap, 0.5);  // default
    ASSERT_EQ(s.walls.size(), 1u);
    EXPECT_EQ(s.walls[0].velocity, (Vec3d{0.1, 0, 0}));
    ASSERT_EQ(s.inserts.size(), 1u);
    EXPECT_TRUE(s.inserts[0].frozen);
    EXPECT_EQ(s.output.directory, "out");        // default
    EXPECT_DOUBLE_EQ(s.output.seriesPeriod, 0);  // default: duration/100
    EXPECT_DOUBLE_EQ(s.output.snapshotPeriod, -1);
}

TEST_F(ScenarioTest, HashIsFnv1a64OfTheFileBytes) {
    EXPECT_EQ(fnv1a64Hex(""), "cbf29ce484222325");  // FNV-1a 64 offset basis
    EXPECT_EQ(fnv1a64Hex("a"), "af63dc4c8601ec8c");
    EXPECT_NE(load(kBox3d).hash, load(kBox3d + "\n").hash);
}

// ---------------------------------------------------------------------------------------------------------------
// Overrides (`haet run --set KEY=VALUE`): a value of the file replaced or added before validation.

TEST_F(ScenarioTest, OverridesChangeValues) {
    const fs::path p = write("box.toml", kBox3d);
    const Scenario s =
        loadScenario(p, {"duration=0.01", "tdm.dt=1e-5", "insert[2].count=500", "seed = 7", "domain.hi=[0.2, 0.1, 0.3]",
                         "materials.brass.friction=0.1", "insert[1].region={ lo = [0, 0, 0], hi = [0.1, 0.1, 0.06] }",
                         "method=edm", "edm.cell_size=0.003", "walls[1].point[3]=0.01", "duration=0.02"});
    EXPECT_DOUBLE_EQ(s.duration, 0.02);  // the later of two overrides of one key
    EXPECT_DOUBLE_EQ(*s.tdm.dt, 1e-5);
    EXPECT_EQ(s.inserts[1].count, 500u);
    EXPECT_EQ(s.inserts[0].count, 100u);
    EXPECT_EQ(s.seed, 7u);
    EXPECT_EQ(s.domain.hi, (Vec3d{0.2, 0.1, 0.3}));
    EXPECT_DOUBLE_EQ(s.materials[1].friction, 0.1);
    EXPECT_DOUBLE_EQ(s.materials[0].friction, 0.5);
    EXPECT_EQ(s.inserts[0].regionHi, (Vec3d{0.1, 0.1, 0.06}));
    EXPECT_EQ(s.method, Method::Edm);  // a bare word is a string
    EXPECT_DOUBLE_EQ(*s.edm.cellSize, 0.003);
    EXPECT_DOUBLE_EQ(s.walls[0].point[2], 0.01);
    EXPECT_EQ(s.hash, fnv1a64Hex(kBox3d));  // the file's hash; the overrides are recorded beside it
    const std::vector<std::string> applied = {"tdm.dt=1e-5",
                                              "insert[2].count=500",
                                              "seed=7",
                                              "domain.hi=[0.2, 0.1, 0.3]",
                                              "materials.brass.friction=0.1",
                                              "insert[1].region={ lo = [0, 0, 0], hi = [0.1, 0.1, 0.06] }",
                                              "method=edm",
                                              "edm.cell_size=0.003",
                                              "walls[1].point[3]=0.01",
                                              "duration=0.02"};
    EXPECT_EQ(s.overrides, applied);
    EXPECT_TRUE(loadScenario(p).overrides.empty());
}

TEST_F(ScenarioTest, OverrideAddsATableTheFileLacks) {
    const fs::path p = write("box.toml", kBox3d);
    const Scenario s = loadScenario(p, {"haet.phi_on=0.5", "method=\"haet\""});
    EXPECT_EQ(s.method, Method::Haet);
    EXPECT_DOUBLE_EQ(*s.haet.phiOn, 0.5);
}

TEST_F(ScenarioTest, OverrideFilePathIsRelativeToTheWorkingDirectory) {
    const std::string csv = "x,y,z,radius\n0.05,0.05,0.01,0.001\n";
    write("grains.csv", csv);
    fs::create_directories(dir_ / "scenes");
    const std::string text =
        kBox3d + "\n[[insert]]\narrangement = \"file\"\nfile = \"elsewhere.csv\"\nmaterial = \"glass\"\n";
    const fs::path p = write("scenes/box.toml", text);
    const fs::path cwd = fs::current_path();
    fs::current_path(dir_);
    Scenario s;
    try {
        s = loadScenario(p, {"insert[3].file=\"grains.csv\""});
    } catch (...) {
        fs::current_path(cwd);
        throw;
    }
    fs::current_path(cwd);
    ASSERT_EQ(s.inserts.size(), 3u);
    EXPECT_EQ(fs::path(s.inserts[2].file), dir_ / "grains.csv");
}

/// Loads kBox3d with `override` expecting a ScenarioError that names the override and `key`.
void expectOverrideError(const fs::path& p, const std::string& override, const std::string& key) {
    try {
        loadScenario(p, {override});
        ADD_FAILURE() << "no ScenarioError for --set " << override;
    } catch (const ScenarioError& e) {
        const std::string msg = e.what();
        EXPECT_EQ(e.pos().file, p.string() + " (--set " + override + ")") << msg;
        EXPECT_EQ(e.key(), key) << msg;
        EXPECT_EQ(msg.rfind(p.string() + " (--set " + override + "): " + (key.empty() ? "" : key + ": "), 0), 0u)
            << msg;
    }
}

TEST_F(ScenarioTest, OverrideErrorsNameTheOverrideAndTheKey) {
    const fs::path p = write("box.toml", kBox3d);
    expectOverrideError(p, "tdm.dtt=1e-5", "tdm.dtt");  // unknown key
    expectOverrideError(p, "colour=1", "colour");       // unknown key at the top
    expectOverrideError(p, "materials.glass.colour=1", "materials.glass.colour");
    expectOverrideError(p, "insert[2].count=abc", "insert[2].count");  // bad value (a string)
    expectOverrideError(p, "insert[2].count=-5", "insert[2].count");   // bad value (out of range)
    expectOverrideError(p, "duration=[1, 2]", "duration");             // bad type
    expectOverrideError(p, "materials.glass.restitution=1.5", "materials.glass.restitution");
    expectOverrideError(p, "insert[3].count=5", "insert[3]");                              // no such element
    expectOverrideError(p, "walls.point=[0, 0, 1]", "walls");                              // an array, not a table
    expectOverrideError(p, "duration.x=1", "duration");                                    // a value has no keys
    expectOverrideError(p, "duration=1 2", "duration");                                    // not TOML
    expectOverrideError(p, "duration=", "duration");                                       // no value
    expectOverrideError(p, "insert[0].count=5", "insert[0].count");                        // 1-based
    expectOverrideError(p, "duration", "");                                                // no '='
    expectOverrideError(p, "insert[2].region={ lo = [0, 0, 0] }", "insert[2].region.hi");  // inside a table value
}

// ---------------------------------------------------------------------------------------------------------------
// Bad input: one test per kind; each checks file name, line and key in the message.

TEST_F(ScenarioTest, ErrorUnknownKey) {
    const std::string t = replaced(kBox3d, "friction = 0.5\n", "friction = 0.5\ncolour = \"green\"\n");
    const std::string msg = expectError(t, lineOf(t, "colour"), "materials.glass.colour");
    EXPECT_NE(msg.find("unknown key"), std::string::npos) << msg;

    const std::string top = replaced(kBox3d, "seed = 42\n", "seed = 42\nsteps = 3\n");
    expectError(top, lineOf(top, "steps = 3"), "steps");
}

TEST_F(ScenarioTest, ErrorWrongType) {
    const std::string t = replaced(kBox3d, "duration = 1.0", "duration = \"long\"");
    EXPECT_NE(expectError(t, lineOf(t, "duration = \"long\""), "duration").find("expected a number"),
              std::string::npos);

    const std::string g = replaced(kBox3d, "gravity = [0, 0, -9.81]", "gravity = [0, -9.81]");
    EXPECT_NE(expectError(g, lineOf(g, "gravity"), "domain.gravity").find("expected an array of 3 numbers"),
              std::string::npos);
}

TEST_F(ScenarioTest, ErrorNegativeRadius) {
    const std::string t = replaced(kBox3d, "radius = [0.0008, 0.0012]", "radius = -0.001");
    EXPECT_NE(expectError(t, lineOf(t, "radius = -0.001"), "insert[2].radius").find("must be > 0"), std::string::npos);
}

TEST_F(ScenarioTest, ErrorRestitutionAboveOne) {
    const std::string t = replaced(kBox3d, "restitution = 0.9", "restitution = 1.2");
    expectError(t, lineOf(t, "restitution = 1.2"), "materials.glass.restitution");
}

TEST_F(ScenarioTest, ErrorHiNotAboveLo) {
    const std::string t = replaced(kBox3d, "hi = [0.1, 0.1, 0.2]", "hi = [0.1, 0.1, 0]");
    const std::string msg = expectError(t, lineOf(t, "hi = [0.1, 0.1, 0]"), "domain.hi");
    EXPECT_NE(msg.find("axis z"), std::string::npos) << msg;
}

TEST_F(ScenarioTest, ErrorOverlappingLattice) {
    const std::string t = replaced(kBox3d, "spacing = 0.0021", "spacing = 0.0015");
    const std::string msg = expectError(t, lineOf(t, "spacing = 0.0015"), "insert[1].spacing");
    EXPECT_NE(msg.find("lattice overlaps"), std::string::npos) << msg;

    // The same rule holds for a scenario built in code, reported at the insert's table.
    Scenario s = load(kBox3d);
    s.inserts[0].spacing = 0.0015;
    Particles<3> p;
    try {
        insertParticles(s, p, Rng(s.seed, RngStream::Insert));
        ADD_FAILURE() << "no error";
    } catch (const ScenarioError& e) {
        EXPECT_EQ(e.key(), "insert[1].spacing");
        EXPECT_EQ(e.pos().line, lineOf(kBox3d, "[[insert]]"));
        EXPECT_NE(std::string(e.what()).find("lattice overlaps"), std::string::npos);
    }
}

TEST_F(ScenarioTest, ErrorUnknownMaterial) {
    const std::string t = replaced(kBox3d, "material = \"brass\"", "material = \"wood\"");
    const std::string msg = expectError(t, lineOf(t, "material = \"wood\""), "walls[1].material");
    EXPECT_NE(msg.find("unknown material \"wood\""), std::string::npos) << msg;
}

TEST_F(ScenarioTest, ErrorKnTogetherWithDuration) {
    const std::string t = replaced(kBox3d, "duration = 1e-5\n", "duration = 1e-5\nkn = 2e5\n");
    const std::string msg = expectError(t, lineOf(t, "kn = 2e5"), "contact.kn");
    EXPECT_NE(msg.find("not together with duration"), std::string::npos) << msg;
}

TEST_F(ScenarioTest, ErrorLinearLawWithoutDurationOrKn) {
    const std::string t = replaced(kBox3d, "duration = 1e-5\n", "");
    expectError(t, lineOf(t, "[contact]"), "contact.duration");
}

TEST_F(ScenarioTest, ErrorRegionOutsideDomain) {
    const std::string t = replaced(kBox3d, "hi = [0.1, 0.1, 0.2] }", "hi = [0.1, 0.1, 0.3] }");
    const std::string msg = expectError(t, lineOf(t, "hi = [0.1, 0.1, 0.3] }"), "insert[2].region");
    EXPECT_NE(msg.find("inside the domain"), std::string::npos) << msg;
}

TEST_F(ScenarioTest, ErrorTomlSyntax) {
    const std::string t = replaced(kBox3d, "friction = 0.3", "friction = = 0.3");
    const std::string msg = expectError(t, lineOf(t, "friction = = 0.3"), "");
    EXPECT_NE(msg.find("TOML syntax error"), std::string::npos) << msg;
}

TEST_F(ScenarioTest, ErrorBadCsvLine) {
    const std::string csv = "x,y,z,radius\n0.01,0.01,0.01,0.001\n0.02,abc,0.02,0.001\n";
    const fs::path csvPath = write("grains.csv", csv);
    const std::string t = replaced(kBox3d, "[[insert]]\narrangement = \"lattice\"",
                                   "[[insert]]\narrangement = \"file\"\nfile = \"grains.csv\"\nmaterial = \"glass\"\n"
                                   "\n[[insert]]\narrangement = \"lattice\"");
    const Scenario s = load(t);
    EXPECT_EQ(s.inserts[0].file, csvPath.string());
    Particles<3> p;
    try {
        insertParticles(s, p, Rng(s.seed, RngStream::Insert));
        ADD_FAILURE() << "no error";
    } catch (const ScenarioError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(csvPath.string() + ":3: insert[1].file: "), std::string::npos) << msg;
        EXPECT_NE(msg.find("column y"), std::string::npos) << msg;
    }
    EXPECT_EQ(p.size(), 0u);

    const std::string missing = replaced(t, "file = \"grains.csv\"", "file = \"nowhere.csv\"");
    expectError(missing, lineOf(missing, "nowhere.csv"), "insert[1].file");
}

// ---------------------------------------------------------------------------------------------------------------
// Insertion

TEST_F(ScenarioTest, InsertLatticeAndRandom3d) {
    const Scenario s = load(kBox3d);
    Particles<3> p;
    insertParticles(s, p, Rng(s.seed, RngStream::Insert));
    ASSERT_EQ(p.size(), 300u);
    for (std::size_t i = 0; i < p.size(); ++i) EXPECT_EQ(p.id[i], i);
    expectInside(p, 0, 100, s.inserts[0].regionLo, s.inserts[0].regionHi);
    expectInside(p, 100, 300, s.inserts[1].regionLo, s.inserts[1].regionHi);
    expectNoOverlaps(p);
    for (std::size_t i = 0; i < p.size(); ++i) EXPECT_GE(p.x[i][2], p.radius[i]);  // clear of the floor
    // lattice: first site one radius inside the region corner, then spacing along x
    EXPECT_DOUBLE_EQ(p.x[0][0], 0.001);
    EXPECT_DOUBLE_EQ(p.x[1][0], 0.001 + 0.0021);
    EXPECT_DOUBLE_EQ(p.mass[0], 2500 * Particles<3>::volumeOf(0.001));
    for (std::size_t i = 100; i < 300; ++i) {
        EXPECT_GE(p.radius[i], 0.0008);
        EXPECT_LE(p.radius[i], 0.0012);
        EXPECT_EQ(p.material[i], 1);
        EXPECT_NEAR(p.mass[i], 8500 * Particles<3>::volumeOf(p.radius[i]), 1e-18);
    }

    // Same seed, same particles; another seed, other positions.
    Particles<3> again;
    insertParticles(s, again, Rng(s.seed, RngStream::Insert));
    EXPECT_EQ(again.x, p.x);
    EXPECT_EQ(again.v, p.v);
    Particles<3> other;
    insertParticles(s, other, Rng(s.seed + 1, RngStream::Insert));
    EXPECT_NE(other.x[150], p.x[150]);
}

TEST_F(ScenarioTest, InsertLatticeStopsWhenRegionIsFull2d) {
    // 4 x 4 sites fit: centres from -0.004 in steps of 0.0025 up to 0.0035 (<= 0.004) on x, likewise on y.
    const Scenario s = load(kDisk2d);
    Particles<2> p;
    insertParticles(s, p, Rng(s.seed, RngStream::Insert));
    ASSERT_EQ(p.size(), 16u);
    expectInside(p, 0, p.size(), s.inserts[0].regionLo, s.inserts[0].regionHi);
    expectNoOverlaps(p);
    for (std::size_t i = 0; i < p.size(); ++i) {
        EXPECT_TRUE(p.frozen(i));
        EXPECT_EQ(p.invMass[i], 0.0);
        EXPECT_DOUBLE_EQ(p.mass[i], 7.8 * Particles<2>::volumeOf(0.001));
    }
}

TEST_F(ScenarioTest, InsertRandom2dAvoidsEarlierInsertsAndWalls) {
    const std::string t = kDisk2d + R"(
[[insert]]
arrangement = "random"
count = 150
radius = [0.0005, 0.001]
material = "steel"
region = { lo = [-0.01, 0], hi = [0.01, 0.06] }
)";
    const Scenario s = load(t);
    Particles<2> p;
    insertParticles(s, p, Rng(7, RngStream::Insert));
    ASSERT_EQ(p.size(), 166u);
    expectInside(p, 16, p.size(), s.inserts[1].regionLo, s.inserts[1].regionHi);
    expectNoOverlaps(p);  // includes the lattice disks of the first insert
    for (std::size_t i = 0; i < p.size(); ++i) EXPECT_GE(p.x[i][1], p.radius[i]);
}

TEST_F(ScenarioTest, InsertRandomGivesUpWhenRegionIsTooSmall) {
    const std::string t = replaced(kBox3d, "count = 200", "count = 5000");
    const Scenario s = load(t);
    Scenario small = s;
    small.inserts[1].regionLo = {0, 0, 0.1976};  // a slab one diameter thick: under 2000 fit
    Particles<3> p;
    try {
        insertParticles(small, p, Rng(s.seed, RngStream::Insert));
        ADD_FAILURE() << "no error";
    } catch (const ScenarioError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("could not place 5000 particles without overlap: region too small"), std::string::npos)
            << msg;
        EXPECT_EQ(e.key(), "insert[2].count");
        EXPECT_EQ(e.pos().line, lineOf(t, "arrangement = \"random\"") - 1);
    }
    EXPECT_EQ(p.size(), 100u);  // the lattice insert before it, nothing of the failed one
}

TEST_F(ScenarioTest, InsertMaxwellianHasZeroMomentumAndRequestedVariance) {
    const double temperature = 0.04;  // [m^2/s^2]
    const std::string t = R"(name = "gas"
dimension = 3
duration = 1
[domain]
lo = [0, 0, 0]
hi = [0.2, 0.2, 0.2]
[materials.glass]
density = 2500
restitution = 1
friction = 0
[contact]
duration = 1e-5
[[insert]]
count = 5000
radius = 0.001
material = "glass"
temperature = 0.04
)";
    const Scenario s = load(t);
    Particles<3> p;
    insertParticles(s, p, Rng(s.seed, RngStream::Insert));
    ASSERT_EQ(p.size(), 5000u);
    Vec<3> momentum = Vec<3>::zero();
    Vec<3> sumSq = Vec<3>::zero();
    double speedScale = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        momentum += p.mass[i] * p.v[i];
        for (int k = 0; k < 3; ++k) sumSq[k] += p.v[i][k] * p.v[i][k];
        speedScale += p.mass[i] * std::sqrt(temperature);
    }
    EXPECT_LT(norm(momentum), 1e-12 * speedScale);
    double mean = 0;
    for (int k = 0; k < 3; ++k) {
        const double variance = sumSq[k] / double(p.size());
        EXPECT_NEAR(variance, temperature, 0.05 * temperature) << "component " << k;
        mean += variance / 3;
    }
    EXPECT_NEAR(mean, temperature, 0.05 * temperature);
}

// ---------------------------------------------------------------------------------------------------------------
// Particle files

TEST_F(ScenarioTest, CsvFileRoundTrip) {
    const std::string csv =
        "# three grains\n"
        "radius, x, y, z, vx, vy, vz, material, frozen\n"
        "0.001, 0.01, 0.02, 0.03, 0.1, 0.2, 0.3, brass, 0\n"
        "\n"
        "0.002, 0.05, 0.05, 0.05, 0, 0, -1, 0, 1\n"
        "0.0015, 0.08, 0.07, 0.06, 0, 0, 0, glass, false\n";
    write("grains.csv", csv);
    const std::string t = replaced(kBox3d, "[[insert]]\narrangement = \"lattice\"",
                                   "[[insert]]\narrangement = \"file\"\nfile = \"grains.csv\"\nmaterial = \"glass\"\n"
                                   "format = \"csv\"\n\n[[insert]]\narrangement = \"lattice\"");
    const Scenario s = load(t);
    Particles<3> p;
    insertParticles(s, p, Rng(s.seed, RngStream::Insert));
    ASSERT_EQ(p.size(), 303u);  // 3 from the file, then 100 lattice and 200 random around them
    EXPECT_EQ(p.x[0], (Vec<3>{{0.01, 0.02, 0.03}}));
    EXPECT_EQ(p.v[0], (Vec<3>{{0.1, 0.2, 0.3}}));
    EXPECT_DOUBLE_EQ(p.radius[0], 0.001);
    EXPECT_EQ(p.material[0], 1);
    EXPECT_DOUBLE_EQ(p.mass[0], 8500 * Particles<3>::volumeOf(0.001));
    EXPECT_FALSE(p.frozen(0));
    EXPECT_EQ(p.material[1], 0);
    EXPECT_TRUE(p.frozen(1));
    EXPECT_DOUBLE_EQ(p.v[1][2], -1);
    EXPECT_DOUBLE_EQ(p.mass[1], 2500 * Particles<3>::volumeOf(0.002));
    EXPECT_EQ(p.material[2], 0);
    EXPECT_EQ(p.id[2], 2u);
    expectNoOverlaps(p);  // later inserts avoid the file's grains

    // 2D: no z columns; the reader rejects one.
    const ParticleFile two = readParticleCsv(write("flat.csv", "x,y,radius\n0.1,0.2,0.01\n"), 2, s.materials, "k");
    ASSERT_EQ(two.particles.size(), 1u);
    EXPECT_EQ(two.particles[0].x, (Vec3d{0.1, 0.2, 0}));
    EXPECT_THROW(readParticleCsv(write("z.csv", "x,y,z,radius\n0.1,0.2,0,0.01\n"), 2, s.materials, "k"), ScenarioError);
}

TEST_F(ScenarioTest, LammpsDataRoundTrip) {
    const std::string data = R"(LAMMPS data file via write_data, atom_style sphere

3 atoms
5 atom types

0 0.1 xlo xhi
0 0.1 ylo yhi
-0.05 0.2 zlo zhi

Atoms # sphere

1 1 0.002 2500 0.01 0.02 0.03 0 0 0
2 2 0.003 7800 0.05 0.05 0.05 1 0 -1
3 5 0.002 1000 0.08 0.08 0.08

Velocities

2 0.1 0.2 0.3 1 2 3
1 -0.1 0 0 0 0 0.5
)";
    write("bed.data", data);
    const ParticleFile f = readLammpsData(dir_ / "bed.data", "insert[1].file");
    EXPECT_EQ(f.atomTypes, 5);
    ASSERT_TRUE(f.boxLo && f.boxHi);
    EXPECT_EQ(*f.boxLo, (Vec3d{0, 0, -0.05}));
    EXPECT_EQ(*f.boxHi, (Vec3d{0.1, 0.1, 0.2}));
    ASSERT_EQ(f.particles.size(), 3u);
    EXPECT_EQ(f.particles[1].image, (std::array<int, 3>{1, 0, -1}));
    EXPECT_EQ(f.particles[1].line, lineOf(data, "2 2 0.003"));

    const std::string t = replaced(kBox3d, "[[insert]]\narrangement = \"lattice\"",
                                   "[[insert]]\narrangement = \"file\"\nfile = \"bed.data\"\nformat = \"lammps\"\n"
                                   "material = \"glass\"\nfrozen = false\n\n[[insert]]\narrangement = \"lattice\"");
    const Scenario s = load(t);
    EXPECT_EQ(s.inserts[0].format, FileFormat::LammpsData);
    Particles<3> p;
    insertParticles(s, p, Rng(s.seed, RngStream::Insert));
    ASSERT_EQ(p.size(), 303u);
    EXPECT_EQ(p.x[0], (Vec<3>{{0.01, 0.02, 0.03}}));
    EXPECT_DOUBLE_EQ(p.radius[0], 0.001);
    EXPECT_DOUBLE_EQ(p.mass[0], 2500 * Particles<3>::volumeOf(0.001));
    EXPECT_DOUBLE_EQ(p.mass[1], 7800 * Particles<3>::volumeOf(0.0015));  // density from the file, not the material
    EXPECT_EQ(p.material[0], 0);                                         // type 1 -> material 0
    EXPECT_EQ(p.material[1], 1);                                         // type 2 -> material 1
    EXPECT_EQ(p.material[2], 0);                                         // type 5: no fifth material -> the insert's
    EXPECT_EQ(p.v[0], (Vec<3>{{-0.1, 0, 0}}));
    EXPECT_EQ(p.w[0], (Vec<3>{{0, 0, 0.5}}));
    EXPECT_EQ(p.v[1], (Vec<3>{{0.1, 0.2, 0.3}}));
    EXPECT_EQ(p.w[1], (Vec<3>{{1, 2, 3}}));
    EXPECT_EQ(p.v[2], Vec<3>::zero());                               // no Velocities line
    EXPECT_EQ(p.image[1], (std::array<std::int32_t, 3>{1, 0, -1}));  // the file's flags

    // A malformed Atoms line is reported at its line.
    const fs::path bad = write("bad.data", replaced(data, "3 5 0.002 1000", "3 5 -0.002 1000"));
    try {
        readLammpsData(bad, "insert[1].file");
        ADD_FAILURE() << "no error";
    } catch (const ScenarioError& e) {
        EXPECT_EQ(e.pos().line, lineOf(data, "3 5 0.002"));
        EXPECT_NE(std::string(e.what()).find("diameter must be > 0"), std::string::npos);
    }
}

// ---------------------------------------------------------------------------------------------------------------
// Random numbers

TEST(ScenarioRng, PhiloxMatchesRandom123KnownAnswers) {
    // Random123 tests/kat_vectors, "philox4x32 10" lines: counter, key -> result.
    using A4 = std::array<std::uint32_t, 4>;
    EXPECT_EQ(philox4x32({0, 0, 0, 0}, {0, 0}), (A4{0x6627e8d5, 0xe169c58d, 0xbc57ac4c, 0x9b00dbd8}));
    EXPECT_EQ(philox4x32({0xffffffff, 0xffffffff, 0xffffffff, 0xffffffff}, {0xffffffff, 0xffffffff}),
              (A4{0x408f276d, 0x41c83b0e, 0xa20bc7c6, 0x6d5451fd}));
    EXPECT_EQ(philox4x32({0x243f6a88, 0x85a308d3, 0x13198a2e, 0x03707344}, {0xa4093822, 0x299f31d0}),
              (A4{0xd16cfe09, 0x94fdcceb, 0x5001e420, 0x24126ea1}));
}

TEST(ScenarioRng, StreamsAreReproducibleAndDistinct) {
    Rng a(5, 1), b(5, 1), c(5, 2);
    double sum = 0, sumSq = 0;
    const int n = 200000;
    bool differ = false;
    for (int i = 0; i < n; ++i) {
        const double u = a.uniform();
        ASSERT_EQ(u, b.uniform());
        differ = differ || u != c.uniform();
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        const double g = a.normal();
        ASSERT_EQ(g, b.normal());
        c.normal();
        sum += g;
        sumSq += g * g;
    }
    EXPECT_TRUE(differ);
    EXPECT_NEAR(sum / n, 0.0, 0.01);
    EXPECT_NEAR(sumSq / n, 1.0, 0.01);
}
