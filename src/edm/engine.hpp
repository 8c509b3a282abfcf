#pragma once
// Event-driven engine for hard disks (D = 2) and spheres (D = 3): Lubachevsky's scheme (docs/physics.md D.1) with
// one pending event per particle, collision counters for stale events, per-particle clocks (lazy updates),
// neighbour shells (a list per particle of those it can reach while it stays near where the list was made) or a
// cell grid with cell-crossing events, periodic images, moving plane walls, static mesh walls (segments, triangles:
// D.8), gravity, frozen particles, the rough-particle collision operator with Walton's rule (C), and the TC model
// against inelastic collapse (D.7).
// docs/edm.md describes the algorithm, the invalid-state rules and the defaults.
//
// The engine in parts: this class is the event loop (clocks, the event queue, dispatch of the events, particles
// joining and leaving, synchronisation; the collisions in edm/collide.cpp); the particle state it shares with the
// other parts is edm/slots.hpp; the broad phase is the event grid with its cell crossings (edm/event_grid.hpp) or the
// neighbour shells (edm/shells.hpp), behind one interface; the batched candidate scan is edm/scan.hpp over the lane
// primitives of core/lanes_scan.hpp; the mesh walls' elements, binned into the event grid's cells, and their
// canonical times edm/mesh_walls.hpp; the TC model edm/tc_model.hpp; the reference twin edm/reference.hpp; a
// coupled engine (the hybrid) follows the particles through edm/observer.hpp.
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "edm/collision.hpp"
#include "edm/event_grid.hpp"
#include "edm/event_queue.hpp"
#include "edm/mesh_walls.hpp"
#include "edm/observer.hpp"
#include "edm/predict.hpp"
#include "edm/shells.hpp"
#include "edm/slots.hpp"
#include "edm/tc_model.hpp"
#include "io/checkpoint.hpp"
#include "world/world.hpp"

namespace haet {

struct EdmSettings {
    /// Edge of the event grid's cells [m]; 0: the largest particle diameter (with neighbour shells: plus the
    /// shell), and in a 3D world without gravity (with cell crossings) at least the edge that makes 2.5 cells per
    /// particle (docs/edm.md). Must not be smaller than the largest diameter (plus the shell).
    double cellSize = 0;
    /// Neighbour shells (docs/edm.md), thickness [in units of the largest diameter]: each particle keeps a list
    /// of the particles it can touch while it stays within half the thickness (per axis) of where its list was
    /// made, and leaving that cube is its only non-collision event. 0: cell-crossing events (an EdmObserver needs
    /// them). Shells save instructions in dense states (phi >= 0.4 in 3D: 0.25) but not cache misses, so they
    /// pay only when the engine's arrays fit in the cache (measured in docs/edm.md).
    double shell = 0;
    /// Tangential restitution: Walton's rule with (e, mu, beta0) of the material pair, or beta = beta0 always.
    enum class Tangential { Walton, Constant } tangential = Tangential::Walton;
    /// TC model (docs/physics.md A.4, D.7): a collision less than tcTime after the previous collision of either
    /// particle is elastic (e = 1, beta = -1). Also enables the rest hop on walls and frozen particles.
    bool tcModel = true;
    /// TC model time [s]; 0: the TDM contact duration world.contact.contactTime.
    double tcTime = 0;
    /// Bound on the event rate [events per moving particle per second of simulated time], checked over windows
    /// of max(10^6, 100 N) events; above it the run stops with SimulationError (inelastic collapse, zero-time
    /// loop). 0: 1000 / tcTime (also when the TC model is off); without any TC time 10^4 u / d_min, where u is
    /// the largest of the rms particle speed, sqrt(|g| d_min) and the fastest wall speed at the start.
    double maxEventRate = 0;
    /// A pure event-driven run (no other engine on the store, firstParticle = 0): between synchronisations the
    /// engine holds the only copy of positions, velocities and radii. advanceEvents releases the World's
    /// (Particles::releaseMotion) and synchronise writes them back; reset() needs them back first. The engine then
    /// keeps no World-to-slot table: the questions about single particles (owns, add, remove, swapIndices,
    /// positionAt, velocityAt, collisionCount) are the hybrid's, and unavailable.
    bool holdState = false;
    /// World index of the first particle this engine owns. Those before it belong to another engine (the
    /// time-driven one of a hybrid run) and are invisible here; particles join and leave with add() and remove().
    std::size_t firstParticle = 0;
    /// The largest radius a particle may have that joins later (an inlet's) [m]: the grid is sized for it as for
    /// the particles at the start. 0: those at the start.
    double radiusBound = 0;
    /// Reference twin: the next event by brute force (all pairs and all walls at every event, O(N^2) per event),
    /// no cells, no queue. For tests.
    bool reference = false;
    /// Walls this engine cannot predict (docs/physics.md H.6: walls of any shape that are curved or move,
    /// oscillating planes) belong to a coupled engine, which keeps this engine's particles away from them (the
    /// hybrid's guard, docs/haet.md): they are left out. false: such a wall is an error (std::invalid_argument).
    bool guardedWalls = false;
    /// Set from outside (a signal handler: run/stop.hpp) to end advanceEvents after the event under way; null:
    /// never. A hybrid leaves it null (its own steps stop).
    const std::atomic<bool>* stop = nullptr;
};

/// One collision as seen by an observer (tests, diagnostics).
template <int D>
struct EdmCollision {
    double time = 0;            ///< [s]
    std::uint32_t i = 0;        ///< World index of the particle (of a pair: the lower index, unless frozen)
    std::uint32_t partner = 0;  ///< World index of the other particle, or the wall index when wall is true
    bool wall = false;
    bool elastic = false;  ///< made elastic by the TC model
    bool restHop = false;  ///< normal speed raised to the rest-hop speed (wall or frozen partner)
    Vec<D> impulse;        ///< impulse on particle i [N s]
    Vec<D> position;       ///< centre of particle i at the collision [m]
    /// x_i - x_j (minimum image) for a pair; for a wall, from the contact point to the centre of i [m]
    Vec<D> branch;
    /// The wall is a mesh: partner is its index in World::surfaces (else in World::walls), element which of its
    /// elements.
    bool surface = false;
    std::uint32_t element = 0;
};

/// Counts of what the engine did.
struct EdmStats {
    /// Wall collisions: with planes and with the elements of meshes.
    std::uint64_t pairCollisions = 0, wallCollisions = 0;
    std::uint64_t cellCrossings = 0;  ///< cell-crossing events
    std::uint64_t shellExits = 0;     ///< neighbour-shell exits (list rebuilt)
    std::uint64_t listGrowths = 0;    ///< neighbour lists enlarged (a list was full)
    std::uint64_t stale = 0;          ///< events found invalid (partner collided since) and re-predicted
    std::uint64_t tcElastic = 0;      ///< collisions made elastic by the TC model
    std::uint64_t restHops = 0;       ///< collisions whose normal speed was raised to the rest-hop speed
    std::uint64_t grazing = 0;        ///< predicted collisions found not approaching (round-off), skipped
    double dissipated = 0;            ///< kinetic energy lost in collisions (walls: including a moving wall's work) [J]
};

template <int D>
class EdmEngine {
public:
    /// Takes the particles' state at world.time. Throws std::invalid_argument for unusable settings or worlds
    /// (cell size below the largest diameter, periodic box shorter than two diameters, no contact table).
    /// observer (may be null; it must outlive the engine): told of every particle's cell (EdmObserver); needs cell
    /// crossings (std::logic_error with neighbour shells).
    EdmEngine(World<D>& world, const EdmSettings& settings, EdmObserver<D>* observer = nullptr);

