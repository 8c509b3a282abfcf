// Checkpoints and `haet run --resume` (docs/scenario.md, "Resuming"): a run of duration T and the same run stopped at
// a checkpoint and resumed write the same bytes (series.csv, the snapshots, their collections), for each engine and
// kind of scene, on one and two threads; a checkpoint that is truncated, corrupt, of a later format or of another
// scenario is refused with exit code 2 and a message that says which, and a corrupt newest one gives way to the one
// before it. The runs are of the `haet` program, on scenes of examples/ shortened by overrides.
#include <algorithm>
#include <cmath>
#include <csignal>
#include <limits>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_util.hpp"
#include "io/checkpoint.hpp"
#include "run/checkpoint.hpp"
#include "scenario/loader.hpp"
#include "world/build.hpp"
#include "world/state.hpp"

namespace {

using namespace haet::testing::cli;
namespace fs = std::filesystem;

/// A scene of examples/ with the overrides that make it short.
struct Scene {
    std::string file;
    std::vector<std::string> sets;
    double duration;  ///< T [s]
};

/// The last value of column `name` of a series.csv.
double lastValue(const std::string& csv, const std::string& name) {
    std::istringstream in(csv);
    std::string header, line, last;
    std::getline(in, header);
    while (std::getline(in, line))
        if (!line.empty()) last = line;
    auto cells = [](const std::string& row) {
        std::vector<std::string> out;
        std::stringstream ss(row);
        for (std::string c; std::getline(ss, c, ',');) out.push_back(c);
        return out;
    };
    const auto h = cells(header), v = cells(last);
    const auto at = std::find(h.begin(), h.end(), name);
    if (at == h.end() || static_cast<std::size_t>(at - h.begin()) >= v.size()) {
        ADD_FAILURE() << "no column " << name;
        return 0;
    }
    return std::stod(v[static_cast<std::size_t>(at - h.begin())]);
}

class Restart : public Cli {
protected:
    /// `haet run -q examples/SCENE` with the scene's overrides and `extra`, into out.
    Result run(const Scene& s, const fs::path& out, int threads, const std::vector<std::string>& extra,
               const std::string& resume = "") {
        std::string args = "run -q '" + std::string(HAET_SOURCE_DIR) + "/examples/" + s.file + "' --threads " +
                           std::to_string(threads);
        args += resume.empty() ? " --out '" + out.string() + "'" : " --resume '" + resume + "'";
        for (const std::string& v : s.sets) args += " --set '" + v + "'";
        for (const std::string& v : extra) args += " --set '" + v + "'";
        return haet(args);
    }
    static std::string duration(double t) { return "duration=" + std::to_string(t); }
    /// A hybrid run changed modes both ways (or handed grains over by the modified EDM).
    static void expectModeChanges(const fs::path& dir) {
        const std::string csv = read(dir / "series.csv");
        EXPECT_GT(lastValue(csv, "to_tdm"), 0) << dir;
        EXPECT_GT(lastValue(csv, "to_edm") + lastValue(csv, "tc_handovers"), 0) << dir;
    }

    /// Every output a resumed run must reproduce: series.csv, the collections and every snapshot file, by name.
    static std::vector<std::pair<std::string, std::string>> outputs(const fs::path& dir) {
        std::vector<std::pair<std::string, std::string>> files;
        static const std::regex re(R"(series\.csv|final\.(csv|data)|.*\.pvd|.*_[0-9]{6}\.(vtu|vtp|vti)|)"
                                   R"(fields_.*\.csv|contacts_[0-9]{6}\.csv)");
        for (const auto& e : fs::directory_iterator(dir))
            if (std::regex_match(e.path().filename().string(), re))
                files.emplace_back(e.path().filename().string(), read(e.path()));
        std::sort(files.begin(), files.end());
        return files;
    }
    static void expectSameOutputs(const fs::path& a, const fs::path& b) {
        const auto fa = outputs(a), fb = outputs(b);
        ASSERT_EQ(fa.size(), fb.size());
        ASSERT_GE(fa.size(), 3u);
        for (std::size_t k = 0; k < fa.size(); ++k) {
            EXPECT_EQ(fa[k].first, fb[k].first);
            EXPECT_TRUE(fa[k].second == fb[k].second) << fa[k].first << " differs";
        }
    }

