// Inputs a hostile (or tired) user gives: each once ran, hung, blew up quietly or blamed the wrong key. Now each is
// bad input (exit code 2, "file:line: key"), a warning, or runs as it should.
#include <string>

#include "cli_util.hpp"

namespace {

using namespace haet::testing::cli;
namespace fs = std::filesystem;

class Hostile : public Cli {
protected:
    /// `haet check` of `text` (written to a file) and its result.
    Result check(const std::string& text, const std::string& sets = "") {
        return haet("check '" + write("scene.toml", text).string() + "' " + sets);
    }
    /// Expects exit code 2 from check and run, with "KEY: " and `what` in the message.
    void expectRejected(const std::string& text, const std::string& key, const std::string& what) {
        const fs::path f = write("bad.toml", text);
        for (const std::string& cmd :
             {"check '" + f.string() + "'", "run -q '" + f.string() + "' --out '" + (dir_ / "out").string() + "'"}) {
            const Result r = haet(cmd);
            EXPECT_EQ(r.code, 2) << cmd << ": " << r.err;
            EXPECT_NE(r.err.find(key + ": "), std::string::npos) << "expected " << key << " in: " << r.err;
            EXPECT_NE(r.err.find(what), std::string::npos) << "expected \"" << what << "\" in: " << r.err;
        }
        EXPECT_FALSE(fs::exists(dir_ / "out" / "run.json"));
    }
};

/// A fully periodic box of 20 hot spheres with k_n = 1e9 (t_c = 2.3e-7 s) and the given [tdm] lines.
std::string stiffGas(const std::string& tdm) {
    return "name = \"stiff\"\ndimension = 3\nduration = 0.05\n[domain]\nlo = [0, 0, 0]\nhi = [0.01, 0.01, 0.01]\n"
           "periodic = [true, true, true]\n[materials.glass]\ndensity = 2500\nrestitution = 0.9\nfriction = 0.0\n"
           "[contact]\nnormal = \"linear\"\nkn = 1e9\ntangential = \"none\"\n[tdm]\n" +
           tdm +
           "\n[[insert]]\narrangement = \"random\"\ncount = 20\nradius = 0.001\nmaterial = \"glass\"\n"
           "temperature = 1.0\n[output]\nseries_period = 1e-3\n";
}

// dt = 600 contact durations: it once ran to "completed" with the kinetic energy up by 1e9 and no overlap ever seen at
// the end of a step. Rejected at the key; and a step just below t_c, which is still unstable, stops the run when a
// particle moves more than its radius in a step.
TEST_F(Hostile, BlowUpWithoutOverlapIsCaught) {
    expectRejected(stiffGas("dt = 1.4e-4"), "tdm.dt", "longer than the contact duration");
    const fs::path f = write("stiff.toml", stiffGas("dt = 2e-7\nmax_overlap = 1.0"));
    const Result r = haet("run -q '" + f.string() + "' --out '" + (dir_ / "out").string() + "'");
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_NE(r.err.find("more than its radius"), std::string::npos) << r.err;
}

// A hand-set dt with fewer than 10 steps per contact: a warning on stderr and in run.json.
TEST_F(Hostile, FewStepsPerContactWarns) {
    const fs::path f = write("stiff.toml", stiffGas("dt = 5e-8"));
    const Result r = haet("run -q '" + f.string() + "' --out '" + (dir_ / "out").string() + "' --set duration=1e-5");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: tdm.dt: 5e-08 s gives 4.55 steps per contact"), std::string::npos) << r.err;
    EXPECT_NE(read(dir_ / "out" / "run.json").find("\"tdm.dt\": \"5e-08 s gives"), std::string::npos);
    const Result fine = haet("run -q '" + f.string() + "' --out '" + (dir_ / "out").string() +
                             "' --set duration=1e-5 --set tdm.dt=2e-8");
    EXPECT_EQ(fine.err.find("warning"), std::string::npos) << fine.err;
}

// An infinite dt and one longer than the run: bad input, not "completed" after 0 steps.
TEST_F(Hostile, InfiniteOrOverlongStepIsBadInput) {
    expectRejected(stiffGas("dt = inf"), "tdm.dt", "must be finite");
    expectRejected(stiffGas("dt = 1.0"), "tdm.dt", "longer than the duration");
}

// Overlapping particles from a file: hard particles (edm, haet) would pass through each other for the whole run; the
// loader names the file, the line and the other particle's line. Soft particles (tdm) may start so.
TEST_F(Hostile, OverlappingFileParticlesForHardParticles) {
    write("grains.csv", "x,y,z,radius\n0.002,0.002,0.002,0.001\n0.005,0.005,0.005,0.001\n0.0055,0.005,0.005,0.001\n");
    const std::string text = withInsert("arrangement = \"file\"\nfile = \"grains.csv\"\nmaterial = \"glass\"\n");
    for (const char* method : {"edm", "haet"}) {
        const std::string t = edit("duration = 0.001", "duration = 0.001\nmethod = \"" + std::string(method) + "\"");
        const Result r = check(withInsert("arrangement = \"file\"\nfile = \"grains.csv\"\nmaterial = \"glass\"\n", t));
        EXPECT_EQ(r.code, 2) << method << r.err;
        EXPECT_NE(r.err.find((dir_ / "grains.csv").string() + ":4: insert[1].file: overlaps the particle of line 3"),
                  std::string::npos)
            << r.err;
    }
    EXPECT_EQ(check(text).code, 0) << "method = \"tdm\" takes them";
}

// The event-driven engine's constraints, at `check` time with the key (they were found only by `run`, exit 2 without
// a line): a wall across a periodic axis, a periodic axis shorter than two diameters, a cell below a diameter.
TEST_F(Hostile, EventDrivenConstraintsAtCheckTime) {
    const std::string edm = edit("duration = 0.001", "duration = 0.001\nmethod = \"edm\"");
    const std::string periodicZ = haet::testing::replaced(edm, "hi = [0.01, 0.01, 0.01]",
                                                          "hi = [0.01, 0.01, 0.01]\nperiodic = [false, false, true]");
    expectRejected(periodicZ, "walls[1].normal", "periodic axis z");
    const std::string narrow = haet::testing::replaced(edm, "hi = [0.01, 0.01, 0.01]",
                                                       "hi = [0.0035, 0.01, 0.01]\nperiodic = [true, false, false]");
    expectRejected(withInsert("arrangement = \"lattice\"\ncount = 2\nradius = 0.001\nmaterial = \"glass\"\n", narrow),
                   "domain.hi", "shorter than two largest diameters");
    expectRejected(edm + "\n[edm]\ncell_size = 0.001\n", "edm.cell_size", "smaller than the largest diameter");
}

// A count of 1e12, and one that fits the indices but not the memory (1e9 spheres, about 1 TB): the key, at once.
TEST_F(Hostile, HugeCountsStopAtTheKey) {
    expectRejected(edit("count = 8", "count = 1000000000000"), "insert[1].count", "at most");
    expectRejected(withInsert("arrangement = \"random\"\ncount = 1000000000\nradius = 1e-6\nmaterial = \"glass\"\n"),
                   "insert[1].count", "GB, more than this machine's");
}

// Grids follow the particles, not the box: a periodic box of 1e6 m (its cells overflowed an int) runs, and a hybrid
// box of 2 cm with grains of 10 um gets at most 2^20 zones (249^3 took 17 s and 1 GB in `check`).
TEST_F(Hostile, GridsAreCappedByTheirParticles) {
    std::string big = haet::testing::replaced(kTiny, "hi = [0.01, 0.01, 0.01]\ngravity = [0, 0, -9.81]",
                                              "hi = [1e6, 1e6, 0.01]\nperiodic = [true, true, false]\n"
                                              "gravity = [0, 0, -9.81]");
    big = withInsert(
        "arrangement = \"lattice\"\ncount = 8\nradius = 0.001\nmaterial = \"glass\"\n"
        "region = { lo = [0, 0, 0], hi = [0.01, 0.01, 0.01] }\n",
        big);
    const fs::path f = write("big.toml", big);
    const Result r = haet("run -q '" + f.string() + "' --out '" + (dir_ / "out").string() + "' --set duration=1e-4");
    EXPECT_EQ(r.code, 0) << r.err;
    const std::string fine =
        withInsert("arrangement = \"random\"\ncount = 1000\nradius = 5e-6\nmaterial = \"glass\"\n",
                   haet::testing::replaced(edit("duration = 0.001", "duration = 0.001\nmethod = \"haet\""),
                                           "hi = [0.01, 0.01, 0.01]", "hi = [0.02, 0.02, 0.02]"));
    const Result c = check(fine);
    ASSERT_EQ(c.code, 0) << c.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(c.out, m, std::regex("\\(([0-9]+) x ([0-9]+) x ([0-9]+) zones\\)"))) << c.out;
    EXPECT_LE(std::stod(m[1]) * std::stod(m[2]) * std::stod(m[3]), 1048576.0) << c.out;
}

