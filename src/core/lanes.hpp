#pragma once
// Four doubles side by side, one per contact, for the force loop's contact law on four touching pairs at once
// (tdm/disk_kernel.hpp). Lane by lane the arithmetic is that of double in the same order, with the same correctly
// rounded operations (+ - * / and the square root; no fused multiply-add under -ffp-contract=off), so a contact
// evaluated in a lane gives the bits it gives alone. A branch of the scalar law becomes select(): both sides are
// computed and each lane keeps its own, which is the value its branch would have given.
//
// The contact law is written once for both (contact/laws.hpp): its scalar type S is double or Lanes, its vectors
// Vec<N> (or Wide3) or LaneVec<N>, and it uses the helpers below that have a version for each: sqrtOf, select,
// anyOf, minOf.
//
// With AVX a Lanes is one register; without it GCC splits the same code into pairs of SSE operations. Lanes2 holds
// two groups of four and runs each operation on both, one after the other (the 2D force loop's eight contacts).
#include <algorithm>
#include <cmath>
#include <cstdint>
#ifdef __AVX__
#include <immintrin.h>
#endif

#include "core/vec.hpp"

namespace haet {

/// The result of comparing Lanes: all bits set in a lane where the comparison holds.
struct LaneMask {
    using Bits = long long __attribute__((vector_size(32)));
    Bits m;
    friend LaneMask operator&(LaneMask a, LaneMask b) { return {a.m & b.m}; }
    friend LaneMask operator|(LaneMask a, LaneMask b) { return {a.m | b.m}; }
};

struct Lanes {
    using Values = double __attribute__((vector_size(32)));
    Values v;

    Lanes() = default;
    Lanes(double s) : v{s, s, s, s} {}  // NOLINT: a constant of the law, the same in every lane
    explicit Lanes(Values x) : v(x) {}

    Lanes& operator+=(Lanes o) {
        v += o.v;
        return *this;
    }
    Lanes& operator-=(Lanes o) {
        v -= o.v;
        return *this;
    }
    Lanes& operator*=(Lanes o) {
        v *= o.v;
        return *this;
    }
    friend Lanes operator+(Lanes a, Lanes b) { return Lanes(a.v + b.v); }
    friend Lanes operator-(Lanes a, Lanes b) { return Lanes(a.v - b.v); }
    friend Lanes operator*(Lanes a, Lanes b) { return Lanes(a.v * b.v); }
    friend Lanes operator/(Lanes a, Lanes b) { return Lanes(a.v / b.v); }
    friend Lanes operator-(Lanes a) { return Lanes(-a.v); }
    friend LaneMask operator<(Lanes a, Lanes b) { return {a.v < b.v}; }
    friend LaneMask operator>(Lanes a, Lanes b) { return {a.v > b.v}; }
    double operator[](int l) const { return v[l]; }
};

// The helpers, for double and for Lanes.
inline double sqrtOf(double x) { return std::sqrt(x); }
inline Lanes sqrtOf(Lanes x) {
#ifdef __AVX__
    return Lanes(_mm256_sqrt_pd(x.v));
#else
    return Lanes(Lanes::Values{std::sqrt(x.v[0]), std::sqrt(x.v[1]), std::sqrt(x.v[2]), std::sqrt(x.v[3])});
#endif
}
/// m ? a : b, lane by lane.
template <class T>
inline T select(bool m, const T& a, const T& b) {
    return m ? a : b;
}
inline Lanes select(LaneMask m, Lanes a, Lanes b) { return Lanes(m.m ? a.v : b.v); }
/// Whether the condition holds in some lane: the law skips work no lane needs.
inline bool anyOf(bool m) { return m; }
inline bool anyOf(LaneMask m) {
#ifdef __AVX__
    return _mm256_movemask_pd(reinterpret_cast<__m256d>(m.m)) != 0;
#else
    return (m.m[0] | m.m[1] | m.m[2] | m.m[3]) != 0;
#endif
}
/// The mask as four bits, lane l in bit l.
inline unsigned bitsOf(LaneMask m) {
#ifdef __AVX__
    return static_cast<unsigned>(_mm256_movemask_pd(reinterpret_cast<__m256d>(m.m)));
#else
    return unsigned(m.m[0] != 0) | unsigned(m.m[1] != 0) << 1 | unsigned(m.m[2] != 0) << 2 | unsigned(m.m[3] != 0) << 3;
#endif
}
/// std::min(a, b) = (b < a) ? b : a, lane by lane (double, Lanes, Lanes2).
template <class S>
inline S minOf(S a, S b) {
    return select(b < a, b, a);
}
/// std::max(a, b) = (a < b) ? b : a, lane by lane.
template <class S>
inline S maxOf(S a, S b) {
    return select(a < b, b, a);
}

/// Two groups of four contacts evaluated together: each operation on the first four, then the same on the
/// other four, so that the two groups' long chains (square roots, divisions) are in flight at the same time.
/// Lane by lane the arithmetic is that of Lanes.
struct LaneMask2 {
    LaneMask lo, hi;
    friend LaneMask2 operator&(LaneMask2 a, LaneMask2 b) { return {a.lo & b.lo, a.hi & b.hi}; }
    friend LaneMask2 operator|(LaneMask2 a, LaneMask2 b) { return {a.lo | b.lo, a.hi | b.hi}; }
};
struct Lanes2 {
    Lanes lo, hi;

