// Long checks of a discharging silo (examples/silo2d_reduced.toml, docs/physics.md K.4): the discharge rate of a
// granular silo is steady and does not depend on the fill height while the fill is more than about twice the silo's
// width (Janssen screening of the weight by the walls; Beverloo, Leniger & van de Velde, Chem. Eng. Sci. 15 (1961)
// 260), unlike a liquid's sqrt(h); and the hybrid discharges at the time-driven method's rate.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../csv_util.hpp"
#include "../physics_util.hpp"
#include "run/runner.hpp"
#include "scenario/loader.hpp"

namespace haet {
namespace {

namespace fs = std::filesystem;

/// The scene's numbers, as examples/silo2d_reduced.toml has them.
constexpr double kWidth = 0.06;  // silo width [m]
constexpr double kMeanArea =
    3.141592653589793 * (1.5e-3 * 1.5e-3 + 0.4e-3 * 0.4e-3 / 12);  // pi <r^2>, r in [1.3, 1.7] mm
/// Below this many grains the fill may be lower than two widths: a disk packing is never denser than 0.907.
const double kTwoWidthsCount = 2 * kWidth * kWidth * 0.907 / kMeanArea;

struct Series {
    std::vector<double> time, present, drained, tdm;
};

Series runSilo(const std::string& method, int seed, double duration) {
    const Scenario sc = testing::exampleScenario("silo2d_reduced.toml",
                                                 {"method=" + method, "seed=" + std::to_string(seed),
                                                  "duration=" + std::to_string(duration), "output.snapshot_period=-1"});
    RunOptions o;
    o.outDir = fs::temp_directory_path() /
               ("haet_silo_" + std::to_string(::getpid()) + "_" + method + "_" + std::to_string(seed));
    o.quiet = true;
    std::ostringstream log;
    EXPECT_EQ(runScenario(sc, o, log), RunStatus::Completed) << log.str();
    Series s;
    const testing::CsvTable csv = testing::readCsv(o.outDir / "series.csv");
    const bool hybrid = std::find(csv.header.begin(), csv.header.end(), "n_tdm") != csv.header.end();
    s.time = csv.column("time");
    s.present = csv.column("n_particles");
    s.drained = csv.column("drain_particles");
    s.tdm = hybrid ? csv.column("n_tdm") : s.present;
    fs::remove_all(o.outDir);
    return s;
}

/// Mean discharge rate [grains/s] over [t0, t1) and its standard error, from the rates of blocks of `block` s (the
/// blocks' scatter measures the flow's intermittency, which is not Poisson).
struct Rate {
    double mean = 0, error = 0;
};
Rate rateOver(const Series& s, double t0, double t1, double block) {
    auto drainedAt = [&](double t) {  // rows are at multiples of the series period
        const auto it = std::lower_bound(s.time.begin(), s.time.end(), t - 1e-9);
        EXPECT_NE(it, s.time.end()) << "no row at t = " << t;
        return s.drained[std::size_t(it - s.time.begin())];
    };
    std::vector<double> rates;
    for (double a = t0; a + block <= t1 + 1e-9; a += block)
        rates.push_back((drainedAt(a + block) - drainedAt(a)) / block);
    const testing::SampleStats st = testing::sampleStats(rates);
    Rate r;
    r.mean = st.mean;
    r.error = st.sd / std::sqrt(double(rates.size()));
    return r;
}

/// The runs, made once for both tests: the time-driven ones to 2.2 s (the fill-height test), the hybrid's to 1.3 s.
const Series& silo(const std::string& method, int seed) {
    static std::map<std::pair<std::string, int>, Series> runs;
    const auto key = std::make_pair(method, seed);
    if (!runs.count(key)) runs[key] = runSilo(method, seed, method == "tdm" ? 2.2 : 1.3);
    return runs[key];
}

constexpr int kSeeds = 3;

TEST(SiloValidate, DischargeRateDoesNotDependOnTheFillHeight) {
    // Per seed: from the flow's start (the fill settled, the arch above the orifice formed) to the last row at which
    // the fill is still more than two widths high, split in two halves; the halves' rates pooled over the seeds.
    const double t0 = 0.3, block = 0.1;
    double r1 = 0, r2 = 0, var1 = 0, var2 = 0, h1 = 0, h2 = 0;
    for (int seed = 1; seed <= kSeeds; ++seed) {
        const Series& s = silo("tdm", seed);
        double t1 = t0;
        for (std::size_t r = 0; r < s.time.size(); ++r)
            if (s.present[r] > kTwoWidthsCount) t1 = s.time[r];
        const double half = std::floor((t1 - t0) / 2 / block) * block;
        ASSERT_GE(half, 0.5) << "seed " << seed << ": the fill must stay above two widths for a second (t1 = " << t1
                             << " s)";
        const Rate a = rateOver(s, t0, t0 + half, block), b = rateOver(s, t0 + half, t0 + 2 * half, block);
        r1 += a.mean / kSeeds;
        r2 += b.mean / kSeeds;
        var1 += a.error * a.error / (kSeeds * kSeeds);
        var2 += b.error * b.error / (kSeeds * kSeeds);
        // The mean fill of each half, as grains present (the height is proportional to them).
        auto meanPresent = [&](double from, double to) {
            double sum = 0;
            int n = 0;
            for (std::size_t r = 0; r < s.time.size(); ++r)
                if (s.time[r] >= from - 1e-9 && s.time[r] < to - 1e-9) sum += s.present[r], ++n;
            return sum / n;
        };
        h1 += meanPresent(t0, t0 + half) / kSeeds;
        h2 += meanPresent(t0 + half, t0 + 2 * half) / kSeeds;
    }
    const double spread = std::sqrt(var1 + var2);
    EXPECT_GT(r1, 300) << "the silo must flow";
    EXPECT_NEAR(r2, r1, 3 * spread) << "first half " << r1 << " +- " << std::sqrt(var1) << " grains/s, second " << r2
                                    << " +- " << std::sqrt(var2);
    // The check can tell a liquid from a granular silo: a rate following sqrt(h) (Torricelli) would fall between the
    // halves by more than three standard errors.
    EXPECT_GT(r1 * (1 - std::sqrt(h2 / h1)), 3 * spread)
        << "too noisy to tell: mean fills " << h1 << " and " << h2 << " grains, spread " << spread << " grains/s";
}

TEST(SiloValidate, HybridDischargesAtTheTimeDrivenRate) {
    // Several seeds each: the run-to-run spread of the mean rate over [0.3, 1.3) s is the yardstick.
    std::vector<double> tdm, haet;
    double edmShare = 0;
    for (int seed = 1; seed <= kSeeds; ++seed) {
        tdm.push_back(rateOver(silo("tdm", seed), 0.3, 1.3, 0.1).mean);
        const Series& h = silo("haet", seed);
        haet.push_back(rateOver(h, 0.3, 1.3, 0.1).mean);
        double nt = 0, n = 0;
        for (std::size_t r = 0; r < h.time.size(); ++r)
            if (h.time[r] >= 0.3) nt += h.tdm[r], n += h.present[r];
        edmShare += (1 - nt / n) / kSeeds;
    }
    auto mean = [](const std::vector<double>& v) { return testing::sampleStats(v).mean; };
    auto sd = [](const std::vector<double>& v) { return testing::sampleStats(v).sd; };
    const double spread = std::hypot(sd(tdm), sd(haet)) / std::sqrt(3.0);
    EXPECT_GT(edmShare, 0.03) << "the jet must be event-driven in the hybrid";
    EXPECT_NEAR(mean(haet), mean(tdm), std::max(3 * spread, 0.02 * mean(tdm)))
        << "TDM " << mean(tdm) << " +- " << sd(tdm) << ", HAET " << mean(haet) << " +- " << sd(haet) << " grains/s";
}

}  // namespace
}  // namespace haet
