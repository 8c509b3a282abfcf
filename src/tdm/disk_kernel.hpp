#pragma once
// The contact kernel of disks (2D) and spheres (3D) for the pair pass (tdm/pair_pass.hpp): the contact test and the
// law (contact/laws.hpp, written once for one pair and for four in lanes, core/lanes.hpp) of a block's listed pairs,
// instantiated per (normal law, tangential law). A block goes in two steps: (1) the contact tests, without a branch
// on their outcome (findTouchingLanes, four at a time; findTouching), each touching pair appended to the block's
// list of touching pairs; (2) the law on the touching pairs, four (or eight) at a time in lanes (evalTouching), where
// their long chains of square roots and divisions overlap instead of waiting one behind the other. Every pair gets
// the bits it gets alone (tests/test_force_lanes.cpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "contact/laws.hpp"
#include "contact/setup.hpp"
#include "core/lanes.hpp"
#include "core/lanes_pack.hpp"
#include "core/particles.hpp"
#include "core/wide3.hpp"
#include "neighbor/pair_list.hpp"
#include "tdm/contact_record.hpp"
#include "tdm/pair_block.hpp"
#include "tdm/pair_pass.hpp"
#include "tdm/wall_kernel.hpp"

namespace haet {

/// No record of the law's parts: the ordinary passes.
struct NoLawParts {};
/// The law's parts of one contact as it computed them (the contact network, tdm/contact_record.hpp).
template <int D>
struct LawParts {
    KernelVec<D> normal, fn, ft;  ///< unit normal (from j to i), normal and tangential force on i [N]
    KernelVec<D> d;               ///< x_i - x_j with the pair's periodic shift [m]
    double delta = 0;             ///< overlap [m]
};

/// What one touching pair adds to its owner (its partner gets -f and n x F_t): f = F on i in a (the virial r . F in
/// a[3]); n x F_t in b (the overlap / smaller radius in b[3]).
struct DiskEntry {
    Row a, b;
    double virial() const { return a.c[3]; }
    double overlap() const { return b.c[3]; }
};
template <int D>
using DiskBlock = PairBlock<D, DiskEntry>;

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
    std::uint32_t nPairs;        ///< listed pairs (elements of partner)
    const std::uint32_t* owner;  ///< owner of each pair (PairList::owner, made for the four-wide contact tests)
    const std::uint8_t* shift;
    const Vec<D>* shiftVec;
    Vec<D>* history;
    const PairCoeffs* table;
    int nMaterials;
    bool uniform;  ///< every material pair has the same force law (uniformForceLaw): table[0] serves all
    bool clip;
    double dt;
};

/// The views of one force evaluation (sv, sw: the step's mean velocities; dt: the step).
template <int D>
PairInputs<D> pairInputs(const Particles<D>& p, PairList<D>& pl, const ContactSetup& cs, const Vec<D>* sv,
                         const Ang<D>* sw, double dt) {
    return {p.x.data(),
            p.v.data(),
            p.w.data(),
            p.radius.data(),
            p.invMass.data(),
            p.material.data(),
            sv,
            sw,
            pl.partner.data(),
            static_cast<std::uint32_t>(pl.partner.size()),
            pl.owner.data(),
            pl.shift.data(),
            pl.shiftVec.data(),
            pl.history.data(),
            cs.table.data(),
            cs.nMaterials,
            uniformForceLaw(cs.table.data(), cs.table.size()),
            !cs.attraction,
            dt};
}

/// Particle i's own data, loaded once for all its pairs.
template <int D>
struct Owner {
    KernelVec<D> x, v, sv;
    KernelVec<kAngDim<D>> w, sw;
    double radius, invMass;
    const PairCoeffs* coeffRow;  ///< row of i's material in the coefficient table

    Owner(const PairInputs<D>& in, std::size_t i)
        : x(kernelVec(in.x[i])),
          v(kernelVec(in.v[i])),
          sv(kernelVec(in.sv[i])),
          w(kernelVec(in.w[i])),
          sw(kernelVec(in.sw[i])),
          radius(in.radius[i]),
          invMass(in.invMass[i]),
          coeffRow(in.table + in.material[i] * in.nMaterials) {}
};

