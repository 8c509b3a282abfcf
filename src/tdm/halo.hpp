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
void TdmEngine<D>::check(Check run) {
    try {
        run();
    } catch (const SimulationError& e) {
        if (failure_.empty()) failure_ = e.what();
    }
}

}  // namespace haet
