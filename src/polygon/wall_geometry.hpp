#pragma once
// The contact geometry of a polygon and a wall of any shape (geometry/surface.hpp: segments and polylines, circles
// and arcs; docs/physics.md G.6). A wall is taken as the boundary of a solid: the contact is the overlap of the
// polygon with the solid on the far side of the wall from the polygon's centre, with the chord and spin moment of the
// polygon's outline inside it (geometry.hpp), so that the force law and dA/dt are those of a polygon pair.
//
//  - Segment: the solid behind it is the half-plane on the far side of its line, cut at each end. Where two segments
//    of a polyline meet, the cut is the bisector of their angle (a mitre), so the solids behind the segments of a
//    polyline tile the solid behind the whole polyline: at a ridge they do not overlap, in a valley they leave no gap,
//    and on collinear segments the cut is the perpendicular and the pieces add up to the plane's half-plane. At an
//    open end (or a vertex where more than two segments meet) the cut is the perpendicular to the segment.
//  - Which side is solid: the far side from the polygon's centre x when x's closest point on the segment is inside
//    it; when it is an end shared with one other segment, the wedge between the two segments that does not hold x
//    (a centre beyond the end of a segment of a ridge may lie behind that segment's line, yet the solid is the ridge).
//  - Circle: seen from inside (a drum) the solid is the outside, and the overlap the polygon's part outside the circle
//    (its area minus the circle-polygon overlap); from outside (a post), the disk. An arc is that solid cut to the
//    arc's angles by the radial lines through its ends.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "polygon/geometry.hpp"