    /// The run of duration T, and the same run stopped at a checkpoint and resumed in two ways: run to T/2 (its
    /// last checkpoint) then resumed to T; the full run's directory without its last checkpoint, resumed from the
    /// periodic one before it. Both give the full run's bytes.
    /// `halve`: also the run to T/2 resumed to T, which only a time-driven run can match bit for bit (an event-driven
    /// engine is called in pieces of 1/500 of the duration, and its state depends on where the calls end).
    void expectResumeIdentical(const Scene& s, int threads, bool halve = true) {
        SCOPED_TRACE(s.file + " on " + std::to_string(threads) + " threads");
        const std::string period = "output.checkpoint_period=" + std::to_string(s.duration / 4);
        const fs::path full = dir_ / "full", half = dir_ / "half", older = dir_ / "older";
        for (const fs::path& p : {full, half, older}) fs::remove_all(p);
        Result r = run(s, full, threads, {duration(s.duration), period});
        ASSERT_EQ(r.code, 0) << r.err;
        // Two checkpoints kept: the one at the end and the periodic one before it.
        const auto kept = haet::listCheckpoints(full);
        ASSERT_EQ(kept.size(), 2u);

        if (halve) {
            r = run(s, half, threads, {duration(s.duration / 2), period});
            ASSERT_EQ(r.code, 0) << r.err;
            r = run(s, half, threads, {duration(s.duration), period}, half.string());
            ASSERT_EQ(r.code, 0) << r.err;
            EXPECT_NE(r.err.find("resuming from"), std::string::npos) << r.err;
            expectSameOutputs(full, half);
        }

        fs::copy(full, older);
        fs::remove(older / kept[0].filename());
        r = run(s, older, threads, {duration(s.duration), period}, older.string());
        ASSERT_EQ(r.code, 0) << r.err;
        expectSameOutputs(full, older);
        EXPECT_NE(read(older / "run.json").find("\"resumed_from\": \"" + kept[1].filename().string()),
                  std::string::npos);
    }
};

// Spheres settling in a box on planes (velocity Verlet), the same with Gear's predictor-corrector.
const Scene kBox{
    "box3d_settle.toml", {"insert[1].count=150", "output.series_period=0.002", "output.snapshot_period=0.01"}, 0.04};
const Scene kBoxGear{
    "box3d_settle.toml",
    {"insert[1].count=150", "tdm.integrator=\"gear5\"", "output.series_period=0.002", "output.snapshot_period=0.01"},
    0.04};
// A silo of segment walls fed by an inlet and drained by an outlet: walls of any shape, particles that come and go.
// Its inlet's end and its outlet's interval follow from the duration unless set (so the halved run sets them).
const Scene kSilo{"silo2d.toml",
                  {"method=\"tdm\"", "inlet[1].end=1", "outlet[1].interval=1e-3", "outlet[2].interval=1e-3",
                   "output.series_period=0.002", "output.snapshot_period=0.01"},
                  0.04};

TEST_F(Restart, TdmVerletResumesBitForBit) {
    for (int threads : {1, 2}) expectResumeIdentical(kBox, threads);
}

TEST_F(Restart, TdmGearResumesBitForBit) { expectResumeIdentical(kBoxGear, 1); }

TEST_F(Restart, TdmWithInletsOutletsAndSegmentsResumesBitForBit) {
    for (int threads : {1, 2}) expectResumeIdentical(kSilo, threads);
}

// Polygons (Gear's integrator, the overlap-area law, their tangential springs in the pair list): a box of hexagons and
// random convex shapes settling on planes, and a hopper of segment walls (their contacts with walls of any shape).
const Scene kPolygonBox{
    "box2d_polygons.toml",
    {"insert[1].count=100", "insert[2].count=100", "output.series_period=0.01", "output.snapshot_period=0.05"},
    0.2};
const Scene kPolygonHopper{"hopper2d_polygons.toml",
                           {"insert[1].count=300", "output.series_period=0.002", "output.snapshot_period=0.01"},
                           0.04};

TEST_F(Restart, PolygonsResumeBitForBit) {
    for (int threads : {1, 2}) {
        expectResumeIdentical(kPolygonBox, threads);
        EXPECT_GT(lastValue(read(dir_ / "full" / "series.csv"), "n_contacts"), 50);
        expectResumeIdentical(kPolygonHopper, threads);
    }
}

// Event-driven: a gas in a periodic box (cell crossings, collisions, the TC model's clocks, the re-sorting of the
// slots), and a 2D gas in a closed box (plane walls).
const Scene kGas{
    "dilute_gas3d.toml", {"insert[1].count=300", "output.series_period=0.002", "output.snapshot_period=0.01"}, 0.05};
const Scene kGas2d{"gas2d.toml", {"method=edm", "output.series_period=0.002", "output.snapshot_period=0.01"}, 0.05};

// The measurements (run/measures.hpp): a [[fields]] window open at a checkpoint, its samples' sums carried in the
// checkpoint; the contact network and the series' stress; an event-driven gas's collisions in the window.
const Scene kBed{
    "bed3d_fields.toml",
    {"fields[1].period=0.015", "fields[1].window=0.01", "output.series_period=0.002", "output.snapshot_period=0.01"},
    0.04};
const Scene kGasFields{
    "gas3d_fields.toml",
    {"fields[1].period=0.02", "fields[1].window=0.015", "output.series_period=0.005", "output.snapshot_period=0.01"},
    0.06};

TEST_F(Restart, FieldsWindowsResumeBitForBit) {
    expectResumeIdentical(kBed, 2);
    expectResumeIdentical(kGasFields, 1, false);
}

TEST_F(Restart, EdmResumesBitForBit) {
    expectResumeIdentical(kGas, 1, false);
    expectResumeIdentical(kGas2d, 1, false);
}

// The hybrid: the demo's bed with its stream just above it (grains land and change mode within the run), and the
// silo of segments with its inlet and outlets (particles born and removed in either mode). The state of every part
// is saved (haet/state.cpp); the hybrid steps whole time steps whatever the pieces it is called in, so the run to T/2
// resumed to T matches too. The runs are checked to change modes, or they would not test the books of a change.
const Scene kHaetDemo{
    "haet_demo.toml",
    {"insert[1].count=250", "insert[2].count=800", "insert[2].region={lo=[0.05,0.016],hi=[0.25,0.05]}",
     "contact.duration=4e-4", "output.series_period=0.004", "output.snapshot_period=0.02"},
    0.08};
const Scene kHaetSilo{"silo2d.toml",
                      {"insert[1].count=800", "inlet[1].end=1", "outlet[1].interval=1e-3", "outlet[2].interval=1e-3",
                       "output.series_period=0.002", "output.snapshot_period=0.01"},
                      0.04};

TEST_F(Restart, HybridResumesBitForBit) {
    for (int threads : {1, 2}) {
        expectResumeIdentical(kHaetDemo, threads);
        expectModeChanges(dir_ / "full");
    }
}

TEST_F(Restart, HybridWithInletsOutletsAndSegmentsResumesBitForBit) {
    for (int threads : {1, 2}) {
        expectResumeIdentical(kHaetSilo, threads);
        expectModeChanges(dir_ / "full");
    }
}

// An output directory that cannot be made (a file stands in its way) or written in: exit code 4, the path named.
TEST_F(Restart, UnwritableOutputIsExitFourNamingThePath) {
    write("afile", "not a directory");
    for (const fs::path& out : {dir_ / "afile" / "run", fs::path("/proc/self")}) {
        const Result r = haet("run -q '" + std::string(HAET_SOURCE_DIR) + "/examples/drop3d_tiny.toml' --out '" +
                              out.string() + "'");
        EXPECT_EQ(r.code, 4) << r.err;
        EXPECT_NE(r.err.find("cannot write an output: " + out.string()), std::string::npos) << r.err;
    }
}

// A disk that fills up: the run resumed from T/2 may write no file larger than its snapshots (RLIMIT_FSIZE with
// SIGXFSZ ignored: a write past the limit fails with EFBIG, as one on a full disk with ENOSPC), so its next
// checkpoint fails. Exit code 4 naming the file; every file left is whole (no temporary file renamed into place,
// none left behind; the checkpoints before parse, series.csv and the collections are complete, run.json says
// "failed: output"); resumed on a disk with room, the run writes the bytes of the run that never failed.
TEST_F(Restart, FullDiskIsExitFourAndLeavesEveryFileWhole) {
    const Scene& s = kSilo;
    const std::string period = "output.checkpoint_period=" + std::to_string(s.duration / 4);
    const fs::path full = dir_ / "full", out = dir_ / "out";
    Result r = run(s, full, 1, {duration(s.duration), period});
    ASSERT_EQ(r.code, 0) << r.err;
    r = run(s, out, 1, {duration(s.duration / 2), period});
    ASSERT_EQ(r.code, 0) << r.err;
    std::uintmax_t largest = 0, smallestCheckpoint = ~std::uintmax_t{0};
    for (const auto& e : fs::directory_iterator(full)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("checkpoint_", 0) == 0)
            smallestCheckpoint = std::min(smallestCheckpoint, e.file_size());
        else if (name.rfind("final", 0) != 0)
            largest = std::max(largest, e.file_size());
    }
    ASSERT_LT(largest, smallestCheckpoint) << "a checkpoint is the largest file the run writes before its end";
    const auto before = haet::listCheckpoints(out);
    ASSERT_EQ(before.size(), 2u);

