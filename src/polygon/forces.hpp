#pragma once
// The force loop of 2D scenes holding polygons (alone or mixed with disks): the variant of tdm/forces.hpp that
// TdmEngine<2> runs when the particle store has shapes. The disk loop stays free of shape branches.
//
// Per pair (from the same pair list; the bounding circles are the particles' radii, so the cell grid is the
// broad phase): two disks use the disk law (evalPair of tdm/forces.hpp); a polygon pair is screened by the
// separating-axis test and then clipped; a polygon and a disk use the exact circle-polygon overlap. All overlaps
// go through polygonContact (polygon/contact.hpp). Walls: half-plane overlap for polygons, the disk law for disks.
//
// Summation order, hence thread-count independence, is that of tdm/forces.hpp: gravity, the pairs in which the
// particle is the partner (increasing pair index), its own pairs, its walls.
#include <cmath>
#include <vector>

#include <omp.h>

#include "contact/setup.hpp"
#include "polygon/contact.hpp"
#include "polygon/geometry.hpp"
#include "tdm/forces.hpp"

namespace haet::polygon {

/// Per-step work arrays of the polygon loop.
struct PolygonScratch {
    std::vector<V2> rotated;        ///< vertices of every shape turned by its particle's angle (body -> world
                                    ///< without the translation) [m]
    std::vector<double> torqueI;    ///< threaded path: torque on i of each pair [N m]
    std::vector<double> torqueJ;    ///< threaded path: torque on j of each pair [N m]
    std::vector<double> pairEnergy; ///< estimated elastic energy of each pair [J] (contactEnergy)
    std::vector<double> wallEnergy; ///< per particle: estimated elastic energy of its wall contacts [J]
    std::vector<double> torque;     ///< per particle: pair torques [N m]
    std::vector<double> inradius;   ///< per shape: distance from the centroid to the nearest edge line [m]
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

/// Result of one pair: force on i, torques on i and j.
struct PairResult {
    V2 f{};
    double ti = 0, tj = 0;
    double energy = 0;
};

/// Evaluates pair slot k of particle i (at least one of the two a polygon). Frame: origin at x_j.
inline bool evalPolygonPair(const Particles<2>& p, PairList<2>& pl, const ContactSetup& cs, const PolygonScratch& ps,
                            const V2* sv, const Ang<2>* sw, double dt, std::size_t i, std::uint32_t k,
                            PairResult& out, double& overlapRatio, double& virial) {
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
    VertexBuffer<kMaxVertices> P, Q;
    if (si != kNoShape && sj != kNoShape) {
        const int np = st.count(si), nq = st.count(sj);
        const V2* a = ps.rotated.data() + st.first[si];
        const V2* b = ps.rotated.data() + st.first[sj];
        // Broad phase passed (bounding circles). Inscribed circles that overlap mean overlapping polygons (most
        // touching pairs of a packing); otherwise the line of centres separates most remaining pairs cheaply (P's
        // projections on d are a's shifted by |d|^2); the clipping finds that the others do not overlap (the full
        // separating-axis test, polygon::separated, would cost about as much as the clipping).
        const double rin = ps.inradius[si] + ps.inradius[sj];
        if (dist2 >= rin * rin && dist2 > 0 && separatedAlong(d, dist2, a, np, b, nq)) {
            if (!(hist == V2::zero())) hist = V2::zero();
            return false;
        }
        o = clipOverlap(a, np, b, nq, nullptr, &d, ri, &d);
    } else if (si != kNoShape) {  // polygon i, disk j: the circle at the origin
        const int np = st.count(si);
        const V2* a = ps.rotated.data() + st.first[si];
        for (int m = 0; m < np; ++m) P[m] = a[m] + d;
        o = circlePolygonOverlap(rj, P.data(), np);
    } else {  // disk i, polygon j: overlap about x_i, then back to the frame of x_j, outline pieces of i
        const int nq = st.count(sj);
        const V2* b = ps.rotated.data() + st.first[sj];
        for (int m = 0; m < nq; ++m) Q[m] = b[m] - d;
        o = circlePolygonOverlap(ri, Q.data(), nq);
        o.centroid += d;
        o.chord = -o.chord;  // the circle's arcs inside j: minus j's outline inside the circle
        o.spin = -o.spin;
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
    const ContactForce cf = polygonContact(c, o, bi, bj, nullptr, len, cs.attraction,
                                           cs.tangential == TangentialLaw::Spring, dt, hist);
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

/// Forces and torques of a 2D scene with polygons, at the predicted state (see tdm/forces.hpp for sv, sw).
template <class Normal, class Tangential>
ForceStats computePolygonForces(Particles<2>& p, PairList<2>& pl, const std::vector<Wall<2>>& walls,
                                std::vector<V2>& wallHistory, const ContactSetup& cs, const Domain<2>& dom,
                                double time, double dt, const V2* sv, const Ang<2>* sw, ForceScratch<2>& s,
                                PolygonScratch& ps) {
    const std::size_t n = p.tdmCount();
    const std::size_t np = pl.size();
    rotateShapes(p, ps);
    s.maxOverlap.resize(n);  // these three are written for every particle below
    s.contacts.resize(n);
    s.virial.resize(n);
    ps.wallEnergy.assign(n, 0.0);
    ps.pairEnergy.assign(np, 0.0);
    std::vector<double>& torque = ps.torque;
    torque.assign(n, 0.0);
    const bool clip = !cs.attraction;
    const int nm = cs.nMaterials;
    const PairCoeffs* table = cs.table.data();
    const V2 g = dom.gravity;
    const bool threaded = n >= kParallelMin && omp_get_max_threads() > 1;

    // One pair, whichever its kind: force on i and the torques on i and j.
    const PairInputs<2> in{p.x.data(),        p.v.data(),      p.w.data(),         p.radius.data(),
                           p.invMass.data(),  p.material.data(), sv,               sw,
                           pl.partner.data(), pl.shift.data(), pl.shiftVec.data(), pl.history.data(),
                           table,             nm,              clip,               dt};
    auto pair = [&](std::size_t i, std::uint32_t k, PairResult& r, double& worst, double& vir) {
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

    if (!threaded) {
        for (std::size_t i = 0; i < n; ++i) p.f[i] = g * p.mass[i];
        for (std::size_t i = 0; i < n; ++i) {
            double worst = 0, vir = 0;
            std::uint32_t nc = 0;
            for (std::uint32_t k = pl.first[i]; k < pl.first[i + 1]; ++k) {
                PairResult r;
                if (!pair(i, k, r, worst, vir)) continue;
                const std::uint32_t j = pl.partner[k];
                p.f[i] += r.f;
                torque[i] += r.ti;
                p.f[j] -= r.f;
                torque[j] += r.tj;
                ps.pairEnergy[k] = r.energy;
                ++nc;
            }
            s.maxOverlap[i] = worst;
            s.contacts[i] = nc;
            s.virial[i] = vir;
        }
    } else {
        if (pl.firstT.size() != n + 1) buildTransposedIndex(pl);  // built on first use after a list build
        s.pairForce.resize(np);
        ps.torqueI.resize(np);
        ps.torqueJ.resize(np);
#pragma omp parallel for schedule(dynamic, 256)
        for (std::size_t i = 0; i < n; ++i) {
            double worst = 0, vir = 0;
            std::uint32_t nc = 0;
            for (std::uint32_t k = pl.first[i]; k < pl.first[i + 1]; ++k) {
                PairResult r;
                if (pair(i, k, r, worst, vir)) {
                    ++nc;
                } else {
                    r = PairResult{};
                }
                s.pairForce[k] = r.f;
                ps.torqueI[k] = r.ti;
                ps.torqueJ[k] = r.tj;
                ps.pairEnergy[k] = r.energy;
            }
            s.maxOverlap[i] = worst;
            s.contacts[i] = nc;
            s.virial[i] = vir;
        }
#pragma omp parallel for schedule(static)
        for (std::size_t i = 0; i < n; ++i) {
            V2 f = g * p.mass[i];
            double tq = 0;
            for (std::uint32_t q = pl.firstT[i]; q < pl.firstT[i + 1]; ++q) {
                const std::uint32_t k = pl.pairT[q];
                if (s.pairForce[k] == V2::zero() && ps.torqueJ[k] == 0) continue;
                f -= s.pairForce[k];
                tq += ps.torqueJ[k];
            }
            for (std::uint32_t k = pl.first[i]; k < pl.first[i + 1]; ++k) {
                if (s.pairForce[k] == V2::zero() && ps.torqueI[k] == 0) continue;
                f += s.pairForce[k];
                tq += ps.torqueI[k];
            }
            p.f[i] = f;
            torque[i] = tq;
        }
    }

    // Walls, per particle in wall order.
    const std::size_t nw = walls.size();
    std::size_t wallContacts = 0;
    const ShapeTable& st = p.shapes;
#pragma omp parallel for schedule(static) reduction(+ : wallContacts) if (threaded)
    for (std::size_t i = 0; i < n; ++i) {
        double tq = torque[i];
        if (nw > 0 && !(p.flags[i] & kFrozen)) {
            V2 f = p.f[i];
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
                    const PolygonCoeffs& c = cs.polygonPair(p.material[i], wall.material);
                    const PairLengths len = wallLengths(ri);
                    const ContactForce cf = polygonContact(c, o, bi, bw, &nrm, len, cs.attraction,
                                                           cs.tangential == TangentialLaw::Spring, dt, hist);
                    f += cf.f;
                    tq += cf.torqueI;
                    ps.wallEnergy[i] += polygonContactEnergy(c, o, cf, len);
                    const double clen = norm(o.chord);
                    s.maxOverlap[i] = std::max(s.maxOverlap[i], clen > 0 ? o.area / clen / ri : 1.0);
                    ++wallContacts;
                    continue;
                }
                const double delta = ri - dist;
                const double meff = p.mass[i];
                const V2 dv = p.v[i] - wall.velocity;
                const double gn = dot(dv, nrm);
                const PairCoeffs& c = cs.pair(p.material[i], wall.material);
                NormalResult nr = Normal::eval(c, delta, -gn, meff, ri);
                if (clip && nr.fn < 0) nr.fn = 0;
                f += nrm * nr.fn;
                if constexpr (Tangential::kHasHistory) {
                    const V2 gg = dv - cross(p.w[i] * ri, nrm);
                    const V2 gt = gg - nrm * dot(gg, nrm);
                    const V2 gs = sv[i] - wall.velocity - cross(sw[i] * ri, nrm);
                    const V2 gst = gs - nrm * dot(gs, nrm);
                    const V2 ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, gt, gst, hist, dt);
                    f += ft;
                    tq += cross(nrm, ft)[0] * (-ri);
                }
                s.maxOverlap[i] = std::max(s.maxOverlap[i], delta / ri);
                ++wallContacts;
            }
            p.f[i] = f;
        }
        p.torque[i][0] = tq;
    }

    ForceStats out;
    out.contacts = wallContacts;
    for (std::size_t i = 0; i < n; ++i) {
        out.contacts += s.contacts[i];
        if (s.maxOverlap[i] > out.maxOverlapRatio) {
            out.maxOverlapRatio = s.maxOverlap[i];
            out.worstParticle = i;
        }
    }
    return out;
}

}  // namespace haet::polygon
