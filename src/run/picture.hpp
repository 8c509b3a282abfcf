#pragma once
// Pictures of a snapshot: the particles of a ParticleFrame coloured by one of its fields (a legend for categories,
// a colour bar for values), the walls, the box; 2D as drawn disks and polygons, 3D as an orthographic projection of
// shaded spheres (io/spheres.hpp). The run draws final.png with it and `haet render` every snapshot, from the same
// frame: what the run wrote is what is drawn.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/colour.hpp"
#include "io/frame.hpp"
#include "io/png.hpp"
#include "io/vtk.hpp"

namespace haet {

/// The box of the run and what orients a 3D picture.
struct PictureBox {
    int dimension = 3;
    std::array<double, 3> lo{0, 0, 0}, hi{1, 1, 1};  ///< [m] (2D: z = 0)
    std::array<double, 3> gravity{0, 0, 0};          ///< [m/s^2]; up on the screen is the box axis against it
};

struct PictureOptions {
    std::string colorBy;                         ///< a field of the frame (docs/scenario.md, [output]); "" = default
    std::optional<std::array<double, 2>> range;  ///< colour bar limits; none = the data's
    std::array<double, 3> view{0, 1, 0};         ///< 3D: the direction the camera looks along
    int widthPx = 900;                           ///< [px] of the view, before the key
};

/// What a picture is coloured by when nothing is asked: mode in a hybrid run (the frame has it), else velocity.
std::string defaultColorBy(const ParticleFrame& frame);

/// The values a continuous colouring reads (a field, the magnitude of a vector field, or one component with the
/// suffix _x, _y, _z), or nullopt for a categorical one (mode, material). Throws std::invalid_argument naming the
/// fields the frame has when `colorBy` is none of them.
std::optional<std::vector<double>> colourValues(const ParticleFrame& frame, const std::string& colorBy);

/// The finite [min, max] of a continuous colouring over the frame, or nullopt (categorical, no finite value).
std::optional<std::array<double, 2>> colourRange(const ParticleFrame& frame, const std::string& colorBy);

struct ParticleColours {
    std::vector<std::uint32_t> rgb;  ///< one per particle
    PictureKey key;
};

/// The colours of the particles and their key. `materials` names material k (an index past it is "material k").
ParticleColours colourParticles(const ParticleFrame& frame, const std::string& colorBy,
                                const std::optional<std::array<double, 2>>& range,
                                const std::vector<std::string>& materials);

/// Up on the screen for a 3D view: of +z, +y, +x, -z, -y, -x the first most opposed to gravity that is not
/// parallel to the view (with no gravity: +z, or +y when looking along z).
std::array<double, 3> screenUp(const std::array<double, 3>& view, const std::array<double, 3>& gravity);

/// The 2D walls as segments: line cells as they are, a plane (a thin quad of wallShapes) as the line through its
/// middle, long enough to cross the picture.
std::vector<PngScene::Segment> wallSegments2d(const WallShapes& walls);

/// Draws the frame as PNG (atomically). `polygons` are the outlines of 2D polygon particles, matched by id.
/// Throws std::invalid_argument for a field the frame lacks, IoError if the file cannot be written.
void writeFramePicture(const std::filesystem::path& path, const ParticleFrame& frame, const WallShapes& walls,
                       const PictureBox& box, const PictureOptions& options, const std::vector<std::string>& materials,
                       const PolygonOutlines* polygons = nullptr);

}  // namespace haet