    std::vector<std::string> args = {"run",        "-q",    std::string(HAET_SOURCE_DIR) + "/examples/" + s.file,
                                     "--threads",  "1",     "--resume",
                                     out.string(), "--set", duration(s.duration),
                                     "--set",      period};
    for (const std::string& v : s.sets) args.insert(args.end(), {"--set", v});
    // First a limit below the checkpoints only, then one below the snapshots too (written through a stream).
    const fs::path checkpoint =
        out / haet::checkpointFileName(haet::parseCheckpoint(read(before[0])).header.sequence + 1);
    for (const auto& [limit, failing] : {std::pair{(largest + smallestCheckpoint) / 2, checkpoint.string()},
                                         std::pair{largest / 2, (out / "particles_").string()}}) {
        SCOPED_TRACE("at most " + std::to_string(limit) + " bytes a file");
        const int code = wait(spawn(args, {}, limit));
        const std::string err = read(dir_ / "stderr.txt");
        EXPECT_EQ(code, 4) << err;
        EXPECT_NE(err.find("cannot write an output: " + failing), std::string::npos) << err;
        EXPECT_NE(err.find(".tmp."), std::string::npos) << err;  // the temporary file it wrote
        EXPECT_NE(err.find("File too large"), std::string::npos) << err;

        for (const auto& e : fs::directory_iterator(out))
            EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path() << " left behind";
        EXPECT_EQ(haet::listCheckpoints(out), before);
        for (const fs::path& k : before) EXPECT_NO_THROW(haet::parseCheckpoint(read(k))) << k;
        EXPECT_GE(checkSeries(out / "series.csv"), 10);
        EXPECT_GE(checkPvd(out / "particles.pvd"), 3);
        const std::string json = read(out / "run.json");
        EXPECT_TRUE(JsonCheck(json).valid()) << json;
        EXPECT_EQ(jsonString(json, "status").rfind("failed: output: " + failing, 0), 0u) << json;
    }

