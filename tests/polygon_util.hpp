#pragma once
// Scenes shared by the polygon tests (tests/test_polygon_physics.cpp) and their long versions (tests/validate/).
#include <algorithm>
#include <cmath>
#include <vector>

#include "contact/setup.hpp"
#include "core/rng.hpp"
#include "geometry/surface.hpp"
#include "physics_util.hpp"
#include "polygon/geometry.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world_util.hpp"

namespace haet::testing {

/// Relative change of the kinetic energy (translation + rotation) over one collision of two random convex polygons
/// (elastic, frictionless: no damping, no friction), integrated with Gear5 at dtFactor x the polygon rule.
/// `seed` picks the shapes, orientations, the sideways offset of the approach and the spins.
/// `law`, `young` [N/m]: the normal law and its stiffness.
inline double collisionEnergyChange(std::uint64_t seed, double dtFactor, PolygonLaw law = PolygonLaw::OverlapArea,
                                    double young = 1e4) {
    Rng rng(seed, 777);
    Scenario sc = linearScenario(2, 1.0, 1e-3, 0.0, TangentialLaw::None);
    sc.materials[0].young = young;
    sc.contact.polygonLaw = law;
    sc.materials[0].density = 2.0;
    World<2> w;
    w.domain = openBox<2>(0.1);
    const double R = 0.002;
    const int n1 = 3 + int(rng.uniform() * 8), n2 = 3 + int(rng.uniform() * 8);
    const auto a = polygon::randomConvexPolygon(rng, n1, R, 1.8, 0.0);
    const auto b = polygon::randomConvexPolygon(rng, n2, R, 1.8, 0.0);
    const double off = rng.uniform(-1.2, 1.2) * R;
    const double spin = rng.uniform(-60, 60);
    w.particles.addPolygon(Vec<2>{{-1.05 * R, 0}}, Vec<2>{{0.1, 0}}, Ang<2>{{spin}}, rng.uniform(0, 6.3), a, 2.0, 0, 0);
    w.particles.addPolygon(Vec<2>{{1.05 * R, off}}, Vec<2>{{-0.1, 0}}, Ang<2>::zero(), rng.uniform(0, 6.3), b, 2.0, 0,
                           1);
    w.contact = buildContactSetup<2>(sc, materialStats(w.particles, 1));
    TdmSettings s;
    s.integrator = IntegratorKind::Gear5;
    s.dt = w.contact.polygonStep * dtFactor;
    s.skin = 0.2 * R;
    s.sortEvery = 0;
    TdmEngine<2> eng(w, s);
    const Particles<2>& p = w.particles;
    auto energy = [&]() {
        return 0.5 * (p.mass[0] * norm2(p.v[0]) + p.inertia(0) * norm2(p.w[0]) + p.mass[1] * norm2(p.v[1]) +
                      p.inertia(1) * norm2(p.w[1]));
    };
    const double e0 = energy();
    bool touched = false;
    // Until the bodies have met and parted (or, if they miss each other, until they are well apart).
    while (w.time < 0.1) {
        eng.step();
        const bool contact = eng.forceStats().contacts > 0;
        touched = touched || contact;
        if (touched && !contact) break;
    }
    return energy() / e0 - 1;
}

/// Energy of the elastic, frictionless polygon gas of examples/elastic_polygon_gas.toml (120 polygons, Gear5 at the
/// polygon time step) under the normal law `law`, Young's modulus `young` [N/m] (0: the file's), over `steps` steps.
/// The energy is read at instants without any contact, where it is purely kinetic.
struct GasEnergy {
    double drift = 0;       ///< largest |E / E0 - 1| over the contact-free instants
    int samples = 0;        ///< contact-free instants
    double collisions = 0;  ///< contact-steps / 10 (a contact lasts about ten steps)
    double maxOverlap = 0;  ///< largest overlap depth A/|c| over the smaller bounding radius
    std::size_t particles = 0;
};

inline GasEnergy gasEnergy(PolygonLaw law, int steps, double young = 0) {
    Scenario sc = exampleScenario("elastic_polygon_gas.toml");
    sc.contact.polygonLaw = law;
    if (young > 0) sc.materials[0].young = young;
    World<2> w = buildWorld<2>(sc);
    TdmEngine<2> eng(w, tdmSettings<2>(sc, w));
    const double e0 = kineticEnergy(w.particles);
    GasEnergy g;
    g.particles = w.particles.size();
    double contactSteps = 0;
    for (int k = 1; k <= steps; ++k) {
        eng.step();
        const ForceStats& fs = eng.forceStats();
        contactSteps += double(fs.contacts);
        g.maxOverlap = std::max(g.maxOverlap, fs.maxOverlapRatio);
        if (fs.contacts == 0) {
            g.drift = std::max(g.drift, std::abs(kineticEnergy(w.particles) / e0 - 1));
            ++g.samples;
        }
    }
    g.collisions = contactSteps / 10;
    return g;
}

}  // namespace haet::testing

