// Geometry of convex polygons (src/polygon/geometry.hpp) and the pair law's symmetry (src/polygon/contact.hpp):
// closed forms of regular n-gons (docs/physics.md G.1), overlap areas against an independent exact construction and
// Monte Carlo (G.2), the exact area rate against finite differences, degenerate contacts, Newton's third law and
// the torque balance (G.3).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/particles.hpp"
#include "core/rng.hpp"
#include "physics_util.hpp"
#include "polygon/contact.hpp"
#include "polygon/geometry.hpp"

namespace haet::polygon {
namespace {

constexpr double kPi = 3.14159265358979323846;
using testing::record;

std::vector<V2> moved(std::vector<V2> v, const V2& by, double angle = 0) {
    const double c = std::cos(angle), s = std::sin(angle);
    for (V2& p : v) p = rotate(p, c, s) + by;
    return v;
}

// ---- G.1 closed forms ----

TEST(PolygonGeometry, RegularPolygonMomentsMatchClosedForms) {
    double worst = 0;
    for (int n = 3; n <= 20; ++n) {
        for (double R : {1e-3, 0.37, 12.0}) {
            const double phi = 0.1 * n;
            // Away from the origin, to include the round-off of the shift.
            const auto v = moved(regularPolygon(n, R, phi), V2{{3 * R, -2 * R}});
            const Moments m = polygonMoments(v.data(), n);
            const double area = 0.5 * n * R * R * std::sin(2 * kPi / n);
            const double ipm = R * R / 6 * (1 + 2 * std::cos(kPi / n) * std::cos(kPi / n));
            const double eA = std::abs(m.area - area) / area;
            const double eC = norm(m.centroid - V2{{3 * R, -2 * R}}) / R;
            const double eI = std::abs(m.inertiaPerMass - ipm) / ipm;
            worst = std::max({worst, eA, eC, eI});
            EXPECT_LT(eA, 1e-12) << n << "-gon, R = " << R;
            EXPECT_LT(eC, 1e-12) << n << "-gon, R = " << R;
            EXPECT_LT(eI, 1e-12) << n << "-gon, R = " << R;
        }
    }
    record("worst_relative_error", worst);
    // A square of side s: I = m s^2 / 6.
    const auto sq = rectangle(1.0, std::sqrt(0.5), 0.3);
    EXPECT_NEAR(polygonMoments(sq.data(), 4).inertiaPerMass, 1.0 / 6.0, 1e-14);
}

TEST(PolygonGeometry, ParticleStoreTakesMassAndInertiaFromTheVertices) {
    Particles<2> p;
    p.add(Vec<2>{{0.5, 0.5}}, Vec<2>::zero(), Ang<2>::zero(), 0.1, 2.0, 0, 0);  // a disk first
    // A clockwise hexagon about an off-centre origin: re-centred and re-ordered by the store.
    auto hex = moved(regularPolygon(6, 0.02, 0.2), V2{{0.005, 0.003}});
    std::reverse(hex.begin(), hex.end());
    const std::size_t i = p.addPolygon(Vec<2>{{0.1, 0.2}}, Vec<2>::zero(), Ang<2>::zero(), 0.7, hex, 3.0, 0, 1);
    const double area = 3 * std::sqrt(3.0) / 2 * 0.02 * 0.02;
    EXPECT_NEAR(p.mass[i], 3.0 * area, 1e-14 * p.mass[i]);
    EXPECT_NEAR(p.inertia(i), p.mass[i] * 0.02 * 0.02 / 6 * (1 + 2 * 0.75), 1e-12 * p.inertia(i));
    EXPECT_NEAR(p.radius[i], 0.02, 1e-15);
    EXPECT_EQ(p.angle[i][0], 0.7);
    EXPECT_EQ(p.shape[0], kNoShape);
    EXPECT_TRUE(isConvexCcw(p.shapes.of(p.shape[i]), 6));
    EXPECT_NEAR(p.inertia(0), 0.5 * p.mass[0] * 0.01, 1e-15);                   // disks keep I = m r^2 / 2
    p.add(Vec<2>{{0.9, 0.5}}, Vec<2>::zero(), Ang<2>::zero(), 0.1, 2.0, 0, 2);  // a disk after a polygon
    EXPECT_EQ(p.shape.size(), 3u);
    EXPECT_EQ(p.shape[2], kNoShape);
    p.permute({2, 1, 0});
    EXPECT_EQ(p.shape[1], 0u);
    EXPECT_NEAR(p.inertia(1), p.mass[1] * 0.02 * 0.02 / 6 * 2.5, 1e-12 * p.inertia(1));
}

TEST(PolygonGeometry, RandomShapesAreConvexWithTheRequestedCircumradius) {
    Rng rng(7, 99);
    for (int t = 0; t < 200; ++t) {
        const int n = 3 + t % 18;
        const auto v = randomConvexPolygon(rng, n, 0.01, 2.0, rng.uniform(0, 6.3));
        ASSERT_TRUE(isConvexCcw(v.data(), n)) << t;
        const Moments m = polygonMoments(v.data(), n);
        EXPECT_LT(norm(m.centroid), 1e-15);
        EXPECT_NEAR(circumradius(v.data(), n, V2::zero()), 0.01, 1e-15);
    }
}

// ---- G.2 overlaps ----

bool insideConvex(const std::vector<V2>& P, const V2& x) {
    for (std::size_t k = 0; k < P.size(); ++k)
        if (cross2(P[(k + 1) % P.size()] - P[k], x - P[k]) < 0) return false;
    return true;
}

// The reference twin: the overlap of two convex polygons is the convex hull of the vertices of each inside the
// other and the crossings of their edges (a different construction from clipping).
Moments referenceOverlap(const std::vector<V2>& P, const std::vector<V2>& Q) {
    std::vector<V2> pts;
    for (const V2& x : P)
        if (insideConvex(Q, x)) pts.push_back(x);
    for (const V2& x : Q)
        if (insideConvex(P, x)) pts.push_back(x);
    for (std::size_t a = 0; a < P.size(); ++a)
        for (std::size_t b = 0; b < Q.size(); ++b) {
            const V2 p0 = P[a], p1 = P[(a + 1) % P.size()], q0 = Q[b], q1 = Q[(b + 1) % Q.size()];
            const double den = cross2(p1 - p0, q1 - q0);
            if (den == 0) continue;
            const double t = cross2(q0 - p0, q1 - q0) / den, u = cross2(q0 - p0, p1 - p0) / den;
            if (t >= 0 && t <= 1 && u >= 0 && u <= 1) pts.push_back(p0 + (p1 - p0) * t);
        }
    if (pts.size() < 3) return Moments{};
    // Andrew's monotone chain.
    std::sort(pts.begin(), pts.end(),
              [](const V2& a, const V2& b) { return a[0] != b[0] ? a[0] < b[0] : a[1] < b[1]; });
    std::vector<V2> h(2 * pts.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
        while (k >= 2 && cross2(h[k - 1] - h[k - 2], pts[i] - h[k - 2]) <= 0) --k;
        h[k++] = pts[i];
    }
    for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross2(h[k - 1] - h[k - 2], pts[i] - h[k - 2]) <= 0) --k;
        h[k++] = pts[i];
    }
    h.resize(k - 1);
    return h.size() < 3 ? Moments{} : polygonMoments(h.data(), int(h.size()));
}

