#pragma once
// The contact-force loop, written once and instantiated per (normal law, tangential law) pair.
//
// Results do not depend on the thread count: every particle sums its contributions in one fixed order —
// gravity, then the pairs in which it is the partner j (by increasing pair index), then its own pairs, then its
// wall contacts. Two ways produce that order:
//  - serial: one pass over particles in index order that adds each pair force to both particles (scatter);
//  - threaded: pass 1 evaluates every pair once into its own slot, pass 2 gathers per particle through the
//    transposed index. Same additions in the same order, so the same bits.
// Once its sums are complete a particle is finished at once (finishParticle: walls, torque, statistics, the
// caller's per-particle step such as the Verlet corrector), so a step reads the particles once instead of once
// per pass. In the serial path particle i's sums are complete right after its own pairs: its partners j > i come
// later and never see it again, and the pairs where it is the partner came before.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <omp.h>

#include "contact/laws.hpp"
#include "contact/setup.hpp"
#include "core/particles.hpp"
#include "core/wide3.hpp"
#include "geometry/domain.hpp"
#include "neighbor/pair_list.hpp"

namespace haet {

/// Buffers of the threaded path, kept between steps so that no step allocates (the serial path needs none).
template <int D>
struct ForceScratch {
    std::vector<Vec<D>> pairForce;   ///< force on i of each pair [N]
    std::vector<Ang<D>> pairNxFt;    ///< n x F_t of each pair [N]
    std::vector<double> maxOverlap;  ///< per particle: largest overlap / smaller radius, pairs and walls
    std::vector<std::uint32_t> contacts;  ///< per particle: own pairs and walls in contact
    std::vector<double> virial;      ///< per particle: sum over own pairs of r_ij . F_ij [N m]
};

struct ForceStats {
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::size_t contacts = 0;        ///< pair and wall contacts
    double maxOverlapRatio = 0;      ///< largest overlap / smaller radius
    std::size_t worstParticle = 0;   ///< particle with that overlap
    double virial = 0;               ///< sum over pair contacts of r_ij . F_ij, summed particle by particle [J]
    std::size_t nonFinite = kNone;   ///< first particle with a non-finite position or force, or kNone
};

/// Force of one pair: F on i (on j: -F) and n x F_t (torque on each: -a (n x F_t)).
template <int D>
struct PairForce {
    KernelVec<D> f;
    KernelVec<kAngDim<D>> nxft;
};

/// Raw views of what the pair kernel reads, taken once per force evaluation: a local copy the stores of the
/// loop cannot alias, so the loop does not reload the vectors' data pointers after every store.
template <int D>
struct PairInputs {
    const Vec<D>* x;
    const Vec<D>* v;
    const Ang<D>* w;
    const double* radius;
    const double* invMass;
    const std::uint16_t* material;
    const Vec<D>* sv;  ///< mean velocities over the last step (StepMotion)
    const Ang<D>* sw;
    const std::uint32_t* partner;
    const std::uint8_t* shift;
    const Vec<D>* shiftVec;
    Vec<D>* history;
    const PairCoeffs* table;
    int nMaterials;
    bool clip;
    double dt;
};

/// Particle i's own data, loaded once for all its pairs.
template <int D>
struct Owner {
    KernelVec<D> x, v, sv;
    KernelVec<kAngDim<D>> w, sw;
    double radius, invMass;
    const PairCoeffs* coeffRow;  ///< row of i's material in the coefficient table

