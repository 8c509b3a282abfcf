#pragma once
// The hybrid's book of its event-driven particles (docs/physics.md A.2-A.4, docs/haet.md): it is the EdmObserver
// (edm/observer.hpp) of the hybrid's event-driven engine, so the engine tells it every particle joining, leaving
// and crossing a cell of its event grid, and every collision within the TC time; from that it keeps what the hybrid
// asks per cell of that grid: the particle volume per zone (for the zone labels), the particles that entered a
// guarded cell, the occupants of each cell, and the particles to hand to the time-driven engine (the modified EDM).
// It holds its own copy of the grid's geometry, as told by the engine, and reads nothing of the engine's storage.
#include <array>
#include <cstdint>
#include <vector>

#include "edm/observer.hpp"
#include "haet/zones.hpp"
#include "io/checkpoint.hpp"

namespace haet {

template <int D>
class EdmBook final : public EdmObserver<D> {
public:
    /// zones: the zone a cell belongs to is that of its centre. guard: per cell of the event grid, nonzero where an
    /// event-driven particle is watched (owned by the hybrid, sized cells().count() before the first crossing).
    EdmBook(const ZoneGrid<D>& zones, const std::vector<std::uint8_t>& guard) : zones_(zones), guard_(guard) {}

    void restart(const CellGrid<D>& cells) override;
    void joined(std::uint32_t i, std::uint32_t cell, double r) override;
    void left(std::uint32_t i, std::uint32_t cell, double r) override;
    void crossed(std::uint32_t i, std::uint32_t from, std::uint32_t to, double r) override;
    void tcCollision(std::uint32_t i) override { tcHandovers_.push_back(i); }

    /// The event grid's geometry.
    const CellGrid<D>& cells() const { return cells_; }
    /// Per axis and zone coordinate z: the first cell coordinate whose centre is in zone z (entry z + 1 ends it).
    const std::array<std::vector<std::uint32_t>, D>& zoneCellBegin() const { return zoneCellBegin_; }
    /// The cell of event-driven World particle i.
    std::uint32_t cellOf(std::uint32_t i) const { return cell_[i]; }
    /// Per zone: volume of the event-driven particles in it [m^D].
    const std::vector<double>& zoneVolume() const { return volume_; }
    /// World indices that entered a cell with a nonzero guard since the last call (may repeat an index; some may have
    /// left the engine since).
    std::vector<std::uint32_t> takeGuardEntries();
    /// World indices of particles that collided within the TC time of their previous collision, since the last call.
    std::vector<std::uint32_t> takeTcHandovers();
    /// Calls f(World index) for every event-driven particle in cell c.
    template <class F>
    void forEachIn(std::uint32_t c, F&& f) const {
        for (std::uint32_t i = head_[c]; i != kNone; i = next_[i]) f(i);
    }
    /// The World exchanged particles i and j (Particles::swapEntries).
    void swapped(std::uint32_t i, std::uint32_t j);

    /// The book as it is (haet/state.cpp): the volumes are sums in the order the particles came and went, which a
    /// recount would not repeat to the last bit. loadState, after the engine told the book its grid (restart), for
    /// event-driven particles [first, n); throws CheckpointError (Corrupt) when the lists do not hold those.
    void saveState(ByteWriter& out) const;
    void loadState(ByteReader& in, std::size_t first, std::size_t n);

private:
    static constexpr std::uint32_t kNone = 0xFFFFFFFFu;
    std::uint32_t zoneOfCell(std::uint32_t c) const;
    void grow(std::uint32_t i);
    void link(std::uint32_t i, std::uint32_t c);
    void unlink(std::uint32_t i);
    /// The word that points to i in its cell's list.
    std::uint32_t* pointerTo(std::uint32_t i);

    const ZoneGrid<D>& zones_;
    const std::vector<std::uint8_t>& guard_;
    CellGrid<D> cells_;
    std::array<std::vector<std::uint32_t>, D> zoneCoord_;  // per axis and cell coordinate: zone coordinate
    std::array<std::vector<std::uint32_t>, D> zoneCellBegin_;
    std::vector<double> volume_;
    // Occupants: per cell the first, per World index the next in its cell, its cell (kNone: not event-driven) and
    // that cell's zone (a crossing then looks up the zone of the new cell only).
    std::vector<std::uint32_t> head_, next_, cell_, zone_;
    std::vector<std::uint32_t> guardEntries_, tcHandovers_;
};

extern template class EdmBook<2>;
extern template class EdmBook<3>;

}  // namespace haet
