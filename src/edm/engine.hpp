#pragma once
// Event-driven engine for hard disks (D = 2) and spheres (D = 3): Lubachevsky's scheme (PHYSICS.md D.1) with
// one pending event per particle, collision counters for stale events, per-particle clocks (lazy updates),
// neighbour shells (a list per particle of those it can reach while it stays near where the list was made) or a
// cell grid with cell-crossing events, periodic images, moving plane walls, gravity, frozen particles, the
// rough-particle collision operator with Walton's rule (C), and the TC model against inelastic collapse (D.7).
// docs/edm.md describes the algorithm, the invalid-state rules and the defaults.
#include <array>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "edm/collision.hpp"
#include "edm/event_queue.hpp"
#include "edm/predict.hpp"
#include "world/world.hpp"

namespace haet {

struct EdmSettings {
    /// Edge of the event grid's cells [m]; 0: the largest particle diameter (with neighbour shells: plus the
    /// shell), and in a 3D world without gravity (with cell crossings) at least the edge that makes 2.5 cells per
    /// particle (docs/edm.md). Must not be smaller than the largest diameter (plus the shell).
    double cellSize = 0;
    /// Neighbour shells (docs/edm.md), thickness [in units of the largest diameter]: each particle keeps a list
    /// of the particles it can touch while it stays within half the thickness (per axis) of where its list was
    /// made, and leaving that cube is its only non-collision event. 0: cell-crossing events (attachZones needs
    /// them). Shells save instructions in dense states (phi >= 0.4 in 3D: 0.25) but not cache misses, so they
    /// pay only when the engine's arrays fit in the cache (measured in docs/edm.md).
    double shell = 0;
    /// Tangential restitution: Walton's rule with (e, mu, beta0) of the material pair, or beta = beta0 always.
    enum class Tangential { Walton, Constant } tangential = Tangential::Walton;
    /// TC model (PHYSICS.md A.4, D.7): a collision less than tcTime after the previous collision of either
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
    /// positionAt, velocityAt, collisionCount, cellOfParticle) are the hybrid's, and unavailable.
    bool holdState = false;
    /// World index of the first particle this engine owns. Those before it belong to another engine (the
    /// time-driven one of a hybrid run) and are invisible here; particles join and leave with add() and remove().
    std::size_t firstParticle = 0;
    /// Reference twin: the next event by brute force (all pairs and all walls at every event, O(N^2) per event),
    /// no cells, no queue. For tests.
    bool reference = false;
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
};

/// What a hybrid run asks of the event-driven engine (PHYSICS.md A.2-A.4): the volume of its particles per zone,
/// kept current as they cross cells, and the particles that must leave it for the time-driven engine.
template <int D>
struct EdmZoneLink {
    /// Per cell of the event grid: nonzero where an event-driven particle must not be (near time-driven ones).
    /// Owned by the hybrid, which changes it between advances.
    const std::vector<std::uint8_t>* guard = nullptr;
    /// Zone of a cell: sum over axes of zoneCoord[k][cell coordinate k] * zoneStride[k] (cell centre's zone).
    std::array<std::vector<std::uint32_t>, D> zoneCoord;
    std::array<std::uint32_t, D> zoneStride{};
    std::size_t zones = 0;
    /// A collision within the TC time (tcTime, the modified EDM's dt_min) hands both particles over, instead of
    /// only making the collision elastic.
    bool handoverOnTc = true;
};

/// Counts of what the engine did.
struct EdmStats {
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
    EdmEngine(World<D>& world, const EdmSettings& settings);

    /// Processes all events before t, then brings every particle to time t (positions and velocities under
    /// gravity; periodic positions wrapped into the box, wraps recorded in Particles::image); world.time = t.
    /// Between calls the World holds the state at world.time; during a call the engine's own copy is current.
    /// Throws SimulationError if the event rate exceeds the bound (EdmSettings::maxEventRate) or a particle's
    /// state is not finite.
    void advanceTo(double t);

