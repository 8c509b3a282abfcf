#pragma once
// Rigid motion of a wall (docs/physics.md H.1): a translation with constant velocity, a sinusoidal oscillation and a
// rotation about an axis, alone or combined. A wall is defined in its body frame, which is the world frame at t = 0;
// at time t a body point b is at
//     x(t) = c + d(t) + R(t) (b - c),    d(t) = v t + A sin(2 pi f t + phi) - A sin(phi),
// with c the centre of rotation, R(t) the rotation by the angle omega t about the axis, so d(0) = 0 and x(0) = b.
// The wall's material point at x moves with u(x, t) = v + 2 pi f A cos(2 pi f t + phi) + Omega x (x - c - d(t)),
// Omega = omega times the unit axis (2D: the spin about z): the velocity a contact sees at its contact point.
//
// A motion changed during a run (Motion::rebase, from a script) counts from the time of the change, t0: the pose the
// wall had then becomes its base B (body point b -> B b), and x(t) = c0 + d(t - t0) + R(t - t0) (B b - c0), with c0 the
// centre of rotation at t0, so that the wall goes on from where it was. Until then the base is the identity, t0 = 0,
// and the formulas above are computed as written (the same bits).
#include <cmath>
#include <numbers>

#include "core/vec.hpp"

namespace haet {

/// The displacement A (sin(2 pi f t + phi) - sin phi) of an oscillation, zero at t = 0 [m], and its velocity [m/s]:
/// the oscillation of planes (geometry/domain.hpp) and of every other wall (Motion below).
template <int D>
Vec<D> oscillationDisplacement(const Vec<D>& amplitude, double frequency, double phase, double t) {
    const double w = 2 * std::numbers::pi * frequency;
    return amplitude * (std::sin(w * t + phase) - std::sin(phase));
}
template <int D>
Vec<D> oscillationVelocity(const Vec<D>& amplitude, double frequency, double phase, double t) {
    const double w = 2 * std::numbers::pi * frequency;
    return amplitude * (w * std::cos(w * t + phase));
}

/// A rotation matrix in D dimensions, applied as R b and R^T x.
template <int D>
struct Rotation {
    std::array<std::array<double, D>, D> m{};

    static Rotation identity() {
        Rotation r;
        for (int k = 0; k < D; ++k) r.m[k][k] = 1;
        return r;
    }
    Vec<D> apply(const Vec<D>& b) const {
        Vec<D> x;
        for (int i = 0; i < D; ++i) {
            double s = m[i][0] * b[0];
            for (int k = 1; k < D; ++k) s += m[i][k] * b[k];
            x[i] = s;
        }
        return x;
    }
    /// The rotation `this` after `first`: (this first) b.
    Rotation after(const Rotation& first) const {
        Rotation r;
        for (int i = 0; i < D; ++i)
            for (int j = 0; j < D; ++j) {
                double s = m[i][0] * first.m[0][j];
                for (int k = 1; k < D; ++k) s += m[i][k] * first.m[k][j];
                r.m[i][j] = s;
            }
        return r;
    }
    Vec<D> applyInverse(const Vec<D>& x) const {
        Vec<D> b;
        for (int i = 0; i < D; ++i) {
            double s = m[0][i] * x[0];
            for (int k = 1; k < D; ++k) s += m[k][i] * x[k];
            b[i] = s;
        }
        return b;
    }
};

/// The rotation by `angle` [rad] about the unit axis (3D, Rodrigues' formula) or about z (2D, axis ignored).
template <int D>
Rotation<D> rotationOf(const Ang<D>& axis, double angle) {
    Rotation<D> r;
    const double c = std::cos(angle), s = std::sin(angle);
    if constexpr (D == 2) {
        r.m = {{{c, -s}, {s, c}}};
    } else {
        const double x = axis[0], y = axis[1], z = axis[2], t = 1 - c;
        r.m = {{{c + x * x * t, x * y * t - z * s, x * z * t + y * s},
                {y * x * t + z * s, c + y * y * t, y * z * t - x * s},
                {z * x * t - y * s, z * y * t + x * s, c + z * z * t}}};
    }
    return r;
}

/// Where a wall is at one time: body point b -> world R b + shift; and how it moves then.
template <int D>
struct Pose {
    Rotation<D> rot = Rotation<D>::identity();
    Vec<D> shift;     ///< world position of the body origin [m]
    Vec<D> velocity;  ///< translation velocity, v + oscillation [m/s]
    Vec<D> centre;    ///< centre of rotation, moved with the translation [m]
    Ang<D> spin;      ///< angular velocity [rad/s]
    bool rotated = false;

