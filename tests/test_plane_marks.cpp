// The planes' broad phase of the time-driven engine (TdmEngine::markNearPlanes): particles marked far from every
// plane at a pair-list build skip the planes until the next build. Tested against its twin, every particle testing
// every plane (TdmSettings::markPlanes = false): the same bits, step after step, with settling beds in 3D and 2D,
// a plane moved from outside mid-run, and moving planes (no marks).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "physics_util.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"

namespace haet {
namespace {

using testing::exampleScenario;
using testing::sameBits;

template <int D>
void expectSameState(const World<D>& a, const World<D>& b, const std::string& where) {
    EXPECT_TRUE(sameBits(a.particles.x, b.particles.x)) << where;
    EXPECT_TRUE(sameBits(a.particles.v, b.particles.v)) << where;
    EXPECT_TRUE(sameBits(a.particles.w, b.particles.w)) << where;
    EXPECT_TRUE(sameBits(a.particles.f, b.particles.f)) << where;
    EXPECT_TRUE(sameBits(a.particles.torque, b.particles.torque)) << where;
}

/// Steps a scene with and without the marks side by side, comparing the states at every piece; returns the
/// fewest particles marked near at the pieces' ends (the marks must leave some out, or the test tests nothing).
template <int D>
std::size_t runTwins(const Scenario& sc, int pieces, double piece, bool raiseFloor = false) {
    World<D> wa = buildWorld<D>(sc), wb = buildWorld<D>(sc);
    TdmSettings marked = tdmSettings<D>(sc, wa);
    TdmSettings twin = marked;
    twin.markPlanes = false;
    TdmEngine<D> a(wa, marked), b(wb, twin);
    std::size_t fewest = wa.particles.size();
    for (int k = 1; k <= pieces; ++k) {
        a.advanceTo(k * piece);
        b.advanceTo(k * piece);
        expectSameState(wa, wb, "after piece " + std::to_string(k));
        EXPECT_TRUE(b.nearPlanes().empty());
        std::size_t near = 0;
        for (std::uint8_t m : a.nearPlanes()) near += m;
        if (!a.nearPlanes().empty()) fewest = std::min(fewest, near);
        // Every particle touching a plane now is marked near.
        if (!a.nearPlanes().empty())
            for (std::size_t i = 0; i < wa.particles.tdmCount(); ++i)
                for (const Wall<D>& wall : wa.walls)
                    if (wall.distanceNow(wa.particles.x[i]) < wa.particles.radius[i])
                        EXPECT_EQ(a.nearPlanes()[i], 1) << "particle " << i;
        if (raiseFloor && k == pieces / 2) {  // the floor raised by hand: the marks no longer hold
            wa.walls[0].point[D - 1] += 2 * marked.skin;
            wb.walls[0].point[D - 1] += 2 * marked.skin;
        }
    }
    return fewest;
}

TEST(PlaneMarks, SettlingBedIn3DGivesTheBitsOfTheTwin) {
    const Scenario sc = exampleScenario("box3d_settle.toml", {"insert[1].count=600"});
    const std::size_t fewest = runTwins<3>(sc, 8, 0.01);
    EXPECT_LT(fewest, 600u);  // particles in the middle of the box skip the planes
    EXPECT_GT(fewest, 0u);
}

TEST(PlaneMarks, SettlingBedIn2DGivesTheBitsOfTheTwin) {
    const Scenario sc = exampleScenario("box2d_settle.toml", {"insert[1].count=400"});
    const std::size_t fewest = runTwins<2>(sc, 8, 0.02);
    EXPECT_LT(fewest, 400u);
    EXPECT_GT(fewest, 0u);
}

TEST(PlaneMarks, APlaneMovedFromOutsideIsTestedByEveryParticle) {
    const Scenario sc = exampleScenario("box3d_settle.toml", {"insert[1].count=600"});
    runTwins<3>(sc, 6, 0.02, true);
}

TEST(PlaneMarks, MovingPlanesAreNotMarked) {
    const Scenario sc =
        exampleScenario("box3d_settle.toml", {"insert[1].count=300", "walls[1].velocity=[0.0, 0.0, 0.01]"});
    World<3> w = buildWorld<3>(sc);
    TdmEngine<3> e(w, tdmSettings<3>(sc, w));
    e.advanceTo(0.005);
    EXPECT_TRUE(e.nearPlanes().empty());
    runTwins<3>(sc, 3, 0.005);
}

}  // namespace
}  // namespace haet
