#include "scenario/loader.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "io/spheres.hpp"
#include "scenario/checks.hpp"
#include "scenario/fields_loader.hpp"
#include "scenario/flow_loader.hpp"
#include "scenario/table_reader.hpp"
#include "scenario/text.hpp"
#include "scenario/walls.hpp"

namespace haet {
namespace {

class Loader {
public:
    Loader(const toml::table& root, std::string file, std::filesystem::path dir)
        : root_(root, "", file), file_(std::move(file)), dir_(std::move(dir)) {}

    Scenario load() {
        root_.allowOnly({"name", "dimension", "method", "duration", "seed", "domain", "materials", "contact", "tdm",
                         "edm", "haet", "walls", "insert", "outlet", "inlet", "output", "fields", "regions"});
        Scenario s;
        s.path = file_;
        readTop(s);
        readDomain(s);
        readMaterials(s);
        readContact(s);
        readTdm(s);
        readEdm(s);
        readHaet(s);
        readWalls(s);
        readInserts(s);
        checkWalls(s);
        readFlows(s);
        checkDiskLaw(s);
        readOutput(s);
        readMeasures(s);
        checkScenario(s);  // the checks across tables (scenario/checks.hpp)
        return s;
    }

private:
    TableReader child(std::string_view key) const {
        const toml::table* t = root_.subTable(key);
        return TableReader(t ? *t : emptyTable(), std::string(key), file_);
    }

    void readTop(Scenario& s) {
        s.name = root_.requiredString("name");
        if (s.name.empty()) root_.fail("name", "must not be empty");

        const auto dim = root_.integer("dimension");
        if (!dim) root_.fail("dimension", "is required");
        if (*dim != 2 && *dim != 3) root_.fail("dimension", "must be 2 or 3");
        s.dimension = int(*dim);
        dim_ = s.dimension;

        s.method = root_.choice<Method>("method", {{"tdm", Method::Tdm}, {"edm", Method::Edm}, {"haet", Method::Haet}})
                       .value_or(Method::Tdm);

        s.duration = root_.requiredNumber("duration");
        if (!(s.duration > 0)) root_.fail("duration", "must be > 0");

        if (const auto seed = root_.integer("seed")) {
            if (*seed < 0) root_.fail("seed", "must be >= 0");
            s.seed = std::uint64_t(*seed);
        }
    }

    void readDomain(Scenario& s) {
        if (!root_.has("domain")) root_.fail("domain", "is required");
        const TableReader r = child("domain");
        r.allowOnly({"lo", "hi", "periodic", "gravity"});
        DomainDef& d = s.domain;
        d.pos = r.tablePos();
        d.lo = r.requiredVector("lo", dim_);
        d.hi = r.requiredVector("hi", dim_);
        for (int k = 0; k < dim_; ++k)
            if (!(d.hi[k] > d.lo[k]))
                r.fail("hi", std::string("must be > lo on every axis (axis ") + kAxisName[k] + ": hi " +
                                 formatNumber(d.hi[k]) + " <= lo " + formatNumber(d.lo[k]) + ")");
        d.periodic = r.booleans("periodic", dim_).value_or(std::array<bool, 3>{false, false, false});
        d.gravity = r.vector("gravity", dim_).value_or(Vec3d{0, 0, 0});
        domain_ = d;
    }

    void readMaterials(Scenario& s) {
        if (!root_.has("materials")) root_.fail("materials", "at least one [materials.NAME] table is required");
        const TableReader all = child("materials");
        // Materials are numbered in file order (LAMMPS atom type k is material k-1); toml++ keeps keys sorted.
        std::vector<std::pair<const toml::key*, const toml::node*>> entries;
        for (auto&& [k, v] : all.table()) entries.emplace_back(&k, &v);
        std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
            return a.first->source().begin.line < b.first->source().begin.line;
        });
        if (entries.empty()) all.failTable("at least one [materials.NAME] table is required");
        if (entries.size() > 65535) all.failTable("at most 65535 materials");

        for (const auto& [key, node] : entries) {
            const toml::table* t = node->as_table();
            if (!t) all.fail(key->str(), "expected a table ([materials." + std::string(key->str()) + "])");
            const TableReader r(*t, all.keyPath(key->str()), file_);
            r.allowOnly({"density", "young", "poisson", "restitution", "friction", "tangential_restitution",
                         "dissipation_time"});
            MaterialDef m;
            m.name = key->str();
            m.pos = r.tablePos();
            m.density = r.requiredNumber("density");
            if (!(m.density > 0)) r.fail("density", "must be > 0");
            m.young = r.number("young").value_or(m.young);
            if (!(m.young > 0)) r.fail("young", "must be > 0");
            m.poisson = r.number("poisson").value_or(m.poisson);
            if (!(m.poisson > -1 && m.poisson < 0.5)) r.fail("poisson", "must satisfy -1 < poisson < 0.5");
            // Optional where nothing reads it (the linear law with kn and gamma_n, checkRestitution).
            m.restitution = r.number("restitution").value_or(kRestitutionUnset);
            if (r.has("restitution") && !(m.restitution > 0 && m.restitution <= 1))
                r.fail("restitution", "must satisfy 0 < e <= 1");
            m.friction = r.requiredNumber("friction");
            if (!(m.friction >= 0)) r.fail("friction", "must be >= 0");
            m.tangentialRestitution = r.number("tangential_restitution").value_or(m.tangentialRestitution);
            if (!(m.tangentialRestitution >= -1 && m.tangentialRestitution <= 1))
                r.fail("tangential_restitution", "must satisfy -1 <= beta0 <= 1");
            m.dissipationTime = r.number("dissipation_time");
            if (m.dissipationTime && !(*m.dissipationTime > 0)) r.fail("dissipation_time", "must be > 0");
            s.materials.push_back(std::move(m));
        }
        materials_ = &s.materials;
    }

