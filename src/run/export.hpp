#pragma once
// The state at the end of a run, for the next stage of staged work (pour, then settle, then shear): final.csv, which
// `[[insert]] arrangement = "file"` reads back to the same particles bit for bit (positions, velocities, spins,
// radii, materials, frozen flags, image flags; numbers in the shortest text that reads back exactly; positions
// wrapped into the box on periodic axes as a pair-list rebuild wraps them), and
// final.data, a LAMMPS data file as `write_data` writes one for atom_style sphere (Atoms with image flags,
// Velocities). docs/scenario.md, "Outputs".
#include <filesystem>
#include <vector>

#include "scenario/definition.hpp"
#include "world/world.hpp"

namespace haet {

/// Writes the particles, in the order of their ids, as a CSV particle file (atomically). Throws IoError; a store of
/// polygons has no such file (std::invalid_argument): the CSV holds disks and spheres.
template <int D>
void writeStateCsv(const std::filesystem::path& path, const World<D>& w, const std::vector<MaterialDef>& materials);

/// Writes the particles, in the order of their ids (ids 1, 2, ... in that order), as a LAMMPS data file (atomically):
/// type = material + 1, diameter, density = mass / (4/3 pi r^3) (in 2D too, as LAMMPS computes masses), image flags,
/// velocities and angular velocities; the box of the domain (2D: z from -0.5 to 0.5). Throws IoError; polygons:
/// std::invalid_argument.
template <int D>
void writeLammpsData(const std::filesystem::path& path, const World<D>& w, const std::vector<MaterialDef>& materials);

}  // namespace haet