    Vec<D> toWorld(const Vec<D>& b) const { return rotated ? rot.apply(b) + shift : b + shift; }
    Vec<D> toBody(const Vec<D>& x) const { return rotated ? rot.applyInverse(x - shift) : x - shift; }
    Vec<D> directionToWorld(const Vec<D>& n) const { return rotated ? rot.apply(n) : n; }
    Vec<D> directionToBody(const Vec<D>& n) const { return rotated ? rot.applyInverse(n) : n; }
    /// Velocity of the wall's material point at world position x [m/s].
    Vec<D> surfaceVelocity(const Vec<D>& x) const { return rotated ? velocity + cross(spin, x - centre) : velocity; }
};

template <int D>
struct Motion {
    Vec<D> velocity;        ///< constant translation velocity v [m/s]
    Vec<D> amplitude;       ///< oscillation amplitude A [m]
    double frequency = 0;   ///< oscillation frequency f [Hz]
    double phase = 0;       ///< oscillation phase phi [rad]
    Vec<D> centre;          ///< centre of rotation c at t = 0 [m]
    Ang<D> axis = unitZ();  ///< unit rotation axis (3D; 2D: z, the only one) [-]
    double omega = 0;       ///< angular speed about the axis [rad/s], counter-clockwise about it
    /// The time the motion counts from [s]: 0, or the time of the last rebase.
    double origin = 0;
    /// The wall's pose at `origin` (body point b -> baseRot b + baseShift): the identity until a rebase.
    Rotation<D> baseRot = Rotation<D>::identity();
    Vec<D> baseShift;
    bool rebased = false;      ///< rebased at least once: at() composes the base
    bool baseRotated = false;  ///< baseRot is not the identity

    static Ang<D> unitZ() {
        Ang<D> z;
        z[kAngDim<D> - 1] = 1;
        return z;
    }
    bool rotates() const { return omega != 0; }
    bool oscillates() const { return frequency != 0 && norm2(amplitude) > 0; }
    bool moves() const { return rotates() || oscillates() || norm2(velocity) > 0; }

    // (t - origin is t itself until a rebase: the same bits as the formulas with t.)
    /// Translation d(t) of the body (the centre of rotation moves with it) [m].
    Vec<D> displacement(double t) const {
        const double s = t - origin;
        Vec<D> d = velocity * s;
        if (oscillates()) d += oscillationDisplacement(amplitude, frequency, phase, s);
        return d;
    }
    Vec<D> translationVelocity(double t) const {
        if (!oscillates()) return velocity;
        return velocity + oscillationVelocity(amplitude, frequency, phase, t - origin);
    }
    Pose<D> at(double t) const {
        if (rebased) return composedAt(t);
        Pose<D> p;
        const Vec<D> d = displacement(t);
        p.velocity = translationVelocity(t);
        p.centre = centre + d;
        if (rotates()) {
            p.rotated = true;
            p.rot = rotationOf<D>(axis, omega * t);
            p.spin = axis * omega;
            p.shift = centre + d - p.rot.apply(centre);  // x = c + d + R (b - c) = R b + (c + d - R c)
        } else {
            p.shift = d;
        }
        return p;
    }
    /// Makes the pose at time t the base and t the origin, so that a change of velocity, omega or axis made next
    /// takes effect from t with the wall where it is (no jump); the oscillation goes on in phase.
    void rebase(double t) {
        const Pose<D> p = at(t);
        if (oscillates())
            phase = std::remainder(phase + 2 * std::numbers::pi * frequency * (t - origin), 2 * std::numbers::pi);
        baseRot = p.rot;
        baseShift = p.shift;
        baseRotated = p.rotated;
        origin = t;
        rebased = true;
    }
    /// The centre of rotation at `origin` in the world [m] (centre itself until a rebase).
    Vec<D> baseCentre() const { return rebased ? base(centre) : centre; }
    /// A bound on how far any point within `reach` [m] of the centre of rotation has moved between t0 and t1 [m]:
    /// the translation's path length bound plus the chord of the rotation.
    double maxDisplacement(double t0, double t1, double reach) const {
        double s = norm(displacement(t1) - displacement(t0));
        if (rotates()) {
            const double a = std::min(std::abs(omega * (t1 - t0)), std::numbers::pi);
            s += 2 * std::sin(0.5 * a) * reach;
        }
        return s;
    }

private:
    Vec<D> base(const Vec<D>& b) const { return baseRotated ? baseRot.apply(b) + baseShift : b + baseShift; }
    // x(t) = c0 + d + R (B b - c0) = (R B) b + (c0 + d + R (baseShift - c0)), B b = baseRot b + baseShift.
    Pose<D> composedAt(double t) const {
        Pose<D> p;
        const Vec<D> d = displacement(t);
        const Vec<D> c0 = base(centre);
        p.velocity = translationVelocity(t);
        p.centre = c0 + d;
        if (rotates()) {
            const Rotation<D> r = rotationOf<D>(axis, omega * (t - origin));
            p.rotated = true;
            p.rot = r.after(baseRot);
            p.spin = axis * omega;
            p.shift = c0 + d + r.apply(baseShift - c0);
        } else {
            p.rotated = baseRotated;
            p.rot = baseRot;
            p.shift = baseShift + d;
        }
        return p;
    }
};

}  // namespace haet
