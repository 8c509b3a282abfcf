#include "io/png.hpp"

#include <cairo.h>
#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "io/atomic_file.hpp"
#include "io/canvas.hpp"

namespace haet {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kMaxMarkers = 60;  // denser series would be hidden under their own dots

void pngWrite(png_structp png, png_bytep data, png_size_t length) {
    auto* out = static_cast<AtomicOfstream*>(png_get_io_ptr(png));
    out->write(data, length);
}

void pngFlush(png_structp) {}

/// Encodes Cairo's RGB24 pixels as an 8-bit RGB PNG with the fastest zlib level and the "sub" filter: pictures
/// of disks on a white ground compress about as well as with libpng's defaults (level 6, the filter chosen per
/// row) at a small fraction of the time. Returns false if libpng failed (its errors jump back here).
bool encodePng(const unsigned char* pixels, int width, int height, int stride, AtomicOfstream& out) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    if (!png) return false;
    png_infop info = png_create_info_struct(png);
    std::vector<png_byte> row(3 * static_cast<std::size_t>(width));
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_set_write_fn(png, &out, pngWrite, pngFlush);
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 1);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_write_info(png, info);
    for (int y = 0; y < height; ++y) {
        const auto* src = reinterpret_cast<const std::uint32_t*>(pixels + static_cast<std::ptrdiff_t>(y) * stride);
        for (int x = 0; x < width; ++x) {  // Cairo: one native-endian 32-bit word per pixel, x R G B
            row[3 * x] = static_cast<png_byte>(src[x] >> 16);
            row[3 * x + 1] = static_cast<png_byte>(src[x] >> 8);
            row[3 * x + 2] = static_cast<png_byte>(src[x]);
        }
        png_write_row(png, row.data());
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

Canvas makeCanvas(const std::filesystem::path& path, int width, int height) {
    if (width < 1 || height < 1 || width > kMaxPx || height > kMaxPx)
        throw std::invalid_argument(
            fmt::format("{}: image size {}x{} px is outside 1..{}", path.string(), width, height, kMaxPx));
    Canvas c;
    c.surface.reset(cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height));
    c.cr.reset(cairo_create(c.surface.get()));
    if (cairo_status(c.cr.get()) != CAIRO_STATUS_SUCCESS)
        throw IoError(path, std::string("cannot create image: ") + cairo_status_to_string(cairo_status(c.cr.get())));
    cairo_set_source_rgb(c.cr.get(), 1, 1, 1);
    cairo_paint(c.cr.get());
    return c;
}

void setColor(cairo_t* cr, std::uint32_t rgb, double alpha) {
    cairo_set_source_rgba(cr, ((rgb >> 16) & 0xff) / 255.0, ((rgb >> 8) & 0xff) / 255.0, (rgb & 0xff) / 255.0, alpha);
}

void savePng(cairo_surface_t* surface, const std::filesystem::path& path) {
    cairo_surface_flush(surface);
    AtomicOfstream out(path);
    if (!encodePng(cairo_image_surface_get_data(surface), cairo_image_surface_get_width(surface),
                   cairo_image_surface_get_height(surface), cairo_image_surface_get_stride(surface), out) ||
        !out.stream())
        throw IoError(path, "PNG encoding failed");
    out.commit();
}

void drawText(cairo_t* cr, const std::string& s, double x, double y, double ax, double ay) {
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    cairo_move_to(cr, x - e.x_bearing - ax * e.width, y - e.y_bearing - ay * e.height);
    cairo_show_text(cr, s.c_str());
}

void drawCaption(cairo_t* cr, const std::string& caption, int widthPx) {
    if (caption.empty()) return;
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, std::clamp(widthPx / 50.0, 10.0, 24.0));
    cairo_text_extents_t e;
    cairo_text_extents(cr, caption.c_str(), &e);
    const double pad = 4;
    cairo_rectangle(cr, pad, pad, e.width + 2 * pad, e.height + 2 * pad);
    cairo_set_source_rgba(cr, 1, 1, 1, 0.8);  // keeps the caption legible over particles
    cairo_fill(cr);
    setColor(cr, kInk);
    drawText(cr, caption, 2 * pad, 2 * pad, 0, 0);
}

