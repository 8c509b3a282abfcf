// Convergence order of the integrators on a damped harmonic oscillator (PHYSICS.md F.1): x'' = -w0^2 x - 2 eta x'.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tdm/integrators.hpp"

namespace haet {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kW0 = 2 * kPi, kEta = 1.0;

/// Exact solution with x(0) = 1, v(0) = 0.
double exact(double t) {
    const double w = std::sqrt(kW0 * kW0 - kEta * kEta);
    return std::exp(-kEta * t) * (std::cos(w * t) + kEta / w * std::sin(w * t));
}

/// Integrates one period with n steps; returns |x(T) - exact|.
double error(bool gear, int n) {
    const double T = 1.0, dt = T / n;
    Particles<2> p;
    p.add(Vec<2>{{1, 0}}, Vec<2>::zero(), Ang<2>::zero(), 1.0, 1.0 / kPi, 0, 0);  // mass 1
    auto force = [&]() {
        p.f[0] = (p.x[0] * (-kW0 * kW0) - p.v[0] * (2 * kEta)) * p.mass[0];
        p.torque[0] = Ang<2>::zero();
    };
    force();
    std::unique_ptr<Integrator<2>> integ;
    if (gear) {
        auto g = std::make_unique<Gear5<2>>();
        g->start(p, dt);
        // consistent start-up: derivatives of the exact solution by differentiating the ODE
        const double x0 = 1, v0 = 0;
        const double a0 = -kW0 * kW0 * x0 - 2 * kEta * v0;
        const double j0 = -kW0 * kW0 * v0 - 2 * kEta * a0;
        const double s0 = -kW0 * kW0 * a0 - 2 * kEta * j0;
        const double c0 = -kW0 * kW0 * j0 - 2 * kEta * s0;
        g->setDerivatives(0, Vec<2>{{a0, 0}}, Vec<2>{{j0, 0}}, Vec<2>{{s0, 0}}, Vec<2>{{c0, 0}}, dt);
        integ = std::move(g);
    } else {
        integ = std::make_unique<VelocityVerlet<2>>();
        integ->start(p, dt);
    }
    StepMotion<2> m;
    const std::vector<Vec<2>> ref = p.x;
    for (int k = 0; k < n; ++k) {
        integ->predict(p, dt, m, ref.data(), 1e300);
        force();
        integ->correct(p, dt);
    }
    return std::abs(p.x[0][0] - exact(T));
}

TEST(Integrators, GearConvergesAtFifthOrder) {
    const double e1 = error(true, 100), e2 = error(true, 200);
    const double order = std::log2(e1 / e2);
    EXPECT_GT(order, 4.8) << e1 << " " << e2;
    std::printf("Gear errors: %.3g (100 steps) %.3g (200 steps), order %.2f\n", e1, e2, order);
    EXPECT_LT(e2, 1e-8);  // PHYSICS.md F.1 table: ~4e-10 at 200 steps/period
}

TEST(Integrators, VerletConvergesAtSecondOrder) {
    const double e1 = error(false, 100), e2 = error(false, 200);
    const double order = std::log2(e1 / e2);
    EXPECT_NEAR(order, 2.0, 0.2) << e1 << " " << e2;
}

}  // namespace
}  // namespace haet
