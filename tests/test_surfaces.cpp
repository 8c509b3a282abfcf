// Walls of any shape (docs/physics.md H): the closest points against independent twins, the contact rule on flat,
// convex and concave meshes, the broad phase against its brute-force twin, and whole runs: a ball rolling down a mesh
// of many triangles on the path it takes on the plane they make, a disk on collinear segments, a rotating drum, the
// load of a bed on its floor.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>

#include "geometry/closest.hpp"
#include "geometry/surface.hpp"
#include "neighbor/surface_list.hpp"
#include "run/runner.hpp"
#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world_util.hpp"

namespace haet {
namespace {

constexpr double kPi = 3.141592653589793;

Vec<3> v3(double x, double y, double z) { return Vec<3>{{x, y, z}}; }

/// All contacts of a centre with a wall, merged (as the kernel takes them).
template <int D>
std::vector<SurfaceHit<D>> hitsOf(const SurfaceWall<D>& w, const Vec<D>& x, double reach) {
    std::vector<SurfaceHit<D>> h;
    for (std::size_t e = 0; e < w.elementCount(); ++e)
        w.contacts(e, x, reach, [&](const SurfaceHit<D>& s) { h.push_back(s); });
    h.resize(static_cast<std::size_t>(mergeHits(h.data(), static_cast<int>(h.size()))));
    return h;
}

TEST(Closest, TriangleMatchesFaceOrEdgeTwin) {
    // Twin: the projection onto the plane when it falls inside, else the nearest of the three edges' points.
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int k = 0; k < 20000; ++k) {
        const Vec<3> a = v3(u(rng), u(rng), u(rng)), b = v3(u(rng), u(rng), u(rng)), c = v3(u(rng), u(rng), u(rng));
        const Vec<3> x = v3(2 * u(rng), 2 * u(rng), 2 * u(rng));
        const ClosestPoint<3> got = closestOnTriangle(x, a, b, c);
        Vec<3> n = cross(b - a, c - a);
        n *= 1 / norm(n);
        const Vec<3> proj = x - n * dot(n, x - a);
        auto inside = [&](const Vec<3>& p, const Vec<3>& q) { return dot(cross(q - p, proj - p), n) >= 0; };
        Vec<3> want;
        if (inside(a, b) && inside(b, c) && inside(c, a)) {
            want = proj;
        } else {
            want = closestOnSegment<3>(x, a, b).point;
            for (const Vec<3>& q : {closestOnSegment<3>(x, b, c).point, closestOnSegment<3>(x, c, a).point})
                if (norm(x - q) < norm(x - want)) want = q;
        }
        ASSERT_NEAR(norm(x - got.point), norm(x - want), 1e-12) << k;
    }
}

/// A square [0, L]^2 at height z0 cut into an n x n grid, each cell into two triangles, interior vertices moved at
/// random within the plane (so edges run in every direction).
SurfaceWall<3> flatMesh(double L, int n, double z0, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    std::vector<Vec<3>> v((n + 1) * (n + 1));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const bool inner = i > 0 && i < n && j > 0 && j < n;
            const double h = L / n;
            v[j * (n + 1) + i] = v3(i * h + (inner ? u(rng) * h : 0), j * h + (inner ? u(rng) * h : 0), z0);
        }
    std::vector<std::array<Vec<3>, 3>> tris;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
            tris.push_back({v[a], v[b], v[c]});
            tris.push_back({v[a], v[c], v[d]});
        }
    SurfaceWall<3> w;
    buildMesh<3>(w, tris);
    return w;
}

TEST(SurfaceContact, FlatMeshGivesOneContactLikeItsPlane) {
    const SurfaceWall<3> w = flatMesh(1.0, 8, 0.0, 5);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.05, 0.95);
    int vertexNear = 0;
    for (int k = 0; k < 20000; ++k) {
        Vec<3> x = v3(u(rng), u(rng), 0.01 + 0.02 * u(rng));
        if (k % 4 == 0) x = w.vertices[static_cast<std::size_t>(k / 4) % w.vertices.size()] + v3(1e-9, -2e-9, 0.02);
        vertexNear += k % 4 == 0;
        const auto h = hitsOf(w, x, 0.05);
        ASSERT_EQ(h.size(), 1u) << "at " << x[0] << " " << x[1] << " " << x[2];
        EXPECT_NEAR(h[0].distance, x[2], 1e-15);
        EXPECT_NEAR(h[0].normal[2], 1.0, 1e-12);
    }
    EXPECT_GT(vertexNear, 0);
}