    /// Index of the material named by `key` (a required string).
    int materialIndex(const TableReader& r, std::string_view key) const {
        const std::string name = r.requiredString(key);
        for (std::size_t i = 0; i < materials_->size(); ++i)
            if ((*materials_)[i].name == name) return int(i);
        r.fail(key, "unknown material " + inQuotes(name) + " (no [materials." + name + "] table)");
    }

    void readContact(Scenario& s) {
        const TableReader r = child("contact");
        r.allowOnly({"normal", "duration", "kn", "gamma_n", "damping", "tangential", "kt", "kt_ratio", "gamma_t",
                     "attraction", "impact_velocity", "polygon_damping", "polygon_law"});
        ContactDef& c = s.contact;
        c.pos = r.tablePos();
        c.normal = r.choice<NormalLaw>("normal", {{"linear", NormalLaw::Linear}, {"hertz", NormalLaw::Hertz}})
                       .value_or(NormalLaw::Linear);
        if (c.normal == NormalLaw::Linear) {
            c.duration = r.number("duration");
            c.kn = r.number("kn");
            c.gammaN = r.number("gamma_n");
            if (c.duration && c.kn) r.fail("kn", "not together with duration (give one of them)");
            // Checked once the inserts are known (checkDiskLaw): a scene of polygons alone does not use it.
            needDiskLaw_ = !c.duration && !c.kn;
            if (c.duration && !(*c.duration > 0)) r.fail("duration", "must be > 0");
            if (c.kn && !(*c.kn > 0)) r.fail("kn", "must be > 0");
            if (c.gammaN && !c.kn)
                r.fail("gamma_n", "only together with kn (with duration, damping follows from restitution)");
            if (c.gammaN && !(*c.gammaN >= 0)) r.fail("gamma_n", "must be >= 0");
            r.forbid("damping", "only for normal = \"hertz\"");
        } else {
            const std::string why = "only for normal = \"linear\"";
            r.forbid("duration", why + " (the Hertz contact duration follows from impact_velocity)");
            r.forbid("kn", why);
            r.forbid("gamma_n", why);
            c.hertzDamping = r.choice<HertzDamping>("damping", {{"none", HertzDamping::None},
                                                                {"viscoelastic", HertzDamping::Viscoelastic},
                                                                {"tsuji", HertzDamping::Tsuji}})
                                 .value_or(HertzDamping::Viscoelastic);
        }

        c.tangential =
            r.choice<TangentialLaw>("tangential", {{"none", TangentialLaw::None}, {"spring", TangentialLaw::Spring}})
                .value_or(TangentialLaw::Spring);
        if (c.tangential == TangentialLaw::None) {
            for (const char* key : {"kt", "kt_ratio", "gamma_t"}) r.forbid(key, "only for tangential = \"spring\"");
        }
        c.kt = r.number("kt");
        c.ktRatio = r.number("kt_ratio");
        if (c.kt && c.ktRatio) r.fail("kt_ratio", "not together with kt (give one of them)");
        if (c.kt && !(*c.kt > 0)) r.fail("kt", "must be > 0");
        if (c.ktRatio && !(*c.ktRatio > 0 && *c.ktRatio <= 1)) r.fail("kt_ratio", "must satisfy 0 < kt_ratio <= 1");
        c.gammaT = r.number("gamma_t").value_or(c.gammaT);
        if (!(c.gammaT >= 0)) r.fail("gamma_t", "must be >= 0");
        c.attraction = r.boolean("attraction").value_or(c.attraction);
        c.impactVelocity = r.number("impact_velocity").value_or(c.impactVelocity);
        if (!(c.impactVelocity > 0)) r.fail("impact_velocity", "must be > 0");
        c.polygonDamping = r.number("polygon_damping");
        if (c.polygonDamping && !(*c.polygonDamping >= 0)) r.fail("polygon_damping", "must be >= 0");
        c.polygonLaw = r.choice<PolygonLaw>("polygon_law", {{"overlap_area", PolygonLaw::OverlapArea},
                                                            {"potential", PolygonLaw::Potential}})
                           .value_or(PolygonLaw::OverlapArea);
    }

    /// The linear law needs (duration or kn) as soon as the scene may hold disks: a disk insert or a particle file.
    void checkDiskLaw(const Scenario& s) const {
        if (!needDiskLaw_) return;
        bool disks = s.inserts.empty();
        for (const InsertDef& in : s.inserts) disks = disks || in.shape == ShapeKind::Disk;
        for (const InletDef& in : s.inlets) disks = disks || in.particles.shape == ShapeKind::Disk;
        if (disks)
            child("contact").fail("duration", "the linear law needs a contact duration (or kn); neither is given");
    }

