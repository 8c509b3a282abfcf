// What `haet run` writes, and when: rows and snapshots at k x period exactly (no sum of periods or of time steps
// that drifts), each once even when a step is longer than the period, the last state always, nothing of an earlier
// run left beside a new one, and the same bits whether or not the progress line shows.
#include <cstdio>
#include <string>
#include <vector>

#include "cli_util.hpp"

namespace {

using namespace haet::testing::cli;
namespace fs = std::filesystem;

class RunOutputs : public Cli {};

/// The first cell of every data row of series.csv.
std::vector<std::string> seriesTimes(const std::string& csv) {
    std::vector<std::string> t;
    std::istringstream in(csv);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) t.push_back(line.substr(0, line.find(',')));
    return t;
}

/// The timestep attributes of a .pvd collection, in order.
std::vector<std::string> pvdTimes(const std::string& pvd) {
    std::vector<std::string> t;
    const std::regex re("timestep=\"([^\"]+)\"");
    for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), re); it != std::sregex_iterator(); ++it)
        t.push_back((*it)[1].str());
    return t;
}

/// k x period as the shortest decimal a reader expects (0.0003, not 0.00030000000000000003).
std::string decimal(double x) {
    char s[32];
    std::snprintf(s, sizeof s, "%.15g", x);
    return s;
}

// 50 000 steps of dt = 2e-6 s: summed step by step the time drifts by some 1e-15 s (the pvd once said
// 0.09999999999999393); the rows and snapshots carry k x period.
TEST_F(RunOutputs, TimesAreKTimesThePeriod) {
    const fs::path f = write("tiny.toml", kTiny);
    const fs::path out = dir_ / "run";
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() +
                          "' --set duration=0.1 --set output.series_period=0.003 --set output.snapshot_period=0.01");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<std::string> rows = seriesTimes(read(out / "series.csv"));
    ASSERT_EQ(rows.size(), 35u);  // 0, 0.003, ..., 0.099 and the end, 0.1
    for (std::size_t k = 0; k + 1 < rows.size(); ++k) EXPECT_EQ(rows[k], decimal(k * 0.003)) << "row " << k;
    EXPECT_EQ(rows.back(), "0.1");
    const std::vector<std::string> shots = pvdTimes(read(out / "particles.pvd"));
    ASSERT_EQ(shots.size(), 11u);
    for (std::size_t k = 0; k < shots.size(); ++k) EXPECT_EQ(shots[k], decimal(k * 0.01)) << "snapshot " << k;
    EXPECT_EQ(read(out / "particles_000010.vtu").find("0.09999999"), std::string::npos);
}

// A period shorter than dt: one row and one snapshot per step (as LAMMPS's thermo and dump, which count steps),
// never two at one time and never a loop at t = 0; the run says so on stderr and in run.json.
TEST_F(RunOutputs, PeriodShorterThanTheStepGivesOneOutputPerStep) {
    const fs::path f = write("tiny.toml", kTiny);
    const fs::path out = dir_ / "run";
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() +
                          "' --set duration=2e-5 --set output.series_period=1e-7 --set output.snapshot_period=3e-8");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(checkSeries(out / "series.csv"), 11);  // steps 0..10 of dt = 2e-6 s, times increasing
    EXPECT_EQ(checkPvd(out / "particles.pvd"), 11);
    for (const char* key : {"output.series_period", "output.snapshot_period"}) {
        EXPECT_NE(r.err.find(std::string("warning: ") + key), std::string::npos) << r.err;
        EXPECT_NE(read(out / "run.json").find(std::string("\"") + key + "\""), std::string::npos);
    }
}

