#include "io/spheres.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

#include "io/canvas.hpp"

namespace haet {

namespace {

using V3 = std::array<double, 3>;

double dot3(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 sub3(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 cross3(const V3& a, const V3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
V3 unit3(const V3& a, const char* what) {
    const double n = std::sqrt(dot3(a, a));
    if (!(n > 0) || !std::isfinite(n)) throw std::invalid_argument(what);
    return {a[0] / n, a[1] / n, a[2] / n};
}

/// At most this many pixels on a side of a view, and in all (4096 x 4096: its colour and depth buffers stay under
/// 200 MB); a larger view is drawn smaller.
constexpr double kMaxViewSide = 4096, kMaxViewPixels = 16777216;
constexpr std::uint32_t kWallRgb = 0x6f86a8, kBoxRgb = 0xb4b4b4, kEdgeRgb = 0x303030;
constexpr double kWallAlpha = 0.18;
/// The light, in screen axes (right, up, towards the viewer): from the upper left, in front.
constexpr V3 kLight = {-0.4319, 0.5758, 0.6939};
/// Half-way between the light and the eye (0, 0, 1), normalised.
constexpr V3 kHalf = {-0.2347, 0.3129, 0.9204};

/// A channel value rounded half up (the values are >= 0: no call to lround, a fifth of a frame's time).
std::uint32_t channel(double v) { return static_cast<std::uint32_t>(std::clamp(v, 0.0, 255.0) + 0.5); }

std::uint32_t shade(std::uint32_t rgb, double f) {
    auto ch = [&](int shift) { return channel(((rgb >> shift) & 0xff) * f) << shift; };
    return ch(16) | ch(8) | ch(0);
}

std::uint32_t blend(std::uint32_t under, std::uint32_t over, double alpha) {
    auto ch = [&](int shift) {
        const double a = (under >> shift) & 0xff, b = (over >> shift) & 0xff;
        return channel(a + alpha * (b - a)) << shift;
    };
    return ch(16) | ch(8) | ch(0);
}

/// The rasteriser: spheres into the depth buffer, then translucent triangles and lines tested against it.
class Raster {
public:
    explicit Raster(SphereImage& img) : img_(img) {}

    void sphere(const V3& p, double rp, std::uint32_t rgb) {
        const int w = img_.width, h = img_.height;
        // A sphere smaller than a pixel still marks the pixel of its centre.
        int x0 = static_cast<int>(std::ceil(p[0] - rp - 0.5)), x1 = static_cast<int>(std::floor(p[0] + rp - 0.5));
        int y0 = static_cast<int>(std::ceil(p[1] - rp - 0.5)), y1 = static_cast<int>(std::floor(p[1] + rp - 0.5));
        const bool tiny = x0 > x1 || y0 > y1;
        if (tiny) x0 = x1 = static_cast<int>(std::floor(p[0])), y0 = y1 = static_cast<int>(std::floor(p[1]));
        x0 = std::max(x0, 0), y0 = std::max(y0, 0), x1 = std::min(x1, w - 1), y1 = std::min(y1, h - 1);
        const double r2 = rp * rp, rim2 = rp >= 3 ? (rp - 1) * (rp - 1) : r2;
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const double dx = x + 0.5 - p[0], dy = y + 0.5 - p[1], q = dx * dx + dy * dy;
                if (q > r2 && !tiny) continue;
                const double hz = std::sqrt(std::max(0.0, r2 - q));
                const double z = p[2] - hz;
                const std::size_t k = static_cast<std::size_t>(y) * w + x;
                if (!(z < img_.depth[k])) continue;
                img_.depth[k] = z;
                if (tiny) {
                    img_.rgb[k] = rgb;
                    continue;
                }
                // Lambert shading of the surface normal (dx, -dy, hz) / rp with a highlight (Blinn: the normal
                // against the half-way vector of light and eye); a dark rim outlines each sphere.
                const double lit = std::max(0.0, (dx * kLight[0] - dy * kLight[1] + hz * kLight[2]) / rp);
                const double half = std::max(0.0, (dx * kHalf[0] - dy * kHalf[1] + hz * kHalf[2]) / rp);
                const double h2 = half * half, h4 = h2 * h2, h8 = h4 * h4;
                const std::uint32_t c = shade(rgb, (0.45 + 0.55 * lit) * (q > rim2 ? 0.45 : 1.0));
                img_.rgb[k] = q > rim2 ? c : blend(c, 0xffffff, 0.3 * h8 * h8);
            }
    }

    /// A triangle in screen coordinates, blended over whatever lies behind it. The pixels on an edge shared by two
    /// triangles belong to one of them only (by the edge's direction), so that a mesh shows no seams.
    void triangle(V3 a, V3 b, V3 c, std::uint32_t rgb, double alpha) {
        auto edge = [](const V3& p, const V3& q, double x, double y) {
            return (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]);
        };
        double area = edge(a, b, c[0], c[1]);
        if (!(std::abs(area) > 1e-12)) return;
        if (area < 0) std::swap(b, c), area = -area;
        auto owns = [](const V3& p, const V3& q, double e) {
            const double dx = q[0] - p[0], dy = q[1] - p[1];
            return e > 0 || (e == 0 && (dy > 0 || (dy == 0 && dx > 0)));
        };
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a[0], b[0], c[0]}))));
        const int x1 = std::min(img_.width - 1, static_cast<int>(std::ceil(std::max({a[0], b[0], c[0]}))));
        const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a[1], b[1], c[1]}))));
        const int y1 = std::min(img_.height - 1, static_cast<int>(std::ceil(std::max({a[1], b[1], c[1]}))));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const double px = x + 0.5, py = y + 0.5;
                const double w0 = edge(b, c, px, py), w1 = edge(c, a, px, py), w2 = edge(a, b, px, py);
                if (!owns(b, c, w0) || !owns(c, a, w1) || !owns(a, b, w2)) continue;
                const double z = (w0 * a[2] + w1 * b[2] + w2 * c[2]) / area;
                const std::size_t k = static_cast<std::size_t>(y) * img_.width + x;
                if (z < img_.depth[k]) img_.rgb[k] = blend(img_.rgb[k], rgb, alpha);
            }
    }

    /// A 1 px line in screen coordinates, hidden where a sphere is nearer.
    void line(const V3& a, const V3& b, std::uint32_t rgb) {
        const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
        const double len = std::max(std::abs(dx), std::abs(dy));
        if (!std::isfinite(len) || len > 4.0 * kMaxPx) return;
        const int n = std::max(1, static_cast<int>(std::ceil(len)));
        for (int s = 0; s <= n; ++s) {
            const double t = static_cast<double>(s) / n;
            const int x = static_cast<int>(std::floor(a[0] + t * dx)), y = static_cast<int>(std::floor(a[1] + t * dy));
            if (x < 0 || y < 0 || x >= img_.width || y >= img_.height) continue;
            const std::size_t k = static_cast<std::size_t>(y) * img_.width + x;
            if (a[2] + t * dz <= img_.depth[k] + 1.0) img_.rgb[k] = rgb;
        }
    }

