#include "scenario/flow_loader.hpp"

#include <cctype>
#include <cmath>
#include <set>
#include <string>
#include <vector>

namespace haet::loader {
namespace {

/// An array of numbers of any length (at least one).
std::vector<double> numbers(const TableReader& r, std::string_view key) {
    const toml::node* n = r.table().get(key);
    if (!n) r.fail(key, "is required");
    const toml::array* a = n->as_array();
    if (!a || a->empty()) r.fail(key, "expected an array of numbers");
    std::vector<double> out;
    for (std::size_t k = 0; k < a->size(); ++k) {
        const auto v = a->get(k)->value<double>();
        if (!v) r.fail(key, "expected an array of numbers");
        if (!std::isfinite(*v)) r.fail(key, "must be finite");
        out.push_back(*v);
    }
    return out;
}

/// `range = [min, max]` of a distribution, 0 < min < max (strictly, unless `equal` allows one size).
std::array<double, 2> range(const TableReader& r, bool equal) {
    const auto v = r.vector("range", 2);
    if (!v) r.fail("range", "is required ([min, max] radius, m)");
    const double lo = (*v)[0], hi = (*v)[1];
    if (!(lo > 0)) r.fail("range", "radii must be > 0");
    if (equal ? !(lo <= hi) : !(lo < hi)) r.fail("range", equal ? "must satisfy min <= max" : "must satisfy min < max");
    return {lo, hi};
}

SizeDistribution readDistribution(const TableReader& d, int dim) {
    const SizeKind kind = [&] {
        const auto k = d.choice<SizeKind>("kind", {{"uniform", SizeKind::Uniform},
                                                   {"discrete", SizeKind::Discrete},
                                                   {"lognormal", SizeKind::LogNormal},
                                                   {"normal", SizeKind::Normal}});
        if (!k) d.fail("kind", "is required (\"uniform\", \"discrete\", \"lognormal\" or \"normal\")");
        return *k;
    }();
    switch (kind) {
        case SizeKind::Uniform: {
            d.allowOnly({"kind", "range"});
            const auto [lo, hi] = range(d, true);
            return uniformSizes(lo, hi);
        }
        case SizeKind::Discrete: {
            d.allowOnly({"kind", "radii", "fractions", "basis"});
            const std::vector<double> radii = numbers(d, "radii");
            const std::vector<double> fractions = numbers(d, "fractions");
            for (std::size_t k = 0; k < radii.size(); ++k) {
                if (!(radii[k] > 0)) d.fail("radii", "every radius must be > 0");
                for (std::size_t j = 0; j < k; ++j)
                    if (radii[j] == radii[k]) d.fail("radii", "radius " + formatNumber(radii[k]) + " appears twice");
            }
            if (fractions.size() != radii.size())
                d.fail("fractions", "expected one fraction per radius (" + std::to_string(radii.size()) + "), got " +
                                        std::to_string(fractions.size()));
            double sum = 0;
            for (const double f : fractions) {
                if (!(f >= 0)) d.fail("fractions", "every fraction must be >= 0");
                sum += f;
            }
            if (!(std::abs(sum - 1) <= 1e-6))
                d.fail("fractions", "must sum to 1 (they sum to " + formatNumber(sum) + ")");
            const bool byMass =
                d.choice<bool>("basis", {{"mass", true}, {"number", false}}).value_or(true);  // a sieve: by mass
            return discreteSizes(radii, fractions, byMass, dim);
        }
        case SizeKind::LogNormal:
        case SizeKind::Normal: {
            const bool logn = kind == SizeKind::LogNormal;
            const char* where = logn ? "median" : "mean";
            d.allowOnly({"kind", where, "sigma", "range"});
            const double loc = d.requiredNumber(where);
            if (logn && !(loc > 0)) d.fail(where, "must be > 0");
            const double sigma = d.requiredNumber("sigma");
            if (!(sigma > 0)) d.fail("sigma", "must be > 0");
            const auto [lo, hi] = range(d, false);
            // A range many sigmas out in a tail holds no probability that a double can tell from zero.
            auto z = [&](double x) { return logn ? std::log(x / loc) / sigma : (x - loc) / sigma; };
            const double za = z(lo), zb = z(hi), h = 1 / std::sqrt(2.0);
            const double mass = za >= 0 ? 0.5 * (std::erfc(za * h) - std::erfc(zb * h))
                                        : 0.5 * (std::erfc(-zb * h) - std::erfc(-za * h));
            if (!(mass > 1e-12))
                d.fail("range", "holds no probability (too many sigmas from the " + std::string(where) + ")");
            const SizeDistribution s = logn ? logNormalSizes(loc, sigma, lo, hi) : normalSizes(loc, sigma, lo, hi);
            return s;
        }
    }
    d.fail("kind", "unknown");
}

}  // namespace

void readSizes(const TableReader& r, int dim, InsertDef& in) {
    const toml::node* n = r.table().get("radius");
    if (const toml::table* t = r.subTable("distribution")) {
        if (n) r.fail("radius", "not together with distribution (give one of them)");
        const TableReader d(*t, r.keyPath("distribution"), r.file());
        in.size = readDistribution(d, dim);
        in.radiusMin = in.size.min;
        in.radiusMax = in.size.max;
        return;
    }
    if (!n) r.fail("radius", "is required (or a distribution table)");
    if (n->is_array()) {
        const auto range = r.vector("radius", 2);  // "expected an array of 2 numbers" when malformed
        in.radiusMin = (*range)[0];
        in.radiusMax = (*range)[1];
        if (!(in.radiusMin > 0 && in.radiusMin <= in.radiusMax)) r.fail("radius", "must satisfy 0 < min <= max");
    } else {
        if (!n->is_number()) r.fail("radius", "expected a number or an array [min, max] of 2 numbers");
        in.radiusMin = in.radiusMax = *r.number("radius");
        if (!(in.radiusMin > 0)) r.fail("radius", "must be > 0");
    }
    in.size = uniformSizes(in.radiusMin, in.radiusMax);
}

void readCylinder(const TableReader& r, int dim, const DomainDef& domain, InsertDef& in) {
    if (dim != 3) r.fail("cylinder", "only in 3D (a 2D inlet's region is a box)");
    if (r.has("region")) r.fail("cylinder", "not together with region (give one of them)");
    const toml::table* t = r.subTable("cylinder");
    const TableReader c(*t, r.keyPath("cylinder"), r.file());
    c.allowOnly({"center", "radius", "z"});
    const Vec3d centre = c.requiredVector("center", 2);
    const double radius = c.requiredNumber("radius");
    if (!(radius > 0)) c.fail("radius", "must be > 0");
    const Vec3d z = c.requiredVector("z", 2);
    if (!(z[1] > z[0])) c.fail("z", "must satisfy lo < hi");
    in.cylinder = true;
    in.cylinderCentre = {centre[0], centre[1]};
    in.cylinderRadius = radius;
    in.regionLo = {centre[0] - radius, centre[1] - radius, z[0]};
    in.regionHi = {centre[0] + radius, centre[1] + radius, z[1]};
    for (int k = 0; k < 3; ++k)
        if (in.regionLo[k] < domain.lo[k] || in.regionHi[k] > domain.hi[k])
            r.fail("cylinder", std::string("must lie inside the domain (axis ") + kAxisName[k] + ")");
    if (2 * in.radiusMax > std::min(radius, 0.5 * (z[1] - z[0])) * 2)
        r.fail("cylinder", "narrower than one particle diameter");
}

void readSurface(const TableReader& r, int dim, const DomainDef& domain, InletDef& in) {
    if (r.has("region") || r.has("cylinder")) r.fail("surface", "not together with region or cylinder (give one)");
    InsertDef& p = in.particles;
    const TableReader f(*r.subTable("surface"), r.keyPath("surface"), r.file());
    f.allowOnly({"center", "normal", "size", "length", "radius", "axis"});
    const Vec3d c = f.requiredVector("center", dim);
    const Vec3d n = unitVector(f, "normal", f.requiredVector("normal", dim));
    double vn = 0;
    for (int k = 0; k < dim; ++k) vn += p.velocity[k] * n[k];
    if (!(vn > 0))
        r.fail(r.has("velocity") ? "velocity" : "surface",
               "a surface inlet's velocity must cross its face (velocity . normal > 0)");
    // Default: a slab of four largest diameters, so that each batch has room and leaves it before the next one.
    if (!(in.interval > 0)) in.interval = std::min(8 * p.radiusMax / vn, in.end - in.start);
    const double thick = vn * in.interval;  // how far the flow moves in one interval [m]
    if (thick < 2 * p.radiusMax)
        r.fail(r.has("interval") ? "interval" : "surface",
               "the slab a batch fills, velocity . normal x interval = " + formatNumber(thick) +
                   " m, is thinner than one particle diameter");
    // In-plane axes: 2D the face's direction; 3D `axis` (the rectangle's first side, made normal to n) or any.
    std::array<Vec3d, 3> axes{};
    Vec3d half{0, 0, 0};
    auto cross = [](const Vec3d& a, const Vec3d& b) {
        return Vec3d{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    };
    bool round = false;
    if (dim == 2) {
        for (const char* key : {"size", "radius", "axis"}) f.forbid(key, "not in 2D (a face is a segment: length)");
        const double len = f.requiredNumber("length");
        if (!(len > 0)) f.fail("length", "must be > 0");
        axes[0] = {-n[1], n[0], 0};
        axes[1] = n;
        half = {0.5 * len, 0.5 * thick, 0};
    } else {
        f.forbid("length", "only in 2D (a 3D face is a rectangle, size, or a disc, radius)");
        if (f.has("size") == f.has("radius"))
            f.fail("size", "give one of size = [a, b] (a rectangle) or radius (a disc)");
        Vec3d u = f.vector("axis", 3).value_or(std::abs(n[0]) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0});
        const double un = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
        for (int k = 0; k < 3; ++k) u[k] -= un * n[k];
        const double ul = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        if (!(ul > 1e-9)) f.fail("axis", "must not be parallel to normal");
        for (double& x : u) x /= ul;
        axes = {u, cross(n, u), n};
        if (f.has("size")) {
            const Vec3d ab = *f.vector("size", 2);
            if (!(ab[0] > 0 && ab[1] > 0)) f.fail("size", "must be > 0");
            half = {0.5 * ab[0], 0.5 * ab[1], 0.5 * thick};
        } else {
            f.forbid("axis", "only for a rectangle (size)");
            const double rad = f.requiredNumber("radius");
            if (!(rad > 0)) f.fail("radius", "must be > 0");
            half = {rad, rad, 0.5 * thick};
            round = true;
        }
    }
    for (int a = 0; a + 1 < dim; ++a)
        if (half[a] < p.radiusMax)
            f.fail(dim == 2 ? "length" : (round ? "radius" : "size"), "narrower than one particle diameter");
    p.slab = true;
    p.slabRound = round;
    p.slabAxes = axes;
    p.slabHalf = half;
    for (int k = 0; k < 3; ++k) p.slabCentre[k] = c[k] + (k < dim ? 0.5 * thick * n[k] : 0.0);
    // The bounding box, for the overlap grid: it must lie inside the domain.
    for (int k = 0; k < dim; ++k) {
        double e = 0;
        for (int a = 0; a < dim; ++a) e += std::abs(axes[a][k]) * half[a];
        p.regionLo[k] = p.slabCentre[k] - e;
        p.regionHi[k] = p.slabCentre[k] + e;
        if (p.regionLo[k] < domain.lo[k] - 1e-12 || p.regionHi[k] > domain.hi[k] + 1e-12)
            r.fail("surface", std::string("the slab a batch fills (downstream of the face, velocity . normal x "
                                          "interval thick) must lie inside the domain (axis ") +
                                  kAxisName[k] + ")");
    }
}

void readInletFlow(const TableReader& r, int dim, const Scenario& s, InletDef& in) {
    in.pos = r.tablePos();
    in.name = r.string("name").value_or("");
    const auto rate = r.number("rate"), massRate = r.number("mass_rate");
    if (rate && massRate) r.fail("mass_rate", "not together with rate (give one of them)");
    if (!rate && !massRate) r.fail("rate", "is required (particles/s), or mass_rate (kg/s)");
    if (rate && !(*rate > 0)) r.fail("rate", "must be > 0");
    if (massRate && !(*massRate > 0)) r.fail("mass_rate", "must be > 0");
    in.rate = rate.value_or(0);
    in.massRate = massRate.value_or(0);
    in.start = r.number("start").value_or(0);
    if (!(in.start >= 0)) r.fail("start", "must be >= 0");
    in.end = r.number("end").value_or(s.duration);
    if (!(in.end > in.start)) r.fail("end", "must be > start");
    if (const auto iv = r.number("interval")) {
        if (!(*iv > 0)) r.fail("interval", "must be > 0");
        in.interval = *iv;
    } else if (r.has("surface")) {
        in.interval = 0;  // readSurface's default: it depends on the velocity across the face
    } else {
        // A batch leaves the region before the next one comes (LIGGGHTS's advice for insert/rate/region): the time
        // in which a particle starting at the inlet's velocity v, along v (or gravity), with the gravity component
        // a >= 0 along it, crosses the region's extent L in that direction: v tau + a tau^2 / 2 = L.
        const InsertDef& p = in.particles;
        Vec3d u = p.velocity;
        double speed = 0, g = 0;
        for (int k = 0; k < dim; ++k) speed += u[k] * u[k];
        speed = std::sqrt(speed);
        if (!(speed > 0)) {
            u = s.domain.gravity;
            for (int k = 0; k < dim; ++k) g += u[k] * u[k];
            g = std::sqrt(g);
        }
        const double len = speed > 0 ? speed : g;
        double extent = 0, along = 0;
        for (int k = 0; k < dim && len > 0; ++k) {
            extent += std::abs(u[k]) / len * (p.regionHi[k] - p.regionLo[k]);
            along += s.domain.gravity[k] * u[k] / len;
        }
        const double a = std::max(0.0, along);
        const double span = in.end - in.start;
        in.interval =
            (speed > 0 || a > 0) ? 2 * extent / (speed + std::sqrt(speed * speed + 2 * a * extent)) : span / 100;
        in.interval = std::min(in.interval, span);
    }
}

OutletDef readOutlet(const TableReader& r, int dim, double duration) {
    r.allowOnly({"name", "region", "plane", "interval", "remove"});
    OutletDef o;
    o.pos = r.tablePos();
    o.name = r.string("name").value_or("");
    if (r.has("region") == r.has("plane"))
        r.fail("region", "give one of region = { lo, hi } or plane = { point, normal }");
    if (const toml::table* t = r.subTable("region")) {
        const TableReader g(*t, r.keyPath("region"), r.file());
        g.allowOnly({"lo", "hi"});
        o.kind = OutletKind::Box;
        o.lo = g.requiredVector("lo", dim);
        o.hi = g.requiredVector("hi", dim);
        for (int k = 0; k < dim; ++k)
            if (!(o.hi[k] > o.lo[k]))
                g.fail("hi", std::string("must be > lo on every axis (axis ") + kAxisName[k] + ")");
    } else {
        const TableReader g(*r.subTable("plane"), r.keyPath("plane"), r.file());
        g.allowOnly({"point", "normal"});
        o.kind = OutletKind::HalfSpace;
        o.point = g.requiredVector("point", dim);
        o.normal = unitVector(g, "normal", g.requiredVector("normal", dim));
    }
    o.interval = r.number("interval").value_or(duration / 1000);
    if (!(o.interval > 0)) r.fail("interval", "must be > 0");
    o.remove = r.boolean("remove").value_or(true);
    return o;
}

void nameFlows(Scenario& s) {
    std::set<std::string> seen;
    auto take = [&](std::string& name, const std::string& key, const std::string& fallback, const SourcePos& pos) {
        if (name.empty()) name = fallback;
        for (const char c : name)
            if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-')
                throw ScenarioError(pos, key + ".name",
                                    "letters, digits, '_' and '-' only (it names series.csv columns)");
        if (!seen.insert(name).second)
            throw ScenarioError(pos, key + ".name", inQuotes(name) + " names another inlet or outlet");
    };
    for (std::size_t k = 0; k < s.inlets.size(); ++k)
        take(s.inlets[k].name, "inlet[" + std::to_string(k + 1) + "]", "inlet" + std::to_string(k + 1),
             s.inlets[k].pos);
    for (std::size_t k = 0; k < s.outlets.size(); ++k)
        take(s.outlets[k].name, "outlet[" + std::to_string(k + 1) + "]", "outlet" + std::to_string(k + 1),
             s.outlets[k].pos);
}

}  // namespace haet::loader