    void readTdm(Scenario& s) {
        const TableReader r = child("tdm");
        r.allowOnly({"integrator", "dt", "steps_per_contact", "skin", "max_overlap", "sort_every"});
        TdmDef& t = s.tdm;
        t.pos = r.tablePos();
        t.integrator = r.choice<IntegratorKind>("integrator",
                                                {{"verlet", IntegratorKind::Verlet}, {"gear5", IntegratorKind::Gear5}})
                           .value_or(IntegratorKind::Verlet);
        t.integratorGiven = r.has("integrator");
        t.dtPos = r.posOf("dt");
        if (const toml::node* n = r.table().get("dt")) {
            if (const auto* str = n->as_string()) {
                if (str->get() != "auto") r.fail("dt", "must be \"auto\" or a number > 0");
            } else if (n->is_number()) {
                t.dt = r.number("dt");
                if (!(*t.dt > 0)) r.fail("dt", "must be > 0");
                if (*t.dt > s.duration)
                    r.fail("dt", "the time step " + formatNumber(*t.dt) + " s is longer than the duration " +
                                     formatNumber(s.duration) + " s: the run would take no step");
            } else {
                r.fail("dt", "expected a number or \"auto\"");
            }
        }
        t.stepsPerContact = r.number("steps_per_contact").value_or(t.stepsPerContact);
        if (!(t.stepsPerContact >= 5)) r.fail("steps_per_contact", "must be >= 5");
        t.skin = r.number("skin");
        if (t.skin && !(*t.skin > 0)) r.fail("skin", "must be > 0");
        t.maxOverlap = r.number("max_overlap").value_or(t.maxOverlap);
        if (!(t.maxOverlap > 0 && t.maxOverlap <= 1)) r.fail("max_overlap", "must satisfy 0 < max_overlap <= 1");
        if (const auto every = r.integer("sort_every")) {
            if (*every < 0) r.fail("sort_every", "must be >= 0");
            if (*every > 2147483647) r.fail("sort_every", "too large");
            t.sortEvery = int(*every);
        }
    }

    void readEdm(Scenario& s) {
        const TableReader r = child("edm");
        r.allowOnly({"tangential", "tc_model", "tc_time", "cell_size"});
        EdmDef& e = s.edm;
        e.pos = r.tablePos();
        e.tangential = r.choice<EdmTangential>(
                            "tangential", {{"walton", EdmTangential::Walton}, {"constant", EdmTangential::Constant}})
                           .value_or(EdmTangential::Walton);
        e.tcModel = r.boolean("tc_model").value_or(true);
        e.tcTime = r.number("tc_time");
        if (e.tcTime && !(*e.tcTime > 0)) r.fail("tc_time", "must be > 0");
        e.cellSize = r.number("cell_size");
        e.cellPos = r.posOf("cell_size");
        if (e.cellSize && !(*e.cellSize > 0)) r.fail("cell_size", "must be > 0");
    }

    void readHaet(Scenario& s) {
        const TableReader r = child("haet");
        r.allowOnly({"zone_size", "phi_on", "phi_off", "relabel_every", "buffer", "dilute_steps", "dt_min"});
        HaetDef& h = s.haet;
        h.pos = r.tablePos();
        h.zoneSize = r.number("zone_size");
        if (h.zoneSize && !(*h.zoneSize > 0)) r.fail("zone_size", "must be > 0");
        h.phiOn = r.number("phi_on");
        if (h.phiOn && !(*h.phiOn > 0 && *h.phiOn < 1)) r.fail("phi_on", "must satisfy 0 < phi_on < 1");
        h.phiOff = r.number("phi_off");
        if (h.phiOff && !(*h.phiOff > 0 && *h.phiOff < 1)) r.fail("phi_off", "must satisfy 0 < phi_off < 1");
        const double on = h.phiOn.value_or(s.dimension == 2 ? 0.45 : 0.30);
        const double off = h.phiOff.value_or(s.dimension == 2 ? 0.40 : 0.25);
        if (!(off < on)) r.fail(h.phiOff ? "phi_off" : "phi_on", "phi_off must be smaller than phi_on (hysteresis)");
        auto count = [&](const char* key, int& out, int min) {
            if (const auto v = r.integer(key)) {
                if (*v < min || *v > 1000000000) r.fail(key, "must be an integer >= " + std::to_string(min));
                out = int(*v);
            }
        };
        count("relabel_every", h.relabelEvery, 1);
        count("buffer", h.buffer, 0);
        count("dilute_steps", h.diluteSteps, 0);
        h.dtMin = r.number("dt_min");
        if (h.dtMin && !(*h.dtMin > 0)) r.fail("dt_min", "must be > 0");
    }

    void readWalls(Scenario& s) {
        const toml::array* walls = root_.arrayOfTables("walls");
        if (!walls) return;
        for (std::size_t i = 0; i < walls->size(); ++i) {
            const TableReader r(*walls->get(i)->as_table(), "walls[" + std::to_string(i + 1) + "]", file_);
            s.walls.push_back(readWall(r, dim_, materialIndex(r, "material"), dir_));
        }
    }

    void readInserts(Scenario& s) {
        const toml::array* inserts = root_.arrayOfTables("insert");
        if (!inserts) return;
        for (std::size_t i = 0; i < inserts->size(); ++i) {
            const TableReader r(*inserts->get(i)->as_table(), "insert[" + std::to_string(i + 1) + "]", file_);
            s.inserts.push_back(readInsert(r));
            if (s.inserts.back().shape == ShapeKind::Polygon && s.method != Method::Tdm)
                r.fail("shape", "polygons need method = \"tdm\" (the event-driven engine handles disks and spheres)");
        }
    }

