#pragma once
// The hybrid (docs/physics.md A, docs/haet.md): time-driven DEM where the flow is dense, event-driven dynamics where it
// is dilute, on one particle store. Particles [0, tdmCount()) are the time-driven engine's, the rest the
// event-driven engine's; a particle changes mode by exchanging places with the first (or last) particle of the
// other range, so a mode change costs O(1) in the store plus a pair-list rebuild, never a copy of the system.
//
// One step: the event-driven engine processes its events up to the step's end, the time-driven engine takes its
// step, then particles change mode where the rules say so. The event-driven particles keep their own clocks and
// are brought to the common time only when they change mode or are written out.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "edm/engine.hpp"
#include "haet/edm_book.hpp"
#include "haet/wall_guard.hpp"
#include "haet/zones.hpp"
#include "neighbor/cell_grid.hpp"
#include "tdm/engine.hpp"
#include "world/world.hpp"

namespace haet {

struct HaetSettings {
    ZoneSettings zones;      ///< zone edge, phi_on / phi_off, buffer (docs/physics.md A.2)
    int relabelEvery = 50;   ///< zones are re-labelled, and particles change mode, every this many steps [steps];
                             ///< the guard follows the TDM particles at every pair-list build
    int diluteSteps = 20;    ///< a time-driven particle without contacts returns to EDM once its zone has been
                             ///< event-driven this long [steps]
    double dtMin = 0;        ///< modified EDM (A.4): a collision within dtMin of the particle's previous one hands
                             ///< both particles to the TDM [s]; 0: the contact duration
    double radiusBound = 0;  ///< the largest radius of particles added later (inlets) [m]; 0: those at the start
    /// Set from outside (a signal handler: run/stop.hpp) to end advanceTo after the step under way; null: never.
    const std::atomic<bool>* stop = nullptr;
};

/// Where the energy went, since the start [J]. Potential energy is that of gravity, -m g.x (unwrapped x).
struct HaetEnergy {
    double initial = 0;        ///< total energy at the start (kinetic + rotational + potential + contacts)
    double dissipatedTdm = 0;  ///< lost in time-driven contacts (the TDM particles' energy balance)
    double dissipatedEdm = 0;  ///< lost in event-driven collisions (summed at each collision)
    double total = 0;          ///< total energy now
    double inflow = 0;         ///< brought by particles that were added (inlets), at their birth
    double outflow = 0;        ///< taken away by particles that were removed (outlets), their contacts' included
    /// initial + inflow - outflow - total - dissipatedTdm - dissipatedEdm: what neither engine accounts for
    /// (round-off). A moving wall's work is in the dissipation of the engine whose particles it touches
    /// (dissipatedTdm is a balance, dissipatedEdm sums each collision's loss, a moving plane's work included;
    /// docs/haet.md).
    double unaccounted = 0;
};

struct HaetCounters {
    std::uint64_t toTdm = 0, toEdm = 0;  ///< mode changes
    std::uint64_t tcHandovers = 0;       ///< particles handed to the TDM by the modified EDM (A.4)
    std::uint64_t nearTdm = 0;           ///< event-driven particles that came within reach of a TDM particle
    std::uint64_t nearWall = 0;  ///< event-driven particles that came within reach of a wall the EDM does not predict
    std::uint64_t relabels = 0;  ///< zone relabellings
};

template <int D>
class HaetEngine {
public:
    /// Labels the zones, splits the particles and builds both engines at world.time. The time step is the TDM's.
    HaetEngine(World<D>& world, const TdmSettings& tdm, EdmSettings edm, const HaetSettings& hs);
    ~HaetEngine();

    /// One time step of the whole system (events up to its end, one TDM step, mode changes).
    void step();
    /// Steps until the time reaches t (to within half a step).
    void advanceTo(double t);
    /// Brings the event-driven particles to world.time in the World (for outputs).
    void synchronise();