// A particle of radius 1e300 m from a file once "completed" with 0 steps and NaN energies, then hung in the PNG
// writer: the file's line and key.
TEST_F(Hostile, AbsurdRadiusFromAFile) {
    write("boulder.csv", "x,y,z,radius\n0.005,0.005,0.005,1e300\n");
    const Result r = check(withInsert("arrangement = \"file\"\nfile = \"boulder.csv\"\nmaterial = \"glass\"\n"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find((dir_ / "boulder.csv").string() + ":2: insert[1].file: radius 1e+300 m"), std::string::npos)
        << r.err;
}

/// kTiny with the Hertz law and `materials` extra materials (all like glass, unused but one).
std::string hertzScene(int materials) {
    std::string t = haet::testing::replaced(kTiny, "normal = \"linear\"\nduration = 1e-4", "normal = \"hertz\"");
    std::string extra;
    for (int k = 0; k < materials; ++k)
        extra += "[materials.m" + std::to_string(k) + "]\ndensity = 2500\nyoung = " + std::to_string(1e8 + k) +
                 "\nrestitution = 0.8\nfriction = 0.5\n";
    return haet::testing::replaced(t, "[contact]", extra + "[contact]");
}

// Hertz with a tiny Young's modulus: the head-on calibration spun for minutes on a collision that never ends; now
// the material's key, at once. And 300 materials (one head-on integration per pair took 55 s for 200) are quick:
// only pairs of used materials are calibrated.
TEST_F(Hostile, HertzCalibrationIsBounded) {
    expectRejected(haet::testing::replaced(hertzScene(0), "density = 2500", "density = 2500\nyoung = 1e-300"),
                   "materials.glass.young", "does not end");
    expectRejected(haet::testing::replaced(hertzScene(0), "density = 2500", "density = 2500\nyoung = 1e-3"),
                   "materials.glass.young", "effective radii");
    const Result r = check(hertzScene(300));
    EXPECT_EQ(r.code, 0) << r.err;
}

// A 2D domain 50 times taller than wide: final.png (900 px wide, 45 000 px tall) once failed every run after it had
// finished; the picture is scaled to fit.
TEST_F(Hostile, TallTwoDimensionalDomainDrawsAPicture) {
    std::string t = haet::testing::sceneText("gas2d.toml");
    t = haet::testing::replaced(t, "hi = [0.1, 0.1]", "hi = [0.01, 0.5]");
    t = haet::testing::replaced(t, "count = 1000", "count = 50");
    const fs::path f = write("tall.toml", t);
    const Result r = haet("run -q '" + f.string() + "' --out '" + (dir_ / "out").string() + "' --set duration=1e-3");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_GT(fs::file_size(dir_ / "out" / "final.png"), 100u);
}

// Wall normals: [1e200, 1e200] squared overflowed (and [1e-200, 1e-200] underflowed) to a zero length that passed the
// nonzero check; both are the diagonal. A normal that points out of the insertion region names the wall.
TEST_F(Hostile, WallNormalsScaleAndPointTowardTheParticles) {
    for (const char* n : {"[1e200, 0, 1e200]", "[1e-200, 0, 1e-200]"}) {
        const Result r = check(edit("normal = [0, 0, 1]", std::string("normal = ") + n));
        EXPECT_EQ(r.code, 0) << n << ": " << r.err;
    }
    expectRejected(edit("normal = [0, 0, 1]", "normal = [0, 0, -1]"), "walls[1].normal",
                   "leaves no room for insert[1]");
}

// A directory or a device as the scenario: exit 2 with a plain message, read to a bound (/dev/zero took all memory).
TEST_F(Hostile, DirectoryOrDeviceAsTheScenario) {
    Result r = haet("check '" + dir_.string() + "'");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("is a directory"), std::string::npos) << r.err;
    r = haet("run -q /dev/zero --out '" + (dir_ / "out").string() + "'");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("/dev/zero: longer than 16 MiB"), std::string::npos) << r.err;
}