private:
    SphereImage& img_;
};

/// A polygon clipped to the box (Sutherland–Hodgman, one face at a time); each vertex carries whether the edge that
/// starts at it is drawn. An edge made by the clipping lies on a face of the box: where the wall meets the box, drawn.
struct ClipVertex {
    V3 p;
    bool drawn;
};

std::vector<ClipVertex> clipToBox(std::vector<ClipVertex> poly, const V3& lo, const V3& hi) {
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const double bound = side == 0 ? lo[axis] : hi[axis];
            auto inside = [&](const V3& p) { return side == 0 ? p[axis] >= bound : p[axis] <= bound; };
            std::vector<ClipVertex> out;
            for (std::size_t k = 0; k < poly.size(); ++k) {
                const ClipVertex& a = poly[k];
                const ClipVertex& b = poly[(k + 1) % poly.size()];
                auto cut = [&] {
                    const double t = (bound - a.p[axis]) / (b.p[axis] - a.p[axis]);
                    V3 p;
                    for (int c = 0; c < 3; ++c) p[c] = a.p[c] + t * (b.p[c] - a.p[c]);
                    p[axis] = bound;
                    return p;
                };
                if (inside(b.p)) {
                    if (!inside(a.p)) out.push_back({cut(), a.drawn});
                    out.push_back(b);
                } else if (inside(a.p)) {
                    out.push_back({cut(), true});
                }
            }
            poly = std::move(out);
            if (poly.empty()) return poly;
        }
    return poly;
}

