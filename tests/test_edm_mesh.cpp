// The event-driven engine with static mesh walls (docs/physics.md D.8, H.6): the fast engine against the brute-force
// reference over long random runs with gravity (bit-identical event sequences, with cell crossings and with
// neighbour shells), a flat mesh floor against its analytic plane, one collision where elements meet, the energy
// books of a pure event-driven run, and the walls the engine refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/rng.hpp"
#include "edm_mesh_util.hpp"
#include "io/stl.hpp"
#include "scenario/loader.hpp"
#include "test_edm_util.hpp"
#include "world/build.hpp"

namespace haet {
namespace {

using testing::boxElements;
using testing::compareWithReference;
using testing::Corners;
using testing::edmContact;
using testing::Logged;
using testing::meshDistance;
using testing::MeshGas;
using testing::meshGas;
using testing::meshWall;
using testing::runLogged;

/// How many of the logged collisions are with mesh elements.
template <int D>
std::size_t meshCollisions(const World<D>& w, EdmSettings s, double tEnd) {
    std::size_t n = 0;
    const std::vector<Logged> log = runLogged(w, s, tEnd);
    for (const Logged& c : log) n += c.wall && c.b >= w.walls.size();
    std::printf("%zu collisions, %zu with mesh elements, by t = %g s\n", log.size(), n, tEnd);
    return n;
}

TEST(EdmMesh, MatchesReference2DBoxOfSegments) {
    MeshGas m;
    m.n = 30;
    m.e = 0.95;
    m.seed = 3;
    const World<2> w = meshGas<2>(m);
    ASSERT_GT(w.particles.size(), 20u);
    EdmSettings s;
    s.tcTime = 1e-3;
    const EdmStats st = compareWithReference<2>(w, s, 8000);
    EXPECT_GT(st.cellCrossings, 300u);
    EXPECT_GT(meshCollisions<2>(w, s, 20.0), 300u);
}

TEST(EdmMesh, MatchesReference3DBoxOfTriangles) {
    MeshGas m;
    m.n = 27;
    m.inner = 5;
    m.seed = 4;
    const World<3> w = meshGas<3>(m);
    ASSERT_GT(w.particles.size(), 18u);
    EdmSettings s;
    s.tcTime = 1e-3;
    compareWithReference<3>(w, s, 5000);
    EXPECT_GT(meshCollisions<3>(w, s, 20.0), 500u);
}

TEST(EdmMesh, MatchesReferenceElasticRough3D) {
    MeshGas m;
    m.n = 27;
    m.inner = 6;
    m.e = 1;
    m.mu = 0;
    m.beta0 = 1;
    m.seed = 5;
    EdmSettings s;
    s.tcModel = false;
    s.tangential = EdmSettings::Tangential::Constant;
    compareWithReference<3>(meshGas<3>(m), s, 3000);
}

// A mesh floor across periodic axes: the box frame of a particle moves where it crosses a periodic face (wraps), in
// the fast engine at its cell crossings, in the reference at the face.
TEST(EdmMesh, MatchesReferencePeriodicMeshFloor2D) {
    MeshGas m;
    m.n = 30;
    m.inner = 3;
    m.periodic = true;
    m.seed = 6;
    EdmSettings s;
    s.tcTime = 1e-3;
    compareWithReference<2>(meshGas<2>(m), s, 5000, false);
}

TEST(EdmMesh, MatchesReferencePeriodicMeshFloor3D) {
    MeshGas m;
    m.n = 27;
    m.inner = 2;
    m.periodic = true;
    m.seed = 7;
    EdmSettings s;
    s.tcTime = 1e-3;
    compareWithReference<3>(meshGas<3>(m), s, 2500, false);
}

// ---- a flat mesh is its plane ----------------------------------------------------------------------------------

/// A ball in the box [0, L] (plane side walls and ceiling) bouncing elastically on a floor that is the plane y = 0
/// (2D) or z = 0 (3D), or a flat mesh in it (3D: the example incline's 1600 jittered triangles; 2D: 120 collinear
/// segments of unequal lengths): the times of its collisions and where it ends.
template <int D>
std::vector<double> bounces(bool mesh, bool rough, const Vec<D>& x0, const Vec<D>& v0, double tEnd, Vec<D>* end) {
    World<D> w;
    w.contact = rough ? edmContact(1.0, 0.4, 0.3) : edmContact(1.0);
    w.domain.lo = Vec<D>::zero();
    if constexpr (D == 3)
        w.domain.hi = Vec<3>{{0.1, 0.05, 0.03}};
    else
        w.domain.hi = Vec<2>{{0.1, 0.03}};
    w.domain.gravity = Vec<D>::zero();
    w.domain.gravity[D - 1] = -9.81;
    for (int k = 0; k < D; ++k) {
        Vec<D> n = Vec<D>::zero();
        n[k] = 1;
        if (k < D - 1 || !mesh) w.walls.push_back(Wall<D>::plane(w.domain.lo, n, Vec<D>::zero(), 0));
        w.walls.push_back(Wall<D>::plane(w.domain.hi, n * -1.0, Vec<D>::zero(), 0));
    }
    if (mesh) {
        std::vector<Corners<D>> floor;
        if constexpr (D == 3) {
            for (const auto& t : readStl(std::string(HAET_SOURCE_DIR) + "/examples/meshes/incline.stl").triangles)
                floor.push_back(t);
        } else {
            Rng rng(17, 3);
            double x = -0.005;
            while (x < 0.105) {
                const double next = x + rng.uniform(0.0005, 0.0012);
                floor.push_back({Vec<2>{{x, 0}}, Vec<2>{{next, 0}}});
                x = next;
            }
        }
        w.surfaces.push_back(meshWall<D>(floor, static_cast<int>(w.walls.size())));
    }
    w.particles.add(x0, v0, Ang<D>::zero(), 0.002, 2500, 0, 0);
    EdmSettings s;
    s.tcModel = false;
    EdmEngine<D> eng(w, s);
    std::vector<double> times;
    eng.setObserver([&](const EdmCollision<D>& c) { times.push_back(c.time); });
    eng.advanceTo(tEnd);
    *end = w.particles.x[0];
    return times;
}

template <int D>
void flatMeshIsThePlane(bool rough, const Vec<D>& x0, const Vec<D>& v0, double tEnd, std::size_t least) {
    Vec<D> endPlane, endMesh;
    const std::vector<double> plane = bounces<D>(false, rough, x0, v0, tEnd, &endPlane);
    const std::vector<double> mesh = bounces<D>(true, rough, x0, v0, tEnd, &endMesh);
    ASSERT_EQ(mesh.size(), plane.size()) << "a collision more or less where elements meet";
    EXPECT_GE(plane.size(), least);
    double worst = 0;
    for (std::size_t k = 0; k < plane.size(); ++k) worst = std::max(worst, std::abs(mesh[k] - plane[k]) / plane[k]);
    EXPECT_LT(worst, 1e-12);
    EXPECT_LT(norm(endMesh - endPlane), 1e-12);
    ::testing::Test::RecordProperty("max_relative_time_difference", std::to_string(worst));
}

TEST(EdmMesh, FlatTriangleFloorIsThePlane) {
    // Hopping across the incline's 1600 triangles, smooth and rough.
    flatMeshIsThePlane<3>(false, Vec<3>{{0.013, 0.021, 0.012}}, Vec<3>{{0.31, 0.17, 0.05}}, 2.0, 25);
    flatMeshIsThePlane<3>(true, Vec<3>{{0.013, 0.021, 0.012}}, Vec<3>{{0.31, 0.17, 0.05}}, 2.0, 25);
}

TEST(EdmMesh, FlatSegmentFloorIsThePlane) {
    flatMeshIsThePlane<2>(false, Vec<2>{{0.013, 0.012}}, Vec<2>{{0.37, 0.05}}, 2.0, 25);
    flatMeshIsThePlane<2>(true, Vec<2>{{0.013, 0.012}}, Vec<2>{{0.37, 0.05}}, 2.0, 25);
}

// Dropped onto a vertex shared by six triangles, or onto an edge between two, or onto a segment end shared by two
// segments: one collision per landing, as on the plane, not one per element (the second element finds the ball
// receding from the same feature: no event, docs/physics.md D.6), and it bounces straight up.
TEST(EdmMesh, SharedEdgesAndVerticesCollideOnce) {
    const auto tris = readStl(std::string(HAET_SOURCE_DIR) + "/examples/meshes/incline.stl").triangles;
    const auto& p = tris[2 * (20 * 17 + 9)];  // a cell away from the rim
    const double a = 0.002;
    for (const Vec<3>& q : {p[0], p[1], p[2], (p[0] + p[1]) * 0.5, (p[1] + p[2]) * 0.5}) {
        SCOPED_TRACE(::testing::Message() << "at " << q[0] << ", " << q[1]);
        const Vec<3> x0 = q + Vec<3>{{0, 0, a + 0.004}};
        flatMeshIsThePlane<3>(false, x0, Vec<3>{}, 1.0, 15);
        Vec<3> end;
        bounces<3>(true, false, x0, Vec<3>{}, 1.0, &end);
        EXPECT_LT(std::abs(end[0] - x0[0]) + std::abs(end[1] - x0[1]), 1e-12);
    }
    // 2D: onto the join of two segments of the floor (the ends as bounces<2> draws them).
    Rng rng(17, 3);
    double join = -0.005;
    while (join < 0.05) join += rng.uniform(0.0005, 0.0012);
    flatMeshIsThePlane<2>(false, Vec<2>{{join, a + 0.004}}, Vec<2>{}, 1.0, 15);
}

// ---- energy books of a pure event-driven run ------------------------------------------------------------------

template <int D>
double totalEnergy(const World<D>& w) {
    double e = 0;
    const Particles<D>& p = w.particles;
    for (std::size_t i = 0; i < p.size(); ++i)
        e += 0.5 * p.mass[i] * norm2(p.v[i]) + 0.5 * p.inertia(i) * norm2(p.w[i]) -
             p.mass[i] * dot(w.domain.gravity, p.x[i]);
    return e;
}

/// A gas in a box of mesh walls with random elements inside, under gravity: kinetic + rotational + potential energy
/// minus what the collisions dissipated stays the initial energy, to round-off (elastic: the energy itself), and no
/// particle leaves the box or passes into an element.
template <int D>
void energyBooks(double e) {
    MeshGas m;
    m.n = D == 3 ? 64 : 49;
    m.e = e;
    m.mu = e == 1 ? 0.0 : 0.3;
    m.beta0 = e == 1 ? -1.0 : 0.4;
    m.seed = 11;
    World<D> w = meshGas<D>(m);
    const std::size_t n = w.particles.size();
    EdmSettings s;
    s.tcModel = e < 1;
    s.tcTime = 1e-3;
    EdmEngine<D> eng(w, s);
    const double e0 = totalEnergy(w);
    double scale = 0;
    for (std::size_t i = 0; i < n; ++i) scale += w.particles.mass[i] * norm(w.domain.gravity) * m.L;
    for (int k = 1; k <= 10; ++k) {
        eng.advanceTo(k * (e < 1 ? 1.0 : 5.0));  // a dissipative gas settles into a hopping bed: more events
        const double books = e0 - totalEnergy(w) - eng.stats().dissipated;
        EXPECT_LT(std::abs(books), 1e-12 * scale) << "t = " << w.time;
        if (e == 1) {
            EXPECT_LT(std::abs(eng.stats().dissipated), 1e-12 * scale);
        }
    }
    ASSERT_EQ(w.particles.size(), n);
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double r = w.particles.radius[i];
        worst = std::max(worst, (r - meshDistance(w, w.particles.x[i])) / r);
        for (int k = 0; k < D; ++k) EXPECT_TRUE(w.particles.x[i][k] > 0 && w.particles.x[i][k] < m.L) << i;
    }
    EXPECT_LT(worst, 1e-9) << "a particle overlaps a mesh element";
    EXPECT_GT(eng.stats().wallCollisions, D == 3 ? 2000u : 300u);
    EXPECT_GT(eng.stats().pairCollisions, 500u);
}

TEST(EdmMesh, ElasticRunConservesEnergy2D) { energyBooks<2>(1.0); }
TEST(EdmMesh, ElasticRunConservesEnergy3D) { energyBooks<3>(1.0); }
TEST(EdmMesh, DissipativeRunBalancesItsBooks3D) { energyBooks<3>(0.7); }

// ---- what the engine refuses ----------------------------------------------------------------------------------

TEST(EdmMesh, WallsItCannotPredictAreRefusedUnlessGuarded) {
    World<2> w = meshGas<2>(MeshGas{});
    auto refused = [&](const World<2>& world, const std::string& what) {
        World<2> copy = world;
        try {
            EdmEngine<2> eng(copy, EdmSettings{});
            ADD_FAILURE() << "no error: " << what;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
        EdmSettings guarded;
        guarded.guardedWalls = true;
        copy = world;
        const EdmEngine<2> eng(copy, guarded);
        EXPECT_EQ(eng.meshWalls().size(), w.surfaces[0].elementCount() + w.surfaces[1].elementCount());
    };
    World<2> arc = w;
    SurfaceWall<2> drum;
    drum.kind = SurfaceKind::Arc;
    drum.centre = Vec<2>::filled(5);
    drum.radius = 5;
    drum.angle1 = 2 * testing::kPiEdm;
    drum.id = 2;
    arc.surfaces.push_back(drum);
    refused(arc, "wall 3 is curved");
    World<2> turning = w;
    SurfaceWall<2> blade = meshWall<2>({{Vec<2>{{4, 4}}, Vec<2>{{6, 4}}}}, 2);
    blade.motion.omega = 1;
    blade.motion.centre = Vec<2>::filled(5);
    turning.surfaces.push_back(blade);
    refused(turning, "wall 3 moves");
    World<2> shaken = w;
    Wall<2> floor = Wall<2>::plane(Vec<2>{}, Vec<2>{{0, 1}}, Vec<2>{}, 0);
    floor.amplitude = Vec<2>{{0, 0.01}};
    floor.frequency = 20;
    shaken.walls.push_back(floor);
    refused(shaken, "oscillates");
}

// ---- the scenario's walls and the methods ---------------------------------------------------------------------

std::string wallScene(int dim, const std::string& method, const std::string& walls) {
    const std::string lo = dim == 2 ? "[0, 0]" : "[0, 0, 0]", hi = dim == 2 ? "[1, 1]" : "[1, 1, 1]";
    return "name = \"w\"\ndimension = " + std::to_string(dim) + "\nmethod = \"" + method +
           "\"\nduration = 0.1\n[domain]\nlo = " + lo + "\nhi = " + hi +
           "\n[materials.m]\ndensity = 1000\nrestitution = 0.5\nfriction = 0.3\n[contact]\nnormal = "
           "\"linear\"\nduration = 1e-4\n" +
           walls;
}

std::string wall(const std::string& keys) { return "[[walls]]\nmaterial = \"m\"\n" + keys; }

const std::string kFloor2 = wall("point = [0, 0]\nnormal = [0, 1]\n");
const std::string kSegment = wall("type = \"segment\"\npoints = [[0.1, 0.5], [0.9, 0.4]]\n");
const std::string kCircle = wall("type = \"circle\"\ncenter = [0.5, 0.5]\nradius = 0.4\n");
const std::string kMesh =
    wall("type = \"mesh\"\nvertices = [[0, 0, 0.1], [1, 0, 0.1], [0, 1, 0.2]]\ntriangles = [[0, 1, 2]]\n");

void expectRejected(const std::string& text, const std::string& key, const std::string& what) {
    try {
        parseScenario(text, "walls.toml");
        ADD_FAILURE() << "no error for " << key;
    } catch (const ScenarioError& e) {
        const std::string msg = e.what();
        EXPECT_EQ(e.key(), key) << msg;
        EXPECT_NE(msg.find("walls.toml:"), std::string::npos) << msg;
        EXPECT_NE(msg.find(what), std::string::npos) << msg;
        EXPECT_NE(msg.find("method = \"haet\""), std::string::npos) << msg;
        EXPECT_NE(msg.find("method = \"tdm\""), std::string::npos) << msg;
    }
}

TEST(EdmMeshInput, EventDrivenRunsTakePlanesAndStaticMeshes) {
    // Accepted: planes at a constant velocity, static segments, polylines, meshes, rectangles.
    EXPECT_NO_THROW(parseScenario(
        wallScene(2, "edm",
                  wall("point = [0, 1]\nnormal = [0, -1]\nvelocity = [0, -0.1]\n") + kSegment +
                      wall("type = \"polyline\"\npoints = [[0.1, 0.2], [0.5, 0.1], [0.9, 0.2]]\nclosed = true\n")),
        "walls.toml"));
    EXPECT_NO_THROW(parseScenario(
        wallScene(3, "edm",
                  kMesh + wall("type = \"rectangle\"\ncenter = [0.5, 0.5, 0.5]\nedges = [[0.2, 0, 0], [0, 0.2, 0]]\n")),
        "walls.toml"));
    // Rejected, naming the wall and the key, saying what to use instead.
    expectRejected(wallScene(2, "edm", kFloor2 + kCircle), "walls[2].type", "\"circle\" wall is curved");
    expectRejected(wallScene(2, "edm", wall("type = \"arc\"\ncenter = [0.5, 0.5]\nradius = 0.4\nangles = [0, 90]\n")),
                   "walls[1].type", "\"arc\" wall is curved");
    expectRejected(
        wallScene(3, "edm",
                  wall("type = \"cylinder\"\nbase = [0.5, 0.5, 0]\naxis = [0, 0, 1]\nlength = 1\nradius = 0.4\n")),
        "walls[1].type", "\"cylinder\" wall is curved");
    expectRejected(
        wallScene(3, "edm", wall("type = \"disc\"\ncenter = [0.5, 0.5, 0.5]\nnormal = [0, 0, 1]\nradius = 0.3\n")),
        "walls[1].type", "\"disc\" wall is curved");
    expectRejected(
        wallScene(2, "edm",
                  wall("point = [0, 0]\nnormal = [0, 1]\noscillation = { amplitude = [0, 0.01], frequency = 20 }\n")),
        "walls[1].oscillation", "oscillating plane");
    expectRejected(wallScene(2, "edm",
                             kFloor2 + wall("type = \"segment\"\npoints = [[0.1, 0.5], [0.9, 0.5]]\n"
                                            "rotation = { center = [0.5, 0.5], omega = 2 }\n")),
                   "walls[2].rotation", "moving wall");
    expectRejected(wallScene(3, "edm",
                             wall("type = \"mesh\"\nvertices = [[0, 0, 0.1], [1, 0, 0.1], [0, 1, 0.2]]\n"
                                  "triangles = [[0, 1, 2]]\nvelocity = [0, 0, 0.1]\n")),
                   "walls[1].velocity", "moving wall");
    // The hybrid and the time-driven engine take them all.
    for (const char* method : {"haet", "tdm"}) {
        EXPECT_NO_THROW(parseScenario(wallScene(2, method, kFloor2 + kCircle), "walls.toml")) << method;
        EXPECT_NO_THROW(parseScenario(
            wallScene(
                2, method,
                wall("point = [0, 0]\nnormal = [0, 1]\noscillation = { amplitude = [0, 0.01], frequency = 20 }\n") +
                    wall("type = \"segment\"\npoints = [[0.1, 0.5], [0.9, 0.5]]\n"
                         "rotation = { center = [0.5, 0.5], omega = 2 }\n")),
            "walls.toml"))
            << method;
    }
}

// The example silo of segments, shortened and thinned (its header lists the overrides), event-driven: particles
// pour through the orifice onto the floor, none lost, none through a segment.
TEST(EdmMeshInput, HopperOfSegmentsRunsEventDriven) {
    const Scenario sc =
        loadScenario(std::string(HAET_SOURCE_DIR) + "/examples/hopper2d.toml", {"method=edm", "insert[1].count=300"});
    World<2> w = buildWorld<2>(sc);
    const std::size_t n = w.particles.size();
    ASSERT_EQ(n, 300u);
    EdmSettings s = edmSettings(sc);
    EdmEngine<2> eng(w, s);
    EXPECT_GT(eng.meshWalls().size(), 3u);
    eng.advanceTo(0.3);
    ASSERT_EQ(w.particles.size(), n);
    double worst = 0;
    std::size_t below = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double r = w.particles.radius[i];
        worst = std::max(worst, (r - meshDistance(w, w.particles.x[i])) / r);
        below += w.particles.x[i][1] < 0.3;
    }
    EXPECT_LT(worst, 1e-9) << "a particle overlaps a segment";
    EXPECT_GT(below, 10u) << "particles pour through the orifice";
    EXPECT_GT(eng.stats().wallCollisions, 1000u);
}

}  // namespace
}  // namespace haet