    Owner(const PairInputs<D>& in, std::size_t i)
        : x(kernelVec(in.x[i])), v(kernelVec(in.v[i])), sv(kernelVec(in.sv[i])), w(kernelVec(in.w[i])),
          sw(kernelVec(in.sw[i])), radius(in.radius[i]), invMass(in.invMass[i]),
          coeffRow(in.table + in.material[i] * in.nMaterials) {}
};

/// Evaluates pair slot k of owner a. Returns false when the pair is not touching (its spring is cleared).
template <int D, class Normal, class Tangential>
[[gnu::always_inline]] inline bool evalPair(const PairInputs<D>& in, const Owner<D>& a, std::uint32_t k,
                                            PairForce<D>& out, double& overlapRatio, double& virial) {
    using V = KernelVec<D>;
    const std::uint32_t j = in.partner[k];
    const V d = a.x - kernelVec(in.x[j]) + kernelVec(in.shiftVec[in.shift[k]]);
    const double ri = a.radius, rj = in.radius[j];
    const double rsum = ri + rj;
    const double dist2 = norm2(d);
    if (dist2 >= rsum * rsum) {
        // Storing the zero costs less than testing whether the spring already is zero.
        if constexpr (Tangential::kHasHistory) in.history[k] = Vec<D>::zero();
        return false;
    }
    const double dist = std::sqrt(dist2);
    const V nrm = d * (1.0 / dist);
    const double delta = rsum - dist;
    // A frozen particle has 1/m = 0: it acts as infinitely heavy. (Frozen-frozen pairs are never listed.)
    const double meff = 1.0 / (a.invMass + in.invMass[j]);
    const double reff = ri * rj / rsum;
    const V dv = a.v - kernelVec(in.v[j]);
    const double gn = dot(dv, nrm);
    const PairCoeffs& c = a.coeffRow[in.material[j]];
    NormalResult nr = Normal::eval(c, delta, -gn, meff, reff);
    if (in.clip && nr.fn < 0) nr.fn = 0;
    out.f = nrm * nr.fn;
    if constexpr (Tangential::kHasHistory) {
        // w x n lies in the contact plane already: only dv needs its normal part (gn) removed.
        const V gt = dv - nrm * gn - cross(a.w * ri + kernelVec(in.w[j]) * rj, nrm);
        const V gs = a.sv - kernelVec(in.sv[j]) - cross(a.sw * ri + kernelVec(in.sw[j]) * rj, nrm);
        V xi = kernelVec(in.history[k]);
        const V ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, gt, gs, xi, in.dt);
        in.history[k] = storedVec(xi);
        out.f += ft;
        out.nxft = cross(nrm, ft);
    } else {
        out.nxft = KernelVec<kAngDim<D>>::zero();
    }
    virial += dot(d, out.f);
    overlapRatio = std::max(overlapRatio, delta / std::min(ri, rj));
    return true;
}

/// What finishParticle reports of one particle.
struct ParticleTally {
    double worst;       ///< largest overlap / smaller radius, pairs and walls
    std::uint32_t contacts;  ///< own pairs and walls in contact
    bool finite;        ///< position and force finite
};

/// Particle i's pair sums are complete (f: force, nx: sum of n x F_t): adds its wall contacts (in wall order),
/// stores force and torque -a (sum) + wall torques, then runs the caller's per-particle step.
template <int D, class Normal, class Tangential, class Then>
[[gnu::always_inline]] inline ParticleTally finishParticle(Particles<D>& p, const PairInputs<D>& in,
                                                          const std::vector<Wall<D>>& walls,
                                                          Vec<D>* wallHistory, const ContactSetup& cs,
                                                          double time, std::size_t i, Vec<D> f, const Ang<D>& nx,
                                                          double worst, std::uint32_t contacts, Then& then) {
    const double ri = p.radius[i];
    Ang<D> tq = nx * (-ri);
    const std::size_t nw = walls.size();
    if (nw > 0 && !(p.flags[i] & kFrozen)) {
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
            if (in.clip && nr.fn < 0) nr.fn = 0;
            f += nrm * nr.fn;
            if constexpr (Tangential::kHasHistory) {
                const Vec<D> gt = dv - nrm * gn - cross(p.w[i] * ri, nrm);
                const Vec<D> gs = in.sv[i] - wall.velocity - cross(in.sw[i] * ri, nrm);
                const Vec<D> ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, gt, gs, hist, in.dt);
                f += ft;
                tq += cross(nrm, ft) * (-ri);
            }
            worst = std::max(worst, delta / ri);
            ++contacts;
        }
    }
    p.f[i] = f;
    p.torque[i] = tq;
    double s = 0;  // a NaN anywhere reaches the force of its particle in the same step
    for (int k = 0; k < D; ++k) s += f[k] + p.x[i][k];
    then(i);
    return {worst, contacts, std::isfinite(s)};
}

