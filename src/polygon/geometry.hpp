#pragma once
// Contact geometry of 2D convex polygons (docs/physics.md G.2; their shapes and moments: core/polygon_shape.hpp): the
// separating-axis test, the overlap of two convex polygons by Sutherland-Hodgman clipping,
// the overlap of a circle and a convex polygon, and the overlap of a polygon with a half-plane (a wall).
//
// Every overlap routine also returns the two quantities the force law needs besides area and centroid
// (docs/physics.md G.3):
//  - the chord c: the sum of the edge vectors of the overlap's boundary that lie on the first body's outline,
//    counter-clockwise. With two outline intersection points S1, S2 it is S2 - S1, and the contact normal is
//    perpendicular to it. It is also the gradient of the overlap area: translating the first body by t changes
//    the area by (c_y, -c_x) . t. So the normal from c stays defined when the outlines cross more than twice
//    (deep overlaps): it is the direction in which the overlap shrinks fastest.
//  - the spin moment s = sum over the same edges of (|b - C|^2 - |a - C|^2)/2, with C the overlap centroid:
//    spinning the first body about C changes the area by -omega s, which makes dA/dt exact for rigid motion.
// Edges that lie on both outlines (parallel, touching edges) count once, for whichever body the clipping
// assigned them to; their contributions cancel in c, so the normal does not depend on that choice.
//
// Degenerate cases never produce NaN: a segment is only intersected with a line when its end points lie
// strictly on different sides; fewer than three surviving vertices means no overlap (area 0); touching outlines
// (vertex on vertex, edge on edge) give zero area.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "core/lanes.hpp"
#include "core/polygon_shape.hpp"
#include "core/vec.hpp"

