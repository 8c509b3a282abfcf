// Convergence order of the integrators on a damped harmonic oscillator (docs/physics.md F.1): x'' = -w0^2 x - 2 eta x'.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/rng.hpp"
#include "physics_util.hpp"
#include "tdm/integrators.hpp"

namespace haet {
namespace {

using testing::sameBits;

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
        integ->correct(p, dt, m);
    }
    return std::abs(p.x[0][0] - exact(T));
}

TEST(Integrators, GearConvergesAtFifthOrder) {
    const double e1 = error(true, 100), e2 = error(true, 200);
    const double order = std::log2(e1 / e2);
    EXPECT_GT(order, 4.8) << e1 << " " << e2;
    std::printf("Gear errors: %.3g (100 steps) %.3g (200 steps), order %.2f\n", e1, e2, order);
    EXPECT_LT(e2, 1e-8);  // docs/physics.md F.1 table: ~4e-10 at 200 steps/period
}

TEST(Integrators, VerletConvergesAtSecondOrder) {
    const double e1 = error(false, 100), e2 = error(false, 200);
    const double order = std::log2(e1 / e2);
    EXPECT_NEAR(order, 2.0, 0.2) << e1 << " " << e2;
}

// Velocity Verlet's corrector and next predictor four particles at a time (CorrectPredict::finishBlock, run by the
// force pass on each block) against its twins, Corrector then Predictor one particle at a time: the same bits,
// for blocks of every length 0..9 at every offset modulo 4, with frozen particles among them (which keep their
// position and velocity and get the velocity as mean velocity), two steps in a row (the second's corrector reads
// the mean velocities the first's predictor stored). With polygons (2D) the store keeps orientations, which are
// held to the same bits too; without, it keeps none.

template <int D>
void checkBlockStepMatchesTwins(bool polygons = false) {
    Rng rng(7, 3);
    auto u = [&] { return 2 * rng.uniform() - 1; };
    auto vec = [&]<int N>(Vec<N>) {
        Vec<N> r;
        for (int k = 0; k < N; ++k) r[k] = u();
        return r;
    };
    Particles<D> p;
    const std::size_t n = 47;
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint8_t flag = (i % 5 == 2 || i == 9 || i == 10) ? kFrozen : 0;
        if constexpr (D == 2) {
            if (polygons && i % 3 == 1) {
                const std::vector<Vec<2>> square{{{-0.4, -0.4}}, {{0.4, -0.4}}, {{0.4, 0.4}}, {{-0.4, 0.4}}};
                p.addPolygon(vec(Vec<D>{}), vec(Vec<D>{}), vec(Ang<D>{}), u(), square, 1000, 0, i, flag);
                continue;
            }
        }
        p.add(vec(Vec<D>{}), vec(Vec<D>{}), vec(Ang<D>{}), 0.5 + 0.2 * rng.uniform(), 1000, 0, i, flag);
    }
    ASSERT_EQ(p.angle.size(), polygons ? n : 0);
    for (std::size_t i = 0; i < n; ++i) {
        p.f[i] = vec(Vec<D>{});
        p.torque[i] = vec(Ang<D>{});
    }
    const double dt = 1e-3;
    // The drift test: one particle in seven (i % 7 == 3, one of them frozen: 17), in every lane of a group of four
    // somewhere, starts half a unit from its reference, beyond the limit of 0.1; the others stay within it.
    std::vector<Vec<D>> ref(p.x);
    for (std::size_t i = 0; i < n; ++i) ref[i] += Vec<D>::filled(i % 7 == 3 ? 0.5 : 0.0);
    VelocityVerlet<D> one, blocks;
    one.start(p, dt);
    blocks.start(p, dt);
    Particles<D> a = p, b = p;
    StepMotion<D> ma, mb;
    // A first predictor (the same for both) gives the mean velocities the correctors start from.
    one.predict(a, dt, ma, ref.data(), 1e300);
    blocks.predict(b, dt, mb, ref.data(), 1e300);
    for (int step = 0; step < 2; ++step) {
        // New forces, the same for both.
        for (std::size_t i = 0; i < n; ++i) {
            a.f[i] = b.f[i] = vec(Vec<D>{}) * 1e3;
            a.torque[i] = b.torque[i] = vec(Ang<D>{});
        }
        const double limit2 = 0.01;
        const auto pr = one.predictor(a, dt, ma, ref.data(), limit2);
        const auto c = one.corrector(a, dt, ma);
        // Blocks of lengths 0, 1, ..., 9, cycling, so that they start at every offset modulo 4; each block's
        // drift test against the one-particle results over the same particles.
        int farBlocks = 0;
        for (std::size_t s = 0, len = 0; s < n; s += len, len = (len + 1) % 10) {
            const std::size_t e = std::min(n, s + len);
            bool farOne = false;
            for (std::size_t i = s; i < e; ++i) {
                c(i, a.f[i], a.torque[i]);
                farOne |= pr(i);
            }
            std::atomic<bool> far{false};
            blocks.correctPredict(b, dt, mb, ref.data(), limit2, &far).finishBlock(s, e);
            EXPECT_EQ(far.load(), farOne) << "step " << step << ", block [" << s << ", " << e << ")";
            farBlocks += farOne;
        }
        EXPECT_GT(farBlocks, 3);
        EXPECT_TRUE(sameBits(a.x, b.x)) << "step " << step;
        EXPECT_TRUE(sameBits(a.v, b.v)) << "step " << step;
        EXPECT_TRUE(sameBits(a.w, b.w)) << "step " << step;
        EXPECT_TRUE(sameBits(a.angle, b.angle)) << "step " << step;
        EXPECT_TRUE(sameBits(ma.v, mb.v)) << "step " << step;
        EXPECT_TRUE(sameBits(ma.w, mb.w)) << "step " << step;
    }
    // Frozen particles did not move; the others did.
    for (std::size_t i = 0; i < n; ++i) {
        if (p.frozen(i)) {
            EXPECT_TRUE(std::memcmp(&b.x[i], &p.x[i], sizeof(Vec<D>)) == 0) << i;
            EXPECT_TRUE(std::memcmp(&b.v[i], &p.v[i], sizeof(Vec<D>)) == 0) << i;
        } else {
            EXPECT_NE(b.x[i][0], p.x[i][0]) << i;
            if (polygons) {
                EXPECT_NE(b.angle[i][0], p.angle[i][0]) << i;
            }
        }
    }
}

TEST(Integrators, VerletBlockStepMatchesOneParticleAtATime2D) { checkBlockStepMatchesTwins<2>(); }
TEST(Integrators, VerletBlockStepMatchesOneParticleAtATime3D) { checkBlockStepMatchesTwins<3>(); }
TEST(Integrators, VerletBlockStepMatchesOneParticleAtATimeWithOrientations) { checkBlockStepMatchesTwins<2>(true); }

}  // namespace
}  // namespace haet