    r = run(s, out, 1, {duration(s.duration), period}, out.string());
    ASSERT_EQ(r.code, 0) << r.err;
    expectSameOutputs(full, out);
}

/// The files of a run to T with checkpoints, and a copy of its directory to resume from.
class RestartFaults : public Restart {
protected:
    void SetUp() override {
        Restart::SetUp();
        const Result r = run(kBox, dir_ / "full", 1, {duration(0.02), "output.checkpoint_period=0.01"});
        ASSERT_EQ(r.code, 0) << r.err;
        kept_ = haet::listCheckpoints(dir_ / "full");
        ASSERT_EQ(kept_.size(), 2u);
    }
    /// A copy of the run directory to damage.
    fs::path copy() {
        const fs::path c = dir_ / "copy";
        fs::remove_all(c);
        fs::copy(dir_ / "full", c);
        return c;
    }
    Result resume(const fs::path& c, const std::vector<std::string>& extra = {}) {
        std::vector<std::string> sets = {duration(0.03), "output.checkpoint_period=0.01"};
        sets.insert(sets.end(), extra.begin(), extra.end());
        return run(kBox, c, 1, sets, c.string());
    }
    static void patch(const fs::path& p, std::size_t at, char value) {
        std::string s = read(p);
        s[at] = value;
        std::ofstream(p, std::ios::binary) << s;
    }
    std::vector<fs::path> kept_;
};