    /// Processes all events before t without bringing the particles to t (their clocks stay where their last
    /// event left them); the World's copy of this engine's particles is stale (with EdmSettings::holdState: absent)
    /// until synchronise(). If it throws, a held state is put back as it is, each particle at its own clock.
    void advanceEvents(double t);
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
    /// The World exchanged particles i and j (Particles::swapEntries); owned or not.
    void swapIndices(std::size_t i, std::size_t j);
    /// Hybrid coupling: zone volumes and the guard (EdmZoneLink). Needs cell crossings (EdmSettings::shell = 0).
    void attachZones(const EdmZoneLink<D>& link);
    /// Per zone: volume of this engine's particles in it [m^D] (attachZones first).
    const std::vector<double>& zoneVolume() const { return zoneVolume_; }
    /// World indices that entered a cell with a nonzero guard since the last call (may repeat an index; all
    /// still owned by this engine).
    std::vector<std::uint32_t> takeGuardEntries();
    /// World indices of particles that collided within the TC time of their previous collision (with
    /// EdmZoneLink::handoverOnTc), since the last call.
    std::vector<std::uint32_t> takeTcHandovers();
    /// Position of owned particle i at time t (>= its clock), wrapped into the box [m].
    Vec<D> positionAt(std::size_t i, double t) const;
    /// Collisions of owned particle i so far (pair and wall; changes whenever its velocity jumps) [-].
    std::uint32_t collisionCount(std::size_t i) const { return link_[slotOf_[i]].count; }
    /// Velocity of owned particle i at time t [m/s].
    Vec<D> velocityAt(std::size_t i, double t) const { return velAt(hot_[slotOf_[i]], t); }
    /// Guard value of the cell particle i is in.
    std::uint32_t cellOfParticle(std::size_t i) const { return rec_[slotOf_[i]].cell; }
    /// The event grid, for the hybrid's guard.
    std::uint32_t cellIndex(const Vec<D>& x) const { return cellOf(x); }
    std::uint32_t cellCount() const { return static_cast<std::uint32_t>(head_.size()); }
    const std::array<int, D>& cellDims() const { return nCell_; }
    const Vec<D>& cellWidths() const { return cellW_; }
    /// Calls f(cell index, image) for cell c and its 3^D - 1 neighbours: periodic axes wrap (image: -1 or +1 box
    /// lengths on the axes crossed), open ones end; on a periodic axis of fewer than 3 cells a cell can come twice.
    template <class F>
    void forEachCellAround(std::uint32_t c, F&& f) const {
        std::array<int, D> cc;
        bool interior = true;
        for (int k = 0; k < D; ++k) {
            cc[k] = static_cast<int>((c / stride_[k]) % static_cast<std::uint32_t>(nCell_[k]));
            interior = interior && cc[k] >= 1 && cc[k] <= nCell_[k] - 2;
        }
        if (interior) {
            const Shift none{};
            for (int q = 0; q < kNbrCells; ++q) f(c + static_cast<std::uint32_t>(deltaFull_[q]), none);
            return;
        }
        constexpr int m = D == 3 ? 27 : 9;
        for (int code = 0; code < m; ++code) {
            std::uint32_t idx = 0;
            Shift image{};
            bool ok = true;
            int q = code;
            for (int k = 0; k < D; ++k) {
                int ck = cc[k] + q % 3 - 1;
                q /= 3;
                if (ck < 0 || ck >= nCell_[k]) {
                    if (!w_.domain.periodic[k]) {
                        ok = false;
                        break;
                    }
                    image[k] = ck < 0 ? -1 : 1;
                    ck -= image[k] * nCell_[k];
                }
                idx += static_cast<std::uint32_t>(ck) * stride_[k];
            }
            if (ok) f(idx, image);
        }
    }
    /// The same without the images: f(cell index).
    template <class F>
    void forEachNeighbourCell(std::uint32_t c, F&& f) const {
        forEachCellAround(c, [&](std::uint32_t idx, const Shift&) { f(idx); });
    }
    /// Calls f(World index) for every particle of this engine in cell c.
    template <class F>
    void forEachInCell(std::uint32_t c, F&& f) const {
        for (std::uint32_t s = head_[c]; s != kNil; s = link_[s].next) f(rec_[s].idx);
    }

    /// Re-reads every particle from the World (after outside changes at world.time: positions, velocities,
    /// frozen flags, particles added or removed) and re-predicts all events. The engine keeps its own copy of
    /// positions and velocities, so outside changes are lost at the next advanceTo without it.
    void reset();

