#pragma once
// The force loop of 2D scenes holding polygons (alone or mixed with disks): the variant of tdm/forces.hpp that
// TdmEngine<2> runs when the particle store has shapes. The disk loop stays free of shape branches.
//
// Per pair (from the same pair list; the bounding circles are the particles' radii, so the cell grid is the
// broad phase): two disks use the disk law (evalPair of tdm/forces.hpp); a polygon pair is screened by the
// inscribed circles and the line of centres, then overlapped (convexOverlap: directly when the outlines cross
// twice, else by clipping); a polygon and a disk use the exact circle-polygon overlap. All overlaps
// go through polygonContact (polygon/contact.hpp). Walls: half-plane overlap for polygons, the disk law for disks.
//
// Summation order, hence thread-count independence, is that of tdm/forces.hpp: gravity, the pairs in which the
// particle is the partner (increasing pair index), its own pairs, its walls. So is the pass: one thread runs once
// over the particles, each finished (walls, statistics) right after its own pairs; T threads evaluate the cross
// pairs of PairList::split first, then run that pass over their ranges.
#include <omp.h>

#include <cmath>
#include <vector>

#include "contact/setup.hpp"
#include "polygon/contact.hpp"
#include "polygon/geometry.hpp"
#include "tdm/forces.hpp"