    std::size_t nTdm() const { return w_.particles.tdmCount(); }
    std::size_t nEdm() const { return w_.particles.size() - nTdm(); }
    std::uint64_t steps() const { return steps_; }
    std::uint64_t events() const { return edm_->events(); }
    std::uint64_t collisions() const { return edm_->collisions(); }
    const HaetCounters& counters() const { return counters_; }
    /// The event-driven collisions' virial since the last call (EdmEngine::takeCollisionVirial) [J].
    double takeCollisionVirial() { return edm_->takeCollisionVirial(); }
    /// Energy accounting at world.time (call synchronise() first).
    HaetEnergy energy() const;

    const TdmEngine<D>& tdm() const { return *tdm_; }
    const EdmEngine<D>& edm() const { return *edm_; }
    /// The measurements' hooks (run/measures.hpp): the time-driven contacts of the step ending at t
    /// (TdmEngine::recordContactsAt), every event-driven collision (EdmEngine::setObserver).
    void recordContactsAt(ContactSink<D>* sink, double t) { tdm_->recordContactsAt(sink, t); }
    bool recordStartContacts(ContactSink<D>* sink) { return tdm_->recordStartContacts(sink); }
    void setCollisionHook(std::function<void(const EdmCollision<D>&)> f) { edm_->setObserver(std::move(f)); }
    const ZoneGrid<D>& zones() const { return zones_; }
    const HaetSettings& settings() const { return hs_; }
    double dtMin() const { return edm_->tcTime(); }
    double dt() const { return ts_.dt; }

    // ---- particles that come and go (run/flow.hpp; haet/flow.cpp, docs/haet.md "Inlets and outlets") ----
    /// Removes World particles `which` (ascending, distinct; either mode) at world.time; the others keep their
    /// state, the store shrinks by which.size() (the removed ones are exchanged with the last ones first).
    void removeParticles(const std::vector<std::uint32_t>& which);
    /// Particles [first, size()) were appended to the World at world.time (synchronise() first): each is born in
    /// the mode of its zone, time-driven in a time-driven zone, event-driven elsewhere.
    void addParticles(std::size_t first);

    /// Sets particle modes by hand (tests): toTdm / toEdm list World indices; rules apply again at the next
    /// relabel unless freezeModes(true).
    void forceModes(const std::vector<std::uint32_t>& toTdm, const std::vector<std::uint32_t>& toEdm);
    /// Switches the automatic mode changes off (tests of a fixed split) or on.
    void freezeModes(bool on) { frozenModes_ = on; }
    // ---- checkpoints (haet/state.cpp; ARCHITECTURE.md, "Checkpoints") ----
    /// Whether saveState can hold the whole state (that of the event-driven engine included).
    bool restartable() const { return edm_->restartable(); }
    /// Between steps: what the construction resolved from the particles at the start (zone edge, event-grid
    /// edge, largest radius, skin), the zones' labels, the guard with its bins and near grid, the wall guard's
    /// cells, the watch list, the per-zone step marks, counters and energy books, then both engines' states and the
    /// book of the event-driven particles.
    void saveState(ByteWriter& out) const;
    /// Replaces the state with a saved one, in an engine made for the same scenario. reloadWorld puts the
    /// checkpoint's particles into the World: called first, and again after the engines are made anew on them with
    /// the saved configuration (making them sorts and wraps the store). Throws CheckpointError (Corrupt) for a state
    /// that does not fit.
    void loadState(ByteReader& in, const std::function<void()>& reloadWorld);