/// Forces at the predicted state. sv/sw: mean velocities over the last step (StepMotion), which increment
/// the tangential springs; the damping terms use the predicted velocities p.v, p.w. then(i) runs once particle
/// i's force and torque are final (it may change i's velocities, not its position; nothing reads them after).
template <int D, class Normal, class Tangential, class Then>
ForceStats computeForces(Particles<D>& p, PairList<D>& pl, const std::vector<Wall<D>>& walls,
                         std::vector<Vec<D>>& wallHistory, const ContactSetup& cs, const Domain<D>& dom,
                         double time, double dt, const Vec<D>* sv, const Ang<D>* sw, ForceScratch<D>& s,
                         Then then) {
    const std::size_t n = p.tdmCount();
    const PairInputs<D> in{p.x.data(),        p.v.data(),      p.w.data(),       p.radius.data(),
                           p.invMass.data(),  p.material.data(), sv,             sw,
                           pl.partner.data(), pl.shift.data(), pl.shiftVec.data(), pl.history.data(),
                           cs.table.data(),   cs.nMaterials,   !cs.attraction,   dt};
    const std::uint32_t* first = pl.first.data();
    Vec<D>* wh = wallHistory.data();
    const Vec<D> g = dom.gravity;
    const bool threaded = n >= kParallelMin && omp_get_max_threads() > 1;
    ForceStats st;

    if (!threaded) {
        Vec<D>* f = p.f.data();
        Ang<D>* nx = p.torque.data();  // holds the sums of n x F_t until the particle is finished
        for (std::size_t i = 0; i < n; ++i) {
            f[i] = g * p.mass[i];
            nx[i] = Ang<D>::zero();
        }
        for (std::size_t i = 0; i < n; ++i) {
            const Owner<D> a(in, i);
            KernelVec<D> fi = kernelVec(f[i]);
            KernelVec<kAngDim<D>> nxi = kernelVec(nx[i]);
            double worst = 0, vir = 0;
            std::uint32_t nc = 0;
            for (std::uint32_t k = first[i]; k < first[i + 1]; ++k) {
                PairForce<D> pf;
                if (!evalPair<D, Normal, Tangential>(in, a, k, pf, worst, vir)) continue;
                const std::uint32_t j = in.partner[k];
                fi += pf.f;
                nxi += pf.nxft;
                f[j] = storedVec(kernelVec(f[j]) - pf.f);
                nx[j] = storedVec(kernelVec(nx[j]) + pf.nxft);
                ++nc;
            }
            const ParticleTally t = finishParticle<D, Normal, Tangential>(
                p, in, walls, wh, cs, time, i, storedVec(fi), storedVec(nxi), worst, nc, then);
            st.contacts += t.contacts;
            st.virial += vir;
            if (t.worst > st.maxOverlapRatio) {
                st.maxOverlapRatio = t.worst;
                st.worstParticle = i;
            }
            if (!t.finite && st.nonFinite == ForceStats::kNone) st.nonFinite = i;
        }
        return st;
    }

    if (pl.firstT.size() != n + 1) buildTransposedIndex(pl);
    const std::size_t np = pl.size();
    s.pairForce.resize(np);
    s.pairNxFt.resize(np);
    s.maxOverlap.resize(n);
    s.contacts.resize(n);
    s.virial.resize(n);
    Vec<D>* pairForce = s.pairForce.data();
    Ang<D>* pairNxFt = s.pairNxFt.data();
    std::size_t nonFinite = ForceStats::kNone;
#pragma omp parallel
    {
#pragma omp for schedule(dynamic, 512)
        for (std::size_t i = 0; i < n; ++i) {
            const Owner<D> a(in, i);
            double worst = 0, vir = 0;
            std::uint32_t nc = 0;
            for (std::uint32_t k = first[i]; k < first[i + 1]; ++k) {
                PairForce<D> pf;
                if (evalPair<D, Normal, Tangential>(in, a, k, pf, worst, vir)) {
                    ++nc;
                    pairForce[k] = storedVec(pf.f);
                    pairNxFt[k] = storedVec(pf.nxft);
                } else {
                    pairForce[k] = Vec<D>::zero();
                    pairNxFt[k] = Ang<D>::zero();
                }
            }
            s.maxOverlap[i] = worst;
            s.contacts[i] = nc;
            s.virial[i] = vir;
        }
        // Pass 1, which reads every particle, is over (the barrier of the loop above).
#pragma omp for schedule(static) reduction(min : nonFinite)
        for (std::size_t i = 0; i < n; ++i) {
            Vec<D> f = g * p.mass[i];
            Ang<D> nx = Ang<D>::zero();
            for (std::uint32_t q = pl.firstT[i]; q < pl.firstT[i + 1]; ++q) {
                const std::uint32_t k = pl.pairT[q];
                if (pairForce[k] == Vec<D>::zero() && pairNxFt[k] == Ang<D>::zero()) continue;
                f -= pairForce[k];
                nx += pairNxFt[k];
            }
            for (std::uint32_t k = first[i]; k < first[i + 1]; ++k) {
                if (pairForce[k] == Vec<D>::zero() && pairNxFt[k] == Ang<D>::zero()) continue;
                f += pairForce[k];
                nx += pairNxFt[k];
            }
            const ParticleTally t = finishParticle<D, Normal, Tangential>(p, in, walls, wh, cs, time, i, f, nx,
                                                                          s.maxOverlap[i], s.contacts[i], then);
            s.maxOverlap[i] = t.worst;
            s.contacts[i] = t.contacts;
            if (!t.finite) nonFinite = std::min(nonFinite, i);
        }
    }
    // The serial path's reductions, in the same order.
    for (std::size_t i = 0; i < n; ++i) {
        st.contacts += s.contacts[i];
        st.virial += s.virial[i];
        if (s.maxOverlap[i] > st.maxOverlapRatio) {
            st.maxOverlapRatio = s.maxOverlap[i];
            st.worstParticle = i;
        }
    }
    st.nonFinite = nonFinite;
    return st;
}

}  // namespace haet
