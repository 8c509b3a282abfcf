#pragma once
// Quick-look pictures with Cairo: a 2D state (disks, polygons, walls) and simple line plots for the
// benchmark results. Files are written atomically.
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "io/colour.hpp"

namespace haet {

/// A 2D state to draw. Coordinates are simulation lengths [m] with y up; colours are 0xRRGGBB.
/// The shape types are nested so their generic names do not clash with geometry types.
struct PngScene {
    struct Disk {
        double x = 0, y = 0;  ///< centre [m]
        double r = 0;         ///< radius [m]
        std::uint32_t rgb = 0x9e9e9e;
    };
    struct Polygon {
        std::vector<std::array<double, 2>> pts;  ///< vertices in order [m]
        std::uint32_t rgb = 0x9e9e9e;
    };
    struct Segment {
        double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< end points [m]
    };

    std::array<double, 2> lo{0, 0};  ///< lower-left corner of the view [m]
    std::array<double, 2> hi{1, 1};  ///< upper-right corner of the view [m]
    int widthPx = 800;               ///< image width [px]; the height follows from the view's aspect ratio
    std::vector<Disk> disks;
    std::vector<Polygon> polygons;
    std::vector<Segment> walls;
    std::string caption;  ///< drawn at the top left (time, step count, ...)
    PictureKey key;       ///< drawn in a strip at the right of the view, unless empty
};

/// Draws the scene on white (and its key to the right of the view) with thin dark outlines. A view that would be taller
/// than 16384 px at widthPx is drawn narrower (16384 px tall); disks with non-finite or far-away coordinates are left
/// out. Throws std::invalid_argument for an empty view, IoError if the file cannot be written.
void writePng(const std::filesystem::path& path, const PngScene& scene);

/// One line of a plot. Points with a non-finite coordinate (or a non-positive one on a log axis) are
/// skipped and break the line.
struct PlotSeries {
    std::string label;  ///< legend text; series without a label get no legend entry
    std::vector<double> x, y;
    std::uint32_t rgb = 0x1f77b4;
};

struct LinePlotOptions {
    int widthPx = 800;   ///< [px]
    int heightPx = 500;  ///< [px]
    bool logX = false;   ///< decades on the x axis (scaling plots)
    bool logY = false;
    bool markers = true;  ///< a dot on every data point, for series of at most 60 points
};

/// An axis of a line plot: limits rounded out to ticks from the finite data range [lo, hi] (lo > hi when there is no
/// data): ticks at 1, 2 or 5 times a power of ten, about six of them; on a log axis at decades.
struct PlotAxis {
    double lo = 0, hi = 1;
    bool log = false;
    std::vector<double> ticks;

    /// Where v lies between lo (0) and hi (1).
    double fraction(double v) const {
        return log ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (v - lo) / (hi - lo);
    }
};
PlotAxis plotAxis(double lo, double hi, bool log);

/// The labelled ticks of a colour bar over [lo, hi]: the multiples within it of the step plotAxis would take; {lo}
/// alone when hi <= lo.
std::vector<double> colourBarTicks(double lo, double hi);

/// A line plot with axes, ticks, grid, axis labels and a legend. Throws as writePng().
void writeLinePlotPng(const std::filesystem::path& path, const std::string& title, const std::string& xlabel,
                      const std::string& ylabel, const std::vector<PlotSeries>& series,
                      const LinePlotOptions& options = {});

}  // namespace haet