    /// Processes all events before t, then brings every particle to time t (positions and velocities under
    /// gravity; periodic positions wrapped into the box, wraps recorded in Particles::image); world.time = t.
    /// Between calls the World holds the state at world.time; during a call the engine's own copy is current.
    /// Throws SimulationError if the event rate exceeds the bound (EdmSettings::maxEventRate) or a particle's
    /// state is not finite.
    void advanceTo(double t);

    /// Processes all events before t without bringing the particles to t (their clocks stay where their last
    /// event left them); the World's copy of this engine's particles is stale (with EdmSettings::holdState: absent)
    /// until synchronise(). If it throws, a held state is put back as it is, each particle at its own clock.
    /// Returns t, or, when EdmSettings::stop ended it early, the time of the last event processed (no event is
    /// pending before it, so every particle can be synchronised there).
    double advanceEvents(double t);
    /// Brings every particle of this engine to time t and writes its state to the World; world.time = t.
    /// With EdmSettings::holdState it also gives the World back its positions, velocities and radii.
    void synchronise(double t);

    // ---- particles joining and leaving (hybrid runs) ----
    /// Number of particles this engine owns.
    std::size_t size() const { return nLive_; }
    bool owns(std::size_t i) const { return i < slotOf_.size() && slotOf_[i] != kNil; }
    /// Particle i leaves at time t (>= its clock): its state at t is written to the World.
    void remove(std::size_t i, double t);
    /// Particle i (not owned) joins at time t with its World state.
    void add(std::size_t i, double t);
    /// Room for World particles [0, n): particles appended to the World (an inlet's) can then join with add().
    void grow(std::size_t n);
    /// The World exchanged particles i and j (Particles::swapEntries); owned or not.
    void swapIndices(std::size_t i, std::size_t j);
    /// Position of owned particle i at time t (>= its clock), wrapped into the box [m].
    Vec<D> positionAt(std::size_t i, double t) const;
    /// Collisions of owned particle i so far (pair and wall; changes whenever its velocity jumps) [-].
    std::uint32_t collisionCount(std::size_t i) const { return sl_.link[slotOf_[i]].count; }
    /// Velocity of owned particle i at time t [m/s].
    Vec<D> velocityAt(std::size_t i, double t) const { return sl_.velAt(sl_.hot[slotOf_[i]], t); }

