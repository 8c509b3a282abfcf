// Checkpoints and `haet run --resume` (docs/scenario.md, "Resuming"): a run of duration T and the same run stopped at
// a checkpoint and resumed write the same bytes (series.csv, the snapshots, their collections), for each engine and
// kind of scene, on one and two threads; a checkpoint that is truncated, corrupt, of a later format or of another
// scenario is refused with exit code 2 and a message that says which, and a corrupt newest one gives way to the one
// before it. The runs are of the `haet` program, on scenes of examples/ shortened by overrides.
#include <cmath>
#include <csignal>
#include <limits>
#include <regex>
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

    /// Every output a resumed run must reproduce: series.csv, the collections and every snapshot file, by name.
    static std::vector<std::pair<std::string, std::string>> outputs(const fs::path& dir) {
        std::vector<std::pair<std::string, std::string>> files;
        static const std::regex re(R"(series\.csv|.*\.pvd|.*_[0-9]{6}\.(vtu|vtp|vti))");
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

// Event-driven: a gas in a periodic box (cell crossings, collisions, the TC model's clocks, the re-sorting of the
// slots), and a 2D gas in a closed box (plane walls).
const Scene kGas{
    "dilute_gas3d.toml", {"insert[1].count=300", "output.series_period=0.002", "output.snapshot_period=0.01"}, 0.05};
const Scene kGas2d{"gas2d.toml", {"method=edm", "output.series_period=0.002", "output.snapshot_period=0.01"}, 0.05};

TEST_F(Restart, EdmResumesBitForBit) {
    expectResumeIdentical(kGas, 1, false);
    expectResumeIdentical(kGas2d, 1, false);
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
