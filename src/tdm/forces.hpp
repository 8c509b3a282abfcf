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
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "contact/laws.hpp"
#include "contact/setup.hpp"
#include "core/lanes.hpp"
#include "core/particles.hpp"
#include "core/wide3.hpp"
#include "geometry/domain.hpp"
#include "neighbor/pair_list.hpp"

namespace haet {

struct ForceStats {
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::size_t contacts = 0;       ///< pair and wall contacts
    double maxOverlapRatio = 0;     ///< largest overlap / smaller radius
    std::size_t worstParticle = 0;  ///< particle with that overlap
    double virial = 0;              ///< sum over pair contacts of r_ij . F_ij, summed particle by particle [J]
    std::size_t nonFinite = kNone;  ///< first particle with a non-finite position or force, or kNone
};

/// What forceRange reports of its particles: ForceStats without the virial, which is summed per particle.
struct RangeTally {
    std::size_t contacts = 0;
    double maxOverlapRatio = 0;
    std::size_t worstParticle = 0;
    std::size_t nonFinite = ForceStats::kNone;
};

/// Folds a range's statistics into the step's; ranges come in particle order, so the result is the one-thread one.
inline void addTally(ForceStats& st, const RangeTally& t) {
    st.contacts += t.contacts;
    if (t.maxOverlapRatio > st.maxOverlapRatio) {
        st.maxOverlapRatio = t.maxOverlapRatio;
        st.worstParticle = t.worstParticle;
    }
    if (st.nonFinite == ForceStats::kNone) st.nonFinite = t.nonFinite;
}

/// What one pair adds to its owner (its partner gets -f and n x F_t): a cross pair evaluated before the ranges
/// run (threaded path), or an entry of a PairBlock.
template <int D>
struct CrossPair {
    Vec<D> f;        ///< force on i [N]
    Ang<D> nxft;     ///< n x F_t [N]
    double virial;   ///< r_ij . F_ij [N m]
    double overlap;  ///< overlap / smaller radius
    bool touching;
};

/// One thread's buffers for a block of particles in forceRange: the block's touching pairs as a list (in pair
/// order), and what each adds to its owner. A block holds at most kPairs listed pairs (more only when one particle
/// alone has more), so its buffers stay in L1.
template <int D>
struct PairBlock {
    static constexpr std::uint32_t kPairs = 128;              ///< listed pairs per block
    static constexpr std::uint32_t kOwners = 64;              ///< particles per block
    static constexpr std::uint32_t kNoPartner = 0xFFFFFFFFu;  ///< an entry taken from a cross pair's slot
    static constexpr std::uint32_t kNoOwner = 0xFFFFFFFFu;    ///< past the last touching pair
    /// Four doubles (a vector, zero-padded): the rows of four pairs are transposed into lanes and back.
    struct alignas(32) Row {
        double c[4];
    };
    /// What an entry adds to its owner: f = F on i in a (the virial r . F in a[3]); n x F_t in b (the overlap /
    /// smaller radius in b[3]).
    struct Entry {
        Row a, b;
    };
    // The touching pairs the law evaluates (list index m), padded to a multiple of 4, each field in an array of
    // its own (the lanes load four at once, and the contact tests store four at once): owner i, partner j, pair
    // slot k (whose spring stays in the pair list), the separation d = x_i - x_j (+ shift) component by component,
    // and (threaded) the entry each fills.
    std::vector<std::uint32_t> owner, partner, slot;
    std::vector<double> sep[D];
    std::vector<std::uint32_t> entry;
    // The entries of the block's owners, in pair order: evaluated pairs and (threaded) cross pairs.
    std::vector<Entry> out;
    std::vector<std::uint32_t> outPartner;  ///< j of each entry, kNoPartner for a cross pair
    /// Blocks with cross pairs: the block's particle b0 + q has entries [ownerEnd[q-1], ownerEnd[q]). Other blocks
    /// find a particle's touching pairs by their owner: owner[nl] = kNoOwner ends the list.
    std::vector<std::uint32_t> ownerEnd;
    std::size_t reach = 0;  ///< 1 + the largest partner of the block's pairs (cross pairs aside)

