#pragma once
// The pair pass: one driver over a contact kernel, for every kind of pair the time-driven engine evaluates (disks
// and spheres in lanes, tdm/disk_kernel.hpp; polygons, polygon/polygon_kernel.hpp) and its wall contacts
// (tdm/wall_kernel.hpp). The driver owns the blocks, the cross pairs of the thread split, the order of the sums and
// the finishing of particles; a kernel says what one touching pair adds to its two particles (ARCHITECTURE.md,
// "Adding a contact kernel").
//
// Results do not depend on the thread count: every particle sums its contributions in one fixed order — gravity,
// then the pairs in which it is the partner j (by increasing pair index), then its own pairs, then its wall
// contacts. One pass over particles in index order produces it: each pair's contribution is added to both
// particles (scatter) as its owner i comes. Once its sums are complete a particle is finished at once
// (finishParticle: walls, torque, statistics, the caller's per-particle step such as the Verlet corrector), so a
// step reads the particles once: particle i's sums are complete right after its own pairs, since its partners
// j > i come later and never see it again, and the pairs where it is the partner came before.
// With T threads the particles are cut into T contiguous ranges (PairList::split) and each thread runs that pass
// over its range. Only the "cross" pairs, whose partner lies in a later range, reach outside a range; they are
// evaluated first, each into its own slot. A range then adds the cross pairs in which its particles are partners
// (in pair order: they all precede the range's own pairs), and takes its own cross pairs from their slots in
// their place among its pairs. Same additions in the same order as with one thread, so the same bits. After a
// spatial sort the ranges are slabs of space and the cross pairs lie along their faces: a few per cent.
//
// The kernel K (a class; every member is inlined into the pass):
//   K::Entry           what one touching pair adds; entry.virial() (r_ij . F_ij) and entry.overlap() (its overlap
//                      over the smaller radius) are read by the pass
//   K::Load            an entry's contribution, loaded once for owner and partner: K::load(entry)
//   K::Sum             a particle's running sums: K::sumOf(f, a) from the stored ones, K::addOwner(sum, load),
//                      K::addPartner(f, a, load) into the stored ones of the partner, K::forceOf(sum)
//   k.torqueOf(i, sum) the torque of the pair sums
//   k.pair(i, k, j, e) one listed pair (slot k of owner i, partner j): whether it touches, its entry
//   K::kOneByOne       true: the pass evaluates the pairs one by one as their owner comes (k.pair) and adds each
//                      at once; false: block by block, the kernel filling a block's entries first:
//   k.block<kCross>(b0, b1, e, cross, c, bl)  the entries of the block's pairs (see PairBlock), the cross pairs
//                      (kCross: partner >= e) taken from cross[c...]; returns the entries' count
//   k.walls()          the wall kernel W: W.add(i, w, f, torque, worst) adds plane w's contact (returns whether
//                      it touches); W.energy(i, w) its elastic energy [J]; W.addSurfaces(i, f, torque, worst)
//                      the contacts with walls of any shape (returns how many), W.surfaceEnergy(i) theirs
//   k.energy(i, k)     the elastic energy of listed pair k [J] at the current state
// The storage between a kernel's pairs and its particles' sums is the particles' f and torque arrays: the pass
// starts them (gravity, zero), the kernel adds to them, the pass stores the final force and torque there.
#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "contact/setup.hpp"
#include "core/lanes_pack.hpp"
#include "core/particles.hpp"
#include "core/wide3.hpp"
#include "geometry/domain.hpp"
#include "neighbor/pair_list.hpp"
#include "tdm/contact_record.hpp"
#include "tdm/force_stats.hpp"
#include "tdm/pair_block.hpp"
#include "tdm/surface_state.hpp"