/// The part of segment ab inside the box (Liang–Barsky); false if none.
bool clipSegment(V3& a, V3& b, const V3& lo, const V3& hi) {
    double t0 = 0, t1 = 1;
    const V3 d = sub3(b, a);
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0) {
            if (a[k] < lo[k] || a[k] > hi[k]) return false;
            continue;
        }
        double ta = (lo[k] - a[k]) / d[k], tb = (hi[k] - a[k]) / d[k];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta), t1 = std::min(t1, tb);
        if (t0 > t1) return false;
    }
    const V3 a0 = a;
    for (int k = 0; k < 3; ++k) a[k] = a0[k] + t0 * d[k], b[k] = a0[k] + t1 * d[k];
    return true;
}

/// Newell's normal of a polygon (not normalised).
V3 newell(const std::vector<V3>& pts) {
    V3 n{0, 0, 0};
    for (std::size_t k = 0; k < pts.size(); ++k) {
        const V3& a = pts[k];
        const V3& b = pts[(k + 1) % pts.size()];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    return n;
}

/// Whether each edge of the walls' polygons is outlined: a rim (an edge of one polygon only) or a silhouette (between
/// a polygon that faces the camera and one that does not: faces away or is seen edge on, as the sides of a box seen
/// face on). Keyed by wall and point ids, in a fixed order.
std::map<std::tuple<std::int32_t, std::int64_t, std::int64_t>, bool> outlinedEdges(const WallShapes& sh, const V3& d) {
    struct Use {
        int count = 0, front = 0, other = 0;
    };
    std::map<std::tuple<std::int32_t, std::int64_t, std::int64_t>, Use> uses;
    for (std::size_t c = 0; c + 1 < sh.polyFirst.size(); ++c) {
        const std::int64_t f0 = sh.polyFirst[c], f1 = sh.polyFirst[c + 1];
        std::vector<V3> pts;
        for (std::int64_t k = f0; k < f1; ++k) pts.push_back(sh.points[static_cast<std::size_t>(sh.polyIndex[k])]);
        const V3 n = newell(pts);
        const double facing = dot3(n, d), tol = 1e-9 * std::sqrt(dot3(n, n));
        for (std::int64_t k = f0; k < f1; ++k) {
            const std::int64_t a = sh.polyIndex[k], b = sh.polyIndex[k + 1 < f1 ? k + 1 : f0];
            Use& u = uses[{sh.polyWall[c], std::min(a, b), std::max(a, b)}];
            ++u.count;
            u.front += facing < -tol;
            u.other += facing >= -tol;
        }
    }
    std::map<std::tuple<std::int32_t, std::int64_t, std::int64_t>, bool> out;
    for (const auto& [key, u] : uses) out[key] = u.count == 1 || (u.front > 0 && u.other > 0);
    return out;
}

}  // namespace

std::optional<std::array<double, 3>> axisView(const std::string& name) {
    const bool neg = !name.empty() && name[0] == '-';
    const std::string axis = neg ? name.substr(1) : name;
    if (axis != "x" && axis != "y" && axis != "z") return std::nullopt;
    std::array<double, 3> v{0, 0, 0};
    v[static_cast<std::size_t>(axis[0] - 'x')] = neg ? -1 : 1;
    return v;
}

