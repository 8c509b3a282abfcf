#pragma once
// Event-time predictions against static mesh elements under gravity (docs/physics.md D.8): the first time a sphere
// (disk) of radius a whose centre moves as c(t) = x + v t + g t^2/2 touches a segment (2D) or a triangle (3D), which
// feature it touches (the face or segment interior, an edge, a vertex), where and along which normal. Pure functions,
// no allocation; the engine calls them for the elements of static meshes (edm/mesh_walls.hpp).
//
// The distance from c to an element is the least of the distances to its features, each counted only where the
// feature's closest point lies in it (the Voronoi regions of Ericson 2005, 5.1.5): so the first contact is the
// earliest time at which some feature's gap falls through zero with its closest point inside the feature:
//  * face (the plane of a triangle, the line of a segment): s(t) = n . (c(t) - p) is quadratic; the gaps s - a
//    (from the side of n) and -s - a (from the other side), the foot of c inside the element;
//  * edge (3D): the distance to the edge's line is |P (c(t) - p)|, P the projection across the line, and P c(t) is
//    again a parabola, so |P w(t)|^2 - a^2 is a quartic (a quadratic without gravity across the line); the foot
//    e . (c(t) - p) in [0, L];
//  * vertex: |c(t) - p|^2 - a^2, a quartic, always valid.
// Each feature's gap is at most the true gap (the plane is closer than the triangle it holds, the line than the
// segment), so a feature's contact in its region is a true contact, and the earliest over the features is the first.
// The quartics go through roots::firstFalling (the derivative cascade, poly_roots.hpp), which also applies the
// invalid-state rule of D.6 (touching and receding: no event now).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "core/vec.hpp"
#include "edm/poly_roots.hpp"
#include "edm/predict.hpp"