namespace haet {

/// What one evaluation of the forces reads and writes: the particles (forces and torques written), the pair list
/// (its springs updated), the walls with their springs, the coefficients, the state's time and the step.
template <int D>
struct ForceContext {
    Particles<D>& p;
    PairList<D>& pl;
    const Wall<D>* walls;
    std::size_t nWalls;
    Vec<D>* wallHistory;  ///< spring of particle i at wall w: [i * nWalls + w] [m]
    const ContactSetup& cs;
    Vec<D> gravity;    ///< [m/s^2]
    double time;       ///< [s]
    double dt;         ///< [s]
    const Vec<D>* sv;  ///< mean velocities over the last step (StepMotion): they increment the springs [m/s]
    const Ang<D>* sw;  ///< [rad/s]
    Vec<D>* planeForce = nullptr;         ///< null, or each plane contact's force on its particle [N]: [i nWalls + w]
    SurfaceState<D>* surfaces = nullptr;  ///< null, or the walls of any shape with the particles' contacts
    /// null, or where the pass puts every contact it evaluates (the contact network; the pass then runs on one
    /// thread through the kernel's record(), the same bits as its blocks: recordingPass)
    ContactSink<D>* contacts = nullptr;
    /// null, or per particle whether it may touch a plane (0: it cannot before the next pair-list build, and its
    /// plane springs and forces are zero: the planes are skipped, which adds nothing, as their test would)
    const std::uint8_t* nearPlanes = nullptr;
};

template <int D>
ForceContext<D> forceContext(Particles<D>& p, PairList<D>& pl, const std::vector<Wall<D>>& walls,
                             std::vector<Vec<D>>& wallHistory, const ContactSetup& cs, const Domain<D>& dom,
                             double time, double dt, const Vec<D>* sv, const Ang<D>* sw) {
    return {p, pl, walls.data(), walls.size(), wallHistory.data(), cs, dom.gravity, time, dt, sv, sw};
}

/// The pairs of a block [b0, b1) in pair order, for kernels that take them one by one: onOwner(i) before owner i's
/// pairs, onPair(i, k, j, t) -> whether listed pair k (partner j) touches, having written entry t when it does.
/// With kCross the pairs whose partner is >= e are taken from their slots cross[c...], and the block's outPartner and
/// ownerEnd are written (PairBlock). Sets the block's reach; returns the number of entries.
template <bool kCross, int D, class Entry, class OnOwner, class OnPair>
[[gnu::always_inline]] inline std::uint32_t walkBlock(const std::uint32_t* first, const std::uint32_t* partner,
                                                      std::size_t b0, std::size_t b1, std::size_t e,
                                                      const CrossSlot<Entry>* cross, std::size_t& c,
                                                      PairBlock<D, Entry>& bl, OnOwner&& onOwner, OnPair&& onPair) {
    using Block = PairBlock<D, Entry>;
    std::uint32_t ne = 0, last = 0;
    for (std::size_t i = b0; i < b1; ++i) {
        onOwner(i);
        for (std::uint32_t k = first[i]; k < first[i + 1]; ++k) {
            const std::uint32_t j = partner[k];
            if constexpr (kCross) {
                if (j >= e) {  // evaluated before, in its slot
                    const CrossSlot<Entry>& q = cross[c++];
                    if (!q.touching) continue;
                    bl.out[ne] = q.e;
                    bl.outPartner[ne++] = Block::kNoPartner;
                    continue;
                }
                bl.outPartner[ne] = j;
            }
            last = std::max(last, j);
            ne += onPair(i, k, j, ne);
        }
        if constexpr (kCross) bl.ownerEnd[i - b0] = ne;
    }
    bl.reach = std::max<std::size_t>(std::size_t{last} + 1, b1);
    return ne;
}

/// What finishing a particle reads and writes, taken once per range.
template <int D>
struct FinishViews {
    Vec<D>* f;
    Ang<D>* torque;
    const Vec<D>* x;
    const std::uint8_t* flags;
    const std::uint8_t* nearPlanes;
    std::size_t nWalls;
    bool surfaces;
    explicit FinishViews(const ForceContext<D>& ctx)
        : f(ctx.p.f.data()),
          torque(ctx.p.torque.data()),
          x(ctx.p.x.data()),
          flags(ctx.p.flags.data()),
          nearPlanes(ctx.nearPlanes),
          nWalls(ctx.nWalls),
          surfaces(ctx.surfaces != nullptr) {}
};

/// Particle i's pair sums are complete: adds its wall contacts (planes in wall order, unless it is far from them all,
/// then the walls of any shape; not for a frozen particle), stores
/// force and torque, then runs the caller's per-particle step then(i, f, torque).
template <int D, class K, class Then>
[[gnu::always_inline]] inline ParticleTally finishParticle(const FinishViews<D>& fv, const K& kernel, std::size_t i,
                                                           const typename K::Sum& s, double worst,
                                                           std::uint32_t contacts, Then& then) {
    const KernelVec<D> fk = K::forceOf(s);
    const KernelVec<kAngDim<D>> tqk = kernel.torqueOf(i, s);
    const KernelVec<D> xi = kernelVec(fv.x[i]);
    // A NaN anywhere reaches the force of its particle in the same step.
    bool finite;
    // A particle far from every plane skips them (ForceContext::nearPlanes): most of a deep bed.
    const std::size_t nw = fv.nearPlanes && !fv.nearPlanes[i] ? 0 : fv.nWalls;
    if ((nw > 0 || fv.surfaces) && !(fv.flags[i] & kFrozen)) {
        Vec<D> f = storedVec(fk);
        Ang<D> tq = storedVec(tqk);
        const auto& walls = kernel.walls();
        for (std::size_t w = 0; w < nw; ++w) contacts += walls.add(i, w, f, tq, worst);
        if (fv.surfaces) contacts += walls.addSurfaces(i, f, tq, worst);
        fv.f[i] = f;
        fv.torque[i] = tq;
        finite = allFinite(f + storedVec(xi));
    } else {
        fv.f[i] = storedVec(fk);
        fv.torque[i] = storedVec(tqk);
        finite = allFinite(fk + xi);
    }
    then(i, fv.f[i], fv.torque[i]);
    return {worst, contacts, finite};
}

/// One range of the pass: particles [b, e), which hold every partner of their pairs except the cross pairs (kCross:
/// partner >= e), evaluated before into cross[c0...] in pair order; crossIn: the cross pairs whose partner is in
/// [b, e), by partner then pair. Per-particle virial sums go to virial[i] when a thread split needs them kept apart,
/// else into *virialSum (in particle order either way).
template <class Entry>
struct PassRange {
    std::size_t b, e;
    const CrossSlot<Entry>* cross;
    std::size_t c0;
    const std::uint64_t* crossIn;
    const std::uint64_t* crossInEnd;
    double* virial;
    double* virialSum;
};

/// The start of the particles' sums in a range: gravity, then the cross pairs where the particle is the partner.
/// Particles [b, done) have started. Starting the sums just before the first pairs that add to them, not in a pass of
/// their own, keeps them in cache until they are used.
template <int D, class K, bool kCross>
struct SumStart {
    using Entry = typename K::Entry;
    Vec<D>* f;
    Ang<D>* nx;
    const double* mass;
    Vec<D> g;
    const PassRange<Entry>& r;
    std::size_t done;
    const std::uint64_t* q;

