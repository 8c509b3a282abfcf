#pragma once
// What the event-driven engine tells an engine coupled to it (the hybrid, haet/engine.hpp; docs/physics.md A.2-A.4)
// about where its particles are: it reports every particle joining, leaving and crossing a cell of its event grid,
// and collisions within the TC time. The coupled engine keeps whatever it needs per cell (zone volumes, a guard of
// cells near its own particles, the occupants of those cells) from these reports and the grid's geometry; it reads
// nothing of the engine's own storage.
//
// The interface lives here, below the hybrid, so that the layers run one way: haet/ includes edm/, never the
// reverse. The engine calls it through a pointer given at construction, at crossings (not at every prediction);
// without an observer (a pure event-driven run) a call site costs one test of the pointer.
#include <cstdint>

#include "neighbor/cell_grid.hpp"

namespace haet {

template <int D>
class EdmObserver {
public:
    virtual ~EdmObserver() = default;
    /// The engine (re)starts: the geometry of the cells it reports in; every particle it owns is reported afresh
    /// (joined) right after, in the engine's order.
    virtual void restart(const CellGrid<D>& cells) = 0;
    /// World particle i (radius r [m]) joined the engine, in cell `cell`.
    virtual void joined(std::uint32_t i, std::uint32_t cell, double r) = 0;
    /// World particle i (radius r [m]) left the engine; it was in cell `cell`.
    virtual void left(std::uint32_t i, std::uint32_t cell, double r) = 0;
    /// World particle i (radius r [m]) crossed from cell `from` into cell `to`.
    virtual void crossed(std::uint32_t i, std::uint32_t from, std::uint32_t to, double r) = 0;
    /// World particle i took part in a collision within the TC time of its (or its partner's) previous one (the
    /// modified EDM's dt_min, A.4), made elastic.
    virtual void tcCollision(std::uint32_t i) = 0;
};

}  // namespace haet