/// What the law reads of the two sides' motion: dv = v_i - v_j, wr = w_i r_i + w_j r_j, and the same of the mean
/// velocities over the step (dsv, swr; the tangential spring's increment). Combined as soon as they are loaded, so
/// that four pairs' kinematics take half the registers.
template <class V, class A>
struct RelMotion {
    V dv;
    A wr;
    V dsv;
    A swr;
};
template <class S, class V, class A>
[[gnu::always_inline]] inline RelMotion<V, A> relMotion(const V& vi, const V& vj, const A& wi, const A& wj,
                                                        const V& svi, const V& svj, const A& swi, const A& swj, S ri,
                                                        S rj) {
    return {vi - vj, wi * ri + wj * rj, svi - svj, swi * ri + swj * rj};
}

/// The contact law of a touching pair, from the pair's separation d = x_i - x_j (+ shift), |d|^2, radii, inverse
/// masses and velocities: F on i, n x F_t and the spring xi (updated), r . F and overlap / smaller radius.
/// Written once for one pair (S = double) and for four in lanes (S = Lanes; core/lanes.hpp): the same operations
/// in the same order, so a pair gets the same bits either way.
/// With parts (one pair, the contact network's pass only) also the law's normal and tangential forces as it
/// computed them.
template <class Normal, class Tangential, class C, class S, class V, class A, class Parts = NoLawParts>
[[gnu::always_inline]] inline void contactLaw(const C& c, const V& d, S dist2, S ri, S rj, S invMi, S invMj,
                                              const RelMotion<V, A>& m, V& xi, bool clip, double dt, V& f, A& nxft,
                                              S& virial, S& overlap, Parts* parts = nullptr) {
    const S rsum = ri + rj;
    const S dist = sqrtOf(dist2);
    const V nrm = d * (1.0 / dist);
    const S delta = rsum - dist;
    // A frozen particle has 1/m = 0: it acts as infinitely heavy. (Frozen-frozen pairs are never listed.)
    const S meff = 1.0 / (invMi + invMj);
    const S reff = ri * rj / rsum;
    const V& dv = m.dv;
    const S gn = dot(dv, nrm);
    NormalResultOf<S> nr = Normal::eval(c, delta, -gn, meff, reff);
    if (clip) nr.fn = select(nr.fn < 0, S(0.0), nr.fn);
    f = nrm * nr.fn;
    if constexpr (!std::is_same_v<Parts, NoLawParts>) {
        parts->normal = nrm;
        parts->fn = f;
        parts->ft = V::zero();
        parts->delta = delta;
    }
    if constexpr (Tangential::kHasHistory) {
        // w x n lies in the contact plane already: only dv needs its normal part (gn) removed.
        const V gt = dv - nrm * gn - cross(m.wr, nrm);
        const V gs = m.dsv - cross(m.swr, nrm);
        const V ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, d, dist2, gt, gs, xi, dt);
        f += ft;
        nxft = cross(nrm, ft);
        if constexpr (!std::is_same_v<Parts, NoLawParts>) parts->ft = ft;
    } else {
        nxft = A::zero();
    }
    virial = dot(d, f);
    overlap = delta / minOf(ri, rj);
}

