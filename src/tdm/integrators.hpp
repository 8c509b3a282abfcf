#pragma once
// Time integrators for the time-driven engine (PHYSICS.md F). Each step is predict -> forces -> correct:
// predict() moves positions and velocities to t + dt (velocities as the estimate the velocity-dependent forces
// see) and reports each particle's mean velocity over the step (displacement / dt), which drives the tangential
// spring so that its elongation is the true relative displacement of the contact points; correct() applies the
// new forces. Frozen particles are never moved. predict() also tells whether a particle has moved farther than a
// given distance from a reference position (the pair list's skin test), so the engine reads positions once.
#include <atomic>
#include <cstdint>
#include <vector>

#include "core/particles.hpp"

namespace haet {

/// Mean velocities over the last step: displacement / dt and rotation / dt.
template <int D>
struct StepMotion {
    std::vector<Vec<D>> v;
    std::vector<Ang<D>> w;
};

template <int D>
class Integrator {
public:
    virtual ~Integrator() = default;
    /// Called once after the first force evaluation, with forces at the initial state.
    virtual void start(const Particles<D>& p, double dt) = 0;
    /// Returns whether some particle is now farther than sqrt(limit2) from ref[i] (its position at the last
    /// pair-list build).
    virtual bool predict(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2) = 0;
    virtual void correct(Particles<D>& p, double dt) = 0;
    /// Reorders per-particle history after Particles::permute(order).
    virtual void permute(const std::vector<std::uint32_t>& order) = 0;
    /// Re-initialises the history of particle i from its current state and force (HAET mode switch).
    virtual void restart(const Particles<D>& p, std::size_t i, double dt) = 0;
    /// After the particle set changed: new particle k was old particle from[k], or is new (0xFFFFFFFF) and
    /// restarts from its current state and force.
    virtual void remap(const Particles<D>& p, const std::vector<std::uint32_t>& from, double dt) = 0;
};

/// Velocity Verlet (Swope et al. 1982; F.2). Forces see v* = v + a(t) dt, the explicit estimate of v(t+dt).
template <int D>
class VelocityVerlet final : public Integrator<D> {
public:
    void start(const Particles<D>& p, double dt) override;
    bool predict(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2) override;
    void correct(Particles<D>& p, double dt) override;
    void permute(const std::vector<std::uint32_t>& order) override;
    void restart(const Particles<D>& p, std::size_t i, double dt) override;
    void remap(const Particles<D>& p, const std::vector<std::uint32_t>& from, double dt) override;

    /// The corrector of one particle, for a force loop that finishes particles one at a time (TdmEngine runs it
    /// inside the force pass, with the particle's new force and torque at hand); correct() runs it over all.
    struct Corrector {
        Vec<D>* v;
        Ang<D>* w;
        Vec<D>* acc;
        Ang<D>* alpha;
        const double* invMass;
        const double* invInertia;
        const std::uint8_t* flags;
        double h;  ///< dt / 2 [s]
        [[gnu::always_inline]] void operator()(std::size_t i, const Vec<D>& f, const Ang<D>& torque) const {
            if (flags[i] & kFrozen) return;
            const Vec<D> a = f * invMass[i];
            const Ang<D> al = torque * invInertia[i];
            v[i] += (a - acc[i]) * h;  // v(t+dt) = v(t) + (a(t) + a(t+dt)) dt/2
            w[i] += (al - alpha[i]) * h;
            acc[i] = a;
            alpha[i] = al;
        }
    };
    Corrector corrector(Particles<D>& p, double dt) {
        return {p.v.data(),       p.w.data(),          acc_.data(),      alpha_.data(),
                p.invMass.data(), p.invInertia.data(), p.flags.data(),   0.5 * dt};
    }