namespace haet::polygon {

/// Result of one pair: force on i, torques on i and j.
struct PairResult {
    V2 f{};
    double ti = 0, tj = 0;
    double energy = 0;
};

/// A pair evaluated before the ranges run (threaded path): a cross pair of PairList::split.
struct PolygonCrossPair {
    PairResult r;
    double virial = 0;   ///< r_ij . F_ij [N m]
    double overlap = 0;  ///< overlap / smaller radius
    bool touching = false;
};

/// Work arrays of the polygon loop, kept between steps so that no step allocates.
struct PolygonScratch {
    std::vector<V2> rotated;              ///< vertices of every shape turned by its particle's angle (body -> world
                                          ///< without the translation) [m]
    std::vector<double> inradius;         ///< per shape: distance from the centroid to the nearest edge line [m]
    std::vector<double> pairEnergy;       ///< estimated elastic energy of each pair [J] (contactEnergy)
    std::vector<double> wallEnergy;       ///< per particle: estimated elastic energy of its wall contacts [J]
    V2 gravity{};                         ///< [m/s^2]
    std::vector<PolygonCrossPair> cross;  ///< threaded path: the cross pairs (PairList::split)
    std::vector<double> virial;           ///< threaded path, per particle: sum over own pairs of r_ij . F_ij [N m]
    std::vector<RangeTally> tally;        ///< threaded path: per-range statistics
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

/// Evaluates pair slot k of particle i (at least one of the two a polygon). Frame: origin at x_j.
/// Inlined into the pass: a call per pair cost as much as the rejection of a pair that does not touch.
[[gnu::always_inline]] inline bool evalPolygonPair(const Particles<2>& p, PairList<2>& pl, const ContactSetup& cs,
                                                   const PolygonScratch& ps, const V2* sv, const Ang<2>* sw, double dt,
                                                   std::size_t i, std::uint32_t k, PairResult& out,
                                                   double& overlapRatio, double& virial) {
    const std::uint32_t j = pl.partner[k];
    const V2 d = p.x[i] - p.x[j] + pl.shiftVec[pl.shift[k]];
    const double ri = p.radius[i], rj = p.radius[j];
    V2& hist = pl.history[k];
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
    BodyState bi = bodyOf(p, sv, sw, i);
    bi.x = d;
    const BodyState bj = bodyOf(p, sv, sw, j);
    const PolygonCoeffs& c = cs.polygonPair(p.material[i], p.material[j]);
    const double rmin = std::min(ri, rj);
    const PairLengths len = pairLengths(ri, rj);
    const ContactForce cf =
        polygonContact(c, o, bi, bj, nullptr, len, cs.attraction, cs.tangential == TangentialLaw::Spring, dt, hist);
    out.f = cf.f;
    out.ti = cf.torqueI;
    out.tj = cf.torqueJ;
    out.energy = polygonContactEnergy(c, o, cf, len);
    virial += dot(d, cf.f);
    // Depth of the overlap, area / chord, relative to the smaller bounding radius (1 when the chord vanishes).
    const double clen = norm(o.chord);
    overlapRatio = std::max(overlapRatio, clen > 0 ? o.area / clen / rmin : 1.0);
    return true;
}

/// The pass over particles [b, e) of tdm/forces.hpp (forceRange), for scenes with polygons: a particle's sums start
/// (gravity, then the cross pairs where it is the partner) just before the first pair that adds to them, its own
/// pairs scatter to both particles, and right after them it is finished (walls, torque, statistics). kCross: the
/// pairs whose partner is >= e were evaluated before into cross[c0...] in pair order; crossIn: the cross pairs
/// whose partner is in [b, e), by partner then pair.
template <class Normal, class Tangential, bool kCross, class Pair>
RangeTally polygonRange(Particles<2>& p, const PairList<2>& pl, const std::vector<Wall<2>>& walls,
                        std::vector<V2>& wallHistory, const ContactSetup& cs, double time, double dt, const V2* sv,
                        const Ang<2>* sw, PolygonScratch& ps, std::size_t b, std::size_t e,
                        const PolygonCrossPair* crossPairs, std::size_t c0, const std::uint64_t* crossIn,
                        const std::uint64_t* crossInEnd, double* virial, double* virialSum, Pair& pair) {
    V2* f = p.f.data();
    Ang<2>* tq = p.torque.data();  // holds the pair torques until the particle is finished
    const double* mass = p.mass.data();
    const V2 g = ps.gravity;
    double* pairEnergy = ps.pairEnergy.data();
    std::size_t done = b;
    const std::uint64_t* q = crossIn;
    auto startUpTo = [&](std::size_t end) {
        for (; done < end; ++done) {
            f[done] = g * mass[done];
            tq[done][0] = 0;
            if constexpr (kCross) {
                for (; q != crossInEnd && (*q >> 32) == done; ++q) {
                    const PolygonCrossPair& c = crossPairs[*q & 0xFFFFFFFFu];
                    if (!c.touching) continue;
                    f[done] -= c.r.f;
                    tq[done][0] += c.r.tj;
                }
            }
        }
    };
    const std::size_t nw = walls.size();
    const bool clip = !cs.attraction;
    const ShapeTable& st = p.shapes;
    RangeTally out;
    std::size_t c = c0;
    for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t k0 = pl.first[i], k1 = pl.first[i + 1];
        std::size_t reach = k1 > k0 ? std::size_t{pl.partner[k1 - 1]} + 1 : i + 1;
        if constexpr (kCross) reach = std::min(reach, e);
        startUpTo(std::max(reach, i + 1));
        V2 fi = f[i];
        double ti = tq[i][0];
        double worst = 0, vir = 0;
        std::uint32_t nc = 0;
        for (std::uint32_t k = k0; k < k1; ++k) {
            const std::uint32_t j = pl.partner[k];
            if constexpr (kCross) {
                if (j >= e) {
                    const PolygonCrossPair& x = crossPairs[c++];
                    if (!x.touching) continue;
                    fi += x.r.f;
                    ti += x.r.ti;
                    vir += x.virial;
                    worst = std::max(worst, x.overlap);
                    ++nc;
                    continue;
                }
            }
            PairResult r;
            if (!pair(i, k, r, worst, vir)) {
                pairEnergy[k] = 0;
                continue;
            }
            fi += r.f;
            ti += r.ti;
            f[j] -= r.f;
            tq[j][0] += r.tj;
            pairEnergy[k] = r.energy;
            ++nc;
        }

        // Walls, in wall order.
        double wallEnergy = 0;
        if (nw > 0 && !(p.flags[i] & kFrozen)) {
            const double ri = p.radius[i];
            const std::uint32_t si = p.shape[i];
            for (std::size_t w = 0; w < nw; ++w) {
                const Wall<2>& wall = walls[w];
                V2& hist = wallHistory[i * nw + w];
                const double dist = wall.distance(p.x[i], time);
                if (dist >= ri) {
                    if (!(hist == V2::zero())) hist = V2::zero();
                    continue;
                }
                const V2& nrm = wall.normal;
                if (si != kNoShape) {
                    // Frame: origin at x_i.
                    const int nv = st.count(si);
                    const V2* rv = ps.rotated.data() + st.first[si];
                    const Overlap o = halfPlaneOverlap(rv, nv, nrm * (-dist), nrm);
                    if (!(o.area > 0)) {
                        if (!(hist == V2::zero())) hist = V2::zero();
                        continue;
                    }
                    const BodyState bi = bodyOf(p, sv, sw, i);
                    BodyState bw;
                    bw.v = wall.velocity;
                    bw.vStep = wall.velocity;
                    const PolygonCoeffs& pc = cs.polygonPair(p.material[i], wall.material);
                    const PairLengths len = wallLengths(ri);
                    const ContactForce cf = polygonContact(pc, o, bi, bw, &nrm, len, cs.attraction,
                                                           cs.tangential == TangentialLaw::Spring, dt, hist);
                    fi += cf.f;
                    ti += cf.torqueI;
                    wallEnergy += polygonContactEnergy(pc, o, cf, len);
                    const double clen = norm(o.chord);
                    worst = std::max(worst, clen > 0 ? o.area / clen / ri : 1.0);
                    ++nc;
                    continue;
                }
                const double delta = ri - dist;
                const double meff = p.mass[i];
                const V2 dv = p.v[i] - wall.velocity;
                const double gn = dot(dv, nrm);
                const PairCoeffs& pc = cs.pair(p.material[i], wall.material);
                NormalResult nr = Normal::eval(pc, delta, -gn, meff, ri);
                if (clip && nr.fn < 0) nr.fn = 0;
                fi += nrm * nr.fn;
                if constexpr (Tangential::kHasHistory) {
                    const V2 gg = dv - cross(p.w[i] * ri, nrm);
                    const V2 gt = gg - nrm * dot(gg, nrm);
                    const V2 gs = sv[i] - wall.velocity - cross(sw[i] * ri, nrm);
                    const V2 gst = gs - nrm * dot(gs, nrm);
                    const V2 ft = Tangential::eval(pc, nr.fn, nr.k, meff, nrm, gt, gst, hist, dt);
                    fi += ft;
                    ti += cross(nrm, ft)[0] * (-ri);
                }
                worst = std::max(worst, delta / ri);
                ++nc;
            }
        }
        f[i] = fi;
        tq[i][0] = ti;
        ps.wallEnergy[i] = wallEnergy;
        out.contacts += nc;
        if constexpr (kCross)
            virial[i] = vir;
        else
            *virialSum += vir;
        if (worst > out.maxOverlapRatio) {
            out.maxOverlapRatio = worst;
            out.worstParticle = i;
        }
        double sum = 0;  // a NaN anywhere reaches the force of its particle in the same step
        for (int k = 0; k < 2; ++k) sum += fi[k] + p.x[i][k];
        if (!std::isfinite(sum) && out.nonFinite == ForceStats::kNone) out.nonFinite = i;
    }
    return out;
}

/// Forces and torques of a 2D scene with polygons, at the predicted state (see tdm/forces.hpp for sv, sw).
/// One thread: one pass over the particles (polygonRange). T threads: the ranges of PairList::split, as in
/// tdm/forces.hpp; every particle sums its contributions in the same order either way.
template <class Normal, class Tangential>
ForceStats computePolygonForces(Particles<2>& p, PairList<2>& pl, const std::vector<Wall<2>>& walls,
                                std::vector<V2>& wallHistory, const ContactSetup& cs, const Domain<2>& dom, double time,
                                double dt, const V2* sv, const Ang<2>* sw, PolygonScratch& ps) {
    const std::size_t n = p.tdmCount();
    rotateShapes(p, ps);
    ps.pairEnergy.resize(pl.size());  // both written for every pair and particle below
    ps.wallEnergy.resize(n);
    ps.gravity = dom.gravity;
    const int nt = n >= kParallelMin ? omp_get_max_threads() : 1;

    // One pair, whichever its kind: force on i and the torques on i and j.
    const PairInputs<2> in = pairInputs(p, pl, cs, sv, sw, dt);
    // Inlined into each pass (GCC leaves a lambda used in three places out of line: 3 % more instructions).
    auto pair = [&](std::size_t i, std::uint32_t k, PairResult & r, double& worst, double& vir)
        __attribute__((always_inline)) {
        const std::uint32_t j = pl.partner[k];
        if (p.shape[i] == kNoShape && p.shape[j] == kNoShape) {
            PairForce<2> pf;
            if (!evalPair<2, Normal, Tangential>(in, Owner<2>(in, i), k, pf, worst, vir)) return false;
            r.f = pf.f;
            r.ti = -p.radius[i] * pf.nxft[0];
            r.tj = -p.radius[j] * pf.nxft[0];
            r.energy = 0;  // disk pairs: TdmEngine::contactEnergy adds them from the overlaps
            return true;
        }
        return evalPolygonPair(p, pl, cs, ps, sv, sw, dt, i, k, r, worst, vir);
    };

    ForceStats st;
    if (nt <= 1) {
        const RangeTally t =
            polygonRange<Normal, Tangential, false>(p, pl, walls, wallHistory, cs, time, dt, sv, sw, ps, 0, n, nullptr,
                                                    0, nullptr, nullptr, nullptr, &st.virial, pair);
        addTally(st, t);
        return st;
    }

    if (pl.split.ranges() != static_cast<std::size_t>(nt)) buildThreadSplit(pl, nt);
    const ThreadSplit& sp = pl.split;
    const std::size_t ncross = sp.crossSlot.size();
    ps.cross.resize(ncross);
    ps.virial.resize(n);
    ps.tally.assign(static_cast<std::size_t>(nt), RangeTally{});
    PolygonCrossPair* cross = ps.cross.data();
#pragma omp parallel num_threads(nt)
    {
        // The cross pairs first: every particle is still unfinished.
#pragma omp for schedule(static)
        for (std::size_t c = 0; c < ncross; ++c) {
            PolygonCrossPair& x = cross[c];
            const std::uint32_t k = sp.crossSlot[c];
            x.overlap = 0;
            x.virial = 0;
            x.touching = pair(sp.crossOwner[c], k, x.r, x.overlap, x.virial);
            ps.pairEnergy[k] = x.touching ? x.r.energy : 0.0;
        }
#pragma omp for schedule(static, 1)
        for (int r = 0; r < nt; ++r) {
            const std::uint64_t* ci = sp.crossIn.data();
            ps.tally[r] = polygonRange<Normal, Tangential, true>(p, pl, walls, wallHistory, cs, time, dt, sv, sw, ps,
                                                                 sp.start[r], sp.start[r + 1], cross, sp.crossFirst[r],
                                                                 ci + sp.crossInFirst[r], ci + sp.crossInFirst[r + 1],
                                                                 ps.virial.data(), nullptr, pair);
        }
    }
    // The one-thread reductions, in the same order.
    for (const RangeTally& t : ps.tally) addTally(st, t);
    for (std::size_t i = 0; i < n; ++i) st.virial += ps.virial[i];
    return st;
}

}  // namespace haet::polygon