TEST_F(RestartFaults, CorruptNewestGivesWayToTheOneBefore) {
    const fs::path c = copy();
    const fs::path newest = c / kept_[0].filename();
    patch(newest, read(newest).size() / 2, 'x');
    const Result r = resume(c);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("checksum mismatch"), std::string::npos) << r.err;
    EXPECT_NE(read(c / "run.json").find(kept_[1].filename().string()), std::string::npos);
}

TEST_F(RestartFaults, TruncatedAndCorruptAreExitTwo) {
    const fs::path c = copy();
    for (const fs::path& k : kept_) fs::resize_file(c / k.filename(), fs::file_size(c / k.filename()) - 100);
    Result r = resume(c);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("truncated checkpoint"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("no whole checkpoint"), std::string::npos) << r.err;
    for (const fs::path& k : kept_) std::ofstream(c / k.filename(), std::ios::binary) << "not a checkpoint";
    r = resume(c);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("not a HAET checkpoint"), std::string::npos) << r.err;
}

TEST_F(RestartFaults, LaterFormatIsExitTwo) {
    const fs::path c = copy();
    patch(c / kept_[0].filename(), 8, char(haet::kCheckpointVersion + 1));  // the version's low byte
    const Result r = resume(c);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("format version " + std::to_string(haet::kCheckpointVersion + 1)), std::string::npos) << r.err;
}

TEST_F(RestartFaults, EarlierFormatIsExitTwo) {
    const fs::path c = copy();
    for (const fs::path& k : kept_) patch(c / k.filename(), 8, char(haet::kCheckpointVersion - 1));
    const Result r = resume(c);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("format version " + std::to_string(haet::kCheckpointVersion - 1) + ", older than"),
              std::string::npos)
        << r.err;
}

TEST_F(RestartFaults, AnotherScenarioIsExitTwoNamingTheKey) {
    const fs::path c = copy();
    Result r = resume(c, {"materials.glass.restitution=0.5"});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("materials.glass.restitution changed (checkpoint: 0.7, scenario: 0.5)"), std::string::npos)
        << r.err;
    r = resume(c, {"tdm.sort_every=10"});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("tdm.sort_every changed (checkpoint: not set, scenario: 10)"), std::string::npos) << r.err;
    // Other periods and directories are safe to change.
    r = resume(c, {"output.series_period=0.005", "output.snapshot_period=-1", "output.directory=\"elsewhere\""});
    EXPECT_EQ(r.code, 0) << r.err;
}

// A duration that the inlets' schedule follows (their end by default) cannot change on resume.
TEST_F(Restart, DurationDefaultsAreNamed) {
    const Scene s{
        "silo2d.toml", {"method=\"tdm\"", "output.series_period=0.002", "output.checkpoint_period=0.01"}, 0.02};
    Result r = run(s, dir_ / "run", 1, {duration(0.01)});
    ASSERT_EQ(r.code, 0) << r.err;
    r = run(s, dir_ / "run", 1, {duration(0.02)}, (dir_ / "run").string());
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("inlet[1].end changed (checkpoint: 0.01 (the default, from duration"), std::string::npos)
        << r.err;
}

