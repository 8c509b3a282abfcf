// The hybrid engine (docs/physics.md A, docs/haet.md): one physics in both modes, no particle lost or duplicated when
// modes change, energy and momentum bookkeeping that closes, and pure EDM / pure TDM where the flow is uniformly
// dilute / dense.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "edm/engine.hpp"
#include "haet/engine.hpp"
#include "physics_util.hpp"
#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world_util.hpp"

namespace haet {
namespace {

std::size_t indexOf(const std::vector<std::uint64_t>& ids, std::uint64_t id) {
    return static_cast<std::size_t>(std::find(ids.begin(), ids.end(), id) - ids.begin());
}

// ---- one binary collision, three ways ------------------------------------------------------------------------
// Same set-up as tests/test_edm_consistency.cpp: e = 0.9, t_c = 10 us, mu = 0.5, two particles built in code.

constexpr double kTc = 1e-5, kA = 0.01, kVn = 0.1;

template <int D>
World<D> pairWorld(double ratio) {
    Scenario sc = testing::linearScenario(D, 0.9, kTc, 0.5, TangentialLaw::Spring);
    sc.materials[0].tangentialRestitution = 0.99787;
    World<D> w;
    w.domain = testing::openBox<D>(0.2);
    Vec<D> n = Vec<D>::zero(), t = Vec<D>::zero();
    n[D - 1] = 1;
    t[0] = 1;
    const double gap = kVn * (kTc / 50) * 5.1;
    const Vec<D> v0 = n * (-kVn) + t * (ratio * kVn);
    w.particles.add(n * (kA + 0.5 * gap), v0 * 0.5, Ang<D>::zero(), kA, 1000, 0, 0);
    w.particles.add(n * (-kA - 0.5 * gap), v0 * -0.5, Ang<D>::zero(), kA, 1000, 0, 1);
    w.contact = buildContactSetup<D>(sc, testing::statsOf(w.particles, 1));
    return w;
}

template <int D>
Vec<D> contactPointVelocity(const World<D>& w) {
    Vec<D> n = Vec<D>::zero();
    n[D - 1] = 1;
    const auto& p = w.particles;
    const std::size_t a = indexOf(p.id, 0), b = indexOf(p.id, 1);
    return p.v[a] - p.v[b] - cross((p.w[a] + p.w[b]) * kA, n);
}

/// e and beta of the collision with particle ids `tdm` time-driven at the start (the others event-driven).
template <int D>
std::pair<double, double> hybridCollision(double ratio, const std::vector<std::uint32_t>& tdm) {
    World<D> w = pairWorld<D>(ratio);
    TdmSettings ts;
    ts.dt = kTc / 50;
    ts.skin = kA;
    ts.sortEvery = 0;
    HaetSettings hs;
    hs.diluteSteps = 1 << 30;  // time-driven particles stay so (the box is dilute everywhere)
    HaetEngine<D> h(w, ts, EdmSettings{}, hs);
    EXPECT_EQ(h.nTdm(), 0u);
    std::vector<std::uint32_t> idx;
    for (std::uint32_t id : tdm) idx.push_back(static_cast<std::uint32_t>(indexOf(w.particles.id, id)));
    h.forceModes(idx, {});
    EXPECT_EQ(h.nTdm(), tdm.size());
    const Vec<D> g0 = contactPointVelocity(w);
    h.advanceTo(20 * kTc);
    h.synchronise();
    const Vec<D> g1 = contactPointVelocity(w);
    return {-g1[D - 1] / g0[D - 1], g0[0] != 0 ? -g1[0] / g0[0] : 0.0};
}

template <int D>
void collisionSameInEveryMode() {
    for (double ratio : {0.0, 0.5, 3.0}) {
        const auto ee = hybridCollision<D>(ratio, {});
        const auto tt = hybridCollision<D>(ratio, {0, 1});
        const auto et = hybridCollision<D>(ratio, {1});
        // The EDM operator uses the e the soft law produces; single TDM collisions scatter by the contact onset
        // within a step (test_collisions.cpp), hence the tolerances of test_edm_consistency.cpp.
        EXPECT_NEAR(tt.first, ee.first, 0.01) << "ratio " << ratio;
        EXPECT_NEAR(et.first, ee.first, 0.01) << "ratio " << ratio;
        EXPECT_NEAR(ee.first, 0.9, 0.01) << "ratio " << ratio;
        if (ratio > 0) {
            EXPECT_NEAR(tt.second, ee.second, 0.02) << "ratio " << ratio;
            EXPECT_NEAR(et.second, ee.second, 0.02) << "ratio " << ratio;
        }
    }
}

TEST(HaetEngine, BinaryCollisionSameInEveryMode2D) { collisionSameInEveryMode<2>(); }
TEST(HaetEngine, BinaryCollisionSameInEveryMode3D) { collisionSameInEveryMode<3>(); }

// ---- particles changing modes ----------------------------------------------------------------------------------

/// A periodic box without gravity: a hot dense block (which expands into the box) and a dilute gas around it.
/// Gear in 2D, velocity Verlet in 3D.
std::string mixedScene(int dim) {
    const bool d3 = dim == 3;
    const std::string L = d3 ? "0.03" : "0.06";
    const std::string z = d3 ? ", 0.0" : "";
    const std::string zl = d3 ? ", 0.03" : "";
    const std::string lo = d3 ? ", 0.01" : "";
    const std::string hi = d3 ? ", 0.02" : "";
    return "name = 'mixed'\ndimension = " + std::to_string(dim) +
           "\nmethod = 'haet'\nduration = 1\nseed = 5\n"
           "[domain]\nlo = [0.0, 0.0" +
           z + "]\nhi = [" + L + ", " + L + zl + "]\nperiodic = [true, true" + (d3 ? ", true" : "") +
           "]\n"
           "[materials.m]\ndensity = 2500\nrestitution = 0.8\nfriction = 0.4\n"
           "[contact]\nnormal = 'linear'\nduration = 1e-4\ntangential = 'spring'\n"
           "[tdm]\nintegrator = '" +
           (d3 ? "verlet" : "gear5") +
           "'\n"  // both integrators' start-up on a mode change
           "[[insert]]\narrangement = 'lattice'\ncount = " +
           std::string(d3 ? "729" : "400") +
           "\nradius = 0.0005\nspacing = 0.00105\nmaterial = 'm'\ntemperature = 0.01\n"
           "region = { lo = [" +
           (d3 ? "0.01, 0.01" : "0.02, 0.02") + lo + "], hi = [" + (d3 ? "0.02, 0.02" : "0.04, 0.04") + hi +
           "] }\n"
           "[[insert]]\narrangement = 'random'\ncount = " +
           std::string(d3 ? "300" : "300") +
           "\nradius = 0.0005\nmaterial = 'm'\ntemperature = 0.04\n"
           "region = { lo = [0.0, 0.0" +
           z + "], hi = [" + L + ", " + (d3 ? "0.009" : "0.018") + zl + "] }\n";
}

template <int D>
void modesChangeWithoutLoss(int buffer) {
    const Scenario sc = parseScenario(mixedScene(D), "mixed.toml");
    World<D> w = buildWorld<D>(sc);
    const std::size_t n = w.particles.size();
    std::vector<std::uint64_t> ids0 = w.particles.id;
    std::sort(ids0.begin(), ids0.end());
    const Vec<D> p0 = testing::momentum(w.particles);
    const double scale = testing::momentumScale(w.particles);
    TdmSettings ts = tdmSettings<D>(sc, w);
    HaetSettings hs;
    hs.zones.phiOn = D == 2 ? 0.45 : 0.30;
    hs.zones.phiOff = D == 2 ? 0.40 : 0.25;
    hs.zones.size = 0.0025;  // 2.5 diameters: the block spans several zones, so its smoothed fraction is dense
    hs.zones.buffer = buffer;
    HaetEngine<D> h(w, ts, EdmSettings{}, hs);
    EXPECT_GT(h.nTdm(), 0u);
    EXPECT_GT(h.nEdm(), 0u);
    for (int k = 0; k < 20; ++k) {
        for (int s = 0; s < 100; ++s) {
            h.step();
            ASSERT_EQ(h.unwatchedInGuard(), 0u)
                << "an event-driven particle in a guard cell is not watched, step " << h.steps();
        }
        h.synchronise();
        ASSERT_EQ(w.particles.size(), n);
        std::vector<std::uint64_t> ids = w.particles.id;
        std::sort(ids.begin(), ids.end());
        ASSERT_EQ(ids, ids0) << "a particle was lost or duplicated at step " << h.steps();
        const Vec<D> p = testing::momentum(w.particles);
        EXPECT_LT(norm(p - p0), 1e-12 * scale) << "step " << h.steps();
        const HaetEnergy e = h.energy();
        EXPECT_LT(std::abs(e.unaccounted), 1e-10 * e.initial) << "step " << h.steps();
    }
    const HaetEnergy e = h.energy();
    EXPECT_GT(h.counters().toTdm, 0u);
    EXPECT_GT(h.counters().toEdm, 0u);
    EXPECT_GT(e.dissipatedTdm, 0.0);
    EXPECT_GT(e.dissipatedEdm, 0.0);
    testing::record("to_tdm", double(h.counters().toTdm));
    testing::record("to_edm", double(h.counters().toEdm));
}

TEST(HaetEngine, ModesChangeWithoutLossOrDuplicates2D) { modesChangeWithoutLoss<2>(1); }
TEST(HaetEngine, ModesChangeWithoutLossOrDuplicates3D) { modesChangeWithoutLoss<3>(1); }
// Without a buffer the guard alone keeps event-driven particles from touching time-driven ones.
TEST(HaetEngine, ModesChangeWithoutLossOrDuplicatesNoBuffer2D) { modesChangeWithoutLoss<2>(0); }
TEST(HaetEngine, ModesChangeWithoutLossOrDuplicatesNoBuffer3D) { modesChangeWithoutLoss<3>(0); }

// ---- uniform systems -------------------------------------------------------------------------------------------

/// Inelastic rough spheres at phi = 0.04: the hybrid never leaves the EDM and follows the pure EDM run. The
/// modified EDM's dt_min is set far below the contact duration in both runs, so that the rare near-simultaneous
/// triple collisions of a gas (which would hand their particles to the TDM) do not occur: the runs are then the
/// same sequence of events.
TEST(HaetEngine, UniformlyDiluteRunsAsPureEdm) {
    const std::string text =
        "name = 'dilute'\ndimension = 3\nduration = 1\nseed = 2\n"
        "[domain]\nlo = [0.0, 0.0, 0.0]\nhi = [0.02, 0.02, 0.02]\nperiodic = [true, true, true]\n"
        "[materials.m]\ndensity = 2500\nrestitution = 0.9\nfriction = 0.3\n"
        "[contact]\nnormal = 'linear'\nduration = 1e-5\ntangential = 'spring'\n"
        "[[insert]]\narrangement = 'random'\ncount = 650\nradius = 0.0005\nmaterial = 'm'\ntemperature = 1.0\n";
    const Scenario sc = parseScenario(text, "dilute.toml");
    World<3> a = buildWorld<3>(sc), b = buildWorld<3>(sc);
    const TdmSettings ts = tdmSettings<3>(sc, a);
    HaetSettings hs;
    hs.dtMin = 1e-10;
    EdmSettings es;
    es.tcTime = hs.dtMin;
    HaetEngine<3> h(a, ts, es, hs);
    EdmEngine<3> e(b, es);
    ASSERT_EQ(h.nTdm(), 0u);
    for (int k = 0; k < 10; ++k) {
        h.advanceTo(a.time + 2000 * ts.dt);
        EXPECT_EQ(h.nTdm(), 0u) << "t = " << a.time << ": " << h.counters().tcHandovers << " hand-overs, "
                                << h.counters().nearTdm << " near TDM, " << h.counters().toTdm << " to TDM";
    }
    h.synchronise();
    e.advanceTo(a.time);
    EXPECT_GT(h.collisions(), 500u);
    EXPECT_EQ(h.collisions(), e.collisions());
    double worst = 0;
    for (std::size_t i = 0; i < b.particles.size(); ++i) {
        const std::size_t j = indexOf(a.particles.id, b.particles.id[i]);
        worst = std::max(worst,
                         norm(a.particles.x[j] - b.particles.x[i]) + norm(a.particles.v[j] - b.particles.v[i]) * 1e-3);
    }
    EXPECT_LT(worst, 1e-9);
    testing::record("collisions", double(h.collisions()));
}

/// The event grid's default edge (docs/haet.md): K / ((D - 1) 3^(D-1)) event-driven particles per cell at their
/// density, within [largest diameter + skin, zone edge]; the grid's cells are that edge rounded up to fit the box.
TEST(HaetEngine, EventGridEdgeFollowsTheDilutePartsDensity) {
    auto edge = [](int dim, int count, double side) {
        std::string lo = dim == 2 ? "[0.0, 0.0]" : "[0.0, 0.0, 0.0]";
        std::string hi = dim == 2 ? "[S, S]" : "[S, S, S]";
        std::string per = dim == 2 ? "[true, true]" : "[true, true, true]";
        hi.replace(hi.find('S'), 1, std::to_string(side));
        while (hi.find('S') != std::string::npos) hi.replace(hi.find('S'), 1, std::to_string(side));
        const std::string text = "name = 'gas'\ndimension = " + std::to_string(dim) +
                                 "\nduration = 1\nseed = 3\n[domain]\nlo = " + lo + "\nhi = " + hi +
                                 "\nperiodic = " + per +
                                 "\n[materials.m]\ndensity = 2500\nrestitution = 0.9\nfriction = 0.3\n"
                                 "[contact]\nnormal = 'linear'\nduration = 1e-5\n"
                                 "[[insert]]\narrangement = 'random'\ncount = " +
                                 std::to_string(count) + "\nradius = 0.0005\nmaterial = 'm'\ntemperature = 1.0\n";
        const Scenario sc = parseScenario(text, "gas.toml");
        double cell = 0;
        auto run = [&](auto dimTag) {
            constexpr int D = decltype(dimTag)::value;
            World<D> w = buildWorld<D>(sc);
            const HaetEngine<D> h(w, tdmSettings<D>(sc, w), EdmSettings{}, HaetSettings{});
            EXPECT_EQ(h.nTdm(), 0u);
            cell = h.edm().cellSize();
        };
        if (dim == 2)
            run(std::integral_constant<int, 2>{});
        else
            run(std::integral_constant<int, 3>{});
        return cell;
    };
    // 3D, 650 spheres in (20 mm)^3: 20 / 18 particles per cell at n = 650 / (20 mm)^3 gives 2.39 mm, between
    // diameter + skin (1.1 mm) and the zone edge (4 mm); 8 cells of 2.5 mm fit the box.
    const double h3 = std::cbrt(20.0 / 18 / (650 / 8e-6));
    EXPECT_GE(edge(3, 650, 0.02), h3);
    EXPECT_LT(edge(3, 650, 0.02), 1.1 * h3);
    // Four times as dense: a smaller edge, down to diameter + skin.
    EXPECT_LT(edge(3, 2600, 0.02), 0.7 * h3);
    EXPECT_GE(edge(3, 2600, 0.02), 1.1e-3);
    // 2D, 60 disks in (40 mm)^2: 20 / 3 per cell would need 21 mm, more than the zone edge (4 mm).
    EXPECT_NEAR(edge(2, 60, 0.04), 0.04 / std::floor(0.04 / 0.004), 1e-12);
}

/// A hot lattice filling a periodic box: the hybrid never leaves the TDM and reproduces the pure TDM run exactly.
template <int D>
void uniformlyDenseRunsAsPureTdm() {
    const bool d3 = D == 3;
    const std::string text =
        "name = 'dense'\ndimension = " + std::to_string(D) +
        "\nduration = 1\nseed = 4\n"
        "[domain]\nlo = [0.0, 0.0" +
        std::string(d3 ? ", 0.0" : "") + "]\nhi = [0.0105, 0.0105" + (d3 ? ", 0.0105" : "") +
        "]\nperiodic = [true, true" + (d3 ? ", true" : "") +
        "]\n"
        "[materials.m]\ndensity = 2500\nrestitution = 0.7\nfriction = 0.5\n"
        "[contact]\nnormal = 'linear'\nduration = 1e-4\ntangential = 'spring'\n"
        "[tdm]\nintegrator = 'gear5'\n"
        "[[insert]]\narrangement = 'lattice'\ncount = 1000\nradius = 0.0005\nspacing = 0.00105\nmaterial = 'm'\n"
        "temperature = 0.01\n";
    const Scenario sc = parseScenario(text, "dense.toml");
    World<D> a = buildWorld<D>(sc), b = buildWorld<D>(sc);
    const TdmSettings ts = tdmSettings<D>(sc, a);
    HaetSettings hs;
    hs.zones.phiOn = d3 ? 0.30 : 0.45;
    hs.zones.phiOff = d3 ? 0.25 : 0.40;
    HaetEngine<D> h(a, ts, EdmSettings{}, hs);
    TdmEngine<D> t(b, ts);
    EXPECT_EQ(h.nEdm(), 0u);
    for (int k = 0; k < 10; ++k) {
        h.advanceTo(a.time + 50 * ts.dt);
        t.advanceTo(b.time + 50 * ts.dt);
        EXPECT_EQ(h.nEdm(), 0u) << "t = " << a.time;
    }
    for (std::size_t i = 0; i < b.particles.size(); ++i) {
        ASSERT_EQ(a.particles.id[i], b.particles.id[i]);
        EXPECT_EQ(a.particles.x[i][0], b.particles.x[i][0]);
        EXPECT_EQ(a.particles.v[i][D - 1], b.particles.v[i][D - 1]);
    }
}

TEST(HaetEngine, UniformlyDenseRunsAsPureTdm2D) { uniformlyDenseRunsAsPureTdm<2>(); }
TEST(HaetEngine, UniformlyDenseRunsAsPureTdm3D) { uniformlyDenseRunsAsPureTdm<3>(); }

}  // namespace
}  // namespace haet
