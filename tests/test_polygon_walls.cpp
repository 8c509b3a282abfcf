// Polygons against walls of any shape (docs/physics.md G.6): the overlap with the solid behind segments, polylines,
// circles and arcs against independent twins (the plane's half-plane, a convex solid clipped directly, point
// sampling), dA/dt exact for rigid motion of the polygon and of the wall; whole runs: a polygon on collinear segments
// on the plane's path, its load, a square dragged by a rotating drum and by a conveyor segment, the energy of elastic
// bounces under the potential law, and the example silo of polygons.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "contact/setup.hpp"
#include "physics_util.hpp"
#include "polygon/geometry.hpp"
#include "polygon/surface_kernel.hpp"
#include "polygon/wall_geometry.hpp"
#include "polygon_util.hpp"
#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world_util.hpp"

namespace haet {
namespace {

using polygon::cross2;
using polygon::Overlap;
using polygon::perp;
using polygon::polygonMoments;
using polygon::V2;
using testing::record;

constexpr double kPi = 3.14159265358979323846;

V2 v2(double x, double y) { return V2{{x, y}}; }

/// Random convex polygon about the origin (centroid at 0), circumradius about R.
std::vector<V2> randomPolygon(std::uint64_t seed, double R) {
    Rng rng(seed, 5);
    const int n = 3 + int(rng.uniform() * 8);
    return polygon::randomConvexPolygon(rng, n, R, 1.8, rng.uniform(0, 6.3));
}

std::vector<V2> moved(const std::vector<V2>& P, const V2& shift, double angle) {
    std::vector<V2> out;
    for (const V2& v : P) out.push_back(polygon::rotate(v, std::cos(angle), std::sin(angle)) + shift);
    return out;
}

double polygonArea(const std::vector<V2>& P) { return polygonMoments(P.data(), int(P.size())).area; }

/// A mesh wall from a polyline's points (2D), as the loader builds it.
SurfaceWall<2> polylineWall(const std::vector<V2>& pts, bool closed = false) {
    std::vector<std::array<V2, 2>> segs;
    for (std::size_t k = 0; k + 1 < pts.size(); ++k) segs.push_back({pts[k], pts[k + 1]});
    if (closed) segs.push_back({pts.back(), pts.front()});
    SurfaceWall<2> w;
    buildMesh<2>(w, segs);
    return w;
}

/// Every element of a wall as a candidate of one particle at x, at the wall's pose at time t; the merged overlaps.
std::vector<polygon::SurfaceOverlap> overlapsWith(const std::vector<SurfaceWall<2>>& walls, const std::vector<V2>& P,
                                                  const V2& x, double t = 0) {
    SurfaceState<2> s;
    s.walls = &walls;
    for (const SurfaceWall<2>& w : walls) s.poses.push_back(w.motion.at(t));
    s.candidates.first = {0};
    for (std::uint32_t w = 0; w < walls.size(); ++w)
        for (std::uint32_t e = 0; e < walls[w].elementCount(); ++e) {
            s.candidates.wall.push_back(w);
            s.candidates.element.push_back(e);
        }
    s.candidates.first.push_back(std::uint32_t(s.candidates.wall.size()));
    std::vector<polygon::SurfaceOverlap> out(polygon::kMaxSurfaceOverlaps);
    const int n = polygon::polygonSurfaceOverlaps(s, P.data(), int(P.size()), polygonArea(P), x, 0,
                                                  s.candidates.first[1], out.data());
    out.resize(std::size_t(n));
    return out;
}

TEST(PolygonWallGeometry, CollinearSegmentsAddUpToThePlane) {
    // A line y = 0 cut into segments 0.3 R long, polygons straddling the joints at every depth and angle: the merged
    // overlap is the half-plane's.
    const double R = 1.0;
    std::vector<V2> pts;
    for (int k = 0; k <= 40; ++k) pts.push_back(v2(-6 + 0.3 * k, 0));
    const std::vector<SurfaceWall<2>> walls{polylineWall(pts)};
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0, 1);
    int touching = 0;
    for (int k = 0; k < 2000; ++k) {
        const std::vector<V2> body = randomPolygon(std::uint64_t(k), R);
        const V2 x = v2(-3 + 6 * u(rng), 0.2 + 0.9 * u(rng));
        const std::vector<V2> P = moved(body, V2::zero(), 0.0);
        const std::vector<V2> world = moved(body, x, 0.0);
        const Overlap plane = polygon::halfPlaneOverlap(world.data(), int(world.size()), V2::zero(), v2(0, 1));
        const auto got = overlapsWith(walls, P, x);
        if (!(plane.area > 0)) {
            EXPECT_TRUE(got.empty()) << k;
            continue;
        }
        ++touching;
        ASSERT_EQ(got.size(), 1u) << k;
        const Overlap& o = got[0].o;
        const double scale = std::sqrt(plane.area);
        EXPECT_NEAR(o.area, plane.area, 1e-13 * R * R) << k;
        EXPECT_LT(norm(o.centroid + x - plane.centroid), 1e-12 * R) << k;
        EXPECT_LT(norm(o.chord - plane.chord), 1e-12 * R) << k;
        EXPECT_NEAR(o.spin, plane.spin, 1e-12 * R * scale) << k;
        EXPECT_NEAR(got[0].normal[1], 1.0, 1e-12) << k;
    }
    EXPECT_GT(touching, 500);
}

/// The area of P inside a region given by a point test, by sampling a fine grid over P's box.
template <class Inside>
double sampledArea(const std::vector<V2>& P, Inside inside, int n = 600) {
    V2 lo = P[0], hi = P[0];
    for (const V2& v : P)
        for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], v[a]), hi[a] = std::max(hi[a], v[a]);
    const double hx = (hi[0] - lo[0]) / n, hy = (hi[1] - lo[1]) / n;
    int count = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const V2 q = v2(lo[0] + (i + 0.5) * hx, lo[1] + (j + 0.5) * hy);
            bool inP = true;
            for (std::size_t k = 0; k < P.size() && inP; ++k) inP = cross2(P[(k + 1) % P.size()] - P[k], q - P[k]) >= 0;
            count += inP && inside(q);
        }
    return count * hx * hy;
}

