// One physics (docs/physics.md A.1): for one material, a binary collision gives the same normal and tangential
// restitution whether the time-driven engine integrates the soft contact or the event-driven engine applies its
// collision operator (Walton's rule with the e the soft law really produces). Same set-up as
// tests/test_collisions.cpp: linear spring-dashpot e = 0.9 (force clipped at zero), t_c = 10 us, Cundall-Strack
// spring k_t/k_n = q/(1+q), mu = 0.5; two particles (or one and a floor wall) built directly in a World.
#include <gtest/gtest.h>

#include <cmath>

#include "edm/engine.hpp"
#include "tdm/engine.hpp"
#include "world_util.hpp"

namespace haet {
namespace {

constexpr double kTc = 1e-5;  // contact duration [s]
constexpr double kA = 0.01;   // radius [m]
constexpr double kVn = 0.1;   // normal approach speed [m/s]
constexpr double kE = 0.9, kMu = 0.5;
// Walton's sticking value = what the sticking spring gives: -cos(omega_t t_c) (docs/physics.md B.4 table).
constexpr double kBeta0 = 0.99787;

template <int D>
struct Outcome {
    double e = 0, beta = 0;
};

/// World with particle 0 approaching particle 1 (or a floor), relative velocity -vn n + ratio vn t.
template <int D>
World<D> collisionWorld(bool wall, double ratio, double phase) {
    Scenario sc = testing::linearScenario(D, kE, kTc, kMu, TangentialLaw::Spring);
    sc.materials[0].tangentialRestitution = kBeta0;
    World<D> w;
    w.domain = testing::openBox<D>(1.0);
    Vec<D> n = Vec<D>::zero(), t = Vec<D>::zero();
    n[D - 1] = 1;
    t[0] = 1;
    const double gap = kVn * (kTc / 50) * (5 + phase);
    const Vec<D> v0 = n * (-kVn) + t * (ratio * kVn);
    if (wall) {
        w.particles.add(n * (kA + gap), v0, Ang<D>::zero(), kA, 1000, 0, 0);
        w.walls.push_back(Wall<D>::plane(Vec<D>::zero(), n, Vec<D>::zero(), 0));
    } else {
        w.particles.add(n * (kA + 0.5 * gap), v0 * 0.5, Ang<D>::zero(), kA, 1000, 0, 0);
        w.particles.add(n * (-kA - 0.5 * gap), v0 * -0.5, Ang<D>::zero(), kA, 1000, 0, 1);
    }
    w.contact = buildContactSetup<D>(sc, testing::statsOf(w.particles, 1));
    return w;
}

template <int D>
Vec<D> contactPointVelocity(const World<D>& w, bool wall) {
    Vec<D> n = Vec<D>::zero();
    n[D - 1] = 1;
    const auto& p = w.particles;
    if (wall) return p.v[0] - cross(p.w[0] * kA, n);
    return p.v[0] - p.v[1] - cross((p.w[0] + p.w[1]) * kA, n);
}

template <int D>
Outcome<D> measure(const Vec<D>& g0, const Vec<D>& g1) {
    Outcome<D> o;
    o.e = -g1[D - 1] / g0[D - 1];
    o.beta = g0[0] != 0 ? -g1[0] / g0[0] : 0;
    return o;
}

template <int D>
Outcome<D> tdmCollision(bool wall, double ratio, double phase) {
    World<D> w = collisionWorld<D>(wall, ratio, phase);
    TdmSettings s;
    s.integrator = IntegratorKind::Verlet;
    s.dt = kTc / 50;
    s.skin = kA;
    s.sortEvery = 0;
    TdmEngine<D> eng(w, s);
    const Vec<D> g0 = contactPointVelocity(w, wall);
    bool touched = false;
    for (int k = 0; k < 400; ++k) {
        eng.step();
        if (eng.forceStats().contacts > 0)
            touched = true;
        else if (touched)
            break;
    }
    EXPECT_TRUE(touched);
    return measure(g0, contactPointVelocity(w, wall));
}

template <int D>
Outcome<D> edmCollision(bool wall, double ratio) {
    World<D> w = collisionWorld<D>(wall, ratio, 0.0);
    EdmEngine<D> eng(w, EdmSettings{});
    const Vec<D> g0 = contactPointVelocity(w, wall);
    eng.advanceTo(20 * kTc);
    EXPECT_EQ(eng.collisions(), 1u);
    return measure(g0, contactPointVelocity(w, wall));
}

/// Head-on: the mean TDM restitution over contact-onset phases (single collisions scatter by the onset within a
/// step, see HeadOn in test_collisions.cpp) against the EDM's, which is PairCoeffs::restitution.
template <int D>
void headOn(bool wall) {
    constexpr int kPhases = 16;
    double sum = 0;
    for (int k = 0; k < kPhases; ++k) sum += tdmCollision<D>(wall, 0.0, (k + 0.5) / kPhases).e;
    const double eTdm = sum / kPhases;
    const double eEdm = edmCollision<D>(wall, 0.0).e;
    EXPECT_NEAR(eEdm, eTdm, 2e-3) << (wall ? "wall" : "pair");
    ::testing::Test::RecordProperty(wall ? "e_wall" : "e_pair", std::to_string(eEdm) + " vs " + std::to_string(eTdm));
}

/// Oblique: beta of both engines, away from Walton's stick/slip crossover (|g_t|/|g_n| = 1.66 spheres, 1.43 disks).
template <int D>
void oblique(bool wall) {
    for (double ratio : {0.1, 0.5, 3.0, 5.0, 10.0}) {
        const Outcome<D> tdm = tdmCollision<D>(wall, ratio, 0.1);
        const Outcome<D> edm = edmCollision<D>(wall, ratio);
        EXPECT_NEAR(edm.beta, tdm.beta, 0.02) << (wall ? "wall" : "pair") << ", g_t/g_n = " << ratio;
        EXPECT_NEAR(edm.e, tdm.e, 0.01) << (wall ? "wall" : "pair") << ", g_t/g_n = " << ratio;
    }
}

TEST(EdmConsistency, HeadOnRestitutionMatchesTdm2D) {
    headOn<2>(false);
    headOn<2>(true);
}
TEST(EdmConsistency, HeadOnRestitutionMatchesTdm3D) {
    headOn<3>(false);
    headOn<3>(true);
}
TEST(EdmConsistency, ObliqueBetaMatchesTdm2D) {
    oblique<2>(false);
    oblique<2>(true);
}
TEST(EdmConsistency, ObliqueBetaMatchesTdm3D) {
    oblique<3>(false);
    oblique<3>(true);
}

}  // namespace
}  // namespace haet
