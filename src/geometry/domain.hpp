#pragma once
// Simulation box: bounds, periodic axes, gravity; and plane walls.
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>

#include "core/vec.hpp"
#include "geometry/motion.hpp"

namespace haet {

template <int D>
struct Domain {
    Vec<D> lo, hi;                   ///< box corners [m]
    std::array<bool, D> periodic{};  ///< periodic per axis
    Vec<D> gravity;                  ///< [m/s^2]

    Vec<D> length() const { return hi - lo; }
    bool fullyPeriodic() const {
        for (int k = 0; k < D; ++k)
            if (!periodic[k]) return false;
        return true;
    }
    double volume() const {
        double v = 1;
        for (int k = 0; k < D; ++k) v *= hi[k] - lo[k];
        return v;
    }
    /// The unwrapped position of x after `image[k]` crossings of periodic axis k (Particles::image).
    Vec<D> unwrap(Vec<D> x, const std::array<std::int32_t, D>& image) const {
        for (int k = 0; k < D; ++k) x[k] += image[k] * (hi[k] - lo[k]);
        return x;
    }
    /// Minimum-image displacement along periodic axes.
    Vec<D> minimumImage(Vec<D> d) const {
        for (int k = 0; k < D; ++k) {
            if (!periodic[k]) continue;
            const double L = hi[k] - lo[k];
            d[k] -= L * std::nearbyint(d[k] / L);
        }
        return d;
    }
};

/// An infinite plane wall, translating with a constant velocity and optionally oscillating about that motion
/// (a vibrated floor, docs/physics.md H.1): point(t) = point + v s + A (sin(2 pi f s + phi) - sin phi), s = t - origin.
/// The normal points into the domain. origin is 0 until the motion is changed during a run (setVelocity).
template <int D>
struct Wall {
    Vec<D> point;     ///< a point of the plane at time 0 [m]
    Vec<D> normal;    ///< unit normal into the domain
    Vec<D> velocity;  ///< [m/s]
    int material = 0;
    Vec<D> amplitude;      ///< oscillation amplitude A [m]
    double frequency = 0;  ///< oscillation frequency f [Hz]; 0 = none
    double phase = 0;      ///< oscillation phase phi [rad]
    std::string name;      ///< named walls report their load (series.csv); may be empty
    int id = 0;            ///< the wall's place among the scenario's walls, 0-based (outputs number walls by it)
    double origin = 0;     ///< the time point, velocity and the oscillation count from [s]
    bool changed = false;  ///< the motion was changed during the run (setVelocity): not the scenario's any more
    /// Where the plane is and how fast it moves at the time of the current force pass (moveTo).
    Vec<D> pointNow, velocityNow;

    /// A plane through `p` with unit normal `n`, moving with velocity `v`, at time 0.
    static Wall plane(const Vec<D>& p, const Vec<D>& n, const Vec<D>& v, int material) {
        Wall w;
        w.point = p;
        w.normal = n;
        w.velocity = v;
        w.material = material;
        w.moveTo(0);
        return w;
    }
    bool oscillates() const { return frequency != 0; }
    // (t - origin is t itself while origin is 0: the same bits as the formula with t.)
    Vec<D> pointAt(double t) const {
        const double s = t - origin;
        Vec<D> p = point + velocity * s;
        if (oscillates()) p += oscillationDisplacement(amplitude, frequency, phase, s);
        return p;
    }
    Vec<D> velocityAt(double t) const {
        if (!oscillates()) return velocity;
        return velocity + oscillationVelocity(amplitude, frequency, phase, t - origin);
    }
    /// From time t on, the plane translates with velocity v, from where it is at t (no jump); an oscillation goes on
    /// in phase.
    void setVelocity(const Vec<D>& v, double t) {
        point = pointAt(t);
        if (oscillates())
            phase = std::remainder(phase + 2 * std::numbers::pi * frequency * (t - origin), 2 * std::numbers::pi);
        origin = t;
        velocity = v;
        changed = true;
        moveTo(t);
    }
    /// Sets pointNow and velocityNow to time t: once before every force pass, which reads only them.
    void moveTo(double t) {
        pointNow = pointAt(t);
        velocityNow = velocityAt(t);
    }
    /// Signed distance of x from the plane at time t (positive inside the domain) [m].
    double distance(const Vec<D>& x, double t) const { return dot(normal, x - pointAt(t)); }
    /// The same at the time of moveTo.
    double distanceNow(const Vec<D>& x) const { return dot(normal, x - pointNow); }
};

}  // namespace haet