/// Evaluates pair slot k of owner a. Returns false when the pair is not touching (its spring is cleared).
template <int D, class Normal, class Tangential, class Parts = NoLawParts>
[[gnu::always_inline]] inline bool evalPair(const PairInputs<D>& in, const Owner<D>& a, std::uint32_t k,
                                            PairForce<D>& out, double& overlapRatio, double& virial,
                                            Parts* parts = nullptr) {
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
    V xi = V::zero();
    if constexpr (Tangential::kHasHistory) xi = kernelVec(in.history[k]);
    double vir, overlap;
    contactLaw<Normal, Tangential>(a.coeffRow[in.material[j]], d, dist2, ri, rj, a.invMass, in.invMass[j],
                                   relMotion(a.v, kernelVec(in.v[j]), a.w, kernelVec(in.w[j]), a.sv,
                                             kernelVec(in.sv[j]), a.sw, kernelVec(in.sw[j]), ri, rj),
                                   xi, in.clip, in.dt, out.f, out.nxft, vir, overlap, parts);
    if constexpr (!std::is_same_v<Parts, NoLawParts>) parts->d = d;
    if constexpr (Tangential::kHasHistory) in.history[k] = storedVec(xi);
    virial += vir;
    overlapRatio = std::max(overlapRatio, overlap);
    return true;
}

/// The contact test of listed pair k (owner i at xi with radius ri, partner j), written at place nl of the block's
/// list of touching pairs whatever its outcome (the list grows by one when it touches). The pair's spring stays in
/// the pair list; a pair not touching has it cleared there (by a mask, without a branch). Returns whether the pair
/// touches.
template <int D, class Tangential>
[[gnu::always_inline]] inline bool testPair(const PairInputs<D>& in, DiskBlock<D>& bl, std::uint32_t i,
                                            const KernelVec<D>& xi, double ri, std::uint32_t k, std::uint32_t j,
                                            std::uint32_t nl) {
    KernelVec<D> d = xi - kernelVec(in.x[j]);
    if (in.shift[k] != PairList<D>::kNoShift) d += kernelVec(in.shiftVec[in.shift[k]]);
    const double rsum = ri + in.radius[j];
    const double dist2 = norm2(d);
    bl.owner[nl] = i;
    bl.partner[nl] = j;
    bl.slot[nl] = k;
    const Vec<D> ds = storedVec(d);
    for (int c = 0; c < D; ++c) bl.sep[c][nl] = ds[c];
    const bool touching = !(dist2 >= rsum * rsum);  // a NaN counts as touching: it must be seen
    if constexpr (Tangential::kHasHistory) {
        double* h = in.history[k].c.data();
        const std::uint64_t keep = std::uint64_t{0} - std::uint64_t{touching};
        for (int c = 0; c < D; ++c) {
            std::uint64_t b;
            __builtin_memcpy(&b, h + c, 8);
            b &= keep;
            __builtin_memcpy(h + c, &b, 8);
        }
    }
    return touching;
}

/// Step (1) over the block's particles [b0, b1), one pair at a time: the contact test of each listed pair, without
/// a branch on its outcome (testPair). Cross pairs (kCross, partner >= e) come from their slots, cross[c...].
/// Returns the number of touching pairs. The twin of findTouchingLanes, and the threaded path's.
template <int D, class Tangential, bool kCross>
[[gnu::noinline]] std::uint32_t findTouching(const PairInputs<D>& in, const std::uint32_t* first, std::size_t b0,
                                             std::size_t b1, std::size_t e, const CrossSlot<DiskEntry>* cross,
                                             std::size_t& c, DiskBlock<D>& bl) {
    std::uint32_t* entry = bl.entry.data();
    std::uint32_t nl = 0;
    KernelVec<D> xi;
    double ri = 0;
    walkBlock<kCross>(
        first, in.partner, b0, b1, e, cross, c, bl,
        [&](std::size_t i) __attribute__((always_inline)) {
            xi = kernelVec(in.x[i]);
            ri = in.radius[i];
        },
        [&](std::size_t i, std::uint32_t k, std::uint32_t j, std::uint32_t ne) __attribute__((always_inline)) {
            if constexpr (kCross) entry[nl] = ne;
            const bool touching = testPair<D, Tangential>(in, bl, static_cast<std::uint32_t>(i), xi, ri, k, j, nl);
            nl += touching;
            return touching;
        });
    return nl;
}