TEST(SurfaceContact, ConcaveCornerOnePerFaceConvexRidgeOnce) {
    // Two faces at right angles along the y axis: floor z = 0 (x > 0) and wall x = 0 (z > 0): concave seen from
    // x, z > 0, convex from below-behind.
    SurfaceWall<3> w;
    buildMesh<3>(w, {{v3(0, 0, 0), v3(1, 0, 0), v3(1, 1, 0)},
                     {v3(0, 0, 0), v3(1, 1, 0), v3(0, 1, 0)},
                     {v3(0, 0, 0), v3(0, 1, 0), v3(0, 1, 1)},
                     {v3(0, 0, 0), v3(0, 1, 1), v3(0, 0, 1)}});
    const auto corner = hitsOf(w, v3(0.01, 0.5, 0.01), 0.02);
    ASSERT_EQ(corner.size(), 2u);
    EXPECT_NEAR(corner[0].distance, 0.01, 1e-15);
    EXPECT_NEAR(corner[1].distance, 0.01, 1e-15);
    // Over the ridge (x < 0, z < 0): one contact with the edge, along the bisector.
    const auto ridge = hitsOf(w, v3(-0.01, 0.5, -0.01), 0.05);
    ASSERT_EQ(ridge.size(), 1u);
    EXPECT_NEAR(ridge[0].distance, 0.01 * std::sqrt(2.0), 1e-15);
    // Below the floor, beyond the ridge's region: the floor's face only (x > 0 side).
    const auto below = hitsOf(w, v3(0.003, 0.5, -0.01), 0.05);
    ASSERT_EQ(below.size(), 1u);
    EXPECT_NEAR(below[0].normal[2], -1.0, 1e-12);
}

TEST(SurfaceContact, CollinearSegmentsOneContactVOneEach) {
    SurfaceWall<2> flat;
    buildMesh<2>(flat, {{Vec<2>{{0, 0}}, Vec<2>{{1, 0}}}, {Vec<2>{{1, 0}}, Vec<2>{{2, 0}}}});
    for (double x : {0.5, 1.0, 1.0 + 1e-12, 1.0 - 1e-12, 1.3}) {
        const auto h = hitsOf(flat, Vec<2>{{x, 0.01}}, 0.02);
        ASSERT_EQ(h.size(), 1u) << x;
        EXPECT_NEAR(h[0].distance, 0.01, 1e-15);
    }
    SurfaceWall<2> vee;  // a V opening upward: a disk at its bottom touches both arms
    buildMesh<2>(vee, {{Vec<2>{{-1, 1}}, Vec<2>{{0, 0}}}, {Vec<2>{{0, 0}}, Vec<2>{{1, 1}}}});
    EXPECT_EQ(hitsOf(vee, Vec<2>{{0, 0.02}}, 0.02).size(), 2u);
    EXPECT_EQ(hitsOf(vee, Vec<2>{{0, -0.01}}, 0.02).size(), 1u);  // below the tip: the vertex once
}

TEST(SurfaceContact, CylinderInsideAndCorner) {
    SurfaceWall<3> c;
    c.kind = SurfaceKind::Cylinder;
    c.centre = v3(0, 0, 0);
    c.axis = v3(0, 0, 1);
    c.radius = c.radius1 = 1;
    c.length = 2;
    c.cap0 = true;
    const auto mid = hitsOf(c, v3(0.9, 0, 1), 0.2);
    ASSERT_EQ(mid.size(), 1u);
    EXPECT_NEAR(mid[0].distance, 0.1, 1e-15);
    EXPECT_NEAR(mid[0].normal[0], -1, 1e-15);
    const auto corner = hitsOf(c, v3(0, 0.95, 0.05), 0.1);  // in the corner of mantle and base: both
    ASSERT_EQ(corner.size(), 2u);
    const auto outside = hitsOf(c, v3(1.05, 0, -0.05), 0.1);  // beyond the rim, outside: the rim once
    ASSERT_EQ(outside.size(), 1u);
    EXPECT_NEAR(outside[0].distance, 0.05 * std::sqrt(2.0), 1e-14);
}