    Lanes2() = default;
    Lanes2(double s) : lo(s), hi(s) {}  // NOLINT: a constant of the law, the same in every lane
    Lanes2(Lanes a, Lanes b) : lo(a), hi(b) {}

    Lanes2& operator+=(Lanes2 o) {
        lo += o.lo;
        hi += o.hi;
        return *this;
    }
    Lanes2& operator-=(Lanes2 o) {
        lo -= o.lo;
        hi -= o.hi;
        return *this;
    }
    Lanes2& operator*=(Lanes2 o) {
        lo *= o.lo;
        hi *= o.hi;
        return *this;
    }
    friend Lanes2 operator+(Lanes2 a, Lanes2 b) { return {a.lo + b.lo, a.hi + b.hi}; }
    friend Lanes2 operator-(Lanes2 a, Lanes2 b) { return {a.lo - b.lo, a.hi - b.hi}; }
    friend Lanes2 operator*(Lanes2 a, Lanes2 b) { return {a.lo * b.lo, a.hi * b.hi}; }
    friend Lanes2 operator/(Lanes2 a, Lanes2 b) { return {a.lo / b.lo, a.hi / b.hi}; }
    friend Lanes2 operator-(Lanes2 a) { return {-a.lo, -a.hi}; }
    friend LaneMask2 operator<(Lanes2 a, Lanes2 b) { return {a.lo < b.lo, a.hi < b.hi}; }
    friend LaneMask2 operator>(Lanes2 a, Lanes2 b) { return {a.lo > b.lo, a.hi > b.hi}; }
    double operator[](int l) const { return l < 4 ? lo[l] : hi[l - 4]; }
};
inline Lanes2 sqrtOf(Lanes2 x) { return {sqrtOf(x.lo), sqrtOf(x.hi)}; }
inline Lanes2 select(LaneMask2 m, Lanes2 a, Lanes2 b) { return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)}; }
inline bool anyOf(LaneMask2 m) {
#ifdef __AVX__
    return _mm256_movemask_pd(reinterpret_cast<__m256d>(m.lo.m | m.hi.m)) != 0;
#else
    return anyOf(m.lo) || anyOf(m.hi);
#endif
}

/// N-vectors of four contacts (L = Lanes; or eight, L = Lanes2): component c of lane l is c[c][l]. The operations
/// are those of Vec<N>, in the same order.
template <int N, class L = Lanes>
struct LaneVec {
    std::array<L, N> c;