double referenceArea(const std::vector<V2>& P, const std::vector<V2>& Q) { return referenceOverlap(P, Q).area; }

TEST(PolygonOverlap, ClippedAreaMatchesExactReferenceOnRandomPairs) {
    Rng rng(11, 3);
    double worst = 0;
    int overlapping = 0;
    for (int t = 0; t < 2000; ++t) {
        const int np = 3 + int(rng.uniform() * 18), nq = 3 + int(rng.uniform() * 18);
        const auto P = randomConvexPolygon(rng, np, 1.0, 2.5, rng.uniform(0, 6.3));
        const auto Q = moved(randomConvexPolygon(rng, nq, rng.uniform(0.3, 1.5), 2.5, 0.0),
                             V2{{rng.uniform(-2, 2), rng.uniform(-2, 2)}});
        const Overlap o = clipOverlap(P.data(), np, Q.data(), nq);
        const double ref = referenceArea(P, Q);
        const double err = std::abs(o.area - ref);
        worst = std::max(worst, err);
        EXPECT_LT(err, 1e-12) << "pair " << t;
        EXPECT_EQ(separated(P.data(), np, Q.data(), nq), ref == 0) << "pair " << t;
        overlapping += ref > 0;
        // The same overlap seen from the other body: same area and centroid, opposite chord.
        const Overlap r = clipOverlap(Q.data(), nq, P.data(), np);
        EXPECT_NEAR(r.area, o.area, 1e-12);
        if (o.area > 1e-6) {
            EXPECT_LT(norm(r.centroid - o.centroid), 1e-10);
            EXPECT_LT(norm(r.chord + o.chord), 1e-10);
        }
    }
    EXPECT_GT(overlapping, 500);
    record("worst_area_error", worst);
}

