#pragma once
// The times at which a run writes its outputs: k x period for k = 0, 1, 2, ..., each computed as k x period (a
// sum of periods drifts: twenty additions of 0.005 are not 0.1), and each written once, even when one step of the
// engine passes several of them.
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "scenario/definition.hpp"

namespace haet {

class OutputClock {
public:
    /// period > 0 [s]; anything else: never due.
    explicit OutputClock(double period) : period_(period > 0 && std::isfinite(period) ? period : 0) {}

    /// The next scheduled time [s]: k x period to 15 significant digits (3 x 1e-4 is 0.0003, not the product's
    /// 0.00030000000000000003); infinity when the clock never ticks.
    double next() const {
        if (!(period_ > 0)) return std::numeric_limits<double>::infinity();
        return round15(static_cast<double>(k_) * period_);
    }
    /// Whether the next time has come at engine time t, which resolves times to within tol [s].
    bool due(double t, double tol) const { return next() <= t + tol; }
    /// After an output at engine time t: every scheduled time up to t + tol is done (a step longer than the period
    /// passes several: one output stands for them all).
    void pass(double t, double tol) {
        if (!(period_ > 0)) return;
        const double k = std::floor((t + tol) / period_);
        if (k + 1 > static_cast<double>(k_)) k_ = static_cast<std::uint64_t>(k) + 1;
        while (next() <= t + tol) ++k_;  // the division may round down by one
    }
    /// The time an output at engine time t carries: the scheduled time when t is that time to within rounding (a
    /// step of n dt that lands on k x period), else t to 15 significant digits (5 x 2e-6 is 1e-05, not the
    /// product's 9.999999999999999e-06).
    static double stamp(double t, double scheduled) {
        return std::abs(t - scheduled) <= 8 * DBL_EPSILON * std::abs(scheduled) ? scheduled : round15(t);
    }
    /// x to 15 significant decimal digits, the most that every double keeps through a decimal round trip.
    static double round15(double x) {
        char text[32];
        std::snprintf(text, sizeof text, "%.15g", x);
        return std::strtod(text, nullptr);
    }
    double period() const { return period_; }

private:
    double period_;
    std::uint64_t k_ = 0;
};

/// What a run will write and what it warns of, from the scenario and the engine's time step.
struct RunPlan {
    double seriesPeriod = 0;    ///< [s] between rows of series.csv
    double snapshotPeriod = 0;  ///< [s] between snapshots; <= 0: none on a schedule (the last state still is)
    /// (key, what): said on stderr when the run starts and kept in run.json under "warnings".
    std::vector<std::pair<std::string, std::string>> warnings;
};

/// dt: the engine's time step [s] (0: event-driven, none); contactTime: t_c [s]. Warns of output periods shorter than
/// dt (one output per step, never two at one time) and of a hand-set dt with fewer than 10 steps per contact.
RunPlan planRun(const Scenario& sc, double dt, double contactTime);

}  // namespace haet