    static LaneVec zero() {
        LaneVec r;
        for (int k = 0; k < N; ++k) r.c[k] = L(0.0);
        return r;
    }
    L& operator[](int k) { return c[k]; }
    L operator[](int k) const { return c[k]; }
    LaneVec& operator+=(const LaneVec& o) {
        for (int k = 0; k < N; ++k) c[k] += o.c[k];
        return *this;
    }
    LaneVec& operator-=(const LaneVec& o) {
        for (int k = 0; k < N; ++k) c[k] -= o.c[k];
        return *this;
    }
    LaneVec& operator*=(L s) {
        for (int k = 0; k < N; ++k) c[k] *= s;
        return *this;
    }
    friend LaneVec operator+(LaneVec a, const LaneVec& b) { return a += b; }
    friend LaneVec operator-(LaneVec a, const LaneVec& b) { return a -= b; }
    friend LaneVec operator*(LaneVec a, L s) { return a *= s; }
    /// Lane l as a Vec<N>.
    Vec<N> lane(int l) const {
        Vec<N> r;
        for (int k = 0; k < N; ++k) r[k] = c[k][l];
        return r;
    }
};

/// Eight contacts' vectors from two groups of four.
template <int N>
inline LaneVec<N, Lanes2> joinLanes(const LaneVec<N>& a, const LaneVec<N>& b) {
    LaneVec<N, Lanes2> r;
    for (int k = 0; k < N; ++k) r.c[k] = Lanes2(a.c[k], b.c[k]);
    return r;
}
/// Group g (0: the first four, 1: the other four) of eight contacts' vectors.
template <int N>
inline LaneVec<N> halfOf(const LaneVec<N, Lanes2>& a, int g) {
    LaneVec<N> r;
    for (int k = 0; k < N; ++k) r.c[k] = g == 0 ? a.c[k].lo : a.c[k].hi;
    return r;
}

/// Component k, or zeros past the last.
template <int N, class L>
inline L laneOr0(const LaneVec<N, L>& a, int k) {
    return k < N ? a.c[k] : L(0.0);
}

template <int N, class L>
inline L dot(const LaneVec<N, L>& a, const LaneVec<N, L>& b) {
    L s = a[0] * b[0];
    for (int k = 1; k < N; ++k) s += a[k] * b[k];
    return s;
}
template <int N, class L>
inline L norm2(const LaneVec<N, L>& a) {
    return dot(a, a);
}
template <class L>
inline LaneVec<2, L> cross(const LaneVec<1, L>& w, const LaneVec<2, L>& r) {
    return {{-w[0] * r[1], w[0] * r[0]}};
}
template <class L>
inline LaneVec<3, L> cross(const LaneVec<3, L>& a, const LaneVec<3, L>& b) {
    return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}
template <class L>
inline LaneVec<1, L> cross(const LaneVec<2, L>& r, const LaneVec<2, L>& f) {
    return {{r[0] * f[1] - r[1] * f[0]}};
}
template <int N, class L, class M>
inline LaneVec<N, L> select(M m, const LaneVec<N, L>& a, const LaneVec<N, L>& b) {
    LaneVec<N, L> r;
    for (int k = 0; k < N; ++k) r.c[k] = select(m, a.c[k], b.c[k]);
    return r;
}

/// Four element indices (int32, as the AVX2 gathers take them).
using LaneIndex = std::int32_t __attribute__((vector_size(16)));

inline LaneIndex loadIndex(const std::uint32_t* p) {
    LaneIndex r;
    __builtin_memcpy(&r, p, sizeof r);
    return r;
}

/// base[idx[l]] in lane l: four loads put side by side. (The AVX2 gather instructions are slow on AMD Zen 4, where
/// they made the 3D chute's step markedly slower; bench/README.md, "Partners prefetched".)
inline Lanes gather(const double* base, LaneIndex idx) {
#ifdef __AVX__
    const __m128d lo = _mm_loadh_pd(_mm_load_sd(base + idx[0]), base + idx[1]);
    const __m128d hi = _mm_loadh_pd(_mm_load_sd(base + idx[2]), base + idx[3]);
    return Lanes(_mm256_insertf128_pd(_mm256_castpd128_pd256(lo), hi, 1));
#else
    return Lanes(Lanes::Values{base[idx[0]], base[idx[1]], base[idx[2]], base[idx[3]]});
#endif
}

