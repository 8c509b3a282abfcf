#include "run/schedule.hpp"

#include <fmt/format.h>

namespace haet {

RunPlan planRun(const Scenario& sc, double dt, double contactTime) {
    RunPlan p;
    p.seriesPeriod = sc.output.seriesPeriod > 0 ? sc.output.seriesPeriod : sc.duration / 100;
    p.snapshotPeriod = sc.output.snapshotPeriod == 0 ? sc.duration / 20 : sc.output.snapshotPeriod;
    // As LAMMPS's thermo and dump, which count in steps: an output period below one step gives an output per step.
    auto shorterThanStep = [&](const char* key, double period, const char* what) {
        if (dt > 0 && period > 0 && period < dt)
            p.warnings.emplace_back(key, fmt::format("{:.4g} s is shorter than the time step dt = {:.4g} s: {} every "
                                                     "step, not every {:.4g} s",
                                                     period, dt, what, period));
    };
    shorterThanStep("output.series_period", p.seriesPeriod, "a row of series.csv");
    shorterThanStep("output.snapshot_period", p.snapshotPeriod, "a snapshot");
    // docs/physics.md F.3: velocity Verlet resolves a contact with some 10 steps or more; fewer lose energy balance
    // and restitution, and below pi (omega dt = 2) the spring is unstable.
    if (sc.tdm.dt && sc.method != Method::Edm && contactTime > 0 && dt > 0 && contactTime / dt < 10)
        p.warnings.emplace_back("tdm.dt",
                                fmt::format("{:.4g} s gives {:.3g} steps per contact duration t_c = {:.4g} s; "
                                            "at least 10 are needed for the contact's restitution and "
                                            "energy (dt = \"auto\": t_c / steps_per_contact)",
                                            dt, contactTime / dt, contactTime));
    return p;
}

}  // namespace haet
