// Long validations of the event-driven engine (`ctest -L validate`): the 10^6-collision versions of the fast tests
// in tests/test_edm_engine.cpp and tests/test_edm_physics.cpp. Same scenes (tests/test_edm_util.hpp), tighter
// criteria.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "../test_edm_util.hpp"

namespace haet {
namespace {

void record(const std::string& key, double value) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", value);
    ::testing::Test::RecordProperty(key, buf);
}

// ---- equation of state: Z from the collision virial against Carnahan-Starling within 1.5 % (docs/physics.md E.1) ----

void zAgainstCarnahanStarling(double phi, double shell = 0) {
    const double z = testing::measureZ<3>(1000, phi, 2000000, 50, 21, shell);
    const double cs = testing::carnahanStarling(phi);
    record("Z", z);
    record("Z_CS", cs);
    EXPECT_NEAR(z, cs, 0.015 * cs) << "phi = " << phi;
}

TEST(EdmValidate, CompressibilityFactorPhi01) { zAgainstCarnahanStarling(0.1); }
TEST(EdmValidate, CompressibilityFactorPhi03) { zAgainstCarnahanStarling(0.3); }
TEST(EdmValidate, CompressibilityFactorPhi045Shells) { zAgainstCarnahanStarling(0.45, 0.25); }

// ---- elastic gas: total energy conserved to round-off over 10^6 collisions ----

template <int D>
void elasticEnergy(bool rough, double shell = 0) {
    testing::GasSpec g;
    g.n = D == 3 ? 2000 : 1600;
    g.phi = D == 3 ? 0.25 : 0.5;
    g.polydisperse = true;
    g.spin = rough ? 1 : 0;
    World<D> w = testing::makeGas<D>(g, testing::edmContact(1.0, 0.0, rough ? 1.0 : -1.0));
    EdmSettings s;
    s.tangential = EdmSettings::Tangential::Constant;
    s.shell = shell;
    EdmEngine<D> eng(w, s);
    const double e0 = testing::kineticEnergyEdm(w.particles);
    double worst = 0, t = 0;
    while (eng.collisions() < 1000000) {
        eng.advanceTo(t += 1.0);
        worst = std::max(worst, std::abs(testing::kineticEnergyEdm(w.particles) / e0 - 1));
    }
    record("relative_energy_error", worst);
    EXPECT_LT(worst, 1e-11);
    EXPECT_LT(testing::maxOverlapRatio(w), 1e-9);
}

TEST(EdmValidate, ElasticSmoothGasConservesEnergy3D) { elasticEnergy<3>(false); }
TEST(EdmValidate, ElasticRoughGasConservesEnergy2D) { elasticEnergy<2>(true); }
TEST(EdmValidate, ElasticSmoothGasConservesEnergy3DShells) { elasticEnergy<3>(false, 0.25); }

// ---- a dissipative heap of 2000 spheres (e = 0.5) poured into a box: bounded wall time, no overlap, none lost ----

TEST(EdmValidate, DissipativeHeap2000) {
    World<3> w = testing::pouringBox(2000, 0.5, 5e-4, 31);
    EdmEngine<3> eng(w, EdmSettings{});
    const auto start = std::chrono::steady_clock::now();
    const double tEnd = 5.0;
    for (double t = 0.5; t <= tEnd; t += 0.5) eng.advanceTo(t);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    record("wall_time_s", wall);
    record("events", static_cast<double>(eng.events()));
    record("collisions", static_cast<double>(eng.collisions()));
    record("tc_elastic", static_cast<double>(eng.stats().tcElastic));
    record("rest_hops", static_cast<double>(eng.stats().restHops));
    EXPECT_EQ(w.time, tEnd);
    EXPECT_LT(wall, 300.0);
    EXPECT_LT(testing::maxOverlapRatio(w), 1e-8);
    EXPECT_LT(testing::maxWallPenetration(w), 1e-8);
    EXPECT_LT(testing::maxEscape(w), 1e-8);
    double ke = 0, m = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i) {
        ke += 0.5 * w.particles.mass[i] * norm2(w.particles.v[i]);
        m += w.particles.mass[i];
    }
    record("ke_per_mass", ke / m);
    EXPECT_LT(ke / m, 1e-4 * 9.81 * w.domain.hi[2]) << "not settled";
}

// ---- fast engine against the brute-force reference over a longer run ----

TEST(EdmValidate, MatchesReferenceLongRun) {
    testing::GasSpec g;
    g.n = 100;
    g.phi = 0.2;
    g.polydisperse = true;
    g.gravity = 1.0;
    g.speed = 2;
    g.seed = 41;
    World<3> w = testing::makeGas<3>(g, testing::edmContact(0.9, 0.3, 0.5));
    w.domain.periodic[2] = false;
    const double L = w.domain.hi[2];
    w.walls.push_back(Wall<3>::plane(Vec<3>::zero(), Vec<3>{{0, 0, 1}}, Vec<3>::zero(), 0));
    w.walls.push_back(
        Wall<3>::plane(Vec<3>::filled(L), Vec<3>{{0, 0, -1}}, Vec<3>{{0, 0, -0.01}}, 0));  // a slowly moving lid
    EdmSettings s;
    s.tcTime = 1e-3;
    auto run = [&](bool reference, double shell, std::vector<EdmCollision<3>>& log) {
        World<3> copy = w;
        EdmSettings rs = s;
        rs.reference = reference;
        rs.shell = shell;
        EdmEngine<3> eng(copy, rs);
        eng.setObserver([&](const EdmCollision<3>& c) { log.push_back(c); });
        eng.advanceTo(12.0);
    };
    std::vector<EdmCollision<3>> ref;
    run(true, 0, ref);
    record("collisions", static_cast<double>(ref.size()));
    ASSERT_GT(ref.size(), 50000u);
    for (const double shell : {0.0, 0.25}) {  // cell crossings, neighbour shells
        SCOPED_TRACE(shell);
        std::vector<EdmCollision<3>> fast;
        run(false, shell, fast);
        ASSERT_EQ(fast.size(), ref.size());
        for (std::size_t k = 0; k < ref.size(); ++k) {
            ASSERT_EQ(fast[k].wall, ref[k].wall) << k;
            ASSERT_EQ(std::min(fast[k].i, fast[k].partner), std::min(ref[k].i, ref[k].partner)) << k;
            ASSERT_EQ(std::max(fast[k].i, fast[k].partner), std::max(ref[k].i, ref[k].partner)) << k;
            ASSERT_EQ(fast[k].time, ref[k].time) << k;
        }
    }
}

}  // namespace
}  // namespace haet
