#pragma once
// Lane permutations of GCC vector types (vector_size), spelled once for the two compilers that build HAET: GCC's
// __builtin_shuffle takes the indices as a vector, clang's __builtin_shufflevector as constants (clang builds the
// fuzz targets, `make fuzz`). Both give the same permutation, so the same bits.
#include <cstddef>
#include <utility>

namespace haet {

namespace lanes_detail {
/// The integer vector GCC takes as the indices of a shuffle of a vector of `Bytes` bytes in lanes of `Lane` bytes:
/// as many lanes, each as wide (spelled per size: GCC drops a vector_size that depends on a template parameter).
template <std::size_t Bytes, std::size_t Lane>
struct IndexVec;
template <>
struct IndexVec<32, 8> {
    using type = long long __attribute__((vector_size(32)));
};
template <>
struct IndexVec<16, 8> {
    using type = long long __attribute__((vector_size(16)));
};
template <>
struct IndexVec<32, 4> {
    using type = int __attribute__((vector_size(32)));
};
template <>
struct IndexVec<16, 4> {
    using type = int __attribute__((vector_size(16)));
};
template <class V>
using IndexOf = IndexVec<sizeof(V), sizeof(std::declval<V>()[0])>;
}  // namespace lanes_detail

/// r[k] = a[I_k]: the lanes of one vector in another order.
template <int... I, class V>
[[gnu::always_inline]] inline V shuffleLanes(V a) {
    static_assert(sizeof...(I) * sizeof(a[0]) == sizeof(V), "one index per lane");
#if defined(__clang__)
    return __builtin_shufflevector(a, a, I...);
#else
    return __builtin_shuffle(a, typename lanes_detail::IndexOf<V>::type{I...});
#endif
}

/// r[k] = (a, b)[I_k]: lanes of two vectors, b's numbered after a's.
template <int... I, class V>
[[gnu::always_inline]] inline V shuffleLanes(V a, V b) {
    static_assert(sizeof...(I) * sizeof(a[0]) == sizeof(V), "one index per lane");
#if defined(__clang__)
    return __builtin_shufflevector(a, b, I...);
#else
    return __builtin_shuffle(a, b, typename lanes_detail::IndexOf<V>::type{I...});
#endif
}

}  // namespace haet
