#pragma once
// Initial particles: executes the [[insert]] blocks of a scenario (lattice, random sequential addition, or a particle
// file) into the particle store. Rules and file formats: docs/scenario.md.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <istream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "core/polygon_shape.hpp"
#include "core/rng.hpp"
#include "neighbor/cell_grid.hpp"
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
/// The same from a stream (what the file's overload reads; the fuzz target's entry), `name` naming it in errors.
std::vector<FilePolygon> readPolygonCsv(std::istream& in, const std::string& name,
                                        const std::vector<MaterialDef>& materials, const std::string& key);

/// The longest line a particle file may hold (a CSV record of 20 vertices takes well under 1 kB).
inline constexpr std::size_t kMaxParticleLineBytes = std::size_t(1) << 20;

/// Reads a CSV particle file whose header names the columns x,y[,z],radius[,vx,vy[,vz]][,material][,frozen] in any
/// order (z and vz only in 3D). A material is a name from `materials` or its 0-based index; frozen is 0/1/true/false.
/// Blank lines and lines starting with '#' are skipped. Errors: ScenarioError at the file's line, named `key`.
ParticleFile readParticleCsv(const std::filesystem::path& file, int dimension,
                             const std::vector<MaterialDef>& materials, const std::string& key);
ParticleFile readParticleCsv(std::istream& in, const std::string& name, int dimension,
                             const std::vector<MaterialDef>& materials, const std::string& key);

/// Reads a LAMMPS data file written for atom_style sphere: header counts and box bounds, "Atoms # sphere" lines
/// `id type diameter density x y z [ix iy iz]`, optional "Velocities" lines `id vx vy vz wx wy wz`.
/// Particles keep the order of the Atoms section. Errors: ScenarioError at the file's line, named `key`.
ParticleFile readLammpsData(const std::filesystem::path& file, const std::string& key);
ParticleFile readLammpsData(std::istream& in, const std::string& name, const std::string& key);

// ---- Placing particles: shared by [[insert]] and the inlets (run/flow.hpp) -----------------------------------------

/// Linked-cell grid over a box, for the overlap test of a candidate against the particles placed so far.
/// The cell edge is at least the largest diameter, so a candidate can only overlap particles in the 3^D cells
/// around its own. Points beyond the box are stored in the border cells (clamped), which keeps that rule true.
template <int D>
class OverlapGrid {
public:
    /// Box [lo, hi]; `maxRadius` bounds every radius that will be added or tested [m]; `expected` is the number of
    /// particles that will be added, used to keep the cell count proportional to it.
    OverlapGrid(const Vec<D>& lo, const Vec<D>& hi, double maxRadius, std::size_t expected) {
        double cell = 2 * maxRadius;
        const double cap = std::max(4096.0, std::min(8.0 * double(expected), double(1u << 22)));
        auto cellCount = [&](double c) {
            double n = 1;
            for (int k = 0; k < D; ++k) n *= std::max(1.0, std::ceil((hi[k] - lo[k]) / c));
            return n;
        };
        while (cellCount(cell) > cap) cell *= 1.5;
        std::array<int, D> n;
        for (int k = 0; k < D; ++k) n[k] = std::max(1, int(std::ceil((hi[k] - lo[k]) / cell)));
        grid_ = CellGrid<D>(lo, n, Vec<D>::filled(cell), std::array<bool, D>{});
        head_.assign(std::size_t(grid_.count()), kNone);
    }

    void add(const Vec<D>& x, double r) {
        const std::size_t c = std::size_t(grid_.cellOf(x));
        x_.push_back(x);
        r_.push_back(r);
        next_.push_back(head_[c]);
        head_[c] = std::uint32_t(x_.size() - 1);
    }

