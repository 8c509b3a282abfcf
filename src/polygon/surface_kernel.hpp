#pragma once
// The wall kernel of polygons against walls of any shape (2D: segments and polylines, circles and arcs;
// docs/physics.md G.6), the polygon side of ShapeWall (polygon_kernel.hpp). Per particle: its candidates from the
// broad phase (tdm/surface_state.hpp), each element's overlap with the solid behind it (wall_geometry.hpp), the
// overlaps of one wall whose normals agree within kMergeAngle merged into one contact (collinear segments: the plane's
// overlap), each contact matched to the particle's contact with that wall in the last pass by its normal (its spring
// carries over, H.3), then polygonContact with the wall as a body of infinite mass moving with its pose. The contacts
// live in the same slots as a disk's: normal, spring, force, the force point, the depth A / |c|, the wall.
#include <algorithm>
#include <cstdint>

#include "contact/setup.hpp"
#include "polygon/contact.hpp"
#include "polygon/wall_geometry.hpp"
#include "tdm/pair_pass.hpp"
#include "tdm/surface_kernel.hpp"
#include "tdm/surface_state.hpp"

namespace haet::polygon {

/// One contact of a polygon with a wall of any shape, in world axes about the polygon's centre.
struct SurfaceOverlap {
    Overlap o;           ///< centroid relative to the polygon's centre [m]
    V2 normal;           ///< the contact normal: perpendicular to the chord, from the wall to the polygon [-]
    V2 shape;            ///< the element's own normal (segment normal, radial), which merging compares [-]
    std::uint32_t wall;  ///< index into the surface walls
};

/// Overlaps of one polygon with the elements near it in one pass, before merging: at most this many are kept.
inline constexpr int kMaxSurfaceOverlaps = 32;

/// The contacts of a polygon of vertices P[0, np) about its centre x (world axes; area `area`) with the candidate
/// elements [k0, k1) of surface state s, merged per wall, the largest kSurfaceSlots kept (in their order otherwise).
/// Returns how many were written to out (room for kMaxSurfaceOverlaps).
inline int polygonSurfaceOverlaps(const SurfaceState<2>& s, const V2* P, int np, double area, const V2& x,
                                  std::uint32_t k0, std::uint32_t k1, SurfaceOverlap* out) {
    constexpr int kMax = kMaxSurfaceOverlaps;
    const std::vector<SurfaceWall<2>>& walls = *s.walls;
    int n = 0;
    VertexBuffer<kMaxVertices> Pb;
    for (std::uint32_t k = k0; k < k1;) {
        const std::uint32_t w = s.candidates.wall[k];
        const SurfaceWall<2>& wall = walls[w];
        const Pose<2>& pose = s.poses[w];
        // In the wall's body axes about the polygon's centre (the same numbers as the world's for a wall that does
        // not rotate).
        const V2 xb = pose.toBody(x);
        for (int m = 0; m < np; ++m) Pb[m] = pose.directionToBody(P[m]);
        const int start = n;
        for (; k < k1 && s.candidates.wall[k] == w; ++k) {
            Overlap o[kMaxCirclePieces];
            V2 shapeNormal[kMaxCirclePieces];
            int pieces = 0;
            if (wall.kind == SurfaceKind::Mesh) {
                const std::size_t e = s.candidates.element[k];
                const auto& el = wall.elements[e];
                const V2 a = wall.vertices[el[0]] - xb, b = wall.vertices[el[1]] - xb;
                const V2 ab = b - a, along = ab / norm(ab);
                // The one other segment at each end (the Voronoi directions of the end vertex: the segments there).
                V2 other[2];
                const V2* op[2] = {nullptr, nullptr};
                for (int end = 0; end < 2; ++end) {
                    const std::size_t f = e * kFeatures<2> + static_cast<std::size_t>(kFirstVertexFeature<2> + end);
                    const std::uint32_t c0 = wall.constraintFirst[f], c1 = wall.constraintFirst[f + 1];
                    if (c1 - c0 != 2) continue;
                    const V2 away = end == 0 ? along : -along;
                    const V2 &u = wall.constraints[c0], &v = wall.constraints[c0 + 1];
                    other[end] = dot(u, away) < dot(v, away) ? u : v;
                    op[end] = &other[end];
                }
                shapeNormal[0] = segmentFreeNormal(a, b, V2::zero(), op[0], op[1]);
                o[0] = segmentOverlap(Pb.data(), np, a, b, shapeNormal[0], segmentCut(along, op[0]),
                                      segmentCut(-along, op[1]));
                pieces = o[0].area > 0 ? 1 : 0;
            } else if (wall.kind == SurfaceKind::Arc) {
                const V2 c = wall.centre - xb;
                const bool inside = norm2(c) < wall.radius * wall.radius;
                pieces = circleSolidOverlaps(Pb.data(), np, area, c, wall.radius, inside, !wall.fullCircle(),
                                             wall.angle0, wall.angle1, o);
                for (int q = 0; q < pieces; ++q) {  // radial through the piece's centroid, towards the polygon
                    const V2 r = inside ? c - o[q].centroid : o[q].centroid - c;
                    const double l = norm(r);
                    shapeNormal[q] = l > 0 ? r / l : V2{{0.0, 1.0}};
                }
            }
            for (int piece = 0; piece < pieces; ++piece) {
                if (!(o[piece].area > 0) || n == kMax) continue;
                // Merge with an earlier overlap of this wall whose element faces the same way (collinear segments).
                bool merged = false;
                for (int q = start; q < n && !merged; ++q) {
                    if (norm2(out[q].shape - shapeNormal[piece]) < kMergeAngle * kMergeAngle) {
                        out[q].o = sumOf(out[q].o, o[piece]);
                        merged = true;
                    }
                }
                if (!merged) out[n++] = SurfaceOverlap{o[piece], V2::zero(), shapeNormal[piece], w};
            }
        }
        for (int q = start; q < n; ++q) {
            SurfaceOverlap& c = out[q];
            c.o.centroid = pose.directionToWorld(c.o.centroid);
            c.o.chord = pose.directionToWorld(c.o.chord);
            c.shape = pose.directionToWorld(c.shape);
            // The chord's normal: the direction in which the overlap shrinks fastest (-grad A), which the potential
            // law needs to conserve energy; the element's normal when there is no chord (the polygon inside the solid).
            const double cl = norm(c.o.chord);
            c.normal = cl > 1e-12 * std::sqrt(c.o.area) ? perp(c.o.chord) / cl : c.shape;
        }
    }
    if (n > kSurfaceSlots) {  // the largest, in their order otherwise
        int order[kMax];
        for (int q = 0; q < n; ++q) order[q] = q;
        std::stable_sort(order, order + n, [&](int a, int b) { return out[a].o.area > out[b].o.area; });
        std::sort(order, order + kSurfaceSlots);
        for (int q = 0; q < kSurfaceSlots; ++q) out[q] = out[order[q]];
        n = kSurfaceSlots;
    }
    return n;
}

/// Polygons against walls of any shape. Law: OverlapAreaLaw or PotentialLaw; kFriction: the tangential spring.
template <class Law, bool kFriction>
class PolygonSurfaceKernel {
public:
    PolygonSurfaceKernel(const ForceContext<2>& ctx, const std::vector<V2>& rotated)
        : ctx_(ctx), s_(ctx.surfaces), rotated_(rotated) {}

