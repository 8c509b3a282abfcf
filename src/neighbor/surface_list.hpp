#pragma once
// The broad phase of walls of any shape (geometry/surface.hpp): for each particle, the wall elements within its
// radius plus a margin (the skin; half of it when no wall moves, the engine decides), found through the one cell grid
// (neighbor/cell_grid.hpp). Elements are binned into the cells they come within reach of (their box, refined by the
// distance from each cell's centre); a particle looks only at its own cell's elements. Rebuilt with the pair list,
// and when a moving wall has moved more than half the skin since the last build: a particle and an element then
// closed in by at most the margin, so every contact until the next build is with a listed element. A brute-force twin
// (every element of every wall) gives the same lists (tests/test_surfaces.cpp).
#include <cstdint>
#include <vector>

#include "core/particles.hpp"
#include "geometry/domain.hpp"
#include "geometry/surface.hpp"

namespace haet {

/// The elements near each particle, by particle (CSR), each particle's in wall order then element order.
struct SurfaceCandidates {
    std::vector<std::uint32_t> first{0};  ///< particle i's candidates: [first[i], first[i+1])
    std::vector<std::uint32_t> wall;      ///< index into the surface walls
    std::vector<std::uint32_t> element;   ///< element of that wall
    std::size_t size() const { return wall.size(); }
};

/// The candidates of particles [0, n) at the walls' poses (poses[w] for wall w), within radius + skin [m] (`skin`:
/// the margin beyond the radius).
template <int D>
void buildSurfaceCandidates(const Particles<D>& p, std::size_t n, const Domain<D>& dom,
                            const std::vector<SurfaceWall<D>>& walls, const std::vector<Pose<D>>& poses, double skin,
                            SurfaceCandidates& out);

/// The reference twin: every element of every wall tested against every particle.
template <int D>
void buildSurfaceCandidatesBrute(const Particles<D>& p, std::size_t n, const std::vector<SurfaceWall<D>>& walls,
                                 const std::vector<Pose<D>>& poses, double skin, SurfaceCandidates& out);

}  // namespace haet
