#pragma once
// The packing primitives of the lane layer (core/lanes.hpp): what a pass over pairs needs besides the lane
// arithmetic to move four pairs at a time between lanes and lists. Compacting the lanes a mask selects onto the end
// of a list, clearing the rows of the lanes a mask drops, widening byte codes to indices, the unsigned maximum of
// indices, the rows of a block read and written as vectors, the finiteness of a vector in one compare.
//
// Every primitive has a portable twin of the same shape in namespace portable, the reference the tests hold it to
// (tests/test_lanes_pack.cpp) and what a target without AVX2 runs. Only this file and core/lanes.hpp, core/wide3.hpp
// spell out instructions: a port (AVX-512, NEON) changes these files, not the algorithms.
#include <cstdint>
#include <cstring>
#ifdef __AVX__
#include <immintrin.h>
#endif

#include "core/lanes.hpp"
#include "core/wide3.hpp"

namespace haet {

/// Whether the lane layer has fast four-wide loads, compares and permutations (AVX2): passes over pairs then test
/// and evaluate four pairs at a time; otherwise one by one. The same bits either way.
#ifdef __AVX2__
inline constexpr bool kLanePairs = true;
#else
inline constexpr bool kLanePairs = false;
#endif
/// Whether the target has 32 vector registers (AVX-512VL): enough for two groups of four 3D pairs side by side.
#ifdef __AVX512VL__
inline constexpr bool kManyLaneRegisters = true;
#else
inline constexpr bool kManyLaneRegisters = false;
#endif

/// For each mask of four lanes, its set lanes in order (then zeros): i32 moves four 32-bit numbers, i64 four doubles
/// (as pairs of 32-bit halves).
struct CompactTables {
    alignas(16) std::int32_t i32[16][4];
    alignas(32) std::int32_t i64[16][8];
    constexpr CompactTables() : i32{}, i64{} {
        for (int m = 0; m < 16; ++m) {
            int n = 0;
            for (int l = 0; l < 4; ++l)
                if (m >> l & 1) {
                    i32[m][n] = l;
                    i64[m][2 * n] = 2 * l;
                    i64[m][2 * n + 1] = 2 * l + 1;
                    ++n;
                }
        }
    }
};
inline constexpr CompactTables kCompact{};

/// Hints that *p is read soon.
inline void prefetch(const void* p) { __builtin_prefetch(p); }

namespace portable {

/// The lanes of a mask (bits 0-3) moved to the front, in order: store() writes four values, of which the first
/// count() are the selected lanes (the others are whatever the table gives; the list's next entries overwrite them).
class Compaction {
public:
    explicit Compaction(unsigned mask) : mask_(mask), row_(kCompact.i32[mask]), row64_(kCompact.i64[mask]) {}
    unsigned count() const { return static_cast<unsigned>(__builtin_popcount(mask_)); }
    void store(double* out, Lanes v) const {
        // Moved as 32-bit halves by the table, as a permutation of eight 32-bit lanes does (the same bits past
        // count() too).
        std::uint32_t in[8], r[8];
        std::memcpy(in, &v.v, sizeof in);
        for (int h = 0; h < 8; ++h) r[h] = in[row64_[h]];
        std::memcpy(out, r, sizeof r);
    }
    void store(std::uint32_t* out, LaneIndex v) const {
        for (int l = 0; l < 4; ++l) out[l] = static_cast<std::uint32_t>(v[row_[l]]);
    }
    /// base + the selected lanes' numbers: the slots of four consecutive pairs starting at base.
    void storeIota(std::uint32_t* out, std::uint32_t base) const {
        for (int l = 0; l < 4; ++l) out[l] = base + static_cast<std::uint32_t>(row_[l]);
    }

private:
    unsigned mask_;
    const std::int32_t* row_;
    const std::int32_t* row64_;
};

/// !(a >= b) lane by lane: true where a < b or either is NaN.
inline LaneMask notGreaterEqual(Lanes a, Lanes b) { return {~(a.v >= b.v)}; }

/// Four bytes (in memory order) as four indices.
inline LaneIndex widenBytes(std::uint32_t bytes) {
    unsigned char b[4];
    std::memcpy(b, &bytes, 4);
    return LaneIndex{b[0], b[1], b[2], b[3]};
}

/// Where a lane of idx equals v, all bits set in that lane of a mask over doubles.
inline LaneMask equalTo(LaneIndex idx, std::int32_t v) {
    return {LaneMask::Bits{idx[0] == v ? -1LL : 0LL, idx[1] == v ? -1LL : 0LL, idx[2] == v ? -1LL : 0LL,
                           idx[3] == v ? -1LL : 0LL}};
}

/// Lane by lane the unsigned maximum (indices as unsigned numbers).
inline LaneIndex maxIndex(LaneIndex a, LaneIndex b) {
    LaneIndex r;
    for (int l = 0; l < 4; ++l)
        r[l] = static_cast<std::uint32_t>(a[l]) < static_cast<std::uint32_t>(b[l]) ? b[l] : a[l];
    return r;
}
/// The unsigned maximum of a's lane 0 and j; the other lanes kept.
inline LaneIndex maxIndex(LaneIndex a, std::uint32_t j) {
    if (static_cast<std::uint32_t>(a[0]) < j) a[0] = static_cast<std::int32_t>(j);
    return a;
}
/// The unsigned maximum of the four lanes.
inline std::uint32_t maxLane(LaneIndex a) {
    std::uint32_t m = static_cast<std::uint32_t>(a[0]);
    for (int l = 1; l < 4; ++l) m = std::max(m, static_cast<std::uint32_t>(a[l]));
    return m;
}

/// Four N-vectors in a row (4 N doubles from rows): the vectors of the lanes not in keep set to zero bitwise,
/// those in keep left with their bits.
template <int N>
inline void clearRows(double* rows, LaneMask keep) {
    for (int l = 0; l < 4; ++l)
        for (int c = 0; c < N; ++c) {
            std::uint64_t b;
            std::memcpy(&b, rows + N * l + c, 8);
            b &= static_cast<std::uint64_t>(keep.m[l]);
            std::memcpy(rows + N * l + c, &b, 8);
        }
}

/// A vector into a row of four doubles (32-byte aligned), zero-padded.
template <int N>
inline void storeRow(double* row, const KernelVec<N>& v) {
    const Vec<N> a = storedVec(v);
    for (int k = 0; k < 4; ++k) row[k] = k < N ? a[k] : 0.0;
}
/// The first N numbers of a row as a vector.
template <int N>
inline KernelVec<N> rowVec(const double* row) {
    Vec<N> a;
    for (int k = 0; k < N; ++k) a[k] = row[k];
    return kernelVec(a);
}

/// Whether every component is finite (inf - inf and NaN - NaN are NaN, anything else minus itself is 0).
template <int N>
inline bool allFinite(const Vec<N>& v) {
    double s = 0;
    for (int k = 0; k < N; ++k) s += v[k] - v[k];
    return s == 0;
}
inline bool allFinite(const Wide3& v) {
    const Wide3::Lanes z = v.l - v.l;
    return (z[0] == 0) & (z[1] == 0) & (z[2] == 0);
}

}  // namespace portable

#ifdef __AVX2__
class Compaction {
public:
    explicit Compaction(unsigned mask)
        : mask_(mask),
          p64_(_mm256_load_si256(reinterpret_cast<const __m256i*>(kCompact.i64[mask]))),
          p32_(_mm_load_si128(reinterpret_cast<const __m128i*>(kCompact.i32[mask]))) {}
    unsigned count() const { return static_cast<unsigned>(__builtin_popcount(mask_)); }
    void store(double* out, Lanes v) const {
        _mm256_storeu_pd(out, _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(v.v), p64_)));
    }
    void store(std::uint32_t* out, LaneIndex v) const {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out),
                         _mm_castps_si128(_mm_permutevar_ps(_mm_castsi128_ps(reinterpret_cast<__m128i>(v)), p32_)));
    }
    void storeIota(std::uint32_t* out, std::uint32_t base) const {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_add_epi32(_mm_set1_epi32(static_cast<int>(base)), p32_));
    }

