#pragma once
// Initial particles: executes the [[insert]] blocks of a scenario (lattice, random sequential addition, or a particle
// file) into the particle store. Rules and file formats: docs/scenario.md.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "core/rng.hpp"
#include "scenario/definition.hpp"

namespace haet {

/// One particle as read from a particle file, SI units. Components beyond the scenario's dimension are zero.
struct FileParticle {
    Vec3d x{0, 0, 0};               ///< centre [m]
    Vec3d v{0, 0, 0};               ///< velocity [m/s]
    Vec3d w{0, 0, 0};               ///< angular velocity [rad/s] (LAMMPS Velocities section; 2D uses w[2])
    double radius = 0;              ///< [m]
    std::optional<double> density;  ///< [kg/m^3] from a LAMMPS data file; unset: the material's
    int material = -1;              ///< CSV material column (index into Scenario::materials); -1: the insert's material
    int type = 0;                   ///< LAMMPS atom type (1-based); 0 for CSV
    bool frozen = false;            ///< CSV frozen column
    std::array<int, 3> image{0, 0, 0};  ///< LAMMPS image flags (periodic box crossings)
    int line = 0;                       ///< line of the file the particle came from, for messages
};

/// The contents of a particle file.
struct ParticleFile {
    std::vector<FileParticle> particles;  ///< in file order
    std::optional<Vec3d> boxLo, boxHi;    ///< LAMMPS header box bounds [m] (xlo xhi, ylo yhi, zlo zhi)
    int atomTypes = 0;                    ///< LAMMPS "atom types" count; 0 for CSV
};

/// One polygon as read from a polygon CSV file (2D), SI units.
struct FilePolygon {
    std::vector<Vec<2>> vertices;  ///< world coordinates [m], counter-clockwise, convex
    Vec3d v{0, 0, 0};              ///< velocity [m/s]
    double w = 0;                  ///< angular velocity [rad/s]
    int material = -1;             ///< index into Scenario::materials; -1: the insert's material
    bool frozen = false;
    int line = 0;  ///< line of the file, for messages
};

/// Reads a polygon CSV file (insert with shape = "polygon", arrangement = "file"): a header naming the columns
/// vertices[,vx,vy][,w][,material][,frozen] in any order; `vertices` holds "x0 y0 x1 y1 ..." (3 to 20 vertices, in
/// either order, convex) in world coordinates. Errors: ScenarioError at the file's line, named `key`.
std::vector<FilePolygon> readPolygonCsv(const std::filesystem::path& file, const std::vector<MaterialDef>& materials,
                                        const std::string& key);

/// Reads a CSV particle file whose header names the columns x,y[,z],radius[,vx,vy[,vz]][,material][,frozen] in any
/// order (z and vz only in 3D). A material is a name from `materials` or its 0-based index; frozen is 0/1/true/false.
/// Blank lines and lines starting with '#' are skipped. Errors: ScenarioError at the file's line, named `key`.
ParticleFile readParticleCsv(const std::filesystem::path& file, int dimension,
                             const std::vector<MaterialDef>& materials, const std::string& key);

/// Reads a LAMMPS data file written for atom_style sphere: header counts and box bounds, "Atoms # sphere" lines
/// `id type diameter density x y z [ix iy iz]`, optional "Velocities" lines `id vx vy vz wx wy wz`.
/// Particles keep the order of the Atoms section. Errors: ScenarioError at the file's line, named `key`.
ParticleFile readLammpsData(const std::filesystem::path& file, const std::string& key);

/// Executes every [[insert]] of `scenario` in order, appending to `particles` (ids consecutive from its current size).
/// Random numbers come from `rng` only, so the result depends on the seed alone. Throws ScenarioError when an insert
/// cannot be done (lattice spacing below one diameter, no room for random placement, a bad particle file); the store
/// keeps the particles of the inserts done before. Requires scenario.dimension == D.
template <int D>
void insertParticles(const Scenario& scenario, Particles<D>& particles, Rng rng);

extern template void insertParticles<2>(const Scenario&, Particles<2>&, Rng);
extern template void insertParticles<3>(const Scenario&, Particles<3>&, Rng);

}  // namespace haet
