#pragma once
// One snapshot of the particles as owned arrays: what particles_NNNNNN.vtu holds. The run builds it from its state,
// writes it, and draws final.png from it; `haet render` reads it back from the files and draws it the same way.
// Reading covers the files HAET writes (VTK XML, appended raw, UInt64 headers), not VTK XML in general.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/vtk.hpp"

namespace haet {

/// A file that is not one HAET wrote or that is cut short. The message starts with the path.
class VtkReadError : public std::invalid_argument {
public:
    VtkReadError(const std::filesystem::path& path, const std::string& what)
        : std::invalid_argument(path.string() + ": " + what) {}
};

/// One per-particle array. Values are kept as doubles (integer arrays exactly: ids below 2^53); `type` is how the
/// file stores them.
struct FrameField {
    std::string name;
    int components = 1;
    VtkField::Type type = VtkField::Float64;
    std::vector<double> values;  ///< size() * components, interleaved

    double at(std::size_t i, int c = 0) const { return values[i * static_cast<std::size_t>(components) + c]; }
};

struct ParticleFrame {
    double time = 0;          ///< [s]
    std::vector<double> xyz;  ///< 3 per particle [m] (z = 0 in 2D)
    std::vector<FrameField> fields;

    std::size_t size() const { return xyz.size() / 3; }
    /// The field of that name, or nullptr.
    const FrameField* field(const std::string& name) const;
    /// Appends a field of n * components values, all zero.
    FrameField& add(std::string name, int components, VtkField::Type type);
};

/// Writes the frame as VTK_VERTEX cells with its fields as point data (writeVtuPoints). Throws IoError.
void writeFrameVtu(const std::filesystem::path& path, const ParticleFrame& frame);

/// Reads a particle snapshot written by writeFrameVtu. Throws VtkReadError if it cannot be read or is not such a
/// file.
ParticleFrame readFrameVtu(const std::filesystem::path& path);

/// Reads walls written by writeVtpShapes. Throws as readFrameVtu.
WallShapes readVtpShapes(const std::filesystem::path& path);

/// The polygons of a polygons_NNNNNN.vtu file: each cell's outline (x, y) [m] and the id of its particle.
struct PolygonOutlines {
    std::vector<std::int64_t> id;
    std::vector<std::vector<std::array<double, 2>>> outline;
};
PolygonOutlines readPolygonVtu(const std::filesystem::path& path);

/// The entries of a .pvd collection in file order: time [s] and file (relative to the collection's directory).
struct PvdEntry {
    double time = 0;
    std::string file;
};
std::vector<PvdEntry> readPvd(const std::filesystem::path& path);

}  // namespace haet
