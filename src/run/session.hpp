#pragma once
// A run in progress. `haet run` is open(), advance(duration), finish(); a script (the Python module) may call
// advance() as often as it likes in between, reading and changing the World between calls. Outputs are written on
// their schedules whatever the pieces advance() is called in. The time-driven engine computes the same bits in
// pieces that end on its steps; the event-driven engine's state depends on where its calls end (docs/edm.md).
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "run/runner.hpp"
#include "scenario/definition.hpp"
#include "world/world.hpp"

namespace haet {

class RunSession {
public:
    /// Builds the World and the engine (or takes them from the newest checkpoint with opt.resumeDir), prepares the
    /// run directory and writes run.json ("running") and the series' header. Throws ScenarioError (bad input,
    /// exit 2), std::invalid_argument (a run that cannot start as asked, exit 2) and IoError (exit 4).
    static std::unique_ptr<RunSession> open(const Scenario& sc, const RunOptions& opt, std::ostream& log);
    virtual ~RunSession() = default;

    /// Drives the run to simulated time `until` [s], writing every output due on the way (the outputs due at the
    /// current time first). Returns false once the run has stopped: a signal, or a blow-up (then status() says
    /// which and what); later calls do nothing. Throws IoError when an output cannot be written (run.json says so).
    virtual bool advance(double until) = 0;
    /// Writes the last state (a checkpoint, a row and a snapshot at the current time unless the schedule just wrote
    /// them, final.csv / final.data, run.json, final.png) and returns the run's outcome. Once; advance() does
    /// nothing after it.
    virtual RunStatus finish() = 0;

    virtual double time() const = 0;             ///< simulated time [s]
    virtual std::uint64_t steps() const = 0;     ///< time steps taken (0 for a pure event-driven run)
    virtual RunStatus status() const = 0;        ///< Completed until the run stopped early
    virtual std::string statusText() const = 0;  ///< run.json's status: "completed", "failed: what", ...
    virtual const Scenario& scenario() const = 0;
    int dimension() const { return scenario().dimension; }
    /// The World of a D-dimensional run (nullptr for the other D). Its particles are current after synchronise().
    template <int D>
    World<D>* world();
    /// Brings the World's particles to time() (an event-driven engine moves them lazily).
    virtual void synchronise() = 0;
    virtual double dt() const = 0;                               ///< the time step [s] (0 for a pure event-driven run)
    virtual const char* method() const = 0;                      ///< "tdm", "edm" or "haet"
    virtual const std::filesystem::path& directory() const = 0;  ///< where the outputs go
    /// Puts the series' rows written so far into series.csv.
    virtual void flush() = 0;
    /// A script's run: whether the next advance() catches SIGINT and SIGTERM (StopScope::Advance) or not (Never,
    /// off the main thread). Not for a run opened with StopScope::Run (std::logic_error).
    virtual void setStopScope(StopScope scope) = 0;

    // ---- changes from outside, between calls of advance(), after synchronise() ----
    /// The World's particles or gravity were changed in place: the engine starts again from them, as after the
    /// flows' changes (Driver::stateChanged).
    virtual void stateChanged() = 0;
    /// Particles [first, size()) were appended to the World: the engine takes them (as an inlet's).
    virtual void added(std::size_t first) = 0;
    /// The first of n consecutive ids for particles to be appended, from the counter the inlets draw from (ids are
    /// never reused, not even those of removed particles).
    virtual std::uint64_t takeIds(std::uint64_t n) = 0;
    /// Removes World particles `which` (ascending, distinct), as an outlet does.
    virtual void remove(const std::vector<std::uint32_t>& which) = 0;
    /// Writes a checkpoint of the state now to `file` (atomically), to start a run from (RunOptions::startFrom).
    /// Throws std::invalid_argument for a method that cannot be checkpointed, IoError.
    virtual void save(const std::filesystem::path& file) = 0;

protected:
    virtual World<2>* world2() = 0;
    virtual World<3>* world3() = 0;
};

template <>
inline World<2>* RunSession::world<2>() {
    return world2();
}
template <>
inline World<3>* RunSession::world<3>() {
    return world3();
}

}  // namespace haet