TEST(PolygonWallGeometry, RidgeAndValleyTileTheSolid) {
    // A ridge /\ (solid below, convex: its overlap by clipOverlap with a large triangle) and a valley \/ (solid below:
    // the polygon's area minus its overlap with the valley's inside, a large triangle), apex at the origin, at several
    // angles; polygons near the apex, from above. The pieces of the two segments neither overlap nor leave a gap.
    const double R = 1.0, far = 50;
    int touching = 0, both = 0;
    for (double half : {30.0, 60.0, 80.0, 89.0}) {
        const double th = half * kPi / 180;
        const V2 left = v2(-std::sin(th), -std::cos(th)), right = v2(std::sin(th), -std::cos(th));
        for (int valley = 0; valley < 2; ++valley) {
            const double sgn = valley ? -1 : 1;  // valley: the arms point up
            const V2 a = left * (3 * sgn), c = right * (3 * sgn);
            const std::vector<SurfaceWall<2>> walls{polylineWall({a, V2::zero(), c})};
            // The convex region: below the ridge; or the valley's inside.
            const std::vector<V2> tri = valley ? std::vector<V2>{V2::zero(), right * -far, left * -far}
                                               : std::vector<V2>{V2::zero(), left * far, right * far};
            for (int k = 0; k < 300; ++k) {
                Rng rng(std::uint64_t(k), 9);
                const std::vector<V2> body = randomPolygon(std::uint64_t(k + 7), R);
                const V2 x = v2(rng.uniform(-1.2, 1.2), rng.uniform(0.2, 1.5) + (valley ? 0.5 : 0.0));
                const std::vector<V2> world = moved(body, x, 0.0);
                // Skip centres on the wrong side (inside the solid).
                bool inSolid = true;
                for (int q = 0; q < 3 && inSolid; ++q) inSolid = cross2(tri[(q + 1) % 3] - tri[q], x - tri[q]) >= 0;
                if (valley ? !inSolid : inSolid) continue;
                const Overlap convex = polygon::clipOverlap(world.data(), int(world.size()), tri.data(), 3);
                const double want = valley ? polygonArea(world) - convex.area : convex.area;
                double got = 0;
                V2 chord{};
                const auto pieces = overlapsWith(walls, moved(body, V2::zero(), 0.0), x);
                for (const auto& h : pieces) {
                    got += h.o.area;
                    chord += h.o.chord;
                }
                both += pieces.size() == 2;
                EXPECT_NEAR(got, want, 1e-12 * R * R) << half << " deg, valley " << valley << ", " << k;
                touching += want > 1e-3;
                if (!valley) {
                    EXPECT_LT(norm(chord - convex.chord), 1e-12 * R) << half << " " << k;
                }
            }
        }
    }
    EXPECT_GT(touching, 300);
    EXPECT_GT(both, 100);  // straddling the apex
}

