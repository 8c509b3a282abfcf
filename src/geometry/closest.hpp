#pragma once
// Closest points on the elements walls are made of (docs/physics.md H.2), with the feature the closest point lies
// on: the interior of a segment (2D) or a triangle (3D), an edge, a vertex. Written after the region tests of
// Ericson, Real-Time Collision Detection (2005), 5.1.2 and 5.1.5.
#include <algorithm>
#include <cstdint>

#include "core/vec.hpp"

namespace haet {

/// Features of an element: 0 its interior (a segment's, a triangle's face), 1-3 a triangle's edges (edge k runs from
/// vertex k-1 to vertex k mod 3), then the vertices: 1-2 of a segment, 4-6 of a triangle.
inline constexpr int kFaceFeature = 0;
template <int D>
inline constexpr int kFirstVertexFeature = D == 2 ? 1 : 4;
template <int D>
inline constexpr int kFeatures = D == 2 ? 3 : 7;

template <int D>
struct ClosestPoint {
    Vec<D> point;
    int feature = kFaceFeature;
};

/// The point of segment [a, b] closest to x.
template <int D>
ClosestPoint<D> closestOnSegment(const Vec<D>& x, const Vec<D>& a, const Vec<D>& b) {
    const Vec<D> ab = b - a;
    const double t = dot(x - a, ab);
    if (t <= 0) return {a, kFirstVertexFeature<D>};
    const double l2 = norm2(ab);
    if (t >= l2) return {b, kFirstVertexFeature<D> + 1};
    return {a + ab * (t / l2), kFaceFeature};
}

/// The point of triangle (a, b, c) closest to x (Ericson 5.1.5): by the Voronoi regions of its vertices, edges and
/// face, the face's point by barycentric coordinates.
inline ClosestPoint<3> closestOnTriangle(const Vec<3>& x, const Vec<3>& a, const Vec<3>& b, const Vec<3>& c) {
    const Vec<3> ab = b - a, ac = c - a, ap = x - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return {a, 4};
    const Vec<3> bp = x - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return {b, 5};
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return {a + ab * (d1 / (d1 - d3)), 1};  // edge ab
    const Vec<3> cp = x - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return {c, 6};
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return {a + ac * (d2 / (d2 - d6)), 3};  // edge ca
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return {b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), 2};  // edge bc
    const double denom = 1 / (va + vb + vc);
    return {a + ab * (vb * denom) + ac * (vc * denom), kFaceFeature};
}

/// A unit vector perpendicular to the unit vector a (3D).
inline Vec<3> anyPerpendicular(const Vec<3>& a) {
    const Vec<3> t = std::abs(a[0]) < 0.9 ? Vec<3>{{1, 0, 0}} : Vec<3>{{0, 1, 0}};
    Vec<3> p = t - a * dot(a, t);
    return p * (1 / norm(p));
}

}  // namespace haet
