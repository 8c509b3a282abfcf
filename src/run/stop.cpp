#include "run/stop.hpp"

#include <csignal>
#include <stdexcept>

namespace haet {
namespace {

// Lock-free atomics are safe to use in a signal handler (a plain store, no lock to be held by the interrupted code).
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free);
std::atomic<bool> gStop{false};
std::atomic<int> gSignal{0};
std::atomic<bool> gInstalled{false};
struct sigaction gOldInt, gOldTerm;

extern "C" void onStopSignal(int sig) {
    if (gStop.load()) {  // the second signal: the default action, now
        std::signal(sig, SIG_DFL);
        std::raise(sig);
        return;
    }
    gSignal.store(sig);  // before the flag, so that whoever sees the flag sees which signal set it
    gStop.store(true);
}

}  // namespace

StopSignals::StopSignals() {
    if (gInstalled.exchange(true)) throw std::logic_error("StopSignals: already installed");
    gStop = false;
    gSignal = 0;
    struct sigaction sa {};
    sa.sa_handler = onStopSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;  // a write interrupted by the signal goes on: the outputs stay whole
    sigaction(SIGINT, &sa, &gOldInt);
    sigaction(SIGTERM, &sa, &gOldTerm);
}

StopSignals::~StopSignals() {
    sigaction(SIGINT, &gOldInt, nullptr);
    sigaction(SIGTERM, &gOldTerm, nullptr);
    gInstalled = false;
}

const std::atomic<bool>* StopSignals::flag() { return &gStop; }
bool StopSignals::requested() { return gStop.load(std::memory_order_relaxed); }
int StopSignals::signal() { return gSignal.load(); }
bool StopSignals::installed() { return gInstalled.load(); }
void StopSignals::clear() {
    if (gInstalled.load()) return;
    gStop = false;
    gSignal = 0;
}

}  // namespace haet
