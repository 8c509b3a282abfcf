#pragma once
// Lane primitives of the event-driven engine's candidate scan (edm/scan.hpp): the heads of up to 27 cells with the
// empty ones dropped, the test whether four candidates need no periodic image shift, and the transpose of four 2D
// particle records into lanes. Each has a portable twin of the same shape in namespace `portable` (plain loops, the
// same results), which the instruction-set version falls back to and which tests/test_lanes_scan.cpp compares it
// against. Algorithm files use these and core/lanes.hpp, never an intrinsic of their own, so a port to another
// instruction set touches this file only.
#include <cstdint>
#ifdef __AVX__
#include <immintrin.h>
#endif

#include "core/lanes.hpp"

namespace haet {

/// The word marking an empty cell or the end of a list.
inline constexpr std::uint32_t kLaneNil = 0xFFFFFFFFu;

namespace portable {

/// The values base[offsets[q]] (q < N) that are not kLaneNil, in order, to out; returns how many. out has room for
/// eight past the last (the vector version stores whole groups of eight); offsets is padded to a multiple of eight
/// with offsets that stay inside the array (zeros).
template <int N>
inline int compactHeads(const std::uint32_t* base, const std::int32_t* offsets, std::uint32_t* out) {
    int n = 0;
    for (int q = 0; q < N; ++q) {
        const std::uint32_t h = base[offsets[q]];
        out[n] = h;
        n += h != kLaneNil;
    }
    return n;
}

/// Whether words[l] == word and ptrs[l] == ptr in all four lanes.
inline bool fourMatch(const std::uint32_t* words, std::uint32_t word, const void* const* ptrs, const void* ptr) {
    return ((words[0] ^ word) | (words[1] ^ word) | (words[2] ^ word) | (words[3] ^ word)) == 0 && ptrs[0] == ptr &&
           ptrs[1] == ptr && ptrs[2] == ptr && ptrs[3] == ptr;
}

/// Four records of six doubles (16-byte aligned), transposed: lane l of out[c] is element c of record l.
inline void transpose4x6(const double* r0, const double* r1, const double* r2, const double* r3, Lanes::Values out[6]) {
    for (int c = 0; c < 6; ++c) out[c] = Lanes::Values{r0[c], r1[c], r2[c], r3[c]};
}

}  // namespace portable

/// portable::compactHeads. With AVX2 and BMI2 eight cells at a time: one gathered load, the empty ones dropped by a
/// lane permutation made from the mask (pdep/pext), one store of all eight lanes.
template <int N>
[[gnu::always_inline]] inline int compactHeads(const std::uint32_t* base, const std::int32_t* offsets,
                                               std::uint32_t* out) {
#if defined(__AVX2__) && defined(__BMI2__)
    int n = 0;
    for (int g = 0; g < N; g += 8) {
        const __m256i idx = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(offsets + g));
        const __m256i h = _mm256_i32gather_epi32(reinterpret_cast<const int*>(base), idx, 4);
        const __m256i empty = _mm256_cmpeq_epi32(h, _mm256_set1_epi32(-1));
        unsigned m = ~static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(empty))) & 0xFFu;
        if (N - g < 8) m &= (1u << (N - g)) - 1;
        const std::uint64_t spread = _pdep_u64(m, 0x0101010101010101ull) * 0xFF;
        const std::uint64_t order = _pext_u64(0x0706050403020100ull, spread);
        const __m256i perm = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(static_cast<long long>(order)));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + n), _mm256_permutevar8x32_epi32(h, perm));
        n += __builtin_popcount(m);
    }
    return n;
#else
    return portable::compactHeads<N>(base, offsets, out);
#endif
}

/// portable::fourMatch; with AVX2 both comparisons four lanes at once, without a branch.
[[gnu::always_inline]] inline bool fourMatch(const std::uint32_t* words, std::uint32_t word, const void* const* ptrs,
                                             const void* ptr) {
#ifdef __AVX2__
    const __m128i w = _mm_loadu_si128(reinterpret_cast<const __m128i*>(words));
    const __m256i p = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ptrs));
    const __m128i sameW = _mm_cmpeq_epi32(w, _mm_set1_epi32(static_cast<int>(word)));
    const __m256i sameP = _mm256_cmpeq_epi64(p, _mm256_set1_epi64x(reinterpret_cast<long long>(ptr)));
    return (_mm_movemask_ps(_mm_castsi128_ps(sameW)) & _mm256_movemask_pd(_mm256_castsi256_pd(sameP))) == 15;
#else
    return portable::fourMatch(words, word, ptrs, ptr);
#endif
}

/// portable::transpose4x6; with AVX elements 0-3 of each record in one load, 4-5 in another, then unpacks.
[[gnu::always_inline]] inline void transpose4x6(const double* r0, const double* r1, const double* r2, const double* r3,
                                                Lanes::Values out[6]) {
#ifdef __AVX__
    const __m256d a0 = _mm256_loadu_pd(r0), a1 = _mm256_loadu_pd(r1), a2 = _mm256_loadu_pd(r2),
                  a3 = _mm256_loadu_pd(r3);
    const __m256d lo01 = _mm256_unpacklo_pd(a0, a1), hi01 = _mm256_unpackhi_pd(a0, a1);
    const __m256d lo23 = _mm256_unpacklo_pd(a2, a3), hi23 = _mm256_unpackhi_pd(a2, a3);
    out[0] = _mm256_permute2f128_pd(lo01, lo23, 0x20);
    out[1] = _mm256_permute2f128_pd(hi01, hi23, 0x20);
    out[2] = _mm256_permute2f128_pd(lo01, lo23, 0x31);
    out[3] = _mm256_permute2f128_pd(hi01, hi23, 0x31);
    const __m256d b02 = _mm256_set_m128d(_mm_load_pd(r2 + 4), _mm_load_pd(r0 + 4));
    const __m256d b13 = _mm256_set_m128d(_mm_load_pd(r3 + 4), _mm_load_pd(r1 + 4));
    out[4] = _mm256_unpacklo_pd(b02, b13);
    out[5] = _mm256_unpackhi_pd(b02, b13);
#else
    portable::transpose4x6(r0, r1, r2, r3, out);
#endif
}

}  // namespace haet
