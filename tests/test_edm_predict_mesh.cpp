// Event-time predictions against static segments and triangles (src/edm/predict_mesh.hpp, docs/physics.md D.8):
// long random runs against brute-force stepping of the distance (mesh_runs.hpp), the special cases of the root
// isolation (no gravity, gravity along an edge, grazing), the plane predictor of D.3 over a face, and the
// invalid-state rules of D.6.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "core/rng.hpp"
#include "edm/predict_mesh.hpp"
#include "io/stl.hpp"
#include "mesh_reference.hpp"
#include "mesh_runs.hpp"

namespace haet {
namespace {

using meshref::LD;

std::filesystem::path fs_path(const char* rel) { return std::filesystem::path(HAET_SOURCE_DIR) / rel; }

void print(const char* what, const meshref::RunStats& s) {
    std::printf(
        "%s: %d events (face %d, edge %d, vertex %d), %d grazing, %d at a region boundary; max |dt| %.2e s, "
        "as a distance %.2e m, max |d - a| %.2e m, max |n - grad d| %.2e\n",
        what, s.events, s.byFeature[1], s.byFeature[2], s.byFeature[3], s.grazing, s.mismatched, s.maxTimeError,
        s.maxDistError, s.maxGapError, s.maxNormalError);
}

TEST(EdmPredictMesh, TrianglesAgainstStepping) {
    const auto s = meshref::runAgainstStepping<3>(41, 400, 16, 1e-4);
    print("3D", s);
    EXPECT_EQ(s.events, 400);
    EXPECT_GT(s.byFeature[static_cast<int>(MeshFeature::Edge)], 10);
    EXPECT_GT(s.byFeature[static_cast<int>(MeshFeature::Vertex)], 2);
    EXPECT_LE(s.grazing, 4);
    EXPECT_LE(s.mismatched, 4);
}

TEST(EdmPredictMesh, SegmentsAgainstStepping) {
    const auto s = meshref::runAgainstStepping<2>(42, 400, 12, 1e-4);
    print("2D", s);
    EXPECT_EQ(s.events, 400);
    EXPECT_GT(s.byFeature[static_cast<int>(MeshFeature::Vertex)], 10);
    EXPECT_LE(s.grazing, 4);
    EXPECT_LE(s.mismatched, 4);
}

/// One triangle, random particles, a chosen gravity: the prediction against stepping.
void singleTriangles(const char* what, std::uint64_t seed, Vec<3> (*gravity)(Rng&, const std::array<Vec<3>, 3>&)) {
    Rng rng(seed, 61);
    int hits = 0, edges = 0, vertices = 0;
    for (int trial = 0; trial < 300; ++trial) {
        std::array<Vec<3>, 3> t;
        for (auto& p : t) p = meshref::randomIn<3>(rng, -1, 1);
        meshref::Scene<3> scene;
        scene.add(t);
        const double a = rng.uniform(0.05, 0.4);
        const Vec<3> g = gravity(rng, t);
        Vec<3> x;
        do x = meshref::randomIn<3>(rng, -2, 2);
        while (scene.gap(meshref::toL(x), a) < 0.01);
        // Aimed at a random point of the triangle's plane region, with some spread: most trials hit.
        const Vec<3> aim = t[0] + (t[1] - t[0]) * rng.uniform(-0.3, 1) + (t[2] - t[0]) * rng.uniform(-0.3, 1);
        const Vec<3> v = (aim - x) * rng.uniform(0.5, 3) + meshref::randomIn<3>(rng, -0.3, 0.3);
        const MeshContact<3> c = predictTriangle(x, v, g, a, makeMeshTriangle(t), 4.0);
        const LD tr = meshref::steppedContact(scene, x, v, g, a, 2e-4L, 4.0L);
        if (tr == kNever) {
            // None, or a touch shorter than a step: then it must be a true touch.
            if (c.time < kNever) {
                EXPECT_LT(std::abs(double(meshref::closest(meshref::centre(x, v, g, c.time), t).dist - a)), 1e-10)
                    << what << " trial " << trial;
            }
            continue;
        }
        ++hits;
        const double slope = meshref::approachSpeed(scene, x, v, g, a, tr);
        EXPECT_NEAR(c.time, double(tr), 1e-11 + 1e-13 / slope) << what << " trial " << trial;
        const auto ref = meshref::closest(meshref::centre(x, v, g, tr), t);
        if (ref.feature == c.feature) {
            EXPECT_EQ(ref.index, c.index) << what << " trial " << trial;
        } else {
            EXPECT_LT(double(meshref::normL(meshref::sub(ref.q, meshref::toL(c.point)))), 1e-7) << what << trial;
        }
        edges += c.feature == MeshFeature::Edge;
        vertices += c.feature == MeshFeature::Vertex;
    }
    EXPECT_GT(hits, 80) << what;
    EXPECT_GT(edges, 10) << what;
    EXPECT_GT(vertices, 3) << what;
}

TEST(EdmPredictMesh, NoGravity) {
    singleTriangles("g = 0", 51, [](Rng&, const std::array<Vec<3>, 3>&) { return Vec<3>{}; });
}

TEST(EdmPredictMesh, GravityAlongAnEdge) {
    // The edge's quartic loses its t^4 and t^3 terms (g has no part across the line): the degree drops.
    singleTriangles("g along edge 0", 52, [](Rng& rng, const std::array<Vec<3>, 3>& t) {
        const Vec<3> e = t[1] - t[0];
        return e * (rng.uniform(-10, 10) / norm(e));
    });
}

TEST(EdmPredictMesh, GravityAlongTheNormal) {
    singleTriangles("g along the normal", 53, [](Rng& rng, const std::array<Vec<3>, 3>& t) {
        const Vec<3> n = cross(t[1] - t[0], t[2] - t[0]);
        return n * (rng.uniform(-10, 10) / norm(n));
    });
}

TEST(EdmPredictMesh, GrazingAVertexAndAnEdge) {
    // A straight path whose closest approach to a vertex (then to an edge's line) is a (1 + eps): touch or not.
    const MeshTriangle tri = makeMeshTriangle({Vec<3>{{0, 0, 0}}, Vec<3>{{1, 0, 0}}, Vec<3>{{0, 1, 0}}});
    const double a = 0.1;
    const Vec<3> v{{0, 0, 1}};  // passes beside vertex 0, outside the triangle, closest at t = 1
    for (const double eps : {1e-6, 1e-10, -1e-10, -1e-6}) {
        const Vec<3> x{{-a * (1 + eps) / std::sqrt(2.0), -a * (1 + eps) / std::sqrt(2.0), -1}};
        const MeshContact<3> c = predictTriangle(x, v, Vec<3>{}, a, tri);
        if (eps > 0) {
            EXPECT_EQ(c.time, kNever) << eps;
        } else {
            EXPECT_EQ(c.feature, MeshFeature::Vertex) << eps;
            const double depth = a * std::sqrt(-2 * eps - eps * eps);  // 1 - t: where d^2 + z^2 = a^2
            EXPECT_NEAR(c.time, 1 - depth, 1e-4 * depth) << eps;
        }
        // Under gravity along the path, the same touch (the parabola reaches z = 0 on the same line).
        const MeshContact<3> cg = predictTriangle(x, Vec<3>{{0, 0, 0}}, Vec<3>{{0, 0, 2}}, a, tri);
        EXPECT_EQ(cg.time < kNever, eps < 0) << eps;
    }
    // Beside edge 0 (the x axis, y = 0), at x = 0.5: the line, not a vertex.
    for (const double eps : {1e-9, -1e-9}) {
        const Vec<3> x{{0.5, -a * (1 + eps), -1}};
        const MeshContact<3> c = predictTriangle(x, v, Vec<3>{}, a, tri);
        EXPECT_EQ(c.time < kNever, eps < 0) << eps;
        if (eps < 0) {
            EXPECT_EQ(c.feature, MeshFeature::Edge);
        }
    }
}

TEST(EdmPredictMesh, FaceIsThePlane) {
    // Over the inside of a large triangle the prediction is that of the plane wall (D.3), to rounding, from
    // either side.
    Rng rng(54, 62);
    const MeshTriangle tri = makeMeshTriangle({Vec<3>{{-50, -50, 0}}, Vec<3>{{50, -50, 0}}, Vec<3>{{0, 60, 0}}});
    int hits = 0;
    for (int trial = 0; trial < 1000; ++trial) {
        const double a = rng.uniform(0.1, 0.5), side = trial % 2 ? 1 : -1;
        const Vec<3> x{{rng.uniform(-3, 3), rng.uniform(-3, 3), side * (a + rng.uniform(0, 2))}};
        const Vec<3> v = meshref::randomIn<3>(rng, -2, 2), g{{rng.normal(), rng.normal(), -side * 9.81}};
        const MeshContact<3> c = predictTriangle(x, v, g, a, tri);
        const double want = wallCollisionTime(x, v, a, Vec<3>{}, Vec<3>{}, Vec<3>{{0, 0, side}}, g);
        ASSERT_LT(want, kNever);
        ++hits;
        EXPECT_NEAR(c.time, want, 1e-14 * (1 + want)) << trial;
        EXPECT_EQ(c.feature, MeshFeature::Face) << trial;
        EXPECT_LT(norm(c.normal - Vec<3>{{0, 0, side}}), 1e-15) << trial;
    }
    EXPECT_EQ(hits, 1000);
    // 2D: a long segment is the line.
    const MeshSegment seg = makeMeshSegment(Vec<2>{{-50, 0}}, Vec<2>{{50, 0}});
    for (int trial = 0; trial < 500; ++trial) {
        const double a = rng.uniform(0.1, 0.5);
        const Vec<2> x{{rng.uniform(-3, 3), a + rng.uniform(0, 2)}}, v = meshref::randomIn<2>(rng, -2, 2);
        const Vec<2> g{{rng.normal(), -9.81}};
        const double want = wallCollisionTime(x, v, a, Vec<2>{}, Vec<2>{}, Vec<2>{{0, 1}}, g);
        EXPECT_NEAR(predictSegment(x, v, g, a, seg).time, want, 1e-14 * (1 + want)) << trial;
    }
}

/// The earliest contact over a mesh, ties to the lower triangle, each triangle searched up to the best so far.
MeshContact<3> firstOnMesh(const std::vector<MeshTriangle>& mesh, const Vec<3>& x, const Vec<3>& v, const Vec<3>& g,
                           double a) {
    MeshContact<3> best;
    for (const auto& t : mesh) {
        const MeshContact<3> c = predictTriangle(x, v, g, a, t, best.time);
        if (c.time < best.time) best = c;
    }
    return best;
}

TEST(EdmPredictMesh, FlatMeshIsThePlane) {
    // The example incline (1600 jittered triangles in z = 0): a particle hopping across it meets the plane's events
    // (D.3) to rounding, with the plane's normal, however it lands relative to the triangles' edges: no extra
    // event where triangles meet, none lost; and dropped onto a vertex or an edge shared by several triangles,
    // one event, along +z.
    std::vector<MeshTriangle> mesh;
    for (const auto& t : readStl(fs_path("examples/meshes/incline.stl")).triangles) mesh.push_back(makeMeshTriangle(t));
    const double a = 0.002;
    const Vec<3> g{{0, 0, -9.81}}, up{{0, 0, 1}};
    Vec<3> x{{0.01, 0.012, a + 1e-5}}, v{{0.25, 0.11, 0}};
    int events = 0;
    while (x[0] < 0.09 && x[1] < 0.045) {
        const MeshContact<3> c = firstOnMesh(mesh, x, v, g, a);
        const double want = wallCollisionTime(x, v, a, Vec<3>{}, Vec<3>{}, up, g);
        ASSERT_NEAR(c.time, want, 1e-13) << "event " << events;
        EXPECT_LT(norm(c.normal - up), 1e-12) << "event " << events;
        x = x + (v + g * (0.5 * c.time)) * c.time;
        v = v + g * c.time;
        v[2] = -v[2];
        ++events;
    }
    EXPECT_GT(events, 80);
    // Onto the mesh's shared vertices and edge midpoints, from rest, a + 1e-4 above: t = sqrt(2e-4 / g).
    const auto& p = mesh[2 * (20 * 17 + 9)].p;  // a cell away from the rim
    for (const Vec<3>& q : {p[0], p[1], p[2], (p[0] + p[1]) * 0.5, (p[1] + p[2]) * 0.5, (p[2] + p[0]) * 0.5}) {
        const Vec<3> start = q + up * (a + 1e-4);
        const MeshContact<3> c = firstOnMesh(mesh, start, Vec<3>{}, g, a);
        EXPECT_NEAR(c.time, std::sqrt(2e-4 / 9.81), 1e-15);
        EXPECT_LT(norm(c.normal - up), 1e-12);
        EXPECT_LT(norm(c.point - q), 1e-12);
        // Reflected: leaving, so the next event is the next landing, 2 v / g later, not a second contact now.
        const Vec<3> x1 = start + g * (0.5 * c.time * c.time), v1 = g * (-c.time);
        EXPECT_NEAR(firstOnMesh(mesh, x1, v1, g, a).time, 2 * c.time, 1e-14);
    }
}

TEST(EdmPredictMesh, InvalidStates) {
    // docs/physics.md D.6: touching and receding is no event now; touching and approaching is an event now.
    const MeshTriangle tri = makeMeshTriangle({Vec<3>{{0, 0, 0}}, Vec<3>{{1, 0, 0}}, Vec<3>{{0, 1, 0}}});
    const double a = 0.1;
    const Vec<3> g{{0, 0, -9.81}};
    for (const double gap : {0.0, -1e-15, 1e-15}) {
        // On the face, leaving upwards at 1 m/s: back after 2 v / g.
        const Vec<3> x{{0.2, 0.2, a + gap}};
        MeshContact<3> c = predictTriangle(x, Vec<3>{{0, 0, 1}}, g, a, tri);
        EXPECT_EQ(c.feature, MeshFeature::Face);
        EXPECT_NEAR(c.time, 2 / 9.81, 1e-12) << gap;
        EXPECT_NEAR(c.time, wallCollisionTime(x, Vec<3>{{0, 0, 1}}, a, Vec<3>{}, Vec<3>{}, Vec<3>{{0, 0, 1}}, g),
                    1e-15);
        // Approaching: now (gap <= 0) or at once (gap > 0).
        c = predictTriangle(x, Vec<3>{{0, 0, -1}}, g, a, tri);
        EXPECT_LE(c.time, 2e-15) << gap;
        if (gap <= 0) {
            EXPECT_EQ(c.time, 0.0);
        }
        // Below the face, leaving downwards: gravity takes it away for good.
        c = predictTriangle(Vec<3>{{0.2, 0.2, -a - gap}}, Vec<3>{{0, 0, -1}}, g, a, tri);
        EXPECT_EQ(c.time, kNever) << gap;
        // Touching edge 0 (the x axis) from outside, leaving outwards and upwards: it falls past the triangle's
        // plane outside it, farther than a from the edge, so there is no contact at all (in any case not now).
        const Vec<3> xe{{0.5, -(a + gap) * std::sqrt(0.5), (a + gap) * std::sqrt(0.5)}};
        c = predictTriangle(xe, Vec<3>{{0, -1, 1}}, g, a, tri);
        EXPECT_TRUE(c.time > 1e-3) << gap << " " << c.time;
        // Touching vertex 1 from outside, leaving.
        const Vec<3> xv{{1 + (a + gap), 0, 0}};
        c = predictTriangle(xv, Vec<3>{{1, 0, 0.5}}, g, a, tri);
        EXPECT_TRUE(c.time > 1e-3) << gap << " " << c.time;
        // The same vertex, approaching: now.
        c = predictTriangle(xv, Vec<3>{{-1, 0, 0}}, Vec<3>{}, a, tri);
        EXPECT_LE(c.time, 2e-15) << gap;
        EXPECT_EQ(c.feature, MeshFeature::Vertex);
        EXPECT_EQ(c.index, 1);
    }
    // Resting on a segment end in 2D, pressed by gravity: an event now (the rest hop's case, D.7), not a loop of
    // growing overlap. Leaving it at an angle: later.
    const MeshSegment seg = makeMeshSegment(Vec<2>{{0, 0}}, Vec<2>{{1, 0}});
    EXPECT_EQ(predictSegment(Vec<2>{{-a, 0}}, Vec<2>{{0, 0}}, Vec<2>{{9.81, 0}}, a, seg).time, 0.0);
    EXPECT_TRUE(predictSegment(Vec<2>{{-a, 0}}, Vec<2>{{-1, 1}}, Vec<2>{{0, -9.81}}, a, seg).time > 1e-3);
}

}  // namespace
}  // namespace haet