namespace haet::testing {

/// Angle of repose of a heap on the floor y = 0 [degrees]: the surface profile h(x) (highest particle top in bins of
/// `bin` width: polygon vertices, disk tops) is fitted by h = a - s |x - x_c| over the heap's flanks: the bins of
/// the contiguous stretch around the highest bin where h > 25 % of the highest H, with h between 25 % and 90 % of H
/// (grains thrown clear of the heap and the rounded top do not count); x_c is the highest bin's centre. The angle
/// is atan(s).
inline double reposeAngle(const Particles<2>& p, double bin) {
    double xc = 0, m = 0, lo = 1e300, hi = -1e300;
    for (std::size_t i = 0; i < p.size(); ++i) {
        xc += p.mass[i] * p.x[i][0];
        m += p.mass[i];
        lo = std::min(lo, p.x[i][0] - p.radius[i]);
        hi = std::max(hi, p.x[i][0] + p.radius[i]);
    }
    xc /= m;
    const int nb = std::max(1, int(std::ceil((hi - lo) / bin)));
    std::vector<double> h(nb, 0.0);
    for (std::size_t i = 0; i < p.size(); ++i) {
        std::vector<Vec<2>> pts;
        if (p.isPolygon(i)) {
            const double c = std::cos(p.angle[i][0]), s = std::sin(p.angle[i][0]);
            const Vec<2>* v = p.shapes.of(p.shape[i]);
            for (int k = 0; k < p.shapes.count(p.shape[i]); ++k) pts.push_back(p.x[i] + polygon::rotate(v[k], c, s));
        } else {
            pts.push_back(p.x[i] + Vec<2>{{0, p.radius[i]}});
        }
        for (const Vec<2>& q : pts) {
            const int b = std::clamp(int((q[0] - lo) / bin), 0, nb - 1);
            h[b] = std::max(h[b], q[1]);
        }
    }
    const int top = int(std::max_element(h.begin(), h.end()) - h.begin());
    const double H = h[top];
    xc = lo + (top + 0.5) * bin;
    int first = top, last = top;
    while (first > 0 && h[first - 1] > 0.25 * H) --first;
    while (last + 1 < nb && h[last + 1] > 0.25 * H) ++last;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (int b = first; b <= last; ++b) {
        if (h[b] > 0.9 * H) continue;
        const double x = std::abs(lo + (b + 0.5) * bin - xc);
        sx += x, sy += h[b], sxx += x * x, sxy += x * h[b];
        ++n;
    }
    if (n < 2) return 0;
    const double slope = -(n * sxy - sx * sy) / (n * sxx - sx * sx);
    return std::atan(std::max(slope, 0.0)) * 180 / 3.14159265358979323846;
}

/// Runs a pile scenario to its end and returns the angle of repose [degrees] (bins of one largest diameter).
inline double pileAngle(const Scenario& sc) {
    World<2> w = buildWorld<2>(sc);
    TdmEngine<2> eng(w, tdmSettings<2>(sc, w));
    eng.advanceTo(sc.duration);
    double dmax = 0;
    for (double r : w.particles.radius) dmax = std::max(dmax, 2 * r);
    return reposeAngle(w.particles, dmax);
}

}  // namespace haet::testing