/// Step (1) over the block's particles [b0, b1) (no cross pairs), four listed pairs at a time in lanes, taken in
/// slot order across owners: the four contact tests give a mask; the touching pairs' fields are compacted by it
/// (core/lanes_pack.hpp) and stored at the end of the list, which grows by the mask's population; the springs of
/// the pairs not touching are cleared by the mask. The last listed pairs (fewer than four) go one pair at a time
/// (testPair). Same list as findTouching.
template <int D, class Tangential>
[[gnu::noinline]] std::uint32_t findTouchingLanes(const PairInputs<D>& in, const std::uint32_t* first, std::size_t b0,
                                                  std::size_t b1, DiskBlock<D>& bl) {
    const std::uint32_t k0 = first[b0], n = first[b1] - k0;
    const std::uint32_t* own = in.owner + k0;
    const std::uint32_t* partner = in.partner;
    std::uint32_t* outOwner = bl.owner.data();
    std::uint32_t* outPartner = bl.partner.data();
    std::uint32_t* outSlot = bl.slot.data();
    double* sep[D];
    for (int c = 0; c < D; ++c) sep[c] = bl.sep[c].data();
    constexpr std::uint32_t kNoShift4 = 0x01010101u * PairList<D>::kNoShift;
    LaneIndex last = {0, 0, 0, 0};
    std::uint32_t nl = 0, g = 0;
    auto onePair = [&](std::uint32_t k) {
        const std::uint32_t i = own[k - k0], j = partner[k];
        last = maxIndex(last, j);
        nl += testPair<D, Tangential>(in, bl, i, kernelVec(in.x[i]), in.radius[i], k, j, nl);
    };
    // The partners' rows that this pass and the law read, prefetched kAhead pairs ahead: the partners are not in
    // address order, and on a core with a small L2 (AMD Zen 4, 1 MB) waiting for them is a large share of the
    // step (bench/README.md, "Partners prefetched").
    constexpr std::uint32_t kAhead = 16;
    for (; 4 * g + 4 <= n; ++g) {
        const std::uint32_t k = k0 + 4 * g;
        const std::uint32_t* jj = partner + k;
        const LaneIndex vi = loadIndex(own + 4 * g);
        const LaneIndex vj = loadIndex(jj);
        if (k + 4 + kAhead <= in.nPairs)
            for (int l = 0; l < 4; ++l) {
                const std::uint32_t j = jj[kAhead + l];
                prefetch(&in.x[j]);
                prefetch(&in.v[j]);
                prefetch(&in.invMass[j]);
                if constexpr (Tangential::kHasHistory) {
                    prefetch(&in.w[j]);
                    prefetch(&in.sv[j]);
                    prefetch(&in.sw[j]);
                }
            }
        LaneVec<D> d = gather(in.x, vi) - gather(in.x, vj);
        const Lanes ri = gather(in.radius, vi);
        const Lanes rj = gather(in.radius, vj);
        std::uint32_t sh;
        __builtin_memcpy(&sh, in.shift + k, 4);
        if (sh != kNoShift4) {
            // Pairs across a periodic boundary: their shift added (as testPair does), the others' d kept.
            const LaneIndex code = widenBytes(sh);
            const LaneVec<D> sv = gather(in.shiftVec, code);
            const LaneMask none = equalTo(code, PairList<D>::kNoShift);
            for (int c = 0; c < D; ++c) d.c[c] = select(none, d.c[c], d.c[c] + sv.c[c]);
        }
        const Lanes dist2 = norm2(d);  // as norm2 of one pair: ((d0 d0 + d1 d1) + d2 d2)
        const Lanes rsum = ri + rj;
        const LaneMask touch = notGreaterEqual(dist2, rsum * rsum);  // NaN: touching
        const Compaction pack(bitsOf(touch));
        for (int c = 0; c < D; ++c) pack.store(sep[c] + nl, d.c[c]);
        pack.store(outOwner + nl, vi);
        pack.store(outPartner + nl, vj);
        pack.storeIota(outSlot + nl, k);
        last = maxIndex(last, vj);
        // Each lane's mask over its pair's spring (bitwise: a kept spring keeps its bits).
        if constexpr (Tangential::kHasHistory) clearRows<D>(in.history[k].c.data(), touch);
        nl += pack.count();
    }
    // The last pairs.
    for (std::uint32_t k = k0 + 4 * g; k < k0 + n; ++k) onePair(k);
    bl.reach = std::max<std::size_t>(std::size_t{maxLane(last)} + 1, b1);
    return nl;
}

