#pragma once
// Small worlds for the event-driven engine's tests, built in code: hard-sphere gases on a lattice with random
// velocities (periodic or walled, with or without gravity, equal or unequal particles) and a one-material
// contact table.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "core/rng.hpp"
#include "edm/engine.hpp"
#include "world/world.hpp"

namespace haet::testing {

inline constexpr double kPiEdm = 3.14159265358979323846;

/// A contact table with one material (or n identical ones) and the given collision-operator view.
inline ContactSetup edmContact(double e, double mu = 0, double beta0 = -1, int nMaterials = 1, double tc = 0) {
    ContactSetup cs;
    cs.nMaterials = nMaterials;
    PairCoeffs c;
    c.restitution = e;
    c.mu = mu;
    c.beta0 = beta0;
    cs.table.assign(nMaterials * nMaterials, c);
    cs.wallTable = cs.table;
    cs.contactTime = tc;
    return cs;
}

struct GasSpec {
    int n = 100;          ///< particles (a few lattice sites stay empty if n is not a cube/square)
    double phi = 0.2;     ///< volume (area) fraction of the box
    double radius = 0.5;  ///< [m]; with polydisperse = true, radii in [0.6, 1] x radius
    bool polydisperse = false;
    bool periodic = true;  ///< all axes periodic; else walls on every side
    double gravity = 0;    ///< along -last axis [m/s^2]
    double speed = 1;      ///< velocity components ~ N(0, speed) [m/s]
    double spin = 0;       ///< angular velocity components ~ N(0, spin) [rad/s]
    std::uint64_t seed = 1;
};

/// Particles on a simple cubic (square) lattice in a cubic box whose size gives the volume fraction phi.
template <int D>
World<D> makeGas(const GasSpec& g, const ContactSetup& cs) {
    World<D> w;
    w.contact = cs;
    Rng rng(g.seed, 7001);
    std::vector<double> radii(g.n);
    double vol = 0;
    for (int i = 0; i < g.n; ++i) {
        radii[i] = g.polydisperse ? g.radius * rng.uniform(0.6, 1.0) : g.radius;
        vol += Particles<D>::volumeOf(radii[i]);
    }
    const double L = std::pow(vol / g.phi, 1.0 / D);
    w.domain.lo = Vec<D>::zero();
    w.domain.hi = Vec<D>::filled(L);
    for (int k = 0; k < D; ++k) w.domain.periodic[k] = g.periodic;
    w.domain.gravity = Vec<D>::zero();
    w.domain.gravity[D - 1] = -g.gravity;
    if (!g.periodic) {
        for (int k = 0; k < D; ++k) {
            Wall<D> lo = Wall<D>::plane(Vec<D>::zero(), Vec<D>::zero(), Vec<D>::zero(), 0);
            lo.normal[k] = 1;
            Wall<D> hi = Wall<D>::plane(Vec<D>::filled(L), Vec<D>::zero(), Vec<D>::zero(), 0);
            hi.normal[k] = -1;
            w.walls.push_back(lo);
            w.walls.push_back(hi);
        }
    }
    int side = 1;
    while (std::pow(side, D) < g.n) ++side;
    const double a = L / side;
    double rmax = 0;
    for (double r : radii) rmax = std::max(rmax, r);
    if (!(a > 2 * rmax)) throw std::runtime_error("makeGas: lattice too tight for these radii; lower phi");
    for (int i = 0; i < g.n; ++i) {
        Vec<D> x;
        int r = i;
        for (int k = 0; k < D; ++k) {
            x[k] = (r % side + 0.5) * a;
            r /= side;
        }
        Vec<D> v;
        for (int k = 0; k < D; ++k) v[k] = g.speed * rng.normal();
        Ang<D> s;
        for (int k = 0; k < kAngDim<D>; ++k) s[k] = g.spin * rng.normal();
        const double density = g.polydisperse ? rng.uniform(0.5, 2.0) : 1.0;
        w.particles.add(x, v, s, radii[i], density, 0, static_cast<std::uint64_t>(i));
    }
    // Zero total momentum (periodic gases).
    if (g.periodic) {
        Vec<D> pm = Vec<D>::zero();
        double m = 0;
        for (int i = 0; i < g.n; ++i) {
            pm += w.particles.v[i] * w.particles.mass[i];
            m += w.particles.mass[i];
        }
        for (int i = 0; i < g.n; ++i) w.particles.v[i] -= pm / m;
    }
    return w;
}

template <int D>
double kineticEnergyEdm(const Particles<D>& p) {
    double e = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.frozen(i)) continue;
        e += 0.5 * p.mass[i] * norm2(p.v[i]) + 0.5 * p.inertia(i) * norm2(p.w[i]);
    }
    return e;
}

