#pragma once
// The contact-force loop, written once and instantiated per (normal law, tangential law) pair.
//
// Results do not depend on the thread count: every particle sums its contributions in one fixed order —
// gravity, then the pairs in which it is the partner j (by increasing pair index), then its own pairs, then its
// wall contacts. Two ways produce that order:
//  - serial: one pass over pairs in index order that adds each pair force to both particles (scatter);
//  - threaded: pass 1 evaluates every pair once into its own slot, pass 2 gathers per particle through the
//    transposed index. Same additions in the same order, so the same bits.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <omp.h>

#include "contact/laws.hpp"
#include "contact/setup.hpp"
#include "core/particles.hpp"
#include "geometry/domain.hpp"
#include "neighbor/pair_list.hpp"

namespace haet {

template <int D>
struct ForceScratch {
    std::vector<Vec<D>> pairForce;   ///< threaded path: force on i of each pair [N]
    std::vector<Ang<D>> pairNxFt;    ///< threaded path: n x F_t of each pair
    std::vector<Ang<D>> nxft;        ///< per particle: sum of n x F_t; torque = -a (sum) [N]
    std::vector<double> maxOverlap;  ///< per particle: largest overlap / smaller radius over its own pairs
    std::vector<std::uint32_t> contacts;  ///< per particle: own pairs in contact
    std::vector<double> virial;      ///< per particle: sum over own pairs of r_ij . F_ij [N m]
};

struct ForceStats {
    std::size_t contacts = 0;        ///< pair and wall contacts
    double maxOverlapRatio = 0;      ///< largest overlap / smaller radius
    std::size_t worstParticle = 0;   ///< particle with that overlap
};

/// Force of one pair: F on i (on j: -F) and n x F_t (torque on each: -a (n x F_t)).
template <int D>
struct PairForce {
    Vec<D> f;
    Ang<D> nxft;
};

/// Evaluates pair slot k of particle i. Returns false when the pair is not touching (history cleared).
template <int D, class Normal, class Tangential>
[[gnu::always_inline]] inline bool evalPair(const Particles<D>& p, PairList<D>& pl, const PairCoeffs* table, int nm, bool clip,
                     const Vec<D>* sv, const Ang<D>* sw, double dt, std::size_t i, std::uint32_t k,
                     PairForce<D>& out, double& overlapRatio, double& virial) {
    const std::uint32_t j = pl.partner[k];
    const Vec<D> d = p.x[i] - p.x[j] + pl.shiftVec[pl.shift[k]];
    const double ri = p.radius[i], rj = p.radius[j];
    const double rsum = ri + rj;
    const double dist2 = norm2(d);
    if (dist2 >= rsum * rsum) {
        if constexpr (Tangential::kHasHistory) {
            Vec<D>& h = pl.history[k];
            if (!(h == Vec<D>::zero())) h = Vec<D>::zero();
        }
        return false;
    }
    const double dist = std::sqrt(dist2);
    const Vec<D> nrm = d * (1.0 / dist);
    const double delta = rsum - dist;
    // A frozen particle has 1/m = 0: it acts as infinitely heavy. (Frozen-frozen pairs are never listed.)
    const double meff = 1.0 / (p.invMass[i] + p.invMass[j]);
    const double reff = ri * rj / rsum;
    const Vec<D> dv = p.v[i] - p.v[j];
    const double gn = dot(dv, nrm);
    const PairCoeffs& c = table[p.material[i] * nm + p.material[j]];
    NormalResult nr = Normal::eval(c, delta, -gn, meff, reff);
    if (clip && nr.fn < 0) nr.fn = 0;
    out.f = nrm * nr.fn;
    if constexpr (Tangential::kHasHistory) {
        const Vec<D> g = dv - cross(p.w[i] * ri + p.w[j] * rj, nrm);
        const Vec<D> gt = g - nrm * dot(g, nrm);
        const Vec<D> gs = sv[i] - sv[j] - cross(sw[i] * ri + sw[j] * rj, nrm);
        const Vec<D> gst = gs - nrm * dot(gs, nrm);
        const Vec<D> ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, gt, gst, pl.history[k], dt);
        out.f += ft;
        out.nxft = cross(nrm, ft);
    } else {
        out.nxft = Ang<D>::zero();
    }
    virial += dot(d, out.f);
    overlapRatio = std::max(overlapRatio, delta / std::min(ri, rj));
    return true;
}

