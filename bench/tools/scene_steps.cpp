// A scene of examples/ stepped by the time-driven engine, one window of it timed: the HAET half of the benchmarks
// that compare whole scenes with another code or with a variant of themselves (bench/compare_liggghts.sh,
// bench/mesh_floor.sh). The other code times its own stepping loop the same way (LIGGGHTS: the "Loop time" of a
// `run` after the one that lets the flow start), so neither counts reading the input or building the world.
//
//   haet_scene_steps SCENE [--set KEY=VALUE]... [--settle N] [--steps M] [--windows K] [--threads T]
//                    [--below Z] [--write FILE]
//
// Steps the scene N steps (untimed), then K windows of M steps, each one advanceTo as a run steps from one output
// time to the next; --write saves the state after them as a LAMMPS data file (atom_style sphere, with velocities),
// the start of another benchmark. Prints one line of KEY=VALUE: the particles, the steps, the fastest and the
// median window and all windows together in ns per particle-step (wall time; the fastest and the median also by the
// process's CPU time, which stops while it waits for a core), and what the state holds, so that two codes or two
// variants can be checked to simulate the same thing: the particles with centre below z = Z before and after the
// windows; at the end the pair contacts, the wall contacts, the particles touching a wall, the kinetic energy; the
// pair-list builds during the windows.
//
// Under callgrind, --toggle-collect='timedWindows*' counts the windows alone (bench/README.md, "Instruction counts").
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include "scenario/definition.hpp"
#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"

namespace {

struct Options {
    std::string scene, write;
    std::vector<std::string> sets;
    long settle = 0, steps = 1000, windows = 1;
    int threads = 1;
    double below = 0;
};

[[noreturn]] void usage(const char* argv0) {
    std::fprintf(stderr,
                 "usage: %s SCENE [--set KEY=VALUE]... [--settle N] [--steps M] [--windows K] [--threads T] "
                 "[--below Z] [--write FILE]\n",
                 argv0);
    std::exit(2);
}

Options parse(int argc, char** argv) {
    Options o;
    for (int k = 1; k < argc; ++k) {
        const std::string a = argv[k];
        auto value = [&]() -> std::string {
            if (k + 1 >= argc) usage(argv[0]);
            return argv[++k];
        };
        if (a == "--set")
            o.sets.push_back(value());
        else if (a == "--settle")
            o.settle = std::stol(value());
        else if (a == "--steps")
            o.steps = std::stol(value());
        else if (a == "--windows")
            o.windows = std::stol(value());
        else if (a == "--threads")
            o.threads = std::stoi(value());
        else if (a == "--below")
            o.below = std::stod(value());
        else if (a == "--write")
            o.write = value();
        else if (!a.empty() && a[0] != '-' && o.scene.empty())
            o.scene = a;
        else
            usage(argv[0]);
    }
    if (o.scene.empty() || o.settle < 0 || o.steps < 1 || o.windows < 1 || o.threads < 1) usage(argv[0]);
    return o;
}

/// The CPU time of the process so far [ns]: it stops while the process waits for a core, so on a busy machine it
/// is the steadier clock.
double cpuNs() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return 1e9 * static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec);
}

/// The timed part, out of line so that callgrind can count it alone: K windows of M steps; their wall times and CPU
/// times [ns].
template <int D>
[[gnu::noinline]] std::vector<double> timedWindows(haet::TdmEngine<D>& eng, haet::World<D>& w, long windows, long steps,
                                                   std::vector<double>& cpu) {
    std::vector<double> ns;
    for (long r = 0; r < windows; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        const double c0 = cpuNs();
        eng.advanceTo(w.time + static_cast<double>(steps) * eng.settings().dt);
        cpu.push_back(cpuNs() - c0);
        ns.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count());
    }
    return ns;
}