/// Step (2): the law on the block's touching pairs [0, nl) (nl a multiple of 4 when kLanes): their springs go
/// back to the pair list, their contributions to the block's entries.
template <int D, class Normal, class Tangential, bool kCross, bool kLanes>
[[gnu::noinline]] void evalTouching(const PairInputs<D>& in, DiskBlock<D>& bl, std::uint32_t nl) {
    using Entry = DiskEntry;
    constexpr int A = kAngDim<D>;
    const std::uint32_t* owner = bl.owner.data();
    const std::uint32_t* partner = bl.partner.data();
    const std::uint32_t* slot = bl.slot.data();
    const std::uint16_t* material = in.material;
    const std::uint32_t nm = static_cast<std::uint32_t>(in.nMaterials);
    const std::uint32_t* entry = bl.entry.data();
    Entry* out = bl.out.data();
    Vec<D>* history = in.history;
    // Four touching pairs' inputs, gathered (lanes).
    struct Group {
        LaneVec<D> d, xi;
        Lanes ri, rj, invMi, invMj;
        RelMotion<LaneVec<D>, LaneVec<A>> rel;
    };
    auto load = [&](std::uint32_t m, Group & g) __attribute__((always_inline)) {
        const LaneIndex ii = loadIndex(owner + m), jj = loadIndex(partner + m);
        for (int k = 0; k < D; ++k) {
            Lanes::Values v;
            __builtin_memcpy(&v, bl.sep[k].data() + m, sizeof v);
            g.d.c[k] = Lanes(v);
        }
        g.xi = LaneVec<D>::zero();
        if constexpr (Tangential::kHasHistory) g.xi = gather(history, loadIndex(slot + m));
        g.ri = gather(in.radius, ii);
        g.rj = gather(in.radius, jj);
        // Each side's kinematics combined as soon as loaded (relMotion, in the same order).
        g.rel.dv = gather(in.v, ii) - gather(in.v, jj);
        if constexpr (Tangential::kHasHistory) {
            g.rel.wr = gather(in.w, ii) * g.ri + gather(in.w, jj) * g.rj;
            g.rel.dsv = gather(in.sv, ii) - gather(in.sv, jj);
            g.rel.swr = gather(in.sw, ii) * g.ri + gather(in.sw, jj) * g.rj;
        }
        g.invMi = gather(in.invMass, ii);
        g.invMj = gather(in.invMass, jj);
    };
    // Mostly the four pairs share one material pair: its coefficients broadcast, not gathered.
    auto coeffs = [&](std::uint32_t m) __attribute__((always_inline)) {
        if (in.uniform) return LanePairCoeffs(in.table[0]);
        LaneIndex cc;
        for (int l = 0; l < 4; ++l)
            cc[l] = static_cast<std::int32_t>(material[owner[m + l]] * nm + material[partner[m + l]]);
        return (cc[1] == cc[0] && cc[2] == cc[0] && cc[3] == cc[0]) ? LanePairCoeffs(in.table[cc[0]])
                                                                    : LanePairCoeffs(in.table, cc);
    };
    // Back to rows, one per pair: the spring, then the entry.
    auto store = [&](std::uint32_t m, const LaneVec<D>& xi, const LaneVec<D>& f, const LaneVec<A>& nxft, Lanes vir,
                     Lanes overlap) __attribute__((always_inline)) {
        const Lanes zero(0.0);
        Row r[4];
        if constexpr (Tangential::kHasHistory) {
            const Lanes h[4] = {xi.c[0], laneOr0(xi, 1), laneOr0(xi, 2), zero};
            transpose4(h, r[0].c, r[1].c, r[2].c, r[3].c);
            for (int l = 0; l < 4; ++l) {
                Vec<D> hv;
                for (int k = 0; k < D; ++k) hv[k] = r[l].c[k];
                history[slot[m + l]] = hv;
            }
        }
        Entry* o[4];
        for (int l = 0; l < 4; ++l) o[l] = out + (kCross ? entry[m + l] : m + l);
        const Lanes fa[4] = {f.c[0], laneOr0(f, 1), laneOr0(f, 2), vir};
        transpose4(fa, o[0]->a.c, o[1]->a.c, o[2]->a.c, o[3]->a.c);
        const Lanes nb[4] = {nxft.c[0], laneOr0(nxft, 1), laneOr0(nxft, 2), overlap};
        transpose4(nb, o[0]->b.c, o[1]->b.c, o[2]->b.c, o[3]->b.c);
    };
    std::uint32_t m = 0;
    // Eight pairs at a time, two groups of four side by side (Lanes2), then the last four. The law's chain of
    // square roots and divisions is long and about one group fits the processor's window, so two groups
    // interleaved overlap their chains (faster in the fastest windows of bench/tdm_chute.cpp). In 3D two groups'
    // 3-vectors need more than AVX2's 16 registers, so only with AVX-512's 32.
    constexpr bool kEight = kLanes && (D == 2 || kManyLaneRegisters);
    if constexpr (kEight) {
        for (; m + 8 <= nl; m += 8) {
            Group g0, g1;
            load(m, g0);
            load(m + 4, g1);
            const LanePairCoeffs2 c(coeffs(m), coeffs(m + 4));
            using L2 = Lanes2;
            const LaneVec<D, L2> d = joinLanes(g0.d, g1.d);
            LaneVec<D, L2> xi = joinLanes(g0.xi, g1.xi);
            RelMotion<LaneVec<D, L2>, LaneVec<A, L2>> rel;
            rel.dv = joinLanes(g0.rel.dv, g1.rel.dv);
            if constexpr (Tangential::kHasHistory) {
                rel.wr = joinLanes(g0.rel.wr, g1.rel.wr);
                rel.dsv = joinLanes(g0.rel.dsv, g1.rel.dsv);
                rel.swr = joinLanes(g0.rel.swr, g1.rel.swr);
            }
            LaneVec<D, L2> f;
            LaneVec<A, L2> nxft;
            L2 vir, overlap;
            contactLaw<Normal, Tangential>(c, d, norm2(d), L2(g0.ri, g1.ri), L2(g0.rj, g1.rj), L2(g0.invMi, g1.invMi),
                                           L2(g0.invMj, g1.invMj), rel, xi, in.clip, in.dt, f, nxft, vir, overlap);
            store(m, halfOf(xi, 0), halfOf(f, 0), halfOf(nxft, 0), vir.lo, overlap.lo);
            store(m + 4, halfOf(xi, 1), halfOf(f, 1), halfOf(nxft, 1), vir.hi, overlap.hi);
        }
    }
    for (; m < nl; m += kLanes ? 4 : 1) {
        if constexpr (kLanes) {
            Group g;
            load(m, g);
            LaneVec<D> f;
            LaneVec<A> nxft;
            Lanes vir, overlap;
            contactLaw<Normal, Tangential>(coeffs(m), g.d, norm2(g.d), g.ri, g.rj, g.invMi, g.invMj, g.rel, g.xi,
                                           in.clip, in.dt, f, nxft, vir, overlap);
            store(m, g.xi, f, nxft, vir, overlap);
        } else {
            using V = KernelVec<D>;
            const std::uint32_t i = owner[m], j = partner[m];
            Vec<D> ds;
            for (int k = 0; k < D; ++k) ds[k] = bl.sep[k][m];
            const V d = kernelVec(ds);
            V xi = V::zero();
            if constexpr (Tangential::kHasHistory) xi = kernelVec(history[slot[m]]);
            V f;
            KernelVec<A> nxft;
            double vir, overlap;
            contactLaw<Normal, Tangential>(
                in.table[material[i] * nm + material[j]], d, norm2(d), in.radius[i], in.radius[j], in.invMass[i],
                in.invMass[j],
                relMotion(kernelVec(in.v[i]), kernelVec(in.v[j]), kernelVec(in.w[i]), kernelVec(in.w[j]),
                          kernelVec(in.sv[i]), kernelVec(in.sv[j]), kernelVec(in.sw[i]), kernelVec(in.sw[j]),
                          in.radius[i], in.radius[j]),
                xi, in.clip, in.dt, f, nxft, vir, overlap);
            if constexpr (Tangential::kHasHistory) history[slot[m]] = storedVec(xi);
            Entry& o = out[kCross ? entry[m] : m];
            storeRow<D>(o.a.c, f);
            o.a.c[3] = vir;
            storeRow<A>(o.b.c, nxft);
            o.b.c[3] = overlap;
        }
    }
}