// The files a scenario names are part of it by their contents: a particle file or an STL mesh changed since the
// checkpoint was written is refused on resume, naming the file (the particles come from the checkpoint, but the
// scenario is another one). The scene: the tiny drop with its spheres read from the file the run of the tiny scene
// wrote as its final state, and a floor of two triangles from an STL file.
TEST_F(Restart, ChangedParticleOrMeshFileIsExitTwoNamingIt) {
    Result r = haet("run -q '" + std::string(HAET_SOURCE_DIR) + "/examples/drop3d_tiny.toml' --out '" +
                    (dir_ / "first").string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    const fs::path bed = dir_ / "bed.csv";
    fs::copy_file(dir_ / "first" / "final.csv", bed);
    auto facet = [](const std::string& a, const std::string& b, const std::string& c) {
        return " facet normal 0 0 1\n  outer loop\n   vertex " + a + "\n   vertex " + b + "\n   vertex " + c +
               "\n  endloop\n endfacet\n";
    };
    const std::string floor = "solid floor\n" + facet("0 0 0.0002", "0.01 0 0.0002", "0.01 0.01 0.0002") +
                              facet("0 0 0.0002", "0.01 0.01 0.0002", "0 0.01 0.0002") + "endsolid floor\n";
    const fs::path stl = write("floor.stl", floor);
    std::string text =
        withInsert("arrangement = \"file\"\nfile = \"bed.csv\"\nformat = \"csv\"\nmaterial = \"glass\"\n");
    text.replace(text.find("[[insert]]"), 0,
                 "[[walls]]\ntype = \"mesh\"\nfile = \"floor.stl\"\nmaterial = \"glass\"\n\n");
    const fs::path scene = write("staged.toml", text);
    const fs::path out = dir_ / "run";
    auto runIt = [&](bool resume) {
        return haet("run -q '" + scene.string() + "' " + (resume ? "--resume '" : "--out '") + out.string() +
                    "' --set duration=" + (resume ? "0.002" : "0.001") + " --set output.checkpoint_period=5e-4");
    };
    r = runIt(false);
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_EQ(runIt(true).code, 0) << "unchanged files resume";
    // A resume that went on wrote checkpoints of its own: start again from the first run's.
    fs::remove_all(out);
    ASSERT_EQ(runIt(false).code, 0);

    std::ofstream(bed, std::ios::app) << "# the same particles, another file\n";
    r = runIt(true);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(bed.string() + ": the file of insert[1].file has changed since the checkpoint"),
              std::string::npos)
        << r.err;

    fs::copy_file(dir_ / "first" / "final.csv", bed, fs::copy_options::overwrite_existing);
    ASSERT_EQ(runIt(true).code, 0) << "the file as it was resumes";
    fs::remove_all(out);
    ASSERT_EQ(runIt(false).code, 0);
    std::string moved = floor;
    moved.replace(moved.find("0 0.01 0.0002"), 13, "0 0.01 0.0003");
    std::ofstream(stl, std::ios::binary) << moved;
    r = runIt(true);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(stl.string() + ": the file of walls[2].file has changed since the checkpoint"),
              std::string::npos)
        << r.err;
}

TEST_F(RestartFaults, NoCheckpointIsExitTwo) {
    const fs::path c = dir_ / "empty";
    fs::create_directories(c);
    const Result r = resume(c);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("no checkpoint"), std::string::npos) << r.err;
}

// The reader takes bytes from memory: every prefix of a whole checkpoint, and every one with a byte changed, is
// refused with a CheckpointError that says which (never a crash, never a read outside the bytes).
TEST_F(RestartFaults, ReaderRefusesEveryPrefixAndEveryFlippedByte) {
    const std::string bytes = read(kept_[1]);
    ASSERT_NO_THROW(haet::parseCheckpoint(bytes));
    const std::size_t step = std::max<std::size_t>(1, bytes.size() / 2000);
    for (std::size_t n = 0; n < bytes.size(); n += n < 64 ? 1 : step) {
        try {
            haet::parseCheckpoint(std::string_view(bytes).substr(0, n));
            ADD_FAILURE() << "a prefix of " << n << " bytes was taken";
        } catch (const haet::CheckpointError& e) {
            EXPECT_TRUE(e.fault() == (n < 8 ? haet::CheckpointFault::Corrupt : haet::CheckpointFault::Truncated))
                << n << ": " << e.what();
        }
    }
    for (std::size_t at = 12; at < bytes.size(); at += step) {
        std::string b = bytes;
        b[at] = static_cast<char>(b[at] ^ 0x10);
        EXPECT_THROW(haet::parseCheckpoint(b), haet::CheckpointError) << "byte " << at;
    }
}

