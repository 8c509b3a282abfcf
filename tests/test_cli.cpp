// The `haet` command line, run as a real process (HAET_BINARY) on scenario files written to a temporary directory:
// exit codes (0 ok, 2 bad input, 3 blew up), error messages "file:line: key: ...", and the files a run writes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.hpp"

namespace {

using namespace haet::testing::cli;
namespace fs = std::filesystem;

// ------------------------------------------------------------------------------------------------------------

TEST_F(Cli, VersionExitsZero) {
    const Result r = haet("--version");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE((r.out + r.err).find("haet"), std::string::npos);
}

TEST_F(Cli, NoSubcommandIsBadInput) {
    const Result r = haet("");
    EXPECT_EQ(r.code, 2);
}

TEST_F(Cli, CheckValidScenarioPrintsTimeStep) {
    const fs::path f = write("tiny.toml", kTiny);
    const Result r = haet("check '" + f.string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    // dt = t_c / steps_per_contact = 1e-4 / 50
    EXPECT_NE(r.out.find("time step"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("dt = 2e-06 s"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("8 "), std::string::npos) << "particle count: " << r.out;
}

// Hertz with a floor of another material: `check` prints the real restitution of the particles' pairs and of their
// contacts with each wall material, each calibrated for its own contact (docs/physics.md B.3): sqrt(0.8 0.9) on steel.
TEST_F(Cli, CheckPrintsTheWallContactsRestitution) {
    std::string t = haet::testing::replaced(kTiny, "normal = \"linear\"\nduration = 1e-4",
                                            "normal = \"hertz\"\nimpact_velocity = 0.5");
    t = haet::testing::replaced(
        t, "[contact]",
        "[materials.steel]\ndensity = 7800\nyoung = 2e11\nrestitution = 0.9\nfriction = 0.3\n[contact]");
    t = haet::testing::replaced(t, "normal = [0, 0, 1]\nmaterial = \"glass\"",
                                "normal = [0, 0, 1]\nmaterial = \"steel\"");
    const Result r = haet("check '" + write("hertz.toml", t).string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("material   glass: restitution of the soft law 0.80000"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("material   glass on walls of steel: restitution of the soft law 0.84853"), std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("steel on walls"), std::string::npos) << "steel has no particles: " << r.out;
}

TEST_F(Cli, UnknownKey) {
    expectBadInput(edit("friction = 0.5", "friction = 0.5\ncolour = \"green\""), "colour", "materials.glass.colour");
}

TEST_F(Cli, WrongType) {
    expectBadInput(edit("duration = 0.001", "duration = \"short\""), "duration = \"short\"", "duration");
}

TEST_F(Cli, NegativeRadius) { expectBadInput(edit("radius = 0.001", "radius = -0.001"), "radius", "insert[1].radius"); }

TEST_F(Cli, RestitutionAboveOne) {
    expectBadInput(edit("restitution = 0.8", "restitution = 1.2"), "restitution", "materials.glass.restitution");
}

TEST_F(Cli, OverlappingLattice) {
    expectBadInput(edit("radius = 0.001", "radius = 0.001\nspacing = 0.0015"), "spacing", "insert[1].spacing");
}

TEST_F(Cli, MissingParticleFile) {
    expectBadInput(withInsert("arrangement = \"file\"\nfile = \"no_such_file.csv\"\nmaterial = \"glass\"\n"),
                   "file = ", "insert[1].file");
}

TEST_F(Cli, MissingScenarioFile) {
    const fs::path f = dir_ / "does_not_exist.toml";
    const Result r = haet("check '" + f.string() + "'");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(f.string()), std::string::npos) << "the message names the file: " << r.err;
    const Result r2 = haet("run -q '" + f.string() + "'");
    EXPECT_EQ(r2.code, 2) << r2.err;
}

TEST_F(Cli, RunWritesOutputs) {
    const fs::path f = write("tiny.toml", kTiny);
    const fs::path out = dir_ / "run";
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    // series: a row at t = 0 and every series_period up to the duration
    EXPECT_EQ(checkSeries(out / "series.csv"), 11);
    const std::string json = read(out / "run.json");
    EXPECT_TRUE(JsonCheck(json).valid()) << json;
    EXPECT_EQ(jsonString(json, "status"), "completed");
    EXPECT_EQ(jsonString(json, "scenario_name"), "tiny");
    // snapshots at 0, 5e-4 and 1e-3 s, listed in the .pvd collection
    EXPECT_EQ(checkPvd(out / "particles.pvd"), 3);
    int vtuFiles = 0;
    for (const auto& e : fs::directory_iterator(out)) vtuFiles += e.path().extension() == ".vtu";
    EXPECT_EQ(vtuFiles, 3);
}

// --set KEY=VALUE: the run takes the value and records it in run.json; `check` prints it; a bad one exits 2 naming
// the override and the key, for `check` and `run` alike.
TEST_F(Cli, SetOverridesAValueAndIsRecorded) {
    const fs::path f = write("tiny.toml", kTiny);
    const Result c = haet("check '" + f.string() + "' --set tdm.dt=1e-5 --set 'insert[1].count=1'");
    ASSERT_EQ(c.code, 0) << c.err;
    EXPECT_NE(c.out.find("dt = 1e-05 s"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("set        tdm.dt=1e-5"), std::string::npos) << c.out;
    const fs::path out = dir_ / "run";
    const Result r =
        haet("run -q --set duration=5e-4 '" + f.string() + "' --out '" + out.string() + "' --set tdm.dt=1e-5");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(checkSeries(out / "series.csv"), 6);  // 5e-4 s instead of 1e-3 s, a row every 1e-4 s
    const std::string json = read(out / "run.json");
    EXPECT_TRUE(JsonCheck(json).valid()) << json;
    EXPECT_EQ(jsonString(json, "duration"), "5e-4") << json;
    EXPECT_EQ(jsonString(json, "tdm.dt"), "1e-5") << json;
    EXPECT_NE(json.find("\"steps\": 50"), std::string::npos) << json;
}

TEST_F(Cli, SetWithUnknownKeyOrBadValueIsBadInput) {
    const fs::path f = write("tiny.toml", kTiny);
    for (const char* set : {"tdm.dtt=1e-5", "insert[1].count=many", "materials.glass.restitution=2"}) {
        const std::string key = std::string(set).substr(0, std::string(set).find('='));
        const std::string where = f.string() + " (--set " + set + "): " + key + ": ";
        for (const std::string& cmd :
             {"check '" + f.string() + "'", "run -q '" + f.string() + "' --out '" + (dir_ / "out").string() + "'"}) {
            const Result r = haet(cmd + " --set '" + set + "'");
            EXPECT_EQ(r.code, 2) << cmd << " " << set << ": " << r.err;
            EXPECT_NE(r.err.find(where), std::string::npos) << "expected \"" << where << "\" in: " << r.err;
        }
    }
    EXPECT_FALSE(fs::exists(dir_ / "out" / "run.json")) << "nothing is run on bad input";
}

// method = "haet": the hybrid's columns in series.csv, the mode field in the snapshots, the zone images, and
// `haet check` naming the values in force.
TEST_F(Cli, HybridRunWritesModesZonesAndColumns) {
    const std::string text =
        edit("duration = 0.001", "duration = 0.002\nmethod = \"haet\"") + "\n[haet]\nrelabel_every = 20\n";
    const fs::path f = write("hybrid.toml", text);
    const Result c = haet("check '" + f.string() + "'");
    ASSERT_EQ(c.code, 0) << c.err;
    for (const char* key : {"haet", "phi_on", "relabel every 20 steps", "dt_min"})
        EXPECT_NE(c.out.find(key), std::string::npos) << key << " in: " << c.out;
    const fs::path out = dir_ / "run";
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(checkSeries(out / "series.csv"), 21);
    const std::string series = read(out / "series.csv");
    const std::string header = series.substr(0, series.find('\n'));
    for (const char* col :
         {"n_tdm", "n_edm", "events", "tdm_steps", "dissipated_tdm", "dissipated_edm", "energy_unaccounted"})
        EXPECT_NE(header.find(col), std::string::npos) << col << " in: " << header;
    EXPECT_EQ(checkPvd(out / "zones.pvd", ".vti"), 5);
    EXPECT_TRUE(fs::exists(out / "zones_000000.vti"));
    EXPECT_NE(read(out / "particles_000001.vtu").find("Name=\"mode\""), std::string::npos);
    const std::string json = read(out / "run.json");
    EXPECT_EQ(jsonString(json, "method"), "haet");
    EXPECT_EQ(jsonString(json, "status"), "completed");
}

// dt = t_c for 8 hot spheres (about 1 m/s) in a closed box: with omega dt = pi the linear spring is unstable
// (velocity Verlet needs omega dt < 2, docs/physics.md F.2), every contact pumps energy in, and within some 20 steps an
// overlap exceeds max_overlap. The run must stop with exit code 3, name the particle and the time, and keep what
// it wrote before.
TEST_F(Cli, BlowUpExitsThreeAndKeepsOutputs) {
    std::string text = withInsert(
        "arrangement = \"lattice\"\ncount = 8\nradius = 0.001\nspacing = 0.003\nmaterial = \"glass\"\n"
        "region = { lo = [0.002, 0.002, 0.002], hi = [0.008, 0.008, 0.008] }\ntemperature = 1.0\n");
    text = text.replace(text.find("duration = 0.001"), 16, "duration = 0.01");
    text = text.replace(text.find("series_period = 1e-4"), 20, "series_period = 1e-4    # = dt");
    std::string walls = "[tdm]\ndt = 1e-4                  # = t_c\n\n";
    for (const char* w :
         {"[0, 0, 0.01]\nnormal = [0, 0, -1]", "[0, 0, 0]\nnormal = [1, 0, 0]", "[0.01, 0, 0]\nnormal = [-1, 0, 0]",
          "[0, 0, 0]\nnormal = [0, 1, 0]", "[0, 0.01, 0]\nnormal = [0, -1, 0]"})
        walls += std::string("[[walls]]\npoint = ") + w + "\nmaterial = \"glass\"\n";
    text = text.replace(text.find("[[walls]]"), 0, walls);
    const fs::path f = write("blowup.toml", text);
    const fs::path out = dir_ / "run";
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 3) << r.out << r.err;
    EXPECT_TRUE(std::regex_search(r.err, std::regex("particle (id )?[0-9]+"))) << r.err;
    EXPECT_TRUE(std::regex_search(r.err, std::regex("t = [0-9.eE+-]+ s"))) << r.err;
    // what was written before the blow-up is still there and readable
    EXPECT_GE(checkSeries(out / "series.csv"), 5);  // a row every step (series_period = dt) until the blow-up
    const std::string json = read(out / "run.json");
    EXPECT_TRUE(JsonCheck(json).valid()) << json;
    EXPECT_EQ(jsonString(json, "status").rfind("failed", 0), 0u) << json;
    EXPECT_GE(checkPvd(out / "particles.pvd"), 1);  // the snapshot at t = 0
}

// The example of particles that come and go (examples/pour3d.toml): `haet check` describes its inlet, sizes and
// outlet; a bad inlet is bad input (exit 2 with file:line: key), in check and run alike.
TEST_F(Cli, CheckDescribesInletAndOutletOfThePourScene) {
    const Result r = haet(std::string("check '") + HAET_SOURCE_DIR + "/examples/pour3d.toml'");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("inlet      feed: 4000 particles/s"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("d50"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("outlet     drain: box"), std::string::npos) << r.out;
    std::string text = read(fs::path(HAET_SOURCE_DIR) / "examples" / "pour3d.toml");
    text.replace(text.find("rate = 4000"), 11, "rate = 0");
    expectBadInput(text, "rate = 0", "inlet[1].rate");
}

}  // namespace
