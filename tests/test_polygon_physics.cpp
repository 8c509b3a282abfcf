// Whole-system checks of the polygon contact law in the time-driven engine (PHYSICS.md G.3, F.1, F.3): a block at
// rest on the floor carries its weight with the static overlap Y A / l = m g; a block on an incline sticks while
// tan(theta) < mu and otherwise slides with a = g (sin(theta) - mu cos(theta)); polygons and disks together.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "contact/setup.hpp"
#include "physics_util.hpp"
#include "polygon/geometry.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world_util.hpp"

namespace haet {
namespace {

constexpr double kPi = 3.14159265358979323846;
using polygon::V2;
using testing::record;

constexpr double kYoung = 1e5;   // [N/m]
constexpr double kDensity = 2.0; // [kg/m^2]
constexpr double kR = 0.005;     // circumradius [m]

/// One polygon standing on the floor y = 0 under gravity tilted by theta (the same physics as a tilted floor).
/// Starts at the static overlap of a flat contact, so the transient is small.
struct FloorScene {
    World<2> w;
    TdmSettings s;
};

FloorScene blockOnFloor(std::vector<V2> body, double thetaDeg, double mu, double e) {
    FloorScene f;
    Scenario sc = testing::linearScenario(2, e, 1e-3, mu, TangentialLaw::Spring);
    sc.materials[0].young = kYoung;
    sc.materials[0].density = kDensity;
    const double th = thetaDeg * kPi / 180, g = 9.81;
    f.w.domain = testing::openBox<2>(0.2);
    f.w.domain.gravity = V2{{g * std::sin(th), -g * std::cos(th)}};
    double ymin = 0;
    for (const V2& v : body) ymin = std::min(ymin, v[1]);
    f.w.particles.addPolygon(V2{{0, 0}}, V2::zero(), Ang<2>::zero(), 0.0, body, kDensity, 0, 0);
    // Static overlap of a flat bottom of width b: Y b delta / (4 (h - delta/2)) = m g cos(theta), h = -ymin.
    double b = 0;
    const Particles<2>& p = f.w.particles;
    const V2* v = p.shapes.of(0);
    const int nv = p.shapes.count(0);
    for (int k = 0; k < nv; ++k) {
        const V2 a = v[k], c = v[(k + 1) % nv];
        if (std::abs(a[1] - ymin) < 1e-12 && std::abs(c[1] - ymin) < 1e-12) b = std::abs(c[0] - a[0]);
    }
    const double h = -ymin, mg = p.mass[0] * g * std::cos(th);
    const double delta = 4 * mg * h / (kYoung * b + 2 * mg);
    f.w.particles.x[0] = V2{{0, h - delta}};
    f.w.walls.push_back(Wall<2>{V2::zero(), V2{{0, 1}}, V2::zero(), 0});
    f.w.contact = buildContactSetup(sc, materialStats(f.w.particles, 1));
    f.s.integrator = IntegratorKind::Gear5;
    f.s.dt = f.w.contact.polygonStep;
    f.s.skin = 0.2 * kR;
    f.s.sortEvery = 0;
    return f;
}

TEST(PolygonStatic, OverlapCarriesTheWeight) {
    // A square (flat bottom of side s: closed form of the overlap) and a hexagon (flat bottom edge).
    const double side = kR * std::sqrt(2.0);
    for (int shape = 0; shape < 2; ++shape) {
        auto body = shape == 0 ? polygon::rectangle(1.0, kR, 0.0) : polygon::regularPolygon(6, kR, 0.0);
        FloorScene f = blockOnFloor(body, 0.0, 0.5, 0.3);
        Particles<2>& p = f.w.particles;
        p.x[0][1] += 0.2 * kR;  // dropped from a little height, so that the test starts out of equilibrium
        TdmEngine<2> eng(f.w, f.s);
        eng.advanceTo(0.15);  // [s]: about 2000 periods of the contact oscillation
        // Measured from the state: the overlap with the floor and its characteristic length.
        std::vector<V2> world;
        const V2* b = p.shapes.of(0);
        for (int k = 0; k < p.shapes.count(0); ++k)
            world.push_back(polygon::rotate(b[k], std::cos(p.angle[0][0]), std::sin(p.angle[0][0])) + p.x[0]);
        const polygon::Overlap o =
            polygon::halfPlaneOverlap(world.data(), int(world.size()), V2::zero(), V2{{0, 1}});
        const double l = 4 * norm(o.centroid - p.x[0]);
        const double mg = p.mass[0] * 9.81;
        record(shape == 0 ? "square_YA_over_l_minus_mg" : "hexagon_YA_over_l_minus_mg", kYoung * o.area / l / mg - 1);
        EXPECT_NEAR(kYoung * o.area / l, mg, 1e-6 * mg) << "shape " << shape;
        EXPECT_LT(norm(p.v[0]), 1e-9) << "at rest";
        EXPECT_LT(std::abs(p.angle[0][0]), 1e-9) << "no tilt";
        if (shape == 0) {  // flat square: delta = 4 m g h / (Y s + 2 m g)
            const double h = side / 2, delta = 4 * mg * h / (kYoung * side + 2 * mg);
            record("square_overlap_depth_over_side", delta / side);
            EXPECT_NEAR(p.x[0][1], h - delta, 1e-6 * delta);
        }
    }
}

struct SlopeResult {
    double accel = 0;    ///< least-squares acceleration along the slope over the window [m/s^2]
    double travel = 0;   ///< distance along the slope over the window [m]
    double maxTilt = 0;  ///< largest |angle| [rad]
};

SlopeResult slope(double thetaDeg, double mu) {
    FloorScene f = blockOnFloor(polygon::rectangle(3.0, kR, 0.0), thetaDeg, mu, 0.3);
    TdmEngine<2> eng(f.w, f.s);
    const Particles<2>& p = f.w.particles;
    const double T = 0.02;  // [s]: settle, then fit over the same time
    eng.advanceTo(T);
    const double x0 = p.x[0][0];
    double st = 0, sv = 0, stt = 0, stv = 0;
    int ns = 0;
    SlopeResult r;
    while (f.w.time < 2 * T) {
        eng.step();
        const double t = f.w.time, v = p.v[0][0];
        st += t, sv += v, stt += t * t, stv += t * v;
        ++ns;
        r.maxTilt = std::max(r.maxTilt, std::abs(p.angle[0][0]));
    }
    r.accel = (ns * stv - st * sv) / (ns * stt - st * st);
    r.travel = p.x[0][0] - x0;
    return r;
}

TEST(PolygonIncline, BlockSticksBelowTheFrictionAngle) {
    // tan(20 deg) = 0.36 < mu = 0.5; tan(25 deg) = 0.47 < 0.5.
    for (double deg : {20.0, 25.0}) {
        const SlopeResult r = slope(deg, 0.5);
        record("travel_over_size_" + std::to_string(int(deg)), r.travel / kR);
        EXPECT_LT(std::abs(r.travel), 1e-6 * kR) << deg << " deg";
        EXPECT_LT(r.maxTilt, 0.05) << deg << " deg";
    }
}

TEST(PolygonIncline, BlockSlidesBeyondTheFrictionAngle) {
    const double g = 9.81;
    for (auto [deg, mu] : {std::pair{35.0, 0.3}, std::pair{30.0, 0.5}, std::pair{40.0, 0.0}}) {
        const double th = deg * kPi / 180, a = g * (std::sin(th) - mu * std::cos(th));
        const SlopeResult r = slope(deg, mu);
        record("accel_relative_error_" + std::to_string(int(deg)), r.accel / a - 1);
        EXPECT_NEAR(r.accel, a, 0.01 * a) << deg << " deg, mu " << mu;
        EXPECT_LT(r.maxTilt, 0.05);
    }
}

}  // namespace
}  // namespace haet