// The two-crossing path against the clipping (its reference twin) and the exact area: on random pairs, moved by a
// shift as the force loop moves them, and on degenerate and deep contacts, where it must either agree or decline.
// A thin sliver is ill-conditioned in either method: the crossings of nearly parallel edges move along them by
// round-off over the angle between them, and the centroid's cross products lose round-off relative to scale^2
// divided by the area; hence the tolerances grow with scale^2 / area.
void expectSameOverlap(const Overlap& f, const Overlap& r, double scale, const char* what) {
    EXPECT_NEAR(f.area, r.area, 1e-12 * scale * scale) << what;
    if (r.area > 1e-14 * scale * scale) {
        const double kappa = std::max(1.0, scale * scale / r.area);
        EXPECT_LT(norm(f.centroid - r.centroid), 1e-12 * kappa * scale) << what;
        EXPECT_LT(norm(f.chord - r.chord), 1e-12 * kappa * scale) << what;
        EXPECT_NEAR(f.spin, r.spin, 1e-12 * kappa * scale * scale) << what;
    }
}

TEST(PolygonOverlap, TwoCrossingPathMatchesClippingOnRandomPairs) {
    Rng rng(12, 7);
    int fast = 0, overlapping = 0, declined = 0;
    for (int t = 0; t < 4000; ++t) {
        const int np = 3 + int(rng.uniform() * 18), nq = 3 + int(rng.uniform() * 18);
        const V2 at{{rng.uniform(-50, 50), rng.uniform(-50, 50)}};
        const auto P = moved(randomConvexPolygon(rng, np, 1.0, 2.5, rng.uniform(0, 6.3)), at);
        const auto Q = moved(randomConvexPolygon(rng, nq, rng.uniform(0.3, 1.5), 2.5, 0.0),
                             at + V2{{rng.uniform(-2, 2), rng.uniform(-2, 2)}});
        std::vector<V2> local = P;  // P about `at`, moved back by the shift
        for (V2& v : local) v -= at;
        const Overlap r = clipOverlap(P.data(), np, Q.data(), nq);
        const double ref = referenceArea(P, Q);
        overlapping += ref > 0;
        Overlap f;
        if (twoCrossingOverlap(local.data(), np, Q.data(), nq, at, 1.0, at, f)) {
            fast += ref > 0;
            expectSameOverlap(f, r, 1.0, "random pair");
            EXPECT_NEAR(f.area, ref, 1e-11) << "pair " << t;
        } else {
            declined += ref > 0;
        }
        expectSameOverlap(convexOverlap(local.data(), np, Q.data(), nq, at, 1.0, at), r, 1.0, "convexOverlap");
    }
    // Most overlapping random pairs cross twice; the rest (one inside the other, deep crossings) fall back.
    EXPECT_GT(fast, 3 * declined);
    EXPECT_GT(declined, 0);
    EXPECT_GT(overlapping, 1000);
    record("two_crossing_share", double(fast) / overlapping);
}