/// The total overlap of a ball of radius a at x with a wall: what its normal force grows with.
template <int D>
double overlapAt(const SurfaceWall<D>& w, const Vec<D>& x, double a) {
    double s = 0;
    for (const SurfaceHit<D>& h : hitsOf(w, x, a)) s += a - h.distance;
    return s;
}

TEST(SurfaceContact, ForceContinuousAcrossEdgesAndVertices) {
    // A ball resting on a convex ridge (two faces 20 degrees apart), on a flat mesh across an edge and over a vertex,
    // and on a concave fold: moved across in small steps, its overlap changes by at most a few times the step (no
    // jump where the contact passes from a face to an edge, a vertex or the next face).
    const double a = 0.01, t = std::tan(10 * kPi / 180);
    SurfaceWall<3> ridge, fold;
    buildMesh<3>(ridge, {{v3(-1, -1, -t), v3(0, -1, 0), v3(0, 1, 0)},
                         {v3(-1, -1, -t), v3(0, 1, 0), v3(-1, 1, -t)},
                         {v3(0, -1, 0), v3(1, -1, -t), v3(1, 1, -t)},
                         {v3(0, -1, 0), v3(1, 1, -t), v3(0, 1, 0)}});
    buildMesh<3>(fold, {{v3(-1, -1, t), v3(0, -1, 0), v3(0, 1, 0)},
                        {v3(-1, -1, t), v3(0, 1, 0), v3(-1, 1, t)},
                        {v3(0, -1, 0), v3(1, -1, t), v3(1, 1, t)},
                        {v3(0, -1, 0), v3(1, 1, t), v3(0, 1, 0)}});
    const SurfaceWall<3> flat = flatMesh(1.0, 4, 0.0, 21);
    const Vec<3> vtx = flat.vertices[7];  // an inner vertex of the flat mesh
    struct Path {
        const SurfaceWall<3>* w;
        Vec<3> from, to;
    };
    const Path paths[] = {{&ridge, v3(-0.03, 0.1, 0.995 * a), v3(0.03, 0.1, 0.995 * a)},
                          {&fold, v3(-0.03, 0.2, 0.995 * a), v3(0.03, 0.2, 0.995 * a)},
                          {&flat, vtx + v3(-0.02, -0.013, 0.995 * a), vtx + v3(0.02, 0.017, 0.995 * a)}};
    for (const Path& p : paths) {
        const int n = 20000;
        const double step = norm(p.to - p.from) / n;
        double prev = overlapAt(*p.w, p.from, a), worst = 0;
        for (int k = 1; k <= n; ++k) {
            const double cur = overlapAt(*p.w, p.from + (p.to - p.from) * (double(k) / n), a);
            worst = std::max(worst, std::abs(cur - prev) / step);
            prev = cur;
        }
        EXPECT_LT(worst, 2.0) << "largest slope of the overlap along the path";
    }
}

