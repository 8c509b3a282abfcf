#pragma once
// Time integrators for the time-driven engine (docs/physics.md F). Each step is predict -> forces -> correct:
// predict() moves positions and velocities to t + dt (velocities as the estimate the velocity-dependent forces
// see) and reports each particle's mean velocity over the step (displacement / dt), which drives the tangential
// spring so that its elongation is the true relative displacement of the contact points; correct() applies the
// new forces. Frozen particles are never moved. predict() also tells whether a particle has moved farther than a
// given distance from a reference position (the pair list's skin test), so the engine reads positions once.
#include <atomic>
#include <cstdint>
#include <vector>

#include "core/particles.hpp"
#include "io/checkpoint.hpp"

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
    /// m: the mean velocities the predict() of this step reported.
    virtual void correct(Particles<D>& p, double dt, const StepMotion<D>& m) = 0;
    /// Reorders per-particle history after Particles::permute(order).
    virtual void permute(const std::vector<std::uint32_t>& order) = 0;
    /// Re-initialises the history of particle i from its current state and force (HAET mode switch).
    virtual void restart(const Particles<D>& p, std::size_t i, double dt) = 0;
    /// After the particle set changed: new particle k was old particle from[k], or is new (0xFFFFFFFF) and
    /// restarts from its current state and force.
    virtual void remap(const Particles<D>& p, const std::vector<std::uint32_t>& from, double dt) = 0;
    /// The integrator's own history, for a checkpoint (none for velocity Verlet); load takes n particles' worth.
    virtual void saveState(ByteWriter&) const {}
    virtual void loadState(ByteReader&, std::size_t) {}
};

/// Velocity Verlet (Swope et al. 1982; F.2). Forces see v* = v + a(t) dt, the explicit estimate of v(t+dt).
/// It keeps no state of its own: a(t) is the force the store holds over the mass (the predictor runs before the
/// next force pass overwrites it), and the corrector starts from the half-step velocity v(t) + a(t) dt/2, which
/// the predictor reports as the step's mean velocity: v(t+dt) = v(t + dt/2) + a(t+dt) dt/2.
template <int D>
class VelocityVerlet final : public Integrator<D> {
public:
    void start(const Particles<D>& p, double dt) override;
    bool predict(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2) override;
    void correct(Particles<D>& p, double dt, const StepMotion<D>& m) override;
    void permute(const std::vector<std::uint32_t>& order) override;
    void restart(const Particles<D>& p, std::size_t i, double dt) override;
    void remap(const Particles<D>& p, const std::vector<std::uint32_t>& from, double dt) override;

    /// The corrector of one particle, for a force loop that finishes particles one at a time (TdmEngine runs it
    /// inside the force pass, with the particle's new force and torque at hand); correct() runs it over all.
    struct Corrector {
        Vec<D>* v;
        Ang<D>* w;
        const Vec<D>* mv;  ///< the step's mean velocities: v(t + dt/2)
        const Ang<D>* mw;
        const double* invMass;
        const double* invInertia;
        const std::uint8_t* flags;
        double h;  ///< dt / 2 [s]
        [[gnu::always_inline]] void operator()(std::size_t i, const Vec<D>& f, const Ang<D>& torque) const {
            if (flags[i] & kFrozen) return;
            const Vec<D> a = f * invMass[i];
            const Ang<D> al = torque * invInertia[i];
            v[i] = mv[i] + a * h;  // v(t+dt) = v(t + dt/2) + a(t+dt) dt/2
            w[i] = mw[i] + al * h;
        }
    };
    Corrector corrector(Particles<D>& p, double dt, const StepMotion<D>& m) {
        return {p.v.data(),       p.w.data(),          m.v.data(),     m.w.data(),
                p.invMass.data(), p.invInertia.data(), p.flags.data(), 0.5 * dt};
    }

