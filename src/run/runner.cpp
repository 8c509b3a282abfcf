#include "run/runner.hpp"

#include <fmt/format.h>
#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>

#include "core/version.hpp"
#include "edm/engine.hpp"
#include "haet/engine.hpp"
#include "io/atomic_file.hpp"
#include "io/checkpoint.hpp"
#include "io/frame.hpp"
#include "io/json.hpp"
#include "io/series.hpp"
#include "io/vtk.hpp"
#include "polygon/output.hpp"
#include "run/checkpoint.hpp"
#include "run/export.hpp"
#include "run/flow.hpp"
#include "run/measures.hpp"
#include "run/picture.hpp"
#include "run/progress.hpp"
#include "run/run_dir.hpp"
#include "run/schedule.hpp"
#include "run/stop.hpp"
#include "run/walls_output.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world/state.hpp"

namespace haet {
namespace {

using Clock = std::chrono::steady_clock;

std::size_t peakRssBytes() {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    return static_cast<std::size_t>(ru.ru_maxrss) * 1024;
}

/// Energies of a state common to every engine [J].
template <int D>
struct Energies {
    double kinetic = 0, rotational = 0, potential = 0;
    double mv2 = 0;  ///< sum m v^2 [J], for the kinetic pressure
};

template <int D>
Energies<D> energies(const World<D>& w) {
    const Particles<D>& p = w.particles;
    Energies<D> s;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double m = p.mass[i];
        const double v2 = norm2(p.v[i]);
        s.kinetic += 0.5 * m * v2;
        s.mv2 += m * v2;
        s.rotational += 0.5 * p.inertia(i) * norm2(p.w[i]);
        s.potential -= m * dot(w.domain.gravity, w.domain.unwrap(p.x[i], p.image[i]));
    }
    return s;
}

/// What the run loop needs from an engine. Engine-specific measurements are extra series columns. As a FlowHost
/// it lets the inlets and outlets (run/flow.hpp) add and remove particles.
template <int D>
class Driver : public FlowHost<D> {
public:
    virtual ~Driver() = default;
    virtual const char* method() const = 0;
    /// Runs the engine to time t; world.time = t. An engine that moves its particles lazily (the EDM) may leave
    /// the World's particle state behind: synchronise() brings it to world.time.
    virtual void advanceTo(double t) = 0;
    /// The run loop calls this before it reads the particles (outputs, the end of the run), not after every
    /// progress chunk: an EDM synchronisation costs O(N), and 500 chunks of a short run cost more than its events.
    virtual void synchronise() {}
    /// Time resolution of the engine: the loop treats times closer than this as equal [s].
    virtual double timeTolerance() const = 0;
    virtual double dt() const = 0;             ///< time step [s] (0 for a pure event-driven run)
    virtual std::uint64_t steps() const = 0;   ///< time steps taken (0 for a pure event-driven run)
    virtual std::size_t contacts() const = 0;  ///< enduring contacts now
    virtual double maxOverlapRatio() const = 0;
    virtual double elasticEnergy() const = 0;  ///< energy stored in contacts [J]
    /// Sum of r_ij . F_ij (soft contacts) plus collision virial / window (hard collisions) [J].
    virtual double virial(double window) = 0;
    virtual std::vector<std::string> extraColumns() const = 0;
    virtual std::vector<std::optional<double>> extraRow() const = 0;
    virtual void describe(JsonObject& j) const = 0;  ///< engine facts for run.json
    /// Hybrid runs: the engine, for the mode field, the zone grid and the picture. Others: nullptr.
    virtual const HaetEngine<D>* hybrid() const { return nullptr; }
    /// The time-driven step [s]; 0 for a pure event-driven run (the outlets' cadence, docs/physics.md K.2).
    virtual double stepTime() const = 0;
    /// Whether the engine's state can be checkpointed and resumed (saveState, loadState).
    virtual bool restartable() const { return false; }
    /// The engine's state beyond the World's, between calls of advanceTo (after exposeState()).
    virtual void saveState(ByteWriter&) const {}
    /// Takes the checkpoint's state, in a driver made on the World loaded from it (loadWorld).
    virtual void loadState(const CheckpointFile&) {}
    /// Before a checkpoint: the World as it must be saved, without changing what the engine computes next (an
    /// event-driven engine holding the positions gives them back as they are, unsynchronised).
    virtual void exposeState() {}
    /// The measurements' hooks (run/measures.hpp): the contacts of the force pass at time t into *sink, the time of
    /// the last pass that recorded them (-1: none), every event-driven collision.
    virtual void recordContactsAt(ContactSink<D>*, double) {}
    virtual double contactsRecordedAt() const { return -1; }
    virtual void setCollisionHook(std::function<void(const EdmCollision<D>&)>) {}
};

/// The driver's loadState for one engine: the World's particles again (making the engine may have sorted them or
/// wrapped them into the box), then the engine's own state.
template <int D, class Engine>
void loadEngineState(const CheckpointFile& f, World<D>& w, Engine& eng) {
    ByteReader world = f.section("WRLD");
    loadWorld(world, w);
    ByteReader in = f.section("ENGN");
    eng.loadState(in);
}

template <int D>
class TdmDriver final : public Driver<D> {
public:
    TdmDriver(World<D>& w, const TdmSettings& s, std::string dtNote) : w_(w), eng_(w, s), note_(std::move(dtNote)) {}
    const char* method() const override { return "tdm"; }
    void advanceTo(double t) override { eng_.advanceTo(t); }
    double timeTolerance() const override { return 0.5 * eng_.settings().dt; }
    double dt() const override { return eng_.settings().dt; }
    std::uint64_t steps() const override { return eng_.steps(); }
    std::size_t contacts() const override { return eng_.forceStats().contacts; }
    double maxOverlapRatio() const override { return eng_.forceStats().maxOverlapRatio; }
    double elasticEnergy() const override { return eng_.contactEnergy(); }
    double virial(double) override { return eng_.pairVirial(); }
    std::vector<std::string> extraColumns() const override {
        std::vector<std::string> c{"rebuilds"};
        for (std::string& name : wallLoadColumns(w_)) c.push_back(std::move(name));
        return c;
    }
    std::vector<std::optional<double>> extraRow() const override {
        std::vector<std::optional<double>> r{double(eng_.rebuilds())};
        appendWallLoads(w_, eng_, r);
        return r;
    }
    void describe(JsonObject& j) const override {
        j.add("dt", eng_.settings().dt);
        j.add("dt_rule", note_);
        j.add("neighbor_rebuilds", eng_.rebuilds());
    }
    const TdmEngine<D>& engine() const { return eng_; }
    double stepTime() const override { return eng_.settings().dt; }
    std::size_t eager() const override { return w_.particles.size(); }
    void synchronise() override {}
    void remove(const std::vector<std::uint32_t>& which) override { removeTimeDriven(w_, eng_, which); }
    void added(std::size_t first) override { addTimeDriven(w_, eng_, first); }
    bool restartable() const override { return true; }
    void saveState(ByteWriter& out) const override { eng_.saveState(out); }
    void loadState(const CheckpointFile& f) override { loadEngineState(f, w_, eng_); }
    void recordContactsAt(ContactSink<D>* s, double t) override { eng_.recordContactsAt(s, t); }
    double contactsRecordedAt() const override { return eng_.contactsRecordedAt(); }

private:
    World<D>& w_;
    TdmEngine<D> eng_;
    std::string note_;
};

template <int D>
class EdmDriver final : public Driver<D> {
public:
    EdmDriver(World<D>& w, const EdmSettings& s) : w_(w), eng_(w, s) {}
    const char* method() const override { return "edm"; }
    void advanceTo(double t) override { w_.time = eng_.advanceEvents(t); }  // earlier than t after a stop
    void synchronise() override { eng_.synchronise(w_.time); }
    double timeTolerance() const override { return 1e-12; }
    double dt() const override { return 0; }
    std::uint64_t steps() const override { return 0; }
    std::size_t contacts() const override { return 0; }
    double maxOverlapRatio() const override { return 0; }
    double elasticEnergy() const override { return 0; }
    /// Collision virial (docs/physics.md E.2): sum of r_ij . dp_i over the window, divided by its length.
    double virial(double window) override {
        const double v = eng_.takeCollisionVirial();
        return window > 0 ? v / window : 0.0;
    }
    std::vector<std::string> extraColumns() const override { return {"events", "collisions"}; }
    std::vector<std::optional<double>> extraRow() const override {
        return {double(eng_.events()), double(eng_.collisions())};
    }
    void describe(JsonObject& j) const override {
        j.add("events", eng_.events());
        j.add("collisions", eng_.collisions());
        j.add("tc_elastic", eng_.stats().tcElastic);
        j.add("tc_time", eng_.tcTime());
    }
    double stepTime() const override { return 0; }
    std::size_t eager() const override { return 0; }
    // Particles come and go between synchronisations: the World is current then, and the engine starts its events
    // anew from it (reset: O(N), at the flows' cadence only when something changed).
    void remove(const std::vector<std::uint32_t>& which) override {
        dropParticles(w_.particles, which);
        eng_.reset();
    }
    void added(std::size_t) override { eng_.reset(); }
    bool restartable() const override { return eng_.restartable(); }
    void exposeState() override { eng_.exposeHeldState(); }
    void saveState(ByteWriter& out) const override { eng_.saveState(out); }
    void loadState(const CheckpointFile& f) override { loadEngineState(f, w_, eng_); }
    void setCollisionHook(std::function<void(const EdmCollision<D>&)> f) override { eng_.setObserver(std::move(f)); }

private:
    World<D>& w_;
    EdmEngine<D> eng_;
};

template <int D>
class HaetDriver final : public Driver<D> {
public:
    HaetDriver(World<D>& w, const TdmSettings& ts, const EdmSettings& es, const HaetSettings& hs, std::string dtNote)
        : eng_(w, ts, es, hs), note_(std::move(dtNote)) {}
    const char* method() const override { return "haet"; }
    void advanceTo(double t) override { eng_.advanceTo(t); }
    void synchronise() override { eng_.synchronise(); }
    double timeTolerance() const override { return 0.5 * eng_.dt(); }
    double dt() const override { return eng_.dt(); }
    std::uint64_t steps() const override { return eng_.steps(); }
    std::size_t contacts() const override { return eng_.tdm().forceStats().contacts; }
    double maxOverlapRatio() const override { return eng_.tdm().forceStats().maxOverlapRatio; }
    double elasticEnergy() const override { return eng_.tdm().contactEnergy(); }
    double virial(double window) override {
        const double collisions = eng_.takeCollisionVirial();
        return eng_.tdm().pairVirial() + (window > 0 ? collisions / window : 0.0);
    }
    std::vector<std::string> extraColumns() const override {
        return {"n_tdm",     "n_edm",        "events",         "collisions",     "tdm_steps",          "to_tdm",
                "to_edm",    "tc_handovers", "dissipated_tdm", "dissipated_edm", "energy_unaccounted", "energy_in",
                "energy_out"};
    }
    std::vector<std::optional<double>> extraRow() const override {
        const HaetEnergy e = eng_.energy();
        const HaetCounters& c = eng_.counters();
        return {double(eng_.nTdm()),
                double(eng_.nEdm()),
                double(eng_.events()),
                double(eng_.collisions()),
                double(eng_.steps()),
                double(c.toTdm),
                double(c.toEdm),
                double(c.tcHandovers),
                e.dissipatedTdm,
                e.dissipatedEdm,
                e.unaccounted,
                e.inflow,
                e.outflow};
    }
    void describe(JsonObject& j) const override {
        const HaetCounters& c = eng_.counters();
        j.add("dt", eng_.dt());
        j.add("dt_rule", note_);
        j.add("dt_min", eng_.dtMin());
        j.add("zone_size", eng_.settings().zones.size);
        j.add("events", eng_.events());
        j.add("collisions", eng_.collisions());
        j.add("n_tdm", eng_.nTdm());
        j.add("n_edm", eng_.nEdm());
        j.add("to_tdm", c.toTdm);
        j.add("to_edm", c.toEdm);
        j.add("tc_handovers", c.tcHandovers);
        j.add("relabels", c.relabels);
        j.add("neighbor_rebuilds", eng_.tdm().rebuilds());
    }
    const HaetEngine<D>* hybrid() const override { return &eng_; }
    double stepTime() const override { return eng_.dt(); }
    std::size_t eager() const override { return eng_.nTdm(); }
    void remove(const std::vector<std::uint32_t>& which) override { eng_.removeParticles(which); }
    void added(std::size_t first) override { eng_.addParticles(first); }
    void recordContactsAt(ContactSink<D>* s, double t) override { eng_.recordContactsAt(s, t); }
    double contactsRecordedAt() const override { return eng_.tdm().contactsRecordedAt(); }
    void setCollisionHook(std::function<void(const EdmCollision<D>&)> f) override {
        eng_.setCollisionHook(std::move(f));
    }

private:
    HaetEngine<D> eng_;
    std::string note_;
};

template <int D>
std::unique_ptr<Driver<D>> makeDriver(const Scenario& sc, World<D>& world, const std::atomic<bool>* stop) {
    switch (sc.method) {
        case Method::Tdm: {
            std::string note;
            TdmSettings ts = tdmSettings<D>(sc, world, &note);
            ts.stop = stop;
            return std::make_unique<TdmDriver<D>>(world, ts, note);
        }
        case Method::Edm: {
            world.particles.dropTdmState();  // forces and torques: nothing reads them in this run
            EdmSettings es = edmSettings(sc);
            es.holdState = true;  // positions, velocities and radii only in the engine between synchronisations
            es.radiusBound = inletRadiusBound(sc);
            es.stop = stop;
            return std::make_unique<EdmDriver<D>>(world, es);
        }
        case Method::Haet: {
            std::string note;
            const TdmSettings ts = tdmSettings<D>(sc, world, &note);
            HaetSettings hs = haetSettings<D>(sc);
            hs.radiusBound = inletRadiusBound(sc);
            hs.stop = stop;  // the hybrid stops between its steps; its engines, inside one, do not
            return std::make_unique<HaetDriver<D>>(world, ts, edmSettings(sc), hs, note);
        }
    }
    throw ScenarioError({sc.path, 0}, "method", "unknown method");
}

/// The particles as a snapshot holds them (particles_NNNNNN.vtu) and final.png draws them: positions, radius,
/// velocity, angular_velocity, force (zero in a pure event-driven run, which keeps none), material, id, and in a
/// hybrid run mode (1 time-driven, 0 event-driven). The names are those of kPictureFields.
template <int D>
ParticleFrame snapshotFrame(const World<D>& w, double time, const HaetEngine<D>* hybrid) {
    const Particles<D>& p = w.particles;
    const std::size_t n = p.size();
    ParticleFrame fr;
    fr.time = time;
    fr.xyz.assign(3 * n, 0.0);
    for (const auto& [name, comps, type] : {std::tuple{"radius", 1, VtkField::Float64},
                                            {"velocity", 3, VtkField::Float64},
                                            {"angular_velocity", 3, VtkField::Float64},
                                            {"force", 3, VtkField::Float64},
                                            {"material", 1, VtkField::Int32},
                                            {"id", 1, VtkField::Int64}})
        fr.add(name, comps, type);
    if (hybrid) fr.add("mode", 1, VtkField::Int32);
    // Every field added: the references stay valid.
    FrameField &rad = fr.fields[0], &vel = fr.fields[1], &spin = fr.fields[2], &force = fr.fields[3],
               &mat = fr.fields[4], &ids = fr.fields[5];
    const bool forces = p.hasTdmState();
    for (std::size_t i = 0; i < n; ++i) {
        for (int k = 0; k < D; ++k) {
            fr.xyz[3 * i + k] = p.x[i][k];
            vel.values[3 * i + k] = p.v[i][k];
            if (forces) force.values[3 * i + k] = p.f[i][k];
        }
        if constexpr (D == 2)
            spin.values[3 * i + 2] = p.w[i][0];
        else
            for (int k = 0; k < 3; ++k) spin.values[3 * i + k] = p.w[i][k];
        rad.values[i] = p.radius[i];
        ids.values[i] = static_cast<double>(p.id[i]);
        mat.values[i] = p.material[i];
    }
    if (hybrid)  // 1: time-driven, 0: event-driven
        for (std::size_t i = 0; i < n; ++i) fr.fields[6].values[i] = i < p.tdmCount() ? 1 : 0;
    return fr;
}

template <int D>
class SnapshotWriter {
public:
    SnapshotWriter(const std::filesystem::path& dir)
        : dir_(dir), pvd_(dir / "particles.pvd"), walls_(dir / "walls.pvd"), zones_(dir / "zones.pvd") {}