// The state at the end is always written: a row and a snapshot at the end time when the periods do not divide the
// duration, and the one snapshot of a run with snapshot_period < 0.
TEST_F(RunOutputs, LastStateIsAlwaysWritten) {
    const fs::path f = write("tiny.toml", kTiny);
    const fs::path out = dir_ / "run";
    Result r = haet("run -q '" + f.string() + "' --out '" + out.string() +
                    "' --set output.series_period=3e-4 --set output.snapshot_period=4e-4");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(seriesTimes(read(out / "series.csv")),
              (std::vector<std::string>{"0", "0.0003", "0.0006", "0.0009", "0.001"}));
    EXPECT_EQ(pvdTimes(read(out / "particles.pvd")), (std::vector<std::string>{"0", "0.0004", "0.0008", "0.001"}));
    r = haet("run -q '" + f.string() + "' --out '" + out.string() + "' --set output.snapshot_period=-1");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(pvdTimes(read(out / "particles.pvd")), std::vector<std::string>{"0.001"});
}

// A second run into the same directory: what the first one wrote is gone (its snapshots, its run.json), the files
// HAET did not write are kept.
TEST_F(RunOutputs, RerunClearsThePreviousRunsOutputs) {
    const fs::path f = write("tiny.toml", kTiny);
    const fs::path out = dir_ / "run";
    ASSERT_EQ(haet("run -q '" + f.string() + "' --out '" + out.string() + "' --set output.snapshot_period=1e-4").code,
              0);
    ASSERT_TRUE(fs::exists(out / "particles_000010.vtu"));
    std::ofstream(out / "notes.txt") << "the user's own file\n";
    std::ofstream(out / "particles_000007.vtu.tmp.12345") << "<VTKFile";  // a temporary file of a killed run
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() +
                          "' --set duration=5e-4 --set output.snapshot_period=-1");
    ASSERT_EQ(r.code, 0) << r.err;
    int vtu = 0;
    for (const auto& e : fs::directory_iterator(out)) vtu += e.path().extension() == ".vtu";
    EXPECT_EQ(vtu, 1) << "only the new run's snapshot";
    EXPECT_FALSE(fs::exists(out / "particles_000007.vtu.tmp.12345"));
    EXPECT_TRUE(fs::exists(out / "notes.txt"));
    EXPECT_NE(read(out / "run.json").find("\"simulated_time\": 0.0005"), std::string::npos) << read(out / "run.json");
}

// Periods that ask for more outputs than a run can keep, and a time step longer than the run: exit 2 with the key.
TEST_F(RunOutputs, AbsurdPeriodsAndStepsAreBadInput) {
    expectBadInput(edit("series_period = 1e-4", "series_period = 1e-12"), "series_period", "output.series_period");
    expectBadInput(edit("snapshot_period = 5e-4", "snapshot_period = 1e-10"), "snapshot_period",
                   "output.snapshot_period");
    expectBadInput(edit("[output]", "[tdm]\ndt = 0.01\n\n[output]"), "dt = 0.01", "tdm.dt");
}

// The engine is called in the same pieces whether or not the progress line shows: series.csv is the same bytes with
// the line forced on as without it, for each method (an event-driven run once differed: row times
// 0.0029999999999999983 instead of 0.003).
TEST_F(RunOutputs, ProgressLineDoesNotChangeTheResults) {
    const std::string scenes[][2] = {
        {"dilute_gas3d.toml", "--set duration=0.02 --set 'insert[1].count=400' --set output.series_period=0.001"},
        {"haet_demo.toml", "--set duration=0.004 --set output.series_period=2e-4"},
        {"drop3d_tiny.toml", "--set duration=0.004 --set output.series_period=1.5e-4"}};
    for (const auto& [scene, sets] : scenes) {
        const std::string f = std::string(HAET_SOURCE_DIR) + "/examples/" + scene;
        const Result a = haet("run -q '" + f + "' --out '" + (dir_ / "off").string() + "' " + sets);
        ASSERT_EQ(a.code, 0) << scene << a.err;
        const Result b = haet("run --progress '" + f + "' --out '" + (dir_ / "on").string() + "' " + sets);
        ASSERT_EQ(b.code, 0) << scene << b.err;
        EXPECT_NE(b.err.find("ETA"), std::string::npos) << "the progress line showed: " << b.err;
        EXPECT_GE(checkSeries(dir_ / "off" / "series.csv"), 20) << scene;
        EXPECT_EQ(read(dir_ / "off" / "series.csv"), read(dir_ / "on" / "series.csv")) << scene;
    }
}

}  // namespace