    /// [[outlet]] and [[inlet]] blocks (docs/scenario.md, "Outlets", "Inlets"): an inlet's particles are read as an
    /// insert's (material, shape, sizes, region, velocities), its timing by loader::readInletFlow.
    void readFlows(Scenario& s) const {
        if (const toml::array* outlets = root_.arrayOfTables("outlet"))
            for (std::size_t i = 0; i < outlets->size(); ++i)
                s.outlets.push_back(loader::readOutlet(
                    TableReader(*outlets->get(i)->as_table(), "outlet[" + std::to_string(i + 1) + "]", file_), dim_,
                    s.duration));
        const toml::array* inlets = root_.arrayOfTables("inlet");
        for (std::size_t i = 0; inlets && i < inlets->size(); ++i) {
            const TableReader r(*inlets->get(i)->as_table(), "inlet[" + std::to_string(i + 1) + "]", file_);
            r.allowOnly({"name", "material", "region", "cylinder", "surface", "radius", "distribution", "velocity",
                         "temperature", "rate", "mass_rate", "start", "end", "interval", "shape", "polygon", "sides",
                         "aspect", "orientation"});
            InletDef in;
            InsertDef& p = in.particles;
            p.material = materialIndex(r, "material");
            readShape(r, p);
            if (p.shape == ShapeKind::Polygon && s.method != Method::Tdm)
                r.fail("shape", "polygons need method = \"tdm\" (the event-driven engine handles disks and spheres)");
            loader::readSizes(r, dim_, p);
            p.velocity = r.vector("velocity", dim_).value_or(Vec3d{0, 0, 0});
            p.temperature = r.number("temperature").value_or(0.0);
            if (!(p.temperature >= 0)) r.fail("temperature", "must be >= 0");
            if (r.has("cylinder"))
                loader::readCylinder(r, dim_, domain_, p);
            else if (!r.has("surface"))
                readRegion(r, p);
            loader::readInletFlow(r, dim_, s, in);
            if (r.has("surface")) loader::readSurface(r, dim_, domain_, in);
            s.inlets.push_back(std::move(in));
        }
        loader::nameFlows(s);
    }

    InsertDef readInsert(const TableReader& r) const {
        r.allowOnly({"arrangement", "count", "radius", "distribution", "material", "region", "spacing", "velocity",
                     "temperature", "frozen", "file", "format", "frozen_types", "shape", "polygon", "sides", "aspect",
                     "orientation"});
        InsertDef in;
        in.pos = r.tablePos();
        in.arrangement = r.choice<Arrangement>("arrangement", {{"random", Arrangement::Random},
                                                               {"lattice", Arrangement::Lattice},
                                                               {"file", Arrangement::File}})
                             .value_or(Arrangement::Random);
        in.material = materialIndex(r, "material");
        in.frozen = r.boolean("frozen").value_or(false);
        readShape(r, in);
        if (r.has("frozen_types") && r.string("arrangement").value_or("random") != "file")
            r.fail("frozen_types", "only for arrangement = \"file\" with format = \"lammps\"");

        if (in.arrangement == Arrangement::File) {
            const std::string why = "not used with arrangement = \"file\" (the file gives it per particle)";
            for (const char* key : {"count", "radius", "distribution", "region", "spacing", "velocity", "temperature"})
                r.forbid(key, why);
            const std::string name = r.requiredString("file");
            if (name.empty()) r.fail("file", "must not be empty");
            std::filesystem::path p(name);
            // A file named on the command line is where the command was typed, as any path on a command line.
            if (p.is_relative()) p = (r.fromOverride("file") ? std::filesystem::current_path() : dir_) / p;
            std::error_code ec;
            if (!std::filesystem::is_regular_file(p, ec))
                r.fail("file", (std::filesystem::exists(p, ec) ? "not a regular file (a directory or a device): "
                                                               : "file not found: ") +
                                   p.string());
            in.file = p.string();
            in.format = r.choice<FileFormat>("format", {{"csv", FileFormat::Csv}, {"lammps", FileFormat::LammpsData}})
                            .value_or(FileFormat::Csv);
            if (in.shape == ShapeKind::Polygon && in.format != FileFormat::Csv)
                r.fail("format", "polygons are read from CSV files (format = \"csv\" with a vertices column)");
            if (in.format != FileFormat::LammpsData)
                r.forbid("frozen_types", "only for format = \"lammps\" (a CSV file has a frozen column)");
            in.frozenTypes = r.integers("frozen_types", 1).value_or(std::vector<int>{});
            return in;
        }

        const std::string why = "only for arrangement = \"file\"";
        r.forbid("file", why);
        r.forbid("format", why);

        const auto count = r.integer("count");
        if (!count) r.fail("count", "is required");
        if (*count <= 0) r.fail("count", "must be > 0");
        in.count = std::size_t(*count);

        loader::readSizes(r, dim_, in);
        readRegion(r, in);

        if (in.arrangement == Arrangement::Lattice) {
            in.spacing = r.number("spacing");
            if (in.spacing) {
                if (!(*in.spacing > 0)) r.fail("spacing", "must be > 0");
                if (*in.spacing < 2 * in.radiusMax)
                    r.fail("spacing", "lattice overlaps: spacing " + formatNumber(*in.spacing) + " < 2 x radius " +
                                          formatNumber(2 * in.radiusMax));
            }
        } else {
            r.forbid("spacing", "only for arrangement = \"lattice\"");
        }

        in.velocity = r.vector("velocity", dim_).value_or(Vec3d{0, 0, 0});
        in.temperature = r.number("temperature").value_or(0.0);
        if (!(in.temperature >= 0)) r.fail("temperature", "must be >= 0");
        return in;
    }

