#pragma once
// Simulation box: bounds, periodic axes, gravity; and plane walls.
#include <array>
#include <cstdint>

#include "core/vec.hpp"

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

/// An infinite plane wall moving with constant velocity. The normal points into the domain.
template <int D>
struct Wall {
    Vec<D> point;     ///< a point of the plane at time 0 [m]
    Vec<D> normal;    ///< unit normal into the domain
    Vec<D> velocity;  ///< [m/s]
    int material = 0;

    Vec<D> pointAt(double t) const { return point + velocity * t; }
    /// Signed distance of x from the plane at time t (positive inside the domain) [m].
    double distance(const Vec<D>& x, double t) const { return dot(normal, x - pointAt(t)); }
};

}  // namespace haet