// A state that no run saves (a run stops at the first NaN), in a file whose checksum is right: a NaN or infinite
// position, velocity or spin, or a position beyond any cell index, is refused by the World's loader, before an
// engine bins the position into a cell.
TEST(RestartState, NonFiniteParticlesAreRefused) {
    const haet::Scenario sc = haet::loadScenario(std::string(HAET_SOURCE_DIR) + "/examples/drop3d_tiny.toml");
    const haet::World<3> built = haet::buildWorld<3>(sc);
    for (int which = 0; which < 4; ++which) {
        haet::World<3> w = built;
        const double bad = which == 3 ? -std::numeric_limits<double>::infinity() : std::nan("");
        (which == 1 ? w.particles.v : which == 2 ? w.particles.w : w.particles.x)[3][1] = bad;
        haet::ByteWriter out;
        haet::saveWorld(out, w);
        haet::ByteReader in(out.bytes(), "WRLD");
        haet::World<3> back = built;
        try {
            haet::loadWorld(in, back);
            ADD_FAILURE() << "case " << which << " was taken";
        } catch (const haet::CheckpointError& e) {
            EXPECT_EQ(e.fault(), haet::CheckpointFault::Corrupt);
            EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
        }
    }
    // 1e294 m (a checkpoint the fuzzer made): beyond any cell index of the grids; 5 box lengths away is a state.
    for (double x : {-2.46e294, 0.05}) {
        haet::World<3> w = built;
        w.particles.x[2][0] = x;
        haet::ByteWriter out;
        haet::saveWorld(out, w);
        haet::ByteReader in(out.bytes(), "WRLD");
        haet::World<3> back = built;
        if (x < 0) {
            EXPECT_THROW(haet::loadWorld(in, back), haet::CheckpointError);
        } else {
            EXPECT_NO_THROW(haet::loadWorld(in, back));
        }
    }
}

