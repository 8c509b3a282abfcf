#pragma once
// A 3-vector held in one 4-lane register, the fourth lane zero, for the contact kernel of the 3D force loop
// (tdm/disk_kernel.hpp): with AVX an add, subtract or scale is one instruction instead of three (GCC does not
// vectorise the 3-element loops of Vec<3> itself). Lane by lane the arithmetic is that of Vec<3> in the same
// order: dot products sum (x y) + (x y) + (z z) left to right; no fused multiply-add under -ffp-contract=off.
// Storage stays Vec<3> (24 bytes): Wide3 lives in registers only.
#ifdef __AVX__
#include <immintrin.h>
#endif

#include "core/lane_shuffle.hpp"
#include "core/vec.hpp"

namespace haet {

struct Wide3 {
    using Lanes = double __attribute__((vector_size(32)));
    Lanes l;

    static Wide3 zero() { return {Lanes{0, 0, 0, 0}}; }
    static Wide3 of(const Vec<3>& a) {
#ifdef __AVX__
        // Spelled out: the generic form compiles to a register-to-register vmovq that valgrind 3.19 (the
        // instruction counts of bench/README.md) cannot decode.
        return {_mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(&a.c[0])), _mm_load_sd(&a.c[2]), 1)};
#else
        return {Lanes{a[0], a[1], a[2], 0}};
#endif
    }
    Vec<3> vec() const { return Vec<3>{{l[0], l[1], l[2]}}; }

    Wide3& operator+=(const Wide3& o) {
        l += o.l;
        return *this;
    }
    Wide3& operator-=(const Wide3& o) {
        l -= o.l;
        return *this;
    }
    Wide3& operator*=(double s) {
        l *= s;
        return *this;
    }
    friend Wide3 operator+(Wide3 a, const Wide3& b) { return {a.l + b.l}; }
    friend Wide3 operator-(Wide3 a, const Wide3& b) { return {a.l - b.l}; }
    friend Wide3 operator*(Wide3 a, double s) { return {a.l * s}; }
};

inline double dot(const Wide3& a, const Wide3& b) {
    const Wide3::Lanes p = a.l * b.l;
    return p[0] + p[1] + p[2];
}
inline double norm2(const Wide3& a) { return dot(a, a); }
/// a x b, component for component as cross(Vec<3>, Vec<3>).
inline Wide3 cross(const Wide3& a, const Wide3& b) {
    const Wide3::Lanes a1 = shuffleLanes<1, 2, 0, 3>(a.l), b1 = shuffleLanes<2, 0, 1, 3>(b.l);
    const Wide3::Lanes a2 = shuffleLanes<2, 0, 1, 3>(a.l), b2 = shuffleLanes<1, 2, 0, 3>(b.l);
    return {a1 * b1 - a2 * b2};
}

/// The vector type of hot loops for N-vectors: Wide3 for 3-vectors when the target has AVX (one register per
/// vector), Vec<N> otherwise. Results are the same bits either way. kernelVec() loads, storedVec() stores.
template <int N>
struct KernelVecOf {
    using type = Vec<N>;
    static Vec<N> of(const Vec<N>& a) { return a; }
};
#ifdef __AVX__
template <>
struct KernelVecOf<3> {
    using type = Wide3;
    static Wide3 of(const Vec<3>& a) { return Wide3::of(a); }
};
#endif
template <int N>
using KernelVec = typename KernelVecOf<N>::type;
template <int N>
inline KernelVec<N> kernelVec(const Vec<N>& a) {
    return KernelVecOf<N>::of(a);
}
template <int N>
inline Vec<N> storedVec(const Vec<N>& a) {
    return a;
}
inline Vec<3> storedVec(const Wide3& a) { return a.vec(); }

}  // namespace haet