    void write(const World<D>& w, double time, const HaetEngine<D>* hybrid) {
        const Particles<D>& p = w.particles;
        const std::string name = fmt::format("particles_{:06d}.vtu", count_);
        writeFrameVtu(dir_ / name, snapshotFrame(w, time, hybrid));
        pvd_.add(time, name);
        if (hybrid) writeZones(*hybrid, time);
        if constexpr (D == 2) {
            if (p.hasPolygons()) {  // the real shapes, as polygon cells (polygons.pvd)
                if (!polys_) polys_.emplace(dir_ / "polygons.pvd");
                const std::string pname = fmt::format("polygons_{:06d}.vtu", count_);
                polygon::writePolygonVtu(dir_ / pname, p, time);
                polys_->add(time, pname);
            }
        }
        if (!w.walls.empty() || !w.surfaces.empty()) {
            const std::string wname = fmt::format("walls_{:06d}.vtp", count_);
            writeVtpShapes(dir_ / wname, wallShapes(w, time));
            walls_.add(time, wname);
        }
        ++count_;
    }

    /// The snapshot count and the collections' entries, for a checkpoint.
    void saveState(ByteWriter& out) const {
        out.put<std::int64_t>(count_);
        savePvd(out, pvd_);
        savePvd(out, walls_);
        savePvd(out, zones_);
        out.put<std::uint8_t>(polys_.has_value());
        if (polys_) savePvd(out, *polys_);
    }
    /// A resumed run's: the collections as they were at the checkpoint (their files rewritten); the snapshots the
    /// stopped run wrote after it are written again, under the same names.
    void loadState(ByteReader& in) {
        count_ = static_cast<int>(in.get<std::int64_t>());
        if (count_ < 0) in.fail("a negative snapshot count");
        loadPvd(in, pvd_);
        loadPvd(in, walls_);
        loadPvd(in, zones_);
        if (in.get<std::uint8_t>()) {
            if (!polys_) polys_.emplace(dir_ / "polygons.pvd");
            loadPvd(in, *polys_);
        }
    }

private:
    /// Zone labels as an image: label 0 event-driven, 1 time-driven (buffer), 2 dense; smoothed fraction phi.
    void writeZones(const HaetEngine<D>& h, double time) {
        const ZoneGrid<D>& z = h.zones();
        const int nz = z.count();
        std::vector<std::int32_t> label(nz);
        std::vector<double> phi(nz);
        for (int q = 0; q < nz; ++q) {
            label[q] = z.dense(q) ? 2 : (z.timeDriven(q) ? 1 : 0);
            phi[q] = z.smoothed(q);
        }
        std::array<int, 3> dims{1, 1, 1};
        std::array<double, 3> origin{0, 0, 0}, spacing{1, 1, 1};
        for (int k = 0; k < D; ++k) {
            dims[k] = z.dims()[k];
            origin[k] = z.origin()[k];
            spacing[k] = z.zoneWidth()[k];
        }
        const std::string name = fmt::format("zones_{:06d}.vti", count_);
        writeVtiCells(dir_ / name, dims, origin, spacing,
                      {{"label", 1, VtkField::Int32, label.data()}, {"phi", 1, VtkField::Float64, phi.data()}}, time);
        zones_.add(time, name);
    }