    SumStart(const ForceContext<D>& ctx, const PassRange<Entry>& range)
        : f(ctx.p.f.data()),
          nx(ctx.p.torque.data()),
          mass(ctx.p.mass.data()),
          g(ctx.gravity),
          r(range),
          done(range.b),
          q(range.crossIn) {}

    [[gnu::always_inline]] void upTo(std::size_t end) {
        for (; done < end; ++done) {
            f[done] = g * mass[done];
            nx[done] = Ang<D>::zero();
            if constexpr (kCross) {
                for (; q != r.crossInEnd && (*q >> 32) == done; ++q) {
                    const CrossSlot<Entry>& c = r.cross[*q & 0xFFFFFFFFu];
                    if (!c.touching) continue;
                    K::addPartner(f[done], nx[done], K::load(c.e));
                }
            }
        }
    }
};

/// Particle i finished: its statistics into the range's.
template <bool kCross>
[[gnu::always_inline]] inline void tallyParticle(RangeTally& st, const ParticleTally& pt, std::size_t i, double vir,
                                                 double* virial, double& virialAcc) {
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

/// The pass over one range for a kernel that takes its pairs one by one (K::kOneByOne: polygons): each pair is
/// evaluated as its owner comes and added to both particles at once, with no block in between.
template <int D, class K, bool kCross, class Then>
[[gnu::always_inline]] inline RangeTally oneByOneRange(const ForceContext<D>& ctx, const K& kernel,
                                                       const PassRange<typename K::Entry>& r, Then& then) {
    using Entry = typename K::Entry;
    Vec<D>* f = ctx.p.f.data();
    Ang<D>* nx = ctx.p.torque.data();
    const std::uint32_t* first = ctx.pl.first.data();
    const std::uint32_t* partner = ctx.pl.partner.data();
    const std::size_t e = r.e;
    SumStart<D, K, kCross> start(ctx, r);
    const FinishViews<D> fv(ctx);
    RangeTally st;
    double virialAcc = kCross ? 0.0 : *r.virialSum;  // the one-thread sum, in particle order
    std::size_t c = r.c0;
    for (std::size_t i = r.b; i < e; ++i) {
        const std::uint32_t k0 = first[i], k1 = first[i + 1];
        // A particle's partners come in increasing order: the last is the farthest its pairs add to.
        std::size_t reach = k1 > k0 ? std::size_t{partner[k1 - 1]} + 1 : i + 1;
        if constexpr (kCross) reach = std::min(reach, e);
        start.upTo(std::max(reach, i + 1));
        typename K::Sum s = K::sumOf(f[i], nx[i]);
        double worst = 0, vir = 0;
        std::uint32_t nc = 0;
        for (std::uint32_t k = k0; k < k1; ++k) {
            const std::uint32_t j = partner[k];
            if constexpr (kCross) {
                if (j >= e) {  // evaluated before, in its slot
                    const CrossSlot<Entry>& x = r.cross[c++];
                    if (!x.touching) continue;
                    K::addOwner(s, K::load(x.e));
                    vir += x.e.virial();
                    worst = std::max(worst, x.e.overlap());
                    ++nc;
                    continue;
                }
            }
            Entry x;
            if (!kernel.pair(i, k, j, x)) continue;
            const typename K::Load l = K::load(x);
            K::addOwner(s, l);
            K::addPartner(f[j], nx[j], l);
            vir += x.virial();
            worst = std::max(worst, x.overlap());
            ++nc;
        }
        const ParticleTally pt = finishParticle<D>(fv, kernel, i, s, worst, nc, then);
        tallyParticle<kCross>(st, pt, i, vir, r.virial, virialAcc);
    }
    if constexpr (!kCross) *r.virialSum = virialAcc;
    return st;
}

/// The pass over one range. The particles go in blocks of a few dozen, each in two steps: (1) the kernel's
/// entries of the block's pairs (k.block: for disks the contact tests and the law, four pairs at a time, in lanes);
/// (2) in pair order, as when each pair was evaluated as its owner came, each entry added to its owner and its
/// partner, and each particle finished. A kernel reads positions and velocities only, which no particle of the block
/// or after it has had changed yet (finishing changes a particle's velocity, after its last pair), so the two steps
/// give the same bits as one pair at a time. A kernel that takes its pairs one by one (K::kOneByOne) skips the
/// blocks (oneByOneRange; pairRange chooses).
template <int D, class K, bool kCross, class Then>
[[gnu::always_inline]] inline RangeTally blockRange(const ForceContext<D>& ctx, const K& kernel,
                                                    const PassRange<typename K::Entry>& r,
                                                    PairBlock<D, typename K::Entry>& bl, Then& then) {
    using Entry = typename K::Entry;
    using Block = PairBlock<D, Entry>;
    Vec<D>* f = ctx.p.f.data();
    Ang<D>* nx = ctx.p.torque.data();  // holds the kernel's angular sums until the particle is finished
    const std::uint32_t* first = ctx.pl.first.data();
    const std::size_t b = r.b, e = r.e;
    SumStart<D, K, kCross> start(ctx, r);
    const FinishViews<D> fv(ctx);
    RangeTally st;
    double virialAcc = kCross ? 0.0 : *r.virialSum;  // the one-thread sum, in particle order
    std::size_t c = r.c0;
    for (std::size_t b0 = b, b1; b0 < e; b0 = b1) {
        b1 = b0 + 1;
        while (b1 < e && b1 - b0 < Block::kOwners && first[b1 + 1] - first[b0] <= Block::kPairs) ++b1;
        // A whole number of fours (but for the range's last block): a step on the block may go four at a time.
        if (b1 < e && b1 - b0 >= 4) b1 = b0 + ((b1 - b0) & ~std::size_t{3});
        bl.fit(first[b1] - first[b0]);
        // kCrossBlock: some of the block's pairs are cross pairs (their partner lies beyond e), taken from their
        // slots in pair order.
        auto runBlock = [&]<bool kCrossBlock>() __attribute__((always_inline)) {
            const std::uint32_t count = kernel.template block<kCrossBlock>(b0, b1, e, r.cross, c, bl);
            // The sums, in pair order, and each particle finished. Without cross pairs a particle's entries are the
            // next ones with it as owner (the list ends with kNoOwner); with them, the entries up to ownerEnd.
            if constexpr (!kCrossBlock) bl.owner[count] = Block::kNoOwner;
            const Entry* out = bl.out.data();
            const std::uint32_t* outPartner = bl.outPartner.data();
            const std::uint32_t* partner = bl.partner.data();
            const std::uint32_t* owner = bl.owner.data();
            // Every particle that the block's pairs add to starts here, once for the block.
            start.upTo(bl.reach);
            std::uint32_t t = 0;
            for (std::size_t i = b0; i < b1; ++i) {
                typename K::Sum s = K::sumOf(f[i], nx[i]);
                double worst = 0, vir = 0;
                std::uint32_t nc = 0;
                const std::uint32_t tEnd = kCrossBlock ? bl.ownerEnd[i - b0] : 0;
                for (; kCrossBlock ? t < tEnd : owner[t] == static_cast<std::uint32_t>(i); ++t) {
                    const Entry& x = out[t];
                    const typename K::Load l = K::load(x);
                    K::addOwner(s, l);
                    const std::uint32_t j = kCrossBlock ? outPartner[t] : partner[t];
                    if (!kCrossBlock || j != Block::kNoPartner) K::addPartner(f[j], nx[j], l);
                    vir += x.virial();
                    worst = std::max(worst, x.overlap());
                    ++nc;
                }
                const ParticleTally pt = finishParticle<D>(fv, kernel, i, s, worst, nc, then);
                tallyParticle<kCross>(st, pt, i, vir, r.virial, virialAcc);
            }
        };
        if constexpr (kCross) {
            // Most blocks of a range have no cross pair (those lie along the face between two ranges): their
            // pairs go the one-thread way.
            const std::uint32_t* pb = ctx.pl.partner.data() + first[b0];
            const std::uint32_t* pe = ctx.pl.partner.data() + first[b1];
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
    if constexpr (!kCross) *r.virialSum = virialAcc;
    return st;
}

template <int D, class K, bool kCross, class Then>
[[gnu::always_inline]] inline RangeTally pairRange(const ForceContext<D>& ctx, const K& kernel,
                                                   const PassRange<typename K::Entry>& r,
                                                   PairBlock<D, typename K::Entry>& bl, Then& then) {
    if constexpr (K::kOneByOne)
        return oneByOneRange<D, K, kCross>(ctx, kernel, r, then);
    else
        return blockRange<D, K, kCross>(ctx, kernel, r, bl, then);
}

/// The kernel K as the contact network's pass runs it: every pair through K::record (one pair, the bits of
/// K's blocks: tests/test_force_lanes.cpp), every wall contact through its wall kernel with a record, each record
/// appended to the sink in the pass's order. The same sums in the same order as K's own pass.
template <int D, class K>
class RecordingKernel {
public:
    using Entry = typename K::Entry;
    using Load = typename K::Load;
    using Sum = typename K::Sum;
    static constexpr bool kOneByOne = K::kOneByOne;

    class Walls {
    public:
        Walls(const K& k, ContactSink<D>& sink, std::size_t nWalls, bool surfaces)
            : w_(k.walls()), sink_(sink), nw_(nWalls), surfaces_(surfaces) {}
        [[gnu::always_inline]] bool add(std::size_t i, std::size_t w, Vec<D>& f, Ang<D>& tq, double& worst) const {
            ContactRecord<D> rec;
            const bool touching = w_.add(i, w, f, tq, worst, &rec);
            if (touching) sink_.push_back(rec);
            return touching;
        }
        std::uint32_t addSurfaces(std::size_t i, Vec<D>& f, Ang<D>& tq, double& worst) const {
            return w_.addSurfaces(i, f, tq, worst, &sink_);
        }

    private:
        const typename std::remove_cvref_t<decltype(std::declval<const K&>().walls())>& w_;
        ContactSink<D>& sink_;
        std::size_t nw_;
        bool surfaces_;
    };

    RecordingKernel(const ForceContext<D>& ctx, const K& k)
        : k_(k),
          sink_(*ctx.contacts),
          first_(ctx.pl.first.data()),
          partner_(ctx.pl.partner.data()),
          walls_(k, *ctx.contacts, ctx.nWalls, ctx.surfaces != nullptr) {}

    [[gnu::always_inline]] static Load load(const Entry& x) { return K::load(x); }
    [[gnu::always_inline]] static Sum sumOf(const Vec<D>& f, const Ang<D>& a) { return K::sumOf(f, a); }
    [[gnu::always_inline]] static void addOwner(Sum& s, const Load& l) { K::addOwner(s, l); }
    [[gnu::always_inline]] static void addPartner(Vec<D>& f, Ang<D>& a, const Load& l) { K::addPartner(f, a, l); }
    [[gnu::always_inline]] static auto forceOf(const Sum& s) { return K::forceOf(s); }
    [[gnu::always_inline]] auto torqueOf(std::size_t i, const Sum& s) const { return k_.torqueOf(i, s); }
    const Walls& walls() const { return walls_; }

    bool pair(std::size_t i, std::uint32_t k, std::uint32_t j, Entry& e) const {
        ContactRecord<D> rec;
        if (!k_.record(i, k, j, e, rec)) return false;
        sink_.push_back(rec);
        return true;
    }

    /// The block's pairs one by one in pair order (no cross pairs: the pass runs on one thread).
    template <bool kCrossBlock>
    std::uint32_t block(std::size_t b0, std::size_t b1, std::size_t e, const CrossSlot<Entry>* cross, std::size_t& c,
                        PairBlock<D, Entry>& bl) const {
        return walkBlock<kCrossBlock>(
            first_, partner_, b0, b1, e, cross, c, bl, [](std::size_t) {},
            [&](std::size_t i, std::uint32_t k, std::uint32_t j, std::uint32_t ne) {
                if (!pair(i, k, j, bl.out[ne])) return false;
                bl.owner[ne] = static_cast<std::uint32_t>(i);
                bl.partner[ne] = j;
                return true;
            });
    }

private:
    const K& k_;
    ContactSink<D>& sink_;
    const std::uint32_t* first_;
    const std::uint32_t* partner_;
    Walls walls_;
};

/// The pass with every contact recorded (ForceContext::contacts): on one thread, through RecordingKernel, which
/// gives the sums of the ordinary pass in the same order, so the same bits.
template <int D, class K, class Then>
[[gnu::noinline]] ForceStats recordingPass(const ForceContext<D>& ctx, const K& kernel,
                                           PairPassScratch<D, typename K::Entry>& s, Then& then) {
    using Entry = typename K::Entry;
    ForceStats st;
    if (s.blocks.empty()) s.blocks.resize(1);
    ctx.contacts->clear();
    const RecordingKernel<D, K> rk(ctx, kernel);
    const PassRange<Entry> r{0, ctx.p.tdmCount(), nullptr, 0, nullptr, nullptr, nullptr, &st.virial};
    addTally(st, pairRange<D, RecordingKernel<D, K>, false>(ctx, rk, r, s.blocks[0], then));
    return st;
}

/// Forces and torques of every particle by the kernel, then(i, f, torque) run once particle i's are final (it may
/// change i's velocities, not its position; nothing reads them after). One thread: one pass over the particles.
/// T threads: the cross pairs of PairList::split first, then the ranges, each on its thread.
template <int D, class K, class Then>
ForceStats runPairPass(const ForceContext<D>& ctx, const K& kernel, PairPassScratch<D, typename K::Entry>& s,
                       Then& then) {
    using Entry = typename K::Entry;
    // The contact network's pass: one test of a pointer in every other step.
    if constexpr (requires(ContactRecord<D> & rec, Entry & e) { kernel.record(0, 0u, 0u, e, rec); })
        if (ctx.contacts) [[unlikely]]
            return recordingPass(ctx, kernel, s, then);
    const std::size_t n = ctx.p.tdmCount();
    const int nt = n >= kParallelMin ? omp_get_max_threads() : 1;
    ForceStats st;
    if (s.blocks.size() < static_cast<std::size_t>(nt)) s.blocks.resize(static_cast<std::size_t>(nt));
    if (nt <= 1) {
        const PassRange<Entry> r{0, n, nullptr, 0, nullptr, nullptr, nullptr, &st.virial};
        addTally(st, pairRange<D, K, false>(ctx, kernel, r, s.blocks[0], then));
        return st;
    }

    PairList<D>& pl = ctx.pl;
    if (pl.split.ranges() != static_cast<std::size_t>(nt)) buildThreadSplit(pl, nt);
    const ThreadSplit& sp = pl.split;
    const std::size_t ncross = sp.crossSlot.size();
    s.cross.resize(ncross);
    s.virial.resize(n);
    CrossSlot<Entry>* cross = s.cross.data();
    s.tally.assign(static_cast<std::size_t>(nt), RangeTally{});
    RangeTally* tally = s.tally.data();
#pragma omp parallel num_threads(nt)
    {
        // The cross pairs first: every particle is still unfinished.
#pragma omp for schedule(static)
        for (std::size_t c = 0; c < ncross; ++c)
            cross[c].touching = kernel.pair(sp.crossOwner[c], sp.crossSlot[c], pl.partner[sp.crossSlot[c]], cross[c].e);
#pragma omp for schedule(static, 1)
        for (int r = 0; r < nt; ++r) {
            const std::uint64_t* ci = sp.crossIn.data();
            const PassRange<Entry> range{sp.start[r],
                                         sp.start[r + 1],
                                         cross,
                                         sp.crossFirst[r],
                                         ci + sp.crossInFirst[r],
                                         ci + sp.crossInFirst[r + 1],
                                         s.virial.data(),
                                         nullptr};
            tally[r] = pairRange<D, K, true>(ctx, kernel, range, s.blocks[static_cast<std::size_t>(r)], then);
        }
    }
    // The one-thread reductions, in the same order.
    for (const RangeTally& t : s.tally) addTally(st, t);
    for (std::size_t i = 0; i < n; ++i) st.virial += s.virial[i];
    return st;
}

/// The elastic energy stored in the contacts at the current state [J], as the kernel's laws give it: particle by
/// particle, its listed pairs, then its walls.
template <int D, class K>
double contactEnergy(const ForceContext<D>& ctx, const K& kernel) {
    const std::uint32_t* first = ctx.pl.first.data();
    const auto& walls = kernel.walls();
    double e = 0;
    for (std::size_t i = 0; i < ctx.p.tdmCount(); ++i) {
        for (std::uint32_t k = first[i]; k < first[i + 1]; ++k) e += kernel.energy(i, k);
        for (std::size_t w = 0; w < ctx.nWalls; ++w) e += walls.energy(i, w);
        if (ctx.surfaces) e += walls.surfaceEnergy(i);
    }
    return e;
}

}  // namespace haet