/// Elastic energy of listed pair k of disks or spheres (owner i) at the current state, by the normal law [J].
template <int D, class Normal>
double diskPairEnergy(const ForceContext<D>& ctx, std::size_t i, std::uint32_t k) {
    const Particles<D>& p = ctx.p;
    const PairList<D>& pl = ctx.pl;
    const std::uint32_t j = pl.partner[k];
    const Vec<D> d = p.x[i] - p.x[j] + pl.shiftVec[pl.shift[k]];
    const double rs = p.radius[i] + p.radius[j];
    const double delta = rs - norm(d);
    if (delta <= 0) return 0;
    const bool fi = p.frozen(i), fj = p.frozen(j);
    const double meff = fi ? p.mass[j] : (fj ? p.mass[i] : p.mass[i] * p.mass[j] / (p.mass[i] + p.mass[j]));
    return Normal::energy(ctx.cs.pair(p.material[i], p.material[j]), delta, meff, p.radius[i] * p.radius[j] / rs);
}

/// The contact network's record of a disk pair from the law's parts (DiskKernel::record; the disks among polygons).
template <int D>
void pairRecord(const PairInputs<D>& in, std::size_t i, std::uint32_t j, const LawParts<D>& parts,
                ContactRecord<D>& rec) {
    rec.i = static_cast<std::uint32_t>(i);
    rec.j = j;
    rec.wall = -1;
    rec.normal = storedVec(parts.normal);
    rec.fn = storedVec(parts.fn);
    rec.ft = storedVec(parts.ft);
    rec.branch = storedVec(parts.d);
    rec.overlap = parts.delta;
    rec.position = in.x[i];
    rec.point = in.x[i] - rec.normal * (in.radius[i] - 0.5 * parts.delta);
}

