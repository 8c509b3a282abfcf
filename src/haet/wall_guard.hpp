#pragma once
// The walls the hybrid's event-driven part does not predict (docs/physics.md H.6; docs/haet.md, "Walls the event-driven
// part does not predict"): walls of any shape that are curved (arcs, cylinders, cones, discs) or move, and oscillating
// planes. The time-driven engine handles every wall, so the hybrid hands an event-driven particle to it before the
// particle can touch such a wall, as it does before a particle can touch a time-driven one.
//
// The cells of the event grid from which a particle could come within its radius plus the margin of such a wall
// before the next refresh, and a ring of one cell around them, are "near": the hybrid guards them (their occupants
// are watched). Each near cell lists the walls' elements within that reach plus the ring of it, so the gap of a
// watched particle to the walls is a minimum over its cell's list, and every element not listed is farther than the
// list's reach. Static walls are binned once; moving ones at every refresh (every due relabel of the hybrid), over
// the distance their points can move until the next.
#include <cstdint>
#include <vector>

#include "io/checkpoint.hpp"
#include "neighbor/cell_grid.hpp"
#include "world/world.hpp"

namespace haet {

template <int D>
class WallGuard {
public:
    /// The guarded walls of the world (the oscillating planes, and the walls of any shape that are not static
    /// meshes); none: empty().
    void collect(const World<D>& world);
    bool empty() const { return planes_.empty() && surfaces_.empty(); }
    /// The fastest speed of a point of a guarded wall [m/s].
    double speed() const { return speed_; }

    /// Bins the guarded walls at time t into the cells for particles of radius <= rmax [m] that must stay `margin`
    /// [m] away from them until t + ahead [s]. Static walls are binned at the first call only (per grid).
    void refresh(const CellGrid<D>& cells, double t, double ahead, double rmax, double margin);
    bool near(std::uint32_t cell) const { return !near_.empty() && near_[cell]; }
    /// The near cells (after refresh).
    const std::vector<std::uint32_t>& cells() const { return list_; }
    /// The walls at time t (before gap).
    void moveTo(double t);
    /// A lower bound of the gap between a sphere (centre x in cell `cell`, radius r) and the guarded walls at the time
    /// of moveTo: exact for the elements listed in its cell (a plane's signed distance: negative beyond it), the
    /// listed reach for all others [m].
    double gap(std::uint32_t cell, const Vec<D>& x, double r) const;

    /// The cells and lists of the last refresh (haet/state.cpp), made at a time a resumed run does not repeat; the
    /// walls themselves come from collect. loadState throws CheckpointError (Corrupt) for another grid of `cells`.
    void saveState(ByteWriter& out) const;
    void loadState(ByteReader& in, std::uint32_t cells);

private:
    struct Item {
        std::uint32_t wall;     // < planes_.size(): a plane; else a surface, wall - planes_.size()
        std::uint32_t element;  // of the surface
    };
    void bin(const CellGrid<D>& cells, double t, double ahead, double rmax, double margin);
    /// How far a point within `reach` [m] of the centre of rotation can move in a time `ahead` [s] [m].
    static double sweep(const Motion<D>& m, double ahead, double reach);

    const World<D>* world_ = nullptr;
    std::vector<std::uint32_t> planes_, surfaces_;  // World::walls and World::surfaces indices
    double speed_ = 0;
    bool moving_ = false, binned_ = false;
    double listReach_ = 0;             // every element not listed in a near cell is farther from each of its points [m]
    std::vector<Pose<D>> poses_;       // the surfaces' at the time of moveTo
    std::vector<Vec<D>> planePoints_;  // the planes' points then [m]
    std::vector<std::uint8_t> near_;
    std::vector<std::uint32_t> list_;
    std::vector<std::uint32_t> first_;  // CSR over the cells
    std::vector<Item> items_;
};

extern template class WallGuard<2>;
extern template class WallGuard<3>;

}  // namespace haet
