#pragma once
// Long random runs for the mesh predictions (docs/physics.md D.8), shared by the fast tests and tests/validate/: a
// particle under gravity bounces elastically inside a closed box made of segments (2D) or triangles (3D) with
// random elements inside; every event the prediction (the earliest over all elements of predictSegment or
// predictTriangle) is checked against the reference twin, brute-force stepping of the distance (mesh_reference.hpp),
// then the particle is moved to the contact and reflected about the predicted normal, so the next prediction
// starts from a touching, receding state (docs/physics.md D.6).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/rng.hpp"
#include "mesh_reference.hpp"

namespace haet::meshref {

struct RunStats {
    int events = 0;
    int grazing = 0;            ///< contacts shallower than the stepping resolves (the predicted one is checked)
    int mismatched = 0;         ///< feature differs from the reference's at a region boundary (point agrees)
    int byFeature[4] = {};      ///< events per MeshFeature
    double maxTimeError = 0;    ///< max |t - t_ref| (s)
    double maxDistError = 0;    ///< max |t - t_ref| times the approach speed (m): the error as a distance
    double maxGapError = 0;     ///< max |distance - a| of the reference at the predicted time (m)
    double maxNormalError = 0;  ///< max |n - grad distance| at the predicted contact
};

inline MeshContact<2> predictElement(const Vec<2>& x, const Vec<2>& v, const Vec<2>& g, double a,
                                     const std::array<Vec<2>, 2>& e, double tMax) {
    return predictSegment(x, v, g, a, makeMeshSegment(e[0], e[1]), tMax);
}
inline MeshContact<3> predictElement(const Vec<3>& x, const Vec<3>& v, const Vec<3>& g, double a,
                                     const std::array<Vec<3>, 3>& e, double tMax) {
    return predictTriangle(x, v, g, a, makeMeshTriangle(e), tMax);
}

template <int D>
Vec<D> randomIn(Rng& rng, double lo, double hi) {
    Vec<D> p;
    for (int k = 0; k < D; ++k) p[k] = rng.uniform(lo, hi);
    return p;
}

/// The box [0, L]^D as elements (2D: 4 segments; 3D: 12 triangles) and `inner` random elements inside.
template <int D>
Scene<D> randomScene(Rng& rng, double L, int inner) {
    Scene<D> s;
    if constexpr (D == 2) {
        const Vec<2> c[4] = {Vec<2>{{0, 0}}, Vec<2>{{L, 0}}, Vec<2>{{L, L}}, Vec<2>{{0, L}}};
        for (int k = 0; k < 4; ++k) s.add({c[k], c[(k + 1) % 4]});
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
                s.add({q[0], q[1], q[2]});
                s.add({q[0], q[2], q[3]});
            }
    }
    for (int i = 0; i < inner; ++i) {
        const double size = rng.uniform(0.3, 2.0);
        const Vec<D> c = randomIn<D>(rng, 0.2 * L, 0.8 * L);
        typename Scene<D>::Element e;
        for (auto& p : e) p = c + randomIn<D>(rng, -size, size);
        s.add(e);
    }
    return s;
}

/// Runs `events` bounces and checks each against the reference (stepping with step h). Returns the statistics.
template <int D>
RunStats runAgainstStepping(std::uint64_t seed, int events, int inner, double h) {
    Rng rng(seed, 900 + D);
    const double L = 4, a = 0.25;
    const Scene<D> scene = randomScene<D>(rng, L, inner);
    Vec<D> g = randomIn<D>(rng, -1, 1);
    g[D - 1] = -9.81;
    Vec<D> x;
    do x = randomIn<D>(rng, a, L - a);
    while (scene.gap(toL(x), a) < 0.05);
    Vec<D> v = randomIn<D>(rng, -3, 3);
    RunStats st;
    int zeroInARow = 0;
    for (int ev = 0; ev < events; ++ev) {
        // The prediction: the earliest over the elements, ties to the lower index.
        MeshContact<D> best;
        int which = -1;
        for (std::size_t i = 0; i < scene.elements.size(); ++i) {
            const MeshContact<D> c = predictElement(x, v, g, a, scene.elements[i], best.time);
            if (c.time < best.time) best = c, which = static_cast<int>(i);
        }
        if (which < 0) {
            ADD_FAILURE() << "event " << ev << ": no contact predicted in a closed box";
            return st;
        }
        const double tp = best.time;
        const LD tEnd = tp + 10 * h;
        const LD tr = steppedContact(scene, x, v, g, a, h, tEnd);
        const auto& elem = scene.elements[static_cast<std::size_t>(which)];
        const VL<D> cp = centre(x, v, g, tp);
        const Closest<D> ref = closest(cp, elem);
        const double gapError = std::abs(double(ref.dist - a));
        st.maxGapError = std::max(st.maxGapError, gapError);
        EXPECT_LT(gapError, 1e-10) << "event " << ev << ": the predicted contact is not at distance a";
        if (tr == kNever || tr > tp + 1e-9) {
            ++st.grazing;  // a touch shorter than a step of the stepping: the gap check above holds for it
        } else {
            const double slope = approachSpeed(scene, x, v, g, a, tr);
            const double err = std::abs(double(tp - tr));
            st.maxTimeError = std::max(st.maxTimeError, err);
            st.maxDistError = std::max(st.maxDistError, err * std::abs(slope));
            EXPECT_LE(err, 1e-11 + 1e-13 / std::max(std::abs(slope), 1e-300))
                << "event " << ev << ": predicted " << tp << ", stepping " << (double)tr << ", slope " << slope;
        }
        // The feature and the contact point: the reference's closest point on the predicted element.
        VL<D> point = toL(best.point);
        if (ref.feature != best.feature || ref.index != best.index) {
            ++st.mismatched;
            EXPECT_LT(double(normL(sub(ref.q, point))), 1e-7) << "event " << ev << ": feature differs";
        } else {
            EXPECT_LT(double(normL(sub(ref.q, point))), 1e-9) << "event " << ev;
        }
        ++st.byFeature[static_cast<int>(best.feature)];
        // The normal is the gradient of the distance to the element at the centre (central differences).
        double nerr = 0;
        for (int k = 0; k < D; ++k) {
            VL<D> up = cp, down = cp;
            const LD d = 1e-6L;
            up[k] += d;
            down[k] -= d;
            const LD grad = (closest(up, elem).dist - closest(down, elem).dist) / (2 * d);
            nerr = std::max(nerr, std::abs(double(grad) - best.normal[k]));
        }
        st.maxNormalError = std::max(st.maxNormalError, nerr);
        EXPECT_LT(nerr, 1e-8) << "event " << ev << ": normal is not the gradient of the distance";
        // Move to the contact and reflect (elastic): the next prediction starts touching and receding.
        for (int k = 0; k < D; ++k) x[k] = double(cp[k]);
        v = v + g * tp;
        const double vn = dot(v, best.normal);
        if (vn < 0) v = v - best.normal * (2 * vn);
        zeroInARow = tp == 0 ? zeroInARow + 1 : 0;
        if (zeroInARow > 100) {
            ADD_FAILURE() << "event " << ev << ": a loop of zero-time events";
            return st;
        }
        ++st.events;
        if (::testing::Test::HasFailure()) return st;
    }
    return st;
}

}  // namespace haet::meshref