/// a[idx[l]] in lane l: the four rows loaded whole and transposed.
template <int N>
inline LaneVec<N> gather(const Vec<N>* a, LaneIndex idx) {
    LaneVec<N> r;
#ifdef __AVX__
    if constexpr (N == 3) {
        // A masked load reads the three doubles only (never past the array's end).
        const __m256i m = _mm256_setr_epi64x(-1, -1, -1, 0);
        const __m256d r0 = _mm256_maskload_pd(a[idx[0]].c.data(), m), r1 = _mm256_maskload_pd(a[idx[1]].c.data(), m);
        const __m256d r2 = _mm256_maskload_pd(a[idx[2]].c.data(), m), r3 = _mm256_maskload_pd(a[idx[3]].c.data(), m);
        const __m256d ab0 = _mm256_unpacklo_pd(r0, r1), ab1 = _mm256_unpackhi_pd(r0, r1);
        const __m256d cd0 = _mm256_unpacklo_pd(r2, r3), cd1 = _mm256_unpackhi_pd(r2, r3);
        r.c[0] = Lanes(_mm256_permute2f128_pd(ab0, cd0, 0x20));
        r.c[1] = Lanes(_mm256_permute2f128_pd(ab1, cd1, 0x20));
        r.c[2] = Lanes(_mm256_permute2f128_pd(ab0, cd0, 0x31));
        return r;
    } else if constexpr (N == 2) {
        const __m256d r02 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(a[idx[0]].c.data())),
                                                 _mm_loadu_pd(a[idx[2]].c.data()), 1);
        const __m256d r13 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(a[idx[1]].c.data())),
                                                 _mm_loadu_pd(a[idx[3]].c.data()), 1);
        r.c[0] = Lanes(_mm256_unpacklo_pd(r02, r13));
        r.c[1] = Lanes(_mm256_unpackhi_pd(r02, r13));
        return r;
    }
#endif
    for (int k = 0; k < N; ++k) r.c[k] = Lanes(Lanes::Values{a[idx[0]][k], a[idx[1]][k], a[idx[2]][k], a[idx[3]][k]});
    return r;
}

/// Rows r0..r3 of four doubles each, transposed: lane l of out[c] is row l's element c.
inline void transpose4(const double* r0, const double* r1, const double* r2, const double* r3, Lanes out[4]) {
#ifdef __AVX__
    const __m256d a = _mm256_load_pd(r0), b = _mm256_load_pd(r1), c = _mm256_load_pd(r2), d = _mm256_load_pd(r3);
    const __m256d ab0 = _mm256_unpacklo_pd(a, b), ab1 = _mm256_unpackhi_pd(a, b);  // a0 b0 a2 b2 | a1 b1 a3 b3
    const __m256d cd0 = _mm256_unpacklo_pd(c, d), cd1 = _mm256_unpackhi_pd(c, d);
    out[0] = Lanes(_mm256_permute2f128_pd(ab0, cd0, 0x20));
    out[1] = Lanes(_mm256_permute2f128_pd(ab1, cd1, 0x20));
    out[2] = Lanes(_mm256_permute2f128_pd(ab0, cd0, 0x31));
    out[3] = Lanes(_mm256_permute2f128_pd(ab1, cd1, 0x31));
#else
    for (int k = 0; k < 4; ++k) out[k] = Lanes(Lanes::Values{r0[k], r1[k], r2[k], r3[k]});
#endif
}

/// The other way: lane l of in[0..3] into row l (32-byte aligned).
inline void transpose4(const Lanes in[4], double* r0, double* r1, double* r2, double* r3) {
#ifdef __AVX__
    const __m256d ab0 = _mm256_unpacklo_pd(in[0].v, in[1].v), ab1 = _mm256_unpackhi_pd(in[0].v, in[1].v);
    const __m256d cd0 = _mm256_unpacklo_pd(in[2].v, in[3].v), cd1 = _mm256_unpackhi_pd(in[2].v, in[3].v);
    _mm256_store_pd(r0, _mm256_permute2f128_pd(ab0, cd0, 0x20));
    _mm256_store_pd(r1, _mm256_permute2f128_pd(ab1, cd1, 0x20));
    _mm256_store_pd(r2, _mm256_permute2f128_pd(ab0, cd0, 0x31));
    _mm256_store_pd(r3, _mm256_permute2f128_pd(ab1, cd1, 0x31));
#else
    double* r[4] = {r0, r1, r2, r3};
    for (int l = 0; l < 4; ++l)
        for (int k = 0; k < 4; ++k) r[l][k] = in[k][l];
#endif
}

}  // namespace haet
