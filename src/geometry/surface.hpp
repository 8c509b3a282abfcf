#pragma once
// Walls of any shape (docs/physics.md H): meshes (segments and polylines in 2D, triangles in 3D), circles and arcs
// (2D), cylinders and cones with or without caps, and discs (3D). A wall is a surface of infinite mass that a
// particle touches from either side, defined in its body frame and moved by its Motion (geometry/motion.hpp).
//
// Contacts (H.2). A particle touches a wall where the distance from its centre to the surface has a local minimum
// below its radius: the closest point of an element (segment, triangle, a cylinder's mantle or cap) counts only when
// no neighbouring element of the same wall is closer near it. The closest point of a face lies inside it and always
// counts; one on an edge or a vertex counts when the centre lies in the edge's or vertex's Voronoi region of the whole
// surface, not only of the element: with n = (x - p) / |x - p|, n . u <= 0 for every direction u that leads from
// the feature into a neighbouring element (into the faces across an edge; along the edges from a vertex). So a ball
// on a flat mesh meets one face, not the edges next to it; one on a ridge meets the ridge once; one in a concave
// corner meets each face. Contacts of one wall whose normals agree within kMergeAngle are one contact (the same
// edge seen from its two triangles, a fold too shallow to matter), the deepest kept.
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "geometry/closest.hpp"
#include "geometry/motion.hpp"

namespace haet {

enum class SurfaceKind : std::uint8_t {
    Mesh,      ///< segments (2D) or triangles (3D) sharing welded vertices
    Arc,       ///< 2D: a circle, or an arc of one between two angles
    Cylinder,  ///< 3D: the mantle of a cylinder or a cone (frustum), each end open or capped by a disc
    Disc,      ///< 3D: a flat disc
};

/// The tolerance of the Voronoi tests: a feature's contact counts when n . u <= kVoronoiTolerance [-].
inline constexpr double kVoronoiTolerance = 1e-9;
/// Contacts of one wall whose normals differ by less than this angle are one contact [rad].
inline constexpr double kMergeAngle = 1e-3;

/// A contact of a particle centre with a wall surface, in the wall's body frame.
template <int D>
struct SurfaceHit {
    Vec<D> point;     ///< the closest point on the surface [m]
    Vec<D> normal;    ///< unit vector from the point to the centre [-]
    double distance;  ///< |centre - point| [m]
};

/// A box in a wall's body frame [m].
template <int D>
struct ElementBox {
    Vec<D> lo, hi;
};

/// The squared distance from x to box b (0 inside it) [m^2].
template <int D>
double boxDistance2(const ElementBox<D>& b, const Vec<D>& x) {
    double d2 = 0;
    for (int a = 0; a < D; ++a) {
        const double d = std::max(b.lo[a] - x[a], 0.0) + std::max(x[a] - b.hi[a], 0.0);
        d2 += d * d;
    }
    return d2;
}

template <int D>
struct SurfaceWall {
    std::string name;  ///< for outputs; may be empty
    int id = 0;        ///< the wall's place among the scenario's walls, 0-based
    int material = 0;
    Motion<D> motion;
    SurfaceKind kind = SurfaceKind::Mesh;

    // Mesh: welded vertices and elements (D vertex indices each: a segment's ends, a triangle's corners).
    std::vector<Vec<D>> vertices;
    std::vector<std::array<std::uint32_t, D>> elements;
    /// The Voronoi directions of element e's feature f (closest.hpp), kFeatures<D> entries per element: the
    /// directions [constraintFirst[e kF + f], constraintFirst[e kF + f + 1]) of `constraints` (unit vectors).
    std::vector<std::uint32_t> constraintFirst;
    std::vector<Vec<D>> constraints;

    // Arc: centre, radius, angles [angle0, angle1] (counter-clockwise; a circle when they span 2 pi).
    // Cylinder: base centre, unit axis, length along it, radius at the base and at the other end, caps.
    // Disc: centre, unit normal (axis), radius.
    Vec<D> centre;
    Vec<D> axis;
    double radius = 0, radius1 = 0, length = 0;
    double angle0 = 0, angle1 = 0;
    bool cap0 = false, cap1 = false;