private:
    unsigned mask_;
    __m256i p64_;
    __m128i p32_;
};

inline LaneMask notGreaterEqual(Lanes a, Lanes b) {
    return {reinterpret_cast<LaneMask::Bits>(_mm256_cmp_pd(a.v, b.v, _CMP_NGE_UQ))};
}
inline LaneIndex widenBytes(std::uint32_t bytes) {
    return reinterpret_cast<LaneIndex>(_mm_cvtepu8_epi32(_mm_cvtsi32_si128(static_cast<int>(bytes))));
}
inline LaneMask equalTo(LaneIndex idx, std::int32_t v) {
    return {reinterpret_cast<LaneMask::Bits>(
        _mm256_cvtepi32_epi64(_mm_cmpeq_epi32(reinterpret_cast<__m128i>(idx), _mm_set1_epi32(v))))};
}
inline LaneIndex maxIndex(LaneIndex a, LaneIndex b) {
    return reinterpret_cast<LaneIndex>(_mm_max_epu32(reinterpret_cast<__m128i>(a), reinterpret_cast<__m128i>(b)));
}
inline LaneIndex maxIndex(LaneIndex a, std::uint32_t j) {
    return reinterpret_cast<LaneIndex>(
        _mm_max_epu32(reinterpret_cast<__m128i>(a), _mm_cvtsi32_si128(static_cast<int>(j))));
}
inline std::uint32_t maxLane(LaneIndex a) {
    __m128i m = reinterpret_cast<__m128i>(a);
    m = _mm_max_epu32(m, _mm_shuffle_epi32(m, 0x4E));
    m = _mm_max_epu32(m, _mm_shuffle_epi32(m, 0xB1));
    return static_cast<std::uint32_t>(_mm_cvtsi128_si32(m));
}
template <int N>
inline void clearRows(double* h, LaneMask keep) {
    // Each lane's mask spread over its vector's N doubles.
    const __m256d k = reinterpret_cast<__m256d>(keep.m);
    if constexpr (N == 3) {
        _mm256_storeu_pd(h, _mm256_and_pd(_mm256_loadu_pd(h), _mm256_permute4x64_pd(k, 0x40)));
        _mm256_storeu_pd(h + 4, _mm256_and_pd(_mm256_loadu_pd(h + 4), _mm256_permute4x64_pd(k, 0xA5)));
        _mm256_storeu_pd(h + 8, _mm256_and_pd(_mm256_loadu_pd(h + 8), _mm256_permute4x64_pd(k, 0xFE)));
    } else if constexpr (N == 2) {
        _mm256_storeu_pd(h, _mm256_and_pd(_mm256_loadu_pd(h), _mm256_permute4x64_pd(k, 0x50)));
        _mm256_storeu_pd(h + 4, _mm256_and_pd(_mm256_loadu_pd(h + 4), _mm256_permute4x64_pd(k, 0xFA)));
    } else {
        portable::clearRows<N>(h, keep);
    }
}
#else
using portable::clearRows;
using portable::Compaction;
using portable::equalTo;
using portable::maxIndex;
using portable::maxLane;
using portable::notGreaterEqual;
using portable::widenBytes;
#endif

#ifdef __AVX__
template <int N>
inline void storeRow(double* row, const KernelVec<N>& v) {
    if constexpr (N == 3)
        _mm256_store_pd(row, v.l);
    else
        portable::storeRow<N>(row, v);
}
template <int N>
inline KernelVec<N> rowVec(const double* row) {
    if constexpr (N == 3)
        return Wide3{_mm256_blend_pd(_mm256_load_pd(row), _mm256_setzero_pd(), 8)};
    else
        return portable::rowVec<N>(row);
}
template <int N>
inline bool allFinite(const Vec<N>& v) {
    return portable::allFinite(v);
}
inline bool allFinite(const Wide3& v) {
    // One compare of the lanes with zero (false for NaN) and its sign bits.
    const Wide3::Lanes z = v.l - v.l;
    return (_mm256_movemask_pd(_mm256_cmp_pd(z, _mm256_setzero_pd(), _CMP_EQ_OQ)) & 7) == 7;
}
#else
using portable::allFinite;
using portable::rowVec;
using portable::storeRow;
#endif

}  // namespace haet
