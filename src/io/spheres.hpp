#pragma once
// Pictures of 3D states: an orthographic projection of shaded spheres with a depth buffer per pixel (the nearest
// surface wins, whatever the order of the spheres), translucent walls clipped to the box, their rims and outlines,
// the box's edges, a caption and a key. Pure arithmetic on the pixels: the same scene gives the same bytes.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/colour.hpp"
#include "io/vtk.hpp"

namespace haet {

struct SphereScene {
    struct Sphere {
        std::array<double, 3> c{};  ///< centre [m]
        double r = 0;               ///< radius [m]
        std::uint32_t rgb = 0x9e9e9e;
    };
    std::array<double, 3> lo{0, 0, 0}, hi{1, 1, 1};  ///< the box [m]: the picture frames its projection
    std::array<double, 3> view{0, 1, 0};             ///< the direction the camera looks along (any length > 0)
    std::array<double, 3> up{0, 0, 1};               ///< up on the screen, once made perpendicular to view
    int widthPx = 900;  ///< width of the view [px]; the height follows; at most 4096 px a side (then smaller)
    std::vector<Sphere> spheres;
    WallShapes walls;  ///< drawn clipped to the box; the points [m]
    std::string caption;
    PictureKey key;  ///< drawn in a strip at the right of the view, unless empty
};

/// The view along an axis named "x", "y", "z", "-x", "-y" or "-z"; nullopt for any other text.
std::optional<std::array<double, 3>> axisView(const std::string& name);

/// The projection of a scene: screen x to the right, y down [px] (pixel centres at k + 1/2) and depth along the
/// view [px], with the box's projection inside a margin of kMargin px.
class OrthoView {
public:
    static constexpr double kMargin = 8;
    /// Throws std::invalid_argument for an empty box, a zero view, or an up parallel to the view.
    explicit OrthoView(const SphereScene& scene);
    std::array<double, 3> toScreen(const std::array<double, 3>& p) const;
    int width() const { return width_; }
    int height() const { return height_; }
    double scale() const { return scale_; }  ///< [px/m]
    const std::array<double, 3>& right() const { return r_; }
    const std::array<double, 3>& up() const { return u_; }
    const std::array<double, 3>& forward() const { return d_; }

private:
    std::array<double, 3> r_{}, u_{}, d_{};
    double u0_ = 0, v1_ = 0, scale_ = 1;
    int width_ = 1, height_ = 1;
};

/// The view's pixels (0xRRGGBB, row by row from the top) and the depth of the nearest sphere at each [px] (+inf where
/// there is none).
struct SphereImage {
    int width = 0, height = 0;
    std::vector<std::uint32_t> rgb;
    std::vector<double> depth;
};

/// The view without caption and key.
SphereImage renderSpheres(const SphereScene& scene);

/// The picture with its caption and key, as PNG (atomically). Throws std::invalid_argument as OrthoView, IoError if
/// the file cannot be written.
void writeSpherePng(const std::filesystem::path& path, const SphereScene& scene);

}  // namespace haet
