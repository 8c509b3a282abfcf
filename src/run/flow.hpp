#pragma once
// Particles that come and go during a run (docs/physics.md K): inlets that insert particles in batches at a rate,
// outlets that remove the particles whose centre enters their region, and their books (series.csv, run.json).
// The run loop (run/runner.cpp) asks Flow when it must act next and lets it act there, through the engine's
// FlowHost; Flow itself knows no engine.
#include <cstdint>
#include <iosfwd>
#include <limits>
#include <optional>
#include <string>
#include <unordered_set>
#include <vector>

#include "core/rng.hpp"
#include "io/checkpoint.hpp"
#include "io/json.hpp"
#include "scenario/definition.hpp"
#include "scenario/insert.hpp"
#include "tdm/engine.hpp"
#include "world/world.hpp"

namespace haet {

/// What an engine lets the flows do to its particles, at world.time (a step boundary).
template <int D>
class FlowHost {
public:
    virtual ~FlowHost() = default;
    /// Particles [0, eager()) are current in the World after every step (time-driven); the others only after
    /// synchronise() (event-driven). A pure time-driven run: all, a pure event-driven run: none.
    virtual std::size_t eager() const = 0;
    /// Brings every particle to world.time in the World.
    virtual void synchronise() = 0;
    /// Removes World particles `which` (ascending, distinct); the store shrinks by which.size().
    virtual void remove(const std::vector<std::uint32_t>& which) = 0;
    /// Particles [first, size()) were appended to the World (after synchronise()): the engine takes them.
    virtual void added(std::size_t first) = 0;
};

/// What one inlet or outlet moved so far.
struct FlowCount {
    std::uint64_t particles = 0;
    double mass = 0;  ///< [kg] (2D: kg per unit depth)
};

template <int D>
class Flow {
public:
    /// dt: the time-driven step [s] (outlets check the time-driven particles after every step); 0 for a pure
    /// event-driven run. The ids of new particles continue after the largest id in the World.
    Flow(const Scenario& sc, const World<D>& world, double dt);

    bool empty() const { return sc_.inlets.empty() && sc_.outlets.empty(); }
    /// n ids for particles added from outside (a script's Simulation.add_particles): the first of n consecutive
    /// ones from the counter the inlets draw from, so that no two particles of a run ever share an id.
    std::uint64_t takeIds(std::uint64_t n) {
        const std::uint64_t first = nextId_;
        nextId_ += n;
        return first;
    }
    /// How many ids outlet k (a counter) remembers as counted: at most the particles in the run.
    std::size_t remembered(std::size_t k) const { return outlets_[k].seen.size(); }
    /// The next time at which act() has work [s] (infinity: none).
    double nextTime() const;
    /// Does what is due at world.time (to within tol [s]): outlet checks, inlet batches.
    void act(World<D>& world, FlowHost<D>& host, double tol);

    /// series.csv: per inlet NAME_particles, NAME_mass, NAME_shortfall; per outlet NAME_particles, NAME_mass,
    /// NAME_rate (the mass it removed since the row before over the time since then [kg/s]: a discharge rate).
    std::vector<std::string> columns() const;
    /// The row at `time` [s]; rows come in time order.
    std::vector<std::optional<double>> row(double time);
    /// run.json: "flows": the initial count and each inlet's and outlet's totals.
    void describe(JsonObject& j) const;

    /// The books and the inlets' places in their random streams and schedules, for a checkpoint; load into a Flow
    /// made from the same scenario. Throws CheckpointError (Corrupt) when the saved inlets and outlets do not fit.
    void saveState(ByteWriter& out) const;
    void loadState(ByteReader& in);

private:
    struct Inlet {
        const InletDef* def;
        Rng rng;
        double next = 0;                      // time of the next batch [s]
        std::vector<NewParticle<D>> pending;  // due, not placed yet (the shortfall)
        std::optional<NewParticle<D>> drawn;  // drawn, not due yet (mass rates: its mass decides when)
        std::uint64_t batches = 0;            // batches made
        std::uint64_t drawnCount = 0;         // particles that fell due so far
        double drawnMass = 0;                 // [kg]
        FlowCount in;
    };
    struct Outlet {
        const OutletDef* def;
        FlowCount out;
        double massAtRow = 0;                    // out.mass at the last row [kg]
        std::unordered_set<std::uint64_t> seen;  // a counter's: the ids it counted (ids are never reused)
    };
    bool inside(const OutletDef& o, const Vec<D>& x) const;
    void batch(World<D>& world, Inlet& in);

    const Scenario& sc_;
    double dt_;
    double time_ = 0;                                            // world.time at the last act() [s]
    double rowTime_ = std::numeric_limits<double>::quiet_NaN();  // time of the last series row [s]
    std::uint64_t nextId_ = 0;
    std::uint64_t initial_ = 0;
    double lazyInterval_ = std::numeric_limits<double>::infinity();  // the smallest of the outlets' intervals [s]
    double nextLazy_ = 0;                                            // next check of the event-driven particles [s]
    std::vector<Inlet> inlets_;
    std::vector<Outlet> outlets_;
};

/// Removes World particles `which` (ascending, distinct) from the store: each exchanges places with the last
/// particle, which then leaves (Particles::popBack). The ids of the others stay.
template <int D>
void dropParticles(Particles<D>& p, const std::vector<std::uint32_t>& which);
/// The same in a pure time-driven run, whose engine then follows (TdmEngine::remap: the remaining particles keep
/// their contact and integrator history).
template <int D>
void removeTimeDriven(World<D>& w, TdmEngine<D>& eng, const std::vector<std::uint32_t>& which);
/// Particles [first, size()) were appended: the time-driven engine takes them (TdmEngine::kFresh).
template <int D>
void addTimeDriven(World<D>& w, TdmEngine<D>& eng, std::size_t first);

/// The largest radius an inlet of the scenario can insert [m] (0: none).
double inletRadiusBound(const Scenario& sc);

/// `haet check`: the size distribution of every insert and inlet (mean and d50 by number and by mass), and the
/// inlets and outlets.
void describeFlows(const Scenario& sc, std::ostream& out);

extern template class Flow<2>;
extern template class Flow<3>;

}  // namespace haet