    std::filesystem::path dir_;
    PvdCollection pvd_, walls_, zones_;
    std::optional<PvdCollection> polys_;
    int count_ = 0;
};

/// The box of a run, as a picture frames it.
template <int D>
PictureBox pictureBox(const World<D>& w) {
    PictureBox b;
    b.dimension = D;
    b.lo = {0, 0, 0}, b.hi = {0, 0, 0};
    for (int k = 0; k < D; ++k) {
        b.lo[k] = w.domain.lo[k];
        b.hi[k] = w.domain.hi[k];
        b.gravity[k] = w.domain.gravity[k];
    }
    return b;
}

PictureOptions pictureOptions(const Scenario& sc) {
    return {sc.output.colorBy, sc.output.colorRange, sc.output.view, sc.output.pictureWidth};
}

std::vector<std::string> materialNames(const Scenario& sc) {
    std::vector<std::string> names;
    for (const MaterialDef& m : sc.materials) names.push_back(m.name);
    return names;
}

/// final.png: the last state, as the last snapshot holds it, drawn as [output] asks.
template <int D>
void writeFinalPicture(const Scenario& sc, const World<D>& w, const HaetEngine<D>* hybrid,
                       const std::filesystem::path& path) {
    PolygonOutlines polygons;
    if constexpr (D == 2)
        for (std::size_t i = 0; i < w.particles.size(); ++i)
            if (w.particles.isPolygon(i)) {
                polygons.id.push_back(static_cast<std::int64_t>(w.particles.id[i]));
                polygons.outline.push_back(polygon::worldOutline(w.particles, i));
            }
    writeFramePicture(path, snapshotFrame(w, w.time, hybrid), wallShapes(w, w.time), pictureBox(w), pictureOptions(sc),
                      materialNames(sc), &polygons);
}

template <int D>
RunStatus runWorld(const Scenario& sc, const RunOptions& opt, std::ostream& log) {
    const auto t0 = Clock::now();
    const std::filesystem::path dir = !opt.resumeDir.empty() ? opt.resumeDir
                                      : opt.outDir.empty()   ? std::filesystem::path(sc.output.directory)
                                                             : opt.outDir;

    // A resumed run starts from the newest whole checkpoint of its directory: the World built from the scenario
    // (box, walls, contact table) takes the saved particles, the engine is made on them and takes its own state.
    std::optional<ResumePoint> resume;
    if (!opt.resumeDir.empty()) resume = findCheckpoint(dir, sc, log);
    World<D> world = buildWorld<D>(sc);
    if (resume) {
        ByteReader in = resume->file.section("WRLD");
        loadWorld(in, world);
        in.expectEnd();
    }
    StopSignals signals;
    std::unique_ptr<Driver<D>> eng = makeDriver<D>(sc, world, signals.flag());
    if (resume) {
        if (!eng->restartable())
            throw std::invalid_argument(std::string("--resume: runs of method \"") + eng->method() +
                                        "\" cannot be resumed yet");
        eng->loadState(resume->file);
    }
    const RunPlan plan = planRun(sc, eng->dt(), world.contact.contactTime);
    for (const auto& [key, what] : plan.warnings) log << "warning: " << key << ": " << what << "\n";

    if (!resume) prepareRunDirectory(dir);
    std::vector<std::string> columns = {
        "time",         "step",        "kinetic_energy", "rotational_energy", "potential_energy", "elastic_energy",
        "total_energy", "n_particles", "n_contacts",     "max_overlap_ratio", "pressure"};
    for (auto& c : eng->extraColumns()) columns.push_back(c);
    Flow<D> flow(sc, world, eng->stepTime());
    if (resume) {
        ByteReader in = resume->file.section("FLOW");
        flow.loadState(in);
    }
    for (auto& c : flow.columns()) columns.push_back(c);
    // Fields, stress tensors, the contact network (run/measures.hpp), fed by the engine's hooks.
    Measures<D> measures(sc, world, dir, plan.snapshotPeriod);
    for (auto& c : measures.columns()) columns.push_back(c);
    eng->setCollisionHook([&measures](const EdmCollision<D>& c) { measures.collision(c); });
    auto contactsNow = [&] { return measures.wantsContacts() && eng->contactsRecordedAt() == world.time; };
    double lastRowTime = world.time;
    auto rowValues = [&](double stamp) {
        const Energies<D> e = energies(world);
        const double elastic = eng->elasticEnergy();
        const double window = world.time - lastRowTime;
        lastRowTime = world.time;
        std::optional<double> pressure;
        const double vir = eng->virial(window);
        if (world.domain.fullyPeriodic()) pressure = (e.mv2 + vir) / (D * world.domain.volume());
        std::vector<std::optional<double>> row = {stamp,
                                                  double(eng->steps()),
                                                  e.kinetic,
                                                  e.rotational,
                                                  e.potential,
                                                  elastic,
                                                  e.kinetic + e.rotational + e.potential + elastic,
                                                  double(world.particles.size()),
                                                  double(eng->contacts()),
                                                  eng->maxOverlapRatio(),
                                                  pressure};
        for (auto& v : eng->extraRow()) row.push_back(v);
        for (auto& v : flow.row(world.time)) row.push_back(v);
        for (auto& v : measures.row(world, contactsNow(), window)) row.push_back(v);
        return row;
    };

    struct {
        std::uint64_t written = 0, bytes = 0;
        double seconds = 0;  // wall time spent making and writing them [s]
    } ckptBook;
    auto writeRunJson = [&](const std::string& status) {
        const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
        JsonObject j;
        j.add("version", kVersion);
        j.add("scenario", sc.path);
        j.add("scenario_name", sc.name);
        j.add("scenario_hash", sc.hash);
        if (!sc.overrides.empty()) {  // --set KEY=VALUE, applied to the file in this order
            JsonObject o;
            for (const std::string& kv : sc.overrides) o.add(kv.substr(0, kv.find('=')), kv.substr(kv.find('=') + 1));
            j.add("overrides", o);
        }
        j.add("method", eng->method());
        if (resume) {  // the checkpoint this run went on from
            j.add("resumed_from", resume->path.filename().string());
            j.add("resumed_at", resume->file.header.time);
        }
        j.add("dimension", static_cast<std::int64_t>(D));
        {  // what `haet render` needs besides the snapshots: the box, the materials' names, the picture's settings
            const PictureBox box = pictureBox(world);
            JsonObject d, pic;
            d.add("lo", std::vector<double>(box.lo.begin(), box.lo.begin() + D));
            d.add("hi", std::vector<double>(box.hi.begin(), box.hi.begin() + D));
            d.add("gravity", std::vector<double>(box.gravity.begin(), box.gravity.begin() + D));
            j.add("domain", d);
            j.add("materials", materialNames(sc));
            const PictureOptions po = pictureOptions(sc);
            pic.add("color_by", po.colorBy);
            if (po.range) pic.add("color_range", std::vector<double>(po.range->begin(), po.range->end()));
            pic.add("view", std::vector<double>(po.view.begin(), po.view.end()));
            pic.add("width", static_cast<std::int64_t>(po.widthPx));
            j.add("picture", pic);
        }
        j.add("status", status);
        j.add("n_particles", world.particles.size());
        j.add("contact_time", world.contact.contactTime);
        j.add("simulated_time", world.time);
        j.add("steps", eng->steps());
        eng->describe(j);
        flow.describe(j);
        if (!plan.warnings.empty()) {  // what the run warned of on stderr, by the key concerned
            JsonObject w;
            for (const auto& [key, what] : plan.warnings) w.add(key, what);
            j.add("warnings", w);
        }
        if (ckptBook.written > 0) {  // what the checkpoints of this run cost: their count, last size, time
            JsonObject c;
            c.add("written", ckptBook.written);
            c.add("last_bytes", ckptBook.bytes);
            c.add("seconds", ckptBook.seconds);
            j.add("checkpoints", c);
        }
        j.add("wall_time", wall);
        j.add("particle_steps_per_second", wall > 0 ? double(eng->steps()) * world.particles.size() / wall : 0.0);
        j.add("threads", static_cast<std::int64_t>(omp_get_max_threads()));
        j.add("peak_rss_bytes", peakRssBytes());
        writeFileAtomic(dir / "run.json", j.dump() + "\n");
    };
    // A resumed run's series.csv as the stopped run left it, read before it is rewritten.
    std::string savedSeries = resume ? readFileText(dir / "series.csv") : std::string();
    // A run killed before its end (kill -9, a node lost) leaves run.json saying so; it also proves the directory
    // writable before any time is spent.
    writeRunJson("running");
    SeriesWriter series(dir / "series.csv", columns);
    SnapshotWriter<D> snaps(dir);

    const bool tty = opt.progress == ProgressDisplay::On ||
                     (opt.progress == ProgressDisplay::Auto && !opt.quiet && isatty(STDERR_FILENO));
    Progress progress(tty, sc.duration);
    const double eps = eng->timeTolerance();
    OutputClock rows(plan.seriesPeriod), shots(plan.snapshotPeriod), ckpts(sc.output.checkpointPeriod);
    // The engine is called in the same pieces whether or not the progress line shows (an event-driven engine's
    // state depends on where its calls end): up to every output time and every 1/500 of the run, at which the
    // progress line may update (at most every 200 ms).
    OutputClock chunks(sc.duration / 500);
    double lastRow = -1, lastShot = -1;  // engine times of the last row and snapshot written
    double lastCheckpoint = -1;          // engine time of the last checkpoint
    std::uint64_t sequence = 0;          // of the last checkpoint written
    if (resume) {
        // The outputs as they were when the checkpoint was written: series.csv up to its rows (a stopped run's
        // last-state row after it is not the schedule's), the collections' entries; the clocks from the times of
        // the last outputs, so that periods changed on resume take effect from here.
        ByteReader in = resume->file.section("RUN ");
        sequence = in.get<std::uint64_t>();
        lastRow = in.get<double>();
        lastShot = in.get<double>();
        lastRowTime = in.get<double>();
        const SeriesMark mark = loadSeriesMark(in);
        snaps.loadState(in);
        in.expectEnd();
        ByteReader meas = resume->file.section("MEAS");
        measures.loadState(meas);
        meas.expectEnd();
        series.resume(seriesAtCheckpoint(std::move(savedSeries), mark, series.path(), resume->path), mark.rows);
        if (lastRow >= 0) rows.pass(lastRow, eps);
        if (lastShot >= 0) shots.pass(lastShot, eps);
        ckpts.pass(world.time, eps);
        lastCheckpoint = world.time;
        log << "resuming from " << resume->path.string() << " at t = " << world.time << " s\n";
    }
    auto row = [&](double stamp) {
        eng->synchronise();
        series.row(rowValues(stamp));
        lastRow = world.time;
    };
    auto shot = [&](double stamp) {
        eng->synchronise();
        snaps.write(world, stamp, eng->hybrid());
        measures.snapshot(world, stamp, contactsNow());
        series.flush();
        lastShot = world.time;
    };
    // A checkpoint: the whole state at world.time and the outputs written so far (series.csv flushed first, so
    // that the file on disk always holds at least the rows a checkpoint counts).
    const bool checkpoints = eng->restartable();
    if (!checkpoints && sc.output.checkpointPeriod > 0)
        log << "warning: output.checkpoint_period: runs of method \"" << eng->method()
            << "\" write no checkpoints yet\n";
    auto checkpoint = [&] {
        if (!checkpoints) return;
        const auto start = Clock::now();
        eng->exposeState();
        series.flush();
        ByteWriter body;
        body.beginSection("SCEN");
        body.putString(sc.stateKeys);
        body.endSection();
        body.beginSection("WRLD");
        saveWorld(body, world);
        body.endSection();
        body.beginSection("ENGN");
        eng->saveState(body);
        body.endSection();
        body.beginSection("FLOW");
        flow.saveState(body);
        body.endSection();
        body.beginSection("MEAS");
        measures.saveState(body);
        body.endSection();
        body.beginSection("RUN ");
        body.put<std::uint64_t>(sequence + 1);
        body.put<double>(lastRow);
        body.put<double>(lastShot);
        body.put<double>(lastRowTime);
        saveSeriesMark(body, series);
        snaps.saveState(body);
        body.endSection();
        CheckpointHeader h;
        h.dimension = D;
        h.method = eng->method();
        h.scenarioHash = sc.stateHash;
        h.time = world.time;
        h.sequence = ++sequence;
        const std::string file = encodeCheckpoint(h, body.bytes());
        writeCheckpoint(dir, sequence, file);
        lastCheckpoint = world.time;
        ckptBook.written += 1;
        ckptBook.bytes = file.size();
        ckptBook.seconds += std::chrono::duration<double>(Clock::now() - start).count();
    };
    RunStatus status = RunStatus::Completed;
    std::string statusText = "completed";
    try {
        for (;;) {
            if (rows.due(world.time, eps)) {
                row(OutputClock::stamp(world.time, rows.next()));
                rows.pass(world.time, eps);
            }
            if (shots.due(world.time, eps)) {
                shot(OutputClock::stamp(world.time, shots.next()));
                shots.pass(world.time, eps);
            }
            if (measures.nextTime() <= world.time + eps) {
                eng->synchronise();
                measures.sample(world, contactsNow(), eps);
            }
            if (ckpts.due(world.time, eps)) {
                if (lastCheckpoint != world.time) checkpoint();
                ckpts.pass(world.time, eps);
            }
            if (world.time + eps >= sc.duration || signals.requested()) break;
            // Inlets and outlets act at their own times (Flow::nextTime), between the engine's calls.
            const double target =
                std::min({sc.duration, rows.next(), shots.next(), ckpts.next(), flow.nextTime(), measures.nextTime()});
            // The force pass that ends at the next output records its contacts for the measurements.
            if (measures.wantsContacts()) eng->recordContactsAt(measures.sink(), target);
            while (chunks.due(world.time, eps)) chunks.pass(world.time, eps);
            eng->advanceTo(chunks.next() < target - eps ? chunks.next() : target);
            if (world.time + eps >= flow.nextTime()) flow.act(world, *eng, eps);
            progress.update(world.time, eng->steps(), eng->contacts());
        }
    } catch (const SimulationError& e) {
        progress.finish();
        log << "error: simulation stopped: " << e.what() << "\n";
        status = RunStatus::BlewUp;
        statusText = std::string("failed: ") + e.what();
    } catch (const IoError& e) {
        // Disk full, directory gone: every file on disk is still a whole one (atomic writes); say so in run.json
        // if that still can be written.
        progress.finish();
        try {
            writeRunJson(std::string("failed: output: ") + e.what());
        } catch (const IoError&) {
        }
        throw;
    }
    if (signals.requested()) {
        status = signals.signal() == SIGINT ? RunStatus::Interrupted : RunStatus::Terminated;
        statusText = "interrupted";
        log << (signals.signal() == SIGINT ? "\nSIGINT" : "\nSIGTERM") << ": stopped at t = " << world.time
            << " s; writing the last state\n";
    }
    // The last state, always: a checkpoint (before the last row and snapshot, which are not the schedule's: a
    // resumed run drops them), then a row and a snapshot at the time the run ended, unless the schedule just wrote
    // them. A blown-up state is not checkpointed: the last checkpoint stays the newest.
    try {
        if (status != RunStatus::BlewUp && lastCheckpoint != world.time) checkpoint();
        if (lastRow != world.time) row(OutputClock::stamp(world.time, sc.duration));
        if (lastShot != world.time) shot(OutputClock::stamp(world.time, sc.duration));
    } catch (const SimulationError& e) {  // a blown-up state the engine cannot bring to one time
        log << "error: the last state cannot be written: " << e.what() << "\n";
    }
    progress.update(world.time, eng->steps(), eng->contacts(), true);
    progress.finish();
    series.flush();
    // The state for a next stage (run/export.hpp): disks and spheres, unless the run blew up.
    if (status != RunStatus::BlewUp && !world.particles.hasPolygons() && world.particles.hasMotion()) {
        writeStateCsv(dir / "final.csv", world, sc.materials);
        writeLammpsData(dir / "final.data", world, sc.materials);
    }
    writeRunJson(statusText);
    writeFinalPicture(sc, world, eng->hybrid(), dir / "final.png");
    if (!opt.quiet) {
        const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
        log << fmt::format("{} ({}): {} particles, simulated {:.4g} s in {:.2f} s wall time; outputs in {}\n", sc.name,
                           eng->method(), world.particles.size(), world.time, wall, dir.string());
    }
    return status;
}

}  // namespace

RunStatus runScenario(const Scenario& sc, const RunOptions& opt, std::ostream& log) {
    if (opt.threads > 0) omp_set_num_threads(opt.threads);
    return sc.dimension == 2 ? runWorld<2>(sc, opt, log) : runWorld<3>(sc, opt, log);
}

}  // namespace haet