namespace {

// The key's layout [px]: a title row, then legend rows or a bar of at most kBarMax px.
constexpr int kKeyWidth = 170, kKeyTitle = 34, kKeyRow = 20, kBarMin = 120, kBarMax = 320, kBarWidth = 18;

}  // namespace

KeySize keySize(const PictureKey& key) {
    if (key.empty()) return {};
    const int body = key.categories.empty() ? kBarMin + 20 : kKeyRow * static_cast<int>(key.categories.size()) + 10;
    return {kKeyWidth, kKeyTitle + body};
}

namespace {

/// Sets the font size to `size`, or smaller (down to 7) when `s` would be wider than `width` px.
void fitFont(cairo_t* cr, const std::string& s, double size, double width) {
    cairo_set_font_size(cr, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    if (e.x_advance > width) cairo_set_font_size(cr, std::max(7.0, size * width / e.x_advance));
}

}  // namespace

void drawKey(cairo_t* cr, const PictureKey& key, double x0, double height) {
    if (key.empty()) return;
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    fitFont(cr, key.title, 13, kKeyWidth - 20);
    setColor(cr, kInk);
    drawText(cr, key.title, x0 + 12, 12, 0, 0);
    cairo_set_font_size(cr, 12);
    if (!key.categories.empty()) {
        for (std::size_t k = 0; k < key.categories.size(); ++k) {
            const double y = kKeyTitle + kKeyRow * (k + 0.5);
            cairo_new_sub_path(cr);
            cairo_arc(cr, x0 + 20, y, 6, 0, 2 * kPi);
            setColor(cr, key.categories[k].rgb);
            cairo_fill_preserve(cr);
            setColor(cr, kInk);
            cairo_set_line_width(cr, 0.75);
            cairo_stroke(cr);
            fitFont(cr, key.categories[k].label, 12, kKeyWidth - 42);
            drawText(cr, key.categories[k].label, x0 + 34, y, 0, 0.5);
        }
        return;
    }
    // The bar, hi at the top: one row of pixels per colour, from the same map as the particles.
    const double top = kKeyTitle, barH = std::clamp(height - kKeyTitle - 20, double(kBarMin), double(kBarMax));
    const double x = x0 + 14;
    const int rows = static_cast<int>(barH);
    for (int r = 0; r < rows; ++r) {
        const double v = key.bar.hi - (r + 0.5) / rows * (key.bar.hi - key.bar.lo);
        setColor(cr, key.bar.rgb(v));
        cairo_rectangle(cr, x, top + r, kBarWidth, 1);
        cairo_fill(cr);
    }
    setColor(cr, kInk);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, x + 0.5, top + 0.5, kBarWidth, rows);
    cairo_stroke(cr);
    for (double t : colourBarTicks(key.bar.lo, key.bar.hi)) {
        const double f = key.bar.hi > key.bar.lo ? (key.bar.hi - t) / (key.bar.hi - key.bar.lo) : 0.5;
        const double y = std::round(top + f * rows) + 0.5;
        cairo_move_to(cr, x + kBarWidth, y);
        cairo_line_to(cr, x + kBarWidth + 5, y);
        cairo_stroke(cr);
        drawText(cr, fmt::format("{:.4g}", t), x + kBarWidth + 8, y, 0, 0.5);
    }
}