    /// The guard's invariant (tests): event-driven particles in guard cells that are not watched. Zero always,
    /// or such a particle could touch a TDM particle unnoticed. O(N log N).
    std::size_t unwatchedInGuard() const;

private:
    struct Binned {  // a TDM particle as seen by the guard: position at the last relabel, radius, next in cell
        Vec<D> x;
        double r;
        std::uint32_t next;      // in its event-grid cell
        std::uint32_t nextNear;  // in its cell of the near grid
    };
    /// A grid of edge >= largest diameter + margin over the binned TDM particles, for gapToTdm: the event grid's
    /// cells may be much larger. Open axes span the binned particles (others fall into the outer cells),
    /// periodic ones the box.
    struct NearGrid {
        CellGrid<D> grid;  // points beyond a periodic face wrap, beyond an open one they fall into the outer cells
        std::vector<std::uint32_t> head;
        bool valid = false;
    };
    /// The near grid over the current bins, with every bin in it; later bins go in as they come.
    void buildNearGrid();
    /// The guard and bins from the current TDM positions; on due steps also the zone labels and the mode changes
    /// they imply (urgent hand-overs always).
    void relabel(std::vector<std::uint32_t> arrivals, bool due);
    void checkWatched(std::vector<std::uint32_t>& arrivals, bool due);
    void convert(std::vector<std::uint32_t> arrivals, std::vector<std::uint32_t> departures);
    /// The default edge of the event grid's cells, for particles [nT, size()) event-driven [m].
    double eventCellEdge(std::size_t nT) const;
    void bin(const Vec<D>& x, double r);
    /// The 3^D cells around `cell` get at least guard `level` (new-level bits during a relabel); occupants of a
    /// cell that became stricter are watched.
    void markAround(std::uint32_t cell, std::uint8_t level);
    /// Smallest gap between a sphere (x, r) and the binned TDM particles within the margin (one at x itself
    /// excluded); infinity if none.
    /// bound (if given): a lower bound of the gap to every binned TDM particle, also those beyond the margin.
    double gapToTdm(const Vec<D>& x, double r, double* bound = nullptr) const;
    /// The walls the event-driven engine does not predict (WallGuard): their cells guarded at level 1 at least,
    /// binned anew on due steps.
    void guardWalls(bool due);
    /// Whether a particle (centre x in event-grid cell `cell`, radius r, speed [m/s]) near such a wall is to be
    /// time-driven: its gap to the wall could close before the next due step, or (due) it is within the margin.
    bool nearGuardedWall(std::uint32_t cell, const Vec<D>& x, double r, double speed, bool due) const;
    double particleEnergy(std::size_t i) const;
    double tdmEnergy() const;

    World<D>& w_;
    TdmSettings ts_;
    HaetSettings hs_;
    ZoneGrid<D> zones_;
    // guard over the event grid: 0 free, 1 near a TDM particle (watched), 2 inside a time-driven zone
    std::vector<std::uint8_t> guard_;
    EdmBook<D> book_;  // where the event-driven particles are (the event-driven engine's observer)
    std::unique_ptr<EdmEngine<D>> edm_;
    std::unique_ptr<TdmEngine<D>> tdm_;

    std::vector<std::uint32_t> guardList_, newList_;
    std::vector<std::uint32_t> binHead_, binCells_;
    std::vector<Binned> bins_;
    NearGrid near_;
    WallGuard<D> walls_;  // the walls the event-driven engine leaves to the time-driven one
    double rmax_ = 0;
    std::vector<std::uint32_t> watch_;  // event-driven particles in guard cells (World indices)
    std::size_t watchSorted_ = 0;       // watch_[0, watchSorted_) is sorted and unique
    // A watched particle whose gap to the bins cannot reach the margin before `until` (World index; valid while
    // the bins' epoch and the particle's collision count are unchanged).
    struct Quiet {
        double until = 0;
        std::uint32_t collisions = 0;
        std::uint64_t epoch = 0;
    };
    std::vector<Quiet> quiet_;
    std::uint64_t binsEpoch_ = 1;
    std::vector<std::uint64_t> lastTdmStep_;  // per zone: last step it was time-driven
    std::vector<std::uint64_t> denseUntil_;   // per zone: kept dense until this step (modified EDM hand-over)
    std::vector<std::uint8_t> sticky_, contact_;
    double margin_ = 0;   // distance at which an event-driven particle counts as near a TDM one [m]
    double vTdmMax_ = 0;  // fastest TDM particle at the last relabel [m/s]

    std::uint64_t steps_ = 0;
    bool frozenModes_ = false;
    HaetCounters counters_;
    double e0_ = 0, tdmIn_ = 0, tdmOut_ = 0, tdm0_ = 0;
    double inflow_ = 0, outflow_ = 0;  // energy brought by added particles, taken by removed ones [J]
};

extern template class HaetEngine<2>;
extern template class HaetEngine<3>;

}  // namespace haet