TEST(SurfaceList, CellsMatchBruteForce) {
    // Particles near a mesh floor, a cylinder turned by a pose and a polyline-free 3D scene; then a 2D one.
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    Particles<3> p;
    for (int k = 0; k < 3000; ++k)
        p.add(v3(u(rng), u(rng), u(rng) * 0.5), Vec<3>::zero(), Ang<3>::zero(), 0.005 + 0.01 * u(rng), 1000, 0,
              static_cast<std::uint64_t>(k));
    std::vector<SurfaceWall<3>> walls{flatMesh(1.0, 12, 0.02, 1)};
    SurfaceWall<3> c;
    c.kind = SurfaceKind::Cylinder;
    c.centre = v3(0.5, 0.5, 0);
    c.axis = v3(0, 0, 1);
    c.radius = 0.3;
    c.radius1 = 0.45;
    c.length = 0.5;
    c.cap1 = true;
    c.motion.centre = v3(0.5, 0.5, 0.2);
    c.motion.axis = v3(1, 0, 0);
    c.motion.omega = 0.7;
    walls.push_back(c);
    std::vector<Pose<3>> poses{walls[0].motion.at(0.4), walls[1].motion.at(0.4)};
    Domain<3> dom;
    dom.lo = v3(0, 0, 0);
    dom.hi = v3(1, 1, 0.5);
    SurfaceCandidates fast, brute;
    buildSurfaceCandidates(p, p.size(), dom, walls, poses, 0.004, fast);
    buildSurfaceCandidatesBrute(p, p.size(), walls, poses, 0.004, brute);
    EXPECT_EQ(fast.first, brute.first);
    EXPECT_EQ(fast.wall, brute.wall);
    EXPECT_EQ(fast.element, brute.element);
    EXPECT_GT(fast.size(), 300u);
}

/// A ball (disk) started at rest on an incline through the origin rolls down it: the incline is a plane wall, or the
/// wall of any shape that surface(n, t) makes in the same plane (n its normal, t uphill). Returns the centre's
/// positions every 500 steps.
template <int D, class Surface>
std::vector<Vec<D>> rollDown(double thetaDeg, double a, double density, Surface&& surface) {
    const double theta = thetaDeg * kPi / 180, tc = 1e-3;
    Scenario sc = testing::linearScenario(D, 0.5, tc, 0.5, TangentialLaw::Spring);
    World<D> w;
    w.domain = testing::openBox<D>(0.5);
    w.domain.gravity[D - 1] = -9.81;
    Vec<D> n, t;
    n[0] = -std::sin(theta);
    n[D - 1] = std::cos(theta);
    t[0] = std::cos(theta);
    t[D - 1] = std::sin(theta);
    w.particles.add(n * (a * 0.999) + t * 0.2, Vec<D>::zero(), Ang<D>::zero(), a, density, 0, 0);
    if (std::optional<SurfaceWall<D>> s = surface(n, t))
        w.surfaces.push_back(*s);
    else
        w.walls.push_back(Wall<D>::plane(Vec<D>::zero(), n, Vec<D>::zero(), 0));
    w.contact = buildContactSetup<D>(sc, testing::statsOf(w.particles, 1));
    TdmSettings s;
    s.dt = tc / 50;
    s.skin = a;
    s.sortEvery = 0;
    TdmEngine<D> eng(w, s);
    std::vector<Vec<D>> path;
    for (int k = 0; k < 30; ++k) {
        for (int q = 0; q < 500; ++q) eng.step();
        path.push_back(w.particles.x[0]);
    }
    return path;
}

/// The largest distance between two paths relative to the distance travelled on the first, which must exceed `min`.
template <int D>
void expectSamePath(const std::vector<Vec<D>>& plane, const std::vector<Vec<D>>& other, double min) {
    ASSERT_EQ(plane.size(), other.size());
    double travelled = 0;
    for (std::size_t k = 0; k < plane.size(); ++k) {
        travelled = norm(plane[k] - plane.front());
        EXPECT_LE(norm(other[k] - plane[k]), 1e-9 * std::max(travelled, 0.01)) << "sample " << k;
    }
    EXPECT_GT(travelled, min);
}

