#pragma once
// Clean stops of `haet run`: SIGINT (Ctrl-C) and SIGTERM (a batch system's time limit, `kill`). The first one sets a
// flag the engines poll after every step (TdmSettings::stop, HaetSettings::stop) or event (EdmSettings::stop); the
// run then writes its last state and exits with 128 + the signal number (130, 143), as a shell reports a program
// killed by it. A second signal of either kind ends the program at once, as if no handler were installed.
#include <atomic>

namespace haet {

class StopSignals {
public:
    /// Installs the handlers (one instance at a time); the destructor puts the previous ones back.
    StopSignals();
    ~StopSignals();
    StopSignals(const StopSignals&) = delete;
    StopSignals& operator=(const StopSignals&) = delete;

    /// The flag the engines poll (set by the first signal). The same flag whether or not handlers are installed,
    /// so that an engine made before them (a script's run installs them only while it advances) sees them.
    static const std::atomic<bool>* flag();
    static bool requested();
    /// The signal that asked for the stop (SIGINT, SIGTERM), 0 before one came.
    static int signal();
    /// Whether an instance exists now.
    static bool installed();
    /// Clears the flag and the signal, when no instance is installed (a new piece of a script's run, after a stop).
    static void clear();
};

}  // namespace haet
