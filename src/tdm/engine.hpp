#pragma once
// Time-driven DEM engine: soft disks (2D) and spheres (3D) with the shared contact laws.
// One step: predict (and the skin test) -> (rebuild the pair list if any particle moved more than skin/2) ->
// forces -> correct.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "contact/kinds.hpp"
#include "io/checkpoint.hpp"
#include "neighbor/pair_list.hpp"
#include "tdm/contact_record.hpp"
#include "tdm/forces.hpp"
#include "tdm/integrators.hpp"
#include "tdm/ranks.hpp"
#include "tdm/shape_pass.hpp"
#include "tdm/surface_state.hpp"
#include "world/world.hpp"

namespace haet {

struct TdmSettings {
    IntegratorKind integrator = IntegratorKind::Verlet;
    double dt = 0;            ///< [s]
    double skin = 0;          ///< [m]
    double maxOverlap = 0.5;  ///< blow-up limit: overlap / smaller radius [-]
    int sortEvery = 1000;     ///< spatial re-sort period in steps (0 = never)
    bool planeLoads = false;  ///< keep each plane contact's force, for the planes' loads (planeLoad)
    /// Particles far from every static plane skip the planes until the next build (markNearPlanes); false: every
    /// particle tests every plane, the twin the marks are tested against (the same bits).
    bool markPlanes = true;
    /// Set from outside (a signal handler: run/stop.hpp) to end advanceTo after the step under way; null: never.
    const std::atomic<bool>* stop = nullptr;
    /// A run across several ranks (tdm/ranks.hpp, docs/parallel.md): each keeps the particles of its slab and ghost
    /// copies of its neighbours'; null (or one rank): every particle here. Velocity Verlet, disks and spheres, planes.
    Ranks* ranks = nullptr;
};

template <int D>
class TdmEngine {
public:
    TdmEngine(World<D>& world, const TdmSettings& s);
    ~TdmEngine();

    /// One time step. Throws SimulationError on NaN or excessive overlap.
    void step();
    /// Steps until the time reaches t (to within half a step): the same state as step() repeated, bit for bit.
    /// If a step fails its health check (SimulationError) inside this call, the particles may already hold the
    /// prediction for the step after it. Returns early, at the end of a whole step, once *settings().stop is set.
    void advanceTo(double t);
    /// The time after k more steps [s]: start time + (steps + k) dt, computed as such (no sum of dt that drifts).
    double timeAfter(std::uint64_t k) const { return t0_ + static_cast<double>(steps_ + k) * s_.dt; }

    const TdmSettings& settings() const { return s_; }
    std::uint64_t steps() const { return steps_; }
    std::uint64_t rebuilds() const { return rebuilds_; }
    const ForceStats& forceStats() const { return stats_; }
    const PairList<D>& pairs() const { return pairs_; }
    /// Particles [0, owned()) are this rank's; across ranks the ghosts follow them. One process: tdmCount().
    std::size_t owned() const { return halo_ ? nOwned_ : w_.particles.tdmCount(); }
    /// Across ranks: the slabs as they are now (null in one process).
    const Slabs* slabs() const;
    /// Across ranks: the particles this rank handed to another's slab so far, and the re-placements of the cuts.
    std::uint64_t migrated() const;
    std::uint64_t rebalances() const;
    /// This rank's share of the contacts now: a pair with a ghost counts one half (its owner's rank counts the
    /// other), wall contacts those of the owned particles. One process: the last force pass's count.
    double contactShare() const;

    /// After the particles in [0, tdmCount()) changed (a hybrid moved some in or out): new particle k was old
    /// particle from[k], or is new to this engine (kFresh). Per-particle history follows; a new particle starts
    /// with no contact history and the integrator history of free flight under gravity (it comes from ballistic
    /// flight); the pair list keeps the pairs of kept particles and gains those of new ones (remapPairList).
    /// Call at a step boundary.
    static constexpr std::uint32_t kFresh = 0xFFFFFFFFu;
    void remap(const std::vector<std::uint32_t>& from);
    /// After outside changes of the particles in place at a step boundary (positions, velocities, spins, radii,
    /// masses, frozen flags) or of gravity: the pair list, the step's velocities, the forces and the integrator's
    /// start as a new engine's on this state would be; the contacts' springs are kept (remap keeps them too).
    void restart();
    /// out[i]: contacts of particle i at the current positions, a wall contact counting 2 (resting on a wall
    /// weighs like two neighbours); saturates at 255. For i < tdmCount().
    void contactCounts(std::vector<std::uint8_t>& out) const;

    /// The contact network: the force pass of the step that ends at time t (to within half a step) puts every
    /// contact it evaluates into *sink (tdm/contact_record.hpp); null: none.
    void recordContactsAt(ContactSink<D>* sink, double t) {
        recordSink_ = sink;
        recordTime_ = t;
    }
    /// The time of the last force pass that recorded its contacts [s] (-1: none yet).
    double contactsRecordedAt() const { return recordedAt_; }
    /// The contact network of the state at construction (an output at the start time): the constructor's force
    /// pass again, recorded into *sink, from the springs as they were before it (none: every contact of a new engine
    /// is new), so the same forces and springs bit for bit. False, and nothing done, once a step, a remap, a restart
    /// or a checkpoint's state came after the constructor.
    bool recordStartContacts(ContactSink<D>* sink);

    /// Elastic energy stored in contacts (pairs and walls) [J]; across ranks this rank's share, as contactShare().
    double contactEnergy() const;
    /// Sum over contacts of r_ij . F_ij [J] (pair virial; walls excluded).
    double pairVirial() const;