namespace haet::testing {

/// A bed of random polygons (about 55, circumradii 1.5-2 mm) in a drum of radius 3 cm turning at 1 rad/s under
/// gravity: settled for `settle` seconds, then averaged over `average` seconds (every 20 steps). The drum is a circle,
/// or (segments > 0) a closed polyline of that many segments inscribed in it.
struct DrumBed {
    double torque = 0;        ///< the bed's torque on the drum about its axis [N m]
    double weightTorque = 0;  ///< -g M x_cm, the weight's torque about the axis [N m]
    double liftAngle = 0;     ///< the bed's centre of mass from the lowest point, in the turning direction [degrees]
    std::size_t particles = 0;
};

inline DrumBed drumBed(int segments, double settle, double average) {
    const double Rd = 0.03, omega = 1.0, g = 9.81, pi = 3.14159265358979323846;
    World<2> w;
    w.domain = openBox<2>(0.05);
    w.domain.gravity = Vec<2>{{0, -g}};
    Rng rng(21, 3);
    std::uint64_t id = 0;
    for (double y = -Rd + 0.003; y < -0.004; y += 0.0042)
        for (double x = -Rd; x < Rd; x += 0.0042)
            if (x * x + y * y < (Rd - 0.0025) * (Rd - 0.0025))
                w.particles.addPolygon(
                    Vec<2>{{x, y}}, Vec<2>::zero(), Ang<2>::zero(), rng.uniform(0, 6.3),
                    polygon::randomConvexPolygon(rng, 4 + int(rng.uniform() * 5), rng.uniform(0.0015, 0.002), 1.5, 0.0),
                    2.0, 0, id++);
    SurfaceWall<2> drum;
    if (segments > 0) {
        std::vector<std::array<Vec<2>, 2>> segs;
        for (int k = 0; k < segments; ++k) {
            const double a = 2 * pi * k / segments, b = 2 * pi * (k + 1) / segments;
            segs.push_back(
                {Vec<2>{{Rd * std::cos(a), Rd * std::sin(a)}}, Vec<2>{{Rd * std::cos(b), Rd * std::sin(b)}}});
        }
        buildMesh<2>(drum, segs);
    } else {
        drum.kind = SurfaceKind::Arc;
        drum.radius = Rd;
        drum.angle1 = 2 * pi;
    }
    drum.motion.omega = omega;
    w.surfaces.push_back(drum);
    Scenario sc = linearScenario(2, 0.3, 1e-3, 0.5, TangentialLaw::Spring);
    sc.materials[0].young = 1000;
    sc.materials[0].density = 2.0;
    w.contact = buildContactSetup<2>(sc, materialStats(w.particles, 1));
    TdmSettings s;
    s.integrator = IntegratorKind::Gear5;
    s.dt = w.contact.polygonStep;
    s.skin = 0.0004;
    s.sortEvery = 0;
    TdmEngine<2> eng(w, s);
    eng.advanceTo(settle);
    const Particles<2>& p = w.particles;
    DrumBed b;
    double sx = 0, sy = 0, m = 0;
    int n = 0;
    while (w.time < settle + average) {
        for (int k = 0; k < 20; ++k) eng.step();
        double mx = 0, my = 0;
        m = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            mx += p.mass[i] * p.x[i][0];
            my += p.mass[i] * p.x[i][1];
            m += p.mass[i];
        }
        b.torque += eng.surfaceLoad(0).torque[0];
        b.weightTorque += -g * mx;
        sx += mx / m;
        sy += my / m;
        ++n;
    }
    b.torque /= n;
    b.weightTorque /= n;
    b.liftAngle = std::atan2(sx, -sy) * 180 / pi;  // counter-clockwise turning lifts the bed to the right (x > 0)
    b.particles = p.size();
    return b;
}

}  // namespace haet::testing
