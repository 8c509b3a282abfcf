// Physics of the event-driven engine, short versions (the long ones are in tests/validate/test_edm_validate.cpp):
// the equation of state of the elastic hard-sphere gas from the collision virial (docs/physics.md E.1, E.2), and a
// dissipative heap under gravity that the TC model lets settle (docs/physics.md A.4, D.7).
#include <gtest/gtest.h>

#include <cmath>

#include "test_edm_util.hpp"

namespace haet {
namespace {

// N = 500 at phi = 0.3, 1.5 10^5 collisions: statistical error ~0.5 %; the validation asks for 1.5 % with more.
TEST(EdmPhysics, CompressibilityFactorNearCarnahanStarling) {
    const double z = testing::measureZ<3>(500, 0.3, 150000, 30, 11);
    ::testing::Test::RecordProperty("Z", std::to_string(z));
    EXPECT_NEAR(z, testing::carnahanStarling(0.3), 0.025 * testing::carnahanStarling(0.3));
}

// 300 unequal spheres fall into a closed box, e = 0.5, TC time 1e-3 s: the run reaches its end time, no particle
// overlaps another or a wall beyond round-off, none leaves the box, and the heap is at rest.
TEST(EdmPhysics, DissipativeHeapSettles) {
    World<3> w = testing::pouringBox(300, 0.5, 1e-3, 12);
    EdmEngine<3> eng(w, EdmSettings{});
    const double ePot0 = 9.81 * w.domain.hi[2];  // per unit mass, scale of the fall
    for (double t = 0.5; t <= 4.0; t += 0.5) eng.advanceTo(t);
    EXPECT_EQ(w.time, 4.0);
    EXPECT_LT(testing::maxOverlapRatio(w), 1e-8);
    EXPECT_LT(testing::maxWallPenetration(w), 1e-8);
    EXPECT_LT(testing::maxEscape(w), 1e-8);
    double ke = 0, m = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i) {
        ke += 0.5 * w.particles.mass[i] * norm2(w.particles.v[i]);
        m += w.particles.mass[i];
    }
    EXPECT_LT(ke / m, 1e-4 * ePot0) << "not settled";
    EXPECT_GT(eng.stats().tcElastic, 0u);
    ::testing::Test::RecordProperty("events", std::to_string(eng.events()));
}

}  // namespace
}  // namespace haet