TEST(PolygonOverlap, TwoCrossingPathOnDegenerateAndDeepContacts) {
    const auto sq = rectangle(1.0, std::sqrt(2.0), 0.0);  // [-1, 1]^2
    const V2 zero = V2::zero();
    auto check = [&](const std::vector<V2>& P, const std::vector<V2>& Q, const char* what) {
        const int np = int(P.size()), nq = int(Q.size());
        const Overlap r = clipOverlap(P.data(), np, Q.data(), nq);
        Overlap f;
        f.area = -1;
        const double radius = circumradius(P.data(), np, zero);
        const bool ok = twoCrossingOverlap(P.data(), np, Q.data(), nq, zero, radius, zero, f);
        if (ok) {
            EXPECT_TRUE(std::isfinite(f.area) && std::isfinite(f.centroid[0]) && std::isfinite(f.chord[1])) << what;
            expectSameOverlap(f, r, 1.0, what);
        } else {
            EXPECT_EQ(f.area, -1.0) << what;  // left alone
        }
        return ok;
    };
    // Touching from outside (vertex on vertex, edge on edge, vertex on edge): zero area when taken.
    for (const V2 by : {V2{{2.0, 2.0}}, V2{{2.0, 0.0}}, V2{{2.0, 0.5}}, V2{{2.0, 1.0}}})
        check(sq, moved(sq, by), "touching");
    check(sq, moved(sq, V2{{1.0 + std::sqrt(2.0), 0.0}}, kPi / 4), "vertex on edge");
    // Parallel overlapping edges, collinear side edges: vertices of P on Q's edge lines.
    check(sq, moved(sq, V2{{1.5, 0.0}}), "parallel edges, collinear sides");
    check(sq, moved(sq, V2{{1.5, 0.5}}), "parallel edges, offset");
    EXPECT_TRUE(check(sq, moved(sq, V2{{1.5, 0.5}}), "parallel edges, offset"));
    // Vertex on vertex inside: a corner of Q exactly on a corner of P, overlapping.
    check(sq, moved(sq, V2{{1.0, 1.0}}), "corner on centre");
    check(sq, moved(sq, V2{{0.5, 0.5}}, kPi / 4), "turned");
    // Deep overlaps: four crossings (a plus sign), six (a hexagram), one inside the other: declined.
    const auto thin = rectangle(4.0, std::sqrt(17.0) / 2, 0.0);
    EXPECT_FALSE(check(thin, moved(thin, V2{{0.0, 0.1}}, kPi / 2), "plus"));
    const auto tri = regularPolygon(3, 1.0, 0.0);
    EXPECT_FALSE(check(tri, moved(tri, V2{{0.01, 0.0}}, kPi / 3), "hexagram"));
    EXPECT_FALSE(check(rectangle(1.0, 0.3, 0.2), sq, "inside"));
    EXPECT_FALSE(check(sq, rectangle(1.0, 0.3, 0.2), "around"));
    // A thin slice of a vertex poking through an edge: Q's vertex inside P, no vertex of P inside Q.
    check(sq, moved(regularPolygon(3, 1.0, kPi), V2{{2.0 - 1e-9, 0.0}}), "poke");
    // Hexagons of the settling benchmark: flat faces pressed together, tiny turns and offsets, vertices nearly on
    // vertices; the clipping and the direct path agree to round-off.
    const double R = 0.999e-3 / std::sqrt(3.0);
    const auto hex = regularPolygon(6, R, kPi / 6);
    Rng rng(3, 3);
    int taken = 0;
    for (int t = 0; t < 2000; ++t) {
        const double turn = rng.uniform(-1, 1) * std::pow(10.0, -rng.uniform(3, 16));
        const double shift = (t % 4 == 0 ? 0.0 : rng.uniform(-1, 1)) * std::pow(10.0, -rng.uniform(5, 16));
        const double gap = 0.999e-3 * (1 - std::pow(10.0, -rng.uniform(2, 8)));
        const double dir = kPi / 3 * int(rng.uniform(0, 6));
        const V2 at{{gap * std::cos(dir) + shift * std::sin(dir), gap * std::sin(dir) - shift * std::cos(dir)}};
        const auto Q = moved(hex, at, turn);
        const Overlap r = clipOverlap(hex.data(), 6, Q.data(), 6);
        Overlap f;
        if (twoCrossingOverlap(hex.data(), 6, Q.data(), 6, zero, R, zero, f)) {
            ++taken;
            expectSameOverlap(f, r, R, "hexagons");
        }
        expectSameOverlap(convexOverlap(hex.data(), 6, Q.data(), 6, zero, R, zero), r, R, "hexagons");
    }
    EXPECT_GT(taken, 1500);
}

TEST(PolygonOverlap, AreasMatchMonteCarlo) {
    std::mt19937_64 gen(4);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    Rng rng(5, 5);
    for (int t = 0; t < 4; ++t) {
        const auto P = randomConvexPolygon(rng, 6 + t, 1.0, 1.5, 0.3 * t);
        const auto Q = moved(regularPolygon(5, 0.8, 0.1), V2{{0.9 - 0.2 * t, 0.3}});
        const int samples = 400000;
        int hits = 0;
        for (int s = 0; s < samples; ++s) {
            const V2 x{{u(gen), u(gen)}};
            hits += insideConvex(P, x) && insideConvex(Q, x);
        }
        const double box = 9.0, pHit = double(hits) / samples;
        const double mc = box * pHit, sigma = box * std::sqrt(pHit * (1 - pHit) / samples);
        const Overlap o = clipOverlap(P.data(), int(P.size()), Q.data(), int(Q.size()));
        EXPECT_NEAR(o.area, mc, 4 * sigma) << t;
        // Circle of radius 0.7 about Q's centre against P.
        const V2 cc{{0.9 - 0.2 * t, 0.3}};
        hits = 0;
        for (int s = 0; s < samples; ++s) {
            const V2 x{{u(gen), u(gen)}};
            hits += insideConvex(P, x) && norm2(x - cc) < 0.49;
        }
        const double pc = double(hits) / samples;
        const auto Pc = moved(P, -cc);
        const Overlap oc = circlePolygonOverlap(0.7, Pc.data(), int(Pc.size()));
        EXPECT_NEAR(oc.area, box * pc, 4 * box * std::sqrt(pc * (1 - pc) / samples)) << t;
    }
}

