// Cost of a polygon step against a disk step: 10 000 hexagons settling in a box, and the same 10 000 particles as
// disks, one and two threads. Both start as a dense triangular packing of 100 rows of 100 (lattice constant a = 2 mm,
// gaps of 0.1 % a) in a box with a floor and two side walls, under gravity, so that every particle presses on its
// six neighbours from the first steps: hexagons of flat-to-flat width 0.999 a (circumradius 1.153 mm), disks of
// diameter 0.999 a. Same time step (1.5e-5 s) and integrator (Gear5) for both; the polygon law with Y = 1000 N/m,
// the linear disk law with a similar stiffness (t_c = 3e-4 s). 300 steps are run first (not timed), then each
// iteration times 200 steps. Counters: particle_steps_per_s, contacts per particle. The cost ratio of a polygon
// step to a disk step is the ratio of the two particle_steps_per_s at the same thread count (bench/run_all.sh).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <string>

#include "polygon/geometry.hpp"
#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"

namespace {

constexpr double kA = 0.002;  // lattice constant [m]
constexpr int kRows = 100, kCols = 100;

haet::Scenario scene() {
    // 100.5 a wide (alternate rows shift by a/2), rows sqrt(3)/2 a apart: examples/hexagon_bed2d.toml.
    return haet::loadScenario(std::string(HAET_SOURCE_DIR) + "/examples/hexagon_bed2d.toml");
}

haet::World<2> packing(const haet::Scenario& sc, bool polygons) {
    haet::World<2> w = haet::buildWorld<2>(sc);  // no [[insert]]: box, walls
    const double h = 0.5 * std::sqrt(3.0) * kA, width = 0.999 * kA;
    const double R = width / std::sqrt(3.0);  // hexagon circumradius, flat-to-flat = width
    for (int r = 0; r < kRows; ++r)
        for (int c = 0; c < kCols; ++c) {
            const haet::Vec<2> x{{(c + 0.5 + 0.5 * (r % 2)) * kA, (r + 0.5) * h + 1e-4}};
            const std::uint64_t id = w.particles.size();
            if (polygons)  // vertices at 30 + 60 k degrees: flat faces towards the six neighbours
                w.particles.addPolygon(x, haet::Vec<2>::zero(), haet::Ang<2>::zero(), 0.0,
                                       haet::polygon::regularPolygon(6, R, 3.14159265358979323846 / 6), 2.0, 0, id);
            else
                w.particles.add(x, haet::Vec<2>::zero(), haet::Ang<2>::zero(), 0.5 * width, 2.0, 0, id);
        }
    w.contact = haet::buildContactSetup<2>(sc, haet::materialStats(w.particles, 1));
    return w;
}

void settle(benchmark::State& state, bool polygons) {
    const int threads = static_cast<int>(state.range(0));
    omp_set_num_threads(threads);
    const haet::Scenario sc = scene();
    haet::World<2> w = packing(sc, polygons);
    haet::TdmEngine<2> eng(w, haet::tdmSettings<2>(sc, w));
    for (int k = 0; k < 300; ++k) eng.step();
    const int steps = 200;
    double contacts = 0;
    for (auto _ : state) {
        for (int k = 0; k < steps; ++k) eng.step();
        contacts += static_cast<double>(eng.forceStats().contacts);
    }
    const double n = static_cast<double>(w.particles.size());
    state.counters["particle_steps_per_s"] =
        benchmark::Counter(n * steps * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["contacts_per_particle"] = contacts / static_cast<double>(state.iterations()) / n;
    state.counters["particles"] = n;
}

void hexagons(benchmark::State& s) { settle(s, true); }
void disks(benchmark::State& s) { settle(s, false); }

BENCHMARK(hexagons)
    ->Name("PolygonSettle2D/hexagons")
    ->Arg(1)
    ->Arg(2)
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(disks)
    ->Name("PolygonSettle2D/disks")
    ->Arg(1)
    ->Arg(2)
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