namespace haet::polygon {

/// A half-plane { y : (y - point) . normal >= 0 }.
struct HalfPlane {
    V2 point;   ///< a point of the boundary line [m]
    V2 normal;  ///< towards the kept side (any length) [-]
};

/// A polygon cut out of a first body by half-planes, with the owner of the edge leaving each vertex (0: the first
/// body's outline, 1: a cut), as clipOverlap tags them.
struct ClippedPolygon {
    VertexBuffer<kMaxClip> v;
    std::uint8_t tag[kMaxClip];
    int n = 0;
};

/// The convex counter-clockwise polygon P clipped by the half-planes h[0, nh) (Sutherland-Hodgman, the conventions of
/// clipOverlap: kept when the side is >= 0, a segment cut only when its ends lie strictly on different sides).
/// Returns false when nothing of P is left (out.n < 3).
inline bool clipByHalfPlanes(const V2* P, int np, const HalfPlane* h, int nh, ClippedPolygon& out) {
    ClippedPolygon tmp;
    const V2* cur = P;
    static constexpr std::uint8_t kPTags[kMaxVertices] = {};
    const std::uint8_t* ct = kPTags;
    int n = np;
    // Each cut writes into the buffer that does not hold the current polygon; the result is copied to out at the end.
    for (int q = 0; q < nh; ++q) {
        double side[kMaxClip];
        int inside = 0;
        for (int k = 0; k < n; ++k) {
            side[k] = dot(cur[k] - h[q].point, h[q].normal);
            inside += side[k] >= 0;
        }
        if (inside == 0) {
            out.n = 0;
            return false;
        }
        if (inside == n) continue;
        ClippedPolygon& dst = (cur == out.v.data()) ? tmp : out;
        int m = 0;
        V2 a = cur[n - 1];
        double sa = side[n - 1];
        std::uint8_t ta = ct[n - 1];
        for (int k = 0; k < n && m < kMaxClip - 1; ++k) {
            const V2 b = cur[k];
            const double sb = side[k];
            const bool ain = sa >= 0, bin = sb >= 0;
            if (ain != bin) {
                const double t = sa / (sa - sb);
                dst.v[m] = a + (b - a) * t;
                dst.tag[m] = bin ? ta : 1;  // entering: the rest of a->b; leaving: along the cut
                ++m;
            }
            if (bin) {
                dst.v[m] = b;
                dst.tag[m] = ct[k];
                ++m;
            }
            a = b;
            sa = sb;
            ta = ct[k];
        }
        cur = dst.v.data();
        ct = dst.tag;
        n = m;
        if (n < 3) {
            out.n = 0;
            return false;
        }
    }
    if (cur != out.v.data()) {
        for (int k = 0; k < n; ++k) {
            out.v[k] = cur[k];
            out.tag[k] = ct[k];
        }
    }
    out.n = n;
    return true;
}

/// Area, centroid, chord and spin of a clipped polygon (geometry.hpp, Overlap): the chord and spin from the edges of
/// the first body's outline (tag 0). Relative to the first vertex, as clipOverlap.
inline Overlap overlapOf(const ClippedPolygon& c) {
    Overlap o;
    const int n = c.n;
    if (n < 3) return o;
    const V2 o0 = c.v[0];
    double a2 = 0, mx = 0, my = 0, spin0 = 0;
    V2 chord{};
    for (int k = 0; k < n; ++k) {
        const V2 p = c.v[k] - o0, q = c.v[k + 1 == n ? 0 : k + 1] - o0;
        const double cr = cross2(p, q);
        a2 += cr;
        mx += (p[0] + q[0]) * cr;
        my += (p[1] + q[1]) * cr;
        if (c.tag[k] == 0) {
            chord += q - p;
            spin0 += 0.5 * (norm2(q) - norm2(p));
        }
    }
    if (!(a2 > 0)) return o;
    const V2 cc{{mx / (3 * a2), my / (3 * a2)}};
    o.area = 0.5 * a2;
    o.centroid = o0 + cc;
    o.chord = chord;
    o.spin = spin0 - dot(cc, chord);
    o.vertices = n;
    return o;
}

/// The overlap of a first body with the union of two disjoint regions, from its overlaps a and b with each: areas and
/// chords add, the centroid is the areas' mean, and each spin moves to the common centroid (s_C = s_a + (C_a - C) .
/// c_a, from the definition of s in geometry.hpp).
inline Overlap sumOf(const Overlap& a, const Overlap& b) {
    if (!(b.area > 0)) return a;
    if (!(a.area > 0)) return b;
    Overlap o;
    o.area = a.area + b.area;
    o.centroid = (a.centroid * a.area + b.centroid * b.area) / o.area;
    o.chord = a.chord + b.chord;
    o.spin = a.spin + dot(a.centroid - o.centroid, a.chord) + b.spin + dot(b.centroid - o.centroid, b.chord);
    o.vertices = a.vertices + b.vertices;
    return o;
}

/// The overlap of a first body with region W minus its part Z (Z inside W), from its overlaps `whole` with W and `part`
/// with Z: as sumOf, with Z's quantities taken away. Area 0 when nothing is left.
inline Overlap differenceOf(const Overlap& whole, const Overlap& part) {
    if (!(part.area > 0)) return whole;
    Overlap o;
    const double area = whole.area - part.area;
    if (!(area > 0)) return o;
    o.area = area;
    o.centroid = (whole.centroid * whole.area - part.centroid * part.area) / area;
    o.chord = whole.chord - part.chord;
    o.spin = whole.spin + dot(whole.centroid - o.centroid, whole.chord) - part.spin -
             dot(part.centroid - o.centroid, part.chord);
    o.vertices = whole.vertices + part.vertices;
    return o;
}

/// Which side of segment (a, b) is free for a polygon centred at x (the solid is the other): the unit normal of the
/// segment pointing to the free side. otherA, otherB: the unit direction of the one other segment at a (at b) away
/// from that vertex, or null (an open end, or a vertex of three or more segments). When x's closest point on the
/// segment is an end with one other segment there, the free side is the one next to the wedge between the two segments
/// that holds x; otherwise it is x's side of the line.
inline V2 segmentFreeNormal(const V2& a, const V2& b, const V2& x, const V2* otherA, const V2* otherB) {
    const V2 ab = b - a;
    const V2 left = perp(ab) / norm(ab);
    const double t = dot(x - a, ab);
    const V2* other = nullptr;
    V2 vertex, along;  // the end nearest x, and the segment's direction away from it
    if (t <= 0 && otherA) {
        other = otherA;
        vertex = a;
        along = ab / norm(ab);
    } else if (t >= norm2(ab) && otherB) {
        other = otherB;
        vertex = b;
        along = -ab / norm(ab);
    }
    if (!other) return cross2(ab, x - a) >= 0 ? left : -left;
    // Angles counter-clockwise from `along`: x lies in the wedge from along to other when its angle is smaller.
    const double twoPi = 2 * 3.14159265358979323846;
    auto angleFrom = [&](const V2& u) {
        const double th = std::atan2(cross2(along, u), dot(along, u));
        return th < 0 ? th + twoPi : th;
    };
    const bool inCcwWedge = angleFrom(x - vertex) < angleFrom(*other);
    // The wedge counter-clockwise from `along` lies to the left of the ray from the vertex along it.
    const V2 rayLeft = perp(along);
    return inCcwWedge ? rayLeft : -rayLeft;
}

/// The cut of a segment's solid at one of its ends: the kept side is (y - end) . k >= 0 with k returned, `along` the
/// segment's unit direction away from that end. With one other segment there (unit direction `other` away from the
/// end), the bisector of their angle (k along along - other); otherwise the perpendicular (k = along).
inline V2 segmentCut(const V2& along, const V2* other) {
    if (other) {
        const V2 k = along - *other;
        const double l = norm(k);
        if (l > 1e-9) return k / l;
    }
    return along;
}

/// The overlap of the convex counter-clockwise polygon P with the solid behind segment (a, b) (the file comment):
/// free, the unit normal to the free side (segmentFreeNormal); ka, kb, the cuts at a and b (segmentCut).
inline Overlap segmentOverlap(const V2* P, int np, const V2& a, const V2& b, const V2& free, const V2& ka,
                              const V2& kb) {
    // Behind the line first: it rejects most polygons near a wall but not touching it.
    const HalfPlane h[3] = {{a, -free}, {a, ka}, {b, kb}};
    ClippedPolygon c;
    if (!clipByHalfPlanes(P, np, h, 3, c)) return Overlap{};
    return overlapOf(c);
}

/// The parts of the polygon Q outside the circle of radius R about the origin (Q counter-clockwise, relative to the
/// circle's centre; tags: the owner of the edge leaving each vertex as ClippedPolygon's, or null for the first body's
/// outline throughout), one Overlap each, written to out (room for maxOut). A part runs along Q's outline from where it
/// leaves the circle to where it comes back, then back along the circle clockwise; by Green's theorem its area and
/// first moment are those of the outline's pieces (triangles from the centre) minus those of the arc's sector, and
/// its chord and spin those of the outline pieces of tag 0. Returns how many, or -1 when the outline does not cross
/// the circle but leaves it (the circle inside Q: the caller takes Q minus the disk).
inline int outsideCirclePieces(const V2* Q, const std::uint8_t* tags, int n, double R, Overlap* out, int maxOut) {
    const double R2 = R * R;
    // The outline's points outside or on the circle, in order: outside vertices (kind 0), exits (+1), entries (-1),
    // each with the edge the outline follows from it.
    struct Point {
        V2 p;
        int edge;
        int kind;
    };
    Point seq[3 * kMaxClip];
    int m = 0, firstExit = -1;
    bool anyOut = false;
    for (int k = 0; k < n; ++k) {
        const V2 a = Q[k], b = Q[k + 1 == n ? 0 : k + 1], d = b - a;
        const bool aOut = norm2(a) > R2, bOut = norm2(b) > R2;
        anyOut = anyOut || aOut;
        if (aOut) seq[m++] = Point{a, k, 0};
        if (!aOut && !bOut) continue;  // an edge between points of the disk stays in it
        const double dd = norm2(d), ad = dot(a, d);
        if (!(dd > 0)) continue;
        const double disc = ad * ad - dd * (norm2(a) - R2);
        const double sq = disc > 0 ? std::sqrt(disc) : 0.0;
        const double t0 = std::clamp((-ad - sq) / dd, 0.0, 1.0), t1 = std::clamp((-ad + sq) / dd, 0.0, 1.0);
        if (aOut && bOut) {  // a dip into the circle, if the edge crosses it
            if (!(disc > 0) || !(t0 > 0 && t1 < 1 && t0 < t1)) continue;
            seq[m++] = Point{a + d * t0, k, -1};
            if (firstExit < 0) firstExit = m;
            seq[m++] = Point{a + d * t1, k, 1};
        } else if (aOut) {
            seq[m++] = Point{a + d * t0, k, -1};
        } else {
            if (firstExit < 0) firstExit = m;
            seq[m++] = Point{a + d * t1, k, 1};
        }
    }
    if (firstExit < 0) return anyOut ? -1 : 0;
    const double twoPi = 2 * 3.14159265358979323846;
    int count = 0;
    for (int q = 0; q < m && count < maxOut; ++q) {
        const int s = (firstExit + q) % m;
        if (seq[s].kind != 1) continue;
        // The piece from exit s to the next entry.
        double a2 = 0, spin0 = 0;
        V2 mom2{}, chord{};
        int j = s;
        for (int step = 0; step < m; ++step) {
            const int nx = j + 1 == m ? 0 : j + 1;
            const V2 u = seq[j].p, w = seq[nx].p;
            const double cr = cross2(u, w);
            a2 += cr;
            mom2 += (u + w) * (cr / 3.0);
            if (!tags || tags[seq[j].edge] == 0) {
                chord += w - u;
                spin0 += 0.5 * (norm2(w) - norm2(u));
            }
            j = nx;
            if (seq[j].kind == -1) break;
        }
        // Back along the circle, clockwise from the entry to the exit: the sector of angle th counter-clockwise from
        // the exit to the entry, taken away.
        const V2 ux = seq[s].p / norm(seq[s].p), ue = seq[j].p / norm(seq[j].p);
        double th = std::atan2(cross2(ux, ue), dot(ux, ue));
        if (th <= 0) th += twoPi;
        a2 -= R2 * th;
        mom2 -= V2{{ue[1] - ux[1], ux[0] - ue[0]}} * (2 * R2 * R / 3);
        if (!(a2 > 0)) continue;
        Overlap o;
        o.area = 0.5 * a2;
        o.centroid = mom2 / a2;
        o.chord = chord;
        o.spin = spin0 - dot(o.centroid, chord);
        out[count++] = o;
    }
    return count;
}

/// Contacts of one circle or arc with a polygon, at most.
inline constexpr int kMaxCirclePieces = 8;

/// The overlaps of the convex counter-clockwise polygon P (of area `areaP`, centroid at the origin of P's
/// coordinates) with the solid of a circle of radius R centred at c, written to out (room for kMaxCirclePieces):
/// outside the circle when `inside` (the polygon's centre inside: a drum), one overlap per part of the polygon
/// outside it (a square's two corners in a drum are two contacts, as two disks would be); else the disk, one overlap.
/// Angles a0 < a1 [rad] cut the solid to an arc's wedge when `arc`, in convex wedges of at most half a turn (each
/// its own parts). Returns how many.
inline int circleSolidOverlaps(const V2* P, int np, double areaP, const V2& c, double R, bool inside, bool arc,
                               double a0, double a1, Overlap* out) {
    const double R2 = R * R;
    // The polygon relative to the circle's centre.
    VertexBuffer<kMaxVertices> Q;
    bool anyOut = false;
    for (int k = 0; k < np; ++k) {
        Q[k] = P[k] - c;
        anyOut = anyOut || norm2(Q[k]) > R2;
    }
    if (inside && !anyOut) return 0;  // wholly inside the drum
    int n = 0;
    if (!arc) {
        if (inside) n = outsideCirclePieces(Q.data(), nullptr, np, R, out, kMaxCirclePieces);
        if (n < 0 || !inside) {  // the disk (a post), or the polygon minus the disk
            const Overlap in = circlePolygonOverlap(R, Q.data(), np);
            Overlap whole;
            whole.area = areaP;  // centroid, chord and spin of the whole outline: zero (in P's frame: -c here)
            whole.centroid = -c;
            out[0] = inside ? differenceOf(whole, in) : in;
            n = out[0].area > 0 ? 1 : 0;
        }
    } else {
        // The wedge [a0, a1] in convex pieces of at most a half turn, each the polygon clipped by two radial lines.
        const double pi = 3.14159265358979323846;
        const int wedges = a1 - a0 > pi ? 2 : 1;
        Overlap disk;
        for (int q = 0; q < wedges; ++q) {
            const double from = a0 + (a1 - a0) * q / wedges, to = a0 + (a1 - a0) * (q + 1) / wedges;
            const V2 u0{{std::cos(from), std::sin(from)}}, u1{{std::cos(to), std::sin(to)}};
            const HalfPlane h[2] = {{V2::zero(), perp(u0)}, {V2::zero(), -perp(u1)}};
            ClippedPolygon cut;
            if (!clipByHalfPlanes(Q.data(), np, h, 2, cut)) continue;
            if (!inside) {  // the post's solid: one overlap over the wedges
                disk = sumOf(disk, circlePolygonOverlapTagged(R, cut.v.data(), cut.n, cut.tag));
                continue;
            }
            const int got = outsideCirclePieces(cut.v.data(), cut.tag, cut.n, R, out + n, kMaxCirclePieces - n);
            if (got > 0) n += got;
            if (got < 0 && n < kMaxCirclePieces) {
                const Overlap d =
                    differenceOf(overlapOf(cut), circlePolygonOverlapTagged(R, cut.v.data(), cut.n, cut.tag));
                if (d.area > 0) out[n++] = d;
            }
        }
        if (!inside && disk.area > 0) out[n++] = disk;
    }
    for (int q = 0; q < n; ++q) out[q].centroid += c;  // from the circle's frame to P's
    return n;
}

}  // namespace haet::polygon
