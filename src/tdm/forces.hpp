#pragma once
// The contact-force loop, written once and instantiated per (normal law, tangential law) pair.
// Two passes make the result independent of the thread count: pass 1 evaluates every pair once and stores its
// force; pass 2 sums, for each particle, its pairs in a fixed order (own pairs, then pairs where it is the
// partner, by pair index), then its wall contacts in wall order.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "contact/laws.hpp"
#include "contact/setup.hpp"
#include "core/particles.hpp"
#include "geometry/domain.hpp"
#include "neighbor/pair_list.hpp"

namespace haet {

template <int D>
struct ForceScratch {
    std::vector<Vec<D>> pairForce;   ///< force on i of each pair [N]
    std::vector<Ang<D>> pairNxFt;    ///< n x F_t of each pair; torque on i is -a_i (n x F_t), on j -a_j (n x F_t)
    std::vector<double> maxOverlap;  ///< per particle: largest overlap / smaller radius over its own pairs
    std::vector<std::uint32_t> contacts;  ///< per particle: own pairs in contact
    std::vector<double> virial;      ///< per particle: sum over own pairs of r_ij . F_ij [N m]
};

struct ForceStats {
    std::size_t contacts = 0;        ///< pair and wall contacts
    double maxOverlapRatio = 0;      ///< largest overlap / smaller radius
    std::size_t worstParticle = 0;   ///< particle with that overlap
};

/// Forces at the predicted state. sv/sw: mean velocities over the last step (StepMotion), which increment
/// the tangential springs; the damping terms use the predicted velocities p.v, p.w.
template <int D, class Normal, class Tangential>
ForceStats computeForces(Particles<D>& p, PairList<D>& pl, const std::vector<Wall<D>>& walls,
                         std::vector<Vec<D>>& wallHistory, const ContactSetup& cs, const Domain<D>& dom,
                         double time, double dt, const Vec<D>* sv, const Ang<D>* sw, ForceScratch<D>& s) {
    const std::size_t n = p.size();
    const std::size_t np = pl.size();
    s.pairForce.resize(np);
    s.pairNxFt.resize(np);
    s.maxOverlap.assign(n, 0.0);
    s.contacts.assign(n, 0);
    s.virial.assign(n, 0.0);
    const bool clip = !cs.attraction;
    const int nm = cs.nMaterials;
    const PairCoeffs* table = cs.table.data();

#pragma omp parallel for schedule(dynamic, 512) if (n >= kParallelMin)
    for (std::size_t i = 0; i < n; ++i) {
        const Vec<D> xi = p.x[i];
        const double ri = p.radius[i];
        const double mi = p.mass[i];
        const bool fi = p.flags[i] & kFrozen;
        const int mati = p.material[i];
        double worst = 0, vir = 0;
        std::uint32_t nc = 0;
        for (std::uint32_t k = pl.first[i]; k < pl.first[i + 1]; ++k) {
            const std::uint32_t j = pl.partner[k];
            const Vec<D> d = xi - p.x[j] + pl.shiftVec[pl.shift[k]];
            const double rsum = ri + p.radius[j];
            const double dist2 = norm2(d);
            if (dist2 >= rsum * rsum) {
                s.pairForce[k] = Vec<D>::zero();
                s.pairNxFt[k] = Ang<D>::zero();
                if constexpr (Tangential::kHasHistory) pl.history[k] = Vec<D>::zero();
                continue;
            }
            const double dist = std::sqrt(dist2);
            const Vec<D> nrm = d * (1.0 / dist);
            const double delta = rsum - dist;
            const double rj = p.radius[j];
            const double mj = p.mass[j];
            // A frozen particle acts as infinitely heavy for the effective mass.
            const bool fj = p.flags[j] & kFrozen;
            const double meff = fi ? mj : (fj ? mi : mi * mj / (mi + mj));
            const double reff = ri * rj / rsum;
            const Vec<D> dv = p.v[i] - p.v[j];
            const double gn = dot(dv, nrm);
            const PairCoeffs& c = table[mati * nm + p.material[j]];
            NormalResult nr = Normal::eval(c, delta, -gn, meff, reff);
            if (clip && nr.fn < 0) nr.fn = 0;
            Vec<D> f = nrm * nr.fn;
            if constexpr (Tangential::kHasHistory) {
                const Vec<D> g = dv - cross(p.w[i] * ri + p.w[j] * rj, nrm);
                const Vec<D> gt = g - nrm * dot(g, nrm);
                const Vec<D> gs = sv[i] - sv[j] - cross(sw[i] * ri + sw[j] * rj, nrm);
                const Vec<D> gst = gs - nrm * dot(gs, nrm);
                const Vec<D> ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, gt, gst, pl.history[k], dt);
                f += ft;
                s.pairNxFt[k] = cross(nrm, ft);
            } else {
                s.pairNxFt[k] = Ang<D>::zero();
            }
            s.pairForce[k] = f;
            vir += dot(d, f);
            worst = std::max(worst, delta / std::min(ri, rj));
            ++nc;
        }
        s.maxOverlap[i] = worst;
        s.contacts[i] = nc;
        s.virial[i] = vir;
    }

    const std::size_t nw = walls.size();
    const Vec<D> g = dom.gravity;
    std::size_t wallContacts = 0;
#pragma omp parallel for schedule(static) reduction(+ : wallContacts) if (n >= kParallelMin)
    for (std::size_t i = 0; i < n; ++i) {
        Vec<D> f = g * p.mass[i];
        Ang<D> nxft = Ang<D>::zero();
        for (std::uint32_t k = pl.first[i]; k < pl.first[i + 1]; ++k) {
            f += s.pairForce[k];
            nxft += s.pairNxFt[k];
        }
        for (std::uint32_t q = pl.firstT[i]; q < pl.firstT[i + 1]; ++q) {
            const std::uint32_t k = pl.pairT[q];
            f -= s.pairForce[k];
            nxft += s.pairNxFt[k];
        }
        Ang<D> tq = nxft * (-p.radius[i]);
        if (nw > 0 && !(p.flags[i] & kFrozen)) {
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
        }
        p.f[i] = f;
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