    /// The predictor of one particle: position and angle to t + dt, velocities to v + a dt, the mean velocities
    /// over the step into m; returns whether the particle is now farther than sqrt(limit2) from ref[i].
    /// predict() runs it over all particles.
    struct Predictor {
        Vec<D>* x;
        Vec<D>* v;
        Ang<D>* ang;
        Ang<D>* w;
        Vec<D>* mv;
        Ang<D>* mw;
        const Vec<D>* acc;
        const Ang<D>* alpha;
        const std::uint8_t* flags;
        const Vec<D>* ref;
        double dt, limit2;
        [[gnu::always_inline]] bool operator()(std::size_t i) const {
            return one(i, x, v, ang, w, mv, mw, acc, alpha, flags, ref, dt, limit2);
        }
        /// The predictor of particle i on the arrays given.
        [[gnu::always_inline]] static bool one(std::size_t i, Vec<D>* __restrict x, Vec<D>* __restrict v,
                                               Ang<D>* __restrict ang, Ang<D>* __restrict w, Vec<D>* __restrict mv,
                                               Ang<D>* __restrict mw, const Vec<D>* __restrict acc,
                                               const Ang<D>* __restrict alpha, const std::uint8_t* __restrict flags,
                                               const Vec<D>* __restrict ref, double dt, double limit2) {
            if (flags[i] & kFrozen) {
                mv[i] = v[i];
                mw[i] = w[i];
                return false;
            }
            const double h2 = 0.5 * dt * dt;
            mv[i] = v[i] + acc[i] * (0.5 * dt);  // v(t + dt/2)
            mw[i] = w[i] + alpha[i] * (0.5 * dt);
            x[i] += v[i] * dt + acc[i] * h2;
            v[i] += acc[i] * dt;
            ang[i] += w[i] * dt + alpha[i] * h2;
            w[i] += alpha[i] * dt;
            return norm2(x[i] - ref[i]) > limit2;
        }
    };
    /// Sizes m for the particles and returns the predictor over them.
    Predictor predictor(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2);

    /// The corrector of this step, then the predictor of the next one, run by a force pass on each block of
    /// particles once their forces are final (finishBlock): it leaves every particle as correct() then predict()
    /// would, bit for bit, in one pass over the particles instead of two, while the block is in cache. A particle
    /// is finished after its last pair, so nothing in the pass reads it afterwards. Four particles at a time:
    /// their 3-vectors (or 2-vectors, or spins) as three (two, one) registers of four doubles, the same operations
    /// per element as Corrector and Predictor, which serve the last particles of a block and are the twins in the
    /// tests. *moved becomes true when some particle moved beyond the predictor's limit; safe from several threads.
    struct CorrectPredict {
        Corrector correct;
        Predictor predict;
        const Vec<D>* f;
        const Ang<D>* torque;
        std::atomic<bool>* moved;
        /// Nothing per particle: the block does it.
        void operator()(std::size_t, const Vec<D>&, const Ang<D>&) const {}
        void finishBlock(std::size_t b, std::size_t e) const;
    };
    CorrectPredict correctPredict(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2,
                                  std::atomic<bool>* moved) {
        return {corrector(p, dt), predictor(p, dt, m, ref, limit2), p.f.data(), p.torque.data(), moved};
    }

private:
    std::vector<Vec<D>> acc_;    ///< a(t) [m/s^2]
    std::vector<Ang<D>> alpha_;  ///< angular acceleration at t [rad/s^2]
};

/// Gear predictor-corrector with 6 values (F.1), corrector coefficients for velocity-dependent forces
/// (c0 = 3/16). Position and velocity live in the particle store; y2..y5 (scaled by dt^k/k!) here.
template <int D>
class Gear5 final : public Integrator<D> {
public:
    static constexpr double kC[6] = {3.0 / 16.0, 251.0 / 360.0, 1.0, 11.0 / 18.0, 1.0 / 6.0, 1.0 / 60.0};

    void start(const Particles<D>& p, double dt) override;
    bool predict(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2) override;
    void correct(Particles<D>& p, double dt) override;
    void permute(const std::vector<std::uint32_t>& order) override;
    void restart(const Particles<D>& p, std::size_t i, double dt) override;
    void remap(const Particles<D>& p, const std::vector<std::uint32_t>& from, double dt) override;

    /// Sets the scaled higher derivatives of particle i from unscaled ones (a, jerk, snap, crackle):
    /// consistent start-up when the caller knows them (PHYSICS.md F.1 start-up pitfall).
    void setDerivatives(std::size_t i, const Vec<D>& a, const Vec<D>& j3, const Vec<D>& j4, const Vec<D>& j5,
                        double dt);

private:
    std::vector<Vec<D>> y_[4];  ///< y2..y5 of positions
    std::vector<Ang<D>> r_[4];  ///< y2..y5 of rotation angles
};

}  // namespace haet
