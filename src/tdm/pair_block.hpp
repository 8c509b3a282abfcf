#pragma once
// The buffers of the pair pass (tdm/pair_pass.hpp): one thread's block of particles with the entries its pairs
// add, the slots of the cross pairs of a thread split, and what the pass keeps between steps so that no step
// allocates. The entry is the kernel's (what one touching pair adds to its owner and its partner).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "tdm/force_stats.hpp"

namespace haet {

/// Four doubles (a vector, zero-padded), 32-byte aligned: the rows of four pairs are transposed into lanes and back.
struct alignas(32) Row {
    double c[4];
};

/// A cross pair of the thread split (PairList::split), evaluated before the ranges run: its entry and whether the
/// pair touches.
template <class Entry>
struct CrossSlot {
    Entry e;
    bool touching;
};

/// One thread's buffers for a block of particles: at most kPairs listed pairs (more only when one particle alone has
/// more), so that they stay in L1.
///
/// The kernel fills, in pair order, the entries of the block's touching pairs (and, in a block with cross pairs,
/// those taken from their slots) and says whose they are:
/// - a block without cross pairs: entry t belongs to owner[t] and its partner is partner[t]; the pass sets
///   owner[count] = kNoOwner after the last;
/// - a block with cross pairs: the block's particle b0 + q has entries [ownerEnd[q-1], ownerEnd[q]), and the
///   partner of entry t is outPartner[t], kNoPartner for a cross pair (whose partner lies in another range).
/// reach: 1 + the largest partner of the block's pairs (cross pairs aside), at least the block's end.
///
/// owner, partner, slot, sep and entry are also the kernel's list of touching pairs, each field in an array of its
/// own (lanes load four at once): pair slot k, the separation d = x_i - x_j (+ shift) component by component, and in
/// a block with cross pairs the entry each fills.
template <int D, class Entry>
struct PairBlock {
    static constexpr std::uint32_t kPairs = 128;              ///< listed pairs per block
    static constexpr std::uint32_t kOwners = 64;              ///< particles per block
    static constexpr std::uint32_t kNoPartner = 0xFFFFFFFFu;  ///< an entry taken from a cross pair's slot
    static constexpr std::uint32_t kNoOwner = 0xFFFFFFFFu;    ///< past the last touching pair

    std::vector<std::uint32_t> owner, partner, slot;
    std::vector<double> sep[D];
    std::vector<std::uint32_t> entry;
    std::vector<Entry> out;
    std::vector<std::uint32_t> outPartner;
    std::vector<std::uint32_t> ownerEnd;
    std::size_t reach = 0;

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

/// What the pass keeps between steps (one thread needs only its block).
template <int D, class Entry>
struct PairPassScratch {
    std::vector<PairBlock<D, Entry>> blocks;  ///< one per thread
    std::vector<CrossSlot<Entry>> cross;      ///< the cross pairs (PairList::split)
    std::vector<double> virial;               ///< per particle: sum over own pairs of r_ij . F_ij [N m]
    std::vector<RangeTally> tally;            ///< per-range statistics
};

}  // namespace haet