TEST(SurfaceRun, BallOnMeshInclineFollowsThePlanePath) {
    auto none = [](const Vec<3>&, const Vec<3>&) { return std::optional<SurfaceWall<3>>(); };
    auto mesh = [](const Vec<3>&, const Vec<3>& t) {
        // flatMesh in the incline's frame: 60 x 60 cells over 0.6 m x 0.6 m.
        const SurfaceWall<3> flat = flatMesh(0.6, 60, 0.0, 9);
        std::vector<std::array<Vec<3>, 3>> tris;
        for (const auto& el : flat.elements) {
            std::array<Vec<3>, 3> tri;
            for (int k = 0; k < 3; ++k) {
                const Vec<3>& q = flat.vertices[el[k]];
                tri[k] = t * (q[0] - 0.3) + v3(0, 1, 0) * (q[1] - 0.3);
            }
            tris.push_back(tri);
        }
        SurfaceWall<3> inc;
        buildMesh<3>(inc, tris);
        return std::optional<SurfaceWall<3>>(inc);
    };
    // Over 0.1 m: across dozens of triangle edges.
    expectSamePath(rollDown<3>(20, 0.005, 2500, none), rollDown<3>(20, 0.005, 2500, mesh), 0.1);
}

TEST(SurfaceRun, DiskOnCollinearSegmentsFollowsThePlanePath) {
    auto none = [](const Vec<2>&, const Vec<2>&) { return std::optional<SurfaceWall<2>>(); };
    auto segments = [](const Vec<2>&, const Vec<2>& t) {  // a vertex every 2 mm
        std::vector<std::array<Vec<2>, 2>> segs;
        for (int k = 0; k < 150; ++k) segs.push_back({t * (-0.05 + 0.002 * k), t * (-0.05 + 0.002 * (k + 1))});
        SurfaceWall<2> line;
        buildMesh<2>(line, segs);
        return std::optional<SurfaceWall<2>>(line);
    };
    expectSamePath(rollDown<2>(25, 0.004, 2.5, none), rollDown<2>(25, 0.004, 2.5, segments), 0.1);
}

TEST(SurfaceRun, RotatingDrumDragsItsParticleToTheWallSpeed) {
    // No gravity: a disk sliding along the inside of a drum (radius R, turning at omega) is pressed to it by its own
    // motion; friction brings its contact point to the wall's speed omega R and keeps it there.
    const double tc = 2e-4, R = 0.05, a = 0.004, omega = 20;
    Scenario sc = testing::linearScenario(2, 0.7, tc, 0.8, TangentialLaw::Spring);
    World<2> w;
    w.domain = testing::openBox<2>(0.1);
    w.particles.add(Vec<2>{{0, -(R - a)}}, Vec<2>{{0.3, 0}}, Ang<2>::zero(), a, 2.5, 0, 0);
    SurfaceWall<2> drum;
    drum.kind = SurfaceKind::Arc;
    drum.radius = R;
    drum.angle1 = 2 * kPi;
    drum.motion.omega = omega;
    w.surfaces.push_back(drum);
    w.contact = buildContactSetup<2>(sc, testing::statsOf(w.particles, 1));
    TdmSettings s;
    s.dt = tc / 50;
    s.skin = a;
    s.sortEvery = 0;
    TdmEngine<2> eng(w, s);
    eng.advanceTo(0.3);
    const Particles<2>& p = w.particles;
    const Vec<2> out = p.x[0] * (1 / norm(p.x[0]));
    const Vec<2> contact = out * R;
    const Vec<2> vContact = p.v[0] + cross(p.w[0], contact - p.x[0]);
    const Vec<2> vWall = cross(Vec<1>{{omega}}, contact);
    EXPECT_LT(norm(vContact - vWall), 1e-3 * omega * R);
    EXPECT_NEAR(norm(vWall), omega * R, 1e-12);
    EXPECT_EQ(eng.wallContacts(), 1u);
    // The drum's torque on the particle keeps it turning: the particle's load on the drum is a force along it.
    const auto load = eng.surfaceLoad(0);
    EXPECT_GT(norm(load.force), 0);
}