TEST(PolygonOverlap, CircleOverlapMatchesFinePolygonAndKnownCases) {
    Rng rng(8, 1);
    double worst = 0;
    const auto fine = regularPolygon(4096, 1.0, 0.0);  // area error 2.0e-6 relative, circumscribed correction below
    const double fineScale = 1.0 / std::sqrt(std::sin(2 * kPi / 4096) * 4096 / (2 * kPi));  // same area as the disk
    std::vector<V2> disk = fine;
    for (V2& p : disk) p *= fineScale;
    for (int t = 0; t < 50; ++t) {
        const auto Q = moved(randomConvexPolygon(rng, 3 + t % 10, rng.uniform(0.3, 2.0), 2.0, rng.uniform(0, 6)),
                             V2{{rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5)}});
        const Overlap o = circlePolygonOverlap(1.0, Q.data(), int(Q.size()));
        const Moments ref = referenceOverlap(disk, Q);
        worst = std::max(worst, std::abs(o.area - ref.area));
        EXPECT_NEAR(o.area, ref.area, 2e-5) << t;
        if (o.area > 1e-3) {
            EXPECT_LT(norm(ref.centroid - o.centroid), 1e-4) << t;
            // The chord is the area gradient: translating Q by (dx, dy) changes the area by c_y dx - c_x dy;
            // turning Q about the origin by dphi changes it by -(s + C . c) dphi.
            const double h = 1e-6;
            auto areaAt = [&](const V2& by, double turn) {
                const auto q = moved(Q, by, turn);
                return circlePolygonOverlap(1.0, q.data(), int(q.size())).area;
            };
            const double ax = (areaAt(V2{{h, 0}}, 0) - areaAt(V2{{-h, 0}}, 0)) / (2 * h);
            const double ay = (areaAt(V2{{0, h}}, 0) - areaAt(V2{{0, -h}}, 0)) / (2 * h);
            const double at = (areaAt(V2::zero(), h) - areaAt(V2::zero(), -h)) / (2 * h);
            EXPECT_NEAR(o.chord[1], ax, 1e-6) << t;
            EXPECT_NEAR(-o.chord[0], ay, 1e-6) << t;
            EXPECT_NEAR(-(o.spin + dot(o.centroid, o.chord)), at, 1e-6) << t;
        }
    }
    record("worst_circle_area_error", worst);
    // Circle inside a big square: pi R^2, no chord. Square edge through the centre: half the disk.
    const auto big = rectangle(1.0, 10.0, 0.0);
    const Overlap in = circlePolygonOverlap(0.5, big.data(), 4);
    EXPECT_NEAR(in.area, kPi * 0.25, 1e-14);
    EXPECT_EQ(norm(in.chord), 0.0);
    const auto half = moved(rectangle(1.0, 10.0, 0.0), V2{{10 / std::sqrt(2.0), 0}});
    const Overlap h = circlePolygonOverlap(0.5, half.data(), 4);
    EXPECT_NEAR(h.area, kPi * 0.125, 1e-14);
    EXPECT_NEAR(h.centroid[0], 4 * 0.5 / (3 * kPi), 1e-14);
    EXPECT_NEAR(h.chord[1], -1.0, 1e-14);  // the square's edge, downwards inside the circle
    // Apart: nothing.
    const auto far = moved(rectangle(1.0, 0.2, 0.0), V2{{2.0, 0.0}});
    EXPECT_EQ(circlePolygonOverlap(0.5, far.data(), 4).area, 0.0);
}

TEST(PolygonOverlap, HalfPlaneCutsTheRightPart) {
    const auto sq = rectangle(1.0, std::sqrt(2.0), 0.0);                          // [-1, 1]^2
    const Overlap o = halfPlaneOverlap(sq.data(), 4, V2{{0, -0.8}}, V2{{0, 1}});  // floor at y = -0.8
    EXPECT_NEAR(o.area, 0.4, 1e-14);
    EXPECT_NEAR(o.centroid[1], -0.9, 1e-14);
    EXPECT_NEAR(o.chord[0], 2.0, 1e-14);  // the square's outline below the floor runs left to right
    EXPECT_NEAR(o.chord[1], 0.0, 1e-14);
    EXPECT_EQ(halfPlaneOverlap(sq.data(), 4, V2{{0, -1.0}}, V2{{0, 1}}).area, 0.0);  // resting exactly on it
}

