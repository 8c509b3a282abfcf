#pragma once
// The contact kernels of 2D scenes holding polygons (alone or mixed with disks) for the pair pass
// (tdm/pair_pass.hpp), which TdmEngine<2> runs through ShapePass (tdm/shape_pass.hpp, polygon/shape_pass.cpp) when
// the particle store has shapes. The disk kernel stays free of shape branches.
//
// Per pair (from the same pair list; the bounding circles are the particles' radii, so the cell grid is the broad
// phase): two disks use the disk law (evalPair of tdm/disk_kernel.hpp); a polygon pair is screened by the inscribed
// circles and the line of centres, then overlapped (convexOverlap: directly when the outlines cross twice, else by
// clipping); a polygon and a disk use the exact circle-polygon overlap. All overlaps go through polygonContact
// (polygon/contact.hpp), whose law (overlap area or potential) is a template parameter. Walls: half-plane overlap
// for polygons against planes, the overlap with the solid behind each element against walls of any shape
// (surface_kernel.hpp); the disk wall kernels for disks. The pairs go one by one (kOneByOne): a polygon pair's work
// varies too much for lanes.
#include <cmath>
#include <cstdint>
#include <vector>

#include "contact/setup.hpp"
#include "polygon/contact.hpp"
#include "polygon/geometry.hpp"
#include "polygon/surface_kernel.hpp"
#include "tdm/disk_kernel.hpp"
#include "tdm/pair_pass.hpp"
#include "tdm/wall_kernel.hpp"

namespace haet::polygon {

/// What one touching pair adds: force on i (on j: -f), torques on i and j, r_ij . F_ij, overlap / smaller radius.
struct PolygonEntry {
    V2 f{};
    double ti = 0, tj = 0;
    double vir = 0, ovl = 0;
    double virial() const { return vir; }
    double overlap() const { return ovl; }
};

/// Work arrays of the polygon kernels, kept between steps so that no step allocates.
struct PolygonScratch {
    std::vector<V2> rotated;       ///< vertices of every shape turned by its particle's angle (body -> world
                                   ///< without the translation) [m]
    std::vector<double> inradius;  ///< per shape: distance from the centroid to the nearest edge line [m]
    PairPassScratch<2, PolygonEntry> pass;
};

/// Particle i as a body of the contact law (BodyState::x left at zero: the caller sets the frame).
inline BodyState bodyOf(const Particles<2>& p, const V2* sv, const Ang<2>* sw, std::size_t i) {
    BodyState b;
    b.v = p.v[i];
    b.w = p.w[i][0];
    b.vStep = sv[i];
    b.wStep = sw[i][0];
    b.invMass = p.invMass[i];
    b.invInertia = p.invInertia[i];
    return b;
}

/// Turns every polygon's body-frame vertices by its current angle.
/// Also keeps the inradius of every shape (shapes are only ever added).
inline void rotateShapes(const Particles<2>& p, PolygonScratch& ps) {
    const ShapeTable& st = p.shapes;
    ps.rotated.resize(st.vertices.size());
    for (std::size_t s = ps.inradius.size(); s < st.size(); ++s)
        ps.inradius.push_back(inradius(st.of(std::uint32_t(s)), st.count(std::uint32_t(s))));
    const std::size_t n = p.tdmCount();
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t s = p.shape[i];
        if (s == kNoShape) continue;
        const double a = p.angle[i][0], c = std::cos(a), sn = std::sin(a);
        for (std::uint32_t k = st.first[s]; k < st.first[s + 1]; ++k) ps.rotated[k] = rotate(st.vertices[k], c, sn);
    }
}

