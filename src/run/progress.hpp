#pragma once
// The progress line of `haet run` on stderr: simulated time, steps per second, contacts, ETA. It only reads: what the
// run computes never depends on whether it shows (run/runner.cpp calls the engine in the same pieces either way).
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

namespace haet {

/// One-line progress on a terminal: simulated time, steps/s, contacts, ETA.
class Progress {
public:
    using Clock = std::chrono::steady_clock;
    Progress(bool enabled, double duration) : on_(enabled), duration_(duration), start_(Clock::now()) {}
    void update(double t, std::uint64_t steps, std::size_t contacts, bool force = false) {
        if (!on_) return;
        const auto now = Clock::now();
        if (!force && now - last_ < std::chrono::milliseconds(200)) return;
        last_ = now;
        const double el = std::chrono::duration<double>(now - start_).count();
        const double frac = std::clamp(t / duration_, 0.0, 1.0);
        const int width = 30, filled = static_cast<int>(frac * width);
        const double eta = frac > 0 ? el * (1 - frac) / frac : 0;
        std::fprintf(stderr, "\r[%s%s] t = %.4g s  %.3g steps/s  %zu contacts  ETA %.0f s   ",
                     std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), t,
                     el > 0 ? steps / el : 0.0, contacts, eta);
        std::fflush(stderr);
    }
    void finish() {
        if (on_) std::fprintf(stderr, "\n");
    }

private:
    bool on_;
    double duration_;
    Clock::time_point start_, last_{};
};

}  // namespace haet