namespace haet {

/// Which part of an element a contact is with.
enum class MeshFeature : std::uint8_t {
    None,    ///< no contact within the horizon
    Face,    ///< the interior of a triangle (3D) or of a segment (2D)
    Edge,    ///< an edge of a triangle (3D): index k runs from vertex k to vertex k + 1 (mod 3)
    Vertex,  ///< a vertex (3D) or an end of a segment (2D): index k
};

/// The first contact of a particle with an element.
template <int D>
struct MeshContact {
    double time = kNever;                     ///< after the common time of the inputs (s); kNever: none
    MeshFeature feature = MeshFeature::None;  ///< what is touched
    int index = 0;                            ///< which edge or vertex (0 for a face)
    Vec<D> point{};                           ///< the contact point on the element at `time` (m)
    Vec<D> normal{};                          ///< unit normal from `point` to the particle's centre at `time`
};

/// A static segment (2D), with its frame worked out once.
struct MeshSegment {
    Vec<2> p, q;    ///< ends (m)
    Vec<2> e;       ///< unit direction from p to q
    Vec<2> n;       ///< unit normal, e turned by +90 degrees
    double length;  ///< |q - p| (m)
};
inline MeshSegment makeMeshSegment(const Vec<2>& p, const Vec<2>& q) {
    const double l = norm(q - p);
    const Vec<2> e = (q - p) / l;
    return MeshSegment{p, q, e, Vec<2>{{-e[1], e[0]}}, l};
}

/// A static triangle (3D), with its frame worked out once (192 bytes).
struct MeshTriangle {
    std::array<Vec<3>, 3> p;       ///< vertices (m)
    Vec<3> n;                      ///< unit normal along (p1 - p0) x (p2 - p0)
    std::array<Vec<3>, 3> e;       ///< unit edge directions, e[k] from p[k] to p[k+1 mod 3]
    std::array<double, 3> length;  ///< edge lengths (m)
};
inline MeshTriangle makeMeshTriangle(const std::array<Vec<3>, 3>& p) {
    MeshTriangle t;
    t.p = p;
    const Vec<3> c = cross(p[1] - p[0], p[2] - p[0]);
    t.n = c / norm(c);
    for (int k = 0; k < 3; ++k) {
        const Vec<3> d = p[(k + 1) % 3] - p[k];
        t.length[k] = norm(d);
        t.e[k] = d / t.length[k];
    }
    return t;
}

namespace mesh_detail {

/// The centre's offset from a point at time t: w + v t + g t^2/2.
template <int D>
[[gnu::always_inline]] inline Vec<D> at(const Vec<D>& w, const Vec<D>& v, const Vec<D>& g, double t) {
    return w + (v + g * (0.5 * t)) * t;
}

/// |w + v t + g t^2/2|^2 - a^2 as c[0] + c[1] t + ... + c[4] t^4.
template <int D>
[[gnu::always_inline]] inline void distanceQuartic(const Vec<D>& w, const Vec<D>& v, const Vec<D>& g, double a,
                                                   double c[5]) {
    c[0] = norm2(w) - a * a;
    c[1] = 2 * dot(w, v);
    c[2] = norm2(v) + dot(w, g);
    c[3] = dot(v, g);
    c[4] = 0.25 * norm2(g);
}

/// w less its component along the unit vector e.
template <int D>
[[gnu::always_inline]] inline Vec<D> across(const Vec<D>& w, const Vec<D>& e) {
    return w - e * dot(w, e);
}

/// Whether a particle at signed distance s0 from an element's plane (or line), moving with s1 and s2 = n . g / 2
/// across it, stays farther than a from it over [0, tMax]: then it touches none of the element's features, which
/// all lie in that plane. Conservative bound |s(t)| >= |s0| - |s1| t - |s2| t^2; false without a horizon.
[[gnu::always_inline]] inline bool outOfReach(double s0, double s1, double s2, double a, double tMax) {
    return tMax < kNever && std::abs(s0) - a > (std::abs(s1) + std::abs(s2) * tMax) * tMax;
}

}  // namespace mesh_detail

/// First contact time of the particle with a point (a vertex): w = x - p, in [0, tMax], or kNever.
template <int D>
double vertexContactTime(const Vec<D>& w, const Vec<D>& v, const Vec<D>& g, double a, double tMax) {
    double c[5];
    mesh_detail::distanceQuartic(w, v, g, a, c);
    return roots::firstFalling(c, tMax, [](double) { return true; });
}

/// First contact time with the segment from p to p + L e (e unit; w = x - p) through its interior, measured as the
/// distance to its line: valid while the foot e . w(t) lies in [0, L]. In 3D the edge of a triangle.
template <int D>
double edgeContactTime(const Vec<D>& w, const Vec<D>& v, const Vec<D>& g, double a, const Vec<D>& e, double length,
                       double tMax) {
    using namespace mesh_detail;
    double c[5];
    distanceQuartic(across(w, e), across(v, e), across(g, e), a, c);
    const double s0 = dot(w, e), s1 = dot(v, e), s2 = 0.5 * dot(g, e);
    return roots::firstFalling(c, tMax, [&](double t) {
        const double s = s0 + (s1 + s2 * t) * t;
        return s >= 0 && s <= length;
    });
}

/// First contact time with a face: the hyperplane through p with unit normal n (w = x - p), from either side,
/// counted only while inside(t) (the foot of the centre in the element). Returns the time, and in `side` +1 or -1
/// for a contact from the side of n or the other.
template <int D, class Inside>
double faceContactTime(const Vec<D>& w, const Vec<D>& v, const Vec<D>& g, double a, const Vec<D>& n, double tMax,
                       Inside&& inside, int& side) {
    const double s0 = dot(n, w), s1 = dot(n, v), s2 = 0.5 * dot(n, g);
    const auto s = [&](double t) { return s0 + (s1 + s2 * t) * t; };
    // The gap from the side of n is s - a; the other side's -s - a. Each counts only on its own side, so a side
    // the particle cannot reach within the horizon (bounds of s on [0, T] from its coefficients) is skipped.
    const double T = tMax < kNever ? tMax : 0.0;
    const bool bounded = tMax < kNever;
    const bool reachUp = !bounded || s0 + std::max(s1, 0.0) * T + std::max(s2, 0.0) * T * T >= 0;
    const bool reachDown = !bounded || s0 + std::min(s1, 0.0) * T + std::min(s2, 0.0) * T * T <= 0;
    double tUp = kNever, tDown = kNever;
    if (reachUp) {
        const double up[5] = {s0 - a, s1, s2, 0, 0};
        tUp = roots::firstFalling(up, tMax, [&](double t) { return s(t) >= 0 && inside(t); });
    }
    if (reachDown) {
        const double down[5] = {-s0 - a, -s1, -s2, 0, 0};
        tDown = roots::firstFalling(down, std::min(tMax, tUp), [&](double t) { return s(t) <= 0 && inside(t); });
    }
    side = tDown < tUp ? -1 : 1;
    return std::min(tUp, tDown);
}

/// First contact of a disk of radius a (centre x, velocity v, acceleration g at a common time) with a static
/// segment, within tMax after that time (docs/physics.md D.8). Ties go to the interior, then to the lower end.
inline MeshContact<2> predictSegment(const Vec<2>& x, const Vec<2>& v, const Vec<2>& g, double a,
                                     const MeshSegment& seg, double tMax = kNever) {
    using namespace mesh_detail;
    MeshContact<2> r;
    const Vec<2> w = x - seg.p;
    if (outOfReach(dot(seg.n, w), dot(seg.n, v), 0.5 * dot(seg.n, g), a, tMax)) return r;
    const double u0 = dot(seg.e, w), u1 = dot(seg.e, v), u2 = 0.5 * dot(seg.e, g);
    int side = 1;
    const double tf = faceContactTime<2>(
        w, v, g, a, seg.n, tMax,
        [&](double t) {
            const double u = u0 + (u1 + u2 * t) * t;
            return u >= 0 && u <= seg.length;
        },
        side);
    if (tf < kNever) {
        r.time = tf;
        r.feature = MeshFeature::Face;
        r.normal = seg.n * side;
    }
    for (int k = 0; k < 2; ++k) {
        const Vec<2>& p = k == 0 ? seg.p : seg.q;
        const double t = vertexContactTime<2>(x - p, v, g, a, std::min(tMax, r.time));
        if (t < r.time) {
            r.time = t;
            r.feature = MeshFeature::Vertex;
            r.index = k;
        }
    }
    if (r.feature == MeshFeature::None) return r;
    const Vec<2> c = at(x, v, g, r.time);
    if (r.feature == MeshFeature::Face) {
        r.point = c - r.normal * dot(r.normal, c - seg.p);
    } else {
        r.point = r.index == 0 ? seg.p : seg.q;
        const double d = norm(c - r.point);
        r.normal = d > 0 ? (c - r.point) / d : seg.n;  // a centre on the end itself (deep overlap): any normal
    }
    return r;
}

/// First contact of a sphere of radius a (centre x, velocity v, acceleration g at a common time) with a static
/// triangle, within tMax after that time (docs/physics.md D.8). Ties go to the face, then to edges, then to
/// vertices, each in index order.
inline MeshContact<3> predictTriangle(const Vec<3>& x, const Vec<3>& v, const Vec<3>& g, double a,
                                      const MeshTriangle& tri, double tMax = kNever) {
    using namespace mesh_detail;
    MeshContact<3> r;
    const Vec<3> w = x - tri.p[0];
    if (outOfReach(dot(tri.n, w), dot(tri.n, v), 0.5 * dot(tri.n, g), a, tMax)) return r;
    // Inside: the centre on the inner side of each edge's plane through n (the in-plane normals e_k x n point out).
    std::array<Vec<3>, 3> out;
    std::array<double, 3> o0, o1, o2;
    for (int k = 0; k < 3; ++k) {
        out[k] = cross(tri.e[k], tri.n);
        const Vec<3> wk = x - tri.p[k];
        o0[k] = dot(out[k], wk);
        o1[k] = dot(out[k], v);
        o2[k] = 0.5 * dot(out[k], g);
    }
    int side = 1;
    const double tf = faceContactTime<3>(
        w, v, g, a, tri.n, tMax,
        [&](double t) {
            for (int k = 0; k < 3; ++k)
                if (o0[k] + (o1[k] + o2[k] * t) * t > 0) return false;
            return true;
        },
        side);
    if (tf < kNever) {
        r.time = tf;
        r.feature = MeshFeature::Face;
        r.normal = tri.n * side;
    }
    for (int k = 0; k < 3; ++k) {
        const double t = edgeContactTime<3>(x - tri.p[k], v, g, a, tri.e[k], tri.length[k], std::min(tMax, r.time));
        if (t < r.time) {
            r.time = t;
            r.feature = MeshFeature::Edge;
            r.index = k;
        }
    }
    for (int k = 0; k < 3; ++k) {
        const double t = vertexContactTime<3>(x - tri.p[k], v, g, a, std::min(tMax, r.time));
        if (t < r.time) {
            r.time = t;
            r.feature = MeshFeature::Vertex;
            r.index = k;
        }
    }
    if (r.feature == MeshFeature::None) return r;
    const Vec<3> c = at(x, v, g, r.time);
    if (r.feature == MeshFeature::Face) {
        r.point = c - r.normal * dot(r.normal, c - tri.p[0]);
        return r;
    }
    const Vec<3>& p = tri.p[r.index];
    if (r.feature == MeshFeature::Edge) {
        const double s = std::clamp(dot(c - p, tri.e[r.index]), 0.0, tri.length[r.index]);
        r.point = p + tri.e[r.index] * s;
    } else {
        r.point = p;
    }
    const double d = norm(c - r.point);
    r.normal = d > 0 ? (c - r.point) / d : tri.n;  // a centre on the edge or vertex itself (deep overlap)
    return r;
}

}  // namespace haet