void writePng(const std::filesystem::path& path, const PngScene& scene) {
    const double spanX = scene.hi[0] - scene.lo[0];
    const double spanY = scene.hi[1] - scene.lo[1];
    if (!(spanX > 0 && spanY > 0)) throw std::invalid_argument(path.string() + ": empty view (hi <= lo)");
    // A view taller than kMaxPx at the asked width (a 2D domain of more than 18 widths) is drawn narrower.
    int widthPx = scene.widthPx;
    if (spanY / spanX * widthPx > kMaxPx) widthPx = std::max(1, static_cast<int>(std::floor(kMaxPx * spanX / spanY)));
    const double scale = widthPx / spanX;  // [px/m]
    const double heightPx = std::round(spanY * scale);
    const KeySize key = keySize(scene.key);
    const int canvasHeight = std::max(static_cast<int>(std::clamp(heightPx, 1.0, double(kMaxPx))), key.height);
    Canvas canvas = makeCanvas(path, widthPx + key.width, canvasHeight);
    const double reach = 4.0 * std::max(widthPx, kMaxPx);  // beyond this a disk covers the picture [px]
    cairo_t* cr = canvas.cr.get();
    auto px = [&](double x) { return (x - scene.lo[0]) * scale; };
    auto py = [&](double y) { return (scene.hi[1] - y) * scale; };
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);

    for (const PngScene::Polygon& p : scene.polygons) {
        if (p.pts.size() < 3) continue;
        cairo_move_to(cr, px(p.pts[0][0]), py(p.pts[0][1]));
        for (std::size_t k = 1; k < p.pts.size(); ++k) cairo_line_to(cr, px(p.pts[k][0]), py(p.pts[k][1]));
        cairo_close_path(cr);
        setColor(cr, p.rgb);
        cairo_fill_preserve(cr);
        setColor(cr, kInk);
        cairo_set_line_width(cr, 0.75);
        cairo_stroke(cr);
    }
    for (const PngScene::Disk& d : scene.disks) {
        // A state that blew up (or a radius of 1e300 m) is drawn as far as it can be, never as an endless arc.
        if (!std::isfinite(px(d.x)) || !std::isfinite(py(d.y)) || !(d.r >= 0)) continue;
        if (std::abs(px(d.x)) > reach || std::abs(py(d.y)) > reach) continue;
        const double rPx = std::min(d.r * scale, reach);
        cairo_new_sub_path(cr);
        cairo_arc(cr, px(d.x), py(d.y), rPx, 0, 2 * kPi);
        setColor(cr, d.rgb);
        // Below ~2 px an outline would hide the fill colour entirely.
        if (rPx < 2) {
            cairo_fill(cr);
            continue;
        }
        cairo_fill_preserve(cr);
        setColor(cr, kInk);
        cairo_set_line_width(cr, std::min(0.75, 0.25 * rPx));
        cairo_stroke(cr);
    }
    setColor(cr, kInk);
    cairo_set_line_width(cr, 2.0);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    for (const PngScene::Segment& s : scene.walls) {
        cairo_move_to(cr, px(s.x0), py(s.y0));
        cairo_line_to(cr, px(s.x1), py(s.y1));
        cairo_stroke(cr);
    }

    drawCaption(cr, scene.caption, widthPx);
    drawKey(cr, scene.key, widthPx, canvasHeight);
    savePng(canvas.surface.get(), path);
}

namespace {

bool usable(double v, bool log) { return std::isfinite(v) && (!log || v > 0); }

/// 1, 2 or 5 times a power of ten, near range/6: about six labelled ticks.
double niceStep(double range) {
    const double raw = range / 6;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double m = raw / mag;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * mag;
}

}  // namespace

std::vector<double> colourBarTicks(double lo, double hi) {
    // A bar narrower than a billionth of its values would take its ticks from steps that k * step cannot tell apart.
    if (!(hi - lo > 1e-9 * std::max(std::abs(lo), std::abs(hi))) || !std::isfinite(hi - lo)) return {lo};
    const double step = niceStep(hi - lo);
    std::vector<double> ticks;
    // Within the bar, to a millionth of a step (so that lo and hi themselves count when they are multiples).
    for (double k = std::ceil(lo / step - 1e-6); k <= std::floor(hi / step + 1e-6); k += 1)
        ticks.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);
    return ticks;
}