/// Forces at the predicted state. sv/sw: mean velocities over the last step (StepMotion), which increment
/// the tangential springs; the damping terms use the predicted velocities p.v, p.w.
template <int D, class Normal, class Tangential>
ForceStats computeForces(Particles<D>& p, PairList<D>& pl, const std::vector<Wall<D>>& walls,
                         std::vector<Vec<D>>& wallHistory, const ContactSetup& cs, const Domain<D>& dom,
                         double time, double dt, const Vec<D>* sv, const Ang<D>* sw, ForceScratch<D>& s) {
    const std::size_t n = p.tdmCount();
    const std::size_t np = pl.size();
    s.maxOverlap.assign(n, 0.0);
    s.contacts.assign(n, 0);
    s.virial.assign(n, 0.0);
    s.nxft.resize(n);
    const bool clip = !cs.attraction;
    const int nm = cs.nMaterials;
    const PairCoeffs* table = cs.table.data();
    const Vec<D> g = dom.gravity;
    const bool threaded = n >= kParallelMin && omp_get_max_threads() > 1;

    if (!threaded) {
        for (std::size_t i = 0; i < n; ++i) {
            p.f[i] = g * p.mass[i];
            s.nxft[i] = Ang<D>::zero();
        }
        for (std::size_t i = 0; i < n; ++i) {
            double worst = 0, vir = 0;
            std::uint32_t nc = 0;
            for (std::uint32_t k = pl.first[i]; k < pl.first[i + 1]; ++k) {
                PairForce<D> pf;
                if (!evalPair<D, Normal, Tangential>(p, pl, table, nm, clip, sv, sw, dt, i, k, pf, worst, vir))
                    continue;
                const std::uint32_t j = pl.partner[k];
                p.f[i] += pf.f;
                s.nxft[i] += pf.nxft;
                p.f[j] -= pf.f;
                s.nxft[j] += pf.nxft;
                ++nc;
            }
            s.maxOverlap[i] = worst;
            s.contacts[i] = nc;
            s.virial[i] = vir;
        }
    } else {
        s.pairForce.resize(np);
        s.pairNxFt.resize(np);
#pragma omp parallel for schedule(dynamic, 512)
        for (std::size_t i = 0; i < n; ++i) {
            double worst = 0, vir = 0;
            std::uint32_t nc = 0;
            for (std::uint32_t k = pl.first[i]; k < pl.first[i + 1]; ++k) {
                PairForce<D> pf;
                if (evalPair<D, Normal, Tangential>(p, pl, table, nm, clip, sv, sw, dt, i, k, pf, worst, vir)) {
                    ++nc;
                } else {
                    pf.f = Vec<D>::zero();
                    pf.nxft = Ang<D>::zero();
                }
                s.pairForce[k] = pf.f;
                s.pairNxFt[k] = pf.nxft;
            }
            s.maxOverlap[i] = worst;
            s.contacts[i] = nc;
            s.virial[i] = vir;
        }
#pragma omp parallel for schedule(static)
        for (std::size_t i = 0; i < n; ++i) {
            Vec<D> f = g * p.mass[i];
            Ang<D> nx = Ang<D>::zero();
            for (std::uint32_t q = pl.firstT[i]; q < pl.firstT[i + 1]; ++q) {
                const std::uint32_t k = pl.pairT[q];
                if (s.pairForce[k] == Vec<D>::zero() && s.pairNxFt[k] == Ang<D>::zero()) continue;
                f -= s.pairForce[k];
                nx += s.pairNxFt[k];
            }
            for (std::uint32_t k = pl.first[i]; k < pl.first[i + 1]; ++k) {
                if (s.pairForce[k] == Vec<D>::zero() && s.pairNxFt[k] == Ang<D>::zero()) continue;
                f += s.pairForce[k];
                nx += s.pairNxFt[k];
            }
            p.f[i] = f;
            s.nxft[i] = nx;
        }
    }

    // Torques from the pair sums, then wall contacts (per particle, in wall order).
    const std::size_t nw = walls.size();
    std::size_t wallContacts = 0;
#pragma omp parallel for schedule(static) reduction(+ : wallContacts) if (threaded)
    for (std::size_t i = 0; i < n; ++i) {
        Ang<D> tq = s.nxft[i] * (-p.radius[i]);
        if (nw > 0 && !(p.flags[i] & kFrozen)) {
            Vec<D> f = p.f[i];
            const double ri = p.radius[i];
            for (std::size_t w = 0; w < nw; ++w) {
                const Wall<D>& wall = walls[w];
                Vec<D>& hist = wallHistory[i * nw + w];
                const double delta = ri - wall.distance(p.x[i], time);
                if (delta <= 0) {
                    if constexpr (Tangential::kHasHistory) hist = Vec<D>::zero();
                    continue;
                }
                const Vec<D>& nrm = wall.normal;
                const double meff = p.mass[i];
                const Vec<D> dv = p.v[i] - wall.velocity;
                const double gn = dot(dv, nrm);
                const PairCoeffs& c = cs.pair(p.material[i], wall.material);
                NormalResult nr = Normal::eval(c, delta, -gn, meff, ri);
                if (clip && nr.fn < 0) nr.fn = 0;
                f += nrm * nr.fn;
                if constexpr (Tangential::kHasHistory) {
                    const Vec<D> gg = dv - cross(p.w[i] * ri, nrm);
                    const Vec<D> gt = gg - nrm * dot(gg, nrm);
                    const Vec<D> gs = sv[i] - wall.velocity - cross(sw[i] * ri, nrm);
                    const Vec<D> gst = gs - nrm * dot(gs, nrm);
                    const Vec<D> ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, gt, gst, hist, dt);
                    f += ft;
                    tq += cross(nrm, ft) * (-ri);
                }
                s.maxOverlap[i] = std::max(s.maxOverlap[i], delta / ri);
                ++wallContacts;
            }
            p.f[i] = f;
        }
        p.torque[i] = tq;
    }

    ForceStats st;
    st.contacts = wallContacts;
    for (std::size_t i = 0; i < n; ++i) {
        st.contacts += s.contacts[i];
        if (s.maxOverlap[i] > st.maxOverlapRatio) {
            st.maxOverlapRatio = s.maxOverlap[i];
            st.worstParticle = i;
        }
    }
    return st;
}

}  // namespace haet
