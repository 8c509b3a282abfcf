// The root isolation of the mesh predictions (src/edm/poly_roots.hpp, docs/physics.md D.8) against polynomials
// with known roots and against dense sampling in long double: every falling sign change in order, grazing double
// roots, vanishing and tiny leading coefficients, the invalid-state rules of D.6, and the quadratic predictor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.hpp"
#include "edm/poly_roots.hpp"
#include "edm/predict.hpp"

namespace haet {
namespace {

/// c[0..4] of k (t - r0)(t - r1)... for the given roots (up to four).
std::array<double, 5> fromRoots(double k, const std::vector<double>& r) {
    std::array<double, 5> c{k, 0, 0, 0, 0};
    for (std::size_t n = 0; n < r.size(); ++n) {
        for (std::size_t j = n + 1; j >= 1; --j) c[j] = c[j - 1] - r[n] * c[j];
        c[0] = -r[n] * c[0];
    }
    return c;
}

/// Every candidate firstFalling offers, in order (accept records and refuses).
std::vector<double> candidates(const std::array<double, 5>& c, double tMax) {
    std::vector<double> out;
    const double t = roots::firstFalling(c.data(), tMax, [&](double s) {
        out.push_back(s);
        return false;
    });
    EXPECT_EQ(t, kNever);
    return out;
}

TEST(PolyRoots, FallingRootsOfKnownQuartics) {
    Rng rng(31, 77);
    int checked = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const int n = 1 + trial % 4;
        std::vector<double> r(static_cast<std::size_t>(n));
        for (auto& x : r) x = rng.uniform(-2, 6);
        const double k = (rng.uniform() < 0.5 ? -1 : 1) * std::exp(rng.uniform(-3, 3));
        const auto c = fromRoots(k, r);
        if (c[0] <= 0) continue;  // start outside: the candidates are exactly the falling roots
        std::sort(r.begin(), r.end());
        bool close = false;
        for (std::size_t j = 0; j + 1 < r.size(); ++j) close |= r[j + 1] - r[j] < 1e-3;
        if (close) continue;  // near-double roots: below
        // The falling roots in (0, 10): f changes from > 0 to < 0; the sign of f after root j is k (-1)^(n-1-j).
        std::vector<double> expect;
        for (std::size_t j = 0; j < r.size(); ++j) {
            const bool negativeAfter = (k > 0) == ((n - 1 - static_cast<int>(j)) % 2 == 1);
            if (r[j] > 0 && r[j] < 10 && negativeAfter) expect.push_back(r[j]);
        }
        // The other candidates are tops below zero (f < 0 turning to decrease): set apart, and checked as such.
        std::vector<double> got;
        for (const double t : candidates(c, 10.0)) {
            const double f = roots::eval(c.data(), 4, t), scale = std::abs(k) * std::pow(1 + t + 6, n);
            if (std::abs(f) <= 1e-12 * scale) {
                got.push_back(t);
            } else {
                EXPECT_LT(f, 0) << "trial " << trial;
                EXPECT_LT(roots::eval(c.data(), 4, t + 1e-5), f) << "trial " << trial;
                EXPECT_LT(roots::eval(c.data(), 4, t - 1e-5), f) << "trial " << trial;
            }
        }
        ASSERT_EQ(got.size(), expect.size()) << "trial " << trial;
        for (std::size_t j = 0; j < got.size(); ++j) {
            // The rounded coefficients move a root by their rounding (~1e-16 of sum |c_k| r^k) over |f'(r)|.
            const double r0 = expect[j];
            double size = 0, slope = 0;
            for (int m = 0; m <= 4; ++m) {
                size += std::abs(c[m]) * std::pow(r0, m);
                if (m > 0) slope += m * c[m] * std::pow(r0, m - 1);
            }
            EXPECT_NEAR(got[j], r0, 1e-14 * (1 + size / std::abs(slope))) << "trial " << trial;
        }
        ++checked;
    }
    EXPECT_GT(checked, 900);
}

TEST(PolyRoots, BracketIsTwoAdjacentDoubles) {
    // The returned time is the first double where f <= 0: the one before it has f > 0.
    Rng rng(32, 78);
    for (int trial = 0; trial < 500; ++trial) {
        const auto c = fromRoots(1, {rng.uniform(0.1, 3), 4, -1, -2});  // f(0) = 8 r0 > 0, falls at r0
        const double t = roots::firstFalling(c.data(), kNever, [](double) { return true; });
        EXPECT_LE(roots::eval(c.data(), 4, t), 0) << trial;
        EXPECT_GT(roots::eval(c.data(), 4, std::nextafter(t, 0.0)), 0) << trial;
    }
}

TEST(PolyRoots, GrazingDoubleRoot) {
    // (t - 1)^2 (t + 2)(t + 3) + delta: touches zero at t = 1 for delta = 0, two roots 1 -+ sqrt(-delta/12) below.
    for (const double delta : {1e-6, 1e-12, 0.0, -1e-12, -1e-6}) {
        auto c = fromRoots(1, {1, 1, -2, -3});
        c[0] += delta;
        const double t = roots::firstFalling(c.data(), kNever, [](double) { return true; });
        if (delta > 0) {
            EXPECT_EQ(t, kNever) << delta;
        } else if (delta < 0) {
            EXPECT_NEAR(t, 1 - std::sqrt(-delta / 12), 1e-4 * std::sqrt(-delta)) << delta;
        } else {
            // Touching: rounding decides between the touching point (f <= 0 there) and none.
            EXPECT_TRUE(t == kNever || std::abs(t - 1) < 1e-7) << t;
        }
    }
}

TEST(PolyRoots, VanishingAndTinyLeadingCoefficients) {
    Rng rng(33, 79);
    for (int trial = 0; trial < 1000; ++trial) {
        // A quadratic gap (a wall): the same first root as the predictor of D.3, with c3, c4 zero or tiny.
        const double f0 = rng.uniform(0, 2), f1 = rng.normal(), f2 = 2 * rng.normal();
        const double want = firstRootFalling(f0, f1, f2);
        for (const double tiny : {0.0, 1e-30, -1e-30}) {
            const double c[5] = {f0, f1, 0.5 * f2, tiny, trial % 2 ? tiny : 0.0};
            const double t = roots::firstFalling(c, 1e6, [](double) { return true; });
            if (want == kNever || want > 1e6) {
                EXPECT_TRUE(t == kNever || t > 1e5) << trial << " " << t;  // a tiny c3 may add a far root
            } else {
                EXPECT_NEAR(t, want, 1e-13 * (1 + want)) << trial;
            }
        }
    }
    // A constant and a zero polynomial: never (nothing decreases), even at or below zero.
    const double zero[5] = {0, 0, 0, 0, 0}, below[5] = {-1, 0, 0, 0, 0};
    EXPECT_EQ(roots::firstFalling(zero, kNever, [](double) { return true; }), kNever);
    EXPECT_EQ(roots::firstFalling(below, kNever, [](double) { return true; }), kNever);
}

TEST(PolyRoots, InvalidStateRules) {
    const auto all = [](double) { return true; };
    // f <= 0 and decreasing: now.
    const double c1[5] = {-1e-14, -1, 0.5, 0, 0.25};
    EXPECT_EQ(roots::firstFalling(c1, kNever, all), 0.0);
    const double touching[5] = {0, -1, 0, 0, 0.25};
    EXPECT_EQ(roots::firstFalling(touching, kNever, all), 0.0);
    // Touching and receding: not now; here never (the gap grows for ever).
    const double c2[5] = {0, 1, 1, 0, 0.25};
    EXPECT_EQ(roots::firstFalling(c2, kNever, all), kNever);
    const double c3[5] = {-1e-14, 1, 0, 0, 0.25};
    EXPECT_EQ(roots::firstFalling(c3, kNever, all), kNever);
    // Below zero and receding, turning back before getting out (top at t = 0.5, f = -0.75): the top.
    const double c4[5] = {-1, 1, -1, 0, 0};
    EXPECT_NEAR(roots::firstFalling(c4, kNever, all), 0.5, 1e-15);
    // Below zero, receding and getting out, then back: the root on the way back, as firstRootFalling has it.
    const double c5[5] = {-0.1, 1, -1, 0, 0};
    EXPECT_NEAR(roots::firstFalling(c5, kNever, all), firstRootFalling(-0.1, 1, -2), 1e-15);
    // A candidate refused (say, outside the feature) gives way to the next.
    const auto c6 = fromRoots(1, {1, 2, 3, 4});  // falls at 1 and 3
    EXPECT_NEAR(roots::firstFalling(c6.data(), kNever, [](double t) { return t > 2; }), 3.0, 1e-13);
    EXPECT_EQ(roots::firstFalling(c6.data(), 2.5, [](double t) { return t > 2; }), kNever);  // horizon
}

TEST(PolyRoots, AgainstDenseSampling) {
    // Random quartics of a point against a moving sphere, the kind the vertices give: the first falling crossing
    // against sampling in long double (step 1e-4, then bisection), where the crossing is not grazing.
    Rng rng(34, 80);
    int hits = 0;
    for (int trial = 0; trial < 600; ++trial) {
        double w[3], v[3], g[3];
        for (int k = 0; k < 3; ++k) {
            w[k] = rng.uniform(-2, 2);
            v[k] = 0.3 * rng.normal() - w[k] * (trial % 3 ? 0.8 : 0.0);  // two in three aimed at the point
            g[k] = trial % 5 == 0 ? 0.0 : 3 * rng.normal();
        }
        const double a = 0.8;
        const double c[5] = {w[0] * w[0] + w[1] * w[1] + w[2] * w[2] - a * a,
                             2 * (w[0] * v[0] + w[1] * v[1] + w[2] * v[2]),
                             v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + (w[0] * g[0] + w[1] * g[1] + w[2] * g[2]),
                             v[0] * g[0] + v[1] * g[1] + v[2] * g[2], 0.25 * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2])};
        if (c[0] <= 0) continue;
        const auto f = [&](long double t) {
            long double s = 0;
            for (int k = 0; k < 3; ++k) {
                const long double x = w[k] + v[k] * t + 0.5L * g[k] * t * t;
                s += x * x;
            }
            return s - (long double)a * a;
        };
        long double ref = kNever;
        const long double h = 1e-4;
        for (long double t = h; t < 5; t += h)
            if (f(t) <= 0) {
                long double lo = t - h, hi = t;
                for (int it = 0; it < 100; ++it) (f(0.5L * (lo + hi)) <= 0 ? hi : lo) = 0.5L * (lo + hi);
                ref = hi;
                break;
            }
        const double got = roots::firstFalling(c, 5.0, [](double) { return true; });
        if (ref == kNever) {
            EXPECT_EQ(got, kNever) << trial;  // or a grazing touch shorter than a step: none seen here
            continue;
        }
        ++hits;
        // Accuracy: a time error is the gap's rounding (~1e-16 of its terms) over its slope at the root.
        const double slope = std::abs((double)((f(ref + 1e-7L) - f(ref - 1e-7L)) / 2e-7L));
        EXPECT_NEAR(got, (double)ref, 1e-13 + 1e-15 / slope) << trial;
    }
    EXPECT_GT(hits, 80);
}

}  // namespace
}  // namespace haet
