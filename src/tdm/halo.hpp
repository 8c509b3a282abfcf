#pragma once
// The time-driven engine's state across ranks (TdmEngine::Halo; tdm/ranks.cpp): the slabs, the ghosts and who
// sends them. Only engine.cpp and ranks.cpp see it.
#include <string>
#include <vector>

#include "tdm/engine.hpp"

namespace haet {

template <int D>
struct TdmEngine<D>::Halo {
    Ranks* ranks = nullptr;
    Slabs slabs;
    double range = 0;  ///< a ghost's reach from its slab: the largest diameter of the run plus the skin [m]
    /// send[r]: the owned particles whose copies rank r keeps, in the order of its ghosts from here.
    std::vector<std::vector<std::uint32_t>> send;
    /// Rank r's ghosts here are [ghostFirst[r], ghostFirst[r + 1]) (after the owned particles).
    std::vector<std::size_t> ghostFirst;
    std::uint64_t migrated = 0;    ///< particles this rank sent to another's slab, over the run
    std::uint64_t rebalances = 0;  ///< re-placements of the cuts
};

template <int D>
template <class Check>
void TdmEngine<D>::together(Check check) const {
    std::string failure;
    try {
        check();
    } catch (const SimulationError& e) {
        failure = e.what();
    }
    Ranks& ranks = *halo_->ranks;
    if (!ranks.any(!failure.empty())) return;
    // Every rank stops with the message of the lowest rank that failed.
    std::vector<std::vector<char>> send(static_cast<std::size_t>(ranks.size()));
    for (int r = 0; r < ranks.size(); ++r)
        if (r != ranks.rank()) send[r].assign(failure.begin(), failure.end());
    const auto got = ranks.exchange(send);
    for (int r = 0; r < ranks.size(); ++r) {
        if (r == ranks.rank() && !failure.empty()) break;
        if (r != ranks.rank() && !got[r].empty()) {
            failure.assign(got[r].begin(), got[r].end());
            break;
        }
    }
    throw SimulationError(failure);
}

}  // namespace haet
