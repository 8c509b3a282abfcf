// The long version of the mesh-prediction runs (tests/test_edm_predict_mesh.cpp, docs/physics.md D.8): 5000
// elastic bounces per run under gravity in boxes of triangles (3D) and segments (2D) with random elements inside,
// several seeds, every event checked against brute-force stepping of the distance.
#include <gtest/gtest.h>

#include <cstdio>

#include "../mesh_runs.hpp"

namespace haet {
namespace {

void report(const char* what, const meshref::RunStats& s) {
    std::printf(
        "%s: %d events (face %d, edge %d, vertex %d), %d grazing, %d at a region boundary; max |dt| %.2e s, "
        "as a distance %.2e m, max |d - a| %.2e m, max |n - grad d| %.2e\n",
        what, s.events, s.byFeature[1], s.byFeature[2], s.byFeature[3], s.grazing, s.mismatched, s.maxTimeError,
        s.maxDistError, s.maxGapError, s.maxNormalError);
}

TEST(MeshPredictValidate, TrianglesLongRuns) {
    for (const std::uint64_t seed : {101u, 102u, 103u}) {
        const auto s = meshref::runAgainstStepping<3>(seed, 5000, 24, 1e-4);
        report("3D", s);
        EXPECT_EQ(s.events, 5000);
        EXPECT_LE(s.grazing, 20);
        EXPECT_LE(s.mismatched, 20);
    }
}

TEST(MeshPredictValidate, SegmentsLongRuns) {
    for (const std::uint64_t seed : {201u, 202u, 203u}) {
        const auto s = meshref::runAgainstStepping<2>(seed, 5000, 16, 1e-4);
        report("2D", s);
        EXPECT_EQ(s.events, 5000);
        EXPECT_LE(s.grazing, 20);
        EXPECT_LE(s.mismatched, 20);
    }
}

}  // namespace
}  // namespace haet
