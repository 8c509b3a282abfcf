#pragma once
// The [[walls]] blocks of a scenario (docs/scenario.md, "[[walls]]"): planes and walls of any shape, their motion,
// and the checks that need the whole scenario (which methods and particles a wall kind works with).
#include <filesystem>

#include "geometry/domain.hpp"
#include "geometry/surface.hpp"
#include "scenario/definition.hpp"
#include "scenario/table_reader.hpp"

namespace haet {

/// One [[walls]] block; `material` is its material's index (the loader resolves the name). Relative file paths are
/// resolved against `dir`.
WallDef readWall(const TableReader& r, int dim, int material, const std::filesystem::path& dir);

/// What the walls need of the rest of the scenario: the method (pure event-driven runs predict planes at a constant
/// velocity and static walls of segments or triangles only; the hybrid and the time-driven engine take every wall),
/// the particles (polygons touch the 2D walls: planes, segments, polylines, circles, arcs), a shape within reach of
/// the domain. Throws ScenarioError naming the wall.
void checkWalls(const Scenario& s);

/// The runtime wall of a plane's definition (time 0), and of any other shape's (its elements, motion, material).
template <int D>
Wall<D> makePlane(const WallDef& w);
template <int D>
SurfaceWall<D> makeSurfaceWall(const WallDef& w);

/// The walls as insertion sees them: whether a particle of radius r at x is clear of every wall (on the inner side
/// of each plane by r; at least r from every wall of another shape).
template <int D>
class WallClearance {
public:
    explicit WallClearance(const std::vector<WallDef>& walls);
    bool clear(const Vec<D>& x, double r) const;

private:
    std::vector<Wall<D>> planes_;
    std::vector<SurfaceWall<D>> surfaces_;
    std::vector<std::vector<std::pair<Vec<D>, Vec<D>>>> boxes_;  ///< each surface element's body box
};

}  // namespace haet