TEST(PolygonWallGeometry, CirclesAndArcsAgainstSampling) {
    // A drum (polygon inside: its part outside the circle) and a post (outside: its part inside), full circles and
    // arcs of less and more than half a turn; the area against sampling, the normal radial.
    const double R = 1.0, Rc = 4.0;
    struct Case {
        double a0, a1;
        bool inside;
    };
    const Case cases[] = {{0, 2 * kPi, true},  {0, 2 * kPi, false}, {-2.0, -1.2, true},
                          {-2.0, -1.2, false}, {-3.5, 0.3, true},   {-3.5, 0.3, false}};
    for (const Case& cs : cases) {
        SurfaceWall<2> arc;
        arc.kind = SurfaceKind::Arc;
        arc.radius = Rc;
        arc.angle0 = cs.a0;
        arc.angle1 = cs.a1;
        const std::vector<SurfaceWall<2>> walls{arc};
        int touching = 0, pieces = 0;
        for (int k = 0; k < 20; ++k) {
            Rng rng(std::uint64_t(k), 11);
            const std::vector<V2> body = randomPolygon(std::uint64_t(k + 100), R);
            const double phi = rng.uniform(-kPi, kPi), rho = Rc + (cs.inside ? -1 : 1) * rng.uniform(0.3, 0.95) * R;
            const V2 x = v2(rho * std::cos(phi), rho * std::sin(phi));
            const std::vector<V2> world = moved(body, x, 0.0);
            const auto got = overlapsWith(walls, moved(body, V2::zero(), 0.0), x);
            auto inArc = [&](const V2& q) {
                double a = std::atan2(q[1], q[0]);
                while (a < cs.a0) a += 2 * kPi;
                while (a >= cs.a0 + 2 * kPi) a -= 2 * kPi;
                return a <= cs.a1;
            };
            const double want =
                sampledArea(world, [&](const V2& q) { return (cs.inside ? norm(q) > Rc : norm(q) < Rc) && inArc(q); });
            double area = 0;
            for (const auto& h : got) {
                area += h.o.area;
                const V2 c = h.o.centroid + x;
                const V2 radial = c * (1 / norm(c));
                EXPECT_GT(dot(h.shape, cs.inside ? -radial : radial), 1 - 1e-12);
            }
            EXPECT_NEAR(area, want, 4e-3 * polygonArea(world) + 1e-12) << cs.a0 << " " << cs.inside << " " << k;
            touching += !got.empty();
            pieces = std::max(pieces, int(got.size()));
        }
        EXPECT_GT(touching, 3) << cs.a0 << " " << cs.inside;
        if (!cs.inside) {
            EXPECT_EQ(pieces, 1) << "the post: one convex overlap";
        }
    }
}

TEST(PolygonWallGeometry, SquareInADrumTouchesAtTwoCorners) {
    // A square sitting low in a drum pokes out at its two lower corners: two contacts, mirror images, together the
    // square's area minus its overlap with the disk.
    const double R = 1.0, Rd = 5.0, h = R / std::sqrt(2.0);
    SurfaceWall<2> drum;
    drum.kind = SurfaceKind::Arc;
    drum.radius = Rd;
    drum.angle1 = 2 * kPi;
    const std::vector<V2> body = polygon::rectangle(1.0, R, 0.0);
    const V2 x = v2(0, -(std::sqrt(Rd * Rd - h * h) - h) - 0.01);
    const auto got = overlapsWith({drum}, body, x);
    ASSERT_EQ(got.size(), 2u);
    EXPECT_NEAR(got[0].o.area, got[1].o.area, 1e-13);
    EXPECT_NEAR(got[0].o.centroid[0], -got[1].o.centroid[0], 1e-11);
    const std::vector<V2> world = moved(body, x, 0.0);
    const double inDisk = polygon::circlePolygonOverlap(Rd, world.data(), 4).area;
    EXPECT_NEAR(got[0].o.area + got[1].o.area, 2 * R * R - inDisk, 1e-12);
    // A little higher, the corners are inside: no contact.
    const auto higher = overlapsWith({drum}, body, x + v2(0, 0.02));
    EXPECT_TRUE(higher.empty()) << higher.size() << " " << (higher.empty() ? 0.0 : higher[0].o.area);
}

