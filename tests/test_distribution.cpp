// Size distributions of inserts and inlets (docs/scenario.md, "Size distributions"): the radii inserted follow the
// requested distribution (Kolmogorov-Smirnov at 1 %), sieve tables by mass give their mass fractions, the summary
// `haet check` prints, and bad input stops with file:line: key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "run/runner.hpp"
#include "scenario/distribution.hpp"
#include "scenario/loader.hpp"
#include "scenario_text.hpp"
#include "world/build.hpp"

namespace haet {
namespace {

using testing::lineOf;
using testing::replaced;
using testing::sceneText;

const std::string kSieve =
    "distribution = { kind = \"discrete\", radii = [0.0004, 0.0006, 0.0008], fractions = [0.2, 0.3, 0.5], basis = "
    "\"mass\" }";

/// The scene examples/sizes3d.toml with its distribution replaced by `dist` and `count` particles.
Scenario sieveScene(const std::string& dist, int count) {
    const std::string text = replaced(sceneText("sizes3d.toml"), kSieve, dist);
    return parseScenario(text, "sizes3d.toml", {"insert[1].count=" + std::to_string(count)});
}

std::vector<double> insertedRadii(const Scenario& sc) {
    const World<3> w = buildWorld<3>(sc);
    return w.particles.radius;
}

/// Kolmogorov-Smirnov statistic of a sample against a CDF: the largest gap between the empirical and the
/// requested distribution functions, on either side of each step.
double ksStatistic(std::vector<double> x, const SizeDistribution& d) {
    std::sort(x.begin(), x.end());
    const double n = double(x.size());
    double worst = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        // Ties (discrete sizes): the empirical CDF jumps once, at the last of equal values.
        if (i + 1 < x.size() && x[i + 1] == x[i]) continue;
        const double f = d.cdf(x[i]);
        std::size_t first = i;
        while (first > 0 && x[first - 1] == x[i]) --first;
        const double below = std::nextafter(x[i], 0.0);
        worst = std::max({worst, std::abs(double(i + 1) / n - f), std::abs(double(first) / n - d.cdf(below))});
    }
    return worst;
}

/// The 1 % critical value of the KS statistic, sqrt(-ln(0.005) / 2) / sqrt(n) (the asymptotic Kolmogorov
/// distribution; n is in the thousands here).
double ksCritical(std::size_t n) { return std::sqrt(-0.5 * std::log(0.005)) / std::sqrt(double(n)); }

void expectKs(const std::string& dist, const SizeDistribution& requested) {
    const Scenario sc = sieveScene(dist, 2500);
    const std::vector<double> r = insertedRadii(sc);
    ASSERT_EQ(r.size(), 2500u);
    const double ks = ksStatistic(r, sc.inserts[0].size);
    EXPECT_LT(ks, ksCritical(r.size())) << dist;
    // The loader built the distribution that was asked for.
    for (const double q : {0.1, 0.3, 0.5, 0.7, 0.9}) {
        const double x = requested.min + q * (requested.max - requested.min);
        EXPECT_NEAR(sc.inserts[0].size.cdf(x), requested.cdf(x), 1e-12) << dist;
    }
}

TEST(SizeDistribution, UniformRadiiPassKolmogorovSmirnov) {
    expectKs("distribution = { kind = \"uniform\", range = [0.0004, 0.0008] }", uniformSizes(0.0004, 0.0008));
}

TEST(SizeDistribution, NormalRadiiPassKolmogorovSmirnov) {
    expectKs("distribution = { kind = \"normal\", mean = 0.0006, sigma = 0.0001, range = [0.0004, 0.00075] }",
             normalSizes(0.0006, 0.0001, 0.0004, 0.00075));
}

TEST(SizeDistribution, LogNormalRadiiPassKolmogorovSmirnovAndOthersFail) {
    const std::string dist =
        "distribution = { kind = \"lognormal\", median = 0.0005, sigma = 0.3, range = [0.0003, 0.0009] }";
    const SizeDistribution want = logNormalSizes(0.0005, 0.3, 0.0003, 0.0009);
    expectKs(dist, want);
    // The test has the power to see a wrong distribution: the same radii fail against the uniform one on the
    // range, and against the log-normal of another width.
    const std::vector<double> r = insertedRadii(sieveScene(dist, 2500));
    EXPECT_GT(ksStatistic(r, uniformSizes(0.0003, 0.0009)), ksCritical(r.size()));
    EXPECT_GT(ksStatistic(r, logNormalSizes(0.0005, 0.4, 0.0003, 0.0009)), ksCritical(r.size()));
}

TEST(SizeDistribution, DiscreteByNumberPassesKolmogorovSmirnov) {
    expectKs(
        "distribution = { kind = \"discrete\", radii = [0.0004, 0.0006, 0.0008], fractions = [0.5, 0.3, 0.2], "
        "basis = \"number\" }",
        discreteSizes({0.0004, 0.0006, 0.0008}, {0.5, 0.3, 0.2}, false, 3));
}

TEST(SizeDistribution, SieveTableGivesItsMassFractions) {
    // The scene's own table: mass fractions 0.2, 0.3, 0.5 of radii 0.4, 0.6, 0.8 mm.
    const Scenario sc = parseScenario(sceneText("sizes3d.toml"), "sizes3d.toml", {"insert[1].count=15000"});
    const World<3> w = buildWorld<3>(sc);
    const std::vector<double> radii{0.0004, 0.0006, 0.0008}, want{0.2, 0.3, 0.5};
    std::vector<double> mass(3, 0), count(3, 0);
    double total = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i) {
        const auto k = std::size_t(std::find(radii.begin(), radii.end(), w.particles.radius[i]) - radii.begin());
        ASSERT_LT(k, 3u) << w.particles.radius[i];
        mass[k] += w.particles.mass[i];
        count[k] += 1;
        total += w.particles.mass[i];
    }
    for (std::size_t k = 0; k < 3; ++k) {
        // Size k's share of the mass; its spread from the multinomial counts is below 0.01 here.
        EXPECT_NEAR(mass[k] / total, want[k], 0.025) << "size " << k;
    }
    // By number the small ones dominate: p_k ~ f_k / r_k^3, 0.569 / 0.253 / 0.178.
    EXPECT_NEAR(count[0] / double(w.particles.size()), 0.569, 0.02);
    // The summary agrees: mean diameter by mass > by number; the two smaller sizes hold half the mass, so d50 by
    // mass is the middle one.
    const SizeSummary m = summarize(sc.inserts[0].size, 3);
    EXPECT_GT(m.meanByMass, m.meanByNumber);
    EXPECT_DOUBLE_EQ(m.d50ByNumber, 0.0008);
    EXPECT_DOUBLE_EQ(m.d50ByMass, 0.0012);
}