// The inscribed circle about the centroid: R cos(pi/n) for a regular n-gon, half the short side of a rectangle; two
// polygons whose inscribed circles overlap always overlap (the force loop then skips its separating-axis test).
TEST(PolygonGeometry, InradiusAndOverlappingInscribedCircles) {
    for (int n = 3; n <= 12; ++n) {
        const auto v = regularPolygon(n, 0.7, 0.3);
        EXPECT_NEAR(inradius(v.data(), n), 0.7 * std::cos(kPi / n), 1e-14) << n;
    }
    const auto r = rectangle(3.0, std::sqrt(10.0), 0.4);  // 6 x 2
    EXPECT_NEAR(inradius(r.data(), 4), 1.0, 1e-14);
    Rng rng(51, 3);
    int checked = 0;
    for (int t = 0; t < 500; ++t) {
        const auto Pb = randomConvexPolygon(rng, 3 + t % 10, 1.0, 2.0, 0);
        const auto Qb = randomConvexPolygon(rng, 3 + (t / 10) % 10, 0.7, 2.0, 0);
        const double rin = inradius(Pb.data(), int(Pb.size())) + inradius(Qb.data(), int(Qb.size()));
        const double ang = rng.uniform(0, 2 * kPi), dist = rng.uniform(0.0, 0.999) * rin;
        const auto P = moved(Pb, V2{{dist * std::cos(ang), dist * std::sin(ang)}}, 0.0);
        const auto Q = moved(Qb, V2::zero(), 0.0);
        EXPECT_GT(clipOverlap(P.data(), int(P.size()), Q.data(), int(Q.size())).area, 0.0) << t;
        ++checked;
    }
    EXPECT_EQ(checked, 500);
}

// ---- degenerate geometry: finite results, documented fallbacks ----

TEST(PolygonOverlap, DegenerateContactsStayFinite) {
    const auto sq = rectangle(1.0, std::sqrt(2.0), 0.0);  // [-1, 1]^2
    // Vertex on vertex, edge on edge: zero area, no NaN.
    for (const V2 by : {V2{{2.0, 2.0}}, V2{{2.0, 0.0}}, V2{{2.0, 0.5}}}) {
        const auto q = moved(sq, by);
        const Overlap o = clipOverlap(sq.data(), 4, q.data(), 4);
        EXPECT_EQ(o.area, 0.0);
        EXPECT_TRUE(separated(sq.data(), 4, q.data(), 4));
    }
    // Parallel overlapping edges: the shared edge pieces cancel in the chord; normal along x.
    const auto q = moved(sq, V2{{1.5, 0.0}});
    const Overlap o = clipOverlap(sq.data(), 4, q.data(), 4);
    EXPECT_NEAR(o.area, 1.0, 1e-14);
    EXPECT_NEAR(o.chord[0], 0.0, 1e-14);
    EXPECT_NEAR(o.chord[1], 2.0, 1e-14);
    // Deep overlap with four outline crossings (a plus sign): the chords of both sides cancel, the normal
    // falls back to the line of centres.
    const auto thin = rectangle(4.0, std::sqrt(17.0) / 2, 0.0);  // 4 x 1
    const auto cross = moved(thin, V2{{0.0, 0.1}}, kPi / 2);
    const Overlap oc = clipOverlap(thin.data(), 4, cross.data(), 4);
    EXPECT_NEAR(oc.area, 1.0, 1e-12);
    PolygonCoeffs c;
    c.young = 1e5;
    c.gamma = 0.3;
    c.kt = 3e4;
    c.gammaT = 0.25;
    c.mu = 0.5;
    BodyState bi, bj;
    bi.invMass = bj.invMass = 1;
    bi.invInertia = bj.invInertia = 10;
    bj.x = V2{{0.0, 0.1}};
    bi.v = V2{{0.3, -0.2}};
    V2 xi{};
    const ContactForce f = polygonContact(c, oc, bi, bj, nullptr, PairLengths{0.01, 1.0}, false, true, 1e-4, xi);
    EXPECT_TRUE(std::isfinite(f.f[0]) && std::isfinite(f.f[1]) && std::isfinite(f.torqueI));
    EXPECT_NEAR(f.normal[1], -1.0, 1e-12);  // from j (above) to i
    // One inside the other, same centre: chord zero, normal +x, finite.
    const auto small = rectangle(1.0, 0.3, 0.2);
    const Overlap oi = clipOverlap(small.data(), 4, sq.data(), 4);
    EXPECT_NEAR(oi.area, 0.18, 1e-14);
    bj.x = V2::zero();
    const ContactForce fi = polygonContact(c, oi, bi, bj, nullptr, PairLengths{0.01, 1.0}, false, true, 1e-4, xi);
    EXPECT_EQ(fi.normal[0], 1.0);
    EXPECT_TRUE(std::isfinite(fi.f[0]) && std::isfinite(fi.f[1]) && std::isfinite(fi.torqueI));
}