// A LAMMPS data file whose box is not the domain on a periodic axis (positions wrap and image flags unwrap by the
// domain's box): the file and the axis.
TEST_F(Hostile, LammpsBoxMustMatchThePeriodicDomain) {
    write("bed.data",
          "LAMMPS data file\n\n1 atoms\n1 atom types\n\n0 0.02 xlo xhi\n0 0.01 ylo yhi\n0 0.01 zlo zhi\n\n"
          "Atoms # sphere\n\n1 1 0.002 2500 0.005 0.005 0.005\n");
    const std::string periodic = haet::testing::replaced(kTiny, "hi = [0.01, 0.01, 0.01]",
                                                         "hi = [0.01, 0.01, 0.01]\nperiodic = [true, true, false]");
    const std::string t = withInsert(
        "arrangement = \"file\"\nfile = \"bed.data\"\nformat = \"lammps\"\nmaterial = \"glass\"\n", periodic);
    expectRejected(t, "insert[1].file", "box on periodic axis x, [0, 0.02], is not the domain's [0, 0.01]");
    EXPECT_EQ(check(haet::testing::replaced(t, "hi = [0.01, 0.01, 0.01]", "hi = [0.02, 0.01, 0.01]")).code, 0);
}

// The linear law with kn and gamma_n gives its own restitution: the materials' is optional there (and `check` prints
// the one obtained); elsewhere it is still required.
TEST_F(Hostile, RestitutionOptionalWithKnAndGammaN) {
    const std::string noE = edit("restitution = 0.8", "# no restitution");
    const std::string withKn = haet::testing::replaced(noE, "duration = 1e-4", "kn = 1e4\ngamma_n = 50");
    const Result r = check(withKn);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("restitution of the soft law 0.9"), std::string::npos) << r.out;
    expectRejected(noE, "materials.glass.restitution", "is required");
}

