#include "scenario/walls.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "io/stl.hpp"

namespace haet {

namespace {

double norm3(const Vec3d& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
Vec3d sub(const Vec3d& a, const Vec3d& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3d cross3(const Vec3d& a, const Vec3d& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double positive(const TableReader& r, std::string_view key) {
    const double v = r.requiredNumber(key);
    if (!(v > 0)) r.fail(key, "must be > 0");
    return v;
}

constexpr double kDegree = std::numbers::pi / 180;

struct TypeInfo {
    std::string_view name;
    WallType type;
    int dim;  ///< the one dimension the type exists in; 0 = both
};
constexpr TypeInfo kTypes[] = {
    {"plane", WallType::Plane, 0},         {"segment", WallType::Segment, 2}, {"polyline", WallType::Polyline, 2},
    {"circle", WallType::Circle, 2},       {"arc", WallType::Arc, 2},         {"mesh", WallType::Mesh, 3},
    {"cylinder", WallType::Cylinder, 3},   {"cone", WallType::Cone, 3},       {"disc", WallType::Disc, 3},
    {"rectangle", WallType::Rectangle, 3},
};

void readMotion(const TableReader& r, int dim, WallDef& w) {
    w.velocity = r.vector("velocity", dim).value_or(Vec3d{0, 0, 0});
    if (const toml::table* t = r.subTable("oscillation")) {
        const TableReader o(*t, r.keyPath("oscillation"), r.file());
        o.allowOnly({"amplitude", "frequency", "phase"});
        w.amplitude = o.requiredVector("amplitude", dim);
        w.frequency = positive(o, "frequency");
        w.phase = o.number("phase").value_or(0) * kDegree;
        if (norm3(w.amplitude) == 0) o.fail("amplitude", "must be nonzero");
    }
    if (const toml::table* t = r.subTable("rotation")) {
        const TableReader o(*t, r.keyPath("rotation"), r.file());
        if (dim == 3)
            o.allowOnly({"center", "axis", "omega"});
        else
            o.allowOnly({"center", "omega"});
        w.rotationCentre = o.requiredVector("center", dim);
        if (dim == 3) w.rotationAxis = unitVector(o, "axis", o.requiredVector("axis", 3));
        w.omega = o.requiredNumber("omega");
        if (w.omega == 0) o.fail("omega", "must be nonzero (leave out [rotation] for a wall that does not turn)");
    }
}

/// Mesh from inline vertices and triangles (0-based vertex indices).
void readInlineMesh(const TableReader& r, WallDef& w) {
    const std::vector<Vec3d> v = *r.vectors("vertices", 3);
    const toml::node* n = r.table().get("triangles");
    const toml::array* a = n ? n->as_array() : nullptr;
    if (!a || a->empty()) r.fail("triangles", "is required: an array of [i, j, k] vertex indices (0-based)");
    for (std::size_t q = 0; q < a->size(); ++q) {
        const std::string at = "triangle " + std::to_string(q + 1) + ": ";
        const toml::array* t = a->get(q)->as_array();
        if (!t || t->size() != 3) r.fail("triangles", at + "expected three vertex indices");
        std::array<Vec3d, 3> tri;
        for (std::size_t k = 0; k < 3; ++k) {
            const auto* i = t->get(k)->as_integer();
            if (!i || i->get() < 0 || i->get() >= static_cast<std::int64_t>(v.size()))
                r.fail("triangles", at + "vertex indices must be integers in [0, " + std::to_string(v.size()) + ")");
            tri[k] = v[static_cast<std::size_t>(i->get())];
        }
        w.triangles.push_back(tri);
    }
}

/// Mesh from an STL file, placed by scale, rotate and translate (io/stl.hpp: p' = R (S p) + T).
void readStlMesh(const TableReader& r, const std::filesystem::path& dir, WallDef& w) {
    const std::string file = r.requiredString("file");
    std::filesystem::path path(file);
    if (path.is_relative() && !r.fromOverride("file")) path = dir / path;
    StlTransform t;
    if (r.has("scale")) {
        const toml::node* n = r.table().get("scale");
        if (n->is_array()) {
            const Vec3d sc = r.requiredVector("scale", 3);
            t.scale = Vec<3>{{sc[0], sc[1], sc[2]}};
        } else {
            t.scale = Vec<3>::filled(r.requiredNumber("scale"));
        }
        for (int k = 0; k < 3; ++k)
            if (t.scale[k] == 0) r.fail("scale", "must be nonzero");
    }
    if (const toml::table* rt = r.subTable("rotate")) {
        const TableReader o(*rt, r.keyPath("rotate"), r.file());
        o.allowOnly({"axis", "angle"});
        const Vec3d ax = unitVector(o, "axis", o.requiredVector("axis", 3));
        t.axis = Vec<3>{{ax[0], ax[1], ax[2]}};
        t.angle_deg = o.requiredNumber("angle");
    }
    if (const auto tr = r.vector("translate", 3)) t.translate = Vec<3>{{(*tr)[0], (*tr)[1], (*tr)[2]}};
    try {
        StlMesh mesh = readStl(path);
        transformStl(mesh, t);
        for (const StlTriangle& tri : mesh.triangles) {
            std::array<Vec3d, 3> c;
            for (int k = 0; k < 3; ++k) c[k] = {tri[k][0], tri[k][1], tri[k][2]};
            w.triangles.push_back(c);
        }
    } catch (const StlError& e) {
        r.fail("file", e.what());
    } catch (const std::invalid_argument& e) {
        r.fail("scale", e.what());
    }
    w.file = path.string();
}

void checkTriangles(const TableReader& r, std::string_view key, const WallDef& w) {
    for (std::size_t q = 0; q < w.triangles.size(); ++q) {
        const auto& t = w.triangles[q];
        const Vec3d e1 = sub(t[1], t[0]), e2 = sub(t[2], t[0]), e3 = sub(t[2], t[1]);
        const double longest = std::max({norm3(e1), norm3(e2), norm3(e3)});
        // Degenerate: its area is a vanishing fraction of its longest edge squared.
        if (!(norm3(cross3(e1, e2)) > 1e-12 * longest * longest))
            r.fail(key, "triangle " + std::to_string(q + 1) + " has zero area");
    }
}

}  // namespace

WallDef readWall(const TableReader& r, int dim, int material, const std::filesystem::path& dir) {
    WallDef w;
    w.pos = r.tablePos();
    w.material = material;
    const std::string type = r.string("type").value_or("plane");
    const TypeInfo* info = nullptr;
    for (const TypeInfo& t : kTypes)
        if (t.name == type) info = &t;
    if (!info) {
        std::string list;
        for (const TypeInfo& t : kTypes)
            if (t.dim == 0 || t.dim == dim) list += (list.empty() ? "" : ", ") + inQuotes(t.name);
        r.fail("type", "must be one of " + list + " in " + std::to_string(dim) + "D (got " + inQuotes(type) + ")");
    }
    if (info->dim != 0 && info->dim != dim)
        r.fail("type", inQuotes(type) + " walls exist in " + std::to_string(info->dim) + "D only");
    w.type = info->type;
    w.name = r.string("name").value_or("");

    auto allow = [&](std::initializer_list<std::string_view> own) {
        std::vector<std::string_view> keys{"type", "name", "material", "velocity", "oscillation", "rotation"};
        keys.insert(keys.end(), own.begin(), own.end());
        // allowOnly takes an initializer list: check by hand, reporting the first unknown key in file order.
        const toml::key* first = nullptr;
        for (auto&& [k, v] : r.table())
            if (std::find(keys.begin(), keys.end(), std::string_view(k.str())) == keys.end() &&
                (!first || k.source().begin.line < first->source().begin.line))
                first = &k;
        if (first) r.fail(first->str(), "unknown key for a " + inQuotes(type) + " wall");
    };
    readMotion(r, dim, w);

    switch (w.type) {
        case WallType::Plane:
            allow({"point", "normal"});
            w.point = r.requiredVector("point", dim);
            w.normal = unitVector(r, "normal", r.requiredVector("normal", dim));
            if (w.rotates())
                r.fail("rotation", "an infinite plane cannot rotate: use a segment (2D) or a rectangle (3D)");
            break;
        case WallType::Segment:
        case WallType::Polyline: {
            allow(w.type == WallType::Segment ? std::initializer_list<std::string_view>{"points"}
                                              : std::initializer_list<std::string_view>{"points", "closed"});
            const auto pts = r.vectors("points", dim);
            if (!pts) r.fail("points", "is required");
            w.points = *pts;
            if (w.type == WallType::Segment && w.points.size() != 2)
                r.fail("points", "a segment has exactly two points");
            if (w.points.size() < 2) r.fail("points", "needs at least two points");
            w.closed = r.boolean("closed").value_or(false);
            if (w.closed && w.points.size() < 3) r.fail("closed", "a closed polyline needs at least three points");
            const std::size_t ns = w.closed ? w.points.size() : w.points.size() - 1;
            for (std::size_t q = 0; q < ns; ++q)
                if (norm3(sub(w.points[(q + 1) % w.points.size()], w.points[q])) == 0)
                    r.fail("points", "segment " + std::to_string(q + 1) + " has zero length (points " +
                                         std::to_string(q + 1) + " and " +
                                         std::to_string((q + 1) % w.points.size() + 1) + " coincide)");
            break;
        }
        case WallType::Circle:
        case WallType::Arc:
            if (w.type == WallType::Circle)
                allow({"center", "radius"});
            else
                allow({"center", "radius", "angles"});
            w.centre = r.requiredVector("center", dim);
            w.radius = positive(r, "radius");
            w.angle0 = 0;
            w.angle1 = 2 * std::numbers::pi;
            if (w.type == WallType::Arc) {
                const Vec3d a = r.requiredVector("angles", 2);
                if (!(a[1] > a[0] && a[1] - a[0] <= 360))
                    r.fail("angles", "must be [from, to] in degrees with from < to <= from + 360");
                w.angle0 = a[0] * kDegree;
                w.angle1 = a[1] * kDegree;
            }
            break;
        case WallType::Cylinder:
        case WallType::Cone: {
            if (w.type == WallType::Cylinder)
                allow({"base", "axis", "length", "radius", "caps"});
            else
                allow({"base", "axis", "length", "radius", "radius_top", "caps"});
            w.centre = r.requiredVector("base", 3);
            w.axis = unitVector(r, "axis", r.requiredVector("axis", 3));
            w.length = positive(r, "length");
            if (w.type == WallType::Cylinder) {
                w.radius = positive(r, "radius");
                w.radiusTop = w.radius;
            } else {
                w.radius = r.requiredNumber("radius");
                w.radiusTop = r.requiredNumber("radius_top");
                if (!(w.radius >= 0)) r.fail("radius", "must be >= 0");
                if (!(w.radiusTop >= 0)) r.fail("radius_top", "must be >= 0");
                if (!(w.radius > 0 || w.radiusTop > 0)) r.fail("radius_top", "radius and radius_top cannot both be 0");
            }
            const std::string caps = r.string("caps").value_or("none");
            if (caps == "both")
                w.capBase = w.capTop = true;
            else if (caps == "base")
                w.capBase = true;
            else if (caps == "top")
                w.capTop = true;
            else if (caps != "none")
                r.fail("caps", "must be one of \"none\", \"base\", \"top\", \"both\" (got " + inQuotes(caps) + ")");
            break;
        }
        case WallType::Disc:
            allow({"center", "normal", "radius"});
            w.centre = r.requiredVector("center", 3);
            w.normal = unitVector(r, "normal", r.requiredVector("normal", 3));
            w.radius = positive(r, "radius");
            break;
        case WallType::Rectangle: {
            allow({"center", "edges"});
            w.centre = r.requiredVector("center", 3);
            const auto e = r.vectors("edges", 3);
            if (!e || e->size() != 2) r.fail("edges", "is required: two edge vectors [[ax, ay, az], [bx, by, bz]]");
            w.edge1 = (*e)[0];
            w.edge2 = (*e)[1];
            const double l1 = norm3(w.edge1), l2 = norm3(w.edge2);
            if (!(norm3(cross3(w.edge1, w.edge2)) > 1e-12 * l1 * l2))
                r.fail("edges", "the two edges must be nonzero and not parallel");
            // Two triangles, corners c - (a + b)/2 ...
            Vec3d c[4];
            for (int k = 0; k < 4; ++k) {
                const double sa = (k == 1 || k == 2) ? 0.5 : -0.5, sb = (k >= 2) ? 0.5 : -0.5;
                for (int q = 0; q < 3; ++q) c[k][q] = w.centre[q] + sa * w.edge1[q] + sb * w.edge2[q];
            }
            w.triangles = {{c[0], c[1], c[2]}, {c[0], c[2], c[3]}};
            break;
        }
        case WallType::Mesh:
            allow({"file", "scale", "rotate", "translate", "vertices", "triangles"});
            if (r.has("file")) {
                if (r.has("vertices")) r.fail("vertices", "give either file or vertices and triangles, not both");
                readStlMesh(r, dir, w);
            } else {
                if (!r.has("vertices"))
                    r.fail("file", "is required (an STL file), or vertices and triangles given in the scenario");
                for (const char* k : {"scale", "rotate", "translate"})
                    if (r.has(k)) r.fail(k, "applies to a mesh from a file");
                readInlineMesh(r, w);
                checkTriangles(r, "triangles", w);
            }
            break;
    }
    return w;
}

namespace {

/// A box that holds the wall at t = 0 (not a tight one for cylinders and cones) [m].
void boundsOf(const WallDef& w, int dim, Vec3d& lo, Vec3d& hi) {
    lo = {1e300, 1e300, 1e300};
    hi = {-1e300, -1e300, -1e300};
    auto take = [&](const Vec3d& p, double r) {
        for (int k = 0; k < dim; ++k) {
            lo[k] = std::min(lo[k], p[k] - r);
            hi[k] = std::max(hi[k], p[k] + r);
        }
    };
    for (const Vec3d& p : w.points) take(p, 0);
    for (const auto& t : w.triangles)
        for (const Vec3d& p : t) take(p, 0);
    const double r = std::max(w.radius, w.radiusTop);
    if (w.type == WallType::Circle || w.type == WallType::Arc || w.type == WallType::Disc) take(w.centre, r);
    if (w.type == WallType::Cylinder || w.type == WallType::Cone) {
        take(w.centre, r);
        take({w.centre[0] + w.axis[0] * w.length, w.centre[1] + w.axis[1] * w.length,
              w.centre[2] + w.axis[2] * w.length},
             r);
    }
}

}  // namespace

namespace {

/// What a pure event-driven run can predict (docs/physics.md H.6): planes at a constant velocity (D.3) and static
/// walls made of segments or triangles (D.8). Anything else is the hybrid's (whose guard hands the particles near it
/// to the time-driven engine) or the time-driven engine's.
void checkEventDriven(const WallDef& w, const std::string& key) {
    const std::string use =
        "; use method = \"haet\" (its time-driven part takes the particles near such a wall) or "
        "method = \"tdm\"";
    const bool meshLike = w.type == WallType::Plane || w.type == WallType::Segment || w.type == WallType::Polyline ||
                          w.type == WallType::Mesh || w.type == WallType::Rectangle;
    if (!meshLike) {
        std::string type;
        for (const TypeInfo& t : kTypes)
            if (t.type == w.type) type = std::string(t.name);
        throw ScenarioError(w.pos, key + ".type",
                            "a " + inQuotes(type) +
                                " wall is curved: the event-driven engine predicts planes and walls made of "
                                "segments or triangles only" +
                                use);
    }
    if (w.isPlane()) {
        if (w.frequency != 0)
            throw ScenarioError(w.pos, key + ".oscillation",
                                "an oscillating plane: the event-driven engine predicts planes at a constant "
                                "velocity only" +
                                    use);
        return;
    }
    const char* motion = w.rotates()             ? ".rotation"
                         : w.frequency != 0      ? ".oscillation"
                         : norm3(w.velocity) > 0 ? ".velocity"
                                                 : nullptr;
    if (motion)
        throw ScenarioError(w.pos, key + motion,
                            "a moving wall of segments or triangles: the event-driven engine predicts them only at "
                            "rest" +
                                use);
}

}  // namespace

void checkWalls(const Scenario& s) {
    bool polygons = false;
    for (const InsertDef& in : s.inserts) polygons = polygons || in.shape == ShapeKind::Polygon;
    for (std::size_t q = 0; q < s.walls.size(); ++q) {
        const WallDef& w = s.walls[q];
        const std::string key = "walls[" + std::to_string(q + 1) + "]";
        if (s.method == Method::Edm) checkEventDriven(w, key);
        // Polygons (2D) touch every 2D wall (docs/physics.md G.6); the 3D shapes are rejected for 2D scenes anyway.
        const bool polygonWall = w.isPlane() || w.type == WallType::Segment || w.type == WallType::Polyline ||
                                 w.type == WallType::Circle || w.type == WallType::Arc;
        if (polygons && !polygonWall)
            throw ScenarioError(w.pos, key + ".type",
                                "polygon particles touch planes, segments, polylines, circles and arcs only");
        const bool moves = w.rotates() || w.frequency != 0 || norm3(w.velocity) > 0;
        if (!w.isPlane() && !moves) {
            Vec3d lo, hi;
            boundsOf(w, s.dimension, lo, hi);
            bool apart = false;
            for (int k = 0; k < s.dimension; ++k) apart = apart || hi[k] < s.domain.lo[k] || lo[k] > s.domain.hi[k];
            if (apart) {
                std::string box;
                for (int k = 0; k < s.dimension; ++k)
                    box += (k ? " x [" : "[") + formatNumber(lo[k]) + ", " + formatNumber(hi[k]) + "]";
                throw ScenarioError(w.pos, key + (w.file.empty() ? ".type" : ".file"),
                                    "the wall lies entirely outside the domain (its box " + box +
                                        "); move it with translate, or fix the domain");
            }
        }
    }
}

namespace {

template <int D>
Motion<D> motionOf(const WallDef& w) {
    Motion<D> m;
    m.velocity = toVec<D>(w.velocity);
    m.amplitude = toVec<D>(w.amplitude);
    m.frequency = w.frequency;
    m.phase = w.phase;
    m.centre = toVec<D>(w.rotationCentre);
    if constexpr (D == 3) m.axis = toVec<3>(w.rotationAxis);
    m.omega = w.omega;
    return m;
}

}  // namespace

template <int D>
Wall<D> makePlane(const WallDef& wd) {
    Wall<D> wall;
    wall.point = toVec<D>(wd.point);
    wall.normal = toVec<D>(wd.normal);
    wall.velocity = toVec<D>(wd.velocity);
    wall.amplitude = toVec<D>(wd.amplitude);
    wall.frequency = wd.frequency;
    wall.phase = wd.phase;
    wall.material = wd.material;
    wall.name = wd.name;
    wall.moveTo(0);
    return wall;
}

template <int D>
SurfaceWall<D> makeSurfaceWall(const WallDef& wd) {
    SurfaceWall<D> w;
    w.name = wd.name;
    w.material = wd.material;
    w.motion = motionOf<D>(wd);
    switch (wd.type) {
        case WallType::Segment:
        case WallType::Polyline:
            if constexpr (D == 2) {
                std::vector<std::array<Vec<2>, 2>> segs;
                const std::size_t np = wd.points.size();
                for (std::size_t q = 0; q + 1 < np; ++q)
                    segs.push_back({toVec<2>(wd.points[q]), toVec<2>(wd.points[q + 1])});
                if (wd.closed) segs.push_back({toVec<2>(wd.points[np - 1]), toVec<2>(wd.points[0])});
                buildMesh<2>(w, segs);
            }
            break;
        case WallType::Circle:
        case WallType::Arc:
            w.kind = SurfaceKind::Arc;
            w.centre = toVec<D>(wd.centre);
            w.radius = wd.radius;
            w.angle0 = wd.angle0;
            w.angle1 = wd.angle1;
            break;
        case WallType::Mesh:
        case WallType::Rectangle:
            if constexpr (D == 3) {
                std::vector<std::array<Vec<3>, 3>> tris;
                for (const auto& t : wd.triangles) tris.push_back({toVec<3>(t[0]), toVec<3>(t[1]), toVec<3>(t[2])});
                buildMesh<3>(w, tris);
            }
            break;
        case WallType::Cylinder:
        case WallType::Cone:
            w.kind = SurfaceKind::Cylinder;
            w.centre = toVec<D>(wd.centre);
            w.axis = toVec<D>(wd.axis);
            w.radius = wd.radius;
            w.radius1 = wd.radiusTop;
            w.length = wd.length;
            w.cap0 = wd.capBase;
            w.cap1 = wd.capTop;
            break;
        case WallType::Disc:
            w.kind = SurfaceKind::Disc;
            w.centre = toVec<D>(wd.centre);
            w.axis = toVec<D>(wd.normal);
            w.radius = wd.radius;
            break;
        case WallType::Plane:
            break;
    }
    return w;
}

template <int D>
WallClearance<D>::WallClearance(const std::vector<WallDef>& walls) {
    for (const WallDef& w : walls) {
        if (w.isPlane()) {
            planes_.push_back(makePlane<D>(w));
            continue;
        }
        surfaces_.push_back(makeSurfaceWall<D>(w));
        const SurfaceWall<D>& s = surfaces_.back();
        boxes_.emplace_back();
        for (std::size_t e = 0; e < s.elementCount(); ++e) {
            Vec<D> lo, hi;
            s.bounds(e, lo, hi);
            boxes_.back().push_back({lo, hi});
        }
    }
}

template <int D>
bool WallClearance<D>::clear(const Vec<D>& x, double r) const {
    for (const Wall<D>& w : planes_)
        if (w.distance(x, 0) < r) return false;
    for (std::size_t q = 0; q < surfaces_.size(); ++q) {
        for (std::size_t e = 0; e < boxes_[q].size(); ++e) {
            const auto& [lo, hi] = boxes_[q][e];
            bool near = true;  // within r of the element's box
            for (int k = 0; k < D; ++k) near = near && x[k] > lo[k] - r && x[k] < hi[k] + r;
            if (near && surfaces_[q].distance(e, x) < r) return false;
        }
    }
    return true;
}

template Wall<2> makePlane<2>(const WallDef&);
template Wall<3> makePlane<3>(const WallDef&);
template SurfaceWall<2> makeSurfaceWall<2>(const WallDef&);
template SurfaceWall<3> makeSurfaceWall<3>(const WallDef&);
template class WallClearance<2>;
template class WallClearance<3>;

}  // namespace haet
