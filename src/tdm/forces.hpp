#pragma once
// The contact-force loop, written once and instantiated per (normal law, tangential law) pair.
//
// Results do not depend on the thread count: every particle sums its contributions in one fixed order —
// gravity, then the pairs in which it is the partner j (by increasing pair index), then its own pairs, then its
// wall contacts. One pass over particles in index order produces it: each pair force is added to both particles
// (scatter) as its owner i comes. Once its sums are complete a particle is finished at once (finishParticle:
// walls, torque, statistics, the caller's per-particle step such as the Verlet corrector), so a step reads the
// particles once: particle i's sums are complete right after its own pairs, since its partners j > i come later
// and never see it again, and the pairs where it is the partner came before.
// With T threads the particles are cut into T contiguous ranges (PairList::split) and each thread runs that pass
// over its range. Only the "cross" pairs, whose partner lies in a later range, reach outside a range; they are
// evaluated first, each into its own slot. A range then adds the cross pairs in which its particles are partners
// (in pair order: they all precede the range's own pairs), and takes its own cross pairs from their slots in
// their place among its pairs. Same additions in the same order as with one thread, so the same bits. After a
// spatial sort the ranges are slabs of space and the cross pairs lie along their faces: a few per cent.
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

struct ForceStats {
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::size_t contacts = 0;        ///< pair and wall contacts
    double maxOverlapRatio = 0;      ///< largest overlap / smaller radius
    std::size_t worstParticle = 0;   ///< particle with that overlap
    double virial = 0;               ///< sum over pair contacts of r_ij . F_ij, summed particle by particle [J]
    std::size_t nonFinite = kNone;   ///< first particle with a non-finite position or force, or kNone
};

/// What forceRange reports of its particles: ForceStats without the virial, which is summed per particle.
struct RangeTally {
    std::size_t contacts = 0;
    double maxOverlapRatio = 0;
    std::size_t worstParticle = 0;
    std::size_t nonFinite = ForceStats::kNone;
};

/// A cross pair evaluated before the ranges run (threaded path).
template <int D>
struct CrossPair {
    Vec<D> f;         ///< force on i [N]
    Ang<D> nxft;      ///< n x F_t [N]
    double virial;    ///< r_ij . F_ij [N m]
    double overlap;   ///< overlap / smaller radius
    bool touching;
};

/// Buffers of the threaded paths, kept between steps so that no step allocates (one thread needs none).
template <int D>
struct ForceScratch {
    std::vector<CrossPair<D>> cross;  ///< the disk loop's cross pairs (PairList::split)
    std::vector<Vec<D>> pairForce;    ///< polygon loop: force on i of each pair [N]
    std::vector<double> maxOverlap;   ///< polygon loop, per particle: largest overlap / smaller radius
    std::vector<std::uint32_t> contacts;  ///< polygon loop, per particle: own pairs and walls in contact
    std::vector<double> virial;       ///< per particle: sum over own pairs of r_ij . F_ij [N m]
    std::vector<RangeTally> tally;    ///< the disk loop's per-range statistics
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
    V d = a.x - kernelVec(in.x[j]);
    // Most pairs do not cross a periodic boundary: their shift is zero and costs a load and an add less.
    if (in.shift[k] != PairList<D>::kNoShift) d += kernelVec(in.shiftVec[in.shift[k]]);
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
/// stores force and torque -a (sum) + wall torques, then runs the caller's per-particle step then(i, f, torque).
template <int D, class Normal, class Tangential, class Then>
[[gnu::always_inline]] inline ParticleTally finishParticle(Particles<D>& p, const PairInputs<D>& in,
                                                          const Wall<D>* walls, std::size_t nw,
                                                          Vec<D>* wallHistory, const ContactSetup& cs,
                                                          double time, std::size_t i, const Owner<D>& a, Vec<D> f,
                                                          const Ang<D>& nx, double worst, std::uint32_t contacts,
                                                          Then& then) {
    const double ri = a.radius;
    Ang<D> tq = nx * (-ri);
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
    const Vec<D> x = storedVec(a.x);
    double s = 0;  // a NaN anywhere reaches the force of its particle in the same step
    for (int k = 0; k < D; ++k) s += f[k] + x[k];
    then(i, f, tq);
    return {worst, contacts, std::isfinite(s)};
}

/// The pass over particles [b, e), which holds every partner of their pairs except the cross pairs (kCross:
/// partner >= e), evaluated before into cross[c0...] in pair order; crossIn: the cross pairs whose partner is in
/// [b, e), by partner then pair. Per-particle virial sums go to virial[i] when a thread split needs them kept
/// apart, else into *virialSum (in particle order either way).
template <int D, class Normal, class Tangential, bool kCross, class Then>
[[gnu::always_inline]] inline RangeTally forceRange(Particles<D>& p, const PairInputs<D>& in,
                                                     const std::uint32_t* first, const Wall<D>* walls, std::size_t nw,
                                                     Vec<D>* wh, const ContactSetup& cs, double time, const Vec<D>& g,
                                                     std::size_t b, std::size_t e, const CrossPair<D>* cross,
                                                     std::size_t c0, const std::uint64_t* crossIn,
                                                     const std::uint64_t* crossInEnd, double* virial,
                                                     double* virialSum, Then& then) {
    Vec<D>* f = p.f.data();
    Ang<D>* nx = p.torque.data();  // holds the sums of n x F_t until the particle is finished
    const double* mass = p.mass.data();
    // A particle's sums start (gravity, then the cross pairs where it is the partner) just before the first pair
    // that adds to them: particles [b, done) have started. Each row is sorted by partner, so its last pair reaches
    // farthest; starting the sums there, not in a pass of their own, keeps them in cache until they are used.
    std::size_t done = b;
    const std::uint64_t* q = crossIn;
    auto startUpTo = [&](std::size_t end) {
        for (; done < end; ++done) {
            f[done] = g * mass[done];
            nx[done] = Ang<D>::zero();
            if constexpr (kCross) {
                for (; q != crossInEnd && (*q >> 32) == done; ++q) {
                    const CrossPair<D>& c = cross[*q & 0xFFFFFFFFu];
                    if (!c.touching) continue;
                    f[done] -= c.f;
                    nx[done] += c.nxft;
                }
            }
        }
    };
    RangeTally st;
    std::size_t c = c0;
    for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t k0 = first[i], k1 = first[i + 1];
        std::size_t reach = k1 > k0 ? std::size_t{in.partner[k1 - 1]} + 1 : i + 1;
        if constexpr (kCross) reach = std::min(reach, e);
        startUpTo(std::max(reach, i + 1));
        const Owner<D> a(in, i);
        KernelVec<D> fi = kernelVec(f[i]);
        KernelVec<kAngDim<D>> nxi = kernelVec(nx[i]);
        double worst = 0, vir = 0;
        std::uint32_t nc = 0;
        for (std::uint32_t k = k0; k < k1; ++k) {
            const std::uint32_t j = in.partner[k];
            if constexpr (kCross) {
                if (j >= e) {
                    const CrossPair<D>& x = cross[c++];
                    if (!x.touching) continue;
                    fi += kernelVec(x.f);
                    nxi += kernelVec(x.nxft);
                    vir += x.virial;
                    worst = std::max(worst, x.overlap);
                    ++nc;
                    continue;
                }
            }
            PairForce<D> pf;
            if (!evalPair<D, Normal, Tangential>(in, a, k, pf, worst, vir)) continue;
            fi += pf.f;
            nxi += pf.nxft;
            f[j] = storedVec(kernelVec(f[j]) - pf.f);
            nx[j] = storedVec(kernelVec(nx[j]) + pf.nxft);
            ++nc;
        }
        const ParticleTally t = finishParticle<D, Normal, Tangential>(p, in, walls, nw, wh, cs, time, i, a,
                                                                      storedVec(fi), storedVec(nxi), worst, nc, then);
        st.contacts += t.contacts;
        if constexpr (kCross) virial[i] = vir;
        else *virialSum += vir;
        if (t.worst > st.maxOverlapRatio) {
            st.maxOverlapRatio = t.worst;
            st.worstParticle = i;
        }
        if (!t.finite && st.nonFinite == ForceStats::kNone) st.nonFinite = i;
    }
    return st;
}