// A centre of 1e92 m in a file of hard particles in a periodic box: the overlap test binned it into a cell before the
// centre was checked, an index far beyond any int (undefined behaviour, a wild cell). Now the file's line, first.
TEST_F(Hostile, FarCentreFromAFileIsOutsideTheDomain) {
    write("far.csv", "x,y,z,radius\n0.005,0.005,0.005,0.001\n1e92,0.005,0.005,0.001\n");
    const std::string periodic =
        haet::testing::replaced(edit("duration = 0.001", "duration = 0.001\nmethod = \"edm\""),
                                "hi = [0.01, 0.01, 0.01]", "hi = [0.01, 0.01, 0.01]\nperiodic = [true, true, false]");
    const Result r = check(withInsert("arrangement = \"file\"\nfile = \"far.csv\"\nmaterial = \"glass\"\n", periodic));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find((dir_ / "far.csv").string() + ":3: insert[1].file: particle centre lies outside the domain"),
              std::string::npos)
        << r.err;
}

// Particle files are text: a NUL byte (a binary file given by mistake) and a line of more than 1 MiB (which was read
// whole into memory, without bound) are errors at the file's line; a device such as /dev/zero is not opened.
TEST_F(Hostile, ParticleFilesAreText) {
    const std::string insert = "arrangement = \"file\"\nfile = \"grains.csv\"\nmaterial = \"glass\"\n";
    write("grains.csv", std::string("x,y,z,radius\n0.005,0.005,0.005,0.001\n0.002,0.0") + '\0' + "2,0.002,0.001\n");
    Result r = check(withInsert(insert));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find((dir_ / "grains.csv").string() + ":3: insert[1].file: a NUL byte"), std::string::npos)
        << r.err;
    write("grains.csv", "x,y,z,radius\n" + std::string(std::size_t(3) << 19, ' ') + "0.005,0.005,0.005,0.001\n");
    r = check(withInsert(insert));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find((dir_ / "grains.csv").string() + ":2: insert[1].file: line longer than 1 MiB"),
              std::string::npos)
        << r.err;
    r = check(withInsert("arrangement = \"file\"\nfile = \"/dev/zero\"\nmaterial = \"glass\"\n"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("insert[1].file: not a regular file (a directory or a device): /dev/zero"), std::string::npos)
        << r.err;
}

// LAMMPS atom types and image flags beyond 32 bits were cut to an int without a word (type 4294967297 became
// type 1): the line that holds them.
TEST_F(Hostile, LammpsIntegersBeyond32Bits) {
    const std::string insert =
        "arrangement = \"file\"\nfile = \"bed.data\"\nformat = \"lammps\"\nmaterial = \"glass\"\n";
    const std::string head =
        "LAMMPS data file\n\n1 atoms\n\n0 0.01 xlo xhi\n0 0.01 ylo yhi\n0 0.01 zlo zhi\n\n"
        "Atoms # sphere\n\n";
    write("bed.data", head + "1 4294967297 0.002 2500 0.005 0.005 0.005\n");
    Result r = check(withInsert(insert));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find((dir_ / "bed.data").string() + ":11: insert[1].file: Atoms line: atom type must be an "
                                                        "integer from 1 to 2147483647, got \"4294967297\""),
              std::string::npos)
        << r.err;
    write("bed.data", head + "1 1 0.002 2500 0.005 0.005 0.005 0 3000000000 0\n");
    r = check(withInsert(insert));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find((dir_ / "bed.data").string() + ":11: insert[1].file: Atoms line: image flag must be an "
                                                        "integer within +-2^31, got \"3000000000\""),
              std::string::npos)
        << r.err;
    write("bed.data", head + "1 1 0.002 2500 0.005 0.005 0.005 0 -2 0\n");
    EXPECT_EQ(check(withInsert(insert)).code, 0);
}

}  // namespace