    /// shape, polygon, sides, aspect, orientation: which particles an insert makes (docs/scenario.md).
    void readShape(const TableReader& r, InsertDef& in) const {
        in.shape = r.choice<ShapeKind>("shape", {{"disk", ShapeKind::Disk}, {"polygon", ShapeKind::Polygon}})
                       .value_or(ShapeKind::Disk);
        if (in.shape == ShapeKind::Disk) {
            for (const char* key : {"polygon", "sides", "aspect", "orientation"})
                r.forbid(key, "only for shape = \"polygon\"");
            return;
        }
        if (dim_ != 2) r.fail("shape", "polygons exist only in 2D (dimension = 2)");
        const bool file = r.string("arrangement").value_or("random") == "file";
        if (file) {
            for (const char* key : {"polygon", "sides", "aspect", "orientation"})
                r.forbid(key, "not used with arrangement = \"file\" (the file gives each polygon's vertices)");
            return;
        }
        in.polygon = r.choice<PolygonKind>("polygon", {{"regular", PolygonKind::Regular},
                                                       {"rectangle", PolygonKind::Rectangle},
                                                       {"random", PolygonKind::Random}})
                         .value_or(PolygonKind::Regular);
        const int maxSides = 20;  // polygon::kMaxVertices
        const std::string sidesRange = "must be an integer from 3 to " + std::to_string(maxSides);
        if (in.polygon == PolygonKind::Rectangle) {
            r.forbid("sides", "not for polygon = \"rectangle\" (4 sides)");
            in.sidesMin = in.sidesMax = 4;
        } else if (const toml::node* n = r.table().get("sides"); n && n->is_array()) {
            if (in.polygon != PolygonKind::Random)
                r.fail("sides", "a range [min, max] only for polygon = \"random\"; a regular polygon has one number");
            const toml::array* a = n->as_array();
            const auto* lo = a->size() == 2 ? a->get(0)->as_integer() : nullptr;
            const auto* hi = a->size() == 2 ? a->get(1)->as_integer() : nullptr;
            if (!lo || !hi) r.fail("sides", "expected an integer or an array [min, max] of 2 integers");
            if (lo->get() < 3 || hi->get() > maxSides || lo->get() > hi->get())
                r.fail("sides", "must satisfy 3 <= min <= max <= " + std::to_string(maxSides));
            in.sidesMin = int(lo->get());
            in.sidesMax = int(hi->get());
        } else {
            const auto sides = r.integer("sides");
            if (!sides)
                r.fail("sides", "is required for polygon = \"" +
                                    std::string(in.polygon == PolygonKind::Regular ? "regular" : "random") + "\"");
            if (*sides < 3 || *sides > maxSides) r.fail("sides", sidesRange);
            in.sidesMin = in.sidesMax = int(*sides);
        }
        if (in.polygon == PolygonKind::Regular) {
            r.forbid("aspect", "only for polygon = \"rectangle\" or \"random\"");
        } else {
            in.aspect = r.number("aspect").value_or(in.polygon == PolygonKind::Random ? 1.5 : 1.0);
            if (in.polygon == PolygonKind::Rectangle && !(in.aspect > 0)) r.fail("aspect", "must be > 0");
            if (in.polygon == PolygonKind::Random && !(in.aspect >= 1)) r.fail("aspect", "must be >= 1");
        }
        in.orientation = 0.0;
        if (const toml::node* n = r.table().get("orientation")) {
            if (const auto* str = n->as_string()) {
                if (str->get() != "random") r.fail("orientation", "must be \"random\" or a number (radians)");
                in.orientation.reset();
            } else if (n->is_number()) {
                in.orientation = r.number("orientation");
            } else {
                r.fail("orientation", "expected a number (radians) or \"random\"");
            }
        }
    }

    void readRegion(const TableReader& r, InsertDef& in) const {
        in.regionLo = domain_.lo;
        in.regionHi = domain_.hi;
        if (const toml::table* t = r.subTable("region")) {
            const TableReader g(*t, r.keyPath("region"), file_);
            g.allowOnly({"lo", "hi"});
            in.regionLo = g.requiredVector("lo", dim_);
            in.regionHi = g.requiredVector("hi", dim_);
            for (int k = 0; k < dim_; ++k) {
                if (!(in.regionHi[k] > in.regionLo[k]))
                    g.fail("hi", std::string("must be > lo on every axis (axis ") + kAxisName[k] + ")");
                if (in.regionLo[k] < domain_.lo[k] || in.regionHi[k] > domain_.hi[k])
                    r.fail("region", std::string("must lie inside the domain (axis ") + kAxisName[k] + ": [" +
                                         formatNumber(in.regionLo[k]) + ", " + formatNumber(in.regionHi[k]) +
                                         "] is not inside [" + formatNumber(domain_.lo[k]) + ", " +
                                         formatNumber(domain_.hi[k]) + "])");
            }
        }
        for (int k = 0; k < dim_; ++k)
            if (in.regionHi[k] - in.regionLo[k] < 2 * in.radiusMax)
                r.fail(r.has("region") ? "region" : "radius",
                       std::string("the region is narrower than one particle diameter on axis ") + kAxisName[k]);
    }

    /// [[fields]] and [[regions]] (scenario/fields_loader.hpp).
    void readMeasures(Scenario& s) const {
        if (const toml::array* a = root_.arrayOfTables("fields"))
            for (std::size_t i = 0; i < a->size(); ++i)
                s.fields.push_back(loader::readFields(
                    TableReader(*a->get(i)->as_table(), "fields[" + std::to_string(i + 1) + "]", file_), dim_, s));
        if (const toml::array* a = root_.arrayOfTables("regions"))
            for (std::size_t i = 0; i < a->size(); ++i)
                s.regions.push_back(loader::readRegion(
                    TableReader(*a->get(i)->as_table(), "regions[" + std::to_string(i + 1) + "]", file_), dim_,
                    s.domain));
        loader::checkMeasureNames(s);
    }

