#pragma once
// Shape geometry of 2D convex polygon particles (docs/physics.md G.1): area, centroid and moment of inertia from
// the vertices, the body frame a particle stores, and the shape generators of insertion. Below every engine: the
// particle store, the scenario's insertion and the polygon contact geometry (polygon/geometry.hpp) all use it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/rng.hpp"
#include "core/vec.hpp"

namespace haet::polygon {

using V2 = Vec<2>;

/// Most vertices of one particle's polygon (the "3 to ~20").
inline constexpr int kMaxVertices = 20;
/// Capacity of an overlap polygon: clipping a convex n-gon by a convex m-gon leaves at most n + m vertices.
inline constexpr int kMaxClip = 2 * kMaxVertices + 4;

inline double cross2(const V2& a, const V2& b) { return a[0] * b[1] - a[1] * b[0]; }
/// a rotated by +90 degrees.
inline V2 perp(const V2& a) { return V2{{-a[1], a[0]}}; }
/// a rotated by angle phi [rad], given its cosine and sine.
inline V2 rotate(const V2& a, double c, double s) { return V2{{c * a[0] - s * a[1], s * a[0] + c * a[1]}}; }

/// Area, centroid and moment of inertia of a polygon of unit areal density.
struct Moments {
    double area = 0;            ///< signed: > 0 for counter-clockwise vertices [m^2]
    V2 centroid{};              ///< [m]
    double inertiaPerMass = 0;  ///< I about the centroid divided by the mass [m^2]
};

/// docs/physics.md G.1. Computed relative to the first vertex, which keeps the round-off relative to the polygon's
/// size even far from the origin.
inline Moments polygonMoments(const V2* v, int n) {
    const V2 o = v[0];
    double a2 = 0, mx = 0, my = 0, io = 0;
    for (int k = 0; k < n; ++k) {
        const V2 p = v[k] - o, q = v[(k + 1) % n] - o;
        const double cr = cross2(p, q);
        a2 += cr;
        mx += (p[0] + q[0]) * cr;
        my += (p[1] + q[1]) * cr;
        io += cr * (p[0] * p[0] + p[0] * q[0] + q[0] * q[0] + p[1] * p[1] + p[1] * q[1] + q[1] * q[1]);
    }
    Moments m;
    m.area = 0.5 * a2;
    if (m.area == 0) {
        m.centroid = o;
        return m;
    }
    const V2 c{{mx / (3 * a2), my / (3 * a2)}};
    m.centroid = o + c;
    m.inertiaPerMass = (io / 12.0) / m.area - norm2(c);  // parallel-axis theorem: I_c = I_o - m |c|^2
    return m;
}

/// Largest distance of a vertex from `c` [m].
inline double circumradius(const V2* v, int n, const V2& c) {
    double r2 = 0;
    for (int k = 0; k < n; ++k) r2 = std::max(r2, norm2(v[k] - c));
    return std::sqrt(r2);
}

/// Distance from the origin to the nearest edge line of a convex counter-clockwise polygon that holds the origin
/// [m]: the radius of the largest circle about the origin inside the polygon.
inline double inradius(const V2* v, int n) {
    double r = std::numeric_limits<double>::infinity();
    for (int k = 0; k < n; ++k) {
        const V2 e = v[k + 1 == n ? 0 : k + 1] - v[k];
        r = std::min(r, cross2(e, -v[k]) / norm(e));
    }
    return r;
}

/// True when the vertices are in counter-clockwise order and every corner turns left (strictly convex up to a
/// relative tolerance), with no repeated vertex.
inline bool isConvexCcw(const V2* v, int n) {
    if (n < 3) return false;
    double scale = 0;
    for (int k = 0; k < n; ++k) scale = std::max(scale, norm2(v[k] - v[0]));
    if (!(scale > 0)) return false;
    for (int k = 0; k < n; ++k) {
        const V2 e0 = v[(k + 1) % n] - v[k], e1 = v[(k + 2) % n] - v[(k + 1) % n];
        if (!(cross2(e0, e1) > 1e-12 * scale)) return false;
    }
    // Turning left at every corner can still wind twice around; the total angle must be one turn.
    double turn = 0;
    for (int k = 0; k < n; ++k) {
        const V2 e0 = v[(k + 1) % n] - v[k], e1 = v[(k + 2) % n] - v[(k + 1) % n];
        turn += std::atan2(cross2(e0, e1), dot(e0, e1));
    }
    return std::abs(turn - 2 * 3.14159265358979323846) < 1e-6;
}

// ---- shapes, in the body frame (centroid at the origin, counter-clockwise) ----

/// Moves the vertices so that their centroid is the origin.
inline void centre(std::vector<V2>& v) {
    const V2 c = polygonMoments(v.data(), int(v.size())).centroid;
    for (V2& p : v) p -= c;
}

/// Regular n-gon of circumradius R [m], first vertex at angle `orientation` [rad].
inline std::vector<V2> regularPolygon(int n, double R, double orientation) {
    std::vector<V2> v(n);
    const double twoPi = 2 * 3.14159265358979323846;
    for (int k = 0; k < n; ++k) {
        const double a = orientation + twoPi * k / n;
        v[k] = V2{{R * std::cos(a), R * std::sin(a)}};
    }
    return v;
}

/// Rectangle whose half-diagonal is R [m] and whose sides have the ratio `aspect` (length along the body x axis
/// over length along y), turned by `orientation` [rad].
inline std::vector<V2> rectangle(double aspect, double R, double orientation) {
    const double h = 1 / std::sqrt(1 + aspect * aspect);
    const double hx = R * aspect * h, hy = R * h;
    const double c = std::cos(orientation), s = std::sin(orientation);
    std::vector<V2> v = {V2{{hx, -hy}}, V2{{hx, hy}}, V2{{-hx, hy}}, V2{{-hx, -hy}}};
    for (V2& p : v) p = rotate(p, c, s);
    return v;
}

/// A random convex polygon with n vertices and circumradius R about its centroid [m]: vertices on an ellipse of
/// axis ratio uniform in [1, maxAspect], at angles 2 pi (k + u_k)/n with u_k uniform in [-0.35, 0.35] (so no two
/// vertices come closer than 0.3 of the regular spacing), turned by `orientation` [rad]. Points taken in order
/// along a convex curve always form a convex polygon.
inline std::vector<V2> randomConvexPolygon(Rng& rng, int n, double R, double maxAspect, double orientation) {
    const double twoPi = 2 * 3.14159265358979323846;
    const double stretch = rng.uniform(1.0, maxAspect);
    const double c = std::cos(orientation), s = std::sin(orientation);
    std::vector<V2> v(n);
    for (int k = 0; k < n; ++k) {
        const double a = twoPi * (k + rng.uniform(-0.35, 0.35)) / n;
        v[k] = rotate(V2{{stretch * std::cos(a), std::sin(a)}}, c, s);
    }
    centre(v);
    const double r = circumradius(v.data(), n, V2::zero());
    for (V2& p : v) p *= R / r;
    return v;
}

/// A polygon put into its body frame: vertices counter-clockwise about their centroid at the origin.
struct BodyFrame {
    double area = 0;            ///< [m^2]
    double inertiaPerMass = 0;  ///< moment of inertia about the centroid over the mass [m^2]
    double circumradius = 0;    ///< largest distance of a vertex from the centroid [m]
};

/// Moves `body` (convex, in either order, about any origin) into its body frame and returns its moments there.
/// The centroid comes from the vertices as given and the moment of inertia from the re-centred vertices, the
/// store's own convention for the shapes it keeps (polygonMoments works relative to the first vertex instead).
inline BodyFrame toBodyFrame(std::vector<V2>& body) {
    double a2 = 0, mx = 0, my = 0;
    const std::size_t nv = body.size();
    for (std::size_t k = 0; k < nv; ++k) {
        const V2& p = body[k];
        const V2& q = body[(k + 1) % nv];
        const double cr = p[0] * q[1] - q[0] * p[1];
        a2 += cr;
        mx += (p[0] + q[0]) * cr;
        my += (p[1] + q[1]) * cr;
    }
    if (a2 < 0) {
        std::reverse(body.begin(), body.end());
        a2 = -a2, mx = -mx, my = -my;
    }
    const V2 c{{mx / (3 * a2), my / (3 * a2)}};
    double r2 = 0, io = 0;
    for (V2& p : body) p -= c;
    for (std::size_t k = 0; k < nv; ++k) {
        const V2& p = body[k];
        const V2& q = body[(k + 1) % nv];
        const double cr = p[0] * q[1] - q[0] * p[1];
        io += cr * (p[0] * p[0] + p[0] * q[0] + q[0] * q[0] + p[1] * p[1] + p[1] * q[1] + q[1] * q[1]);
        r2 = std::max(r2, norm2(p));
    }
    BodyFrame f;
    f.area = 0.5 * a2;
    f.inertiaPerMass = (io / 12.0) / f.area;  // about the centroid, which is now the origin
    f.circumradius = std::sqrt(r2);
    return f;
}

}  // namespace haet::polygon