TEST(SurfaceRun, SettledBedLoadsTheFloorWithItsWeight) {
    // A bed of disks on a floor of collinear segments, periodic sideways: at rest the floor carries the weight.
    const double tc = 2e-4, L = 0.04;
    Scenario sc = testing::linearScenario(2, 0.2, tc, 0.5, TangentialLaw::Spring);
    World<2> w;
    w.domain.lo = Vec<2>{{0, 0}};
    w.domain.hi = Vec<2>{{L, 0.05}};
    w.domain.periodic = {true, false};
    w.domain.gravity = Vec<2>{{0, -9.81}};
    std::mt19937_64 rng(2);
    std::uniform_real_distribution<double> u(0.0016, 0.002);
    int id = 0;
    for (int row = 0; row < 8; ++row)
        for (int col = 0; col < 10; ++col)
            w.particles.add(Vec<2>{{0.002 + 0.004 * col + 0.001 * (row % 2), 0.003 + 0.0042 * row}}, Vec<2>::zero(),
                            Ang<2>::zero(), u(rng), 2.5, 0, static_cast<std::uint64_t>(id++));
    std::vector<std::array<Vec<2>, 2>> segs;
    for (int k = 0; k < 12; ++k) segs.push_back({Vec<2>{{-0.004 + 0.004 * k, 0}}, Vec<2>{{0.004 * k, 0}}});
    SurfaceWall<2> floor;
    buildMesh<2>(floor, segs);
    floor.name = "floor";
    w.surfaces.push_back(floor);
    w.contact = buildContactSetup<2>(sc, testing::statsOf(w.particles, 1));
    TdmSettings s;
    s.dt = tc / 50;
    s.skin = 0.0005;
    s.sortEvery = 0;
    TdmEngine<2> eng(w, s);
    eng.advanceTo(1.0);
    double weight = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i) weight += w.particles.mass[i] * 9.81;
    const auto load = eng.surfaceLoad(0);
    EXPECT_NEAR(load.force[1], -weight, 1e-6 * weight);
    // Sideways the bed is still ringing in its tangential springs (undamped, gamma_t = 0): small, not zero.
    EXPECT_NEAR(load.force[0], 0, 1e-3 * weight);
}

/// Loads a scene expecting a ScenarioError whose key is `key`.
void expectWallError(const std::string& text, const std::string& key, const std::string& what) {
    try {
        parseScenario(text, "walls.toml");
        ADD_FAILURE() << "no error for " << key;
    } catch (const ScenarioError& e) {
        EXPECT_EQ(e.key(), key) << e.what();
        EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("walls.toml:"), std::string::npos) << e.what();
    }
}

std::string scene(int dim, const std::string& method, const std::string& wall) {
    const std::string lo = dim == 2 ? "[0, 0]" : "[0, 0, 0]", hi = dim == 2 ? "[1, 1]" : "[1, 1, 1]";
    return "name = \"w\"\ndimension = " + std::to_string(dim) + "\nmethod = \"" + method +
           "\"\nduration = 0.1\n[domain]\nlo = " + lo + "\nhi = " + hi +
           "\n[materials.m]\ndensity = 1000\nrestitution = 0.5\nfriction = 0.3\n[contact]\nnormal = "
           "\"linear\"\nduration = 1e-4\n[[walls]]\nmaterial = \"m\"\n" +
           wall;
}

