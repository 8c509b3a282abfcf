#pragma once
// Verlet pair list built from a cell grid (linked cells as cell-sorted arrays), with a skin, periodic images
// and per-pair contact history that survives rebuilds. The all-pairs reference twin is buildAllPairs().
//
// Layout: a half list in CSR form. Pairs of particle i are [first[i], first[i+1]) with partners j > i, sorted
// by j. Each pair carries an image-shift code so that r_i - r_j + shift is the minimum-image separation for as
// long as no particle has moved more than skin/2 since the build.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/particles.hpp"
#include "geometry/domain.hpp"

namespace haet {

/// The threaded force loop's split of the particles (tdm/forces.hpp): one contiguous range per thread, and the
/// "cross" pairs, whose partner lies in a later range than their owner. Only the cross pairs need evaluating
/// before the ranges run side by side; every other pair lies inside one range.
struct ThreadSplit {
    std::vector<std::uint32_t> start;         ///< range r is particles [start[r], start[r+1])
    std::vector<std::uint32_t> crossSlot;     ///< pair slot of each cross pair, in pair order
    std::vector<std::uint32_t> crossOwner;    ///< owner i of each cross pair
    std::vector<std::uint32_t> crossFirst;    ///< range r owns cross pairs [crossFirst[r], crossFirst[r+1])
    std::vector<std::uint64_t> crossIn;       ///< partner << 32 | cross pair, sorted: the cross pairs by partner
    std::vector<std::uint32_t> crossInFirst;  ///< range r's partners: crossIn[crossInFirst[r], crossInFirst[r+1])

    std::size_t ranges() const { return start.empty() ? 0 : start.size() - 1; }
};

template <int D>
struct PairList {
    std::vector<std::uint32_t> first;    ///< CSR offsets, size n+1
    std::vector<std::uint32_t> partner;  ///< j of each pair
    std::vector<std::uint8_t> shift;     ///< image-shift code of each pair, index into shiftVec
    std::vector<Vec<D>> history;         ///< tangential spring of each pair [m]; zero when not touching
    std::vector<Vec<D>> shiftVec;        ///< 3^D shift vectors [m]
    // Made from the list when first needed, dropped by every change of the list (dropDerived):
    ThreadSplit split;                 ///< the threaded force loops' split (buildThreadSplit)
    std::vector<std::uint32_t> owner;  ///< owner i of each pair (makeOwners), for the four-wide contact tests

    /// Forgets what was made from the list (after the list changed).
    void dropDerived() {
        split = ThreadSplit{};
        owner = {};
    }
    /// Fills owner from first, unless it already matches the list.
    void makeOwners() {
        if (owner.size() == partner.size()) return;
        owner.resize(partner.size());
        for (std::size_t i = 0; i + 1 < first.size(); ++i)
            std::fill(owner.begin() + first[i], owner.begin() + first[i + 1], static_cast<std::uint32_t>(i));
    }

    std::size_t size() const { return partner.size(); }
    static constexpr int kNoShift = (D == 2) ? 4 : 13;
};

struct NeighborSettings {
    double skin = 0;                 ///< [m]
    bool excludeFrozenPairs = true;  ///< pairs of two frozen particles (or two ghosts: kUnpaired) never matter
};

/// Builds the pair list with a cell grid. Positions must already be wrapped into the box on periodic axes.
/// Contact history of pairs present in `old` (same particle numbering) is carried over.
template <int D>
void buildPairList(const Particles<D>& p, const Domain<D>& dom, const NeighborSettings& s, const PairList<D>& old,
                   PairList<D>& out);

/// Keeps only the pairs whose tangential history is not zero (the contacts), in order, in arrays of their size:
/// all that a rebuild carries over from the old list.
template <int D>
void keepTouchingPairs(PairList<D>& list);

/// Cuts particles [0, n) into `ranges` contiguous ranges of about equal work (pair slots plus particles) and
/// lists the pairs that cross from one range into a later one (list.split).
template <int D>
void buildThreadSplit(PairList<D>& list, int ranges);

/// The reference twin: all N(N-1)/2 pairs tested directly. Same output format (no history transfer).
template <int D>
void buildAllPairs(const Particles<D>& p, const Domain<D>& dom, const NeighborSettings& s, PairList<D>& out);

/// Wraps positions into the box on periodic axes (recording the wraps in p.image).
template <int D>
void wrapPositions(Particles<D>& p, const Domain<D>& dom);

/// Spatial order of particles (cell by cell) for memory locality; returns the permutation for Particles::permute.
template <int D>
std::vector<std::uint32_t> spatialOrder(const Particles<D>& p, const Domain<D>& dom, double cellSize);

/// Incremental twin of buildPairList after a hybrid mode change: `list` was built for the particles as numbered
/// before; new particle k was old particle from[k], or is new to the list (any value >= the old count). Keeps every
/// pair of two kept particles with its shift and history, drops those of particles that left, and adds the pairs
/// of the new particles found with a cell grid at the current positions. Positions are not wrapped, so the shift
/// codes of kept pairs stay valid. ref (new numbering, may be null): where each kept particle's drift is measured
/// from (its position at the last build); a new particle is paired with kept particle j within skin + |x_j - ref_j|.
/// The list then stays valid for as long as no particle moves more than skin/2 from its reference (new particles:
/// their position now). Without ref, kept particles are taken not to have drifted.
template <int D>
void remapPairList(const Particles<D>& p, const Domain<D>& dom, const NeighborSettings& s,
                   const std::vector<std::uint32_t>& from, PairList<D>& list, const Vec<D>* ref = nullptr);

/// Renumbers a pair list's history after Particles::permute(order), so it can be carried into the next build.
/// new particle k was old particle order[k]; entries outside the old range (a particle new to the list) have no
/// history, and pairs of old particles missing from order are dropped.
template <int D>
void permutePairList(PairList<D>& list, const std::vector<std::uint32_t>& order);

}  // namespace haet