    void readOutput(Scenario& s) {
        const TableReader r = child("output");
        r.allowOnly({"directory", "series_period", "snapshot_period", "checkpoint_period", "color_by", "color_range",
                     "view", "picture_width", "contacts", "stress"});
        s.output.contacts = r.boolean("contacts").value_or(false);
        s.output.stress = r.boolean("stress").value_or(true);
        OutputDef& o = s.output;
        o.pos = r.tablePos();
        o.directory = r.string("directory").value_or(o.directory);
        if (o.directory.empty()) r.fail("directory", "must not be empty");
        o.seriesPeriod = r.number("series_period").value_or(o.seriesPeriod);
        if (!(o.seriesPeriod >= 0)) r.fail("series_period", "must be >= 0");
        o.snapshotPeriod = r.number("snapshot_period").value_or(o.snapshotPeriod);
        o.checkpointPeriod = r.number("checkpoint_period").value_or(o.checkpointPeriod);
        if (!(o.checkpointPeriod >= 0) || !std::isfinite(o.checkpointPeriod))
            r.fail("checkpoint_period", "must be a finite number >= 0 (0: only at the end)");
        checkOutputCounts(r, s);
        readPicture(r, s);
    }

    /// The keys of final.png (docs/scenario.md, [output]).
    void readPicture(const TableReader& r, Scenario& s) const {
        OutputDef& o = s.output;
        o.colorBy = r.string("color_by").value_or("");
        if (r.has("color_by")) {
            std::string base = o.colorBy;
            const std::size_t n = base.size();
            bool component = false;
            if (n > 2 && base[n - 2] == '_' && base[n - 1] >= 'x' && base[n - 1] <= 'z') {
                for (const char* v : kPictureVectorFields)
                    if (base.substr(0, n - 2) == v) component = true;
                if (component) base = base.substr(0, n - 2);
            }
            std::string known;
            bool found = false;
            for (const char* f : kPictureFields) {
                known += std::string(known.empty() ? "" : ", ") + "\"" + f + "\"";
                found = found || base == f;
            }
            if (!found)
                r.fail("color_by", "unknown field \"" + o.colorBy + "\"; one of " + known +
                                       ", or a component of a vector field (\"velocity_z\")");
            if (base == "mode" && s.method != Method::Haet)
                r.fail("color_by", "\"mode\" needs method = \"haet\" (only the hybrid has two modes)");
        }
        if (r.has("color_range")) {
            const Vec3d v = *r.vector("color_range", 2);
            if (!(v[1] > v[0])) r.fail("color_range", "expected [lo, hi] with hi > lo");
            if (o.colorBy == "mode" || o.colorBy == "material")
                r.fail("color_range", "a categorical colouring (\"" + o.colorBy + "\") has no colour bar");
            o.colorRange = std::array<double, 2>{v[0], v[1]};
        }
        if (r.has("view")) {
            if (dim_ != 3) r.fail("view", "only for dimension = 3 (a 2D picture shows the plane)");
            if (const toml::node* n = r.table().get("view"); n && n->is_string()) {
                const auto v = axisView(*r.string("view"));
                if (!v) r.fail("view", "expected \"x\", \"y\", \"z\", \"-x\", \"-y\", \"-z\" or [dx, dy, dz]");
                o.view = *v;
            } else {
                o.view = *r.vector("view", 3);
                if (!(o.view[0] * o.view[0] + o.view[1] * o.view[1] + o.view[2] * o.view[2] > 0))
                    r.fail("view", "the direction must not be zero");
            }
        }
        if (const auto w = r.integer("picture_width")) {
            if (*w < 64 || *w > 4096) r.fail("picture_width", "must be 64 to 4096 px");
            o.pictureWidth = static_cast<int>(*w);
        }
    }

    /// A period that would write more rows or snapshots than a run can keep (series.csv is held in memory and
    /// rewritten whole, so that it is always complete on disk) is an error, not hours of output at t = 0.
    void checkOutputCounts(const TableReader& r, const Scenario& s) const {
        const OutputDef& o = s.output;
        if (o.seriesPeriod > 0 && s.duration / o.seriesPeriod > kMaxSeriesRows)
            r.fail("series_period", formatNumber(o.seriesPeriod) + " s asks for " +
                                        formatNumber(std::floor(s.duration / o.seriesPeriod)) + " rows over " +
                                        formatNumber(s.duration) + " s; at most " + formatNumber(kMaxSeriesRows));
        if (o.snapshotPeriod > 0 && s.duration / o.snapshotPeriod > kMaxSnapshots)
            r.fail("snapshot_period", formatNumber(o.snapshotPeriod) + " s asks for " +
                                          formatNumber(std::floor(s.duration / o.snapshotPeriod)) + " snapshots over " +
                                          formatNumber(s.duration) + " s; at most " + formatNumber(kMaxSnapshots));
        if (o.checkpointPeriod > 0 && s.duration / o.checkpointPeriod > kMaxSnapshots)
            r.fail("checkpoint_period", formatNumber(o.checkpointPeriod) + " s asks for " +
                                            formatNumber(std::floor(s.duration / o.checkpointPeriod)) +
                                            " checkpoints over " + formatNumber(s.duration) + " s; at most " +
                                            formatNumber(kMaxSnapshots));
    }

    TableReader root_;
    std::string file_;
    std::filesystem::path dir_;
    int dim_ = 3;
    DomainDef domain_;
    const std::vector<MaterialDef>* materials_ = nullptr;
    bool needDiskLaw_ = false;
};

