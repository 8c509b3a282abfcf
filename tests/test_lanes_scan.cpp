// The lane primitives of the event-driven engine's candidate scan (core/lanes_scan.hpp) against their portable twins:
// the same results on random inputs (empty cells at random, the offset tables of the event grid padded as the engine
// pads them, batches that match in all, some or none of their lanes, records of any values). In a build without
// AVX2 both sides are the portable code and the test checks nothing more than that it runs.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "core/lanes_scan.hpp"

namespace haet {
namespace {

template <int N>
void compareHeads(const std::vector<std::uint32_t>& heads, const std::int32_t* offsets, std::uint32_t centre) {
    std::uint32_t fast[N + 8], twin[N + 8];
    std::fill(std::begin(fast), std::end(fast), 0u);
    std::fill(std::begin(twin), std::end(twin), 0u);
    const int nf = compactHeads<N>(&heads[centre], offsets, fast);
    const int nt = portable::compactHeads<N>(&heads[centre], offsets, twin);
    ASSERT_EQ(nf, nt);
    for (int q = 0; q < nt; ++q) EXPECT_EQ(fast[q], twin[q]) << "head " << q;
}

TEST(LanesScan, CompactHeadsMatchesItsTwin) {
    std::mt19937 rng(7);
    // A 3D grid of 10^3 cells: the 27 offsets around a cell, and the 9 of one side, padded to eight with zeros.
    const std::int32_t sx = 1, sy = 10, sz = 100;
    std::array<std::int32_t, 32> full{};
    std::array<std::int32_t, 16> side{};
    int q = 0, p = 0;
    for (int c = 0; c < 27; ++c) {
        const int ox = c % 3 - 1, oy = (c / 3) % 3 - 1, oz = c / 9 - 1;
        full[q++] = ox * sx + oy * sy + oz * sz;
        if (ox == 1) side[p++] = ox * sx + oy * sy + oz * sz;
    }
    // 2D: 9 around, 3 on a side.
    std::array<std::int32_t, 16> full2{};
    std::array<std::int32_t, 8> side2{};
    q = p = 0;
    for (int c = 0; c < 9; ++c) {
        const int ox = c % 3 - 1, oy = c / 3 - 1;
        full2[q++] = ox * sx + oy * sy;
        if (oy == -1) side2[p++] = ox * sx + oy * sy;
    }
    std::vector<std::uint32_t> heads(1000);
    for (int round = 0; round < 2000; ++round) {
        const double empty = (round % 5) / 4.0;  // from no empty cell to all empty
        for (auto& h : heads)
            h = std::uniform_real_distribution<double>(0, 1)(rng) < empty ? kLaneNil : rng() % 1000000;
        const std::uint32_t centre = 111 + rng() % 700;
        compareHeads<27>(heads, full.data(), centre);
        compareHeads<9>(heads, side.data(), centre);
        compareHeads<9>(heads, full2.data(), centre);
        compareHeads<3>(heads, side2.data(), centre);
    }
}

TEST(LanesScan, FourMatchMatchesItsTwin) {
    std::mt19937 rng(11);
    const int targets[2] = {1, 2};
    const void* ptrs[3] = {&targets[0], &targets[1], nullptr};
    for (int round = 0; round < 20000; ++round) {
        const std::uint32_t word = rng() % 3;
        std::uint32_t words[4];
        const void* p[4];
        for (int l = 0; l < 4; ++l) {
            // Mostly matching lanes, so that every pattern of matches comes up.
            words[l] = rng() % 4 == 0 ? rng() % 3 : word;
            p[l] = rng() % 4 == 0 ? ptrs[rng() % 3] : ptrs[0];
        }
        EXPECT_EQ(fourMatch(words, word, p, ptrs[0]), portable::fourMatch(words, word, p, ptrs[0]));
    }
}

TEST(LanesScan, Transpose4x6MatchesItsTwin) {
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> u(-1e3, 1e3);
    alignas(16) double rec[4][6];
    for (int round = 0; round < 1000; ++round) {
        for (auto& r : rec)
            for (double& x : r) x = u(rng);
        Lanes::Values fast[6], twin[6];
        transpose4x6(rec[0], rec[1], rec[2], rec[3], fast);
        portable::transpose4x6(rec[0], rec[1], rec[2], rec[3], twin);
        for (int c = 0; c < 6; ++c)
            for (int l = 0; l < 4; ++l) {
                EXPECT_EQ(std::memcmp(&fast[c][l], &twin[c][l], sizeof(double)), 0)
                    << "element " << c << ", lane " << l;
                EXPECT_EQ(twin[c][l], rec[l][c]);
            }
    }
}

}  // namespace
}  // namespace haet