/// Largest overlap (a_i + a_j - |r_ij|) / min(a_i, a_j) over all pairs, minimum image (O(N^2)).
template <int D>
double maxOverlapRatio(const World<D>& w) {
    const auto& p = w.particles;
    double worst = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
        for (std::size_t j = i + 1; j < p.size(); ++j) {
            if (p.frozen(i) && p.frozen(j)) continue;
            const double d = norm(w.domain.minimumImage(p.x[i] - p.x[j]));
            worst = std::max(worst, (p.radius[i] + p.radius[j] - d) / std::min(p.radius[i], p.radius[j]));
        }
    return worst;
}

/// Largest penetration of a particle into a wall, over its radius.
template <int D>
double maxWallPenetration(const World<D>& w) {
    double worst = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i)
        for (const auto& wl : w.walls)
            worst = std::max(worst,
                             (w.particles.radius[i] - wl.distance(w.particles.x[i], w.time)) / w.particles.radius[i]);
    return worst;
}

}  // namespace haet::testing

namespace haet::testing {

/// Compressibility factor Z = 1 + (sum r_ij . dp_i / t_w) / sum m v^2 (docs/physics.md E.2) of an elastic smooth
/// hard-sphere (disk) gas, measured over `collisions` collisions after `equilibrate` collisions per particle;
/// shell: EdmSettings::shell.
template <int D>
double measureZ(int n, double phi, std::uint64_t collisions, double equilibrate, std::uint64_t seed, double shell = 0) {
    GasSpec g;
    g.n = n;
    g.phi = phi;
    g.seed = seed;
    World<D> w = makeGas<D>(g, edmContact(1.0));
    EdmSettings s;
    s.tcModel = false;
    s.shell = shell;
    EdmEngine<D> eng(w, s);
    double t = 0;
    while (eng.collisions() < equilibrate * n) eng.advanceTo(t += 0.5);
    eng.takeCollisionVirial();
    const double t0 = t;
    const std::uint64_t c0 = eng.collisions();
    while (eng.collisions() - c0 < collisions) eng.advanceTo(t += 0.5);
    double mv2 = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i) mv2 += w.particles.mass[i] * norm2(w.particles.v[i]);
    return 1 + eng.takeCollisionVirial() / ((t - t0) * mv2);
}

/// Carnahan-Starling (3D, docs/physics.md E.1).
inline double carnahanStarling(double phi) { return (1 + phi + phi * phi - phi * phi * phi) / std::pow(1 - phi, 3); }

/// n particles of radius 0.5 (unequal when polydisperse) on a lattice filling a closed cubic box at volume
/// fraction 0.1, falling under gravity 9.81 onto the floor: a dissipative heap (e, mu = 0.5, beta0 = 0.5).
inline World<3> pouringBox(int n, double e, double tc, std::uint64_t seed) {
    GasSpec g;
    g.n = n;
    g.phi = 0.1;
    g.periodic = false;
    g.gravity = 9.81;
    g.speed = 0.5;
    g.spin = 1;
    g.polydisperse = true;
    g.seed = seed;
    return makeGas<3>(g, edmContact(e, 0.5, 0.5, 1, tc));
}

/// How far any particle has left the box [lo, hi] (0 if none), over its radius.
template <int D>
double maxEscape(const World<D>& w) {
    double worst = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i)
        for (int k = 0; k < D; ++k) {
            const double r = w.particles.radius[i];
            worst = std::max(worst, (w.domain.lo[k] + r - w.particles.x[i][k]) / r);
            worst = std::max(worst, (w.particles.x[i][k] + r - w.domain.hi[k]) / r);
        }
    return worst;
}

}  // namespace haet::testing
