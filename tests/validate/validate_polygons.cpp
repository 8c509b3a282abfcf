// Long validations of the polygon contact law (`make validate`, label "validate"); the short versions are in
// tests/test_polygon_physics.cpp. Same helpers (tests/polygon_util.hpp), same scenes.
//  - Energy of elastic, frictionless polygon collisions with Gear5: the integration error per collision, over 200
//    random collisions, and the energy of a polygon gas over 10^5 steps.
//  - Angle of repose: the heaps of examples/pile2d_polygons.toml and examples/pile2d_disks.toml.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "../physics_util.hpp"
#include "../polygon_util.hpp"

namespace haet {
namespace {

using testing::dataScenario;
using testing::record;

// Gear at the polygon time step against a 16 times smaller step, over 200 random collisions: the energy after a
// collision agrees within 1e-3 of the pair's energy for at least 97 % of them, and within 5e-3 for all (measured:
// 197 of 200 within 1e-3, worst 3.0e-3; the few beyond are contacts whose onset is nearly face-on, a kink of the
// force that Gear resolves only at smaller steps, PHYSICS.md F.3). The converged change itself is the law's (G.3).
TEST(PolygonEnergyLong, GearIntegratesCollisionsLikeASmallStep) {
    double worstIntegration = 0, meanIntegration = 0, worstLaw = 0, meanLaw = 0;
    int beyond = 0;
    const int n = 200;
    for (std::uint64_t seed = 1; seed <= n; ++seed) {
        const double coarse = testing::collisionEnergyChange(seed, 1.0);
        const double fine = testing::collisionEnergyChange(seed, 1.0 / 16);
        const double err = std::abs(coarse - fine);
        worstIntegration = std::max(worstIntegration, err);
        meanIntegration += err / n;
        beyond += err > 1e-3;
        worstLaw = std::max(worstLaw, std::abs(fine));
        meanLaw += std::abs(fine) / n;
        EXPECT_LT(err, 5e-3) << "seed " << seed;
    }
    record("worst_integration_error", worstIntegration);
    record("mean_integration_error", meanIntegration);
    record("collisions_beyond_1e-3", beyond);
    record("worst_law_energy_change", worstLaw);
    record("mean_law_energy_change", meanLaw);
    EXPECT_LE(beyond, n * 3 / 100);
}

// An elastic, frictionless gas of 120 polygons (tests/data/polygon_gas.toml), 10^5 Gear5 steps. The energy is
// read at instants without any contact, where it is purely kinetic (the elastic energy of a polygon contact is only
// an estimate). The overlap-area law is not conservative: a collision with spin or an offset approach changes the
// pair's energy, converged in dt, by 4e-3 on average and up to 6e-2 (PolygonEnergyLong above, spins up to 60
// rad/s), so the gas energy wanders and the 1e-3 goal over a long run is not met by this law (measured 1.0e-2 after
// 10^5 steps). The bound here, 2e-2, only catches a broken integration or a blow-up.
TEST(PolygonEnergyLong, GasEnergyAtContactFreeInstants) {
    const Scenario sc = dataScenario("polygon_gas.toml");
    World<2> w = buildWorld<2>(sc);
    TdmEngine<2> eng(w, tdmSettings<2>(sc, w));
    const double e0 = testing::kineticEnergy(w.particles);
    double drift = 0, contactSteps = 0;
    int samples = 0;
    for (int k = 1; k <= 100000; ++k) {
        eng.step();
        contactSteps += double(eng.forceStats().contacts);
        if (eng.forceStats().contacts == 0) {
            drift = std::max(drift, std::abs(testing::kineticEnergy(w.particles) / e0 - 1));
            ++samples;
        }
    }
    record("energy_drift", drift);
    record("contact_free_samples", samples);
    // At about 10 steps per contact, at least 5 collisions per particle.
    EXPECT_GT(contactSteps / 10, 5.0 * w.particles.size());
    EXPECT_GT(samples, 100);
    EXPECT_LT(drift, 2e-2);
}

// The piles of the examples: 500 grains, the same column collapsing onto a frictional floor. Polygons interlock;
// disks roll and spread into a layer.
TEST(PolygonReposeLong, PolygonHeapIsSteeperThanDiskHeap) {
    const std::filesystem::path ex = std::filesystem::path(HAET_SOURCE_DIR) / "examples";
    const double poly = testing::pileAngle(loadScenario(ex / "pile2d_polygons.toml"));
    const double disk = testing::pileAngle(loadScenario(ex / "pile2d_disks.toml"));
    record("polygon_angle_deg", poly);
    record("disk_angle_deg", disk);
    EXPECT_GT(poly, disk + 5.0) << "polygons " << poly << " deg, disks " << disk << " deg";
}

}  // namespace
}  // namespace haet