PlotAxis plotAxis(double lo, double hi, bool log) {
    PlotAxis a;
    a.log = log;
    if (log) {
        if (lo > hi) lo = 1, hi = 10;
        double e0 = std::floor(std::log10(lo)), e1 = std::ceil(std::log10(hi));
        if (e1 <= e0) e1 = e0 + 1;
        const double stride = std::ceil((e1 - e0) / 8);
        e1 = e0 + stride * std::ceil((e1 - e0) / stride);
        a.lo = std::pow(10.0, e0);
        a.hi = std::pow(10.0, e1);
        for (double e = e0; e <= e1 + 0.5; e += stride) a.ticks.push_back(std::pow(10.0, e));
        return a;
    }
    if (lo > hi) lo = 0, hi = 1;
    if (!(hi - lo > 1e-9 * std::max(std::abs(lo), std::abs(hi)))) {  // one value, or a few ulps: about it
        const double mid = 0.5 * (lo + hi), d = mid == 0 ? 1 : 0.1 * std::abs(mid);
        lo = mid - d, hi = mid + d;
    }
    const double step = niceStep(hi - lo);
    const double k0 = std::floor(lo / step), k1 = std::ceil(hi / step);
    a.lo = k0 * step;
    a.hi = k1 * step;
    for (double k = k0; k <= k1 + 0.5; k += 1) a.ticks.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);
    return a;
}