/// dA/dt by central differences of the merged overlap area, the polygon moving rigidly (v, w about its centre) and
/// the wall with its motion, against areaRate with the wall as the kernel takes it.
void checkAreaRate(const std::vector<SurfaceWall<2>>& walls, const std::vector<V2>& body, const V2& x, const V2& v,
                   double w, double t, const std::string& what) {
    const double h = 1e-7;
    auto area = [&](double s) {
        double a = 0;
        for (const auto& o : overlapsWith(walls, moved(body, V2::zero(), w * s), x + v * s, t + s)) a += o.o.area;
        return a;
    };
    const auto now = overlapsWith(walls, moved(body, V2::zero(), 0.0), x, t);
    ASSERT_EQ(now.size(), 1u) << what;
    EXPECT_GT(now[0].o.area, 1e-3) << what;
    polygon::BodyState bi, bw;
    bi.v = v;
    bi.w = w;
    const Pose<2> pose = walls[0].motion.at(t);
    bw.x = pose.centre - x;
    bw.v = pose.velocity;
    bw.w = pose.spin[0];
    const double rate = polygon::areaRate(now[0].o, bi, bw);
    const double fd = (area(h) - area(-h)) / (2 * h);
    EXPECT_NEAR(rate, fd, 1e-6 * (std::abs(fd) + 1e-3)) << what;
}

TEST(PolygonWallGeometry, AreaRateIsExactForRigidMotion) {
    const std::vector<V2> body = randomPolygon(4, 1.0);
    // A segment floor straddled at a joint, a valley's arm near its vertex, a drum, a post, an arc.
    checkAreaRate({polylineWall({v2(-3, 0), v2(0.2, 0), v2(3, 0)})}, body, v2(0, 0.6), v2(0.3, -0.7), 0.9, 0, "floor");
    checkAreaRate({polylineWall({v2(-3, 3), v2(0, 0), v2(3, 1)})}, body, v2(0.9, 0.9), v2(-0.4, -0.2), -1.3, 0,
                  "valley arm");
    SurfaceWall<2> drum;
    drum.kind = SurfaceKind::Arc;
    drum.radius = 4;
    drum.angle1 = 2 * kPi;
    checkAreaRate({drum}, body, v2(0.3, -3.4), v2(0.5, -0.3), 2.0, 0, "drum");
    checkAreaRate({drum}, body, v2(0.3, 4.5), v2(0.5, -0.3), 2.0, 0, "post");
    SurfaceWall<2> arc = drum;
    arc.angle0 = -2.5;
    arc.angle1 = -0.5;
    checkAreaRate({arc}, body, v2(0.3, -3.4), v2(0.5, -0.3), 2.0, 0, "arc");
    // Moving walls: the floor translating and turning about a far point, the drum turning and oscillating.
    SurfaceWall<2> floor = polylineWall({v2(-3, 0), v2(0.2, 0), v2(3, 0)});
    floor.motion.velocity = v2(0.7, 0.2);
    floor.motion.centre = v2(1.0, -2.0);
    floor.motion.omega = 0.8;
    checkAreaRate({floor}, body, v2(0, 0.4), v2(0.3, -0.7), 0.9, 0.01, "moving floor");
    drum.motion.omega = -3;
    drum.motion.centre = v2(0.5, 0.2);
    drum.motion.amplitude = v2(0.1, 0.05);
    drum.motion.frequency = 2;
    checkAreaRate({drum}, body, v2(0.3, -3.3), v2(0.5, -0.3), 2.0, 0.03, "moving drum");
}

// ------------------------------------------------------------------------------------------------------------
// Whole runs
// ------------------------------------------------------------------------------------------------------------
constexpr double kYoung = 1e5;    // [N/m]
constexpr double kDensity = 2.0;  // [kg/m^2]
constexpr double kR = 0.005;      // circumradius [m]

/// A world for one polygon: gravity down, Gear5, plane loads kept; the contact table comes with finish().
struct Scene {
    World<2> w;
    TdmSettings s;
};

Scene sceneFor() {
    Scene f;
    f.w.domain = testing::openBox<2>(0.3);
    f.w.domain.gravity = v2(0, -9.81);
    f.s.integrator = IntegratorKind::Gear5;
    f.s.skin = 0.2 * kR;
    f.s.sortEvery = 0;
    f.s.planeLoads = true;
    return f;
}

/// The contact table once the particles are in (the polygon step depends on their masses): restitution e, friction
/// mu (0: no tangential law), the polygon law, Gear5 at the polygon step over dtDivisor.
void finish(Scene& f, double e, double mu, PolygonLaw law, double dtDivisor) {
    Scenario sc = testing::linearScenario(2, e, 1e-3, mu, mu > 0 ? TangentialLaw::Spring : TangentialLaw::None);
    sc.materials[0].young = kYoung;
    sc.materials[0].density = kDensity;
    sc.contact.polygonLaw = law;
    f.w.contact = buildContactSetup<2>(sc, materialStats(f.w.particles, 1));
    f.s.dt = f.w.contact.polygonStep / dtDivisor;
}