    /// Adds polygon i's contacts with walls of any shape to its force f and torque tq, and their depth A / |c| over
    /// its radius to worst; returns how many touch. With sink (the contact network's pass) also the contacts as the
    /// law computed them (the point: the force point).
    std::uint32_t add(std::size_t i, V2& f, Ang<2>& tq, double& worst, ContactSink<2>* sink = nullptr) const {
        SurfaceState<2>& s = *s_;
        const std::uint32_t base = s.slotOf[i];
        if (base == SurfaceState<2>::kNoSlots) return 0;
        Scratch<SurfaceOverlap, kMaxSurfaceOverlaps> found;
        const int nh = find(i, found.v);
        SurfaceContact<2>* slot = s.slots.data() + base;
        const int old = s.count[i];
        Scratch<SurfaceContact<2>, kSurfaceSlots> now;
        bool taken[kSurfaceSlots] = {};
        const double ri = ctx_.p.radius[i];
        const V2 xi = ctx_.p.x[i];
        const BodyState bi = bodyOf(i);
        for (int q = 0; q < nh; ++q) {
            const SurfaceOverlap& h = found[q];
            SurfaceContact<2>& c = now[q];
            c.wall = h.wall;
            c.normal = h.normal;
            // The same contact as in the last pass: the wall's contact with the nearest normal (as for disks).
            int match = -1;
            double best = 0.5;
            for (int o = 0; o < old; ++o) {
                if (taken[o] || slot[o].wall != h.wall) continue;
                const double d = dot(slot[o].normal, c.normal);
                if (d > best) {
                    best = d;
                    match = o;
                }
            }
            if (match >= 0) taken[match] = true;
            c.spring = match >= 0 ? slot[match].spring : V2::zero();
        }
        for (int q = 0; q < nh; ++q) {
            const SurfaceOverlap& h = found[q];
            SurfaceContact<2>& c = now[q];
            const ContactForce cf = law(i, h, bi, c.spring);
            f += cf.f;
            tq[0] += cf.torqueI;
            c.force = cf.f;
            c.point = xi + cf.point;
            const double clen = norm(h.o.chord);
            c.overlap = clen > 0 ? h.o.area / clen : ri;
            worst = std::max(worst, c.overlap / ri);
            if (sink) [[unlikely]] {
                ContactRecord<2> rec;
                placeWallRecord(rec, i, (*s.walls)[h.wall].id, xi, c.point, cf.normal, c.overlap);
                rec.fn = cf.normal * cf.fn;
                rec.ft = cf.ft;
                sink->push_back(rec);
            }
            slot[q] = c;
        }
        s.count[i] = static_cast<std::uint8_t>(nh);
        return static_cast<std::uint32_t>(nh);
    }

