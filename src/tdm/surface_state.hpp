#pragma once
// What the time-driven engine keeps of the contacts of particles with walls of any shape (geometry/surface.hpp):
// the walls' poses at the current time, the broad phase's candidates (neighbor/surface_list.hpp) and each
// particle's contacts. A contact belongs to the particle and the wall, not to an element: from one step to the
// next it is found again by its normal (the old contact of the same wall whose normal is nearest the new one,
// within 60 degrees), so its tangential spring survives the step from one triangle or segment to the next
// (docs/physics.md H.3). Only particles with candidates hold slots, so a scene's memory grows with the particles
// near its walls, not with all of them.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "geometry/surface.hpp"
#include "neighbor/surface_list.hpp"

namespace haet {

/// Contacts of one particle with walls of any shape, at most (more: the deepest are kept).
inline constexpr int kSurfaceSlots = 4;

template <int D>
struct SurfaceContact {
    Vec<D> normal;           ///< unit normal from the wall to the centre (world) [-]
    Vec<D> spring;           ///< tangential spring elongation [m]
    Vec<D> force;            ///< the contact's force on the particle at the last force pass [N]
    Vec<D> point;            ///< contact point on the wall (world) [m]
    double overlap = 0;      ///< radius - distance [m]
    std::uint32_t wall = 0;  ///< index into the surface walls
};

template <int D>
struct SurfaceState {
    static constexpr std::uint32_t kNoSlots = 0xFFFFFFFFu;
    const std::vector<SurfaceWall<D>>* walls = nullptr;
    std::vector<Pose<D>> poses;    ///< each wall's pose at the time of the current force pass
    std::vector<double> reach;     ///< each wall's farthest point from its centre of rotation (body frame) [m]
    SurfaceCandidates candidates;  ///< built at candidatesTime
    double candidatesTime = 0;     ///< [s]
    /// Particle i's contacts: slots[slotOf[i] ... + count[i]) (kSurfaceSlots reserved), kNoSlots without candidates.
    std::vector<std::uint32_t> slotOf;
    std::vector<std::uint8_t> count;
    std::vector<SurfaceContact<D>> slots;
    /// The body-frame boxes of the mesh walls' elements, wall w's at boxes[boxFirst[w] + e] (none for other shapes):
    /// the force pass skips a candidate whose box lies beyond the particle's radius before finding its closest
    /// point (SurfaceWall::paddedBox: a skipped element could not have touched).
    std::vector<std::uint32_t> boxFirst;
    std::vector<ElementBox<D>> boxes;

    bool empty() const { return walls == nullptr || walls->empty(); }

    /// Sets the walls and makes their elements' boxes (their shapes never change in the body frame).
    void setWalls(const std::vector<SurfaceWall<D>>* w) {
        walls = w;
        boxFirst.assign(1, 0);
        boxes.clear();
        reach.clear();
        for (const SurfaceWall<D>& wall : *w) {
            // A wall's shape is fixed in its body frame: how far a rotation can move its points is known once.
            reach.push_back(wall.reachFrom(wall.motion.centre));
            if (wall.kind == SurfaceKind::Mesh)
                for (std::size_t e = 0; e < wall.elementCount(); ++e) boxes.push_back(wall.paddedBox(e));
            boxFirst.push_back(static_cast<std::uint32_t>(boxes.size()));
        }
    }
};

}  // namespace haet
