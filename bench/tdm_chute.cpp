// The granular chute of bench/compare_lammps.sh (examples/lammps_chute3d.toml, lammps_chute2d.toml: the LAMMPS
// flowing state), one thread, timed in short windows of steps. The machine is shared and its speed changes within
// a minute; the fastest window is what the code costs when nothing else runs, so two builds compare by their
// minima (and, less sharply, their medians) rather than by the time of a whole run. A window is one advanceTo, as
// a run steps from one output time to the next (and LAMMPS runs a window: one `run`). Counters: ns per
// particle-step, the minimum and the median over the windows.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"

namespace {

template <int D>
void chute(benchmark::State& state) {
    omp_set_num_threads(1);
    const int windows = static_cast<int>(state.range(0)), steps = static_cast<int>(state.range(1));
    const std::string root = std::string(HAET_SOURCE_DIR) + "/";
    const std::string data = root + (D == 3 ? "bench/data/chute3d.flowing.data" : "bench/data/chute2d.flowing.data");
    if (!std::filesystem::exists(data)) {
        state.SkipWithError(
            ("no " + data + ": bench/compare_lammps.sh prepares it (make bench runs it first)").c_str());
        return;
    }
    const haet::Scenario sc =
        haet::loadScenario(root + (D == 3 ? "examples/lammps_chute3d.toml" : "examples/lammps_chute2d.toml"));
    haet::World<D> w = haet::buildWorld<D>(sc);
    haet::TdmEngine<D> eng(w, haet::tdmSettings<D>(sc, w));
    for (int k = 0; k < steps; ++k) eng.step();  // the first list build and the caches warm
    const double n = static_cast<double>(w.particles.size());
    std::vector<double> ns;
    std::uint64_t done = eng.steps();
    bool exact = true;
    for (auto _ : state) {
        for (int r = 0; r < windows; ++r) {
            const auto t0 = std::chrono::steady_clock::now();
            eng.advanceTo(w.time + steps * eng.settings().dt);
            const std::chrono::duration<double, std::nano> dt = std::chrono::steady_clock::now() - t0;
            ns.push_back(dt.count() / (n * steps));
            exact = exact && eng.steps() == done + static_cast<std::uint64_t>(steps);
            done = eng.steps();
        }
    }
    if (!exact) {
        state.SkipWithError("a window did not take the steps it was timed for");
        return;
    }
    std::sort(ns.begin(), ns.end());
    state.counters["min_ns_per_particle_step"] = ns.front();
    state.counters["median_ns_per_particle_step"] = ns[ns.size() / 2];
}

void chute3(benchmark::State& s) { chute<3>(s); }
void chute2(benchmark::State& s) { chute<2>(s); }

// 40 windows of 25 steps (3D: ~0.1 s each), 1 000 steps in all.
BENCHMARK(chute3)->Name("TdmChute3D")->Args({40, 25})->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(chute2)->Name("TdmChute2D")->Args({40, 50})->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