    /// The elastic energy of polygon i's contacts with walls of any shape at the current state [J]
    /// (polygonContactEnergy; the springs are not changed).
    double energy(std::size_t i) const {
        const SurfaceState<2>& s = *s_;
        if (s.slotOf[i] == SurfaceState<2>::kNoSlots) return 0;
        Scratch<SurfaceOverlap, kMaxSurfaceOverlaps> found;
        const int nh = find(i, found.v);
        const BodyState bi = bodyOf(i);
        const PairLengths len = wallLengths(ctx_.p.radius[i]);
        double e = 0;
        for (int q = 0; q < nh; ++q) {
            V2 spring = V2::zero();
            const ContactForce cf = law(i, found[q], bi, spring);
            e += polygonContactEnergy<Law>(coeffs(i, found[q].wall), found[q].o, cf, len);
        }
        return e;
    }

private:
    int find(std::size_t i, SurfaceOverlap* out) const {
        const Particles<2>& p = ctx_.p;
        const ShapeTable& st = p.shapes;
        const std::uint32_t si = p.shape[i];
        return polygonSurfaceOverlaps(*s_, rotated_.data() + st.first[si], st.count(si), st.area[si], p.x[i],
                                      s_->candidates.first[i], s_->candidates.first[i + 1], out);
    }

    BodyState bodyOf(std::size_t i) const {
        const Particles<2>& p = ctx_.p;
        BodyState b;  // x = 0: the frame is centred on the polygon
        b.v = p.v[i];
        b.w = p.w[i][0];
        b.vStep = ctx_.sv[i];
        b.wStep = ctx_.sw[i][0];
        b.invMass = p.invMass[i];
        b.invInertia = p.invInertia[i];
        return b;
    }

    const PolygonCoeffs& coeffs(std::size_t i, std::uint32_t w) const {
        return ctx_.cs.polygonPair(ctx_.p.material[i], (*s_->walls)[w].material);
    }

    /// The law for one contact: the wall a body of infinite mass whose material points move with its pose
    /// (velocity at the centre of rotation, spin about it), so that the relative velocity at the force point and dA/dt
    /// see the wall's surface velocity there (H.1).
    ContactForce law(std::size_t i, const SurfaceOverlap& h, const BodyState& bi, V2& spring) const {
        const Pose<2>& pose = s_->poses[h.wall];
        BodyState bw;
        bw.x = pose.centre - ctx_.p.x[i];
        bw.v = pose.velocity;
        bw.w = pose.spin[0];
        bw.vStep = bw.v;
        bw.wStep = bw.w;
        return polygonContact<Law, kFriction>(coeffs(i, h.wall), h.o, bi, bw, &h.normal, wallLengths(ctx_.p.radius[i]),
                                              ctx_.cs.attraction, ctx_.dt, spring);
    }

    const ForceContext<2>& ctx_;
    SurfaceState<2>* s_;
    const std::vector<V2>& rotated_;
};

}  // namespace haet::polygon
