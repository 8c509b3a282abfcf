// How a run ends when it is stopped: SIGINT and SIGTERM finish the step, write the series so far, a last snapshot and
// run.json ("interrupted") and exit with 130 / 143; a kill -9 at any moment leaves every file whole and parseable; an
// output that cannot be written stops the run with exit code 4 and a message naming the path, nothing corrupt left.
// The signals are sent to a child `haet run`.
#include <csignal>
#include <string>
#include <thread>
#include <vector>

#include "cli_util.hpp"

namespace {

using namespace haet::testing::cli;
namespace fs = std::filesystem;

class RunStops : public Cli {
protected:
    /// Lines in series.csv (header included); 0 while it does not exist.
    int seriesLines(const fs::path& out) {
        const std::string s = read(out / "series.csv");
        return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
    }
    /// Waits (at most 30 s) until the run in `out` has written `lines` lines of series.csv.
    void waitForRows(const fs::path& out, int lines) {
        for (int k = 0; k < 3000 && seriesLines(out) < lines; ++k)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        ASSERT_GE(seriesLines(out), lines) << "the run did not start writing";
    }
    /// Starts a run of examples/SCENE (with overrides) long enough to be stopped.
    pid_t start(const std::string& scene, const std::vector<std::string>& sets, const fs::path& out,
                const std::vector<std::string>& env = {}) {
        std::vector<std::string> args = {"run", "-q", std::string(HAET_SOURCE_DIR) + "/examples/" + scene, "--out",
                                         out.string()};
        for (const std::string& s : sets) args.insert(args.end(), {"--set", s});
        return spawn(args, env);
    }
};

/// The last cell of the first column of series.csv.
std::string lastTime(const std::string& csv) {
    const std::size_t end = csv.find_last_not_of('\n');
    const std::size_t begin = csv.rfind('\n', end) + 1;
    return csv.substr(begin, csv.find(',', begin) - begin);
}

// Each method, each signal: the exit code, run.json, and a last row and snapshot at the time the run stopped.
TEST_F(RunStops, SignalsWriteTheLastStateAndExit130Or143) {
    const std::vector<std::pair<std::string, std::vector<std::string>>> runs = {
        {"drop3d_tiny.toml", {"duration=100", "output.series_period=2e-4", "output.snapshot_period=1e-3"}},
        {"dilute_gas3d.toml",
         {"duration=400", "insert[1].count=300", "output.series_period=1e-3", "output.snapshot_period=5e-3"}},
        {"haet_demo.toml", {"duration=100", "output.series_period=2e-4", "output.snapshot_period=1e-3"}}};
    for (const auto& [scene, sets] : runs)
        for (const int sig : {SIGTERM, SIGINT}) {
            SCOPED_TRACE(scene + (sig == SIGTERM ? " SIGTERM" : " SIGINT"));
            // A directory per run: an earlier run's series.csv would end the wait before this run handles signals.
            const fs::path out = dir_ / (scene + "_" + std::to_string(sig));
            const pid_t pid = start(scene, sets, out);
            waitForRows(out, 4);
            kill(pid, sig);
            EXPECT_EQ(wait(pid), sig == SIGTERM ? 143 : 130) << read(dir_ / "stderr.txt");
            const std::string json = read(out / "run.json");
            EXPECT_TRUE(JsonCheck(json).valid()) << json;
            EXPECT_EQ(jsonString(json, "status"), "interrupted");
            const int rows = checkSeries(out / "series.csv");
            EXPECT_GE(rows, 3);
            const int shots = checkPvd(out / "particles.pvd");
            EXPECT_GE(shots, 1);
            // The last snapshot is the state at the stop, the time of the series' last row.
            const std::string pvd = read(out / "particles.pvd");
            const std::size_t at = pvd.rfind("timestep=\"") + 10;
            EXPECT_EQ(pvd.substr(at, pvd.find('"', at) - at), lastTime(read(out / "series.csv")));
            EXPECT_NE(read(dir_ / "stderr.txt").find("writing the last state"), std::string::npos);
        }
}

// kill -9 at several moments of a run that writes a row every step: every file there is whole.
TEST_F(RunStops, KillNineLeavesEveryFileParseable) {
    for (const int delayMs : {150, 400, 700}) {
        const fs::path out = dir_ / ("run_" + std::to_string(delayMs));
        const pid_t pid =
            start("drop3d_tiny.toml", {"duration=1", "output.series_period=2e-6", "output.snapshot_period=2e-5"}, out);
        waitForRows(out, 2);
        std::this_thread::sleep_for(std::chrono::milliseconds(delayMs));
        kill(pid, SIGKILL);
        EXPECT_EQ(wait(pid), 128 + SIGKILL);
        const std::string json = read(out / "run.json");
        EXPECT_TRUE(JsonCheck(json).valid()) << json;
        EXPECT_EQ(jsonString(json, "status"), "running");
        EXPECT_GE(checkSeries(out / "series.csv"), 1);
        checkPvd(out / "particles.pvd");
        checkPvd(out / "walls.pvd", ".vtp");
    }
}

// An output directory that cannot be made: exit 4 before any work, the path named.
TEST_F(RunStops, UnwritableDirectoryIsExitFour) {
    const fs::path f = write("tiny.toml", kTiny);
    write("plain_file", "not a directory\n");
    const fs::path out = dir_ / "plain_file" / "run";
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 4) << r.err;
    EXPECT_NE(r.err.find(out.string()), std::string::npos) << r.err;
}

