// The packing primitives of the lane layer (core/lanes_pack.hpp) against their portable twins: the same values, bit
// for bit, for every mask of four lanes and for values that include NaN, infinities and signed zeros. (Built without
// AVX2 the two are the same functions and the test checks the twins against plain loops only.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/lanes_pack.hpp"

namespace haet {
namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(LanesPack, CompactionMatchesPortableTwin) {
    const Lanes v(Lanes::Values{1.5, -0.0, kNaN, 7.25});
    const LaneIndex idx{3, 0x7FFFFFFF, -1, 42};
    for (unsigned m = 0; m < 16; ++m) {
        const Compaction fast(m);
        const portable::Compaction twin(m);
        EXPECT_EQ(fast.count(), twin.count());
        EXPECT_EQ(twin.count(), static_cast<unsigned>(__builtin_popcount(m)));
        double a[4], b[4];
        fast.store(a, v);
        twin.store(b, v);
        std::uint32_t ia[4], ib[4], sa[4], sb[4];
        fast.store(ia, idx);
        twin.store(ib, idx);
        fast.storeIota(sa, 1000);
        twin.storeIota(sb, 1000);
        for (int l = 0; l < 4; ++l) {
            EXPECT_TRUE(sameBits(a[l], b[l])) << m << " " << l;
            EXPECT_EQ(ia[l], ib[l]);
            EXPECT_EQ(sa[l], sb[l]);
        }
        // The first count() entries are the selected lanes, in order.
        int n = 0;
        for (int l = 0; l < 4; ++l)
            if (m >> l & 1) {
                EXPECT_TRUE(sameBits(b[n], v[l]));
                EXPECT_EQ(ib[n], static_cast<std::uint32_t>(idx[l]));
                EXPECT_EQ(sb[n], 1000u + static_cast<std::uint32_t>(l));
                ++n;
            }
    }
}

TEST(LanesPack, ComparesAndIndicesMatchPortableTwins) {
    const Lanes a(Lanes::Values{1.0, kNaN, 3.0, -kInf});
    const Lanes b(Lanes::Values{2.0, 1.0, 3.0, kNaN});
    EXPECT_EQ(bitsOf(notGreaterEqual(a, b)), bitsOf(portable::notGreaterEqual(a, b)));
    EXPECT_EQ(bitsOf(portable::notGreaterEqual(a, b)), 0b1011u);  // 1 < 2, NaN, 3 >= 3, NaN
    for (std::uint32_t bytes : {0x04040404u, 0x0D000D01u, 0xFF000180u}) {
        const LaneIndex f = widenBytes(bytes), t = portable::widenBytes(bytes);
        for (int l = 0; l < 4; ++l) EXPECT_EQ(f[l], t[l]);
        EXPECT_EQ(bitsOf(equalTo(f, 4)), bitsOf(portable::equalTo(t, 4)));
        EXPECT_EQ(bitsOf(equalTo(f, 13)), bitsOf(portable::equalTo(t, 13)));
    }
    EXPECT_EQ(bitsOf(portable::equalTo(portable::widenBytes(0x04010404u), 4)), 0b1011u);
    const LaneIndex x{5, -1, 7, 0}, y{6, 3, 2, -2};  // -1, -2: large unsigned numbers
    const LaneIndex mf = maxIndex(x, y), mt = portable::maxIndex(x, y);
    for (int l = 0; l < 4; ++l) EXPECT_EQ(mf[l], mt[l]);
    EXPECT_EQ(mt[1], -1);
    EXPECT_EQ(mt[3], -2);
    const LaneIndex jf = maxIndex(x, 9u), jt = portable::maxIndex(x, 9u);
    for (int l = 0; l < 4; ++l) EXPECT_EQ(jf[l], jt[l]);
    EXPECT_EQ(jt[0], 9);
    EXPECT_EQ(jt[2], 7);
    EXPECT_EQ(maxLane(y), portable::maxLane(y));
    EXPECT_EQ(portable::maxLane(LaneIndex{1, 9, 4, 2}), 9u);
}

template <int N>
void expectClearRowsMatches() {
    for (unsigned m = 0; m < 16; ++m) {
        alignas(32) double a[4 * N + 4], b[4 * N + 4];
        for (int k = 0; k < 4 * N + 4; ++k) a[k] = b[k] = k == 2 ? kNaN : (k == 3 ? -0.0 : 0.5 + k);
        const LaneMask keep{
            LaneMask::Bits{m & 1 ? -1LL : 0LL, m & 2 ? -1LL : 0LL, m & 4 ? -1LL : 0LL, m & 8 ? -1LL : 0LL}};
        clearRows<N>(a, keep);
        portable::clearRows<N>(b, keep);
        for (int k = 0; k < 4 * N + 4; ++k) EXPECT_TRUE(sameBits(a[k], b[k])) << N << " " << m << " " << k;
        for (int l = 0; l < 4; ++l)
            for (int c = 0; c < N; ++c)
                if (!(m >> l & 1)) EXPECT_TRUE(sameBits(b[N * l + c], 0.0));
        for (int k = 4 * N; k < 4 * N + 4; ++k) EXPECT_TRUE(sameBits(b[k], 0.5 + k));  // past the rows: untouched
    }
}

TEST(LanesPack, ClearRowsMatchesPortableTwin) {
    expectClearRowsMatches<2>();
    expectClearRowsMatches<3>();
}

template <int N>
void expectRowsMatch() {
    Vec<N> v;
    for (int k = 0; k < N; ++k) v[k] = k == 1 ? -0.0 : 1.0 / (k + 3);
    alignas(32) double a[4] = {9, 9, 9, 9}, b[4] = {9, 9, 9, 9};
    storeRow<N>(a, kernelVec(v));
    portable::storeRow<N>(b, kernelVec(v));
    for (int k = 0; k < 4; ++k) EXPECT_TRUE(sameBits(a[k], b[k])) << N << " " << k;
    a[3] = 5;  // the row's fourth number (a virial, an overlap) is not part of the vector
    const Vec<N> fa = storedVec(rowVec<N>(a)), fb = storedVec(portable::rowVec<N>(a));
    for (int k = 0; k < N; ++k) {
        EXPECT_TRUE(sameBits(fa[k], fb[k]));
        EXPECT_TRUE(sameBits(fa[k], v[k]));
    }
}

TEST(LanesPack, RowsMatchPortableTwins) {
    expectRowsMatch<1>();
    expectRowsMatch<2>();
    expectRowsMatch<3>();
}

TEST(LanesPack, FinitenessMatchesPortableTwin) {
    const double values[] = {0.0, -0.0, 1e308, -2.5, kInf, -kInf, kNaN};
    for (double x : values)
        for (double y : values) {
            const Vec<3> v{{1.0, x, y}};
            EXPECT_EQ(allFinite(kernelVec(v)), portable::allFinite(kernelVec(v)));
            EXPECT_EQ(portable::allFinite(v), std::isfinite(x) && std::isfinite(y));
            const Vec<2> u{{x, y}};
            EXPECT_EQ(allFinite(u), portable::allFinite(u));
        }
}

}  // namespace
}  // namespace haet
