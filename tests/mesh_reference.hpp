#pragma once
// The reference twin of the mesh predictions (src/edm/predict_mesh.hpp): closest points in long double by the
// Voronoi-region routines of Ericson, Real-Time Collision Detection (2005), 5.1.2 (segment) and 5.1.5 (triangle),
// and brute-force time stepping of the distance from the particle's centre to a set of elements, with bisection
// of the step where it first falls to the radius. Nothing here is shared with the code it checks but the types.
#include <array>
#include <cmath>
#include <vector>

#include "edm/predict_mesh.hpp"

namespace haet::meshref {

using LD = long double;
template <int D>
using VL = std::array<LD, D>;

template <int D>
VL<D> toL(const Vec<D>& v) {
    VL<D> r;
    for (int k = 0; k < D; ++k) r[k] = v[k];
    return r;
}
template <std::size_t D>
std::array<LD, D> sub(const std::array<LD, D>& a, const std::array<LD, D>& b) {
    std::array<LD, D> r;
    for (std::size_t k = 0; k < D; ++k) r[k] = a[k] - b[k];
    return r;
}
template <std::size_t D>
std::array<LD, D> axpy(const std::array<LD, D>& a, LD s, const std::array<LD, D>& b) {  // a + s b
    std::array<LD, D> r;
    for (std::size_t k = 0; k < D; ++k) r[k] = a[k] + s * b[k];
    return r;
}
template <std::size_t D>
LD dotL(const std::array<LD, D>& a, const std::array<LD, D>& b) {
    LD s = 0;
    for (std::size_t k = 0; k < D; ++k) s += a[k] * b[k];
    return s;
}
template <std::size_t D>
LD normL(const std::array<LD, D>& a) {
    return std::sqrt(dotL(a, a));
}

/// The closest point of an element to a point, its distance, and the feature it lies in.
template <int D>
struct Closest {
    LD dist = 0;
    MeshFeature feature = MeshFeature::None;
    int index = 0;
    VL<D> q{};
};

/// Segment [a, b]: the interior or an end (Ericson 5.1.2).
inline Closest<2> closest(const VL<2>& p, const std::array<Vec<2>, 2>& s) {
    const VL<2> a = toL(s[0]), b = toL(s[1]), ab = sub(b, a);
    const LD u = dotL(sub(p, a), ab) / dotL(ab, ab);
    Closest<2> c;
    if (u <= 0) {
        c.feature = MeshFeature::Vertex, c.index = 0, c.q = a;
    } else if (u >= 1) {
        c.feature = MeshFeature::Vertex, c.index = 1, c.q = b;
    } else {
        c.feature = MeshFeature::Face, c.q = axpy(a, u, ab);
    }
    c.dist = normL(sub(p, c.q));
    return c;
}

/// Triangle (a, b, c): the face, an edge k (from vertex k to k + 1) or a vertex, by the Voronoi regions in the
/// order of Ericson 5.1.5 (vertex a, vertex b, edge ab, vertex c, edge ca, edge bc, face).
inline Closest<3> closest(const VL<3>& p, const std::array<Vec<3>, 3>& t) {
    const VL<3> a = toL(t[0]), b = toL(t[1]), c = toL(t[2]);
    const VL<3> ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    Closest<3> r;
    const auto done = [&](MeshFeature f, int k, const VL<3>& q) {
        r.feature = f, r.index = k, r.q = q, r.dist = normL(sub(p, q));
        return r;
    };
    const LD d1 = dotL(ab, ap), d2 = dotL(ac, ap);
    if (d1 <= 0 && d2 <= 0) return done(MeshFeature::Vertex, 0, a);
    const VL<3> bp = sub(p, b);
    const LD d3 = dotL(ab, bp), d4 = dotL(ac, bp);
    if (d3 >= 0 && d4 <= d3) return done(MeshFeature::Vertex, 1, b);
    const LD vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return done(MeshFeature::Edge, 0, axpy(a, d1 / (d1 - d3), ab));
    const VL<3> cp = sub(p, c);
    const LD d5 = dotL(ab, cp), d6 = dotL(ac, cp);
    if (d6 >= 0 && d5 <= d6) return done(MeshFeature::Vertex, 2, c);
    const LD vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return done(MeshFeature::Edge, 2, axpy(a, d2 / (d2 - d6), ac));
    const LD va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
        return done(MeshFeature::Edge, 1, axpy(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(c, b)));
    const LD den = 1 / (va + vb + vc);
    return done(MeshFeature::Face, 0, axpy(axpy(a, vb * den, ab), vc * den, ac));
}

/// The centre at time t: x + v t + g t^2 / 2, in long double.
template <int D>
VL<D> centre(const Vec<D>& x, const Vec<D>& v, const Vec<D>& g, LD t) {
    VL<D> r;
    for (int k = 0; k < D; ++k) r[k] = x[k] + v[k] * t + 0.5L * g[k] * t * t;
    return r;
}

/// A set of elements (segments or triangles) with a bounding sphere each, so that the stepping skips far ones.
template <int D>
struct Scene {
    using Element = std::array<Vec<D>, D>;
    std::vector<Element> elements;
    std::vector<VL<D>> mid;
    std::vector<LD> reach;

    void add(const Element& e) {
        elements.push_back(e);
        VL<D> m{};
        for (const auto& p : e)
            for (int k = 0; k < D; ++k) m[k] += LD(p[k]) / D;
        LD r = 0;
        for (const auto& p : e) r = std::max(r, normL(sub(toL(p), m)));
        mid.push_back(m);
        reach.push_back(r);
    }
    /// min over the elements of distance - a at centre c; `which` the element it comes from. Elements whose
    /// bounding sphere is farther than a + 0.01 contribute that lower bound only: the sign is always right.
    LD gap(const VL<D>& c, LD a, int* which = nullptr) const {
        LD best = 1e300L;
        for (std::size_t i = 0; i < elements.size(); ++i) {
            const LD bound = normL(sub(c, mid[i])) - reach[i] - a;
            const LD g = bound > 0.01L ? bound : closest(c, elements[i]).dist - a;
            if (g < best) {
                best = g;
                if (which) *which = static_cast<int>(i);
            }
        }
        return best;
    }
};

/// The first time in (0, tEnd] at which the centre comes within a of the scene: steps of h from h on, then 100
/// bisections of the step where the gap is first <= 0 (to ~1e-30 h). kNever if none.
template <int D>
LD steppedContact(const Scene<D>& s, const Vec<D>& x, const Vec<D>& v, const Vec<D>& g, LD a, LD h, LD tEnd) {
    LD prev = 0;
    for (long k = 1; k * h <= tEnd; ++k) {
        const LD t = k * h;
        if (s.gap(centre(x, v, g, t), a) <= 0) {
            LD lo = prev, hi = t;
            for (int it = 0; it < 100; ++it) {
                const LD m = 0.5L * (lo + hi);
                (s.gap(centre(x, v, g, m), a) <= 0 ? hi : lo) = m;
            }
            return hi;
        }
        prev = t;
    }
    return kNever;
}

/// The rate at which the scene's gap falls just before t (m/s, > 0 when approaching): how a time error becomes a
/// distance error.
template <int D>
double approachSpeed(const Scene<D>& s, const Vec<D>& x, const Vec<D>& v, const Vec<D>& g, LD a, LD t) {
    const LD dt = 1e-8L;
    const LD t0 = t > dt ? t - dt : LD(0);
    return std::abs(double((s.gap(centre(x, v, g, t0), a) - s.gap(centre(x, v, g, t), a)) / (t - t0)));
}

}  // namespace haet::meshref