/// Overlap of a polygon and a disk, i and j at x_j + d and x_j (one of them a polygon). Frame: origin at x_j.
/// Out of line: it keeps the vertex buffers out of the polygon pairs' stack frame.
[[gnu::noinline]] inline Overlap polygonDiskOverlap(const Particles<2>& p, const PolygonScratch& ps, std::size_t i,
                                                    std::uint32_t j, const V2& d) {
    const ShapeTable& st = p.shapes;
    const std::uint32_t si = p.shape[i], sj = p.shape[j];
    VertexBuffer<kMaxVertices> P, Q;
    if (si != kNoShape) {  // polygon i, disk j: the circle at the origin
        const int np = st.count(si);
        const V2* a = ps.rotated.data() + st.first[si];
        for (int m = 0; m < np; ++m) P[m] = a[m] + d;
        return circlePolygonOverlap(p.radius[j], P.data(), np);
    }
    // disk i, polygon j: overlap about x_i, then back to the frame of x_j, outline pieces of i
    const int nq = st.count(sj);
    const V2* b = ps.rotated.data() + st.first[sj];
    for (int m = 0; m < nq; ++m) Q[m] = b[m] - d;
    Overlap o = circlePolygonOverlap(p.radius[i], Q.data(), nq);
    o.centroid += d;
    o.chord = -o.chord;  // the circle's arcs inside j: minus j's outline inside the circle
    o.spin = -o.spin;
    return o;
}

/// What a polygon pair reads, taken once per pass.
struct PolygonViews {
    const Particles<2>& p;
    const PairList<2>& pl;
    const ContactSetup& cs;
    const PolygonScratch& ps;
    const V2* sv;
    const Ang<2>* sw;
    double dt;
};

/// Evaluates pair slot k of particle i and partner j (at least one of the two a polygon) with the pair's spring
/// hist: whether it touches, and its entry (kEnergy: its elastic energy instead, hist a copy) when it does. Frame:
/// origin at x_j. Inlined into the pass: a call per pair cost as much as the rejection of a pair that does not touch.
/// With rec (the contact network's pass) also the contact as the law computed it.
template <class Law, bool kFriction, bool kEnergy = false>
[[gnu::always_inline]] inline bool evalPolygonPair(const PolygonViews& in, std::size_t i, std::uint32_t k,
                                                   std::uint32_t j, V2& hist, PolygonEntry& out, double& energy,
                                                   ContactRecord<2>* rec = nullptr) {
    const Particles<2>& p = in.p;
    const PairList<2>& pl = in.pl;
    const ContactSetup& cs = in.cs;
    const PolygonScratch& ps = in.ps;
    const V2 d = p.x[i] - p.x[j] + pl.shiftVec[pl.shift[k]];
    const double ri = p.radius[i], rj = p.radius[j];
    const double dist2 = norm2(d);
    if (dist2 >= (ri + rj) * (ri + rj)) {
        if (!(hist == V2::zero())) hist = V2::zero();
        return false;
    }
    const std::uint32_t si = p.shape[i], sj = p.shape[j];
    const ShapeTable& st = p.shapes;
    Overlap o;
    if (si != kNoShape && sj != kNoShape) {
        const int np = st.count(si), nq = st.count(sj);
        const V2* a = ps.rotated.data() + st.first[si];
        const V2* b = ps.rotated.data() + st.first[sj];
        // Broad phase passed (bounding circles). Inscribed circles that overlap mean overlapping polygons (most
        // touching pairs of a packing); otherwise the line of centres separates most remaining pairs cheaply (P's
        // projections on d are a's shifted by |d|^2); the overlap finds that the others do not overlap (the full
        // separating-axis test, polygon::separated, would cost about as much as the clipping).
        const double rin = ps.inradius[si] + ps.inradius[sj];
        if (dist2 >= rin * rin && dist2 > 0 && separatedAlong(d, dist2, a, np, b, nq)) {
            if (!(hist == V2::zero())) hist = V2::zero();
            return false;
        }
        o = convexOverlap(a, np, b, nq, d, ri, d);
    } else {
        o = polygonDiskOverlap(p, ps, i, j, d);
    }
    if (!(o.area > 0)) {
        if (!(hist == V2::zero())) hist = V2::zero();
        return false;
    }
    BodyState bi = bodyOf(p, in.sv, in.sw, i);
    bi.x = d;
    const BodyState bj = bodyOf(p, in.sv, in.sw, j);
    const PolygonCoeffs& c = cs.polygonPair(p.material[i], p.material[j]);
    const double rmin = std::min(ri, rj);
    const PairLengths len = pairLengths(ri, rj);
    const ContactForce cf = polygonContact<Law, kFriction>(c, o, bi, bj, nullptr, len, cs.attraction, in.dt, hist);
    if constexpr (kEnergy) {
        energy = polygonContactEnergy<Law>(c, o, cf, len);  // geometry only: the velocities do not enter
        return true;
    }
    out.f = cf.f;
    out.ti = cf.torqueI;
    out.tj = cf.torqueJ;
    out.vir = dot(d, cf.f);
    // Depth of the overlap, area / chord, relative to the smaller bounding radius (1 when the chord vanishes).
    const double clen = norm(o.chord);
    out.ovl = clen > 0 ? o.area / clen / rmin : 1.0;
    if (rec) [[unlikely]] {
        rec->i = static_cast<std::uint32_t>(i);
        rec->j = j;
        rec->wall = -1;
        rec->normal = cf.normal;
        rec->fn = cf.normal * cf.fn;
        rec->ft = cf.ft;
        rec->branch = d;
        rec->position = p.x[i];
        rec->point = p.x[i] - d + cf.point;  // the force point, from the frame of x_j's image by the pair's shift
        rec->overlap = clen > 0 ? o.area / clen : rmin;
    }
    return true;
}