// ---- G.3: area rate, Newton's third law, torque balance ----

TEST(PolygonContact, AreaRateMatchesFiniteDifferences) {
    Rng rng(21, 2);
    int checked = 0;
    for (int t = 0; t < 300; ++t) {
        const auto Pb = randomConvexPolygon(rng, 3 + t % 8, 1.0, 2.0, 0);
        const auto Qb = randomConvexPolygon(rng, 3 + (t / 8) % 8, 0.8, 2.0, 0);
        BodyState bi, bj;
        bi.x = V2{{rng.uniform(-0.8, 0.8), rng.uniform(-0.8, 0.8)}};
        bj.x = V2{{rng.uniform(-0.8, 0.8), rng.uniform(-0.8, 0.8)}};
        bi.v = V2{{rng.uniform(-1, 1), rng.uniform(-1, 1)}};
        bj.v = V2{{rng.uniform(-1, 1), rng.uniform(-1, 1)}};
        bi.w = rng.uniform(-2, 2);
        bj.w = rng.uniform(-2, 2);
        const double ai = rng.uniform(0, 6), aj = rng.uniform(0, 6);
        auto at = [&](double h) {
            const auto P = moved(Pb, bi.x + bi.v * h, ai + bi.w * h);
            const auto Q = moved(Qb, bj.x + bj.v * h, aj + bj.w * h);
            return clipOverlap(P.data(), int(P.size()), Q.data(), int(Q.size()));
        };
        const Overlap o = at(0);
        if (o.area < 0.05) continue;
        const double h = 1e-6;
        const double fd = (at(h).area - at(-h).area) / (2 * h);
        EXPECT_NEAR(areaRate(o, bi, bj), fd, 1e-6 * (1 + std::abs(fd))) << t;
        ++checked;
    }
    EXPECT_GT(checked, 50);
}

// Both normal laws: the force on j is minus the force on i whichever body's outline gives the chord, and the torques
// balance the moment of the pair force, so momentum and angular momentum are conserved.
TEST(PolygonContact, NewtonsThirdLawAndTorqueBalance) {
    for (const PolygonLaw law : {PolygonLaw::OverlapArea, PolygonLaw::Potential}) {
        const std::string name = law == PolygonLaw::Potential ? "potential" : "overlap_area";
        Rng rng(31, 4);
        PolygonCoeffs c;
        c.young = 2e6;
        c.gamma = 0.4;
        c.kt = 2.0 / 7.0 * c.young;
        c.gammaT = 0.25;
        c.mu = 0.6;
        c.law = law;
        const PairLengths len = pairLengths(0.01, 0.012);
        double worstF = 0, worstT = 0;
        int checked = 0;
        for (int t = 0; t < 400; ++t) {
            const auto P = moved(randomConvexPolygon(rng, 3 + t % 12, 0.01, 2.0, 0), V2{{0.3, 0.2}}, rng.uniform(0, 6));
            const auto Q =
                moved(randomConvexPolygon(rng, 3 + t % 7, 0.012, 2.0, 0),
                      V2{{0.3 + rng.uniform(-0.015, 0.015), 0.2 + rng.uniform(-0.015, 0.015)}}, rng.uniform(0, 6));
            const Overlap oij = clipOverlap(P.data(), int(P.size()), Q.data(), int(Q.size()));
            const Overlap oji = clipOverlap(Q.data(), int(Q.size()), P.data(), int(P.size()));
            if (oij.area < 1e-8) continue;
            BodyState bi, bj;
            bi.x = polygonMoments(P.data(), int(P.size())).centroid;
            bj.x = polygonMoments(Q.data(), int(Q.size())).centroid;
            bi.v = bi.vStep = V2{{rng.uniform(-1, 1), rng.uniform(-1, 1)}};
            bj.v = bj.vStep = V2{{rng.uniform(-1, 1), rng.uniform(-1, 1)}};
            bi.w = bi.wStep = rng.uniform(-50, 50);
            bj.w = bj.wStep = rng.uniform(-50, 50);
            bi.invMass = 1 / 0.3, bj.invMass = 1 / 0.5;
            bi.invInertia = 1e5, bj.invInertia = 5e4;
            const V2 xi0{{rng.uniform(-1e-5, 1e-5), rng.uniform(-1e-5, 1e-5)}};
            V2 xiA = xi0, xiB = -xi0;  // the spring of (j, i) is minus that of (i, j)
            const ContactForce a = polygonContact(c, oij, bi, bj, nullptr, len, false, true, 1e-5, xiA);
            const ContactForce b = polygonContact(c, oji, bj, bi, nullptr, len, false, true, 1e-5, xiB);
            const double scale = norm(a.f) + 1e-300;
            worstF = std::max(worstF, norm(a.f + b.f) / scale);
            EXPECT_LT(norm(a.f + b.f), 1e-8 * scale) << name << " " << t;
            EXPECT_LT(norm(xiA + xiB), 1e-8 * (norm(xiA) + 1e-20)) << name << " " << t;
            EXPECT_NEAR(a.torqueI, b.torqueJ, 1e-8 * (std::abs(a.torqueI) + std::abs(b.torqueJ)) + 1e-300)
                << name << " " << t;
            // Angular momentum: tau_i + tau_j + (x_i - x_j) x F_i = 0, up to round-off.
            const double bal = a.torqueI + a.torqueJ + cross2(bi.x - bj.x, a.f);
            const double tScale = std::abs(a.torqueI) + std::abs(a.torqueJ) + norm(bi.x - bj.x) * scale;
            worstT = std::max(worstT, std::abs(bal) / tScale);
            EXPECT_LT(std::abs(bal), 1e-13 * tScale) << name << " " << t;
            ++checked;
        }
        EXPECT_GT(checked, 100);
        record("worst_force_asymmetry_" + name, worstF);
        record("worst_torque_imbalance_" + name, worstT);
    }
}