/// The incline through the origin at theta to x: a plane wall, or collinear segments `seg` long from -0.1 m to 0.3 m
/// along it (a named polyline "incline"). Unit vectors along (uphill) and normal to it.
void addIncline(World<2>& w, bool segments, double theta, double seg) {
    const V2 n = v2(-std::sin(theta), std::cos(theta)), t = v2(std::cos(theta), std::sin(theta));
    if (segments) {
        std::vector<V2> pts;
        for (double s = -0.1; s <= 0.3 + 1e-12; s += seg) pts.push_back(t * s);
        SurfaceWall<2> line = polylineWall(pts);
        line.name = "incline";
        w.surfaces.push_back(line);
    } else {
        w.walls.push_back(Wall<2>::plane(V2::zero(), n, V2::zero(), 0));
    }
}

/// A polygon released on the incline (flat side down, slightly above it), its path every `every` steps.
struct Path {
    std::vector<V2> x;
    std::vector<double> angle;
};

Path downIncline(bool segments, const std::vector<V2>& body, double thetaDeg, double mu, int samples, double T) {
    const double th = thetaDeg * kPi / 180;
    Scene f = sceneFor();
    double ymin = 0;
    for (const V2& v : body) ymin = std::min(ymin, v[1]);
    const V2 n = v2(-std::sin(th), std::cos(th)), t = v2(std::cos(th), std::sin(th));
    f.w.particles.addPolygon(n * (-ymin + 0.02 * kR) + t * 0.2, V2::zero(), Ang<2>::zero(), th, body, kDensity, 0, 0);
    addIncline(f.w, segments, th, 0.3 * kR);
    finish(f, 0.3, mu, PolygonLaw::OverlapArea, 1);
    TdmEngine<2> eng(f.w, f.s);
    Path p;
    for (int k = 1; k <= samples; ++k) {
        eng.advanceTo(T * k / samples);
        p.x.push_back(f.w.particles.x[0]);
        p.angle.push_back(f.w.particles.angle[0][0]);
    }
    return p;
}

TEST(PolygonWallRun, SlidesAndTumblesOverJointsOnThePlanePath) {
    // A square sliding (35 deg, mu = 0.3) and a hexagon tumbling (30 deg, mu = 0.9) down an incline of segments
    // 0.3 circumradii long: the path on the plane, across some hundred joints.
    struct Case {
        const char* name;
        std::vector<V2> body;
        double deg, mu;
    };
    const Case cases[] = {{"sliding square", polygon::rectangle(1.0, kR, 0.0), 35, 0.3},
                          {"tumbling hexagon", polygon::regularPolygon(6, kR, 0.0), 30, 0.9}};
    for (const Case& c : cases) {
        const Path plane = downIncline(false, c.body, c.deg, c.mu, 20, 0.25);
        const Path segs = downIncline(true, c.body, c.deg, c.mu, 20, 0.25);
        double travelled = 0, worst = 0;
        for (std::size_t k = 0; k < plane.x.size(); ++k) {
            travelled = norm(plane.x[k] - plane.x.front());
            const double d = norm(segs.x[k] - plane.x[k]) / std::max(travelled, kR);
            worst = std::max(worst, d);
            EXPECT_LE(d, 1e-9) << c.name << " sample " << k;
            EXPECT_NEAR(segs.angle[k], plane.angle[k], 1e-9 * std::max(1.0, std::abs(plane.angle[k]))) << c.name;
        }
        record(std::string(c.name) + "_path_difference", worst);
        EXPECT_GT(travelled, 10 * kR) << c.name << ": over dozens of joints";
        if (c.mu > 0.5) {
            EXPECT_GT(std::abs(plane.angle.back()), 2 * kPi) << "the hexagon rolls";
        }
    }
}

