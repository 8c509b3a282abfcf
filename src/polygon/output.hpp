#pragma once
// Polygons in the outputs: world-frame outlines for pictures, and VTK polygon cells so that ParaView shows the real
// shapes (polygons_NNNNNN.vtu next to the particles' point snapshots).
#include <array>
#include <filesystem>
#include <vector>

#include "core/particles.hpp"

namespace haet::polygon {

/// Vertices of polygon particle i in the world frame [m], counter-clockwise.
std::vector<std::array<double, 2>> worldOutline(const Particles<2>& p, std::size_t i);

/// Writes every polygon particle as a VTK_POLYGON cell, with cell data id, material, velocity, angular_velocity
/// (3 components, z for 2D spin), angle [rad] and frozen. Throws IoError.
void writePolygonVtu(const std::filesystem::path& path, const Particles<2>& p, double time);

}  // namespace haet::polygon