    std::uint64_t events() const { return events_; }  ///< events processed (collisions, crossings, stale)
    std::uint64_t collisions() const { return stats_.pairCollisions + stats_.wallCollisions; }
    const EdmStats& stats() const { return stats_; }
    /// Sum of r_ij . dp_i over pair collisions since the last call [J] (PHYSICS.md E.2); walls excluded.
    double takeCollisionVirial() {
        const double v = virial_;
        virial_ = 0;
        return v;
    }
    /// Called after every collision (pair or wall). Leave empty for speed.
    void setObserver(std::function<void(const EdmCollision<D>&)> f) { observer_ = std::move(f); }

    const EdmSettings& settings() const { return s_; }
    double tcTime() const { return tc_; }  ///< the TC time in use [s] (0: TC model off)
    double cellSize() const;               ///< smallest cell edge of the grid [m]
    /// Thickness of the neighbour shells in use [m] (0: cell crossings).
    double shellThickness() const { return shells_ ? 2 * shellHalf_ : 0; }
    double nextEventTime() const;     ///< time of the next pending event [s] (reference mode: infinity)
    std::size_t memoryBytes() const;  ///< heap memory of the engine's own arrays [bytes]

private:
    enum Type : std::uint32_t { kPair = 0, kWall = 1, kCell = 2, kNone = 3 };
    static constexpr std::uint32_t kTypeShift = 30, kIndexMask = (1u << kTypeShift) - 1;
    static constexpr std::uint32_t kNil = 0xFFFFFFFFu;
    using Shift = std::array<std::int32_t, D>;

    // The engine works on slots, its own order of the particles (cell by cell, for memory locality); Rec::idx maps
    // a slot to the particle's index in the World. What a prediction reads of a neighbour is in two records: Hot
    // (one 64-byte cache line in 3D) and Link. The World's x and v are written at synchronisation only.
    struct alignas(D == 3 ? 64 : 16) Hot {
        Vec<D> x;  // position at time t [m]; raw: the periodic wraps since the last synchronisation are in wrap
        double t;  // the particle's clock [s]; kNever marks a frozen particle (never moves)
        Vec<D> v;  // velocity at time t [m/s]
        double r;  // radius [m]
    };
    struct Link {
        std::uint32_t next;   // next slot in the same cell
        std::uint32_t count;  // collision counter (stale-event test)
        std::uint32_t wrap;   // box-frame position = x - wrap * L on periodic axes; packed, wrapsOf
    };
    // Periodic wraps since the last synchronisation, kWrapBits per axis with a bias. One that would leave the
    // field moves the whole box lengths from the stored position into Particles::image, as a synchronisation does.
    static constexpr int kWrapBits = D == 3 ? 10 : 16;
    static constexpr std::int32_t kWrapBias = 1 << (kWrapBits - 1), kWrapLimit = kWrapBias - 2;
    static Shift wrapsOf(std::uint32_t packed) {
        Shift w;
        for (int k = 0; k < D; ++k)
            w[k] = static_cast<std::int32_t>((packed >> (kWrapBits * k)) & ((1u << kWrapBits) - 1)) - kWrapBias;
        return w;
    }
    static std::uint32_t packWraps(const Shift& w) {
        std::uint32_t packed = 0;
        for (int k = 0; k < D; ++k) packed |= static_cast<std::uint32_t>(w[k] + kWrapBias) << (kWrapBits * k);
        return packed;
    }
    void setWraps(std::uint32_t s, Shift w);
    struct Candidate {
        double time = kNever;
        std::uint32_t code = kNone << kTypeShift;
        std::uint32_t stamp = 0;
        bool better(double t, std::uint32_t c) const { return t < time || (t == time && c < code); }
    };

