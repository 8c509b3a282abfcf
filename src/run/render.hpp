#pragma once
// `haet render RUNDIR`: every snapshot of a run drawn as final.png is (run/picture.hpp), from the files the run wrote
// (particles.pvd and its snapshots, the walls and polygons of each, run.json for the box, the materials and the
// picture settings), and a movie of them when ffmpeg is installed. docs/scenario.md, "Pictures".
#include <array>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>

namespace haet {

struct RenderOptions {
    std::filesystem::path runDir;
    std::filesystem::path outDir;                ///< "" = RUNDIR/render
    std::optional<std::string> field;            ///< what the particles are coloured by; none = the run's color_by
    std::optional<std::array<double, 3>> view;   ///< 3D; none = the run's view
    std::optional<std::array<double, 2>> range;  ///< none = the run's color_range, else the range over all snapshots
    std::optional<int> widthPx;                  ///< none = the run's picture_width
    double fps = 10;                             ///< frames per second of the movie
    bool movie = true;                           ///< write movie.mp4 when ffmpeg is on PATH
};

struct RenderSummary {
    std::size_t frames = 0;
    std::filesystem::path outDir;
    bool movie = false;  ///< movie.mp4 written
};

/// Draws the run's snapshots as outDir/frame_NNNNNN.png (and outDir/movie.mp4), after removing the frames and the
/// movie an earlier render left there; notes what it did on `log`. Throws std::invalid_argument for a missing or
/// broken run directory or an option the run cannot take (VtkReadError for a broken snapshot), IoError when an
/// output cannot be written or ffmpeg fails.
RenderSummary renderRun(const RenderOptions& options, std::ostream& log);

/// A view from the command line or the scenario: an axis ("x", "-y", ...) or three numbers "dx,dy,dz" (brackets
/// allowed), not all zero; nullopt if `text` is neither.
std::optional<std::array<double, 3>> parseView(const std::string& text);

/// Two numbers "lo,hi" (brackets allowed) with hi > lo; nullopt otherwise.
std::optional<std::array<double, 2>> parseRange(const std::string& text);

/// The path of an executable `program` on PATH, or "" when there is none.
std::filesystem::path findOnPath(const std::string& program);

}  // namespace haet
