#pragma once
// Measurements shared by the physics tests (tests/test_physics.cpp) and their long versions (tests/validate/).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "core/particles.hpp"
#include "scenario/loader.hpp"

namespace haet::testing {

/// A scene of tests/data/ (the same files `haet run` accepts).
inline Scenario dataScenario(const std::string& name) {
    return loadScenario(std::filesystem::path(HAET_SOURCE_DIR) / "tests" / "data" / name);
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

}  // namespace haet::testing
