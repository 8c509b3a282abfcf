// Long validation of the hybrid (`ctest -L validate`): on the demo geometry at reduced size (a thin bed under a
// falling cloud, 2D), HAET and pure TDM agree on the macroscopic results within their run-to-run spread, measured
// over several seeds: total kinetic energy over time, the number of grains come to rest (the mass flow onto the
// heap), and the height of the centre of mass.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "haet/engine.hpp"
#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"

namespace haet {
namespace {

constexpr int kSamples = 15;         // every 0.02 s up to 0.3 s
constexpr double kEvery = 0.02;      // [s]
constexpr double kRestSpeed = 0.05;  // [m/s]: a grain slower than this has landed

std::string scene(int seed) {
    return "name = 'rain'\ndimension = 2\nduration = 0.3\nseed = " + std::to_string(seed) +
           "\n[domain]\nlo = [0.0, 0.0]\nhi = [0.1, 0.5]\ngravity = [0.0, -9.81]\n"
           "[materials.sand]\ndensity = 2.0\nrestitution = 0.6\nfriction = 0.5\n"
           "[contact]\nnormal = 'linear'\nduration = 2e-4\ntangential = 'spring'\n"
           "[tdm]\nintegrator = 'verlet'\n"
           "[[walls]]\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]\nmaterial = 'sand'\n"
           "[[walls]]\npoint = [0.0, 0.0]\nnormal = [1.0, 0.0]\nmaterial = 'sand'\n"
           "[[walls]]\npoint = [0.1, 0.0]\nnormal = [-1.0, 0.0]\nmaterial = 'sand'\n"
           "[[insert]]\narrangement = 'lattice'\ncount = 160\nspacing = 0.00245\nradius = [0.0008, 0.0012]\n"
           "material = 'sand'\nregion = { lo = [0.0, 0.0], hi = [0.1, 0.015] }\n"
           "[[insert]]\narrangement = 'random'\ncount = 1500\nradius = [0.0008, 0.0012]\nmaterial = 'sand'\n"
           "region = { lo = [0.02, 0.06], hi = [0.08, 0.45] }\ntemperature = 1e-4\n";
}

struct Sample {
    double kinetic = 0, rested = 0, height = 0;
};

Sample measure(const Particles<2>& p) {
    Sample s;
    double m = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        s.kinetic += 0.5 * p.mass[i] * norm2(p.v[i]) + 0.5 * p.inertia(i) * norm2(p.w[i]);
        if (norm(p.v[i]) < kRestSpeed) s.rested += 1;
        s.height += p.mass[i] * p.x[i][1];
        m += p.mass[i];
    }
    s.height /= m;
    return s;
}

std::vector<Sample> run(int seed, bool hybrid, double* cpuSeconds) {
    const Scenario sc = parseScenario(scene(seed), "rain.toml");
    World<2> w = buildWorld<2>(sc);
    const TdmSettings ts = tdmSettings<2>(sc, w);
    std::vector<Sample> out;
    const std::clock_t c0 = std::clock();
    if (hybrid) {
        HaetSettings hs;
        hs.zones.phiOn = 0.45;
        hs.zones.phiOff = 0.40;
        HaetEngine<2> h(w, ts, EdmSettings{}, hs);
        for (int k = 1; k <= kSamples; ++k) {
            h.advanceTo(k * kEvery);
            h.synchronise();
            out.push_back(measure(w.particles));
        }
    } else {
        TdmEngine<2> t(w, ts);
        for (int k = 1; k <= kSamples; ++k) {
            t.advanceTo(k * kEvery);
            out.push_back(measure(w.particles));
        }
    }
    *cpuSeconds += double(std::clock() - c0) / CLOCKS_PER_SEC;
    return out;
}

struct Stats {
    double mean = 0, sd = 0;
};

Stats stats(const std::vector<double>& v) {
    Stats s;
    for (double x : v) s.mean += x;
    s.mean /= double(v.size());
    for (double x : v) s.sd += (x - s.mean) * (x - s.mean);
    s.sd = std::sqrt(s.sd / double(v.size() - 1));
    return s;
}

TEST(HaetValidate, DemoGeometryAgreesWithTdmWithinSeedSpread) {
    const std::vector<int> seeds = {1, 2, 3, 4, 5};
    std::vector<std::vector<Sample>> tdm, haet;
    double cpuTdm = 0, cpuHaet = 0;
    for (int s : seeds) {
        tdm.push_back(run(s, false, &cpuTdm));
        haet.push_back(run(s, true, &cpuHaet));
    }
    const double n = double(seeds.size());
    int checked = 0;
    for (int k = 0; k < kSamples; ++k) {
        auto compare = [&](const char* what, double Sample::*field, double floor) {
            std::vector<double> a, b;
            for (std::size_t r = 0; r < seeds.size(); ++r) {
                a.push_back(tdm[r][k].*field);
                b.push_back(haet[r][k].*field);
            }
            const Stats st = stats(a), sh = stats(b);
            // Difference of the means against three standard errors of that difference (plus a floor for the
            // early samples, when every run is still in free fall and the spread is round-off).
            const double tol = 3 * std::sqrt((st.sd * st.sd + sh.sd * sh.sd) / n) + floor;
            EXPECT_LE(std::abs(sh.mean - st.mean), tol)
                << what << " at t = " << (k + 1) * kEvery << " s: TDM " << st.mean << " +- " << st.sd << ", HAET "
                << sh.mean << " +- " << sh.sd;
            ++checked;
            char buf[160];
            std::snprintf(buf, sizeof buf, "%s t=%.2f TDM %.5g+-%.2g HAET %.5g+-%.2g", what, (k + 1) * kEvery, st.mean,
                          st.sd, sh.mean, sh.sd);
            std::printf("%s\n", buf);
        };
        compare("kinetic energy [J]", &Sample::kinetic, 0.01 * tdm[0][k].kinetic);
        compare("grains at rest", &Sample::rested, 5);
        compare("centre of mass height [m]", &Sample::height, 1e-4);
    }
    EXPECT_EQ(checked, 3 * kSamples);
    std::printf("CPU: TDM %.1f s, HAET %.1f s for %zu seeds (ratio %.2f)\n", cpuTdm, cpuHaet, seeds.size(),
                cpuTdm / cpuHaet);
    ::testing::Test::RecordProperty("cpu_ratio", std::to_string(cpuTdm / cpuHaet));
}

}  // namespace
}  // namespace haet
