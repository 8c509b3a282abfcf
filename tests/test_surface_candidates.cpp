// The broad phase of walls of any shape as the engine keeps it between builds (docs/physics.md H.4): at every step
// checked, each element a particle touches is among its candidates. With walls that all stand still the candidates
// reach the radius plus half the skin (a particle drifts at most skin/2 before the next build); with a moving wall
// the radius plus the skin (the wall closes in by the other half). Checked against every element of every wall, in
// scenes of examples/ where particles are thrown at a static hopper and at a turning mixer blade, and for spheres
// falling onto a mesh from heights spread over one drift between builds, so that some are listed just before
// they come within the margin (a margin short of skin/2 by a tenth of it misses some of their contacts).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world_util.hpp"

namespace haet {
namespace {

/// Counts the (particle, element) contacts at the engine's last force pass and how many of them are not among the
/// particle's candidates.
struct Coverage {
    std::size_t touching = 0, missed = 0;
};

Coverage coverage(const TdmEngine<3>& eng, const World<3>& w) {
    const SurfaceState<3>& s = eng.surfaceState();
    const Particles<3>& p = w.particles;
    Coverage c;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double r = p.radius[i];
        for (std::uint32_t q = 0; q < w.surfaces.size(); ++q) {
            const SurfaceWall<3>& wall = w.surfaces[q];
            const Vec<3> xb = s.poses[q].toBody(p.x[i]);
            for (std::uint32_t e = 0; e < wall.elementCount(); ++e) {
                Vec<3> lo, hi;  // a contact needs the box within the radius: most elements end here
                wall.bounds(e, lo, hi);
                double d2 = 0;
                for (int a = 0; a < 3; ++a) {
                    const double d = std::max({lo[a] - xb[a], xb[a] - hi[a], 0.0});
                    d2 += d * d;
                }
                if (d2 > r * r) continue;
                bool touches = false;
                wall.contacts(e, xb, r, [&](const SurfaceHit<3>&) { touches = true; });
                if (!touches) continue;
                ++c.touching;
                bool listed = false;
                for (std::uint32_t k = s.candidates.first[i]; k < s.candidates.first[i + 1]; ++k)
                    listed = listed || (s.candidates.wall[k] == q && s.candidates.element[k] == e);
                c.missed += !listed;
            }
        }
    }
    return c;
}

/// Steps the scene, checking the coverage every `every` steps; returns the sum over the checks.
Coverage run(const std::string& scene, const std::vector<std::string>& sets, int steps, int every) {
    const Scenario sc = loadScenario(std::string(HAET_SOURCE_DIR) + "/examples/" + scene, sets);
    World<3> w = buildWorld<3>(sc);
    TdmEngine<3> eng(w, tdmSettings<3>(sc, w));
    Coverage total;
    for (int k = 1; k <= steps; ++k) {
        eng.step();
        if (k % every) continue;
        const Coverage c = coverage(eng, w);
        total.touching += c.touching;
        total.missed += c.missed;
    }
    EXPECT_GT(eng.rebuilds(), 5u) << scene << ": the check needs candidates built again and again";
    return total;
}

TEST(SurfaceCandidates, StaticHopperHalfSkinCoversEveryContact) {
    // 300 beads thrown at 1 m/s in all directions inside silo3d's conical hopper (a mesh), falling through its
    // orifice: contacts with faces, edges and vertices, and pair-list builds every few dozen steps.
    const Coverage c =
        run("silo3d.toml",
            {"insert[1].count=300", "insert[1].region={ lo = [-0.007, -0.007, 0.008], hi = [0.007, 0.007, 0.016] }",
             "insert[1].temperature=1.0", "insert[1].velocity=[0.0, 0.0, -0.5]"},
            2000, 5);
    EXPECT_GT(c.touching, 150u);
    EXPECT_EQ(c.missed, 0u);
}

TEST(SurfaceCandidates, SpheresFallingOnAMeshAtEveryPhaseOfTheBuilds) {
    // 49 spheres (radius 1 mm, skin 0.5 mm), no gravity, falling at 0.5 m/s onto a floor of two triangles from
    // heights 2 mm + k/49 of skin/2 above contact: all drift alike, so the pair list and the candidates are built
    // again every skin/2 of fall, each sphere at its own distance from the floor then.
    const double a = 0.001, skin = 0.0005, tc = 1e-4;
    Scenario sc = testing::linearScenario(3, 0.8, tc, 0.3, TangentialLaw::Spring);
    World<3> w;
    w.domain = testing::openBox<3>(0.05);
    for (int k = 0; k < 49; ++k) {
        const Vec<3> x{{-0.012 + 0.004 * (k % 7), -0.012 + 0.004 * (k / 7), a + 0.002 + 0.5 * skin * k / 49.0}};
        w.particles.add(x, Vec<3>{{0, 0, -0.5}}, Ang<3>::zero(), a, 2.5, 0, static_cast<std::uint64_t>(k));
    }
    SurfaceWall<3> floor;
    const Vec<3> c00{{-0.04, -0.04, 0}}, c10{{0.04, -0.04, 0}}, c01{{-0.04, 0.04, 0}}, c11{{0.04, 0.04, 0}};
    buildMesh<3>(floor, {{c00, c10, c11}, {c00, c11, c01}});
    w.surfaces.push_back(floor);
    w.contact = buildContactSetup<3>(sc, testing::statsOf(w.particles, 1));
    TdmSettings s;
    s.dt = tc / 50;
    s.skin = skin;
    s.sortEvery = 0;
    TdmEngine<3> eng(w, s);
    Coverage total;
    for (int k = 0; k < 4000; ++k) {  // 4 mm of fall: onto the floor and back
        eng.step();
        const Coverage c = coverage(eng, w);
        total.touching += c.touching;
        total.missed += c.missed;
    }
    EXPECT_GT(eng.rebuilds(), 10u);
    EXPECT_GT(total.touching, 49u * 50u);  // every sphere touches for some 100 steps
    EXPECT_EQ(total.missed, 0u);
}

TEST(SurfaceCandidates, TurningBladeFullSkinCoversEveryContact) {
    // 300 beads dropped at 1 m/s onto mixer3d's blade (a mesh) turning at 50 rad/s: its candidates are built again
    // as it turns, between the particles' builds.
    const Coverage c =
        run("mixer3d.toml",
            {"insert[1].count=300", "insert[1].region={ lo = [-0.017, -0.017, 0.0152], hi = [0.017, 0.017, 0.021] }",
             "insert[1].velocity=[0.0, 0.0, -1.0]", "insert[1].temperature=0.01", "walls[2].rotation.omega=50.0"},
            1500, 5);
    EXPECT_GT(c.touching, 50u);
    EXPECT_EQ(c.missed, 0u);
}

}  // namespace
}  // namespace haet
