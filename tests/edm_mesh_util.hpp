#pragma once
// Worlds with mesh walls for the event-driven engine's tests (tests/test_edm_mesh.cpp, tests/validate/): gases under
// gravity in boxes made of mesh walls (segments in 2D, triangles in 3D) with random elements inside, or over a mesh
// floor across periodic axes; and the comparison of the fast engine with its reference twin, event by event.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/rng.hpp"
#include "test_edm_util.hpp"

namespace haet::testing {

template <int D>
using Corners = std::array<Vec<D>, D>;

/// A static mesh wall of the given elements (material 0).
template <int D>
SurfaceWall<D> meshWall(const std::vector<Corners<D>>& elements, int id) {
    SurfaceWall<D> w;
    w.id = id;
    buildMesh<D>(w, elements);
    return w;
}

/// The closed box [0, L]^D as elements: 2D four segments, 3D twelve triangles (each face cut along a diagonal).
template <int D>
std::vector<Corners<D>> boxElements(double L) {
    std::vector<Corners<D>> out;
    if constexpr (D == 2) {
        const Vec<2> c[4] = {Vec<2>{{0, 0}}, Vec<2>{{L, 0}}, Vec<2>{{L, L}}, Vec<2>{{0, L}}};
        for (int k = 0; k < 4; ++k) out.push_back({c[k], c[(k + 1) % 4]});
    } else {
        for (int axis = 0; axis < 3; ++axis)
            for (const double side : {0.0, L}) {
                const int u = (axis + 1) % 3, w = (axis + 2) % 3;
                Vec<3> q[4];
                for (int k = 0; k < 4; ++k) {
                    q[k][axis] = side;
                    q[k][u] = (k == 1 || k == 2) ? L : 0;
                    q[k][w] = (k >= 2) ? L : 0;
                }
                out.push_back({q[0], q[1], q[2]});
                out.push_back({q[0], q[2], q[3]});
            }
    }
    return out;
}

/// Distance from x to the nearest element of the world's meshes.
template <int D>
double meshDistance(const World<D>& w, const Vec<D>& x) {
    double d = kNever;
    for (const SurfaceWall<D>& s : w.surfaces)
        for (std::size_t e = 0; e < s.elementCount(); ++e) d = std::min(d, s.distance(e, x));
    return d;
}

struct MeshGas {
    int n = 30;             ///< particles on the lattice (fewer: those too near an element are left out)
    double L = 10;          ///< box edge [m]
    int inner = 6;          ///< random elements inside the box
    bool meshBox = true;    ///< the box's faces as one mesh wall (else planes)
    bool periodic = false;  ///< all axes but the last periodic, a mesh floor and a plane ceiling
    double e = 0.8, mu = 0.3, beta0 = 0.4;
    std::uint64_t seed = 1;
};

/// Particles of radius 0.5 (0.3 to 0.5) on a lattice in the box, with random velocities, under a gravity with a
/// component along every axis (so that edges and vertices are met at all angles), and mesh walls.
template <int D>
World<D> meshGas(const MeshGas& m) {
    World<D> w;
    w.contact = edmContact(m.e, m.mu, m.beta0);
    Rng rng(m.seed, 7101);
    const double L = m.L;
    w.domain.lo = Vec<D>::zero();
    w.domain.hi = Vec<D>::filled(L);
    for (int k = 0; k < D; ++k) w.domain.periodic[k] = m.periodic && k < D - 1;
    for (int k = 0; k < D; ++k) w.domain.gravity[k] = k == D - 1 ? -1.0 : 0.15 * (k + 1);
    std::vector<Corners<D>> box;
    if (m.periodic) {
        // A floor of elements across the periodic axes, slightly wavy and continuous across the periodic faces
        // (an even number of waves), and a plane ceiling.
        const int cells = 4;
        if constexpr (D == 2) {
            for (int k = 0; k < cells; ++k) {
                const double x0 = L * k / cells, x1 = L * (k + 1) / cells;
                box.push_back({Vec<2>{{x0, 0.2 * (k % 2)}}, Vec<2>{{x1, 0.2 * ((k + 1) % 2)}}});
            }
        } else {
            for (int i = 0; i < cells; ++i)
                for (int j = 0; j < cells; ++j) {
                    auto at = [&](int a, int b) { return Vec<3>{{L * a / cells, L * b / cells, 0.2 * ((a + b) % 2)}}; };
                    box.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
                    box.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
                }
        }
        Vec<D> top = Vec<D>::zero(), down = Vec<D>::zero();
        top[D - 1] = L;
        down[D - 1] = -1;
        w.walls.push_back(Wall<D>::plane(top, down, Vec<D>::zero(), 0));
    } else if (m.meshBox) {
        box = boxElements<D>(L);
    } else {
        for (int k = 0; k < D; ++k) {
            Vec<D> n = Vec<D>::zero();
            n[k] = 1;
            w.walls.push_back(Wall<D>::plane(Vec<D>::zero(), n, Vec<D>::zero(), 0));
            w.walls.push_back(Wall<D>::plane(Vec<D>::filled(L), n * -1.0, Vec<D>::zero(), 0));
        }
    }
    if (!box.empty()) w.surfaces.push_back(meshWall<D>(box, 0));
    std::vector<Corners<D>> inner;
    for (int q = 0; q < m.inner; ++q) {
        Vec<D> c;
        for (int k = 0; k < D; ++k) c[k] = rng.uniform(0.25 * L, 0.75 * L);
        Corners<D> el;
        for (auto& p : el)
            for (int k = 0; k < D; ++k) p[k] = c[k] + rng.uniform(-1.5, 1.5);
        inner.push_back(el);
    }
    if (!inner.empty()) w.surfaces.push_back(meshWall<D>(inner, 1));
    int side = 1;
    while (std::pow(side, D) < m.n) ++side;
    const double a = (L - 1) / side;
    for (int i = 0; i < m.n; ++i) {
        Vec<D> x;
        int r = i;
        for (int k = 0; k < D; ++k) {
            x[k] = 0.5 + (r % side + 0.5) * a;
            r /= side;
        }
        const double radius = rng.uniform(0.3, 0.5);
        if (meshDistance(w, x) < radius + 0.05) continue;
        Vec<D> v;
        for (int k = 0; k < D; ++k) v[k] = 2 * rng.normal();
        Ang<D> s;
        for (int k = 0; k < kAngDim<D>; ++k) s[k] = rng.normal();
        w.particles.add(x, v, s, radius, rng.uniform(0.5, 2.0), 0, static_cast<std::uint64_t>(i));
    }
    return w;
}

struct Logged {
    double time;
    std::uint32_t a, b;
    bool wall;
    bool operator==(const Logged& o) const { return time == o.time && a == o.a && b == o.b && wall == o.wall; }
};

template <int D>
std::vector<Logged> runLogged(World<D> w, const EdmSettings& s, double tEnd, EdmStats* stats = nullptr) {
    std::vector<Logged> log;
    EdmEngine<D> eng(w, s);
    const auto planes = static_cast<std::uint32_t>(w.walls.size());
    eng.setObserver([&](const EdmCollision<D>& c) {
        if (c.surface)
            log.push_back({c.time, c.i, planes + 1000000 * c.partner + c.element, true});
        else if (c.wall)
            log.push_back({c.time, c.i, c.partner, true});
        else
            log.push_back({c.time, std::min(c.i, c.partner), std::max(c.i, c.partner), false});
    });
    eng.advanceTo(tEnd);
    if (stats) *stats = eng.stats();
    return log;
}

/// The fast engine (cell crossings, then neighbour shells of two thicknesses) and the reference twin process the
/// same collisions in the same order at the same times, bit for bit, up to the time of the fast engine's
/// minCollisions-th collision. Returns the fast run's statistics (cell crossings).
template <int D>
EdmStats compareWithReference(const World<D>& w, EdmSettings s, std::size_t minCollisions, bool shells = true) {
    s.reference = false;
    double tEnd = 0;
    {
        World<D> probe = w;
        EdmEngine<D> eng(probe, s);
        std::size_t count = 0;
        struct Stop {};
        eng.setObserver([&](const EdmCollision<D>& c) {
            if (++count == minCollisions) {
                tEnd = c.time;
                throw Stop{};
            }
        });
        try {
            eng.advanceTo(1e6);
        } catch (const Stop&) {
        }
        tEnd = std::nextafter(tEnd, kNever);
    }
    s.reference = true;
    const std::vector<Logged> ref = runLogged(w, s, tEnd);
    EXPECT_GE(ref.size(), minCollisions);
    s.reference = false;
    EdmStats cells;
    for (const double shell : {0.0, 0.2, 0.7}) {
        if (shell > 0 && !shells) continue;
        SCOPED_TRACE(shell == 0 ? std::string("cell crossings") : "neighbour shells " + std::to_string(shell));
        s.shell = shell;
        EdmStats st;
        const std::vector<Logged> fast = runLogged(w, s, tEnd, &st);
        if (shell == 0) cells = st;
        for (std::size_t k = 0; k < std::min(ref.size(), fast.size()); ++k)
            if (!(fast[k] == ref[k])) {
                ADD_FAILURE() << "collision " << k << " differs: fast (" << fast[k].a << ", " << fast[k].b << ", wall "
                              << fast[k].wall << ", t " << fast[k].time << "), reference (" << ref[k].a << ", "
                              << ref[k].b << ", wall " << ref[k].wall << ", t " << ref[k].time << ")";
                break;
            }
        EXPECT_EQ(fast.size(), ref.size());
    }
    return cells;
}

}  // namespace haet::testing
