#pragma once
// Runs a scenario: builds the world, drives the engine to the requested time, and writes every output
// (series.csv, VTK snapshots + .pvd, walls, run.json). Writers run at fixed simulated times; the engine only
// advances. Exit codes of `haet run` (docs/scenario.md, "Running"): 0 done, 2 bad input, 3 the simulation blew up
// (outputs so far kept), 4 an output could not be written, 130 / 143 stopped by SIGINT / SIGTERM (the last state
// written).
#include <filesystem>
#include <iosfwd>

#include "scenario/definition.hpp"

namespace haet {

class Ranks;

/// The progress line on stderr: Auto shows it on a terminal unless quiet. It never changes what is computed.
enum class ProgressDisplay { Auto, On, Off };

/// When a run catches SIGINT and SIGTERM to stop cleanly: for its whole life (`haet run`), only while advance() runs
/// (a script's run: Ctrl-C between its calls is the script's), or never (a run advanced off the main thread).
enum class StopScope { Run, Advance, Never };

struct RunOptions {
    std::filesystem::path outDir;  ///< empty: the scenario's [output] directory
    int threads = 0;               ///< 0: OpenMP default
    bool quiet = false;            ///< no progress bar and no summary
    ProgressDisplay progress = ProgressDisplay::Auto;
    /// Non-empty: go on from the newest whole checkpoint of this run directory (which is also the output
    /// directory), instead of starting at t = 0 (docs/scenario.md, "Resuming").
    std::filesystem::path resumeDir;
    /// When the SIGINT / SIGTERM handlers (run/stop.hpp) are installed.
    StopScope stopSignals = StopScope::Run;
    /// Non-empty: start from this checkpoint file (the state of a run saved by a script) with new outputs in the
    /// output directory, instead of from the scenario's initial state. The series starts at the checkpoint's time.
    std::filesystem::path startFrom;
    /// More than one rank (`mpirun -np N haet run`, run/ranks_mpi.hpp): a time-driven run cut into slabs, rank 0
    /// writing the outputs (docs/parallel.md). Null or one rank: the run of one process.
    Ranks* ranks = nullptr;
};

/// The exit code of `haet run` for each outcome.
enum class RunStatus { Completed = 0, BadInput = 2, BlewUp = 3, OutputFailed = 4, Interrupted = 130, Terminated = 143 };

RunStatus runScenario(const Scenario& sc, const RunOptions& opt, std::ostream& log);

/// `haet check`: what the scenario would run (particles, dt and its rule, contact duration, memory estimate).
void describeScenario(const Scenario& sc, std::ostream& out);

}  // namespace haet