TEST(PolygonWallRun, RestsOnASegmentFloorWithItsWeight) {
    // A square and a hexagon at rest across a joint of a named floor of segments carry their weight there, at the
    // plane's overlap and position; the floor's load is their weight.
    for (int shape = 0; shape < 2; ++shape) {
        const auto body = shape == 0 ? polygon::rectangle(1.0, kR, 0.0) : polygon::regularPolygon(6, kR, 0.0);
        V2 rest[2];
        double load[2] = {0, 0}, mg = 0;
        for (int segments = 0; segments < 2; ++segments) {
            Scene f = sceneFor();
            double ymin = 0;
            for (const V2& v : body) ymin = std::min(ymin, v[1]);
            f.w.particles.addPolygon(v2(0.0011, -ymin + 0.1 * kR), V2::zero(), Ang<2>::zero(), 0.0, body, kDensity, 0,
                                     0);
            if (segments) {
                SurfaceWall<2> floor = polylineWall({v2(-0.05, 0), v2(0.001, 0), v2(0.0013, 0), v2(0.05, 0)});
                floor.name = "floor";
                f.w.surfaces.push_back(floor);
            } else {
                f.w.walls.push_back(Wall<2>::plane(V2::zero(), v2(0, 1), V2::zero(), 0));
            }
            finish(f, 0.3, 0.5, PolygonLaw::OverlapArea, 1);
            TdmEngine<2> eng(f.w, f.s);
            eng.advanceTo(0.15);
            rest[segments] = f.w.particles.x[0];
            load[segments] = segments ? eng.surfaceLoad(0).force[1] : eng.planeLoad(0).force[1];
            mg = f.w.particles.mass[0] * 9.81;
            EXPECT_LT(norm(f.w.particles.v[0]), 1e-9) << "at rest";
            if (segments) {
                EXPECT_EQ(eng.wallContacts(), 1u) << "one contact across the joints";
            }
        }
        record(shape == 0 ? "square_rest_difference" : "hexagon_rest_difference", norm(rest[1] - rest[0]) / kR);
        record(shape == 0 ? "square_load_over_weight" : "hexagon_load_over_weight", -load[1] / mg - 1);
        EXPECT_LT(norm(rest[1] - rest[0]), 1e-12 * kR) << "shape " << shape;
        EXPECT_NEAR(load[1], -mg, 1e-6 * mg) << "shape " << shape;
        EXPECT_NEAR(load[1], load[0], 1e-9 * mg) << "shape " << shape;
    }
}

TEST(PolygonWallRun, RotatingDrumDragsASquare) {
    // No gravity: a square sliding along the inside of a drum (radius Rd, turning at omega), its corners on the wall
    // and turning with its path, is pressed to it by its own motion; friction brings it to turn with the drum, its
    // contact points at the wall's speed.
    const double Rd = 0.05, omega = 20, v0 = 0.3;
    const double h = kR / std::sqrt(2.0);               // half the side
    const double rho = std::sqrt(Rd * Rd - h * h) - h;  // the centre's distance with the corners on the wall
    Scene f = sceneFor();
    f.w.domain.gravity = V2::zero();
    f.w.particles.addPolygon(v2(0, -rho), v2(v0, 0), Ang<2>{{v0 / rho}}, 0.0, polygon::rectangle(1.0, kR, 0.0),
                             kDensity, 0, 0);
    SurfaceWall<2> drum;
    drum.kind = SurfaceKind::Arc;
    drum.radius = Rd;
    drum.angle1 = 2 * kPi;
    drum.motion.omega = omega;
    drum.name = "drum";
    f.w.surfaces.push_back(drum);
    finish(f, 0.3, 0.8, PolygonLaw::OverlapArea, 1);
    TdmEngine<2> eng(f.w, f.s);
    const Particles<2>& p = f.w.particles;
    eng.advanceTo(0.4);
    const V2 vRigid = perp(p.x[0]) * omega;  // the drum's velocity field at the square's centre
    record("drum_velocity_error", norm(p.v[0] - vRigid) / (omega * Rd));
    EXPECT_LT(norm(p.v[0] - vRigid), 1e-5 * omega * Rd);
    EXPECT_NEAR(p.w[0][0], omega, 1e-5 * omega);
    EXPECT_EQ(eng.wallContacts(), 2u) << "on two corners";
    // The drum pushes the square towards its axis: the square's load on the drum points outward.
    EXPECT_GT(dot(eng.surfaceLoad(0).force, p.x[0]), 0);
}

TEST(PolygonWallRun, ConveyorSegmentCarriesASquare) {
    // A segment floor moving along itself at u: friction brings a square resting on it to u.
    const double u = 0.1;
    Scene f = sceneFor();
    const auto body = polygon::rectangle(1.0, kR, 0.0);
    f.w.particles.addPolygon(v2(0, kR / std::sqrt(2.0)), V2::zero(), Ang<2>::zero(), 0.0, body, kDensity, 0, 0);
    SurfaceWall<2> belt = polylineWall({v2(-0.2, 0), v2(0.2, 0)});
    belt.motion.velocity = v2(u, 0);
    f.w.surfaces.push_back(belt);
    finish(f, 0.3, 0.5, PolygonLaw::OverlapArea, 1);
    TdmEngine<2> eng(f.w, f.s);
    eng.advanceTo(0.2);
    const Particles<2>& p = f.w.particles;
    record("conveyor_velocity_error", (p.v[0][0] - u) / u);
    EXPECT_NEAR(p.v[0][0], u, 1e-4 * u);
    EXPECT_LT(std::abs(p.w[0][0]), 1e-3);
}