/// A particle against a plane wall: a polygon by its half-plane overlap (polygonContact with the wall's normal), a
/// disk by the disk wall kernel.
template <class Normal, class Tangential, class Law>
class ShapeWall {
public:
    ShapeWall(const ForceContext<2>& ctx, const PolygonScratch& ps)
        : ctx_(ctx),
          ps_(ps),
          disk_(ctx),
          walls_(ctx.walls),
          nw_(ctx.nWalls),
          history_(ctx.wallHistory),
          x_(ctx.p.x.data()),
          radius_(ctx.p.radius.data()),
          shape_(ctx.p.shape.data()),
          surfaces_(ctx, ps.rotated) {}

    /// With rec (the contact network's pass) also the contact as the law computed it.
    [[gnu::always_inline]] bool add(std::size_t i, std::size_t w, V2& f, Ang<2>& tq, double& worst,
                                    ContactRecord<2>* rec = nullptr) const {
        if (shape_[i] == kNoShape) return disk_.add(i, w, f, tq, worst, rec);
        // Most walls are beyond the bounding circle: that test first, the overlap out of line.
        const double dist = walls_[w].distanceNow(x_[i]);
        V2& hist = history_[i * nw_ + w];
        if (ctx_.planeForce) ctx_.planeForce[i * nw_ + w] = V2::zero();
        if (dist >= radius_[i]) {
            if (!(hist == V2::zero())) hist = V2::zero();
            return false;
        }
        double energy;
        return contact<false>(i, w, dist, hist, f, tq, worst, energy, rec);
    }

    /// Walls of any shape: a disk by the disk kernel (tdm/surface_kernel.hpp), a polygon by its overlap with the solid
    /// behind each element (surface_kernel.hpp).
    [[gnu::always_inline]] std::uint32_t addSurfaces(std::size_t i, V2& f, Ang<2>& tq, double& worst,
                                                     ContactSink<2>* sink = nullptr) const {
        return shape_[i] == kNoShape ? disk_.addSurfaces(i, f, tq, worst, sink) : surfaces_.add(i, f, tq, worst, sink);
    }
    double surfaceEnergy(std::size_t i) const {
        return shape_[i] == kNoShape ? disk_.surfaceEnergy(i) : surfaces_.energy(i);
    }