void writeLinePlotPng(const std::filesystem::path& path, const std::string& title, const std::string& xlabel,
                      const std::string& ylabel, const std::vector<PlotSeries>& series,
                      const LinePlotOptions& options) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    double xLo = inf, xHi = -inf, yLo = inf, yHi = -inf;
    for (const PlotSeries& s : series)
        for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
            if (usable(s.x[i], options.logX) && usable(s.y[i], options.logY)) {
                xLo = std::min(xLo, s.x[i]), xHi = std::max(xHi, s.x[i]);
                yLo = std::min(yLo, s.y[i]), yHi = std::max(yHi, s.y[i]);
            }
    const PlotAxis ax = plotAxis(xLo, xHi, options.logX);
    const PlotAxis ay = plotAxis(yLo, yHi, options.logY);

    Canvas canvas = makeCanvas(path, options.widthPx, options.heightPx);
    cairo_t* cr = canvas.cr.get();
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    // Plot rectangle [px]: room on the left for y tick labels and the y label, at the bottom for x.
    const double left = 80, right = options.widthPx - 40.0, top = 44, bottom = options.heightPx - 56.0;
    if (right - left < 20 || bottom - top < 20)
        throw std::invalid_argument(path.string() + ": plot image too small for axes");
    auto px = [&](double x) { return left + ax.fraction(x) * (right - left); };
    auto py = [&](double y) { return bottom - ay.fraction(y) * (bottom - top); };

    cairo_set_font_size(cr, 12);
    cairo_set_line_width(cr, 1);
    for (double t : ax.ticks) {
        const double x = std::round(px(t)) + 0.5;  // half-pixel: crisp 1 px lines
        setColor(cr, 0xdddddd);
        cairo_move_to(cr, x, top);
        cairo_line_to(cr, x, bottom);
        cairo_stroke(cr);
        setColor(cr, kInk);
        cairo_move_to(cr, x, bottom);
        cairo_line_to(cr, x, bottom + 5);
        cairo_stroke(cr);
        drawText(cr, fmt::format("{:g}", t), x, bottom + 8, 0.5, 0);
    }
    for (double t : ay.ticks) {
        const double y = std::round(py(t)) + 0.5;
        setColor(cr, 0xdddddd);
        cairo_move_to(cr, left, y);
        cairo_line_to(cr, right, y);
        cairo_stroke(cr);
        setColor(cr, kInk);
        cairo_move_to(cr, left - 5, y);
        cairo_line_to(cr, left, y);
        cairo_stroke(cr);
        drawText(cr, fmt::format("{:g}", t), left - 8, y, 1, 0.5);
    }
    setColor(cr, kInk);
    cairo_rectangle(cr, left + 0.5, top + 0.5, right - left, bottom - top);
    cairo_stroke(cr);

    cairo_set_font_size(cr, 14);
    drawText(cr, xlabel, 0.5 * (left + right), options.heightPx - 8.0, 0.5, 1);
    cairo_save(cr);
    cairo_translate(cr, 14, 0.5 * (top + bottom));
    cairo_rotate(cr, -kPi / 2);
    drawText(cr, ylabel, 0, 0, 0.5, 0);
    cairo_restore(cr);
    cairo_set_font_size(cr, 16);
    drawText(cr, title, 0.5 * (left + right), 0.5 * top, 0.5, 0.5);

    cairo_save(cr);
    cairo_rectangle(cr, left, top, right - left, bottom - top);
    cairo_clip(cr);
    cairo_set_line_width(cr, 2);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (const PlotSeries& s : series) {
        const std::size_t n = std::min(s.x.size(), s.y.size());
        setColor(cr, s.rgb);
        bool penDown = false;
        for (std::size_t i = 0; i < n; ++i) {
            if (!usable(s.x[i], ax.log) || !usable(s.y[i], ay.log)) {
                penDown = false;
                continue;
            }
            if (penDown)
                cairo_line_to(cr, px(s.x[i]), py(s.y[i]));
            else
                cairo_move_to(cr, px(s.x[i]), py(s.y[i]));
            penDown = true;
        }
        cairo_stroke(cr);
        if (!options.markers || n > kMaxMarkers) continue;
        for (std::size_t i = 0; i < n; ++i) {
            if (!usable(s.x[i], ax.log) || !usable(s.y[i], ay.log)) continue;
            cairo_new_sub_path(cr);
            cairo_arc(cr, px(s.x[i]), py(s.y[i]), 3, 0, 2 * kPi);
        }
        cairo_fill(cr);
    }
    cairo_restore(cr);

    std::vector<const PlotSeries*> labelled;
    for (const PlotSeries& s : series)
        if (!s.label.empty()) labelled.push_back(&s);
    if (!labelled.empty()) {
        cairo_set_font_size(cr, 12);
        double textWidth = 0;
        for (const PlotSeries* s : labelled) {
            cairo_text_extents_t e;
            cairo_text_extents(cr, s->label.c_str(), &e);
            textWidth = std::max(textWidth, e.x_advance);
        }
        const double rowH = 18, w = textWidth + 44, h = rowH * labelled.size() + 8;
        // The corner (top right, top left, bottom right, bottom left) that hides the least of the lines,
        // judged by samples along every drawn segment.
        const double corners[4][2] = {
            {right - w - 8, top + 8}, {left + 8, top + 8}, {right - w - 8, bottom - h - 8}, {left + 8, bottom - h - 8}};
        std::size_t hidden[4] = {0, 0, 0, 0};
        auto sample = [&](double x, double y) {
            for (std::size_t c = 0; c < 4; ++c)
                hidden[c] +=
                    x >= corners[c][0] && x <= corners[c][0] + w && y >= corners[c][1] && y <= corners[c][1] + h;
        };
        for (const PlotSeries& s : series) {
            bool havePrev = false;
            double xPrev = 0, yPrev = 0;
            for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
                if (!usable(s.x[i], ax.log) || !usable(s.y[i], ay.log)) {
                    havePrev = false;
                    continue;
                }
                const double x = px(s.x[i]), y = py(s.y[i]);
                if (havePrev)
                    for (int k = 1; k < 16; ++k) sample(xPrev + (x - xPrev) * k / 16, yPrev + (y - yPrev) * k / 16);
                sample(x, y);
                havePrev = true, xPrev = x, yPrev = y;
            }
        }
        const std::size_t best = static_cast<std::size_t>(std::min_element(hidden, hidden + 4) - hidden);
        const double x0 = corners[best][0], y0 = corners[best][1];
        cairo_rectangle(cr, x0, y0, w, h);
        cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
        cairo_fill_preserve(cr);
        setColor(cr, 0xaaaaaa);
        cairo_set_line_width(cr, 1);
        cairo_stroke(cr);
        for (std::size_t k = 0; k < labelled.size(); ++k) {
            const double y = y0 + 4 + rowH * (k + 0.5);
            setColor(cr, labelled[k]->rgb);
            cairo_set_line_width(cr, 2);
            cairo_move_to(cr, x0 + 8, y);
            cairo_line_to(cr, x0 + 30, y);
            cairo_stroke(cr);
            setColor(cr, kInk);
            drawText(cr, labelled[k]->label, x0 + 36, y, 0, 0.5);
        }
    }
    savePng(canvas.surface.get(), path);
}

}  // namespace haet