// ---- Overrides: `--set KEY=VALUE` on the command line (docs/scenario.md, "Overrides") ----------------------------
// An override replaces (or adds) one value of the parsed file before the Loader reads it, so it is validated by the
// same code as a value of the file and its errors name the key the same way. Its value keeps the TOML source name
// "--set KEY=VALUE", which is how TableReader::posOfNode tells it from the file's values.

bool isBareKeyChar(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

/// One step of a key path: a table's key, and for an array the 1-based index of its element (0: none).
struct KeyStep {
    std::string name;
    std::size_t index = 0;
};

/// "insert[2].region.lo" -> {insert, 2}, {region}, {lo}; nullopt when malformed.
std::optional<std::vector<KeyStep>> parseKeyPath(std::string_view key) {
    std::vector<KeyStep> steps;
    std::size_t i = 0;
    while (true) {
        KeyStep step;
        while (i < key.size() && isBareKeyChar(key[i])) step.name += key[i++];
        if (step.name.empty()) return std::nullopt;
        if (i < key.size() && key[i] == '[') {
            const std::size_t close = key.find(']', i);
            if (close == std::string_view::npos || close == i + 1 || close - i > 10) return std::nullopt;
            for (std::size_t k = i + 1; k < close; ++k) {
                if (key[k] < '0' || key[k] > '9') return std::nullopt;
                step.index = step.index * 10 + std::size_t(key[k] - '0');
            }
            if (step.index == 0) return std::nullopt;
            i = close + 1;
        }
        steps.push_back(std::move(step));
        if (i == key.size()) return steps;
        if (key[i] != '.') return std::nullopt;
        ++i;
    }
}

/// Applies one override to the parsed file `root`; returns "KEY=VALUE" as it was applied (blanks around '=' and the
/// ends trimmed). A value that is not TOML but a bare word (letters, digits, '_', '-') is taken as a string, so that
/// `method=edm` needs no quotes that the shell would remove.
std::string applyOverride(toml::table& root, const std::string& text, const std::string& file) {
    const std::string source = "--set " + text;
    const SourcePos pos{file + " (" + source + ")", 0};
    const std::size_t eq = text.find('=');
    if (eq == std::string::npos) throw ScenarioError(pos, "", "expected KEY=VALUE");
    const std::string key(trim(std::string_view(text).substr(0, eq)));
    const std::string value(trim(std::string_view(text).substr(eq + 1)));
    const auto steps = parseKeyPath(key);
    if (!steps)
        throw ScenarioError(pos, key,
                            "not a key path (dotted keys, an array's element by its 1-based index: insert[2].count)");
    if (value.empty()) throw ScenarioError(pos, key, "no value after '='");

    toml::table parsed;
    try {
        parsed = toml::parse("value = " + value + "\n", std::string_view(source));
    } catch (const toml::parse_error&) {
        if (!std::all_of(value.begin(), value.end(), isBareKeyChar))
            throw ScenarioError(pos, key,
                                "the value is not in TOML syntax (a number, true/false, \"text\", [a, b], "
                                "{ k = v })");
        parsed = toml::parse("value = \"" + value + "\"\n", std::string_view(source));
    }

    // Walk to the table that holds the last key; tables that the file does not have are made.
    toml::table* t = &root;
    std::string done;  // the key path walked so far, written as the loader writes keys
    auto stepName = [](const KeyStep& s) { return s.index ? s.name + "[" + std::to_string(s.index) + "]" : s.name; };
    auto element = [&](toml::node* n, const KeyStep& s) -> toml::node* {
        toml::array* a = n ? n->as_array() : nullptr;
        const std::string here = done.empty() ? s.name : done + "." + s.name;
        if (!a)
            throw ScenarioError(pos, here,
                                n ? "not an array: it has no element " + std::to_string(s.index)
                                  : "not in the file: there is no element to set");
        if (s.index > a->size())
            throw ScenarioError(pos, here + "[" + std::to_string(s.index) + "]",
                                "no such element: the file has " + std::to_string(a->size()));
        return a->get(s.index - 1);
    };
    for (std::size_t k = 0; k + 1 < steps->size(); ++k) {
        const KeyStep& s = (*steps)[k];
        toml::node* n = t->get(s.name);
        if (s.index) {
            n = element(n, s);
        } else if (!n) {
            n = t->insert(s.name, toml::table{}).first->second.as_table();
        }
        done += (done.empty() ? "" : ".") + stepName(s);
        t = n->as_table();
        if (!t) throw ScenarioError(pos, done, "not a table: a value has no keys");
    }
    const KeyStep& last = steps->back();
    toml::node& v = *parsed.get("value");
    if (last.index) {
        element(t->get(last.name), last);  // checks that there is such an element
        toml::array& a = *t->get(last.name)->as_array();
        v.visit([&](auto& x) { a.replace(a.cbegin() + std::ptrdiff_t(last.index - 1), std::move(x)); });
    } else {
        v.visit([&](auto& x) { t->insert_or_assign(last.name, std::move(x)); });
    }
    return key + "=" + value;
}

/// The keys a resume may change (docs/scenario.md, "Resuming"): when the run ends and what it writes, never what
/// it computes.
bool safeOnResume(const std::string& key) { return key == "duration" || key.rfind("output.", 0) == 0; }

/// A number as the shortest text that reads back to it (0.7, not 0.69999999999999996).
std::string shortest(double x) {
    char text[32];
    return std::string(text, std::to_chars(text, text + sizeof text, x).ptr);
}

/// A value in TOML syntax, numbers shortest.
std::string valueText(const toml::node& node) {
    if (const auto* d = node.as_floating_point()) return shortest(d->get());
    if (const toml::array* a = node.as_array()) {
        std::string s = "[";
        for (std::size_t i = 0; i < a->size(); ++i) s += (i ? ", " : "") + valueText(*a->get(i));
        return s + "]";
    }
    if (const toml::table* t = node.as_table()) {
        std::string s = "{";
        for (const auto& [k, v] : *t) s += (s.size() > 1 ? ", " : " ") + std::string(k.str()) + " = " + valueText(v);
        return s + " }";
    }
    std::ostringstream os;  // integers, booleans, strings (quoted and escaped), dates
    node.visit([&](const auto& v) { os << v; });
    return os.str();
}

/// Every leaf of the table as "key = value" lines, keys as the errors write them (insert[2].radius), in key order.
void flattenKeys(const toml::table& t, const std::string& prefix, std::string& out) {
    for (const auto& [k, node] : t) {
        const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
        if (const toml::table* sub = node.as_table()) {
            flattenKeys(*sub, key, out);
            continue;
        }
        const toml::array* a = node.as_array();
        if (a && a->is_array_of_tables()) {
            for (std::size_t i = 0; i < a->size(); ++i)
                flattenKeys(*a->get(i)->as_table(), key + "[" + std::to_string(i + 1) + "]", out);
            continue;
        }
        if (safeOnResume(key)) continue;
        out += key + " = " + valueText(node) + "\n";
    }
}

/// The values that follow from duration unless the file sets them (an inlet's end and interval, an outlet's
/// interval): a resume that changes duration would change them, and with them the run, so they are part of what a
/// resume may not change, as "key = value (the default: ...)" lines.
void appendDurationDefaults(const toml::table& root, const Scenario& s, std::string& out) {
    auto given = [&](const char* array, std::size_t k, const char* key) {
        const toml::array* a = root[array].as_array();
        const toml::table* t = a && k < a->size() ? a->get(k)->as_table() : nullptr;
        return t && t->contains(key);
    };
    auto line = [&](const std::string& key, double value) {
        out += key + " = " + shortest(value) + " (the default, from duration: set it to change duration)\n";
    };
    for (std::size_t k = 0; k < s.inlets.size(); ++k) {
        const std::string at = "inlet[" + std::to_string(k + 1) + "].";
        if (!given("inlet", k, "end")) line(at + "end", s.inlets[k].end);
        if (!given("inlet", k, "interval")) line(at + "interval", s.inlets[k].interval);
    }
    for (std::size_t k = 0; k < s.outlets.size(); ++k)
        if (!given("outlet", k, "interval"))
            line("outlet[" + std::to_string(k + 1) + "].interval", s.outlets[k].interval);
}

/// The files the scenario names (particle files, STL meshes) by their contents: a changed file is another scenario,
/// so their hashes are part of what a resume may not change, as "KEY (contents) = fnv1a64 HASH of PATH" lines; a
/// resume names the file (checkStateKeys). The files were read when the scenario was loaded.
void appendFileContents(const Scenario& s, std::string& out) {
    auto line = [&](const std::string& key, const std::string& path) {
        std::ifstream in(path, std::ios::binary);
        std::ostringstream bytes;
        bytes << in.rdbuf();
        out += key + " (contents) = fnv1a64 " + fnv1a64Hex(bytes.str()) + " of " + path + "\n";
    };
    for (std::size_t k = 0; k < s.inserts.size(); ++k)
        if (!s.inserts[k].file.empty()) line("insert[" + std::to_string(k + 1) + "].file", s.inserts[k].file);
    for (std::size_t k = 0; k < s.walls.size(); ++k)
        if (!s.walls[k].file.empty()) line("walls[" + std::to_string(k + 1) + "].file", s.walls[k].file);
}

}  // namespace

