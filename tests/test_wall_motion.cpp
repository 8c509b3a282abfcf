// A wall's motion changed during a run (geometry/motion.hpp Motion::rebase, geometry/domain.hpp Wall::setVelocity):
// the wall goes on from where it was, moves as the new motion says from then on (checked against the formula of a
// rigid motion started at that time), its surface velocity is the rate of change of its points, and a rebase that
// changes nothing changes no place.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "geometry/domain.hpp"
#include "geometry/motion.hpp"

namespace {

using haet::Motion;
using haet::Pose;
using haet::Vec;

constexpr double kTol = 1e-13;

void expectNear(const Vec<3>& a, const Vec<3>& b, double tol) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], tol) << "component " << k;
}

Motion<3> tumbling() {
    Motion<3> m;
    m.velocity = {{0.1, -0.2, 0.05}};
    m.amplitude = {{0.0, 0.0, 0.003}};
    m.frequency = 7;
    m.phase = 0.4;
    m.centre = {{0.2, 0.1, -0.1}};
    m.axis = {{0.0, 0.6, 0.8}};
    m.omega = 3.0;
    return m;
}

const Vec<3> kBody[] = {{{0.0, 0.0, 0.0}}, {{0.3, -0.1, 0.2}}, {{-0.5, 0.4, 0.1}}};

TEST(WallMotion, ARebaseAloneChangesNoPlace) {
    const Motion<3> m = tumbling();
    Motion<3> r = m;
    r.rebase(0.37);
    for (double t : {0.37, 0.4, 0.9, 2.5}) {
        const Pose<3> a = m.at(t), b = r.at(t);
        for (const Vec<3>& p : kBody) expectNear(b.toWorld(p), a.toWorld(p), kTol);
        expectNear(b.velocity, a.velocity, kTol);
        expectNear(b.centre, a.centre, kTol);
        for (const Vec<3>& p : kBody)
            expectNear(b.surfaceVelocity(a.toWorld(p)), a.surfaceVelocity(a.toWorld(p)), 1e-12);
    }
}

TEST(WallMotion, ANewMotionGoesOnFromWhereTheWallIs) {
    const double t0 = 0.37;
    Motion<3> m = tumbling();
    const Pose<3> then = m.at(t0);
    m.rebase(t0);
    m.velocity = {{0.0, 0.3, 0.0}};
    m.axis = {{1.0, 0.0, 0.0}};
    m.omega = -2.0;
    // no jump at t0
    const Pose<3> now = m.at(t0);
    for (const Vec<3>& p : kBody) expectNear(now.toWorld(p), then.toWorld(p), kTol);
    // later: x(t) = c0 + d(s) + R_x(omega s) (x(t0) - c0), s = t - t0, with the oscillation going on in phase
    const Vec<3> c0 = then.centre;
    for (double t : {0.4, 0.8, 1.9}) {
        const double s = t - t0, a = -2.0 * s;
        const double w = 2 * std::numbers::pi * 7;
        const Vec<3> d =
            Vec<3>{{0.0, 0.3, 0.0}} * s + Vec<3>{{0.0, 0.0, 0.003}} * (std::sin(w * t + 0.4) - std::sin(w * t0 + 0.4));
        const Pose<3> pose = m.at(t);
        for (const Vec<3>& p : kBody) {
            const Vec<3> q = then.toWorld(p) - c0;
            const Vec<3> turned{
                {q[0], std::cos(a) * q[1] - std::sin(a) * q[2], std::sin(a) * q[1] + std::cos(a) * q[2]}};
            expectNear(pose.toWorld(p), c0 + d + turned, 1e-12);
        }
    }
}

TEST(WallMotion, TheSurfaceVelocityIsTheRateOfChangeOfTheWallsPoints) {
    Motion<3> m = tumbling();
    m.rebase(0.37);
    m.velocity = {{-0.2, 0.0, 0.1}};
    m.axis = {{0.0, 0.0, 1.0}};
    m.omega = 5.0;
    const double t = 0.81, h = 1e-6;
    for (const Vec<3>& p : kBody) {
        const Vec<3> rate = (m.at(t + h).toWorld(p) - m.at(t - h).toWorld(p)) * (0.5 / h);
        const Pose<3> pose = m.at(t);
        expectNear(pose.surfaceVelocity(pose.toWorld(p)), rate, 1e-7);
    }
}

TEST(WallMotion, APlaneGoesOnFromItsPointInPhase) {
    haet::Wall<2> w = haet::Wall<2>::plane({{0.0, 0.1}}, {{0.0, 1.0}}, {{0.02, 0.0}}, 0);
    w.amplitude = {{0.0, 0.002}};
    w.frequency = 11;
    w.phase = 0.3;
    const double t0 = 0.4;
    const Vec<2> before = w.pointAt(t0), vBefore = w.velocityAt(t0);
    w.setVelocity({{-0.05, 0.0}}, t0);
    EXPECT_TRUE(w.changed);
    EXPECT_EQ(w.pointAt(t0)[0], before[0]);
    EXPECT_EQ(w.pointAt(t0)[1], before[1]);
    // the oscillation's velocity goes on; the translation is the new one
    EXPECT_NEAR(w.velocityAt(t0)[1], vBefore[1], 1e-12);
    EXPECT_EQ(w.velocityAt(t0)[0], -0.05);
    for (double t : {0.45, 1.3}) {
        const double osc =
            0.002 * (std::sin(2 * std::numbers::pi * 11 * t + 0.3) - std::sin(2 * std::numbers::pi * 11 * t0 + 0.3));
        EXPECT_NEAR(w.pointAt(t)[0], before[0] - 0.05 * (t - t0), kTol);
        EXPECT_NEAR(w.pointAt(t)[1], before[1] + osc, 1e-12);
    }
}

}  // namespace