    /// The predictor of one particle: position and angle (when kept, else ang is null) to t + dt, velocities to
    /// v + a dt, the mean velocities over the step into m; returns whether the particle is now farther than
    /// sqrt(limit2) from ref[i].
    /// predict() runs it over all particles. a(t): the force and torque in the store (of the last force pass).
    struct Predictor {
        Vec<D>* x;
        Vec<D>* v;
        Ang<D>* ang;
        Ang<D>* w;
        Vec<D>* mv;
        Ang<D>* mw;
        const Vec<D>* f;
        const Ang<D>* torque;
        const double* invMass;
        const double* invInertia;
        const std::uint8_t* flags;
        const Vec<D>* ref;
        double dt, limit2;
        [[gnu::always_inline]] bool operator()(std::size_t i) const {
            return one(i, x, v, ang, w, mv, mw, f, torque, invMass, invInertia, flags, ref, dt, limit2);
        }
        /// The predictor of particle i on the arrays given.
        [[gnu::always_inline]] static bool one(std::size_t i, Vec<D>* __restrict x, Vec<D>* __restrict v,
                                               Ang<D>* __restrict ang, Ang<D>* __restrict w, Vec<D>* __restrict mv,
                                               Ang<D>* __restrict mw, const Vec<D>* __restrict f,
                                               const Ang<D>* __restrict torque, const double* __restrict invMass,
                                               const double* __restrict invInertia,
                                               const std::uint8_t* __restrict flags, const Vec<D>* __restrict ref,
                                               double dt, double limit2) {
            if (flags[i] & kFrozen) {
                mv[i] = v[i];
                mw[i] = w[i];
                return false;
            }
            const double h2 = 0.5 * dt * dt;
            const Vec<D> a = f[i] * invMass[i];  // a(t), as the corrector had it
            const Ang<D> al = torque[i] * invInertia[i];
            mv[i] = v[i] + a * (0.5 * dt);  // v(t + dt/2)
            mw[i] = w[i] + al * (0.5 * dt);
            x[i] += v[i] * dt + a * h2;
            v[i] += a * dt;
            if (ang) ang[i] += w[i] * dt + al * h2;
            w[i] += al * dt;
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
        Predictor predict;  ///< its f and torque: the new forces (this step's, the next step's a(t))
        std::atomic<bool>* moved;
        /// Nothing per particle: the block does it.
        void operator()(std::size_t, const Vec<D>&, const Ang<D>&) const {}
        void finishBlock(std::size_t b, std::size_t e) const;
    };
    CorrectPredict correctPredict(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2,
                                  std::atomic<bool>* moved) {
        const Predictor pr = predictor(p, dt, m, ref, limit2);  // sizes m first
        return {corrector(p, dt, m), pr, moved};
    }
};

/// Gear predictor-corrector with 6 values (F.1), corrector coefficients for velocity-dependent forces
/// (c0 = 3/16). Position and velocity live in the particle store; y2..y5 (scaled by dt^k/k!) here.
template <int D>
class Gear5 final : public Integrator<D> {
public:
    static constexpr double kC[6] = {3.0 / 16.0, 251.0 / 360.0, 1.0, 11.0 / 18.0, 1.0 / 6.0, 1.0 / 60.0};

    void start(const Particles<D>& p, double dt) override;
    bool predict(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2) override;
    void correct(Particles<D>& p, double dt, const StepMotion<D>& m) override;
    void permute(const std::vector<std::uint32_t>& order) override;
    void restart(const Particles<D>& p, std::size_t i, double dt) override;
    void remap(const Particles<D>& p, const std::vector<std::uint32_t>& from, double dt) override;

    /// Sets the scaled higher derivatives of particle i from unscaled ones (a, jerk, snap, crackle):
    /// consistent start-up when the caller knows them (docs/physics.md F.1 start-up pitfall).
    void setDerivatives(std::size_t i, const Vec<D>& a, const Vec<D>& j3, const Vec<D>& j4, const Vec<D>& j5,
                        double dt);
    void saveState(ByteWriter& out) const override {
        for (const auto& a : y_) out.putVector(a);
        for (const auto& a : r_) out.putVector(a);
    }
    void loadState(ByteReader& in, std::size_t n) override {
        for (auto& a : y_) in.getVector(a, n, "a Gear derivative of positions");
        for (auto& a : r_) in.getVector(a, n, "a Gear derivative of angles");
    }

private:
    std::vector<Vec<D>> y_[4];  ///< y2..y5 of positions
    std::vector<Ang<D>> r_[4];  ///< y2..y5 of rotation angles
};

}  // namespace haet
