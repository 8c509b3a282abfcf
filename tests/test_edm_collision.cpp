// The hard-particle collision operator (docs/physics.md C.1, C.2): conservation laws and the energy change on random
// states with unequal masses, radii and moments of inertia, pairs and walls, 2D and 3D; Walton's sliding branch.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.hpp"
#include "edm/collision.hpp"

namespace haet {
namespace {

template <int D>
Vec<D> randomVec(Rng& r, double s) {
    Vec<D> v;
    for (int k = 0; k < D; ++k) v[k] = s * r.normal();
    return v;
}
template <int D>
Ang<D> randomAng(Rng& r, double s) {
    Ang<D> v;
    for (int k = 0; k < kAngDim<D>; ++k) v[k] = s * r.normal();
    return v;
}
template <int D>
Vec<D> unit(Vec<D> v) {
    return v * (1.0 / norm(v));
}

/// A random body: mass 0.1..10, radius 0.2..2, q 0.2..0.7.
template <int D>
CollisionBody<D> randomBody(Rng& r, double& mass, double& inertia) {
    CollisionBody<D> b;
    mass = std::exp(r.uniform(std::log(0.1), std::log(10.0)));
    b.radius = r.uniform(0.2, 2.0);
    inertia = r.uniform(0.2, 0.7) * mass * b.radius * b.radius;
    b.invMass = 1 / mass;
    b.invInertia = 1 / inertia;
    b.v = randomVec<D>(r, 1.0);
    b.w = randomAng<D>(r, 1.0 / b.radius);
    return b;
}

template <int D>
double energy(const CollisionBody<D>& b, double m, double I) {
    return 0.5 * m * norm2(b.v) + 0.5 * I * norm2(b.w);
}

/// Angular momentum about the contact point c of a body centred at x: I w + (x - c) x m v.
inline Vec<1> angularAbout(const CollisionBody<2>& b, double m, double I, const Vec<2>& rel) {
    return b.w * I + cross(rel, b.v * m);
}
inline Vec<3> angularAbout(const CollisionBody<3>& b, double m, double I, const Vec<3>& rel) {
    return b.w * I + cross(rel, b.v * m);
}

template <int D>
void checkRandomPairs(bool wall, BetaRule rule) {
    Rng rng(wall ? 11 : 12, 3000 + D);
    int sliding = 0, sticking = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        double m1, I1, m2 = 0, I2 = 0;
        CollisionBody<D> b1 = randomBody<D>(rng, m1, I1);
        CollisionBody<D> b2;
        if (wall) {
            b2.v = randomVec<D>(rng, 0.3);  // moving wall
            b2.radius = 0;
        } else {
            b2 = randomBody<D>(rng, m2, I2);
        }
        Vec<D> n = unit(randomVec<D>(rng, 1.0));
        // approaching: g_n < 0
        if (dot(contactVelocity(b1, b2, n), n) > 0) n = -n;
        CollisionLaw law;
        law.e = rng.uniform(0.0, 1.0);
        law.mu = rng.uniform(0.0, 1.0);
        law.beta0 = rng.uniform(-1.0, 1.0);
        law.rule = rule;
        const CollisionImpulse<D> imp = collisionImpulse(b1, b2, n, law);
        ASSERT_LT(imp.gn, 0);
        // Energies in the frame of body 2 for a moving wall (the wall does work in any other frame).
        const Vec<D> frame = wall ? b2.v : Vec<D>::zero();
        auto energyIn = [&](CollisionBody<D> b, double m, double I) {
            b.v -= frame;
            return energy(b, m, I);
        };
        const double e0 = energyIn(b1, m1, I1) + (wall ? 0 : energy(b2, m2, I2));
        const Vec<D> p0 = b1.v * m1 + (wall ? Vec<D>::zero() : b2.v * m2);
        // Contact point between the centres x1 = 0 and x2 = -(a1 + a2) n: at -a1 n.
        const Vec<D> rel1 = n * b1.radius, rel2 = n * (-b2.radius);
        const auto L1 = angularAbout(b1, m1, I1, rel1);
        const auto L2 = wall ? Ang<D>::zero() : angularAbout(b2, m2, I2, rel2);
        const Vec<D> g0 = contactVelocity(b1, b2, n);
        CollisionBody<D> a1 = b1, a2 = b2;
        applyImpulse(a1, a2, n, imp.impulse);
        const Vec<D> g1 = contactVelocity(a1, a2, n);
        const double scaleE = e0;
        const double scaleP = m1 * norm(b1.v) + (wall ? 0 : m2 * norm(b2.v));
        // restitution laws
        EXPECT_NEAR(dot(g1, n), -imp.e * dot(g0, n), 1e-12 * norm(g0));
        const Vec<D> gt0 = g0 - n * dot(g0, n), gt1 = g1 - n * dot(g1, n);
        EXPECT_NEAR(norm(gt1 + gt0 * imp.beta), 0, 1e-12 * norm(g0));
        // energy change C.1
        const double e1 = energyIn(a1, m1, I1) + (wall ? 0 : energy(a2, m2, I2));
        EXPECT_NEAR(e1 - e0, imp.energyChange(), 1e-12 * scaleE) << "trial " << trial;
        EXPECT_LE(imp.energyChange(), 1e-15 * scaleE);
        // each body's angular momentum about the contact point (the impulse acts there)
        EXPECT_NEAR(norm(angularAbout(a1, m1, I1, rel1) - L1), 0, 1e-12 * (norm(L1) + m1 * b1.radius * norm(b1.v)));
        if (!wall) {
            EXPECT_NEAR(norm(angularAbout(a2, m2, I2, rel2) - L2), 0, 1e-12 * (norm(L2) + m2 * b2.radius * norm(b2.v)));
            // linear momentum
            const Vec<D> p1 = a1.v * m1 + a2.v * m2;
            EXPECT_NEAR(norm(p1 - p0), 0, 1e-12 * scaleP);
        } else {
            EXPECT_TRUE(a2.v == b2.v);  // the wall is not moved
        }
        // Walton: Coulomb in the sliding branch, beta0 otherwise
        if (rule == BetaRule::Walton) {
            const double pn = std::abs(dot(imp.impulse, n));
            const double pt = norm(imp.impulse - n * dot(imp.impulse, n));
            if (imp.sliding) {
                ++sliding;
                EXPECT_NEAR(pt, law.mu * pn, 1e-12 * pn);
            } else {
                ++sticking;
                EXPECT_EQ(imp.beta, law.beta0);
                EXPECT_LE(pt, law.mu * pn * (1 + 1e-12));
            }
        } else {
            EXPECT_EQ(imp.beta, law.beta0);
        }
    }
    if (rule == BetaRule::Walton) {
        EXPECT_GT(sliding, 100);
        EXPECT_GT(sticking, 100);
    }
}

TEST(EdmCollision, PairRandomStates2D) {
    checkRandomPairs<2>(false, BetaRule::Walton);
    checkRandomPairs<2>(false, BetaRule::Constant);
}
TEST(EdmCollision, PairRandomStates3D) {
    checkRandomPairs<3>(false, BetaRule::Walton);
    checkRandomPairs<3>(false, BetaRule::Constant);
}
TEST(EdmCollision, WallRandomStates2D) {
    checkRandomPairs<2>(true, BetaRule::Walton);
    checkRandomPairs<2>(true, BetaRule::Constant);
}
TEST(EdmCollision, WallRandomStates3D) {
    checkRandomPairs<3>(true, BetaRule::Walton);
    checkRandomPairs<3>(true, BetaRule::Constant);
}

// Equal particles: the operator reduces to the eta_n, eta_t form of Luding et al. (docs/physics.md C.1).
TEST(EdmCollision, EqualSpheresMatchLudingForm) {
    Rng rng(5, 3100);
    const double q = 0.4, a = 0.7, m = 2.0;
    for (int trial = 0; trial < 200; ++trial) {
        CollisionBody<3> b1{randomVec<3>(rng, 1), randomAng<3>(rng, 1), a, 1 / m, 1 / (q * m * a * a)};
        CollisionBody<3> b2{randomVec<3>(rng, 1), randomAng<3>(rng, 1), a, 1 / m, 1 / (q * m * a * a)};
        Vec<3> n = unit(randomVec<3>(rng, 1));
        if (dot(contactVelocity(b1, b2, n), n) > 0) n = -n;
        CollisionLaw law{0.8, 0, 0.3, BetaRule::Constant};
        const auto imp = collisionImpulse(b1, b2, n, law);
        CollisionBody<3> a1 = b1, a2 = b2;
        applyImpulse(a1, a2, n, imp.impulse);
        const Vec<3> g = contactVelocity(b1, b2, n);
        const double gn = dot(g, n);
        const Vec<3> gt = g - n * gn;
        const double etaN = (1 + law.e) / 2, etaT = q * (1 + law.beta0) / (2 * (1 + q));
        const Vec<3> v1 = b1.v - n * (etaN * gn) - gt * etaT;
        const Vec<3> w1 = b1.w + cross(n, gt) * (etaT / (q * a));
        const Vec<3> w2 = b2.w + cross(n, gt) * (etaT / (q * a));
        EXPECT_NEAR(norm(a1.v - v1), 0, 1e-13);
        EXPECT_NEAR(norm(a1.w - w1), 0, 1e-13);
        EXPECT_NEAR(norm(a2.w - w2), 0, 1e-13);
    }
}

// Wall limit of the pair operator: a partner of huge mass and inertia gives the wall formulas of C.1.
TEST(EdmCollision, WallIsTheInfiniteMassLimit) {
    Rng rng(6, 3200);
    for (int trial = 0; trial < 100; ++trial) {
        double m, I;
        CollisionBody<3> b = randomBody<3>(rng, m, I);
        Vec<3> n = unit(randomVec<3>(rng, 1));
        const Vec<3> u = randomVec<3>(rng, 0.2);
        CollisionBody<3> wall{u, Ang<3>::zero(), 0, 0, 0};
        if (dot(contactVelocity(b, wall, n), n) > 0) n = -n;
        CollisionBody<3> heavy{u, Ang<3>::zero(), 1.0, 1e-14, 1e-14};
        CollisionLaw law{0.7, 0.4, 0.5, BetaRule::Walton};
        const auto iw = collisionImpulse(b, wall, n, law);
        const auto ih = collisionImpulse(b, heavy, n, law);
        EXPECT_NEAR(norm(iw.impulse - ih.impulse), 0, 1e-11 * norm(iw.impulse));
        // explicit wall form: v' = v - (1+e) g_n n - (1+beta) q/(1+q) g_t
        CollisionBody<3> a = b, aw = wall;
        applyImpulse(a, aw, n, iw.impulse);
        const double q = I / (m * b.radius * b.radius);
        const Vec<3> g = contactVelocity(b, wall, n);
        const Vec<3> gt = g - n * dot(g, n);
        const Vec<3> v1 = b.v - n * ((1 + iw.e) * dot(g, n)) - gt * ((1 + iw.beta) * q / (1 + q));
        const Vec<3> w1 = b.w + cross(n, gt) * ((1 + iw.beta) / ((1 + q) * b.radius));
        EXPECT_NEAR(norm(a.v - v1), 0, 1e-13);
        EXPECT_NEAR(norm(a.w - w1), 0, 1e-12);
    }
}

// The crossover of Walton's rule (docs/physics.md C.2): |g_t|/|g_n| = mu (1+e)(1+1/q)/(1+beta0).
TEST(EdmCollision, WaltonCrossover) {
    const double e = 0.9, mu = 0.5, beta0 = 1.0, q = 0.4;
    const double crossover = mu * (1 + e) * (1 + 1 / q) / (1 + beta0);
    EXPECT_NEAR(crossover, 1.6625, 1e-12);
    EXPECT_EQ(waltonBeta(e, mu, beta0, 1 + 1 / q, 1.0, 0.99 * crossover), beta0);
    EXPECT_LT(waltonBeta(e, mu, beta0, 1 + 1 / q, 1.0, 1.01 * crossover), beta0);
    EXPECT_EQ(waltonBeta(e, 0.0, beta0, 1 + 1 / q, 1.0, 1.0), -1.0);  // smooth
}

}  // namespace
}  // namespace haet