/// Forces at the predicted state. sv/sw: mean velocities over the last step (StepMotion), which increment
/// the tangential springs; the damping terms use the predicted velocities p.v, p.w. then(i) runs once particle
/// i's force and torque are final, with them: then(i, f, torque) (it may change i's velocities, not its position;
/// nothing reads them after).
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
    const Wall<D>* wp = walls.data();
    const std::size_t nw = walls.size();
    const Vec<D> g = dom.gravity;
    const int nt = n >= kParallelMin ? omp_get_max_threads() : 1;
    ForceStats st;

    if (nt <= 1) {
        const RangeTally t = forceRange<D, Normal, Tangential, false>(p, in, first, wp, nw, wh, cs, time, g, 0, n,
                                                                      nullptr, 0, nullptr, nullptr, nullptr,
                                                                      &st.virial, then);
        st.contacts = t.contacts;
        st.maxOverlapRatio = t.maxOverlapRatio;
        st.worstParticle = t.worstParticle;
        st.nonFinite = t.nonFinite;
        return st;
    }

    if (pl.split.ranges() != static_cast<std::size_t>(nt)) buildThreadSplit(pl, nt);
    const ThreadSplit& sp = pl.split;
    const std::size_t ncross = sp.crossSlot.size();
    s.cross.resize(ncross);
    s.virial.resize(n);
    CrossPair<D>* cross = s.cross.data();
    s.tally.assign(static_cast<std::size_t>(nt), RangeTally{});
    RangeTally* tally = s.tally.data();
#pragma omp parallel num_threads(nt)
    {
        // The cross pairs first: every particle is still unfinished.
#pragma omp for schedule(static)
        for (std::size_t c = 0; c < ncross; ++c) {
            const Owner<D> a(in, sp.crossOwner[c]);
            PairForce<D> pf;
            CrossPair<D>& x = cross[c];
            x.overlap = 0;
            x.virial = 0;
            x.touching = evalPair<D, Normal, Tangential>(in, a, sp.crossSlot[c], pf, x.overlap, x.virial);
            if (x.touching) {
                x.f = storedVec(pf.f);
                x.nxft = storedVec(pf.nxft);
            }
        }
#pragma omp for schedule(static, 1)
        for (int r = 0; r < nt; ++r) {
            const std::uint64_t* ci = sp.crossIn.data();
            tally[r] = forceRange<D, Normal, Tangential, true>(
                p, in, first, wp, nw, wh, cs, time, g, sp.start[r], sp.start[r + 1], cross, sp.crossFirst[r],
                ci + sp.crossInFirst[r], ci + sp.crossInFirst[r + 1], s.virial.data(), nullptr, then);
        }
    }
    // The one-thread reductions, in the same order.
    for (const RangeTally& t : s.tally) {
        st.contacts += t.contacts;
        if (t.maxOverlapRatio > st.maxOverlapRatio) {
            st.maxOverlapRatio = t.maxOverlapRatio;
            st.worstParticle = t.worstParticle;
        }
        if (st.nonFinite == ForceStats::kNone) st.nonFinite = t.nonFinite;
    }
    for (std::size_t i = 0; i < n; ++i) st.virial += s.virial[i];
    return st;
}

}  // namespace haet