/// The kernel of the pair pass for disks and spheres (tdm/pair_pass.hpp has the interface): every pair by the
/// particles' law, four at a time in lanes (kLanes) or one by one; same bits either way. Its walls: DiskWall.
template <int D, class Normal, class Tangential, bool kLanes = kLanePairs>
class DiskKernel {
public:
    static constexpr int A = kAngDim<D>;
    static constexpr bool kOneByOne = false;  ///< the blocks' pairs in lanes
    using Entry = DiskEntry;
    /// A particle's force and sum of n x F_t (its torque is -r_i times that sum).
    struct Sum {
        KernelVec<D> f;
        KernelVec<A> a;
    };
    using Load = Sum;

    explicit DiskKernel(const ForceContext<D>& ctx)
        : in_(inputs(ctx)), first_(ctx.pl.first.data()), walls_(ctx), ctx_(ctx) {}

    [[gnu::always_inline]] static Load load(const Entry& x) { return {rowVec<D>(x.a.c), rowVec<A>(x.b.c)}; }
    [[gnu::always_inline]] static Sum sumOf(const Vec<D>& f, const Ang<D>& a) { return {kernelVec(f), kernelVec(a)}; }
    [[gnu::always_inline]] static void addOwner(Sum& s, const Load& l) {
        s.f += l.f;
        s.a += l.a;
    }
    [[gnu::always_inline]] static void addPartner(Vec<D>& f, Ang<D>& a, const Load& l) {
        f = storedVec(kernelVec(f) - l.f);
        a = storedVec(kernelVec(a) + l.a);
    }
    [[gnu::always_inline]] static KernelVec<D> forceOf(const Sum& s) { return s.f; }
    [[gnu::always_inline]] KernelVec<A> torqueOf(std::size_t i, const Sum& s) const { return s.a * (-in_.radius[i]); }
    const DiskWall<D, Normal, Tangential>& walls() const { return walls_; }