// A run stopped by SIGINT or SIGTERM (the batch system's time limit) at whatever step it was in: exit 130 / 143,
// run.json "interrupted", a checkpoint of the state where it stopped; resumed, it writes what the run that was never
// stopped writes. A run killed outright (kill -9) while it writes checkpoints every few steps goes on from the newest
// whole one to the same bytes.
class RestartSignals : public Restart {
protected:
    Scene scene_{"box3d_settle.toml",
                 {"insert[1].count=300", "output.series_period=0.002", "output.snapshot_period=0.02",
                  "output.checkpoint_period=0.01"},
                 0.3};
    /// Starts `haet run` of the scene into out (with `extra` overrides) as a child process.
    pid_t start(const fs::path& out, const std::vector<std::string>& extra = {}) {
        std::vector<std::string> args = {
            "run",   "-q",         std::string(HAET_SOURCE_DIR) + "/examples/" + scene_.file,
            "--out", out.string(), "--threads",
            "1",     "--set",      duration(scene_.duration)};
        for (const std::string& v : scene_.sets) args.insert(args.end(), {"--set", v});
        for (const std::string& v : extra) args.insert(args.end(), {"--set", v});
        return spawn(args);
    }
    /// Starts the scene into out, waits until series.csv has `lines` lines, sends sig, returns the exit code.
    int stopped(const fs::path& out, int sig, int lines) {
        const pid_t pid = start(out);
        for (int k = 0; k < 6000; ++k) {
            const std::string csv = read(out / "series.csv");
            if (std::count(csv.begin(), csv.end(), '\n') >= lines) break;
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        kill(pid, sig);
        return wait(pid);
    }
    /// The scene run uninterrupted, then stopped by SIGTERM (after linesTerm lines of series.csv) and by SIGINT
    /// (after linesInt) and resumed: the same bytes.
    void expectStoppedRunsResume(int linesTerm, int linesInt) {
        const fs::path full = dir_ / "full";
        Result r = run(scene_, full, 1, {duration(scene_.duration)});
        ASSERT_EQ(r.code, 0) << r.err;
        for (const int sig : {SIGTERM, SIGINT}) {
            SCOPED_TRACE(sig == SIGTERM ? "SIGTERM" : "SIGINT");
            const fs::path out = dir_ / ("stopped_" + std::to_string(sig));
            const int code = stopped(out, sig, sig == SIGTERM ? linesTerm : linesInt);
            ASSERT_EQ(code, sig == SIGTERM ? 143 : 130) << read(dir_ / "stderr.txt");
            EXPECT_EQ(jsonString(read(out / "run.json"), "status"), "interrupted");
            const auto kept = haet::listCheckpoints(out);
            ASSERT_FALSE(kept.empty());
            // The newest checkpoint is of the state where the run stopped: the time of its last row (stamped to 15
            // digits).
            const haet::CheckpointFile f = haet::parseCheckpoint(read(kept[0]));
            const std::string csv = read(out / "series.csv");
            const std::size_t last = csv.rfind('\n', csv.size() - 2) + 1;
            EXPECT_NEAR(std::stod(csv.substr(last, csv.find(',', last) - last)), f.header.time, 1e-12);  // 15 digits
            EXPECT_LT(f.header.time, scene_.duration);
            r = run(scene_, out, 1, {duration(scene_.duration)}, out.string());
            ASSERT_EQ(r.code, 0) << r.err;
            expectSameOutputs(full, out);
        }
    }
};

TEST_F(RestartSignals, StoppedRunResumesToTheSameBytes) { expectStoppedRunsResume(30, 80); }

// The event-driven engine stops after the event under way, each particle at its own clock: the checkpoint holds the
// slots so, unsynchronised, and the run goes on from them as it would have.
TEST_F(RestartSignals, StoppedEventDrivenRunResumesToTheSameBytes) {
    scene_ = {"dilute_gas3d.toml",
              {"insert[1].count=3000", "output.series_period=0.002", "output.snapshot_period=0.02",
               "output.checkpoint_period=0.01"},
              1.5};
    expectStoppedRunsResume(40, 200);
}

// The hybrid stops after the step under way, its event-driven particles each at its own clock.
TEST_F(RestartSignals, StoppedHybridRunResumesToTheSameBytes) {
    scene_ = {"haet_demo.toml",
              {"insert[1].count=250", "insert[2].count=800", "insert[2].region={lo=[0.05,0.016],hi=[0.25,0.05]}",
               "contact.duration=4e-4", "output.series_period=0.002", "output.snapshot_period=0.02",
               "output.checkpoint_period=0.01"},
              0.16};
    expectStoppedRunsResume(25, 50);
}

TEST_F(RestartSignals, KillNineLeavesAWholeCheckpointToResumeFrom) {
    const fs::path full = dir_ / "full";
    Result r = run(scene_, full, 1, {duration(scene_.duration), "output.checkpoint_period=1e-3"});
    ASSERT_EQ(r.code, 0) << r.err;
    const fs::path out = dir_ / "killed";
    // Checkpoints every 1e-3 s (every 125 steps): the kill may come while one is written.
    const pid_t pid = start(out, {"output.checkpoint_period=1e-3"});
    for (int k = 0; k < 6000 && haet::listCheckpoints(out).size() < 2; ++k)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    kill(pid, SIGKILL);
    const int code = wait(pid);
    ASSERT_EQ(code, 128 + SIGKILL);
    EXPECT_EQ(jsonString(read(out / "run.json"), "status"), "running");
    EXPECT_GE(checkSeries(out / "series.csv"), 1);
    r = run(scene_, out, 1, {duration(scene_.duration), "output.checkpoint_period=1e-3"}, out.string());
    ASSERT_EQ(r.code, 0) << r.err;
    expectSameOutputs(full, out);
}

}  // namespace
