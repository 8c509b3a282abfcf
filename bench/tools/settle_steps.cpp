// The scene of bench/polygon_settle.cpp stepped a given number of times, for instruction counts of a window of
// steps (callgrind counts a whole run; the difference of two runs isolates the steps between them):
//
//   haet_settle_steps hexagons|disks STEPS [THREADS]
//
// Prints the contacts of the last step and a checksum of the positions and the angles (disks: spins).
#include <cstdio>
#include <cstdlib>
#include <string>

#include "polygon_settle.cpp"

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s hexagons|disks STEPS [THREADS]\n", argv[0]);
        return 2;
    }
    const bool polygons = std::string(argv[1]) == "hexagons";
    const int steps = std::atoi(argv[2]);
    omp_set_num_threads(argc > 3 ? std::atoi(argv[3]) : 1);
    const haet::Scenario sc = scene();
    haet::World<2> w = packing(sc, polygons);
    haet::TdmEngine<2> eng(w, haet::tdmSettings<2>(sc, w));
    for (int k = 0; k < steps; ++k) eng.step();
    double sum = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i)
        sum += w.particles.x[i][0] * double(1 + i % 7) + (polygons ? w.particles.angle[i][0] : w.particles.w[i][0]);
    std::printf("%s, %d steps: %zu contacts, checksum %.17g\n", argv[1], steps, eng.forceStats().contacts, sum);
    return 0;
}