namespace haet::polygon {

/// Stack room for N vertices left uninitialised: Vec zero-fills itself, and clearing the buffers of every pair
/// cost as much as the clipping (measured). The code writes every vertex before reading it.
template <int N>
struct VertexBuffer {
    VertexBuffer() {}
    union {
        V2 v[N];
    };
    V2& operator[](int k) { return v[k]; }
    const V2& operator[](int k) const { return v[k]; }
    V2* data() { return v; }
};

// ---- separating axes ----

/// True when some edge of P or Q separates the two convex counter-clockwise polygons (touching counts as
/// separated: the overlap area is zero). docs/physics.md G.4.
inline bool separated(const V2* P, int np, const V2* Q, int nq) {
    auto byEdgesOf = [](const V2* A, int na, const V2* B, int nb) {
        for (int k = 0; k < na; ++k) {
            const V2 a = A[k], e = A[k + 1 == na ? 0 : k + 1] - a;
            bool allOutside = true;
            for (int m = 0; m < nb && allOutside; ++m) allOutside = cross2(e, B[m] - a) <= 0;
            if (allOutside) return true;
        }
        return false;
    };
    return byEdgesOf(P, np, Q, nq) || byEdgesOf(Q, nq, P, np);
}

/// True when the projections on the direction `u` (any length) of P shifted by a vector whose projection is `shift`
/// and of Q do not overlap (touching counts as apart). The line of centres is the axis that separates most
/// non-touching pairs of a cell list, at n + m dot products.
inline bool separatedAlong(const V2& u, double shift, const V2* P, int np, const V2* Q, int nq) {
    double minP = dot(P[0], u), maxQ = dot(Q[0], u);
    for (int k = 1; k < np; ++k) minP = std::min(minP, dot(P[k], u));
    for (int k = 1; k < nq; ++k) maxQ = std::max(maxQ, dot(Q[k], u));
    return shift + minP >= maxQ;
}

// ---- overlaps ----

/// The overlap of two bodies as the force law needs it. Coordinates are those of the inputs.
struct Overlap {
    double area = 0;   ///< [m^2]; 0 when the bodies do not overlap (then the other members are unset)
    V2 centroid{};     ///< C [m]
    V2 chord{};        ///< c: sum of the first body's outline pieces inside the second [m] (see the file comment)
    double spin = 0;   ///< s: sum over those pieces of (|b - C|^2 - |a - C|^2)/2 [m^2]
    int vertices = 0;  ///< vertices of the overlap polygon (0 for a circle)
};

/// Overlap of the convex counter-clockwise polygons P (the first body) and Q by Sutherland-Hodgman clipping of P
/// against every edge of Q. Vertices beyond kMaxVertices per polygon are not supported. If `out` is given it
/// receives the overlap polygon (capacity kMaxClip). `pCentre`, `pRadius`: a circle holding P, if known; an edge of Q
/// whose inner half-plane holds that whole circle cannot cut P and is skipped (one test instead of one per vertex).
/// `pShift`: if given, P is taken moved by it (P[k] + *pShift), as the force loop keeps vertices about the centre.
/// The clipping runs in P's frame (Q moved by -pShift, the centroid moved back at the end), so that the first edge
/// reads P where it lies instead of a moved copy.
inline Overlap clipOverlap(const V2* P, int np, const V2* Q, int nq, V2* out = nullptr, const V2* pCentre = nullptr,
                           double pRadius = 0, const V2* pShift = nullptr) {
    // Each vertex carries the owner of the edge that leaves it: 0 = P's outline, 1 = Q's.
    static constexpr std::uint8_t kPTags[kMaxVertices] = {};
    VertexBuffer<kMaxClip> bufA, bufB;
    std::uint8_t tagA[kMaxClip], tagB[kMaxClip];
    const V2* cur = P;
    const std::uint8_t* ct = kPTags;
    V2* nxt = bufA.data();
    std::uint8_t* nt = tagA;
    const V2 shift = pShift ? *pShift : V2::zero();
    const V2 centre = pCentre ? *pCentre - shift : V2::zero();
    int n = np;
    for (int e = 0; e < nq && n >= 3; ++e) {
        const V2 q0 = Q[e] - shift, d = Q[e + 1 == nq ? 0 : e + 1] - Q[e];
        if (pCentre) {
            const double sc = cross2(d, centre - q0);  // |d| x the centre's distance inside the edge's line
            if (sc > 0 && sc * sc >= pRadius * pRadius * norm2(d)) continue;
        }
        // Sides first: an edge that leaves every vertex inside changes nothing (the common case), one that leaves
        // none inside ends the overlap.
        double side[kMaxClip];
        int inside = 0;
        for (int k = 0; k < n; ++k) {
            side[k] = cross2(d, cur[k] - q0);
            inside += side[k] >= 0;
        }
        if (inside == n) continue;
        if (inside == 0) return Overlap{};
        int m = 0;
        V2 a = cur[n - 1];
        double sa = side[n - 1];
        std::uint8_t ta = ct[n - 1];
        for (int k = 0; k < n && m < kMaxClip - 1; ++k) {
            const V2 b = cur[k];
            const double sb = side[k];
            const bool ain = sa >= 0, bin = sb >= 0;
            if (ain != bin) {
                // Strictly different sides: sa - sb is nonzero.
                const double t = sa / (sa - sb);
                nxt[m] = a + (b - a) * t;
                nt[m] = bin ? ta : 1;  // entering: the rest of a->b; leaving: along Q's edge e
                ++m;
            }
            if (bin) {
                nxt[m] = b;
                nt[m] = ct[k];
                ++m;
            }
            a = b;
            sa = sb;
            ta = ct[k];
        }
        cur = nxt;
        ct = nt;
        nxt = nxt == bufA.data() ? bufB.data() : bufA.data();
        nt = nt == tagA ? tagB : tagA;
        n = m;
    }
    Overlap o;
    if (n < 3) return o;
    // Area, centroid, chord and spin in one pass, relative to the first vertex (spin about it, then moved to C:
    // s_C = s_0 - (C - v0) . c).
    const V2 o0 = cur[0];
    double a2 = 0, mx = 0, my = 0, spin0 = 0;
    V2 chord{};
    for (int k = 0; k < n; ++k) {
        const V2 p = cur[k] - o0, q = cur[k + 1 == n ? 0 : k + 1] - o0;
        const double cr = cross2(p, q);
        a2 += cr;
        mx += (p[0] + q[0]) * cr;
        my += (p[1] + q[1]) * cr;
        if (ct[k] == 0) {
            chord += q - p;
            spin0 += 0.5 * (norm2(q) - norm2(p));
        }
    }
    if (!(a2 > 0)) return o;
    const V2 c{{mx / (3 * a2), my / (3 * a2)}};
    o.area = 0.5 * a2;
    o.centroid = o0 + c + shift;
    o.chord = chord;
    o.spin = spin0 - dot(c, chord);
    o.vertices = n;
    if (out)
        for (int k = 0; k < n; ++k) out[k] = cur[k] + shift;
    return o;
}

namespace detail {

/// twoCrossingOverlap (below) for np <= 4 kBlocks (the blocks of four vertices unrolled).
template <int kBlocks>
inline bool twoCrossing(const V2* P, int np, const V2* Q, int nq, const V2& pCentre, double pRadius, const V2& pShift,
                        Overlap& o) {
    // P's coordinates side by side; the lanes past np repeat vertex 0 (their bits are dropped).
    // (Filled as doubles, then loaded: writing single lanes becomes an instruction that valgrind cannot run.)
    alignas(32) double xs[4 * kBlocks], ys[4 * kBlocks];
    for (int k = 0; k < 4 * kBlocks; ++k) {
        const V2& v = P[k < np ? k : 0];
        xs[k] = v[0];
        ys[k] = v[1];
    }
    Lanes px[kBlocks], py[kBlocks];
    for (int bl = 0; bl < kBlocks; ++bl) {
        std::memcpy(&px[bl].v, xs + 4 * bl, sizeof px[bl].v);
        std::memcpy(&py[bl].v, ys + 4 * bl, sizeof py[bl].v);
    }
    alignas(32) double side[kMaxVertices][4 * kBlocks];  // [edge of Q][vertex of P]
    std::uint32_t outE[kMaxVertices];  // per edge of Q that cuts P: bit k set when vertex k of P is outside
    int cut[kMaxVertices], ncut = 0;   // those edges
    const std::uint32_t all = (std::uint32_t{1} << np) - 1;
    std::uint32_t outAny = 0, shared = 0;
    const auto next = [&](std::uint32_t m) { return (m >> 1) | ((m & 1u) << (np - 1)); };  // bit k: vertex k + 1
    const V2 centre = pCentre - pShift;
    const double r2 = pRadius * pRadius;
    for (int e = 0; e < nq; ++e) {
        const V2 q0 = Q[e] - pShift, d = Q[e + 1 == nq ? 0 : e + 1] - Q[e];
        const double sc = cross2(d, centre - q0);          // |d| x the centre's distance inside the edge's line
        if (sc > 0 && sc * sc >= r2 * norm2(d)) continue;  // cannot reach P's bounding circle
        const Lanes dx(d[0]), dy(d[1]), qx(q0[0]), qy(q0[1]);
        std::uint32_t out = 0;
        for (int bl = 0; bl < kBlocks; ++bl) {
            const Lanes s = dx * (py[bl] - qy) - dy * (px[bl] - qx);  // cross2(d, P[k] - q0)
            std::memcpy(side[e] + 4 * bl, &s.v, sizeof s.v);
            out |= bitsOf(s < Lanes(0.0)) << (4 * bl);
        }
        out &= all;
        if (out == all) {  // P outside one edge line of Q: apart
            o = Overlap{};
            return true;
        }
        if (!out) continue;
        outE[ncut] = out;
        cut[ncut++] = e;
        outAny |= out;
        shared |= out & next(out);  // edges of P with both ends outside edge e
    }
    const std::uint32_t in = all & ~outAny;
    const std::uint32_t leaving = in & ~next(in) & all, entering = ~in & next(in) & all;
    if (std::popcount(leaving) != 1) return false;      // no run, all inside, or more than one run
    if (outAny & next(outAny) & ~shared) return false;  // an edge of P with both ends outside might cross Q
    const int leave = std::countr_zero(leaving), enter = std::countr_zero(entering);
    // Exit from Q on P's edge leave -> a: the smallest parameter over the edges that a is outside of.
    const int a = leave + 1 == np ? 0 : leave + 1;
    int j2 = -1;
    double t2 = 2;
    for (int c = 0; c < ncut; ++c) {
        if (!(outE[c] >> a & 1u)) continue;
        const int e = cut[c];
        const double sa = side[e][leave], t = sa / (sa - side[e][a]);
        if (t == t2) return false;
        if (t < t2) {
            t2 = t;
            j2 = e;
        }
    }
    // Entry into Q on P's edge enter -> b: the largest parameter over the edges that `enter` is outside of.
    const int b = enter + 1 == np ? 0 : enter + 1;
    int j1 = -1;
    double t1 = -1;
    for (int c = 0; c < ncut; ++c) {
        if (!(outE[c] >> enter & 1u)) continue;
        const int e = cut[c];
        const double sa = side[e][enter], t = sa / (sa - side[e][b]);
        if (t == t1) return false;
        if (t > t1) {
            t1 = t;
            j1 = e;
        }
    }
    const V2 s1 = P[enter] + (P[b] - P[enter]) * t1;
    const V2 s2 = P[leave] + (P[a] - P[leave]) * t2;
    if (j1 == j2 && !(dot(s1 - s2, Q[j1 + 1 == nq ? 0 : j1 + 1] - Q[j1]) > 0)) return false;
    // The overlap polygon relative to S1: S1, P's run, S2, Q's run.
    VertexBuffer<kMaxClip> poly;
    int n = 0;
    poly[n++] = V2::zero();
    for (int k = b;; k = k + 1 == np ? 0 : k + 1) {
        poly[n++] = P[k] - s1;
        if (k == leave) break;
    }
    poly[n++] = s2 - s1;
    // Round-off can pick the wrong one of two edges of Q only at a vertex of Q where both give the same crossing
    // (to round-off): adding or dropping that vertex, next to S1 or S2, changes nothing that matters, unless the
    // picks swap the order of S1 and S2 and Q's run goes the other way round, over nq - 1 >= 2 vertices. So runs of
    // two or more vertices are checked to lie inside P.
    const int nRunQ = j1 >= j2 ? j1 - j2 : j1 - j2 + nq;
    for (int j = j2; j != j1;) {
        j = j + 1 == nq ? 0 : j + 1;
        const V2 v = Q[j] - pShift;
        if (nRunQ >= 2)
            for (int k = 0; k < np; ++k)
                if (cross2(P[k + 1 == np ? 0 : k + 1] - P[k], v - P[k]) < 0) return false;
        poly[n++] = v - s1;
    }
    double a2 = 0, mx = 0, my = 0;
    for (int k = 1; k + 1 < n; ++k) {  // the two edges at S1 = 0 add nothing
        const V2 p = poly[k], q = poly[k + 1];
        const double cr = cross2(p, q);
        a2 += cr;
        mx += (p[0] + q[0]) * cr;
        my += (p[1] + q[1]) * cr;
    }
    o = Overlap{};
    if (!(a2 > 0)) return true;
    const V2 chord = poly[n - 1 - nRunQ];  // S2 - S1
    const V2 c{{mx / (3 * a2), my / (3 * a2)}};
    o.area = 0.5 * a2;
    o.centroid = s1 + c + pShift;
    o.chord = chord;
    o.spin = 0.5 * norm2(chord) - dot(c, chord);
    o.vertices = n;
    return true;
}

}  // namespace detail

/// The common contact of clipOverlap computed directly: when the outlines of the convex counter-clockwise polygons P
/// and Q cross exactly twice, the overlap is the run of P's vertices inside Q, the exit point S2, the run of Q's
/// vertices from S2's edge on to the edge of the entry point S1, and S1 (Sutherland-Hodgman builds the same polygon by
/// cutting P with every edge of Q in turn). Arguments as in clipOverlap, with the bounding circle (pCentre, pRadius)
/// and pShift required; returns false, leaving `o` alone, when it cannot tell that the outlines cross exactly twice,
/// and clipOverlap must run.
///
/// Every edge of Q that can reach P's bounding circle gives the sides of all of P's vertices, four at a time (the
/// clipping's formula and convention: outside when side < 0); a vertex outside no edge is inside Q. Exactly two
/// crossings follow when P's inside vertices form one run (between 1 and np - 1 vertices) and every edge of P with both
/// ends outside Q has them outside one same edge of Q (such an edge cannot cross Q; a second run, or an edge crossing Q
/// twice, would add crossings). The crossing on the edge leaving the run is the first exit over the edges of Q that its
/// outer end is outside of (Cyrus-Beck), the one on the entering edge the last entry. It falls back when two edges of Q
/// give the same crossing parameter (a vertex of Q on P's outline), when both crossings lie on one edge of Q in the
/// wrong order (Q's outline would go all the way round), and when a vertex of a run of two or more of Q's vertices is
/// not inside P (round-off near a vertex of Q). The chord is S2 - S1 and the spin about S1 is |S2 - S1|^2 / 2.
inline bool twoCrossingOverlap(const V2* P, int np, const V2* Q, int nq, const V2& pCentre, double pRadius,
                               const V2& pShift, Overlap& o) {
    if (np <= 4) return detail::twoCrossing<1>(P, np, Q, nq, pCentre, pRadius, pShift, o);
    if (np <= 8) return detail::twoCrossing<2>(P, np, Q, nq, pCentre, pRadius, pShift, o);
    return detail::twoCrossing<(kMaxVertices + 3) / 4>(P, np, Q, nq, pCentre, pRadius, pShift, o);
}

/// Overlap of two convex polygons as clipOverlap computes it (pCentre and pShift required): twoCrossingOverlap
/// where it applies, else the clipping. Out of line, like the clipping (inlined, it made the force pass slower).
[[gnu::noinline]] inline Overlap convexOverlap(const V2* P, int np, const V2* Q, int nq, const V2& pCentre,
                                               double pRadius, const V2& pShift) {
    Overlap o;
    if (twoCrossingOverlap(P, np, Q, nq, pCentre, pRadius, pShift, o)) return o;
    return clipOverlap(P, np, Q, nq, nullptr, &pCentre, pRadius, &pShift);
}

namespace detail {

/// circlePolygonOverlap (below); kTagged: chord and spin only from the edges k with tags[k] == 0.
template <bool kTagged>
inline Overlap circleOverlap(double R, const V2* Q, int nq, const std::uint8_t* tags) {
    const double R2 = R * R;
    double area2 = 0;  // twice the area
    V2 mom2{};         // twice the first moment
    V2 chord{};
    double spinO = 0;  // spin about the circle centre
    bool boundaryInside = false;
    bool centreInside = true;
    auto sector = [&](const V2& p, const V2& q) {
        const double th = std::atan2(cross2(p, q), dot(p, q));
        area2 += R2 * th;
        const V2 u = p / norm(p), w = q / norm(q);
        mom2 += V2{{w[1] - u[1], u[0] - w[0]}} * (2 * R2 * R / 3);
    };
    for (int k = 0; k < nq; ++k) {
        const V2 a = Q[k], b = Q[k + 1 == nq ? 0 : k + 1], d = b - a;
        if (cross2(d, -a) < 0) centreInside = false;
        const double dd = norm2(d), ad = dot(a, d);
        const double disc = ad * ad - dd * (norm2(a) - R2);
        double t0 = 1, t1 = 0;
        if (disc > 0 && dd > 0) {
            const double sq = std::sqrt(disc);
            t0 = std::max(0.0, (-ad - sq) / dd);
            t1 = std::min(1.0, (-ad + sq) / dd);
        }
        if (t0 < t1) {
            const V2 p0 = a + d * t0, p1 = a + d * t1;
            if (t0 > 0) sector(a, p0);
            const double cr = cross2(p0, p1);
            area2 += cr;
            mom2 += (p0 + p1) * (cr / 3.0);
            if (!kTagged || tags[k] == 0) {
                chord += p1 - p0;
                spinO += 0.5 * (norm2(p1) - norm2(p0));
            }
            boundaryInside = true;
            if (t1 < 1) sector(p1, b);
        } else {
            sector(a, b);
        }
    }
    Overlap o;
    if (!boundaryInside && !centreInside) return o;  // no outline inside the circle, centre outside: apart
    if (!(area2 > 0)) return o;
    o.area = 0.5 * area2;
    o.centroid = mom2 / area2;
    o.chord = chord;
    o.spin = spinO - dot(o.centroid, chord);  // about C: sum (|b|^2 - |a|^2)/2 - C . sum (b - a)
    return o;
}

}  // namespace detail

/// Overlap of the disk of radius R centred at the origin with the convex counter-clockwise polygon Q (the first
/// body is the polygon: chord and spin are those of Q's outline inside the circle). Exact: the overlap is cut
/// into triangles (centre, edge piece inside the circle) and circular sectors (edge pieces outside).
inline Overlap circlePolygonOverlap(double R, const V2* Q, int nq) {
    return detail::circleOverlap<false>(R, Q, nq, nullptr);
}

/// circlePolygonOverlap of a polygon Q cut out of a first body: chord and spin from the edges k with tags[k] == 0
/// only (the first body's outline; the cuts are not), as the clipping tags them (wall_geometry.hpp).
inline Overlap circlePolygonOverlapTagged(double R, const V2* Q, int nq, const std::uint8_t* tags) {
    return detail::circleOverlap<true>(R, Q, nq, tags);
}

/// Overlap of the convex counter-clockwise polygon P with the half-plane { y : n . (y - p0) <= 0 } (the outside of
/// a wall whose unit normal n points into the domain). The chord is P's outline inside the half-plane.
inline Overlap halfPlaneOverlap(const V2* P, int np, const V2& p0, const V2& n) {
    VertexBuffer<kMaxVertices + 2> poly;
    std::uint8_t tag[kMaxVertices + 2];
    int m = 0;
    V2 a = P[np - 1];
    double sa = -dot(n, a - p0);
    for (int k = 0; k < np; ++k) {
        const V2 b = P[k];
        const double sb = -dot(n, b - p0);
        const bool ain = sa >= 0, bin = sb >= 0;
        if (ain != bin) {
            const double t = sa / (sa - sb);
            poly[m] = a + (b - a) * t;
            tag[m++] = bin ? 0 : 1;
        }
        if (bin) {
            poly[m] = b;
            tag[m++] = 0;
        }
        a = b;
        sa = sb;
    }
    Overlap o;
    if (m < 3) return o;
    const Moments mo = polygonMoments(poly.data(), m);
    if (!(mo.area > 0)) return o;
    o.area = mo.area;
    o.centroid = mo.centroid;
    o.vertices = m;
    for (int k = 0; k < m; ++k) {
        if (tag[k] != 0) continue;
        const V2 u = poly[k] - o.centroid, w = poly[k + 1 == m ? 0 : k + 1] - o.centroid;
        o.chord += w - u;
        o.spin += 0.5 * (norm2(w) - norm2(u));
    }
    return o;
}

}  // namespace haet::polygon
