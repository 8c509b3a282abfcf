#include "run/picture.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <unordered_map>

#include "io/spheres.hpp"

namespace haet {

namespace {

constexpr std::uint32_t kTimeDriven = 0x2864eb, kEventDriven = 0xff9614;

/// The unit of a snapshot field, for the key's title.
std::string unitOf(const std::string& field) {
    static const std::map<std::string, std::string> units = {
        {"velocity", "m/s"}, {"angular_velocity", "rad/s"}, {"force", "N"}, {"radius", "m"}};
    const auto it = units.find(field);
    return it == units.end() ? std::string() : " [" + it->second + "]";
}

std::string fieldList(const ParticleFrame& frame) {
    std::string s;
    for (const FrameField& f : frame.fields) {
        s += (s.empty() ? "" : ", ") + f.name;
        if (f.components > 1) s += " (also " + f.name + "_x, _y, _z)";
    }
    return s;
}

/// The field and component (-1: magnitude) that `colorBy` names.
std::pair<const FrameField*, int> resolve(const ParticleFrame& frame, const std::string& colorBy) {
    if (const FrameField* f = frame.field(colorBy)) return {f, f->components > 1 ? -1 : 0};
    const std::size_t n = colorBy.size();
    if (n > 2 && colorBy[n - 2] == '_' && colorBy[n - 1] >= 'x' && colorBy[n - 1] <= 'z') {
        const FrameField* f = frame.field(colorBy.substr(0, n - 2));
        const int c = colorBy[n - 1] - 'x';
        if (f && f->components > c) return {f, c};
    }
    throw std::invalid_argument("colour by \"" + colorBy + "\": the snapshot has no such field; it has " +
                                fieldList(frame));
}

bool categorical(const std::string& colorBy) { return colorBy == "mode" || colorBy == "material"; }

}  // namespace

std::string defaultColorBy(const ParticleFrame& frame) { return frame.field("mode") ? "mode" : "velocity"; }

std::optional<std::vector<double>> colourValues(const ParticleFrame& frame, const std::string& colorBy) {
    const auto [f, c] = resolve(frame, colorBy);
    if (categorical(colorBy)) return std::nullopt;
    std::vector<double> v(frame.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (c >= 0) {
            v[i] = f->at(i, c);
            continue;
        }
        double s = 0;
        for (int k = 0; k < f->components; ++k) s += f->at(i, k) * f->at(i, k);
        v[i] = std::sqrt(s);
    }
    return v;
}

std::optional<std::array<double, 2>> colourRange(const ParticleFrame& frame, const std::string& colorBy) {
    const auto v = colourValues(frame, colorBy);
    if (!v) return std::nullopt;
    std::optional<std::array<double, 2>> r;
    for (double x : *v) {
        if (!std::isfinite(x)) continue;
        if (!r) r = std::array<double, 2>{x, x};
        (*r)[0] = std::min((*r)[0], x), (*r)[1] = std::max((*r)[1], x);
    }
    return r;
}

ParticleColours colourParticles(const ParticleFrame& frame, const std::string& colorBy,
                                const std::optional<std::array<double, 2>>& range,
                                const std::vector<std::string>& materials) {
    ParticleColours out;
    const std::size_t n = frame.size();
    out.rgb.resize(n);
    const auto values = colourValues(frame, colorBy);
    if (colorBy == "mode") {
        const FrameField* f = frame.field("mode");
        for (std::size_t i = 0; i < n; ++i) out.rgb[i] = f->at(i) != 0 ? kTimeDriven : kEventDriven;
        out.key.title = "mode";
        out.key.categories = {{"time-driven", kTimeDriven}, {"event-driven", kEventDriven}};
        return out;
    }
    if (colorBy == "material") {
        const FrameField* f = frame.field("material");
        std::set<long> present;
        for (std::size_t i = 0; i < n; ++i) {
            const long k = std::lround(f->at(i));
            out.rgb[i] = categoryColour(static_cast<std::size_t>(std::max(0L, k)));
            present.insert(k);
        }
        for (std::size_t k = 0; k < materials.size(); ++k) present.insert(static_cast<long>(k));
        out.key.title = "material";
        for (const long k : present)
            out.key.categories.push_back({k >= 0 && static_cast<std::size_t>(k) < materials.size()
                                              ? materials[static_cast<std::size_t>(k)]
                                              : fmt::format("material {}", k),
                                          categoryColour(static_cast<std::size_t>(std::max(0L, k)))});
        return out;
    }
    std::array<double, 2> r = range ? *range : colourRange(frame, colorBy).value_or(std::array<double, 2>{0, 1});
    // One value everywhere (to a billionth): a bar about it, the particles in its middle colour.
    if (!(r[1] - r[0] > 1e-9 * std::max(std::abs(r[0]), std::abs(r[1])))) {
        const double mid = 0.5 * (r[0] + r[1]), d = mid == 0 ? 1 : 0.1 * std::abs(mid);
        r = {mid - d, mid + d};
    }
    out.key.bar = {r[0], r[1]};
    for (std::size_t i = 0; i < n; ++i) out.rgb[i] = out.key.bar.rgb((*values)[i]);
    const auto [f, c] = resolve(frame, colorBy);
    out.key.title = (c < 0 ? "|" + f->name + "|" : colorBy) + unitOf(f->name);
    return out;
}

std::array<double, 3> screenUp(const std::array<double, 3>& view, const std::array<double, 3>& gravity) {
    static constexpr std::array<std::array<double, 3>, 6> axes = {
        {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}, {0, 0, -1}, {0, -1, 0}, {-1, 0, 0}}};
    const double vn = std::sqrt(view[0] * view[0] + view[1] * view[1] + view[2] * view[2]);
    const double gn = std::sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]);
    std::array<double, 3> best = axes[0];
    double bestScore = -2;
    for (const auto& a : axes) {
        const double along = vn > 0 ? (a[0] * view[0] + a[1] * view[1] + a[2] * view[2]) / vn : 0;
        if (std::abs(along) > 0.999) continue;
        const double score = gn > 0 ? -(a[0] * gravity[0] + a[1] * gravity[1] + a[2] * gravity[2]) / gn : 0;
        if (score > bestScore + 1e-12) best = a, bestScore = score;
    }
    return best;
}