    /// Room for a block of `pairs` listed pairs.
    void fit(std::size_t pairs) {
        const std::size_t need = std::max<std::size_t>(pairs, kPairs) + 4;
        if (owner.size() >= need) return;
        owner.resize(need);
        partner.resize(need);
        slot.resize(need);
        for (auto& c : sep) c.resize(need);
        entry.resize(need);
        outPartner.resize(need);
        out.resize(need);
        ownerEnd.resize(kOwners + 1);
    }
};

/// Buffers of the threaded paths, kept between steps so that no step allocates (one thread needs none).
template <int D>
struct ForceScratch {
    std::vector<PairBlock<D>> blocks;  ///< one per thread (forceRange)
    std::vector<CrossPair<D>> cross;   ///< the disk loop's cross pairs (PairList::split)
    std::vector<double> virial;        ///< per particle: sum over own pairs of r_ij . F_ij [N m]
    std::vector<RangeTally> tally;     ///< the disk loop's per-range statistics
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
template <class Normal, class Tangential, class C, class S, class V, class A>
[[gnu::always_inline]] inline void contactLaw(const C& c, const V& d, S dist2, S ri, S rj, S invMi, S invMj,
                                              const RelMotion<V, A>& m, V& xi, bool clip, double dt, V& f, A& nxft,
                                              S& virial, S& overlap) {
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
    if constexpr (Tangential::kHasHistory) {
        // w x n lies in the contact plane already: only dv needs its normal part (gn) removed.
        const V gt = dv - nrm * gn - cross(m.wr, nrm);
        const V gs = m.dsv - cross(m.swr, nrm);
        const V ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, d, dist2, gt, gs, xi, dt);
        f += ft;
        nxft = cross(nrm, ft);
    } else {
        nxft = A::zero();
    }
    virial = dot(d, f);
    overlap = delta / minOf(ri, rj);
}

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
    V xi = V::zero();
    if constexpr (Tangential::kHasHistory) xi = kernelVec(in.history[k]);
    double vir, overlap;
    contactLaw<Normal, Tangential>(a.coeffRow[in.material[j]], d, dist2, ri, rj, a.invMass, in.invMass[j],
                                   relMotion(a.v, kernelVec(in.v[j]), a.w, kernelVec(in.w[j]), a.sv,
                                             kernelVec(in.sv[j]), a.sw, kernelVec(in.sw[j]), ri, rj),
                                   xi, in.clip, in.dt, out.f, out.nxft, vir, overlap);
    if constexpr (Tangential::kHasHistory) in.history[k] = storedVec(xi);
    virial += vir;
    overlapRatio = std::max(overlapRatio, overlap);
    return true;
}

/// What finishParticle reports of one particle.
struct ParticleTally {
    double worst;            ///< largest overlap / smaller radius, pairs and walls
    std::uint32_t contacts;  ///< own pairs and walls in contact
    bool finite;             ///< position and force finite
};

/// Whether every component of v is finite (inf - inf and NaN - NaN are NaN, anything else minus itself is 0).
template <int N>
[[gnu::always_inline]] inline bool allFinite(const Vec<N>& v) {
    double s = 0;
    for (int k = 0; k < N; ++k) s += v[k] - v[k];
    return s == 0;
}
inline bool allFinite(const Wide3& v) {
    const Wide3::Lanes z = v.l - v.l;
#ifdef __AVX__
    // One compare of the lanes with zero (false for NaN) and its sign bits.
    return (_mm256_movemask_pd(_mm256_cmp_pd(z, _mm256_setzero_pd(), _CMP_EQ_OQ)) & 7) == 7;
#else
    return (z[0] == 0) & (z[1] == 0) & (z[2] == 0);
#endif
}

