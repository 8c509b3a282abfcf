#pragma once
// What the pictures of io/ share: a Cairo image on white, its PNG encoding, text placement, and the key (legend or
// colour bar) drawn in a strip at the right of a picture. Used by png.cpp and spheres.cpp only.
#include <cairo.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "io/colour.hpp"

namespace haet {

inline constexpr int kMaxPx = 16384;             // well inside Cairo's 32767 limit, and a 1 GiB ARGB buffer at most
inline constexpr std::uint32_t kInk = 0x262626;  // outlines, axes and text

struct Canvas {
    std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface{nullptr, cairo_surface_destroy};
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr{nullptr, cairo_destroy};
};

/// A white RGB24 image. Throws std::invalid_argument for a size outside 1..kMaxPx, IoError if Cairo fails.
Canvas makeCanvas(const std::filesystem::path& path, int width, int height);
void setColor(cairo_t* cr, std::uint32_t rgb, double alpha = 1.0);
/// Encodes the image as PNG, atomically. Throws IoError.
void savePng(cairo_surface_t* surface, const std::filesystem::path& path);
/// Draws `s` so that the point (x, y) [px] sits at fraction (ax, ay) of its box: (0, 0) top left,
/// (0.5, 0.5) centre, (1, 1) bottom right.
void drawText(cairo_t* cr, const std::string& s, double x, double y, double ax, double ay);

/// The key's strip: its width and the least height it needs [px] (0, 0 for an empty key).
struct KeySize {
    int width = 0, height = 0;
};
KeySize keySize(const PictureKey& key);
/// Draws the key in the strip whose top-left corner is (x0, 0), `height` px tall.
void drawKey(cairo_t* cr, const PictureKey& key, double x0, double height);
/// A caption at the top left, on a translucent white box so that it stays legible over particles.
void drawCaption(cairo_t* cr, const std::string& caption, int widthPx);

}  // namespace haet
