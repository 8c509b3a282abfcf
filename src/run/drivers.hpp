#pragma once
// The engines as the run loop sees them: one Driver per method (time-driven, event-driven, hybrid) gives the loop
// the same calls (advance, synchronise, the series' columns, checkpoints) and lets the inlets and outlets add and
// remove particles (FlowHost). Used by run/session.cpp only.
#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "edm/engine.hpp"
#include "haet/engine.hpp"
#include "io/checkpoint.hpp"
#include "io/json.hpp"
#include "run/flow.hpp"
#include "run/walls_output.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world/state.hpp"

namespace haet {

template <int D>
struct Energies {
    double kinetic = 0, rotational = 0, potential = 0;
    double mv2 = 0;   ///< sum m v^2 [J], for the kinetic pressure
    Vec<D> momentum;  ///< sum m v [kg m/s]
};

/// The energies of particles [0, n) (default: all; across ranks, a rank's own).
template <int D>
Energies<D> energies(const World<D>& w, std::size_t n = static_cast<std::size_t>(-1)) {
    const Particles<D>& p = w.particles;
    Energies<D> s;
    for (std::size_t i = 0; i < std::min(n, p.size()); ++i) {
        const double m = p.mass[i];
        const double v2 = norm2(p.v[i]);
        s.kinetic += 0.5 * m * v2;
        s.mv2 += m * v2;
        s.momentum += p.v[i] * m;
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
    virtual double dt() const = 0;            ///< time step [s] (0 for a pure event-driven run)
    virtual std::uint64_t steps() const = 0;  ///< time steps taken (0 for a pure event-driven run)
    /// Particles [0, owned()) of the World are this rank's (across ranks: the rest are ghosts); one process: all.
    virtual std::size_t owned() const { return static_cast<std::size_t>(-1); }
    virtual std::size_t contacts() const = 0;  ///< enduring contacts now
    /// Across ranks, this rank's share of them (TdmEngine::contactShare); one process: contacts().
    virtual double contactShare() const { return static_cast<double>(contacts()); }
    /// Across ranks: the particles this rank handed to another so far (0 in one process).
    virtual double migrated() const { return 0; }
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
    /// The contacts of the state at the start into *sink (TdmEngine::recordStartContacts): whether it could.
    virtual bool recordStartContacts(ContactSink<D>*) { return false; }
    virtual double contactsRecordedAt() const { return -1; }
    virtual void setCollisionHook(std::function<void(const EdmCollision<D>&)>) {}
    /// The World's particles (in place, same count) or gravity were changed from outside, at world.time after
    /// synchronise(): the engine starts again from them. Throws std::invalid_argument if it cannot.
    virtual void stateChanged() = 0;
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
    TdmDriver(World<D>& w, const TdmSettings& s, std::string dtNote)
        : w_(w), eng_(w, s), note_(std::move(dtNote)), ranks_(s.ranks && s.ranks->size() > 1 ? s.ranks : nullptr) {}
    const char* method() const override { return "tdm"; }
    std::size_t owned() const override { return eng_.owned(); }
    void advanceTo(double t) override { eng_.advanceTo(t); }
    double timeTolerance() const override { return 0.5 * eng_.settings().dt; }
    double dt() const override { return eng_.settings().dt; }
    std::uint64_t steps() const override { return eng_.steps(); }
    std::size_t contacts() const override { return eng_.forceStats().contacts; }
    double contactShare() const override { return eng_.contactShare(); }
    double migrated() const override { return static_cast<double>(eng_.migrated()); }
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
        if (ranks_) {  // the walls' loads are sums over the particles, every rank its own (the rebuilds agree)
            std::vector<double> v;
            for (std::size_t k = 1; k < r.size(); ++k) v.push_back(r[k].value_or(0));
            ranks_->sum(v);
            for (std::size_t k = 1; k < r.size(); ++k)
                if (r[k]) r[k] = v[k - 1];
        }
        return r;
    }
    void describe(JsonObject& j) const override {
        j.add("dt", eng_.settings().dt);
        j.add("dt_rule", note_);
        j.add("neighbor_rebuilds", eng_.rebuilds());
        if (const Slabs* s = eng_.slabs()) {
            JsonObject d;
            d.add("ranks", static_cast<std::int64_t>(s->ranks()));
            d.add("axis", static_cast<std::int64_t>(s->axis));
            d.add("cuts", s->cut);
            d.add("rebalances", eng_.rebalances());
            j.add("decomposition", d);
        }
    }
    const TdmEngine<D>& engine() const { return eng_; }
    double stepTime() const override { return eng_.settings().dt; }
    std::size_t eager() const override { return w_.particles.size(); }
    void synchronise() override {}
    void remove(const std::vector<std::uint32_t>& which) override { removeTimeDriven(w_, eng_, which); }
    void added(std::size_t first) override { addTimeDriven(w_, eng_, first); }
    void stateChanged() override { eng_.restart(); }
    bool restartable() const override { return true; }
    void saveState(ByteWriter& out) const override { eng_.saveState(out); }
    void loadState(const CheckpointFile& f) override { loadEngineState(f, w_, eng_); }
    void recordContactsAt(ContactSink<D>* s, double t) override { eng_.recordContactsAt(s, t); }
    bool recordStartContacts(ContactSink<D>* s) override { return eng_.recordStartContacts(s); }
    double contactsRecordedAt() const override { return eng_.contactsRecordedAt(); }

private:
    World<D>& w_;
    TdmEngine<D> eng_;
    std::string note_;
    Ranks* ranks_;  ///< across ranks; null in one process
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
    void stateChanged() override { eng_.restart(); }
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
        : w_(w), eng_(w, ts, es, hs), note_(std::move(dtNote)) {}
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
    bool recordStartContacts(ContactSink<D>* s) override { return eng_.recordStartContacts(s); }
    double contactsRecordedAt() const override { return eng_.tdm().contactsRecordedAt(); }
    void setCollisionHook(std::function<void(const EdmCollision<D>&)> f) override {
        eng_.setCollisionHook(std::move(f));
    }
    // Its split into modes, guard cells and two engines' books follow the particles; a change in place is not
    // followed yet (the flows' removal and addition are).
    void stateChanged() override {
        throw std::invalid_argument("hybrid runs take no change of their particles in place yet");
    }
    bool restartable() const override { return eng_.restartable(); }
    void saveState(ByteWriter& out) const override { eng_.saveState(out); }
    /// The engine loads the World itself, before and after it makes its engines anew (HaetEngine::loadState).
    void loadState(const CheckpointFile& f) override {
        ByteReader in = f.section("ENGN");
        eng_.loadState(in, [&] {
            ByteReader world = f.section("WRLD");
            loadWorld(world, w_);
        });
        in.expectEnd();
    }

private:
    World<D>& w_;
    HaetEngine<D> eng_;
    std::string note_;
};

template <int D>
std::unique_ptr<Driver<D>> makeDriver(const Scenario& sc, World<D>& world, const std::atomic<bool>* stop,
                                      Ranks* ranks = nullptr) {
    switch (sc.method) {
        case Method::Tdm: {
            std::string note;
            TdmSettings ts = tdmSettings<D>(sc, world, &note);
            ts.stop = stop;
            ts.ranks = ranks;
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

}  // namespace haet