    void chooseShell();
    void buildGrid();
    /// World particle i into the box on periodic axes (wraps recorded in Particles::image).
    void wrapIntoBox(std::size_t i);
    std::uint32_t cellOf(const Vec<D>& x) const;
    void linkCells();
    void insertCell(std::uint32_t s, std::uint32_t c);
    void removeCell(std::uint32_t s);
    void resort();
    void predict(std::uint32_t s, double now, int axis = -1, int dir = 0);
    void setPending(std::uint32_t s, const Candidate& best, const Candidate& cross);
    bool keepsColl(std::uint32_t s) const;
    double keptTime(std::uint32_t s, double now) const;
    void predictShell(std::uint32_t s, double now);
    double candidateTime(const Hot& hs, std::uint32_t s, std::uint32_t j, const Shift& m, double now,
                         double bestTime) const;
    /// Four candidates of a scan at once (docs/edm.md, "Four candidates at a time"). ScanState: the scanning
    /// slot's state and the constants, one value per lane. Batch: the candidates' slots, packed wraps and image
    /// bases (the image shift in box lengths is base + wrapsOf(wrap)); a batch whose wraps all equal wsPacked and
    /// whose bases are all plainBase (minus the scanning slot's wraps) needs no shift. best (and bestJ, the slot of a
    /// pair event in it) updated as candidateTime and Candidate::better, one candidate after the other, would.
    struct ScanState {
        using V = double __attribute__((vector_size(32)));
        V x[D], v[D], gh[D], g[D], len[D], t, r;
    };
    struct Batch {
        const std::uint32_t* j;
        const std::uint32_t* wrap;
        const Shift* const* base;
    };
    ScanState scanState(const Hot& hs) const;
    [[gnu::always_inline]] inline void candidates4(const ScanState& sc, const Hot& hs, std::uint32_t s, const Batch& bt,
                                                   std::uint32_t wsPacked, const Shift* plainBase, double now,
                                                   Candidate& best, std::uint32_t& bestJ) const;
    bool shellsMeet(std::uint32_t s, std::uint32_t j, const Shift& image) const;
    bool linkShell(std::uint32_t s);
    void unlinkShell(std::uint32_t s);
    void moveShell(std::uint32_t s, double now);
    void buildLists();
    std::uint32_t* row(std::uint32_t s) { return &nbr_[static_cast<std::size_t>(s) * rowLen_]; }
    const std::uint32_t* row(std::uint32_t s) const { return &nbr_[static_cast<std::size_t>(s) * rowLen_]; }
    double pairTime(std::uint32_t a, std::uint32_t b, const Shift& m, double now, double horizon) const;
    double pairTimeFromNow(std::uint32_t a, std::uint32_t b, const Shift& m, double now) const;
    double wallTime(std::uint32_t s, std::size_t w, double now) const;
    void processNext();
    void advanceReference(double t);
    void collidePair(std::uint32_t a, std::uint32_t b, double t);
    void collideWall(std::uint32_t s, std::uint32_t w, double t);
    void crossCell(std::uint32_t s, int axis, bool up);
    void advance(std::uint32_t s, double t);
    void syncSlot(std::uint32_t s, double t);
    void storeSlot(std::uint32_t s);
    void putBackState();
    std::uint32_t zoneOfCell(std::uint32_t c) const;
    /// Counts an event; at the end of each window of events, checks the event rate (checkRate).
    void countEvent(double t) {
        if (++events_ - winEvents_ >= window_) checkRate(t);
    }
    [[gnu::noinline]] void checkRate(double t);
    Vec<D> posAt(const Hot& h, double t) const;
    Vec<D> velAt(const Hot& h, double t) const;
    bool frozen(std::uint32_t s) const { return hot_[s].t == kNever; }  // also true for a free slot
    CollisionLaw lawFor(int matA, int matB, bool elastic) const;
    /// Throws std::invalid_argument unless World particle i's material is in the contact table.
    void requireKnownMaterial(std::size_t i) const;
    /// Whether the collisions of a material pair have beta = -1 whatever the velocities (Walton's rule with
    /// mu = 0, or a constant beta0 = -1): no tangential impulse, so rotation is left alone.
    bool smoothPair(int matA, int matB) const;
    /// World particle i's material; with one material in the table not read (a World-order array: a cache miss
    /// per particle of a collision).
    int materialOf(std::uint32_t i) const { return w_.contact.nMaterials == 1 ? 0 : w_.particles.material[i]; }
    bool tcElastic(std::uint32_t a, std::uint32_t b, double t) const;  // b = kNil: wall or frozen partner
    void notify(double t, std::uint32_t a, std::uint32_t partner, bool wall, bool elastic, bool hop, const Vec<D>& P);