    /// The event grid's geometry (what an EdmObserver is told).
    const CellGrid<D>& cells() const { return grid_.cells(); }
    std::uint32_t cellCount() const { return grid_.count(); }
    const std::array<int, D>& cellDims() const { return grid_.cells().dims(); }

    /// Re-reads every particle from the World (after outside changes at world.time: positions, velocities,
    /// frozen flags, particles added or removed) and re-predicts all events. The engine keeps its own copy of
    /// positions and velocities, so outside changes are lost at the next advanceTo without it.
    void reset();
    /// reset(), after gravity too may have changed (Domain::gravity, which the predictions of free flight use).
    void restart();

    std::uint64_t events() const { return events_; }  ///< events processed (collisions, crossings, stale)
    std::uint64_t collisions() const { return stats_.pairCollisions + stats_.wallCollisions; }
    const EdmStats& stats() const { return stats_; }
    /// Sum of r_ij . dp_i over pair collisions since the last call [J] (docs/physics.md E.2); walls excluded.
    double takeCollisionVirial() {
        const double v = virial_;
        virial_ = 0;
        return v;
    }
    /// Called after every collision (pair or wall). Leave empty for speed.
    void setObserver(std::function<void(const EdmCollision<D>&)> f) { collisionHook_ = std::move(f); }

    const EdmSettings& settings() const { return s_; }
    double tcTime() const { return tc_.time(); }              ///< the TC time in use [s] (0: TC model off)
    double cellSize() const { return grid_.smallestEdge(); }  ///< smallest cell edge of the grid [m]
    /// Thickness of the neighbour shells in use [m] (0: cell crossings).
    double shellThickness() const { return 2 * shells_.half(); }
    double nextEventTime() const;     ///< time of the next pending event [s] (reference mode: infinity)
    std::size_t memoryBytes() const;  ///< heap memory of the engine's own arrays [bytes]
    /// The mesh elements the engine predicts (its static meshes), binned into its cells.
    const edm::MeshWalls<D>& meshWalls() const { return mesh_; }

    // ---- checkpoints (edm/state.cpp; ARCHITECTURE.md, "Checkpoints") ----
    /// Whether saveState can hold the whole state: not in reference mode (tests), which keeps no events.
    bool restartable() const { return !s_.reference; }
    /// The slots as they are (each particle at its own clock: nothing is advanced), their pending events, the TC
    /// model's clocks, the free slots, the grid's parameters, the neighbour shells' centres and lists, and the
    /// counters. Between calls of advanceEvents; the grid's cell lists and the
    /// queue are made again from the slots on loading, which orders nothing differently (pops go by time, then slot;
    /// a scan's best by time, then code, whatever the order of the cells' lists).
    void saveState(ByteWriter& out) const;
    /// Replaces the state with a saved one, in an engine made for the same scenario on the World loaded from the
    /// same checkpoint. Throws CheckpointError (Corrupt) for a state that does not fit (sizes, slot, cell, wall and
    /// World indices).
    void loadState(ByteReader& in);
    /// With EdmSettings::holdState between calls of advanceEvents: gives the World its positions, velocities and radii
    /// as the slots hold them (each at its own clock, not advanced), so that it can be saved; changes nothing of the
    /// engine's state.
    void exposeHeldState();

private:
    using Sl = edm::Slots<D>;
    using Shift = typename Sl::Shift;
    using Hot = typename Sl::Hot;
    using Link = typename Sl::Link;
    using Rec = typename Sl::Rec;
    using Kept = typename Sl::Kept;
    using Candidate = edm::Candidate;
    static constexpr std::uint32_t kNil = edm::kNil, kTypeShift = edm::kTypeShift, kIndexMask = edm::kIndexMask;
    static constexpr std::uint32_t kPair = edm::kPair, kWall = edm::kWall, kCell = edm::kCell, kNone = edm::kNone;