/// Particle i's pair sums are complete (f: force, nx: sum of n x F_t): adds its wall contacts (in wall order),
/// stores force and torque -r_i (sum) + wall torques, then runs the caller's per-particle step then(i, f, torque).
template <int D, class Normal, class Tangential, class Then>
[[gnu::always_inline]] inline ParticleTally finishParticle(Particles<D>& p, const PairInputs<D>& in,
                                                           const Wall<D>* walls, std::size_t nw, Vec<D>* wallHistory,
                                                           const ContactSetup& cs, double time, std::size_t i,
                                                           KernelVec<D> fk, const KernelVec<kAngDim<D>>& nx,
                                                           double worst, std::uint32_t contacts, Then& then) {
    const double ri = in.radius[i];
    const KernelVec<D> xi = kernelVec(in.x[i]);
    const KernelVec<kAngDim<D>> tqk = nx * (-ri);
    // A NaN anywhere reaches the force of its particle in the same step.
    bool finite;
    if (nw > 0 && !(p.flags[i] & kFrozen)) {
        Vec<D> f = storedVec(fk);
        Ang<D> tq = storedVec(tqk);
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
        p.f[i] = f;
        p.torque[i] = tq;
        finite = allFinite(f + storedVec(xi));
    } else {
        p.f[i] = storedVec(fk);
        p.torque[i] = storedVec(tqk);
        finite = allFinite(fk + xi);
    }
    then(i, p.f[i], p.torque[i]);
    return {worst, contacts, finite};
}

/// Whether the contact law runs on four touching pairs at once (core/lanes.hpp): with AVX2, whose gathers load
/// the four pairs' data. Otherwise the pairs of a block are evaluated one by one. Same bits either way.
#ifdef __AVX2__
inline constexpr bool kLanePairs = true;
#else
inline constexpr bool kLanePairs = false;
#endif

/// A vector into a zero-padded row of PairBlock.
template <int D>
inline void storeRow(double* row, const KernelVec<D>& v) {
#ifdef __AVX__
    if constexpr (D == 3) {
        _mm256_store_pd(row, v.l);
        return;
    }
#endif
    const Vec<D> a = storedVec(v);
    for (int k = 0; k < 4; ++k) row[k] = k < D ? a[k] : 0.0;
}

/// The first N numbers of a row as a vector.
template <int N>
inline KernelVec<N> rowVec(const double* row) {
#ifdef __AVX__
    if constexpr (N == 3) return Wide3{_mm256_blend_pd(_mm256_load_pd(row), _mm256_setzero_pd(), 8)};
#endif
    Vec<N> a;
    for (int k = 0; k < N; ++k) a[k] = row[k];
    return kernelVec(a);
}

