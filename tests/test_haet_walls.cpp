// The hybrid with walls of any shape (docs/physics.md H.6; docs/haet.md, "Walls the event-driven part does not
// predict"): in a drum (a circle, which the event-driven engine does not predict) turning around a static floor of
// segments (which it does), no particle is lost or duplicated, no event-driven particle ever touches the drum (the
// guard hands it to the time-driven engine first), the floor's collisions are the event-driven engine's, and the
// energy books close, the drum turning or at rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "haet/engine.hpp"
#include "scenario/loader.hpp"
#include "world/build.hpp"

namespace haet {
namespace {

constexpr double kCentre = 0.05, kRadius = 0.048;

std::string drumScene(double omega) {
    const std::string rotation =
        omega != 0 ? "rotation = { center = [0.05, 0.05], omega = " + std::to_string(omega) + " }\n" : "";
    return "name = 'drum'\ndimension = 2\nmethod = 'haet'\nduration = 1\nseed = 7\n"
           "[domain]\nlo = [0.0, 0.0]\nhi = [0.1, 0.1]\ngravity = [0.0, -9.81]\n"
           "[materials.m]\ndensity = 2500\nrestitution = 0.8\nfriction = 0.3\n"
           "[contact]\nnormal = 'linear'\nduration = 5e-4\ntangential = 'spring'\n"
           "[[walls]]\ntype = 'circle'\nname = 'drum'\ncenter = [0.05, 0.05]\nradius = 0.048\nmaterial = 'm'\n" +
           rotation +
           "[[walls]]\ntype = 'polyline'\nname = 'floor'\npoints = [[0.015, 0.025], [0.05, 0.02], [0.085, 0.025]]\n"
           "material = 'm'\n"
           "[[insert]]\narrangement = 'random'\ncount = 120\nradius = 0.001\nmaterial = 'm'\ntemperature = 0.3\n"
           "region = { lo = [0.018, 0.028], hi = [0.082, 0.082] }\n";
}

struct DrumRun {
    double closestEdm = 1;  ///< least gap between an event-driven particle and the drum over the run [m]
    std::uint64_t floorEvents = 0, nearWall = 0, toTdm = 0, toEdm = 0;
    double unaccounted = 0, initial = 0;
};

DrumRun runDrum(double omega, int steps) {
    const Scenario sc = parseScenario(drumScene(omega), "drum.toml");
    World<2> w = buildWorld<2>(sc);
    const std::size_t n = w.particles.size();
    std::vector<std::uint64_t> ids0 = w.particles.id;
    std::sort(ids0.begin(), ids0.end());
    HaetEngine<2> h(w, tdmSettings<2>(sc, w), edmSettings(sc), haetSettings<2>(sc));
    DrumRun run;
    const Vec<2> c = Vec<2>::filled(kCentre);
    for (int k = 0; k < steps; ++k) {
        h.step();
        EXPECT_EQ(h.unwatchedInGuard(), 0u) << "step " << h.steps();
        // From the event-driven side: where the engine has its particles now.
        for (std::size_t i = h.nTdm(); i < w.particles.size(); ++i) {
            const double gap = kRadius - norm(h.edm().positionAt(i, w.time) - c) - w.particles.radius[i];
            run.closestEdm = std::min(run.closestEdm, gap);
        }
        if (::testing::Test::HasFailure()) break;
    }
    h.synchronise();
    EXPECT_EQ(w.particles.size(), n);
    std::vector<std::uint64_t> ids = w.particles.id;
    std::sort(ids.begin(), ids.end());
    EXPECT_EQ(ids, ids0) << "a particle was lost or duplicated";
    for (std::size_t i = 0; i < n; ++i) EXPECT_LT(norm(w.particles.x[i] - c), kRadius) << "outside the drum: " << i;
    run.floorEvents = h.edm().stats().wallCollisions;
    run.nearWall = h.counters().nearWall;
    run.toTdm = h.counters().toTdm;
    run.toEdm = h.counters().toEdm;
    const HaetEnergy e = h.energy();
    run.unaccounted = e.unaccounted;
    run.initial = e.initial;
    return run;
}

TEST(HaetWalls, RotatingDrumNeverTouchedByEventDrivenParticles) {
    const DrumRun r = runDrum(3.0, 30000);
    std::printf("closest %g, floor %llu, near wall %llu, to tdm %llu, to edm %llu\n", r.closestEdm,
                (unsigned long long)r.floorEvents, (unsigned long long)r.nearWall, (unsigned long long)r.toTdm,
                (unsigned long long)r.toEdm);
    EXPECT_GE(r.closestEdm, 0.0) << "an event-driven particle touched the drum";
    EXPECT_GT(r.floorEvents, 50u) << "the floor's collisions are the event-driven engine's";
    EXPECT_GT(r.nearWall, 10u) << "particles near the drum were handed to the time-driven engine";
    EXPECT_GT(r.toEdm, 0u);
    // The drum's work is in the time-driven part's balance (docs/haet.md, "Energy bookkeeping").
    EXPECT_LT(std::abs(r.unaccounted), 1e-9 * std::abs(r.initial));
    ::testing::Test::RecordProperty("closest_edm_gap", std::to_string(r.closestEdm));
}

TEST(HaetWalls, StaticDrumKeepsTheEnergyBooks) {
    const DrumRun r = runDrum(0.0, 20000);
    std::printf("closest %g, near wall %llu, unaccounted %g of %g\n", r.closestEdm, (unsigned long long)r.nearWall,
                r.unaccounted, r.initial);
    EXPECT_GE(r.closestEdm, 0.0);
    EXPECT_GT(r.nearWall, 10u);
    EXPECT_LT(std::abs(r.unaccounted), 1e-9 * std::abs(r.initial));
}

// A vibrated floor (an oscillating plane, which the event-driven engine does not predict) under a gas between two
// static side planes (which it does): no event-driven particle ever reaches the floor, none is lost.
TEST(HaetWalls, VibratedFloorNeverTouchedByEventDrivenParticles) {
    const std::string text =
        "name = 'shaker'\ndimension = 2\nmethod = 'haet'\nduration = 1\nseed = 3\n"
        "[domain]\nlo = [0.0, -0.01]\nhi = [0.05, 0.1]\ngravity = [0.0, -9.81]\n"
        "[materials.m]\ndensity = 2500\nrestitution = 0.9\nfriction = 0.3\n"
        "[contact]\nnormal = 'linear'\nduration = 5e-4\ntangential = 'spring'\n"
        "[[walls]]\nname = 'floor'\npoint = [0.0, 0.0]\nnormal = [0.0, 1.0]\nmaterial = 'm'\n"
        "oscillation = { amplitude = [0.0, 0.002], frequency = 30 }\n"
        "[[walls]]\npoint = [0.0, 0.0]\nnormal = [1.0, 0.0]\nmaterial = 'm'\n"
        "[[walls]]\npoint = [0.05, 0.0]\nnormal = [-1.0, 0.0]\nmaterial = 'm'\n"
        "[[insert]]\narrangement = 'random'\ncount = 80\nradius = 0.001\nmaterial = 'm'\ntemperature = 0.2\n"
        "region = { lo = [0.002, 0.01], hi = [0.048, 0.08] }\n";
    const Scenario sc = parseScenario(text, "shaker.toml");
    World<2> w = buildWorld<2>(sc);
    const std::size_t n = w.particles.size();
    HaetEngine<2> h(w, tdmSettings<2>(sc, w), edmSettings(sc), haetSettings<2>(sc));
    double closest = 1;
    for (int k = 0; k < 20000; ++k) {
        h.step();
        const double floor = w.walls[0].pointAt(w.time)[1];
        for (std::size_t i = h.nTdm(); i < n; ++i)
            closest = std::min(closest, h.edm().positionAt(i, w.time)[1] - floor - w.particles.radius[i]);
    }
    h.synchronise();
    EXPECT_EQ(w.particles.size(), n);
    EXPECT_GE(closest, 0.0) << "an event-driven particle reached the floor";
    EXPECT_GT(h.counters().nearWall, 10u);
    EXPECT_GT(h.edm().stats().wallCollisions, 0u) << "the side walls are the event-driven engine's";
    for (std::size_t i = 0; i < n; ++i) EXPECT_GT(w.particles.x[i][1], w.walls[0].pointAt(w.time)[1]) << i;
    ::testing::Test::RecordProperty("closest_edm_gap", std::to_string(closest));
}

}  // namespace
}  // namespace haet