std::string fnv1a64Hex(std::string_view bytes) {
    std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a 64 offset basis
    for (unsigned char c : bytes) {
        h ^= c;
        h *= 0x100000001b3ull;  // FNV 64 prime
    }
    static const char* digits = "0123456789abcdef";
    std::string out(16, '0');
    for (int i = 15; i >= 0; --i, h >>= 4) out[std::size_t(i)] = digits[h & 0xf];
    return out;
}

Scenario parseScenario(std::string_view text, const std::filesystem::path& file,
                       const std::vector<std::string>& overrides) {
    const std::string name = file.string();
    toml::table root;
    try {
        root = toml::parse(text, std::string_view(name));
    } catch (const toml::parse_error& e) {
        throw ScenarioError({name, int(e.source().begin.line)}, "",
                            "TOML syntax error: " + std::string(e.description()));
    }
    std::vector<std::string> applied;
    for (const std::string& o : overrides) {
        const std::string a = applyOverride(root, o, name);
        // A later override of the same key replaces the earlier one, in the record as in the scene.
        const std::string key = a.substr(0, a.find('='));
        std::erase_if(applied, [&](const std::string& b) { return b.compare(0, key.size() + 1, key + "=") == 0; });
        applied.push_back(a);
    }
    Scenario s = Loader(root, name, file.parent_path()).load();
    s.hash = fnv1a64Hex(text);
    flattenKeys(root, "", s.stateKeys);
    appendDurationDefaults(root, s, s.stateKeys);
    appendFileContents(s, s.stateKeys);
    s.stateHash = fnv1a64Hex(s.stateKeys);
    s.overrides = std::move(applied);
    return s;
}

Scenario loadScenario(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
    return parseScenario(readScenarioText(file), file, overrides);
}

}  // namespace haet