/// The contact test of listed pair k (owner i at xi with radius ri, partner j), written at place nl of the block's
/// list of touching pairs whatever its outcome (the list grows by one when it touches). The pair's spring stays in
/// the pair list; a pair not touching has it cleared there (by a mask, without a branch). Returns whether the pair
/// touches.
template <int D, class Tangential>
[[gnu::always_inline]] inline bool testPair(const PairInputs<D>& in, PairBlock<D>& bl, std::uint32_t i,
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

/// Pass (1) over the block's particles [b0, b1), one pair at a time: the contact test of each listed pair, without
/// a branch on its outcome (testPair). Cross pairs (kCross, partner >= e) come from their slots, cross[c...].
/// Returns the number of touching pairs. The twin of findTouchingLanes, and the threaded path's.
template <int D, class Tangential, bool kCross>
[[gnu::noinline]] std::uint32_t findTouching(const PairInputs<D>& in, const std::uint32_t* first, std::size_t b0,
                                             std::size_t b1, std::size_t e, const CrossPair<D>* cross, std::size_t& c,
                                             PairBlock<D>& bl) {
    using Block = PairBlock<D>;
    const std::uint32_t* partner = in.partner;
    std::uint32_t* entry = bl.entry.data();
    std::uint32_t* outPartner = bl.outPartner.data();
    std::uint32_t nl = 0, ne = 0, last = 0;
    for (std::size_t i = b0; i < b1; ++i) {
        const KernelVec<D> xi = kernelVec(in.x[i]);
        const double ri = in.radius[i];
        for (std::uint32_t k = first[i]; k < first[i + 1]; ++k) {
            const std::uint32_t j = partner[k];
            if constexpr (kCross) {
                if (j >= e) {  // evaluated before, in its slot
                    const CrossPair<D>& q = cross[c++];
                    if (!q.touching) continue;
                    typename Block::Entry& o = bl.out[ne];
                    storeRow<D>(o.a.c, kernelVec(q.f));
                    o.a.c[3] = q.virial;
                    storeRow<kAngDim<D>>(o.b.c, kernelVec(q.nxft));
                    o.b.c[3] = q.overlap;
                    outPartner[ne++] = Block::kNoPartner;
                    continue;
                }
            }
            last = std::max(last, j);
            if constexpr (kCross) {
                entry[nl] = ne;
                outPartner[ne] = j;
            }
            const bool touching = testPair<D, Tangential>(in, bl, static_cast<std::uint32_t>(i), xi, ri, k, j, nl);
            nl += touching;
            ne += touching;
        }
        if constexpr (kCross) bl.ownerEnd[i - b0] = ne;
    }
    bl.reach = std::max<std::size_t>(std::size_t{last} + 1, b1);
    return nl;
}

#ifdef __AVX2__
/// For each mask of four lanes, its set lanes in order (then zeros): the compaction of four pairs to the touching
/// ones: i32 moves four 32-bit numbers, i64 four doubles (as pairs of 32-bit halves).
struct CompactTables {
    alignas(16) std::int32_t i32[16][4];
    alignas(32) std::int32_t i64[16][8];
    constexpr CompactTables() : i32{}, i64{} {
        for (int m = 0; m < 16; ++m) {
            int n = 0;
            for (int l = 0; l < 4; ++l)
                if (m >> l & 1) {
                    i32[m][n] = l;
                    i64[m][2 * n] = 2 * l;
                    i64[m][2 * n + 1] = 2 * l + 1;
                    ++n;
                }
        }
    }
};
inline constexpr CompactTables kCompact{};

/// Pass (1) over the block's particles [b0, b1) (one thread: no cross pairs), four listed pairs at a time in AVX
/// lanes, taken in slot order across owners: the four contact tests give a mask; the touching pairs' fields are
/// compacted by it (a table of lane permutations) and stored at the end of the list, which grows by the mask's
/// population; the springs of the pairs not touching are cleared by the mask. The last listed pairs (fewer than
/// four) go one pair at a time (testPair). Same list as findTouching.
template <int D, class Tangential>
[[gnu::noinline]] std::uint32_t findTouchingLanes(const PairInputs<D>& in, const std::uint32_t* first, std::size_t b0,
                                                  std::size_t b1, PairBlock<D>& bl) {
    const std::uint32_t k0 = first[b0], n = first[b1] - k0;
    const std::uint32_t* own = in.owner + k0;
    const std::uint32_t* partner = in.partner;
    std::uint32_t* outOwner = bl.owner.data();
    std::uint32_t* outPartner = bl.partner.data();
    std::uint32_t* outSlot = bl.slot.data();
    double* sep[D];
    for (int c = 0; c < D; ++c) sep[c] = bl.sep[c].data();
    constexpr std::uint32_t kNoShift4 = 0x01010101u * PairList<D>::kNoShift;
    __m128i last = _mm_setzero_si128();
    std::uint32_t nl = 0, g = 0;
    auto onePair = [&](std::uint32_t k) {
        const std::uint32_t i = own[k - k0], j = partner[k];
        last = _mm_max_epu32(last, _mm_cvtsi32_si128(static_cast<int>(j)));
        nl += testPair<D, Tangential>(in, bl, i, kernelVec(in.x[i]), in.radius[i], k, j, nl);
    };
    // The partners' rows that this pass and the law read, prefetched kAhead pairs ahead: the partners are not in
    // address order, and on a core with a 1 MB L2 (AMD Zen 4) waiting for them took about a fifth of the step
    // (bench/README.md, "Partners prefetched").
    constexpr std::uint32_t kAhead = 16;
    for (; 4 * g + 4 <= n; ++g) {
        const std::uint32_t k = k0 + 4 * g;
        const std::uint32_t* ii = own + 4 * g;
        const std::uint32_t* jj = partner + k;
        const __m128i vi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ii));
        const __m128i vj = _mm_loadu_si128(reinterpret_cast<const __m128i*>(jj));
        if (k + 4 + kAhead <= in.nPairs)
            for (int l = 0; l < 4; ++l) {
                const std::uint32_t j = jj[kAhead + l];
                __builtin_prefetch(&in.x[j]);
                __builtin_prefetch(&in.v[j]);
                __builtin_prefetch(&in.invMass[j]);
                if constexpr (Tangential::kHasHistory) {
                    __builtin_prefetch(&in.w[j]);
                    __builtin_prefetch(&in.sv[j]);
                    __builtin_prefetch(&in.sw[j]);
                }
            }
        const LaneVec<D> xi = gather(in.x, reinterpret_cast<LaneIndex>(vi));
        const LaneVec<D> xj = gather(in.x, reinterpret_cast<LaneIndex>(vj));
        const __m256d ri = gather(in.radius, reinterpret_cast<LaneIndex>(vi)).v;
        const __m256d rj = gather(in.radius, reinterpret_cast<LaneIndex>(vj)).v;
        __m256d d[D];
        for (int c = 0; c < D; ++c) d[c] = _mm256_sub_pd(xi.c[c].v, xj.c[c].v);
        std::uint32_t sh;
        __builtin_memcpy(&sh, in.shift + k, 4);
        if (sh != kNoShift4) {
            // Pairs across a periodic boundary: their shift added (as testPair does), the others' d kept.
            const __m128i code = _mm_cvtepu8_epi32(_mm_cvtsi32_si128(static_cast<int>(sh)));
            const LaneVec<D> sv = gather(in.shiftVec, reinterpret_cast<LaneIndex>(code));
            const __m256d none = _mm256_castsi256_pd(
                _mm256_cvtepi32_epi64(_mm_cmpeq_epi32(code, _mm_set1_epi32(PairList<D>::kNoShift))));
            for (int c = 0; c < D; ++c) d[c] = _mm256_blendv_pd(_mm256_add_pd(d[c], sv.c[c].v), d[c], none);
        }
        __m256d dist2 = _mm256_mul_pd(d[0], d[0]);  // as norm2: ((d0 d0 + d1 d1) + d2 d2)
        for (int c = 1; c < D; ++c) dist2 = _mm256_add_pd(dist2, _mm256_mul_pd(d[c], d[c]));
        const __m256d rsum = _mm256_add_pd(ri, rj);
        const __m256d touch = _mm256_cmp_pd(dist2, _mm256_mul_pd(rsum, rsum), _CMP_NGE_UQ);  // NaN: touching
        const unsigned m = static_cast<unsigned>(_mm256_movemask_pd(touch));
        const __m256i p64 = _mm256_load_si256(reinterpret_cast<const __m256i*>(kCompact.i64[m]));
        const __m128i p32 = _mm_load_si128(reinterpret_cast<const __m128i*>(kCompact.i32[m]));
        for (int c = 0; c < D; ++c)
            _mm256_storeu_pd(sep[c] + nl, _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(d[c]), p64)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(outOwner + nl),
                         _mm_castps_si128(_mm_permutevar_ps(_mm_castsi128_ps(vi), p32)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(outPartner + nl),
                         _mm_castps_si128(_mm_permutevar_ps(_mm_castsi128_ps(vj), p32)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(outSlot + nl),
                         _mm_add_epi32(_mm_set1_epi32(static_cast<int>(k)), p32));
        last = _mm_max_epu32(last, vj);
        if constexpr (Tangential::kHasHistory) {
            // Each lane's mask over its pair's D doubles of the spring (bitwise: a kept spring keeps its bits).
            double* h = in.history[k].c.data();
            if constexpr (D == 3) {
                _mm256_storeu_pd(h, _mm256_and_pd(_mm256_loadu_pd(h), _mm256_permute4x64_pd(touch, 0x40)));
                _mm256_storeu_pd(h + 4, _mm256_and_pd(_mm256_loadu_pd(h + 4), _mm256_permute4x64_pd(touch, 0xA5)));
                _mm256_storeu_pd(h + 8, _mm256_and_pd(_mm256_loadu_pd(h + 8), _mm256_permute4x64_pd(touch, 0xFE)));
            } else {
                _mm256_storeu_pd(h, _mm256_and_pd(_mm256_loadu_pd(h), _mm256_permute4x64_pd(touch, 0x50)));
                _mm256_storeu_pd(h + 4, _mm256_and_pd(_mm256_loadu_pd(h + 4), _mm256_permute4x64_pd(touch, 0xFA)));
            }
        }
        nl += static_cast<std::uint32_t>(__builtin_popcount(m));
    }
    // The last pairs.
    for (std::uint32_t k = k0 + 4 * g; k < k0 + n; ++k) onePair(k);
    last = _mm_max_epu32(last, _mm_shuffle_epi32(last, 0x4E));
    last = _mm_max_epu32(last, _mm_shuffle_epi32(last, 0xB1));
    bl.reach = std::max<std::size_t>(std::size_t{static_cast<std::uint32_t>(_mm_cvtsi128_si32(last))} + 1, b1);
    return nl;
}
#endif