    /// The load the particles put on one wall at the last force pass: the force on it [N] and its torque about its
    /// centre [N m] (a plane's point at the current time; a wall of any shape: its centre of rotation, moved with
    /// it). Planes report theirs only with TdmSettings::planeLoads.
    struct WallLoad {
        Vec<D> force;
        Ang<D> torque;
    };
    WallLoad planeLoad(std::size_t w) const;
    WallLoad surfaceLoad(std::size_t w) const;
    /// The walls' contacts with particles now (planes and walls of any shape) [-].
    std::size_t wallContacts() const;
    /// The walls of any shape as the last force pass saw them: poses, candidates, contacts (for tests).
    const SurfaceState<D>& surfaceState() const { return surf_; }
    /// Per particle whether it tests the planes until the next build (markNearPlanes); empty: all do (for tests).
    const std::vector<std::uint8_t>& nearPlanes() const { return nearPlanes_; }

    /// What the engine keeps beyond the World, for a checkpoint (tdm/state.cpp): the pair list with its springs, the
    /// planes' springs, the contacts with walls of any shape and their candidates, the integrator's history, the
    /// step's mean velocities, the counters and the start time. Between calls of advanceTo only (a step boundary).
    void saveState(ByteWriter& out) const;
    /// Replaces that state with a saved one, in an engine made for the same scenario on a World whose particles
    /// were loaded from the same checkpoint: the run then goes on as the saved one would have, bit for bit.
    /// Throws CheckpointError (Corrupt) when the sizes do not fit the World.
    void loadState(ByteReader& in);

private:
    /// Forces at the current (predicted) state; with correct, also the integrator's corrector; with nextMoved
    /// (velocity Verlet only), also the predictor of the next step, which sets *nextMoved as predict() returns.
    void computeForces(bool correct, std::atomic<bool>* nextMoved = nullptr);
    /// The rest of a step whose prediction is done (moved: what it returned): time, rebuild, forces, health.
    void finishStep(bool moved, std::atomic<bool>* nextMoved);
    /// The drift beyond which the pair list is rebuilt, squared: (skin / 2)^2.
    double driftLimit2() const { return 0.25 * s_.skin * s_.skin; }
    void rebuild(bool sort);
    // Across ranks (tdm/ranks.cpp): the first cut into slabs, the rebuild that migrates particles with their springs
    // and makes the ghosts anew, the ghosts' state after every other prediction, and the ranks' agreement, after each
    // prediction, on whether to rebuild and stop and on whether a health check failed on any rank since the last
    // agreement (then every rank throws its SimulationError): one collective a step. check runs a health check,
    // keeping its failure for the agreement.
    void scatterToSlabs();
    void rebuildAcrossRanks(bool sort);
    void refreshGhosts();
    void agree(bool& moved, bool& stop);
    template <class Check>
    void check(Check run);
    double contactEnergyShare() const;
    /// Planes and walls of any shape to the current time; the candidates rebuilt if a wall moved too far.
    void moveWalls();
    /// The broad phase of walls of any shape at the current poses, the elements within each particle's radius plus
    /// margin [m]; the contacts of new particle k are those of old particle from[k] (kFresh: none; from null: the
    /// same particle).
    void buildCandidates(const std::uint32_t* from, double margin);
    /// nearPlanes_ from the positions at the last build (xAtBuild_): a particle is near when some plane lies
    /// within its radius plus half the skin, the farthest it moves before the next build; the springs and forces
    /// of the others' planes are cleared (they do not touch). None when a plane moves, or with polygons.
    void markNearPlanes();
    void checkHealth() const;
    /// After a pass that recorded its contacts: their ids, the time.
    void recorded();
    /// Throws SimulationError when a particle moves more than its radius in one step.
    void checkSpeeds() const;
    /// The state a force pass reads and writes (sv, sw: the step's mean velocities).
    ForceContext<D> context(const Vec<D>* sv, const Ang<D>* sw) const;

    World<D>& w_;
    TdmSettings s_;
    std::unique_ptr<Integrator<D>> integ_;
    VelocityVerlet<D>* verlet_ = nullptr;  ///< integ_ when it is velocity Verlet (its corrector is fused)
    PairList<D> pairs_;
    ForceScratch<D> scratch_;
    StepMotion<D> motion_;
    std::vector<Vec<D>> wallHistory_;
    std::vector<Vec<D>> planeForce_;  ///< with planeLoads: each (particle, plane) contact's force [N]
    SurfaceState<D> surf_;
    bool staticSurfaces_ = true;  ///< no wall of any shape moves: candidates with the pair list reach skin/2 (rebuild)
    std::vector<Vec<D>> xAtBuild_;
    std::vector<std::uint8_t> nearPlanes_;  ///< markNearPlanes; empty: every particle tests every plane
    std::vector<Vec<D>> planesAtMark_;      ///< the planes' points and normals then (a plane moved since: unmarked)
    ForceStats stats_;
    std::unique_ptr<ShapePass> shapes_;  ///< 2D scenes with polygons: their force pass
    std::uint64_t steps_ = 0, rebuilds_ = 0, lastSort_ = 0;
    double t0_ = 0;                         ///< world.time at construction [s]
    ContactSink<D>* recordSink_ = nullptr;  ///< recordContactsAt
    ContactSink<D>* recordNow_ = nullptr;   ///< the sink, during the force pass that records
    double recordTime_ = 0, recordedAt_ = -1;
    bool pristine_ = true;        ///< nothing since the constructor's force pass (recordStartContacts)
    struct Halo;                  ///< across ranks: the slabs, the ghosts and who sends them (tdm/halo.hpp)
    std::unique_ptr<Halo> halo_;  ///< null in one process
    std::size_t nOwned_ = 0;      ///< across ranks: particles [0, nOwned_) are this rank's, the rest ghosts
    std::string failure_;         ///< across ranks: a health check's failure since the last agreement
};

}  // namespace haet