TEST(PolygonWallRun, DrumTorqueBalancesTheBedsWeight) {
    // A bed of random polygons in a drum turning slowly (tests/polygon_util.hpp, drumBed): the torque the bed exerts on
    // the drum about its axis balances the weight's torque, -g M x_cm, averaged over time.
    const testing::DrumBed b = testing::drumBed(0, 0.4, 0.4);
    record("drum_torque_over_weight_torque", b.torque / b.weightTorque - 1);
    EXPECT_GT(b.particles, 50u);
    EXPECT_GT(b.liftAngle, 5.0) << "the bed is carried up the side";
    EXPECT_NEAR(b.torque, b.weightTorque, 0.02 * std::abs(b.weightTorque));
}

/// The energy (kinetic plus gravity's) of one elastic, frictionless polygon dropped with a spin onto walls, under
/// the potential law (Gear5 at a quarter of the polygon step): its largest relative change over contact-free
/// instants after `bounces` contacts, which must be there.
double bounceEnergyChange(const std::vector<SurfaceWall<2>>& surfaces, const std::vector<Wall<2>>& planes, const V2& x0,
                          const V2& v0, int bounces) {
    Scene f = sceneFor();
    f.w.particles.addPolygon(x0, v0, Ang<2>{{7.0}}, 0.3, polygon::regularPolygon(5, kR, 0.1), kDensity, 0, 0);
    f.w.surfaces = surfaces;
    f.w.walls = planes;
    finish(f, 1.0, 0.0, PolygonLaw::Potential, 4);
    TdmEngine<2> eng(f.w, f.s);
    const Particles<2>& p = f.w.particles;
    auto energy = [&]() {
        return 0.5 * (p.mass[0] * norm2(p.v[0]) + p.inertia(0) * norm2(p.w[0])) + p.mass[0] * 9.81 * p.x[0][1];
    };
    const double e0 = energy(), scale = 0.5 * p.mass[0] * norm2(v0) + p.mass[0] * 9.81 * 0.01;
    int contacts = 0;
    bool inContact = false;
    double worst = 0;
    while (contacts < bounces && f.w.time < 2) {
        eng.step();
        const bool now = eng.forceStats().contacts > 0;
        if (now && !inContact) ++contacts;
        if (!now) worst = std::max(worst, std::abs(energy() - e0) / scale);
        inContact = now;
    }
    EXPECT_EQ(contacts, bounces);
    return worst;
}

TEST(PolygonWallEnergy, PotentialLawBouncesKeepTheEnergy) {
    // A spinning pentagon bouncing on a floor of segments (across joints), in a V of two segments, in a drum, and on
    // the plane for comparison: the potential law's force is minus the gradient of Y A^2 / (2 L^2) on every wall.
    std::vector<V2> pts;
    for (int k = 0; k <= 60; ++k) pts.push_back(v2(-0.15 + 0.005 * k, 0));
    SurfaceWall<2> drum;
    drum.kind = SurfaceKind::Arc;
    drum.radius = 0.03;
    drum.angle1 = 2 * kPi;
    drum.centre = v2(0, 0.03);
    struct Case {
        const char* name;
        std::vector<SurfaceWall<2>> surfaces;
        std::vector<Wall<2>> planes;
        V2 x0, v0;
    };
    const Case cases[] = {
        {"plane", {}, {Wall<2>::plane(V2::zero(), v2(0, 1), V2::zero(), 0)}, v2(0, 0.01), v2(0.05, 0)},
        {"segments", {polylineWall(pts)}, {}, v2(0, 0.01), v2(0.05, 0)},
        {"vee", {polylineWall({v2(-0.1, 0.1), v2(0, 0), v2(0.1, 0.05)})}, {}, v2(0.003, 0.015), v2(0.02, 0)},
        {"drum", {drum}, {}, v2(0.01, 0.02), v2(0.1, 0)},
    };
    for (const Case& c : cases) {
        const double change = bounceEnergyChange(c.surfaces, c.planes, c.x0, c.v0, 6);
        record(std::string(c.name) + "_energy_change", change);
        EXPECT_LT(change, 1e-7) << c.name;
    }
}