    void chooseShell();
    void buildGrid();
    /// World particle i into the box on periodic axes (wraps recorded in Particles::image).
    void wrapIntoBox(std::size_t i);
    void resort();
    /// Tells the observer the grid and every particle (construction, reset).
    void reportAll();
    /// The next event of slot s at time now (after a crossing along axis in direction dir = +-1, with a kept
    /// event: only the newly adjacent cells are scanned), with the broad phase in use.
    void predict(std::uint32_t s, double now, int axis = -1, int dir = 0);
    /// The same with a given broad phase (edm::EventGrid or edm::Shells): one body for both.
    template <class Broad>
    [[gnu::always_inline]] inline void predictWith(const Broad& broad, std::uint32_t s, double now, int axis, int dir);
    [[gnu::noinline]] void predictShells(std::uint32_t s, double now);
    void setPending(std::uint32_t s, const Candidate& best, const Candidate& cross);
    bool keepsColl(std::uint32_t s) const;
    double keptTime(std::uint32_t s, double now) const;
    void processNext();
    void advanceReference(double t);
    void collidePair(std::uint32_t a, std::uint32_t b, double t);
    void collideWall(std::uint32_t s, std::uint32_t w, double t);
    /// What a collision with a wall or a mesh element did (wallImpulse): the impulse on the particle, and whether the
    /// TC model made it elastic and the rest hop lifted it.
    struct WallHit {
        Vec<D> P;
        bool elastic = false;
        bool hop = false;
    };
    WallHit wallImpulse(std::uint32_t s, double t, CollisionBody<D>& b1, CollisionBody<D>& b2, const Vec<D>& n,
                        double gn, double uRest, int ma, int wallMaterial, bool smooth);
    /// Slot s against mesh element e (edm/mesh_walls.hpp) at time t, with the normal of the predicted contact.
    void collideMesh(std::uint32_t s, std::uint32_t e, double t);
    /// The best so far (best) against the mesh elements binned into slot s's cell, at time now.
    [[gnu::noinline]] void predictMesh(std::uint32_t s, double now, Candidate& best) const;
    void syncSlot(std::uint32_t s, double t);
    void storeSlot(std::uint32_t s);
    void putBackState();
    /// Counts an event; at the end of each window of events, checks the event rate (checkRate).
    void countEvent(double t) {
        if (++events_ - winEvents_ >= window_) checkRate(t);
    }
    [[gnu::noinline]] void checkRate(double t);
    bool frozen(std::uint32_t s) const { return sl_.frozen(s); }  // also true for a free slot
    /// The collision law of materials (matA, matB); wall: matA a particle's, matB a wall's (ContactSetup::wallTable).
    CollisionLaw lawFor(int matA, int matB, bool wall, bool elastic) const;
    /// Throws std::invalid_argument unless World particle i's material is in the contact table.
    void requireKnownMaterial(std::size_t i) const;
    /// Whether the collisions of a material pair have beta = -1 whatever the velocities (Walton's rule with
    /// mu = 0, or a constant beta0 = -1): no tangential impulse, so rotation is left alone.
    bool smoothPair(int matA, int matB) const;
    /// World particle i's material; with one material in the table not read (a World-order array: a cache miss
    /// per particle of a collision).
    int materialOf(std::uint32_t i) const { return w_.contact.nMaterials == 1 ? 0 : w_.particles.material[i]; }
    void notify(double t, std::uint32_t a, std::uint32_t partner, bool wall, bool elastic, bool hop, const Vec<D>& P,
                const Vec<D>& branch, std::uint32_t element = kNil);

    World<D>& w_;
    EdmSettings s_;
    edm::TcModel tc_;     // TC time in use (0: off) and the last collision per slot
    double tcRef_ = 0;    // TC time, or the contact duration, whether the TC model is on or off [s]
    double maxRate_ = 0;  // events per moving particle per second (0: none)
    std::size_t nMoving_ = 0;
    double rmax_ = 0;
    double gridEdge_ = 0, gridCap_ = 0;  // what the grid was built from at the last reset (buildGrid) [m], [cells]

    Sl sl_;                   // per slot: Hot, Link, Rec
    EventCalendar queue_;     // pending event times
    edm::EventGrid<D> grid_;  // cells and their lists (with neighbour shells: of the shells' centres)
    edm::Shells<D> shells_;   // neighbour shells (on: EdmSettings::shell > 0)
    // The planes it predicts (World::walls indices: all but oscillating ones, which only a guarded run has) and the
    // static meshes' elements; an element's event code is the wall code of World::walls.size() + its index.
    std::vector<std::uint32_t> planes_;
    edm::MeshWalls<D> mesh_;

    // particles joining and leaving: World index -> slot (kNil: not owned), free slots (rec[s].idx == kNil)
    std::vector<std::uint32_t> slotOf_;
    std::vector<std::uint32_t> free_;
    std::size_t nLive_ = 0;
    EdmObserver<D>* observer_ = nullptr;  // a coupled engine (hybrid), or null

    std::uint64_t events_ = 0, sortedAt_ = 0;
    EdmStats stats_;
    double virial_ = 0;
    std::uint64_t window_ = 0, winEvents_ = 0;
    double winTime_ = 0;
    std::function<void(const EdmCollision<D>&)> collisionHook_;
};

extern template class EdmEngine<2>;
extern template class EdmEngine<3>;

}  // namespace haet