// The potential law is minus the gradient of U = Y A^2 / (2 L^2) (polygonContactEnergy): the force on i and the
// torques on i and j match central differences of U under translation of i and rotation of i and of j about their
// centres, over random overlaps of random convex polygons.
TEST(PolygonContact, PotentialLawIsTheGradientOfItsEnergy) {
    Rng rng(41, 6);
    PolygonCoeffs c;
    c.young = 1e5;
    c.law = PolygonLaw::Potential;
    const PairLengths len = pairLengths(1.0, 0.8);
    double worst = 0;
    int checked = 0;
    for (int t = 0; t < 300; ++t) {
        const auto Pb = randomConvexPolygon(rng, 3 + t % 8, 1.0, 2.0, 0);
        const auto Qb = randomConvexPolygon(rng, 3 + (t / 8) % 8, 0.8, 2.0, 0);
        const V2 xi{{rng.uniform(-0.8, 0.8), rng.uniform(-0.8, 0.8)}};
        const V2 xj{{rng.uniform(-0.8, 0.8), rng.uniform(-0.8, 0.8)}};
        const double ai = rng.uniform(0, 6), aj = rng.uniform(0, 6);
        auto energy = [&](const V2& dxi, double dai, double daj) {
            const auto P = moved(Pb, xi + dxi, ai + dai);
            const auto Q = moved(Qb, xj, aj + daj);
            const Overlap o = clipOverlap(P.data(), int(P.size()), Q.data(), int(Q.size()));
            return o.area > 0 ? polygonContactEnergy(c, o, ContactForce{}, len) : 0.0;
        };
        const auto P = moved(Pb, xi, ai);
        const auto Q = moved(Qb, xj, aj);
        const Overlap o = clipOverlap(P.data(), int(P.size()), Q.data(), int(Q.size()));
        if (o.area < 0.05 || norm(o.chord) < 0.1) continue;
        BodyState bi, bj;
        bi.x = xi;
        bj.x = xj;
        bi.invMass = bj.invMass = 1;
        V2 spring{};
        const ContactForce f = polygonContact(c, o, bi, bj, nullptr, len, false, false, 1e-5, spring);
        const double h = 1e-6;
        const V2 hx{{h, 0}}, hy{{0, h}};
        const V2 grad{
            {(energy(hx, 0, 0) - energy(-hx, 0, 0)) / (2 * h), (energy(hy, 0, 0) - energy(-hy, 0, 0)) / (2 * h)}};
        const double dai = (energy(V2::zero(), h, 0) - energy(V2::zero(), -h, 0)) / (2 * h);
        const double daj = (energy(V2::zero(), 0, h) - energy(V2::zero(), 0, -h)) / (2 * h);
        const double scale = norm(f.f) * (1 + norm(xi - xj));
        const double err = std::max({norm(f.f + grad), std::abs(f.torqueI + dai), std::abs(f.torqueJ + daj)}) / scale;
        worst = std::max(worst, err);
        EXPECT_LT(err, 1e-5) << t;
        ++checked;
    }
    EXPECT_GT(checked, 50);
    record("worst_gradient_error", worst);
}

}  // namespace
}  // namespace haet::polygon