    std::size_t elementCount() const { return kind == SurfaceKind::Mesh ? elements.size() : 1; }
    bool fullCircle() const { return angle1 - angle0 >= 2 * 3.141592653589793 - 1e-12; }

    /// The body-frame box of element e [m].
    void bounds(std::size_t e, Vec<D>& lo, Vec<D>& hi) const {
        if (kind == SurfaceKind::Mesh) {
            lo = hi = vertices[elements[e][0]];
            for (int k = 1; k < D; ++k) {
                const Vec<D>& v = vertices[elements[e][k]];
                for (int a = 0; a < D; ++a) {
                    lo[a] = std::min(lo[a], v[a]);
                    hi[a] = std::max(hi[a], v[a]);
                }
            }
            return;
        }
        // A circle of radius r about the unit axis a reaches r sqrt(1 - a_k^2) along coordinate k.
        if (kind == SurfaceKind::Cylinder || kind == SurfaceKind::Disc) {
            const double r = std::max(radius, radius1);
            const Vec<D> top = centre + axis * (kind == SurfaceKind::Cylinder ? length : 0.0);
            for (int a = 0; a < D; ++a) {
                const double reach = r * std::sqrt(std::max(0.0, 1 - axis[a] * axis[a]));
                lo[a] = std::min(centre[a], top[a]) - reach;
                hi[a] = std::max(centre[a], top[a]) + reach;
            }
            return;
        }
        lo = centre - Vec<D>::filled(radius);
        hi = centre + Vec<D>::filled(radius);
    }
    /// The body-frame box of element e widened by 1e-9 of its size and distance from the origin, so that a closest
    /// point as computed, rounded, never lies outside it: an element whose padded box lies beyond a distance cannot
    /// come closer than that, and its closest point need not be found.
    ElementBox<D> paddedBox(std::size_t e) const {
        ElementBox<D> b;
        bounds(e, b.lo, b.hi);
        double size = 0;
        for (int a = 0; a < D; ++a) size = std::max({size, b.hi[a] - b.lo[a], std::abs(b.lo[a]), std::abs(b.hi[a])});
        b.lo -= Vec<D>::filled(1e-9 * size);
        b.hi += Vec<D>::filled(1e-9 * size);
        return b;
    }
    /// The largest distance of a point of the wall from `c` [m] (how far a rotation about c moves it).
    double reachFrom(const Vec<D>& c) const {
        double r = 0;
        if (kind == SurfaceKind::Mesh) {
            for (const Vec<D>& v : vertices) r = std::max(r, norm(v - c));
            return r;
        }
        Vec<D> lo, hi;
        bounds(0, lo, hi);
        Vec<D> far;
        for (int a = 0; a < D; ++a) far[a] = std::max(std::abs(lo[a] - c[a]), std::abs(hi[a] - c[a]));
        return norm(far);
    }

    /// The distance from body point x to element e, whatever the feature [m] (the broad phase's test).
    double distance(std::size_t e, const Vec<D>& x) const {
        double best = std::numeric_limits<double>::infinity();
        parts(e, x, [&](const Vec<D>& p, int, const Vec<D>*, int) { best = std::min(best, norm(x - p)); });
        return best;
    }

    /// Calls emit(SurfaceHit) for every contact of element e with a centre at body point x closer than `reach`,
    /// its Voronoi test passed (the merging of a wall's contacts is the caller's: mergeHits).
    template <class Emit>
    void contacts(std::size_t e, const Vec<D>& x, double reach, Emit&& emit) const {
        parts(e, x, [&](const Vec<D>& p, int, const Vec<D>* u, int nu) {
            const Vec<D> d = x - p;
            const double dist2 = norm2(d);
            if (!(dist2 < reach * reach) || dist2 == 0) return;
            const double dist = std::sqrt(dist2);
            const Vec<D> n = d * (1 / dist);
            for (int q = 0; q < nu; ++q)
                if (dot(n, u[q]) > kVoronoiTolerance) return;
            emit(SurfaceHit<D>{p, n, dist});
        });
    }

private:
    /// Calls f(point, feature, directions, count) for the closest point of each part of element e to x: the
    /// Voronoi directions of its feature that the contact test checks (none for a face).
    template <class F>
    void parts(std::size_t e, const Vec<D>& x, F&& f) const {
        switch (kind) {
            case SurfaceKind::Mesh: {
                const auto& el = elements[e];
                ClosestPoint<D> c;
                if constexpr (D == 2)
                    c = closestOnSegment<2>(x, vertices[el[0]], vertices[el[1]]);
                else
                    c = closestOnTriangle(x, vertices[el[0]], vertices[el[1]], vertices[el[2]]);
                const std::size_t k = e * kFeatures<D> + static_cast<std::size_t>(c.feature);
                const std::uint32_t b = constraintFirst[k], end = constraintFirst[k + 1];
                f(c.point, c.feature, constraints.data() + b, static_cast<int>(end - b));
                return;
            }
            case SurfaceKind::Arc:
                if constexpr (D == 2) arcPart(x, f);
                return;
            case SurfaceKind::Cylinder:
            case SurfaceKind::Disc:
                if constexpr (D == 3) roundParts(x, f);
                return;
        }
    }

