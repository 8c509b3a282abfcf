#pragma once
// Measurements shared by the physics tests (tests/test_physics.cpp) and their long versions (tests/validate/).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "scenario/loader.hpp"

namespace haet::testing {

/// A scene of examples/ (the files `haet run` runs), with `overrides` as `haet run --set` takes them.
inline Scenario exampleScenario(const std::string& name, const std::vector<std::string>& overrides = {}) {
    return loadScenario(std::filesystem::path(HAET_SOURCE_DIR) / "examples" / name, overrides);
}

/// The mean of a sample and its standard deviation (n - 1 in the denominator; 0 for fewer than two values).
struct SampleStats {
    double mean = 0, sd = 0;
};
inline SampleStats sampleStats(const std::vector<double>& v) {
    SampleStats s;
    for (double x : v) s.mean += x;
    s.mean /= double(v.size());
    double var = 0;
    for (double x : v) var += (x - s.mean) * (x - s.mean);
    s.sd = v.size() > 1 ? std::sqrt(var / double(v.size() - 1)) : 0;
    return s;
}

/// Whether two arrays hold the same bits (not only equal values: -0 and 0, NaNs told apart).
template <class T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
    // Empty vectors may hold no storage at all: memcmp of a null pointer is undefined even for 0 bytes.
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/// A measured value in the test's XML report (--gtest_output=xml), to follow margins over time.
inline void record(const std::string& key, double value) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", value);
    ::testing::Test::RecordProperty(key, buf);
}

/// Translational + rotational kinetic energy [J].
template <int D>
double kineticEnergy(const Particles<D>& p) {
    double e = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
        e += 0.5 * p.mass[i] * norm2(p.v[i]) + 0.5 * p.inertia(i) * norm2(p.w[i]);
    return e;
}

template <int D>
Vec<D> momentum(const Particles<D>& p) {
    Vec<D> s = Vec<D>::zero();
    for (std::size_t i = 0; i < p.size(); ++i) s += p.v[i] * p.mass[i];
    return s;
}

/// Sum of |m v| over particles: the scale against which round-off in the total momentum is judged.
template <int D>
double momentumScale(const Particles<D>& p) {
    double s = 0;
    for (std::size_t i = 0; i < p.size(); ++i) s += p.mass[i] * norm(p.v[i]);
    return s;
}

/// Volume (3D) or area (2D) fraction covered by the particles inside the box [lo, hi], by sampling a regular grid of
/// spacing h (error ~ (h/a)^2, well below 1e-3 for h = a/10).
template <int D>
double coveredFraction(const Particles<D>& p, const Vec<D>& lo, const Vec<D>& hi, double h) {
    std::array<long, 3> n{1, 1, 1};
    for (int k = 0; k < D; ++k) n[k] = std::max(1L, static_cast<long>((hi[k] - lo[k]) / h));
    std::vector<std::uint8_t> covered(n[0] * n[1] * n[2], 0);
    auto centre = [&](int k, long c) { return lo[k] + (c + 0.5) * (hi[k] - lo[k]) / n[k]; };
    for (std::size_t i = 0; i < p.size(); ++i) {
        std::array<long, 3> c0{0, 0, 0}, c1{0, 0, 0};
        bool outside = false;
        for (int k = 0; k < D; ++k) {
            const double cell = (hi[k] - lo[k]) / n[k];
            c0[k] = std::max(0L, static_cast<long>(std::floor((p.x[i][k] - p.radius[i] - lo[k]) / cell)));
            c1[k] = std::min(n[k] - 1, static_cast<long>(std::floor((p.x[i][k] + p.radius[i] - lo[k]) / cell)));
            if (c0[k] > c1[k]) outside = true;
        }
        if (outside) continue;
        const double r2 = p.radius[i] * p.radius[i];
        for (long a = c0[0]; a <= c1[0]; ++a)
            for (long b = c0[1]; b <= c1[1]; ++b)
                for (long c = c0[2]; c <= c1[2]; ++c) {
                    double d2 = 0;
                    const long idx[3] = {a, b, c};
                    for (int k = 0; k < D; ++k) d2 += std::pow(centre(k, idx[k]) - p.x[i][k], 2);
                    if (d2 <= r2) covered[(a * n[1] + b) * n[2] + c] = 1;
                }
    }
    std::size_t s = 0;
    for (auto v : covered) s += v;
    return double(s) / covered.size();
}

}  // namespace haet::testing