std::vector<PngScene::Segment> wallSegments2d(const WallShapes& sh) {
    std::vector<PngScene::Segment> out;
    for (std::size_t c = 0; c + 1 < sh.lineFirst.size(); ++c)
        for (std::int64_t k = sh.lineFirst[c]; k + 1 < sh.lineFirst[c + 1]; ++k) {
            const auto& a = sh.points[static_cast<std::size_t>(sh.lineIndex[k])];
            const auto& b = sh.points[static_cast<std::size_t>(sh.lineIndex[k + 1])];
            out.push_back({a[0], a[1], b[0], b[1]});
        }
    for (std::size_t c = 0; c + 1 < sh.polyFirst.size(); ++c) {
        if (sh.polyFirst[c + 1] - sh.polyFirst[c] != 4) continue;
        std::array<std::array<double, 2>, 4> q;
        for (int v = 0; v < 4; ++v) {
            const auto& p = sh.points[static_cast<std::size_t>(sh.polyIndex[sh.polyFirst[c] + v])];
            q[v] = {p[0], p[1]};
        }
        // The middle of each short side; the line through them, ten times as long (a plane has no end).
        auto mid = [&](int a, int b) {
            return std::array<double, 2>{(q[a][0] + q[b][0]) / 2, (q[a][1] + q[b][1]) / 2};
        };
        auto len2 = [&](int a, int b) { return std::pow(q[a][0] - q[b][0], 2) + std::pow(q[a][1] - q[b][1], 2); };
        const bool longFirst = len2(0, 1) >= len2(1, 2);
        const auto m0 = longFirst ? mid(1, 2) : mid(0, 1), m1 = longFirst ? mid(3, 0) : mid(2, 3);
        const double cx = (m0[0] + m1[0]) / 2, cy = (m0[1] + m1[1]) / 2;
        out.push_back({cx + 10 * (m0[0] - cx), cy + 10 * (m0[1] - cy), cx + 10 * (m1[0] - cx), cy + 10 * (m1[1] - cy)});
    }
    return out;
}

void writeFramePicture(const std::filesystem::path& path, const ParticleFrame& frame, const WallShapes& walls,
                       const PictureBox& box, const PictureOptions& options, const std::vector<std::string>& materials,
                       const PolygonOutlines* polygons) {
    const std::string colorBy = options.colorBy.empty() ? defaultColorBy(frame) : options.colorBy;
    const ParticleColours colours = colourParticles(frame, colorBy, options.range, materials);
    const FrameField* radius = frame.field("radius");
    if (!radius) throw std::invalid_argument(path.string() + ": the snapshot has no radius field");
    std::string caption = fmt::format("t = {:.4g} s, {} particles", frame.time, frame.size());
    if (box.dimension == 2) {
        PngScene scene;
        scene.lo = {box.lo[0], box.lo[1]};
        scene.hi = {box.hi[0], box.hi[1]};
        scene.widthPx = options.widthPx;
        std::unordered_map<std::int64_t, std::size_t> outline;  // particle id -> its polygon
        if (polygons)
            for (std::size_t k = 0; k < polygons->id.size(); ++k) outline[polygons->id[k]] = k;
        const FrameField* id = frame.field("id");
        for (std::size_t i = 0; i < frame.size(); ++i) {
            const auto it = id && polygons ? outline.find(static_cast<std::int64_t>(id->at(i))) : outline.end();
            if (it != outline.end())
                scene.polygons.push_back({polygons->outline[it->second], colours.rgb[i]});
            else
                scene.disks.push_back({frame.xyz[3 * i], frame.xyz[3 * i + 1], radius->at(i), colours.rgb[i]});
        }
        scene.walls = wallSegments2d(walls);
        scene.caption = caption;
        scene.key = colours.key;
        writePng(path, scene);
        return;
    }
    SphereScene scene;
    scene.lo = box.lo;
    scene.hi = box.hi;
    scene.view = options.view;
    scene.up = screenUp(options.view, box.gravity);
    scene.widthPx = options.widthPx;
    scene.spheres.reserve(frame.size());
    for (std::size_t i = 0; i < frame.size(); ++i)
        scene.spheres.push_back(
            {{frame.xyz[3 * i], frame.xyz[3 * i + 1], frame.xyz[3 * i + 2]}, radius->at(i), colours.rgb[i]});
    scene.walls = walls;
    scene.caption = caption + fmt::format(", view [{:.3g}, {:.3g}, {:.3g}]", options.view[0] + 0.0,
                                          options.view[1] + 0.0, options.view[2] + 0.0);
    scene.key = colours.key;
    writeSpherePng(path, scene);
}

}  // namespace haet