// ------------------------------------------------------------------------------------------------------------
// Scenarios
// ------------------------------------------------------------------------------------------------------------
TEST(PolygonWallScenario, PolygonsTouchEvery2dWall) {
    const std::string head =
        "name = \"w\"\ndimension = 2\nmethod = \"tdm\"\nduration = 0.1\n[domain]\nlo = [0, 0]\nhi = [1, 1]\n"
        "[materials.m]\ndensity = 2\nyoung = 1000\nrestitution = 0.5\nfriction = 0.3\n"
        "[[insert]]\narrangement = \"lattice\"\nshape = \"polygon\"\nsides = 5\ncount = 4\nradius = 0.01\n"
        "material = \"m\"\nregion = { lo = [0.4, 0.4], hi = [0.6, 0.6] }\n[[walls]]\nmaterial = \"m\"\n";
    for (const char* wall : {"type = \"segment\"\npoints = [[0, 0.1], [1, 0.1]]\n",
                             "type = \"polyline\"\npoints = [[0, 0.5], [0.5, 0.1], [1, 0.5]]\nclosed = false\n",
                             "type = \"circle\"\ncenter = [0.5, 0.5]\nradius = 0.45\n",
                             "type = \"arc\"\ncenter = [0.5, 0.5]\nradius = 0.45\nangles = [180, 360]\n"}) {
        const Scenario sc = parseScenario(head + wall, "walls.toml");
        World<2> w = buildWorld<2>(sc);
        EXPECT_EQ(w.surfaces.size(), 1u) << wall;
        EXPECT_EQ(w.particles.size(), 4u);
    }
}

TEST(PolygonWallScenario, PolygonSiloRunsBriefly) {
    // examples/hopper2d_polygons.toml for 0.05 s: the polygons near the silo's floor of segments rest on it, none
    // crosses a wall, and the silo's halves carry a load.
    const Scenario sc = testing::exampleScenario("hopper2d_polygons.toml", {"duration=0.05"});
    World<2> w = buildWorld<2>(sc);
    TdmEngine<2> eng(w, tdmSettings<2>(sc, w));
    eng.advanceTo(sc.duration);
    const Particles<2>& p = w.particles;
    ASSERT_EQ(p.size(), 1200u);
    for (std::size_t i = 0; i < p.size(); ++i) {
        // Inside the silo: between its side walls and above its floor (the orifice is at x in [0.185, 0.215]).
        const double x = p.x[i][0], y = p.x[i][1];
        EXPECT_TRUE(x > 0.1 && x < 0.3) << i;
        EXPECT_TRUE(y > 0.3 || (x > 0.185 && x < 0.215)) << i;
    }
    EXPECT_LT(eng.forceStats().maxOverlapRatio, 0.2);
    EXPECT_LT(eng.surfaceLoad(0).force[1] + eng.surfaceLoad(1).force[1], 0.0) << "the silo floor is pressed down";
    EXPECT_GT(eng.wallContacts(), 5u);
}

TEST(PolygonWallScenario, SiloBitIdenticalWithOneAndTwoThreads) {
    // The polygon silo with 2400 polygons (the threaded pass runs from 2048 particles on), 1200 steps (the lowest
    // reach the silo's floor): the same bits, wall loads included, with one thread and with two.
    const Scenario sc = testing::exampleScenario(
        "hopper2d_polygons.toml", {"insert[1].count=2400", "insert[1].region={ lo = [0.1, 0.3], hi = [0.3, 0.69] }"});
    struct Out {
        Particles<2> p;
        V2 load;
    };
    auto run = [&](int threads) {
        omp_set_num_threads(threads);
        World<2> w = buildWorld<2>(sc);
        TdmSettings s = tdmSettings<2>(sc, w);
        s.sortEvery = 50;
        TdmEngine<2> eng(w, s);
        for (int k = 0; k < 1200; ++k) eng.step();
        return Out{w.particles, eng.surfaceLoad(0).force + eng.surfaceLoad(1).force};
    };
    const int before = omp_get_max_threads();
    const Out a = run(1), b = run(2);
    omp_set_num_threads(before);
    ASSERT_EQ(a.p.size(), 2400u);
    ASSERT_EQ(a.p.id, b.p.id);
    for (std::size_t i = 0; i < a.p.size(); ++i) {
        ASSERT_EQ(a.p.x[i], b.p.x[i]) << i;
        ASSERT_EQ(a.p.angle[i], b.p.angle[i]) << i;
        ASSERT_EQ(a.p.w[i], b.p.w[i]) << i;
    }
    EXPECT_EQ(a.load, b.load);
    EXPECT_LT(a.load[1], 0.0);
}

}  // namespace
}  // namespace haet