// A full disk, as a file size limit (ulimit -f; SIGXFSZ ignored so that the write fails with EFBIG): series.csv
// cannot grow past 64 KiB. The run stops with exit code 4 naming the file; series.csv holds its last whole version
// and run.json says why.
TEST_F(RunStops, DiskFullIsExitFourAndLeavesWholeFiles) {
    const fs::path f = write("tiny.toml", kTiny);
    const fs::path out = dir_ / "run";
    const std::string cmd = "ulimit -f 64; trap '' XFSZ; exec '" + std::string(HAET_BINARY) + "' run -q '" +
                            f.string() + "' --out '" + out.string() +
                            "' --set output.series_period=2e-6 --set output.snapshot_period=2e-5";
    const int status = std::system(("bash -c \"" + cmd + "\" 2> '" + (dir_ / "err.txt").string() + "'").c_str());
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    const std::string err = read(dir_ / "err.txt");
    EXPECT_EQ(code, 4) << err;
    EXPECT_NE(err.find((out / "series.csv").string()), std::string::npos) << err;
    EXPECT_GE(checkSeries(out / "series.csv"), 10);
    EXPECT_LE(fs::file_size(out / "series.csv"), 64u * 1024);
    const std::string json = read(out / "run.json");
    EXPECT_TRUE(JsonCheck(json).valid()) << json;
    EXPECT_EQ(jsonString(json, "status").rfind("failed: output:", 0), 0u) << json;
    checkPvd(out / "particles.pvd");
}

// OpenMP's waiting threads sleep unless the user says otherwise: `haet run` sets OMP_WAIT_POLICY=passive for itself
// before the OpenMP runtime reads it (spinning threads made the hybrid demo 6 times slower on a loaded machine).
TEST_F(RunStops, OpenMpThreadsWaitPassively) {
    for (const std::string& env : {std::string("OMP_WAIT_POLICY"), std::string("OMP_WAIT_POLICY=active")}) {
        const fs::path out = dir_ / (env.size() > 15 ? "given" : "unset");
        const pid_t pid = start("drop3d_tiny.toml",
                                {"duration=100", "output.series_period=1e-3", "output.snapshot_period=-1"}, out, {env});
        waitForRows(out, 3);
        const std::string environ = read("/proc/" + std::to_string(pid) + "/environ");
        const std::string comm = read("/proc/" + std::to_string(pid) + "/comm");  // the name ps and pkill see
        kill(pid, SIGTERM);
        EXPECT_EQ(comm, "haet\n") << env;
        EXPECT_EQ(wait(pid), 143);
        const std::string expect = env.size() > 15 ? "OMP_WAIT_POLICY=active" : "OMP_WAIT_POLICY=passive";
        EXPECT_NE(environ.find(expect + '\0'), std::string::npos) << env;
    }
}

}  // namespace