TEST(SizeDistribution, SummaryOfUniformMatchesClosedForm) {
    // Uniform radius in [a, b]: mean diameter a + b; d50 by number a + b; by mass (3D) the median of r^3 dr.
    const double a = 1e-3, b = 3e-3;
    const SizeSummary m = summarize(uniformSizes(a, b), 3);
    EXPECT_NEAR(m.meanByNumber, a + b, 1e-12);
    EXPECT_NEAR(m.d50ByNumber, a + b, 1e-9);
    // By mass: mean of r weighted by r^3 is (4/5)(b^5 - a^5)/(b^4 - a^4); median solves r^4 = (a^4 + b^4)/2.
    EXPECT_NEAR(m.meanByMass, 2 * 0.8 * (std::pow(b, 5) - std::pow(a, 5)) / (std::pow(b, 4) - std::pow(a, 4)), 1e-9);
    EXPECT_NEAR(m.d50ByMass, 2 * std::pow(0.5 * (std::pow(a, 4) + std::pow(b, 4)), 0.25), 1e-8);
}

TEST(SizeDistribution, UniformDrawsAreThoseOfARadiusRange) {
    // `radius = [min, max]` and a uniform distribution draw the same radii as inserts always have: the same bits.
    const std::string text = sceneText("sizes3d.toml");
    const Scenario a = parseScenario(replaced(text, kSieve, "radius = [0.0004, 0.0008]"), "a.toml");
    const Scenario b = parseScenario(
        replaced(text, kSieve, "distribution = { kind = \"uniform\", range = [0.0004, 0.0008] }"), "b.toml");
    const World<3> wa = buildWorld<3>(a), wb = buildWorld<3>(b);
    ASSERT_EQ(wa.particles.size(), wb.particles.size());
    for (std::size_t i = 0; i < wa.particles.size(); ++i) {
        EXPECT_EQ(wa.particles.radius[i], wb.particles.radius[i]);
        EXPECT_EQ(wa.particles.x[i][2], wb.particles.x[i][2]);
    }
}

TEST(SizeDistribution, CheckPrintsMeanAndD50) {
    std::ostringstream out;
    describeScenario(parseScenario(sceneText("sizes3d.toml"), "sizes3d.toml"), out);
    const std::string s = out.str();
    EXPECT_NE(s.find("sizes      insert[1]: discrete: 3 radii"), std::string::npos) << s;
    EXPECT_NE(s.find("d50 0.0008 m by number, 0.0012 m by mass"), std::string::npos) << s;
}

/// The file:line: key of a bad distribution.
void expectBad(const std::string& dist, const std::string& key, const std::string& what,
               const std::string& needle = "distribution = {") {
    const std::string text = replaced(sceneText("sizes3d.toml"), kSieve, dist);
    try {
        parseScenario(text, "bad.toml");
        ADD_FAILURE() << "no error for " << dist;
    } catch (const ScenarioError& e) {
        EXPECT_EQ(e.key(), key) << e.what();
        EXPECT_EQ(e.pos().line, lineOf(text, needle)) << e.what();
        EXPECT_NE(
            std::string(e.what()).find("bad.toml:" + std::to_string(lineOf(text, needle)) + ": " + key + ": " + what),
            std::string::npos)
            << e.what();
    }
}

TEST(SizeDistribution, BadInputNamesFileLineAndKey) {
    const std::string k = "insert[1].distribution.";
    expectBad("distribution = { kind = \"discrete\", radii = [0.0004, 0.0006], fractions = [0.5, 0.4] }",
              k + "fractions", "must sum to 1");
    expectBad("distribution = { kind = \"discrete\", radii = [-0.0004, 0.0006], fractions = [0.5, 0.5] }", k + "radii",
              "every radius must be > 0");
    expectBad("distribution = { kind = \"uniform\", range = [0.0008, 0.0004] }", k + "range",
              "must satisfy min <= max");
    expectBad("distribution = { kind = \"normal\", mean = 0.0006, sigma = 0, range = [0.0004, 0.0008] }", k + "sigma",
              "must be > 0");
    expectBad("distribution = { kind = \"lognormal\", median = 0.0006, sigma = -1, range = [0.0004, 0.0008] }",
              k + "sigma", "must be > 0");
    expectBad("distribution = { kind = \"normal\", mean = 0.0006, sigma = 0.0001, range = [0.0009, 0.0004] }",
              k + "range", "must satisfy min < max");
    expectBad("distribution = { kind = \"gamma\" }", k + "kind", "must be one of");
    expectBad("radius = 0.001\n" + kSieve, "insert[1].radius", "not together with distribution", "radius = 0.001");
}

}  // namespace
}  // namespace haet
