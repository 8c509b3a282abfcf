#include "run/walls_output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace haet {

namespace {

/// Facets around a circle for drawing (not the contact: circles, cylinders and discs are exact there).
constexpr int kFacets = 48;

template <int D>
std::array<double, 3> xyz(const Vec<D>& v) {
    std::array<double, 3> a{0, 0, 0};
    for (int k = 0; k < D; ++k) a[k] = v[k];
    return a;
}

/// A plane as a square patch about the box centre's projection onto it (a thin quad in 2D). In 3D its half-side is
/// half the box's diagonal, so that it covers the plane's section of the box whatever its tilt (the pictures clip it
/// to the box).
template <int D>
WallQuad planeQuad(const World<D>& w, std::size_t q, double t) {
    const Vec<D> L = w.domain.length();
    double size = 0;
    for (int k = 0; k < D; ++k) size = std::max(size, L[k]);
    const Wall<D>& wl = w.walls[q];
    std::array<double, 3> c = xyz<D>(wl.pointAt(t)), n = xyz<D>(wl.normal);
    std::array<double, 3> mid{0, 0, 0};
    for (int k = 0; k < D; ++k) mid[k] = 0.5 * (w.domain.lo[k] + w.domain.hi[k]);
    double off = 0;
    for (int k = 0; k < 3; ++k) off += (mid[k] - c[k]) * n[k];
    for (int k = 0; k < 3; ++k) c[k] = mid[k] - off * n[k];
    std::array<double, 3> a = std::abs(n[0]) < 0.9 ? std::array<double, 3>{1, 0, 0} : std::array<double, 3>{0, 1, 0};
    if (D == 2) a = {-n[1], n[0], 0};
    const double an = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
    for (int k = 0; k < 3; ++k) a[k] -= an * n[k];
    const double al = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (int k = 0; k < 3; ++k) a[k] /= al;
    const std::array<double, 3> b{n[1] * a[2] - n[2] * a[1], n[2] * a[0] - n[0] * a[2], n[0] * a[1] - n[1] * a[0]};
    const double ha = D == 2 ? 0.5 * size : 0.5 * norm(L), hb = D == 2 ? 0.01 * size : ha;
    WallQuad wq;
    wq.id = wl.id;
    const double sa[4] = {-1, 1, 1, -1}, sb[4] = {-1, -1, 1, 1};
    for (int v = 0; v < 4; ++v)
        for (int k = 0; k < 3; ++k) wq.corners[v][k] = c[k] + sa[v] * ha * a[k] + sb[v] * hb * b[k];
    return wq;
}

/// Calls f(body point) along a 2D arc, kFacets pieces per full turn (at least 2).
template <class F>
void arcPoints(const SurfaceWall<2>& s, F&& f) {
    const double span = s.angle1 - s.angle0;
    const int n = std::max(2, static_cast<int>(std::ceil(kFacets * span / (2 * std::numbers::pi))));
    for (int k = 0; k <= n; ++k) {
        const double a = s.angle0 + span * k / n;
        f(s.centre + Vec<2>{{std::cos(a), std::sin(a)}} * s.radius);
    }
}

std::string motionText(const Motion<2>& m) {
    std::string s;
    if (norm2(m.velocity) > 0) s += fmt::format(", velocity [{:.4g}, {:.4g}] m/s", m.velocity[0], m.velocity[1]);
    if (m.oscillates()) s += fmt::format(", oscillating {:.4g} Hz", m.frequency);
    if (m.rotates())
        s += fmt::format(", turning {:.4g} rad/s about [{:.4g}, {:.4g}]", m.omega, m.centre[0], m.centre[1]);
    return s;
}
std::string motionText(const Motion<3>& m) {
    std::string s;
    if (norm2(m.velocity) > 0)
        s += fmt::format(", velocity [{:.4g}, {:.4g}, {:.4g}] m/s", m.velocity[0], m.velocity[1], m.velocity[2]);
    if (m.oscillates()) s += fmt::format(", oscillating {:.4g} Hz", m.frequency);
    if (m.rotates())
        s += fmt::format(", turning {:.4g} rad/s about [{:.4g}, {:.4g}, {:.4g}] through [{:.4g}, {:.4g}, {:.4g}]",
                         m.omega, m.axis[0], m.axis[1], m.axis[2], m.centre[0], m.centre[1], m.centre[2]);
    return s;
}

}  // namespace