OrthoView::OrthoView(const SphereScene& scene) {
    for (int k = 0; k < 3; ++k)
        if (!(scene.hi[k] > scene.lo[k]) || !std::isfinite(scene.hi[k] - scene.lo[k]))
            throw std::invalid_argument("picture: empty box (hi <= lo)");
    d_ = unit3(scene.view, "picture: the view direction is zero");
    const double ud = dot3(scene.up, d_);
    u_ = unit3({scene.up[0] - ud * d_[0], scene.up[1] - ud * d_[1], scene.up[2] - ud * d_[2]},
               "picture: the up direction is parallel to the view");
    r_ = cross3(d_, u_);
    double u0 = std::numeric_limits<double>::infinity(), u1 = -u0, v0 = u0, v1 = -u0;
    for (int c = 0; c < 8; ++c) {
        const V3 p = {c & 1 ? scene.hi[0] : scene.lo[0], c & 2 ? scene.hi[1] : scene.lo[1],
                      c & 4 ? scene.hi[2] : scene.lo[2]};
        u0 = std::min(u0, dot3(p, r_)), u1 = std::max(u1, dot3(p, r_));
        v0 = std::min(v0, dot3(p, u_)), v1 = std::max(v1, dot3(p, u_));
    }
    u0_ = u0, v1_ = v1;
    // The asked width, unless the height or the pixel count would pass its cap: then smaller, never larger.
    const double m2 = 2 * kMargin;
    const double avail = std::clamp(static_cast<double>(scene.widthPx), m2 + 1, kMaxViewSide) - m2;
    scale_ = avail / (u1 - u0);
    scale_ = std::min(scale_, (kMaxViewSide - m2) / (v1 - v0));
    const double pixels = ((u1 - u0) * scale_ + m2) * ((v1 - v0) * scale_ + m2);
    if (pixels > kMaxViewPixels) scale_ *= std::sqrt(kMaxViewPixels / pixels) * 0.999;
    width_ = std::max(1, static_cast<int>(std::ceil((u1 - u0) * scale_ + m2)));
    height_ = std::max(1, static_cast<int>(std::ceil((v1 - v0) * scale_ + m2)));
}

std::array<double, 3> OrthoView::toScreen(const std::array<double, 3>& p) const {
    return {(dot3(p, r_) - u0_) * scale_ + kMargin, (v1_ - dot3(p, u_)) * scale_ + kMargin, dot3(p, d_) * scale_};
}