    /// The energy of wall w's contact with particle i at the current state [J]: a disk's by its law, a polygon's
    /// from its overlap (the spring copied, not changed).
    double energy(std::size_t i, std::size_t w) const {
        if (shape_[i] == kNoShape) return disk_.energy(i, w);
        if (ctx_.p.flags[i] & kFrozen) return 0.0;  // never in contact
        V2 hist = history_[i * nw_ + w], f = V2::zero();
        Ang<2> tq = Ang<2>::zero();
        double worst = 0, energy = 0;
        const double dist = walls_[w].distanceNow(x_[i]);
        if (dist >= radius_[i]) return 0.0;
        return contact<true>(i, w, dist, hist, f, tq, worst, energy) ? energy : 0.0;
    }

private:
    /// The contact of a polygon i within its bounding radius of wall w (at distance dist).
    template <bool kEnergy>
    [[gnu::noinline]] bool contact(std::size_t i, std::size_t w, double dist, V2& hist, V2& f, Ang<2>& tq,
                                   double& worst, double& energy, ContactRecord<2>* rec = nullptr) const {
        const Wall<2>& wall = walls_[w];
        const double ri = radius_[i];
        // Frame: origin at x_i.
        const ShapeTable& st = ctx_.p.shapes;
        const std::uint32_t si = shape_[i];
        const Overlap o =
            halfPlaneOverlap(ps_.rotated.data() + st.first[si], st.count(si), wall.normal * (-dist), wall.normal);
        if (!(o.area > 0)) {
            if (!(hist == V2::zero())) hist = V2::zero();
            return false;
        }
        const BodyState bi = bodyOf(ctx_.p, ctx_.sv, ctx_.sw, i);
        BodyState bw;
        bw.v = wall.velocityNow;
        bw.vStep = wall.velocityNow;
        const PolygonCoeffs& pc = ctx_.cs.polygonPair(ctx_.p.material[i], wall.material);
        const PairLengths len = wallLengths(ri);
        const ContactForce cf = polygonContact<Law, Tangential::kHasHistory>(pc, o, bi, bw, &wall.normal, len,
                                                                             ctx_.cs.attraction, ctx_.dt, hist);
        if constexpr (kEnergy) {
            energy = polygonContactEnergy<Law>(pc, o, cf, len);
            return true;
        }
        f += cf.f;
        tq[0] += cf.torqueI;
        if (ctx_.planeForce) ctx_.planeForce[i * nw_ + w] = cf.f;
        const double clen = norm(o.chord);
        worst = std::max(worst, clen > 0 ? o.area / clen / ri : 1.0);
        if (rec) [[unlikely]] {
            // The force point projected onto the wall: the branch ends on its surface, as a disk's does.
            const V2 at = x_[i] + cf.point;
            placeWallRecord(*rec, i, wall.id, x_[i], at - wall.normal * wall.distanceNow(at), wall.normal,
                            clen > 0 ? o.area / clen : ri);
            rec->fn = cf.normal * cf.fn;
            rec->ft = cf.ft;
        }
        return true;
    }

    const ForceContext<2>& ctx_;
    const PolygonScratch& ps_;
    DiskWall<2, Normal, Tangential> disk_;
    const Wall<2>* walls_;
    std::size_t nw_;
    V2* history_;
    const V2* x_;
    const double* radius_;
    const std::uint32_t* shape_;
    PolygonSurfaceKernel<Law, Tangential::kHasHistory> surfaces_;
};

/// The kernel of the pair pass for scenes with polygons (tdm/pair_pass.hpp has the interface). Normal, Tangential:
/// the disk laws (pairs of two disks, and the friction of polygon contacts: TangentialLaw::Spring); Law: the
/// polygon law (OverlapAreaLaw, PotentialLaw). Energies are those of the
/// contacts' overlaps at the current state (energy()).
template <class Normal, class Tangential, class Law>
class PolygonKernel {
public:
    static constexpr bool kOneByOne = true;  ///< each pair added as it is evaluated (no lanes: its work varies)
    using Entry = PolygonEntry;
    struct Sum {
        V2 f;
        Ang<2> t;  ///< the torque
    };
    struct Load {
        V2 f;
        double ti, tj;
    };

