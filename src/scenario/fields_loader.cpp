#include "scenario/fields_loader.hpp"

#include <cctype>
#include <cmath>
#include <set>

#include "scenario/text.hpp"

namespace haet::loader {

namespace {

/// `region = { lo, hi }` inside the domain; default: the domain.
void readBox(const TableReader& r, int dim, const DomainDef& domain, Vec3d& lo, Vec3d& hi) {
    lo = domain.lo;
    hi = domain.hi;
    const toml::table* t = r.subTable("region");
    if (!t) return;
    const TableReader g(*t, r.keyPath("region"), r.file());
    g.allowOnly({"lo", "hi"});
    lo = g.requiredVector("lo", dim);
    hi = g.requiredVector("hi", dim);
    for (int k = 0; k < dim; ++k) {
        if (!(hi[k] > lo[k])) g.fail("hi", std::string("must be > lo on every axis (axis ") + kAxisName[k] + ")");
        if (lo[k] < domain.lo[k] || hi[k] > domain.hi[k])
            r.fail("region", std::string("must lie inside the domain (axis ") + kAxisName[k] + ": [" +
                                 formatNumber(lo[k]) + ", " + formatNumber(hi[k]) + "] is not inside [" +
                                 formatNumber(domain.lo[k]) + ", " + formatNumber(domain.hi[k]) + "])");
    }
}

/// A name for files and columns: letters, digits, '_' and '-'.
void checkName(const TableReader& r, const std::string& name) {
    if (name.empty()) r.fail("name", "must not be empty");
    for (char c : name)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'))
            r.fail("name", "\"" + name + "\": only letters, digits, '_' and '-' (it names files and columns)");
}

}  // namespace

FieldsDef readFields(const TableReader& r, int dim, const Scenario& s) {
    r.allowOnly({"name", "axes", "region", "cells", "kernel", "width", "cutoff", "window", "sample_interval", "period",
                 "fields", "branch_nodes"});
    FieldsDef f;
    f.pos = r.tablePos();
    f.name = r.requiredString("name");
    checkName(r, f.name);
    const std::string axes = r.requiredString("axes");
    if (axes.empty() || axes.size() > static_cast<std::size_t>(dim))
        r.fail("axes", "\"" + axes + "\": expected 1 to " + std::to_string(dim) + " of " +
                           (dim == 3 ? "x, y, z" : "x, y") + " (\"z\", \"xz\", \"xyz\")");
    f.nAxes = static_cast<int>(axes.size());
    std::set<int> seen;
    for (int a = 0; a < f.nAxes; ++a) {
        const int k = axes[a] - 'x';
        if (k < 0 || k >= dim || !seen.insert(k).second)
            r.fail("axes", "\"" + axes + "\": expected distinct letters of " + (dim == 3 ? "x, y, z" : "x, y"));
        f.axes[a] = k;
    }
    readBox(r, dim, s.domain, f.lo, f.hi);
    if (const toml::node* n = r.table().get("cells"); n && n->is_array()) {
        const auto v = r.integers("cells", 1);
        if (!v || static_cast<int>(v->size()) != f.nAxes)
            r.fail("cells", "expected one count per grid axis (" + std::to_string(f.nAxes) + ")");
        for (int a = 0; a < f.nAxes; ++a) f.cells[a] = (*v)[a];
    } else {
        const auto c = r.integer("cells");
        if (!c) r.fail("cells", "required: cells along each grid axis (an integer, or one per axis)");
        if (*c < 1) r.fail("cells", "must be >= 1");
        for (int a = 0; a < f.nAxes; ++a) f.cells[a] = static_cast<int>(*c);
    }
    double total = 1;
    for (int a = 0; a < f.nAxes; ++a) total *= f.cells[a];
    if (total > 1e7) r.fail("cells", formatNumber(total) + " cells; at most 1e7");
    f.kernel = r.choice<CgKernelKind>("kernel", {{"gaussian", CgKernelKind::Gaussian}, {"lucy", CgKernelKind::Lucy}})
                   .value_or(CgKernelKind::Gaussian);
    f.width = r.requiredNumber("width");
    if (!(f.width > 0) || !std::isfinite(f.width)) r.fail("width", "must be > 0 [m]");
    f.cutoff = r.number("cutoff").value_or(f.cutoff);
    if (r.has("cutoff") && f.kernel != CgKernelKind::Gaussian)
        r.fail("cutoff", "only for kernel = \"gaussian\" (Lucy's support is its width)");
    if (!(f.cutoff >= 1 && f.cutoff <= 10)) r.fail("cutoff", "must be 1 to 10 widths");
    f.window = r.number("window").value_or(0.0);
    if (!(f.window >= 0) || !std::isfinite(f.window)) r.fail("window", "must be >= 0 [s]");
    f.period = r.number("period").value_or(0.0);
    if (!(f.period >= 0) || !std::isfinite(f.period)) r.fail("period", "must be >= 0 [s] (0: the snapshot period)");
    if (f.period > 0 && s.duration / f.period > kMaxSnapshots)
        r.fail("period", formatNumber(f.period) + " s asks for more than " + formatNumber(kMaxSnapshots) + " outputs");
    f.sampleInterval = r.number("sample_interval").value_or(0.0);
    if (r.has("sample_interval")) {
        if (!(f.sampleInterval > 0) || !std::isfinite(f.sampleInterval)) r.fail("sample_interval", "must be > 0 [s]");
        if (f.window == 0) r.fail("sample_interval", "needs a window > 0 (without one, one sample per output)");
        if (f.window / f.sampleInterval > 1e4)
            r.fail("sample_interval", "asks for " + formatNumber(std::floor(f.window / f.sampleInterval)) +
                                          " samples per window; at most 1e4");
    }
    if (const auto b = r.integer("branch_nodes")) {
        if (*b < 1 || *b > 6) r.fail("branch_nodes", "must be 1 to 6");
        f.branchNodes = static_cast<int>(*b);
    }
    const bool edm = s.method != Method::Tdm, hybrid = s.method == Method::Haet;
    if (r.has("fields")) {
        const toml::array* a = r.table().get("fields")->as_array();
        if (!a || a->empty()) r.fail("fields", "expected a non-empty array of field names");
        for (const toml::node& n : *a) {
            const auto name = n.value<std::string>();
            int k = -1;
            for (std::size_t q = 0; q < kCgFieldNames.size(); ++q)
                if (name && *name == kCgFieldNames[q]) k = static_cast<int>(q);
            if (k < 0) {
                std::string known;
                for (const char* q : kCgFieldNames) known += std::string(known.empty() ? "" : ", ") + q;
                r.fail("fields", "unknown field " + (name ? "\"" + *name + "\"" : std::string("(not a string)")) +
                                     "; one of " + known);
            }
            if (std::string(kCgFieldNames[k]) == "collisional_stress" && !edm)
                r.fail("fields", "\"collisional_stress\" needs event-driven particles (method \"edm\" or \"haet\")");
            if (std::string(kCgFieldNames[k]) == "mode_fraction" && !hybrid)
                r.fail("fields", "\"mode_fraction\" needs method = \"haet\"");
            f.fields |= 1u << k;
        }
    } else {
        for (std::size_t q = 0; q < kCgFieldNames.size(); ++q) {
            const std::string n = kCgFieldNames[q];
            if ((n == "collisional_stress" && !edm) || (n == "mode_fraction" && !hybrid)) continue;
            f.fields |= 1u << q;
        }
    }
    return f;
}

RegionDef readRegion(const TableReader& r, int dim, const DomainDef& domain) {
    r.allowOnly({"name", "region"});
    RegionDef g;
    g.pos = r.tablePos();
    g.name = r.requiredString("name");
    checkName(r, g.name);
    if (!r.has("region")) r.fail("region", "required: region = { lo = [...], hi = [...] }");
    readBox(r, dim, domain, g.lo, g.hi);
    return g;
}

void checkMeasureNames(const Scenario& s) {
    std::set<std::string> names;
    for (std::size_t i = 0; i < s.fields.size(); ++i)
        if (!names.insert(s.fields[i].name).second)
            throw ScenarioError(s.fields[i].pos, "fields[" + std::to_string(i + 1) + "].name",
                                "\"" + s.fields[i].name + "\" is used twice");
    names.clear();
    for (std::size_t i = 0; i < s.regions.size(); ++i)
        if (!names.insert(s.regions[i].name).second)
            throw ScenarioError(s.regions[i].pos, "regions[" + std::to_string(i + 1) + "].name",
                                "\"" + s.regions[i].name + "\" is used twice");
}

}  // namespace haet::loader