    template <class F>
    void arcPart(const Vec<2>& x, F& f) const {
        const Vec<2> d = x - centre;
        const double rho = norm(d);
        const Vec<2> er = rho > 0 ? d * (1 / rho) : Vec<2>{{std::cos(angle0), std::sin(angle0)}};
        if (!fullCircle()) {
            double a = std::atan2(er[1], er[0]);
            const double twoPi = 2 * 3.141592653589793;
            while (a < angle0) a += twoPi;
            while (a >= angle0 + twoPi) a -= twoPi;
            if (a > angle1) {  // beyond the arc: the nearer end
                const Vec<2> p0 = centre + Vec<2>{{std::cos(angle0), std::sin(angle0)}} * radius;
                const Vec<2> p1 = centre + Vec<2>{{std::cos(angle1), std::sin(angle1)}} * radius;
                if (norm2(x - p0) <= norm2(x - p1))
                    f(p0, 1, nullptr, 0);
                else
                    f(p1, 2, nullptr, 0);
                return;
            }
        }
        f(centre + er * radius, kFaceFeature, nullptr, 0);
    }

    /// A cylinder's mantle and caps, or a disc: in the half-plane of x and the axis, with coordinates (rho, z).
    template <class F>
    void roundParts(const Vec<3>& x, F& f) const {
        const Vec<3> d = x - centre;
        const double z = dot(d, axis);
        const Vec<3> radial = d - axis * z;
        const double rho = norm(radial);
        const Vec<3> er = rho > 0 ? radial * (1 / rho) : anyPerpendicular(axis);
        const Vec<3> inward = -er;
        if (kind == SurfaceKind::Disc) {
            if (rho <= radius)
                f(centre + radial, kFaceFeature, nullptr, 0);
            else
                f(centre + er * radius, 1, nullptr, 0);
            return;
        }
        // The mantle's generator runs from (radius, 0) to (radius1, length).
        const double gr = radius1 - radius, gz = length;
        const double t = std::clamp(((rho - radius) * gr + z * gz) / (gr * gr + gz * gz), 0.0, 1.0);
        const Vec<3> onMantle = centre + axis * (t * gz) + er * (radius + t * gr);
        if (t <= 0 || t >= 1) {
            // On a rim: a cap there bounds its Voronoi region, radially inward.
            const bool capped = t <= 0 ? cap0 : cap1;
            f(onMantle, t <= 0 ? 1 : 2, &inward, capped ? 1 : 0);
        } else {
            f(onMantle, kFaceFeature, nullptr, 0);
        }
        // Caps: discs at both ends; a rim point is bounded by the mantle's direction away from it.
        const double glen = std::sqrt(gr * gr + gz * gz);
        if (cap0 && radius > 0) {
            const Vec<3> along = (axis * gz + er * gr) * (1 / glen);
            if (rho <= radius)
                f(centre + er * rho, kFaceFeature, nullptr, 0);
            else
                f(centre + er * radius, 1, &along, 1);
        }
        if (cap1 && radius1 > 0) {
            const Vec<3> top = centre + axis * length;
            const Vec<3> along = (axis * gz + er * gr) * (-1 / glen);
            if (rho <= radius1)
                f(top + er * rho, kFaceFeature, nullptr, 0);
            else
                f(top + er * radius1, 2, &along, 1);
        }
    }
};

/// Merges the contacts of one wall whose normals agree within kMergeAngle, keeping the deepest (the nearest point;
/// the earlier on ties). Keeps hits[0, n) in their order otherwise; returns the new count.
template <int D>
int mergeHits(SurfaceHit<D>* hits, int n) {
    int m = 0;
    for (int a = 0; a < n; ++a) {
        bool merged = false;
        for (int b = 0; b < m && !merged; ++b) {
            if (norm2(hits[a].normal - hits[b].normal) < kMergeAngle * kMergeAngle) {
                if (hits[a].distance < hits[b].distance) hits[b] = hits[a];
                merged = true;
            }
        }
        if (!merged) hits[m++] = hits[a];
    }
    return m;
}

/// A mesh wall from elements given by their corners (segments in 2D, triangles in 3D): vertices welded where they
/// are equal, and the Voronoi directions of every edge and vertex from the elements around them.
template <int D>
void buildMesh(SurfaceWall<D>& w, const std::vector<std::array<Vec<D>, D>>& corners) {
    w.kind = SurfaceKind::Mesh;
    w.vertices.clear();
    w.elements.clear();
    std::map<std::array<double, D>, std::uint32_t> index;
    for (const auto& el : corners) {
        std::array<std::uint32_t, D> ids;
        for (int k = 0; k < D; ++k) {
            const auto [it, fresh] = index.try_emplace(el[k].c, static_cast<std::uint32_t>(w.vertices.size()));
            if (fresh) w.vertices.push_back(el[k]);
            ids[k] = it->second;
        }
        w.elements.push_back(ids);
    }
    const std::size_t ne = w.elements.size();
    // The edges at each vertex (3D: pairs of vertex ids; 2D: the segments themselves), as unit directions away
    // from it, each once.
    std::vector<std::vector<std::uint32_t>> around(w.vertices.size());
    auto link = [&](std::uint32_t a, std::uint32_t b) {
        if (std::find(around[a].begin(), around[a].end(), b) == around[a].end()) around[a].push_back(b);
        if (std::find(around[b].begin(), around[b].end(), a) == around[b].end()) around[b].push_back(a);
    };
    for (const auto& el : w.elements)
        for (int k = 0; k < D; ++k) link(el[k], el[(k + 1) % D]);
    auto dir = [&](std::uint32_t from, std::uint32_t to) {
        const Vec<D> d = w.vertices[to] - w.vertices[from];
        return d * (1 / norm(d));
    };
    // 3D: the triangles at each edge, to find the faces across it.
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> facesAt;
    if constexpr (D == 3)
        for (std::uint32_t e = 0; e < ne; ++e)
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t a = w.elements[e][k], b = w.elements[e][(k + 1) % 3];
                facesAt[{std::min(a, b), std::max(a, b)}].push_back(e);
            }
    w.constraintFirst.assign(1, 0);
    w.constraints.clear();
    for (std::uint32_t e = 0; e < ne; ++e) {
        const auto& el = w.elements[e];
        for (int f = 0; f < kFeatures<D>; ++f) {
            if (f >= kFirstVertexFeature<D>) {
                const std::uint32_t v = el[f - kFirstVertexFeature<D>];
                for (std::uint32_t o : around[v]) w.constraints.push_back(dir(v, o));
            } else if constexpr (D == 3) {
                if (f > 0) {
                    // Edge f runs from corner f-1 to corner f mod 3 (closestOnTriangle): the faces across it, by
                    // the direction from the edge to their third corner, perpendicular to the edge.
                    const std::uint32_t a = el[f - 1], b = el[f % 3];
                    const Vec<3> t = dir(a, b);
                    for (std::uint32_t o : facesAt[{std::min(a, b), std::max(a, b)}]) {
                        if (o == e) continue;
                        std::uint32_t third = 0;
                        for (int k = 0; k < 3; ++k)
                            if (w.elements[o][k] != a && w.elements[o][k] != b) third = w.elements[o][k];
                        Vec<3> u = w.vertices[third] - w.vertices[a];
                        u -= t * dot(u, t);
                        w.constraints.push_back(u * (1 / norm(u)));
                    }
                }
            }
            w.constraintFirst.push_back(static_cast<std::uint32_t>(w.constraints.size()));
        }
    }
}

}  // namespace haet