    PolygonKernel(const ForceContext<2>& ctx, const PolygonScratch& ps)
        : ctx_(ctx),
          ps_(ps),
          in_(pairInputs(ctx.p, ctx.pl, ctx.cs, ctx.sv, ctx.sw, ctx.dt)),
          shape_(ctx.p.shape.data()),
          views_{ctx.p, ctx.pl, ctx.cs, ps, ctx.sv, ctx.sw, ctx.dt},
          walls_(ctx, ps) {}

    [[gnu::always_inline]] static Load load(const Entry& x) { return {x.f, x.ti, x.tj}; }
    [[gnu::always_inline]] static Sum sumOf(const V2& f, const Ang<2>& t) { return {f, t}; }
    [[gnu::always_inline]] static void addOwner(Sum& s, const Load& l) {
        s.f += l.f;
        s.t[0] += l.ti;
    }
    [[gnu::always_inline]] static void addPartner(V2& f, Ang<2>& t, const Load& l) {
        f -= l.f;
        t[0] += l.tj;
    }
    [[gnu::always_inline]] static V2 forceOf(const Sum& s) { return s.f; }
    [[gnu::always_inline]] Ang<2> torqueOf(std::size_t, const Sum& s) const { return s.t; }
    const ShapeWall<Normal, Tangential, Law>& walls() const { return walls_; }

    /// One listed pair (partner j), whichever its kind.
    [[gnu::always_inline]] bool pair(std::size_t i, std::uint32_t k, std::uint32_t j, Entry& e) const {
        if (shape_[i] == kNoShape && shape_[j] == kNoShape) {
            PairForce<2> pf;
            double overlap = 0, vir = 0;
            if (!evalPair<2, Normal, Tangential>(in_, Owner<2>(in_, i), k, pf, overlap, vir)) return false;
            e.f = pf.f;
            e.ti = -in_.radius[i] * pf.nxft[0];
            e.tj = -in_.radius[j] * pf.nxft[0];
            e.vir = vir;
            e.ovl = overlap;
            return true;
        }
        double energy;
        return evalPolygonPair<Law, Tangential::kHasHistory>(views_, i, k, j, in_.history[k], e, energy);
    }

    /// One listed pair as pair() evaluates it (the same bits), with the law's parts into rec (the contact network).
    bool record(std::size_t i, std::uint32_t k, std::uint32_t j, Entry& e, ContactRecord<2>& rec) const {
        if (shape_[i] == kNoShape && shape_[j] == kNoShape) {
            PairForce<2> pf;
            LawParts<2> parts;
            double overlap = 0, vir = 0;
            if (!evalPair<2, Normal, Tangential>(in_, Owner<2>(in_, i), k, pf, overlap, vir, &parts)) return false;
            e.f = pf.f;
            e.ti = -in_.radius[i] * pf.nxft[0];
            e.tj = -in_.radius[j] * pf.nxft[0];
            e.vir = vir;
            e.ovl = overlap;
            pairRecord(in_, i, j, parts, rec);
            return true;
        }
        double energy;
        return evalPolygonPair<Law, Tangential::kHasHistory>(views_, i, k, j, in_.history[k], e, energy, &rec);
    }

    /// The energy of listed pair k at the current state [J]: two disks' by their law, a polygon contact's from its
    /// overlap (the spring copied, not changed).
    double energy(std::size_t i, std::uint32_t k) const {
        if (shape_[i] == kNoShape && shape_[in_.partner[k]] == kNoShape) return diskPairEnergy<2, Normal>(ctx_, i, k);
        V2 hist = in_.history[k];
        Entry e;
        double energy = 0;
        return evalPolygonPair<Law, Tangential::kHasHistory, true>(views_, i, k, in_.partner[k], hist, e, energy)
                   ? energy
                   : 0.0;
    }

private:
    const ForceContext<2>& ctx_;
    const PolygonScratch& ps_;
    PairInputs<2> in_;
    const std::uint32_t* shape_;
    PolygonViews views_;  ///< what a polygon pair reads (not reloaded through the context)
    ShapeWall<Normal, Tangential, Law> walls_;
};

}  // namespace haet::polygon
