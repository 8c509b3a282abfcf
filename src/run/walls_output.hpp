#pragma once
// What the run writes about its walls: their shapes for ParaView (walls.pvd) and the pictures, the loads of named
// walls in series.csv (docs/physics.md H.5), and their list in `haet check`.
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "io/vtk.hpp"
#include "tdm/engine.hpp"
#include "world/world.hpp"

namespace haet {

/// Every wall at time t: a plane as a square patch over the box (a thin quad in 2D), a mesh as its triangles or
/// segments, a cylinder or a disc as a tessellation, an arc as a polyline.
template <int D>
WallShapes wallShapes(const World<D>& w, double t);

/// The series columns of the named walls' loads: NAME_fx, NAME_fy[, NAME_fz], then the torque (2D: NAME_tz; 3D:
/// NAME_tx, NAME_ty, NAME_tz) [N, N m].
template <int D>
std::vector<std::string> wallLoadColumns(const World<D>& w);
/// Their values at the last force pass, appended to row.
template <int D>
void appendWallLoads(const World<D>& w, const TdmEngine<D>& eng, std::vector<std::optional<double>>& row);

/// `haet check`: one line per wall (kind, elements, bounding box, motion).
template <int D>
void describeWalls(const World<D>& w, std::ostream& out);

}  // namespace haet