    bool overlaps(const Vec<D>& x, double r) const {
        return grid_.forEachNeighbour(grid_.coordsOf(x), [&](int c, int) {
            for (std::uint32_t j = head_[std::size_t(c)]; j != kNone; j = next_[j]) {
                const double reach = r + r_[j];
                // Touching (distance equal to the sum of radii, up to rounding) is allowed: a lattice of
                // spacing 2r touches exactly.
                if (norm2(x - x_[j]) < reach * reach * (1 - 1e-12)) return true;
            }
            return false;
        });
    }

private:
    static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

    CellGrid<D> grid_;  // open on every axis
    std::vector<std::uint32_t> head_;
    std::vector<std::uint32_t> next_;
    std::vector<Vec<D>> x_;
    std::vector<double> r_;
};

/// A particle about to be added to the store.
template <int D>
struct NewParticle {
    Vec<D> x{};
    Vec<D> v{};
    Ang<D> w{};
    double radius = 0;
    double density = 0;  ///< [kg/m^3] (2D: [kg/m^2])
    std::uint16_t material = 0;
    std::uint8_t flags = 0;
    std::array<std::int32_t, D> image{};  ///< periodic box crossings (Particles::image)
    std::vector<Vec<2>> body;             ///< polygon vertices in the body frame [m]; empty for a disk or sphere
    double orientation = 0;               ///< polygon angle [rad]

    double mass() const {
        if (body.empty()) return density * Particles<D>::volumeOf(radius);
        return density * polygon::polygonMoments(body.data(), int(body.size())).area;
    }
};

template <int D>
class WallClearance;  // scenario/walls.hpp: the one test of new particles against the walls (inserts and inlets)

/// Random sequential addition into the region of `in` (a box, or a vertical cylinder) against the store's
/// particles, the walls (WallClearance) and the particles it placed before: the placement of arrangement = "random",
/// and of every inlet batch.
template <int D>
class RandomPlacer {
public:
    /// `expected`: how many particles will be placed (sizes the grid).
    RandomPlacer(const Scenario& s, const InsertDef& in, const Particles<D>& store, std::size_t expected);
    ~RandomPlacer();
    RandomPlacer(RandomPlacer&&) noexcept;
    /// Draws positions of p (radius set) in the region until one is free, at most `tries` times; then p.x holds
    /// it and the placer knows p. Returns the number of draws it took, 0 when none was free.
    std::uint64_t place(NewParticle<D>& p, Rng& rng, std::uint64_t tries);

private:
    const Scenario& s_;
    const InsertDef& in_;
    Vec<D> lo_, hi_;
    OverlapGrid<D> grid_;
    std::unique_ptr<const WallClearance<D>> walls_;
};

/// The shape of a polygon insert (drawn after the position), density, material and flags of a placed particle.
template <int D>
void finishParticle(const Scenario& s, const InsertDef& in, NewParticle<D>& p, Rng& rng);
/// p.v: the insert's mean velocity plus, when its temperature > 0, a Maxwellian of that variance per component.
template <int D>
void thermalVelocity(const InsertDef& in, NewParticle<D>& p, Rng& rng);
/// Appends p to the store with id `id`; returns its index.
template <int D>
std::size_t addToStore(Particles<D>& store, const NewParticle<D>& p, std::uint64_t id);

/// Executes every [[insert]] of `scenario` in order, appending to `particles` (ids consecutive from its current size).
/// Random numbers come from `rng` only, so the result depends on the seed alone. Throws ScenarioError when an insert
/// cannot be done (lattice spacing below one diameter, no room for random placement, a bad particle file); the store
/// keeps the particles of the inserts done before. Requires scenario.dimension == D.
template <int D>
void insertParticles(const Scenario& scenario, Particles<D>& particles, Rng rng);

extern template void insertParticles<2>(const Scenario&, Particles<2>&, Rng);
extern template void insertParticles<3>(const Scenario&, Particles<3>&, Rng);
extern template class RandomPlacer<2>;
extern template class RandomPlacer<3>;

}  // namespace haet
