#pragma once
// Small fixed-size vectors for D = 2 or 3, and the angular quantities that go with them.
// In 2D an angular velocity or torque is a scalar about z, stored as Vec<1>; in 3D it is a Vec<3>.
#include <array>
#include <cmath>

namespace haet {

template <int N>
struct Vec {
    std::array<double, N> c{};

    constexpr double& operator[](int k) { return c[k]; }
    constexpr double operator[](int k) const { return c[k]; }

    static constexpr Vec zero() { return Vec{}; }
    static constexpr Vec filled(double s) {
        Vec r;
        for (int k = 0; k < N; ++k) r.c[k] = s;
        return r;
    }

    constexpr Vec& operator+=(const Vec& o) {
        for (int k = 0; k < N; ++k) c[k] += o.c[k];
        return *this;
    }
    constexpr Vec& operator-=(const Vec& o) {
        for (int k = 0; k < N; ++k) c[k] -= o.c[k];
        return *this;
    }
    constexpr Vec& operator*=(double s) {
        for (int k = 0; k < N; ++k) c[k] *= s;
        return *this;
    }
    friend constexpr Vec operator+(Vec a, const Vec& b) { return a += b; }
    friend constexpr Vec operator-(Vec a, const Vec& b) { return a -= b; }
    friend constexpr Vec operator*(Vec a, double s) { return a *= s; }
    friend constexpr Vec operator*(double s, Vec a) { return a *= s; }
    friend constexpr Vec operator/(Vec a, double s) { return a *= (1.0 / s); }
    friend constexpr Vec operator-(Vec a) {
        for (int k = 0; k < N; ++k) a.c[k] = -a.c[k];
        return a;
    }
    friend constexpr bool operator==(const Vec& a, const Vec& b) { return a.c == b.c; }
};

template <int N>
constexpr double dot(const Vec<N>& a, const Vec<N>& b) {
    double s = a[0] * b[0];  // not 0 + ...: the compiler must keep an add of +0 (it turns -0 into +0)
    for (int k = 1; k < N; ++k) s += a[k] * b[k];
    return s;
}
template <int N>
constexpr double norm2(const Vec<N>& a) {
    return dot(a, a);
}
template <int N>
inline double norm(const Vec<N>& a) {
    return std::sqrt(norm2(a));
}

/// Number of components of an angular quantity (spin, torque) in D dimensions.
template <int D>
inline constexpr int kAngDim = (D == 2) ? 1 : 3;
template <int D>
using Ang = Vec<kAngDim<D>>;

/// w x r : velocity of a point at offset r on a body spinning with w.
inline Vec<2> cross(const Vec<1>& w, const Vec<2>& r) { return Vec<2>{{-w[0] * r[1], w[0] * r[0]}}; }
inline Vec<3> cross(const Vec<3>& a, const Vec<3>& b) {
    return Vec<3>{{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}
/// r x F : torque of force F applied at offset r (2D: the z component).
inline Vec<1> cross(const Vec<2>& r, const Vec<2>& f) { return Vec<1>{{r[0] * f[1] - r[1] * f[0]}}; }

}  // namespace haet