TEST(SurfaceInput, BadGeometryNamesTheKey) {
    expectWallError(scene(2, "tdm", "type = \"polyline\"\npoints = [[0, 0], [0.5, 0], [0.5, 0]]\n"), "walls[1].points",
                    "segment 2 has zero length");
    expectWallError(scene(2, "tdm", "type = \"segment\"\npoints = [[0, 0]]\n"), "walls[1].points", "exactly two");
    expectWallError(scene(3, "tdm",
                          "type = \"cylinder\"\nbase = [0.5, 0.5, 0]\naxis = [0, 0, 1]\nlength = 1\n"
                          "radius = 0\n"),
                    "walls[1].radius", "must be > 0");
    expectWallError(scene(3, "tdm",
                          "type = \"mesh\"\nvertices = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\n"
                          "triangles = [[0, 1, 2]]\n"),
                    "walls[1].triangles", "triangle 1 has zero area");
    expectWallError(scene(3, "tdm",
                          "type = \"mesh\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n"
                          "triangles = [[0, 1, 3]]\n"),
                    "walls[1].triangles", "vertex indices");
    expectWallError(scene(3, "tdm",
                          "type = \"mesh\"\nvertices = [[0, 0, nan], [1, 0, 0], [0, 1, 0]]\n"
                          "triangles = [[0, 1, 2]]\n"),
                    "walls[1].vertices", "finite");
    expectWallError(scene(3, "tdm", "type = \"segment\"\n"), "walls[1].type", "2D only");
    expectWallError(scene(2, "tdm", "type = \"box\"\n"), "walls[1].type", "must be one of");
    expectWallError(scene(2, "tdm", "type = \"circle\"\ncenter = [0.5, 0.5]\nradius = 0.4\nclosed = true\n"),
                    "walls[1].closed", "unknown key");
    expectWallError(scene(2, "tdm", "point = [0, 0]\nnormal = [0, 1]\nrotation = { center = [0, 0], omega = 1 }\n"),
                    "walls[1].rotation", "cannot rotate");
    expectWallError(scene(2, "tdm", "point = [0, 0]\nnormal = [0, 0]\n"), "walls[1].normal", "nonzero");
    expectWallError(scene(2, "edm", "type = \"circle\"\ncenter = [0.5, 0.5]\nradius = 0.4\n"), "walls[1].type",
                    "method = \"tdm\"");
    // The hybrid takes every wall (its guard hands particles near a curved one to its time-driven part).
    EXPECT_NO_THROW(
        parseScenario(scene(2, "haet", "type = \"circle\"\ncenter = [0.5, 0.5]\nradius = 0.4\n"), "walls.toml"));
    expectWallError(scene(2, "tdm", "type = \"arc\"\ncenter = [0.5, 0.5]\nradius = 0.4\nangles = [90, 10]\n"),
                    "walls[1].angles", "from < to");
    expectWallError(scene(3, "tdm", "type = \"mesh\"\nfile = \"no_such.stl\"\n"), "walls[1].file", "no_such.stl");
    expectWallError(scene(3, "tdm", "type = \"disc\"\ncenter = [5, 5, 5]\nnormal = [0, 0, 1]\nradius = 0.1\n"),
                    "walls[1].type", "entirely outside the domain");
    {
        // A truncated binary STL: its count says two triangles, the file holds one and a half.
        const std::string path = ::testing::TempDir() + "truncated.stl";
        std::ofstream f(path, std::ios::binary);
        std::string bytes(80, ' ');
        const std::uint32_t count = 2;
        bytes.append(reinterpret_cast<const char*>(&count), 4);
        bytes.append(75, '\0');
        f << bytes;
        f.close();
        expectWallError(scene(3, "tdm", "type = \"mesh\"\nfile = \"" + path + "\"\n"), "walls[1].file", "truncated");
    }
    // A huge normal is a direction, not an overflow.
    const Scenario ok = parseScenario(scene(2, "tdm", "point = [0, 0]\nnormal = [1e200, 1e200]\n"), "walls.toml");
    EXPECT_NEAR(ok.walls[0].normal[0], std::sqrt(0.5), 1e-15);
}

TEST(SurfaceInput, WallExamplesCheck) {
    // The scenes with walls of every kind load (meshes from their STL files) and `haet check` lists the walls.
    for (const char* name : {"hopper2d.toml", "silo3d.toml", "drum3d.toml", "mixer3d.toml"}) {
        const Scenario sc = loadScenario(std::string(HAET_SOURCE_DIR) + "/examples/" + name);
        std::ostringstream out;
        describeScenario(sc, out);
        EXPECT_NE(out.str().find("wall       1"), std::string::npos) << name << "\n" << out.str();
    }
    const Scenario silo = loadScenario(std::string(HAET_SOURCE_DIR) + "/examples/silo3d.toml");
    EXPECT_EQ(silo.walls[1].triangles.size(), 512u);
    EXPECT_NEAR(silo.walls[1].triangles[0][0][2], 0.016, 0.061);  // moved onto the hopper
    double zmin = 1;
    for (const auto& t : silo.walls[1].triangles)
        for (const auto& p : t) zmin = std::min(zmin, p[2]);
    EXPECT_NEAR(zmin, 0.016, 1e-9);
}

}  // namespace
}  // namespace haet
