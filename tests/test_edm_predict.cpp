// Event-time predictions (docs/physics.md D.2, D.3, D.4, D.6) against brute-force time stepping of the parabolic
// motion, and the invalid-state rules.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.hpp"
#include "edm/predict.hpp"

namespace haet {
namespace {

/// First t in (0, tEnd] where gap(t) <= 0, scanning with step h; then refined by bisection. kNever if none.
template <class F>
double steppedFirstContact(F gap, double tEnd, double h) {
    double a = 0;
    for (double t = h; t <= tEnd; t += h) {
        if (gap(t) <= 0) {
            double lo = a, hi = t;
            for (int it = 0; it < 200; ++it) {
                const double m = 0.5 * (lo + hi);
                if (gap(m) <= 0)
                    hi = m;
                else
                    lo = m;
            }
            return hi;
        }
        a = t;
    }
    return kNever;
}

TEST(EdmPredict, ParabolaBranches) {
    // floor (f2 < 0): moving away first, then back
    EXPECT_NEAR(firstRootFalling(0.0, 1.0, -2.0), 1.0, 1e-15);
    // floor, falling from height 1 at rest: t = sqrt(2 h/g)
    EXPECT_NEAR(firstRootFalling(1.0, 0.0, -9.81), std::sqrt(2 / 9.81), 1e-15);
    // ceiling (f2 > 0): moving towards it but turning before
    EXPECT_EQ(firstRootFalling(1.0, -1.0, 2.0), kNever);  // min of f = 1 - 1/4 > 0
    EXPECT_NEAR(firstRootFalling(1.0, -3.0, 2.0), (3 - std::sqrt(5.0)) / 2, 1e-15);
    // linear
    EXPECT_NEAR(firstRootFalling(2.0, -4.0, 0.0), 0.5, 1e-15);
    EXPECT_EQ(firstRootFalling(2.0, 4.0, 0.0), kNever);
    // invalid states (D.6): overlapping and approaching -> now; overlapping and receding -> no event (f2 >= 0)
    EXPECT_EQ(firstRootFalling(-1e-12, -1.0, 0.0), 0.0);
    EXPECT_EQ(firstRootFalling(-1e-12, -1.0, 3.0), 0.0);
    EXPECT_EQ(firstRootFalling(-1e-12, 1.0, 3.0), kNever);
    EXPECT_EQ(firstRootFalling(-1e-12, 1.0, 0.0), kNever);
    // below a floor, rising but not enough to get out: collide at the top (when it starts to sink again)
    EXPECT_NEAR(firstRootFalling(-1.0, 1.0, -2.0), 0.5, 1e-15);
    // below a floor, rising out of it: no event until it comes back down through the floor
    EXPECT_NEAR(firstRootFalling(-0.1, 1.0, -2.0), (1 + std::sqrt(1 - 0.4)) / 2, 1e-15);
}

TEST(EdmPredict, PairAgainstStepping) {
    Rng rng(21, 4000);
    int hits = 0;
    for (int trial = 0; trial < 400; ++trial) {
        Vec<3> r, v;
        for (int k = 0; k < 3; ++k) {
            r[k] = rng.uniform(-3, 3);
            v[k] = rng.normal();
        }
        if (trial % 2 == 0) v -= r * 0.5;  // aimed: more hits
        const double sigma = rng.uniform(0.5, 1.5);
        if (norm(r) < sigma) continue;
        const double t = pairCollisionTime(r, v, sigma);
        const double ts = steppedFirstContact([&](double s) { return norm(r + v * s) - sigma; }, 20.0, 1e-3);
        if (ts == kNever) {
            EXPECT_TRUE(t == kNever || t > 20.0) << "trial " << trial;
        } else {
            ++hits;
            EXPECT_NEAR(t, ts, 1e-9 * (1 + ts)) << "trial " << trial;
        }
        // symmetric to the bit
        EXPECT_EQ(pairCollisionTime(-r, -v, sigma), t);
    }
    EXPECT_GT(hits, 25);
}

TEST(EdmPredict, PairOverlapRules) {
    const Vec<2> r{{0.99, 0}};
    EXPECT_EQ(pairCollisionTime(r, Vec<2>{{-1, 0}}, 1.0), 0.0);                   // approaching: now
    EXPECT_EQ(pairCollisionTime(r, Vec<2>{{1, 0}}, 1.0), kNever);                 // receding: none
    EXPECT_EQ(pairCollisionTime(r, Vec<2>{{0, 1}}, 1.0), kNever);                 // tangential: none
    EXPECT_EQ(pairCollisionTime(Vec<2>{{1.0, 0}}, Vec<2>{{0, 0}}, 1.0), kNever);  // at rest
}

TEST(EdmPredict, WallUnderGravityAgainstStepping) {
    Rng rng(22, 4001);
    int hits = 0;
    for (int trial = 0; trial < 400; ++trial) {
        Vec<3> x, v, n, u, g, pw;
        for (int k = 0; k < 3; ++k) {
            n[k] = rng.normal();
            v[k] = rng.normal();
            u[k] = 0.3 * rng.normal();
            g[k] = 2 * rng.normal();
            pw[k] = rng.uniform(-1, 1);
        }
        n = n * (1 / norm(n));
        const double a = rng.uniform(0.1, 0.5);
        x = pw + n * (a + rng.uniform(0.0, 2.0));
        const double t = wallCollisionTime(x, v, a, pw, u, n, g);
        auto gap = [&](double s) { return dot(n, x + v * s + g * (0.5 * s * s) - (pw + u * s)) - a; };
        const double ts = steppedFirstContact(gap, 20.0, 1e-3);
        if (ts == kNever) {
            EXPECT_TRUE(t == kNever || t > 20.0) << "trial " << trial;
        } else {
            ++hits;
            EXPECT_NEAR(t, ts, 1e-9 * (1 + ts)) << "trial " << trial;
        }
    }
    EXPECT_GT(hits, 100);
}

TEST(EdmPredict, CellExitAgainstStepping) {
    Rng rng(23, 4002);
    for (int trial = 0; trial < 400; ++trial) {
        const double lo = 0, hi = 1;
        const double x = rng.uniform(lo, hi), v = rng.normal(), g = trial % 3 == 0 ? 0.0 : 3 * rng.normal();
        const CellExit ex = cellExitTime(x, v, g, lo, hi);
        auto outside = [&](double s) {
            const double y = x + v * s + 0.5 * g * s * s;
            return std::min(y - lo, hi - y);
        };
        const double ts = steppedFirstContact(outside, 50.0, 1e-3);
        if (ts == kNever) {
            EXPECT_TRUE(ex.time == kNever || ex.time > 50.0);
            continue;
        }
        EXPECT_NEAR(ex.time, ts, 1e-9 * (1 + ts)) << "trial " << trial;
        const double y = x + v * ts + 0.5 * g * ts * ts;
        EXPECT_EQ(ex.up, y > 0.5) << "trial " << trial;
    }
    // turning around inside the cell under gravity: leaves through the face it started towards only if it reaches it
    const CellExit turn = cellExitTime(0.5, 0.5, -1.0, 0.0, 1.0);  // top at 0.625 < 1
    EXPECT_FALSE(turn.up);
    EXPECT_NEAR(turn.time, (0.5 + std::sqrt(0.25 + 1.0)) / 1.0, 1e-15);
    // open outer cells
    EXPECT_EQ(cellExitTime(0.5, 1.0, 0.0, 0.0, kNever).time, kNever);
}

TEST(EdmPredict, FixedSphereUnderGravityAgainstStepping) {
    Rng rng(24, 4003);
    int hits = 0;
    for (int trial = 0; trial < 400; ++trial) {
        Vec<3> r, v, g;
        for (int k = 0; k < 3; ++k) {
            r[k] = rng.uniform(-2, 2);
            v[k] = rng.normal();
            g[k] = 0.0;
        }
        g[2] = -rng.uniform(0.5, 10.0);
        if (trial % 2 == 0) v -= r;  // aimed: more hits
        const double sigma = rng.uniform(0.5, 1.0);
        if (norm(r) <= sigma) continue;
        const double t = fixedSphereCollisionTime(r, v, g, sigma, kNever);
        auto gap = [&](double s) { return norm(r + v * s + g * (0.5 * s * s)) - sigma; };
        const double ts = steppedFirstContact(gap, 5.0, 1e-4);
        if (ts == kNever) {
            EXPECT_TRUE(t == kNever || t > 5.0) << "trial " << trial;
        } else {
            ++hits;
            EXPECT_NEAR(t, ts, 1e-9 * (1 + ts)) << "trial " << trial;
        }
    }
    EXPECT_GT(hits, 40);
    // resting on top of the fixed sphere (touching, at rest): gravity pushes in -> now
    const Vec<3> top{{0, 0, 1.0}}, zero{{0, 0, 0}}, g{{0, 0, -9.81}};
    EXPECT_EQ(fixedSphereCollisionTime(top, zero, g, 1.0, kNever), 0.0);
    // bouncing up from it: comes back after 2 v / g
    const Vec<3> up{{0, 0, 1.0}};
    EXPECT_NEAR(fixedSphereCollisionTime(top, up, g, 1.0, kNever), 2 / 9.81, 1e-12);
}

}  // namespace
}  // namespace haet