/// Pass (2): the law on the block's touching pairs [0, nl) (nl a multiple of 4 when kLanes): their springs go
/// back to the pair list, their contributions to the block's entries.
template <int D, class Normal, class Tangential, bool kCross, bool kLanes>
[[gnu::noinline]] void evalTouching(const PairInputs<D>& in, PairBlock<D>& bl, std::uint32_t nl) {
    using Row = typename PairBlock<D>::Row;
    using Entry = typename PairBlock<D>::Entry;
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
    // interleaved overlap their chains: the 2D chute's time per particle-step is ~6 % less (the minimum of 40
    // windows, bench/tdm_chute.cpp, two runs of 6 and 8 alternating rounds: 0.938, 0.944). In 3D two groups'
    // 3-vectors need more than AVX2's 16 registers, so only with AVX-512's 32: 1-2 % less on AMD Zen 4 (8 rounds
    // twice: fastest windows 52.07 and 52.68 ns against 53.14 and 53.67); on the Intel Xeon measured before,
    // 1.013.
#ifdef __AVX512VL__
    constexpr bool kEight = kLanes;
#else
    constexpr bool kEight = kLanes && D == 2;
#endif
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

/// The pass over particles [b, e), which holds every partner of their pairs except the cross pairs (kCross:
/// partner >= e), evaluated before into cross[c0...] in pair order; crossIn: the cross pairs whose partner is in
/// [b, e), by partner then pair. Per-particle virial sums go to virial[i] when a thread split needs them kept
/// apart, else into *virialSum (in particle order either way).
///
/// The particles go in blocks of a few dozen, each in three passes: (1) the contact tests, without a branch on
/// their outcome (findTouchingLanes, four at a time; findTouching); (2) the contact law on the touching pairs, four at
/// a time in lanes (evalTouching), where their long chains of square roots and divisions overlap instead of waiting one
/// behind the other; (3) in pair order, as when each pair was evaluated as its owner came, each contribution added to
/// its owner and subtracted from its partner, and each particle finished. The law reads positions and velocities only,
/// which no particle of the block or after it has had changed yet (finishing changes a particle's velocity, after its
/// last pair), so the passes give the same bits as one pair at a time.
template <int D, class Normal, class Tangential, bool kCross, bool kLanes, class Then>
[[gnu::always_inline]] inline RangeTally forceRange(Particles<D>& p, const PairInputs<D>& in,
                                                    const std::uint32_t* first, const Wall<D>* walls, std::size_t nw,
                                                    Vec<D>* wh, const ContactSetup& cs, double time, const Vec<D>& g,
                                                    std::size_t b, std::size_t e, const CrossPair<D>* cross,
                                                    std::size_t c0, const std::uint64_t* crossIn,
                                                    const std::uint64_t* crossInEnd, double* virial, double* virialSum,
                                                    PairBlock<D>& bl, Then& then) {
    using Block = PairBlock<D>;
    Vec<D>* f = p.f.data();
    Ang<D>* nx = p.torque.data();  // holds the sums of n x F_t until the particle is finished
    const double* mass = p.mass.data();
    // A particle's sums start (gravity, then the cross pairs where it is the partner) just before the first block
    // whose pairs add to them: particles [b, done) have started. Starting the sums there, not in a pass of their
    // own, keeps them in cache until they are used.
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
    double virialAcc = kCross ? 0.0 : *virialSum;  // the one-thread sum, in particle order
    std::size_t c = c0;
    for (std::size_t b0 = b, b1; b0 < e; b0 = b1) {
        b1 = b0 + 1;
        while (b1 < e && b1 - b0 < Block::kOwners && first[b1 + 1] - first[b0] <= Block::kPairs) ++b1;
        // A whole number of fours (but for the range's last block): the step on the block goes four at a time.
        if (b1 < e && b1 - b0 >= 4) b1 = b0 + ((b1 - b0) & ~std::size_t{3});
        bl.fit(first[b1] - first[b0]);
        // The block's three steps; kCrossBlock: some of its pairs are cross pairs (their partner lies beyond e),
        // taken from their slots in pair order, so the tests go one pair at a time.
        auto runBlock = [&]<bool kCrossBlock>() __attribute__((always_inline)) {
            std::uint32_t nl;
#ifdef __AVX2__
            if constexpr (kLanes && !kCrossBlock)
                nl = findTouchingLanes<D, Tangential>(in, first, b0, b1, bl);
            else
#endif
                nl = findTouching<D, Tangential, kCrossBlock>(in, first, b0, b1, e, cross, c, bl);
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
                evalTouching<D, Normal, Tangential, kCrossBlock, kLanes>(in, bl, padded);
            }
            // (3) The sums, in pair order, and each particle finished. Without cross pairs a particle's touching
            // pairs are the next ones with it as owner (the list ends with kNoOwner); with them, the entries up to
            // ownerEnd.
            if constexpr (!kCrossBlock) bl.owner[nl] = Block::kNoOwner;
            const typename Block::Entry* out = bl.out.data();
            const std::uint32_t* outPartner = bl.outPartner.data();
            const std::uint32_t* partner = bl.partner.data();
            const std::uint32_t* owner = bl.owner.data();
            // Every particle that the block's pairs add to starts here, once for the block.
            startUpTo(bl.reach);
            std::uint32_t t = 0;
            for (std::size_t i = b0; i < b1; ++i) {
                KernelVec<D> fi = kernelVec(f[i]);
                KernelVec<kAngDim<D>> nxi = kernelVec(nx[i]);
                double worst = 0, vir = 0;
                std::uint32_t nc = 0;
                const std::uint32_t tEnd = kCrossBlock ? bl.ownerEnd[i - b0] : 0;
                for (; kCrossBlock ? t < tEnd : owner[t] == static_cast<std::uint32_t>(i); ++t) {
                    const typename Block::Entry& x = out[t];
                    const KernelVec<D> pf = rowVec<D>(x.a.c);
                    const KernelVec<kAngDim<D>> pn = rowVec<kAngDim<D>>(x.b.c);
                    fi += pf;
                    nxi += pn;
                    const std::uint32_t j = kCrossBlock ? outPartner[t] : partner[t];
                    if (!kCrossBlock || j != Block::kNoPartner) {
                        f[j] = storedVec(kernelVec(f[j]) - pf);
                        nx[j] = storedVec(kernelVec(nx[j]) + pn);
                    }
                    vir += x.a.c[3];
                    worst = std::max(worst, x.b.c[3]);
                    ++nc;
                }
                const ParticleTally pt =
                    finishParticle<D, Normal, Tangential>(p, in, walls, nw, wh, cs, time, i, fi, nxi, worst, nc, then);
                st.contacts += pt.contacts;
                if constexpr (kCross)
                    virial[i] = vir;
                else
                    virialAcc += vir;
                if (pt.worst > st.maxOverlapRatio) {
                    st.maxOverlapRatio = pt.worst;
                    st.worstParticle = i;
                }
                if (!pt.finite && st.nonFinite == ForceStats::kNone) st.nonFinite = i;
            }
        };
        if constexpr (kCross) {
            // Most blocks of a range have no cross pair (those lie along the face between two ranges): their
            // pairs go the one-thread way.
            const std::uint32_t* pb = in.partner + first[b0];
            const std::uint32_t* pe = in.partner + first[b1];
            if (pb != pe && *std::max_element(pb, pe) >= e)
                runBlock.template operator()<true>();
            else
                runBlock.template operator()<false>();
        } else {
            runBlock.template operator()<false>();
        }
        // A step on the whole block, now that its particles are finished (VelocityVerlet::CorrectPredict).
        if constexpr (requires { then.finishBlock(b0, b1); }) then.finishBlock(b0, b1);
    }
    if constexpr (!kCross) *virialSum = virialAcc;
    return st;
}