SphereImage renderSpheres(const SphereScene& scene) {
    const OrthoView view(scene);
    SphereImage img;
    img.width = view.width();
    img.height = view.height();
    const std::size_t n = static_cast<std::size_t>(img.width) * img.height;
    img.rgb.assign(n, 0xffffff);
    img.depth.assign(n, std::numeric_limits<double>::infinity());
    Raster raster(img);
    const double reach = 4.0 * kMaxPx;  // beyond this a sphere covers the picture [px]
    for (const SphereScene::Sphere& s : scene.spheres) {
        const V3 p = view.toScreen(s.c);
        const double rp = s.r * view.scale();
        // A state that blew up is drawn as far as it can be, never as an endless loop over pixels.
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]) || !(rp >= 0)) continue;
        if (std::abs(p[0]) > reach || std::abs(p[1]) > reach) continue;
        raster.sphere(p, std::min(rp, reach), s.rgb);
    }

    // Walls: clipped to the box (a hair wider, so that a wall on a face of the box stays), translucent, outlined.
    double span = 0;
    for (int k = 0; k < 3; ++k) span = std::max(span, scene.hi[k] - scene.lo[k]);
    V3 lo = scene.lo, hi = scene.hi;
    for (int k = 0; k < 3; ++k) lo[k] -= 1e-9 * span, hi[k] += 1e-9 * span;
    const WallShapes& sh = scene.walls;
    const auto outlined = outlinedEdges(sh, view.forward());
    std::vector<std::pair<V3, V3>> edges;
    for (std::size_t c = 0; c + 1 < sh.polyFirst.size(); ++c) {
        const std::int64_t f0 = sh.polyFirst[c], f1 = sh.polyFirst[c + 1];
        std::vector<ClipVertex> poly;
        std::vector<V3> pts;
        for (std::int64_t k = f0; k < f1; ++k) {
            const std::int64_t a = sh.polyIndex[k], b = sh.polyIndex[k + 1 < f1 ? k + 1 : f0];
            const V3& p = sh.points[static_cast<std::size_t>(a)];
            poly.push_back({p, outlined.at({sh.polyWall[c], std::min(a, b), std::max(a, b)})});
            pts.push_back(p);
        }
        V3 nrm = newell(pts);
        const double nn = std::sqrt(dot3(nrm, nrm));
        const double f = nn > 0 ? 0.6 + 0.4 * std::abs(dot3(nrm, view.forward())) / nn : 0.6;
        poly = clipToBox(std::move(poly), lo, hi);
        if (poly.size() < 2) continue;
        std::vector<V3> s;
        for (const ClipVertex& v : poly) s.push_back(view.toScreen(v.p));
        for (std::size_t k = 1; k + 1 < s.size(); ++k)
            raster.triangle(s[0], s[k], s[k + 1], shade(kWallRgb, f), kWallAlpha);
        for (std::size_t k = 0; k < s.size(); ++k)
            if (poly[k].drawn) edges.push_back({s[k], s[(k + 1) % s.size()]});
    }
    for (std::size_t c = 0; c + 1 < sh.lineFirst.size(); ++c)
        for (std::int64_t k = sh.lineFirst[c]; k + 1 < sh.lineFirst[c + 1]; ++k) {
            V3 a = sh.points[static_cast<std::size_t>(sh.lineIndex[k])];
            V3 b = sh.points[static_cast<std::size_t>(sh.lineIndex[k + 1])];
            if (clipSegment(a, b, lo, hi)) edges.push_back({view.toScreen(a), view.toScreen(b)});
        }
    // The box's twelve edges, light, under the walls' outlines.
    for (int c = 0; c < 8; ++c)
        for (int axis = 0; axis < 3; ++axis) {
            if (c & (1 << axis)) continue;
            const int c1 = c | (1 << axis);
            auto corner = [&](int q) {
                return V3{q & 1 ? scene.hi[0] : scene.lo[0], q & 2 ? scene.hi[1] : scene.lo[1],
                          q & 4 ? scene.hi[2] : scene.lo[2]};
            };
            raster.line(view.toScreen(corner(c)), view.toScreen(corner(c1)), kBoxRgb);
        }
    for (const auto& [a, b] : edges) raster.line(a, b, kEdgeRgb);
    return img;
}

void writeSpherePng(const std::filesystem::path& path, const SphereScene& scene) {
    const SphereImage img = renderSpheres(scene);
    const KeySize key = keySize(scene.key);
    Canvas canvas = makeCanvas(path, img.width + key.width, std::max(img.height, key.height));
    cairo_surface_t* surface = canvas.surface.get();
    cairo_surface_flush(surface);
    unsigned char* data = cairo_image_surface_get_data(surface);
    const int stride = cairo_image_surface_get_stride(surface);
    for (int y = 0; y < img.height; ++y) {
        auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
        std::copy_n(img.rgb.begin() + static_cast<std::ptrdiff_t>(y) * img.width, img.width, row);
    }
    cairo_surface_mark_dirty(surface);
    drawCaption(canvas.cr.get(), scene.caption, img.width);
    drawKey(canvas.cr.get(), scene.key, img.width, std::max(img.height, key.height));
    savePng(surface, path);
}

}  // namespace haet
