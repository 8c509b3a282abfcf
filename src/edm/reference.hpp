#pragma once
// The event-driven engine's reference twin (EdmSettings::reference; tests): the next event by brute force, every
// pair, every plane and every mesh element at every event (O(N^2) per event), no cells, no queue. It reads the
// engine's slots and predicts with the same canonical times (Slots::pairTime, wallTime, MeshWalls::time), so the
// fast engine and the twin produce bit-identical event sequences (tests/test_edm_engine.cpp,
// tests/test_edm_mesh.cpp).
#include <cstdint>
#include <vector>

#include "edm/mesh_walls.hpp"
#include "edm/slots.hpp"

namespace haet::edm {

template <int D>
class Reference {
public:
    struct Event {
        double time = kNever;    ///< [s]
        std::uint32_t slot = 0;  ///< the moving slot
        /// kPair or kWall with the partner (a mesh element: World::walls.size() + its index); kNone: the horizon;
        /// kCell: the slot crosses a periodic face of the box (with meshes: its box-frame position wraps)
        std::uint32_t code = kNone << kTypeShift;
    };
    /// rmax: the largest radius [m]; planes: the walls predicted (World::walls indices); mesh: the mesh elements.
    Reference(const Slots<D>& slots, double rmax, const std::vector<std::uint32_t>& planes, const MeshWalls<D>& mesh)
        : sl_(slots), rmax_(rmax), planes_(planes), mesh_(mesh) {}
    /// The earliest pair or wall event of any moving slot after now; or, if it is sooner, the horizon within which
    /// every pair that collides is at its minimum image (periodic boxes), as an event of type kNone; or, with mesh
    /// elements in a periodic box, the next crossing of a periodic face by a slot (kCell, face 2 axis + up): mesh
    /// times are taken in the box frame, which the fast engine moves at its cell crossings.
    Event next(double now) const;

private:
    const Slots<D>& sl_;
    double rmax_;
    const std::vector<std::uint32_t>& planes_;
    const MeshWalls<D>& mesh_;
};

}  // namespace haet::edm