/// The state as a LAMMPS data file for atom_style sphere (id type diameter density x y z; velocities and spins), in
/// the order of the particles' ids, the box the scene's domain.
template <int D>
void writeLammpsData(const std::string& path, const haet::World<D>& w, const std::string& title) {
    const haet::Particles<D>& p = w.particles;
    std::vector<std::size_t> order(p.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
    std::size_t types = 1;
    for (std::size_t i = 0; i < p.size(); ++i) types = std::max<std::size_t>(types, p.material[i] + 1u);
    std::FILE* f = std::fopen((path + ".tmp").c_str(), "w");
    if (!f) {
        std::fprintf(stderr, "cannot write %s\n", path.c_str());
        std::exit(1);
    }
    std::fprintf(f, "%s\n\n%zu atoms\n%zu atom types\n\n", title.c_str(), p.size(), types);
    const char* axes = "xyz";
    for (int a = 0; a < 3; ++a) {
        const double lo = a < D ? w.domain.lo[a] : -0.5, hi = a < D ? w.domain.hi[a] : 0.5;
        std::fprintf(f, "%.17g %.17g %clo %chi\n", lo, hi, axes[a], axes[a]);
    }
    std::fprintf(f, "\nAtoms # sphere\n\n");
    for (std::size_t n = 0; n < order.size(); ++n) {
        const std::size_t i = order[n];
        const double r = p.radius[i];
        const double density = p.mass[i] / (4.0 / 3.0 * 3.14159265358979323846 * r * r * r);
        std::fprintf(f, "%zu %d %.17g %.17g %.17g %.17g %.17g\n", n + 1, p.material[i] + 1, 2 * r, density, p.x[i][0],
                     p.x[i][1], D == 3 ? p.x[i][D - 1] : 0.0);
    }
    std::fprintf(f, "\nVelocities\n\n");
    for (std::size_t n = 0; n < order.size(); ++n) {
        const std::size_t i = order[n];
        double spin[3] = {0, 0, 0};
        if constexpr (D == 3)
            for (int a = 0; a < 3; ++a) spin[a] = p.w[i][a];
        else
            spin[2] = p.w[i][0];
        std::fprintf(f, "%zu %.17g %.17g %.17g %.17g %.17g %.17g\n", n + 1, p.v[i][0], p.v[i][1],
                     D == 3 ? p.v[i][2] : 0.0, spin[0], spin[1], spin[2]);
    }
    if (std::fclose(f) != 0 || std::rename((path + ".tmp").c_str(), path.c_str()) != 0) {
        std::fprintf(stderr, "cannot write %s\n", path.c_str());
        std::exit(1);
    }
}

template <int D>
int run(const Options& o, const haet::Scenario& sc) {
    haet::World<D> w = haet::buildWorld<D>(sc);
    haet::TdmEngine<D> eng(w, haet::tdmSettings<D>(sc, w));
    if (o.settle > 0) eng.advanceTo(w.time + static_cast<double>(o.settle) * eng.settings().dt);
    const std::uint64_t before = eng.steps(), builds = eng.rebuilds();
    std::size_t belowBefore = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i) belowBefore += w.particles.x[i][D - 1] < o.below;
    std::vector<double> cpu;
    const std::vector<double> ns = timedWindows(eng, w, o.windows, o.steps, cpu);
    const long done = static_cast<long>(eng.steps() - before);
    if (done != o.windows * o.steps) {
        std::fprintf(stderr, "the windows took %ld steps, not %ld\n", done, o.windows * o.steps);
        return 1;
    }
    const double n = static_cast<double>(w.particles.size());
    std::vector<double> sorted = ns, sortedCpu = cpu;
    std::sort(sorted.begin(), sorted.end());
    std::sort(sortedCpu.begin(), sortedCpu.end());
    const double total = std::accumulate(ns.begin(), ns.end(), 0.0);

    const haet::Particles<D>& p = w.particles;
    std::size_t below = 0;
    double ke = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        below += p.x[i][D - 1] < o.below;
        ke += 0.5 * p.mass[i] * haet::norm2(p.v[i]);
    }
    const std::size_t walls = eng.wallContacts();
    const std::size_t all = eng.forceStats().contacts;
    // The particles touching a wall (any number of its contacts counting once, as LIGGGHTS's per-particle wall
    // force tells them): every element of every wall tested, at the walls' poses now.
    std::size_t onWall = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        bool touches = false;
        for (const haet::Wall<D>& plane : w.walls)
            touches = touches || haet::dot(p.x[i] - plane.pointAt(w.time), plane.normal) < p.radius[i];
        for (const haet::SurfaceWall<D>& s : w.surfaces) {
            const haet::Vec<D> xb = s.motion.at(w.time).toBody(p.x[i]);
            for (std::size_t e = 0; e < s.elementCount() && !touches; ++e)
                s.contacts(e, xb, p.radius[i], [&](const haet::SurfaceHit<D>&) { touches = true; });
        }
        onWall += touches;
    }
    std::printf(
        "particles=%zu settle=%ld steps=%ld windows=%ld threads=%d min_ns_per_particle_step=%.3f "
        "median_ns_per_particle_step=%.3f ns_per_particle_step=%.3f window_s=%.4f min_cpu_ns_per_particle_step=%.3f "
        "median_cpu_ns_per_particle_step=%.3f below_before=%zu below=%zu "
        "pair_contacts=%zu wall_contacts=%zu on_wall=%zu kinetic_energy=%.9g rebuilds=%llu time=%.9g\n",
        p.size(), o.settle, o.steps, o.windows, o.threads, sorted.front() / (n * o.steps),
        sorted[sorted.size() / 2] / (n * o.steps), total / (n * o.steps * o.windows), total * 1e-9,
        sortedCpu.front() / (n * o.steps), sortedCpu[sortedCpu.size() / 2] / (n * o.steps), belowBefore, below,
        all - walls, walls, onWall, ke, static_cast<unsigned long long>(eng.rebuilds() - builds), w.time);
    if (!o.write.empty())
        writeLammpsData<D>(o.write, w,
                           "HAET " + sc.name + " after " + std::to_string(eng.steps()) +
                               " steps (bench/tools/"
                               "scene_steps.cpp)");
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const Options o = parse(argc, argv);
    omp_set_num_threads(o.threads);
    try {
        const haet::Scenario sc = haet::loadScenario(o.scene, o.sets);
        if (sc.method != haet::Method::Tdm) {
            std::fprintf(stderr, "%s: the scene's method must be \"tdm\"\n", o.scene.c_str());
            return 2;
        }
        return sc.dimension == 3 ? run<3>(o, sc) : run<2>(o, sc);
    } catch (const haet::ScenarioError& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}