template <int D>
WallShapes wallShapes(const World<D>& w, double t) {
    WallShapes sh;
    for (std::size_t q = 0; q < w.walls.size(); ++q) sh.add(planeQuad(w, q, t));
    for (std::size_t q = 0; q < w.surfaces.size(); ++q) {
        const SurfaceWall<D>& s = w.surfaces[q];
        const Pose<D> pose = s.motion.at(t);
        const int id = s.id;
        auto pt = [&](const Vec<D>& b) {
            const auto a = xyz<D>(pose.toWorld(b));
            return sh.point(a[0], a[1], a[2]);
        };
        if (s.kind == SurfaceKind::Mesh) {
            std::vector<std::int64_t> ids(s.vertices.size());
            for (std::size_t v = 0; v < s.vertices.size(); ++v) ids[v] = pt(s.vertices[v]);
            for (const auto& el : s.elements) {
                if constexpr (D == 2)
                    sh.line({ids[el[0]], ids[el[1]]}, id);
                else
                    sh.poly({ids[el[0]], ids[el[1]], ids[el[2]]}, id);
            }
            continue;
        }
        if constexpr (D == 2) {
            std::int64_t prev = -1;
            arcPoints(s, [&](const Vec<2>& b) {
                const std::int64_t cur = pt(b);
                if (prev >= 0) sh.line({prev, cur}, id);
                prev = cur;
            });
        } else {
            const Vec<3> u = anyPerpendicular(s.axis), v = cross(s.axis, u);
            auto ring = [&](const Vec<3>& c, double r) {
                std::vector<std::int64_t> ids(kFacets);
                for (int k = 0; k < kFacets; ++k) {
                    const double a = 2 * std::numbers::pi * k / kFacets;
                    ids[k] = pt(c + (u * std::cos(a) + v * std::sin(a)) * r);
                }
                return ids;
            };
            auto disc = [&](const Vec<3>& c, double r) {
                const std::vector<std::int64_t> rim = ring(c, r);
                const std::int64_t mid = pt(c);
                for (int k = 0; k < kFacets; ++k) sh.poly({mid, rim[k], rim[(k + 1) % kFacets]}, id);
            };
            if (s.kind == SurfaceKind::Disc) {
                disc(s.centre, s.radius);
                continue;
            }
            const Vec<3> top = s.centre + s.axis * s.length;
            const std::vector<std::int64_t> r0 = ring(s.centre, s.radius), r1 = ring(top, s.radius1);
            for (int k = 0; k < kFacets; ++k) {
                const int k1 = (k + 1) % kFacets;
                sh.poly({r0[k], r0[k1], r1[k1], r1[k]}, id);
            }
            if (s.cap0 && s.radius > 0) disc(s.centre, s.radius);
            if (s.cap1 && s.radius1 > 0) disc(top, s.radius1);
        }
    }
    return sh;
}

template <int D>
std::vector<std::string> wallLoadColumns(const World<D>& w) {
    std::vector<std::string> cols;
    auto add = [&](const std::string& name) {
        if (name.empty()) return;
        const char* axes[3] = {"x", "y", "z"};
        for (int k = 0; k < D; ++k) cols.push_back(name + "_f" + axes[k]);
        if constexpr (D == 2)
            cols.push_back(name + "_tz");
        else
            for (int k = 0; k < 3; ++k) cols.push_back(name + "_t" + axes[k]);
    };
    for (const Wall<D>& wl : w.walls) add(wl.name);
    for (const SurfaceWall<D>& s : w.surfaces) add(s.name);
    return cols;
}

template <int D>
void appendWallLoads(const World<D>& w, const TdmEngine<D>& eng, std::vector<std::optional<double>>& row) {
    auto add = [&](const typename TdmEngine<D>::WallLoad& l) {
        for (int k = 0; k < D; ++k) row.push_back(l.force[k]);
        for (int k = 0; k < kAngDim<D>; ++k) row.push_back(l.torque[k]);
    };
    for (std::size_t q = 0; q < w.walls.size(); ++q)
        if (!w.walls[q].name.empty()) add(eng.planeLoad(q));
    for (std::size_t q = 0; q < w.surfaces.size(); ++q)
        if (!w.surfaces[q].name.empty()) add(eng.surfaceLoad(q));
}