    /// One listed pair (a cross pair of the thread split; evalPair loads the partner itself).
    bool pair(std::size_t i, std::uint32_t k, std::uint32_t /*j*/, Entry& e) const {
        PairForce<D> pf;
        double overlap = 0, vir = 0;
        if (!evalPair<D, Normal, Tangential>(in_, Owner<D>(in_, i), k, pf, overlap, vir)) return false;
        storeRow<D>(e.a.c, pf.f);
        e.a.c[3] = vir;
        storeRow<A>(e.b.c, pf.nxft);
        e.b.c[3] = overlap;
        return true;
    }

    /// One listed pair as pair() evaluates it (the same bits), with the law's parts into rec (the contact network).
    bool record(std::size_t i, std::uint32_t k, std::uint32_t j, Entry& e, ContactRecord<D>& rec) const {
        PairForce<D> pf;
        LawParts<D> parts;
        double overlap = 0, vir = 0;
        if (!evalPair<D, Normal, Tangential>(in_, Owner<D>(in_, i), k, pf, overlap, vir, &parts)) return false;
        storeRow<D>(e.a.c, pf.f);
        e.a.c[3] = vir;
        storeRow<A>(e.b.c, pf.nxft);
        e.b.c[3] = overlap;
        pairRecord(in_, i, j, parts, rec);
        return true;
    }

    /// The block's entries: the contact tests (four at a time without cross pairs), then the law on the touching
    /// pairs. Returns the number of touching pairs, the entries' count in a block without cross pairs.
    template <bool kCrossBlock>
    [[gnu::always_inline]] std::uint32_t block(std::size_t b0, std::size_t b1, std::size_t e,
                                               const CrossSlot<Entry>* cross, std::size_t& c, DiskBlock<D>& bl) const {
        std::uint32_t nl;
        if constexpr (kLanes && !kCrossBlock)
            nl = findTouchingLanes<D, Tangential>(in_, first_, b0, b1, bl);
        else
            nl = findTouching<D, Tangential, kCrossBlock>(in_, first_, b0, b1, e, cross, c, bl);
        if (nl > 0) {
            std::uint32_t padded = nl;
            if constexpr (kLanes) {
                // The last lanes repeat the last pair: the same result, written twice to the same places.
                for (; padded % 4 != 0; ++padded) {
                    const std::uint32_t s = nl - 1;
                    bl.owner[padded] = bl.owner[s];
                    bl.partner[padded] = bl.partner[s];
                    bl.slot[padded] = bl.slot[s];
                    for (int k = 0; k < D; ++k) bl.sep[k][padded] = bl.sep[k][s];
                    bl.entry[padded] = bl.entry[s];
                }
            }
            evalTouching<D, Normal, Tangential, kCrossBlock, kLanes>(in_, bl, padded);
        }
        return nl;
    }

    double energy(std::size_t i, std::uint32_t k) const { return diskPairEnergy<D, Normal>(ctx_, i, k); }

private:
    static PairInputs<D> inputs(const ForceContext<D>& ctx) {
        if constexpr (kLanes) ctx.pl.makeOwners();  // the four-wide contact tests read each pair's owner
        return pairInputs(ctx.p, ctx.pl, ctx.cs, ctx.sv, ctx.sw, ctx.dt);
    }

    PairInputs<D> in_;
    const std::uint32_t* first_;
    DiskWall<D, Normal, Tangential> walls_;
    const ForceContext<D>& ctx_;
};

}  // namespace haet