    World<D>& w_;
    EdmSettings s_;
    double tc_ = 0;       // TC time in use (0: off)
    double tcRef_ = 0;    // TC time, or the contact duration, whether the TC model is on or off [s]
    double maxRate_ = 0;  // events per moving particle per second (0: none)
    Vec<D> g_;            // gravity
    Vec<D> boxLen_;       // box lengths
    std::size_t nMoving_ = 0;
    double rmax_ = 0;

    // per slot
    std::vector<Hot> hot_;
    std::vector<Link> link_;
    // What an event of the slot itself needs (16 bytes). The pending event's time is the queue's; the time of
    // coll is not kept: while the crossing is pending it is recomputed when needed (keptTime).
    static constexpr std::uint32_t kCellBits = 28;
    struct Kept {
        std::uint32_t code = kNone << kTypeShift;
        std::uint32_t stamp = 0;
    };
    struct Rec {
        Kept coll;                       // earliest pair or wall event found by the last scan: code, partner's counter
        std::uint32_t cell : kCellBits;  // cell index (free slot: head_.size())
        std::uint32_t exit : 3;          // face of the cell crossing (shell exit) found by the last scan: 2 axis + up
        std::uint32_t crossing : 1;      // the pending event is that crossing, not coll
        std::uint32_t idx;               // slot -> World index
    };
    std::vector<Rec> rec_;
    std::vector<double> tLast_;  // per slot: time of the last collision (only with the TC model)
    EventCalendar queue_;        // pending event times
    // cell grid (singly linked lists: a crossing walks the old cell's few members to unlink)
    std::vector<std::uint32_t> head_;
    static constexpr int kNbrCells = D == 3 ? 27 : 9, kSideCells = D == 3 ? 9 : 3;
    // The offset tables are padded with zeros to whole groups of eight (loadHeads reads eight at a time).
    static constexpr int kNbrPad = (kNbrCells + 7) / 8 * 8, kSidePad = (kSideCells + 7) / 8 * 8;
    std::array<std::int32_t, kNbrPad> deltaFull_{};  // neighbour cell offsets (cells away from the faces)
    std::array<std::array<std::int32_t, kSidePad>, 2 * D> deltaSide_{};  // new neighbours after a crossing
    std::array<int, D> nCell_{};
    std::array<std::uint32_t, D> stride_{};
    Vec<D> cellW_;
    bool partialScans_ =
        true;  // crossings scan only the new neighbour cells (docs/edm.md: needs 7 cells per periodic axis)

    // Neighbour shells (shells_): per slot the box-frame centre of its cube (edge 2 shellHalf_) and a row of rowLen_
    // words in nbr_: the count, then the neighbours, each a slot with the periodic image of the neighbour's centre
    // (kImageShift). The grid holds the centres; its cells are at least a diameter plus the shell wide.
    static constexpr std::uint32_t kImageShift = 26, kSlotMask = (1u << kImageShift) - 1;
    bool shells_ = false;
    bool periodic_ = false;  // some axis is periodic
    double shellHalf_ = 0;
    struct alignas(32) Centre {
        Vec<D> c;  // box-frame centre of the shell [m]
        double r;  // radius [m], a copy of Hot::r: a list rebuild reads one record per candidate
    };
    std::vector<Centre> centre_;
    std::vector<std::uint32_t> nbr_;
    std::size_t rowLen_ = 0;

    // particles joining and leaving: World index -> slot (kNil: not owned), free slots (rec_[s].idx == kNil)
    std::vector<std::uint32_t> slotOf_;
    std::vector<std::uint32_t> free_;
    std::size_t nLive_ = 0;
    // hybrid coupling (attachZones)
    bool zoned_ = false;
    EdmZoneLink<D> zone_;
    std::vector<double> zoneVolume_;
    std::vector<std::uint32_t> guardEntries_, tcHandovers_;

    std::uint64_t events_ = 0, sortedAt_ = 0;
    EdmStats stats_;
    double virial_ = 0;
    std::uint64_t window_ = 0, winEvents_ = 0;
    double winTime_ = 0;
    std::function<void(const EdmCollision<D>&)> observer_;
};

extern template class EdmEngine<2>;
extern template class EdmEngine<3>;

}  // namespace haet