template <int D>
void describeWalls(const World<D>& w, std::ostream& out) {
    auto label = [](const std::string& name) { return name.empty() ? std::string() : " \"" + name + "\""; };
    // In file order: planes and the other walls are kept apart, each knows its place (id).
    auto plane = [&](const Wall<D>& wl) {
        std::string pt, n;
        for (int k = 0; k < D; ++k) {
            pt += fmt::format("{}{:.4g}", k ? ", " : "", wl.point[k]);
            n += fmt::format("{}{:.4g}", k ? ", " : "", wl.normal[k]);
        }
        std::string motion;
        if (norm2(wl.velocity) > 0) motion += ", moving";
        if (wl.oscillates()) motion += fmt::format(", oscillating {:.4g} Hz", wl.frequency);
        out << fmt::format("wall       {}{}: plane through [{}], normal [{}]{}\n", wl.id + 1, label(wl.name), pt, n,
                           motion);
    };
    auto surface = [&](const SurfaceWall<D>& s) {
        Vec<D> lo, hi;
        for (std::size_t e = 0; e < s.elementCount(); ++e) {
            Vec<D> a, b;
            s.bounds(e, a, b);
            for (int k = 0; k < D; ++k) {
                lo[k] = e == 0 ? a[k] : std::min(lo[k], a[k]);
                hi[k] = e == 0 ? b[k] : std::max(hi[k], b[k]);
            }
        }
        std::string box;
        for (int k = 0; k < D; ++k) box += fmt::format("{}[{:.4g}, {:.4g}]", k ? " x " : "", lo[k], hi[k]);
        std::string kind;
        switch (s.kind) {
            case SurfaceKind::Mesh:
                kind =
                    fmt::format("{} of {} {}{} ({} vertices)", D == 2 ? "polyline" : "mesh", s.elements.size(),
                                D == 2 ? "segment" : "triangle", s.elements.size() == 1 ? "" : "s", s.vertices.size());
                break;
            case SurfaceKind::Arc:
                kind = s.fullCircle() ? fmt::format("circle of radius {:.4g}", s.radius)
                                      : fmt::format("arc of radius {:.4g}", s.radius);
                break;
            case SurfaceKind::Cylinder:
                kind =
                    s.radius == s.radius1
                        ? fmt::format("cylinder of radius {:.4g}, length {:.4g}", s.radius, s.length)
                        : fmt::format("cone of radii {:.4g} and {:.4g}, length {:.4g}", s.radius, s.radius1, s.length);
                if (s.cap0 || s.cap1)
                    kind += s.cap0 && s.cap1 ? ", capped" : (s.cap0 ? ", base capped" : ", top capped");
                break;
            case SurfaceKind::Disc:
                kind = fmt::format("disc of radius {:.4g}", s.radius);
                break;
        }
        out << fmt::format("wall       {}{}: {}, box {}{}\n", s.id + 1, label(s.name), kind, box, motionText(s.motion));
    };
    std::size_t a = 0, b = 0;
    while (a < w.walls.size() || b < w.surfaces.size()) {
        if (b == w.surfaces.size() || (a < w.walls.size() && w.walls[a].id < w.surfaces[b].id))
            plane(w.walls[a++]);
        else
            surface(w.surfaces[b++]);
    }
}

template WallShapes wallShapes<2>(const World<2>&, double);
template WallShapes wallShapes<3>(const World<3>&, double);
template std::vector<std::string> wallLoadColumns<2>(const World<2>&);
template std::vector<std::string> wallLoadColumns<3>(const World<3>&);
template void appendWallLoads<2>(const World<2>&, const TdmEngine<2>&, std::vector<std::optional<double>>&);
template void appendWallLoads<3>(const World<3>&, const TdmEngine<3>&, std::vector<std::optional<double>>&);
template void describeWalls<2>(const World<2>&, std::ostream&);
template void describeWalls<3>(const World<3>&, std::ostream&);

}  // namespace haet