/// Forces at the predicted state. sv/sw: mean velocities over the last step (StepMotion), which increment
/// the tangential springs; the damping terms use the predicted velocities p.v, p.w. then(i) runs once particle
/// i's force and torque are final, with them: then(i, f, torque) (it may change i's velocities, not its position;
/// nothing reads them after). kLanes: the law on four pairs at once (kLanePairs) or one by one, for tests that
/// hold the two to the same bits.
template <int D, class Normal, class Tangential, bool kLanes = kLanePairs, class Then>
ForceStats computeForces(Particles<D>& p, PairList<D>& pl, const std::vector<Wall<D>>& walls,
                         std::vector<Vec<D>>& wallHistory, const ContactSetup& cs, const Domain<D>& dom, double time,
                         double dt, const Vec<D>* sv, const Ang<D>* sw, ForceScratch<D>& s, Then then) {
    const std::size_t n = p.tdmCount();
    if constexpr (kLanes) pl.makeOwners();
    const PairInputs<D> in = pairInputs(p, pl, cs, sv, sw, dt);
    const std::uint32_t* first = pl.first.data();
    Vec<D>* wh = wallHistory.data();
    const Wall<D>* wp = walls.data();
    const std::size_t nw = walls.size();
    const Vec<D> g = dom.gravity;
    const int nt = n >= kParallelMin ? omp_get_max_threads() : 1;
    ForceStats st;

    if (s.blocks.size() < static_cast<std::size_t>(nt)) s.blocks.resize(static_cast<std::size_t>(nt));
    if (nt <= 1) {
        const RangeTally t =
            forceRange<D, Normal, Tangential, false, kLanes>(p, in, first, wp, nw, wh, cs, time, g, 0, n, nullptr, 0,
                                                             nullptr, nullptr, nullptr, &st.virial, s.blocks[0], then);
        addTally(st, t);
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
            tally[r] = forceRange<D, Normal, Tangential, true, kLanes>(
                p, in, first, wp, nw, wh, cs, time, g, sp.start[r], sp.start[r + 1], cross, sp.crossFirst[r],
                ci + sp.crossInFirst[r], ci + sp.crossInFirst[r + 1], s.virial.data(), nullptr,
                s.blocks[static_cast<std::size_t>(r)], then);
        }
    }
    // The one-thread reductions, in the same order.
    for (const RangeTally& t : s.tally) addTally(st, t);
    for (std::size_t i = 0; i < n; ++i) st.virial += s.virial[i];
    return st;
}

}  // namespace haet
