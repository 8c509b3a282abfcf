#pragma once
// Time integrators for the time-driven engine (PHYSICS.md F). Each step is predict -> forces -> correct:
// predict() moves positions and velocities to t + dt (velocities as the estimate the velocity-dependent forces
// see) and reports each particle's mean velocity over the step (displacement / dt), which drives the tangential
// spring so that its elongation is the true relative displacement of the contact points; correct() applies the
// new forces. Frozen particles are never moved.
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
    virtual void predict(Particles<D>& p, double dt, StepMotion<D>& m) = 0;
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
    void predict(Particles<D>& p, double dt, StepMotion<D>& m) override;
    void correct(Particles<D>& p, double dt) override;
    void permute(const std::vector<std::uint32_t>& order) override;
    void restart(const Particles<D>& p, std::size_t i, double dt) override;
    void remap(const Particles<D>& p, const std::vector<std::uint32_t>& from, double dt) override;

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
    void predict(Particles<D>& p, double dt, StepMotion<D>& m) override;
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
