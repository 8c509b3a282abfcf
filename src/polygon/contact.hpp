#pragma once
// The overlap-area contact law of 2D polygons (Matuttis & Chen; docs/physics.md G.3), as a pure function of the overlap
// geometry and the two bodies' motion. One law serves polygon-polygon, polygon-disk and polygon-wall contacts.
//
//   normal n        perpendicular to the chord c (c: body i's outline inside body j, geometry.hpp), from j to i
//   force point     the overlap centroid C;  r_i = C - x_i, r_j = C - x_j
//   length          l = 4 |r_i| |r_j| / (|r_i| + |r_j|)   (a wall: l = 4 |r_i|); floored at lMin
//   elastic         F_el = Y A / l
//   damping         F_d = gamma sqrt(m_eff Y) (dA/dt) / l; if F_d > 2 F_el then F_d = F_el (no kick at first touch)
//                   F_n = F_el + F_d, clipped at 0 unless attraction is allowed
//   dA/dt           exact for rigid motion: -|c| (g . n) - (omega_i - omega_j) s, g the relative velocity at C
//   tangential      Cundall-Strack spring xi along t = perp(n), incremented by the mean relative velocity over the
//                   step; F_t = -k_t xi - gamma_t sqrt(k_t m_t) g_t, |F_t| <= mu F_n (slip shortens the spring),
//                   1/m_t = 1/m_i + 1/m_j + |r_i|^2/I_i + |r_j|^2/I_j
//   torques         tau_i = (r_i x F)_z, tau_j = -(r_j x F)_z, F the force on i
// Since tau_i + tau_j + (x_i - x_j) x F = 0, pair forces conserve linear and angular momentum exactly.
//
// This law has no potential: an elastic collision with spin or an offset approach changes the pair's energy, and
// the change does not vanish with dt (docs/scenario.md, Polygons). The energy-conserving variant
// (PolygonLaw::Potential, after Feng & Owen, Eng. Comput. 21, 265 (2004)) derives the force from U = Phi(A),
// Phi = Y A^2 / (2 L^2) with L^2 a constant of the pair. Since translating body i by dx changes A by
// -|c| n . dx and turning it by dphi about x_i changes A by -(s + r_i . c) dphi (geometry.hpp), -grad U is
//   elastic         F_el = Phi'(A) |c| = Y A |c| / L^2 along n
//   force point     P = C + (s / |c|^2) c, the chord's midpoint when the outlines cross twice; the torque on i is
//                   then F_el (s + r_i . c) / |c| = -dU/dphi_i
//   length          L^2 = 4 R_i R_j / (R_i + R_j) x min(R_i, R_j), from the bounding radii (a wall: 4 R_i^2): about
//                   the overlap-area law's stiffness for a flat contact as wide as the smaller bounding radius
//   damping         F_d = gamma sqrt(m_eff Y) (dA/dt) |c| / L^2, from the dissipation function
//                   gamma sqrt(m_eff Y) (dA/dt)^2 / (2 L^2); limiter and clipping as above
// and r_i, r_j, the relative velocity and the tangential force are taken at P.
#include <cmath>

#include "contact/polygon_coeffs.hpp"
#include "polygon/geometry.hpp"

namespace haet::polygon {

/// Lengths of a pair that the law takes from the bodies' bounding radii.
struct PairLengths {
    double lMin = 0;       ///< floor of l [m]
    double potential = 0;  ///< L^2 of PolygonLaw::Potential [m^2]
};

/// Two bodies of bounding radii ri, rj [m]: l >= 1 % of the smaller, L^2 = 4 ri rj / (ri + rj) x min(ri, rj).
inline PairLengths pairLengths(double ri, double rj) {
    const double rmin = std::min(ri, rj);
    return PairLengths{0.01 * rmin, 4 * ri * rj / (ri + rj) * rmin};
}

/// A body of bounding radius ri [m] against a wall (rj infinite): l >= 1 % of ri, L^2 = 4 ri^2.
inline PairLengths wallLengths(double ri) { return PairLengths{0.01 * ri, 4 * ri * ri}; }

/// Motion of one body in the pair's frame (any common origin).
struct BodyState {
    V2 x{};                 ///< centre of mass [m]
    V2 v{};                 ///< velocity [m/s] (the predicted one, seen by the damping)
    double w = 0;           ///< angular velocity [rad/s]
    V2 vStep{};             ///< mean velocity over the last step [m/s] (drives the spring)
    double wStep = 0;       ///< mean angular velocity over the last step [rad/s]
    double invMass = 0;     ///< [1/kg]; 0 for a frozen body or a wall
    double invInertia = 0;  ///< [1/(kg m^2)]; 0 for a frozen body or a wall
};

struct ContactForce {
    V2 f{};              ///< force on i [N] (on j: -f)
    double torqueI = 0;  ///< [N m]
    double torqueJ = 0;  ///< [N m]
    double fn = 0;       ///< normal force [N]
    V2 normal{};         ///< unit normal, from j to i
    V2 point{};          ///< force point, in the frame of the bodies' x [m]
    V2 ft{};             ///< the tangential part of f [N] (f = normal fn + ft)
    double length = 0;   ///< characteristic length l [m] (overlap-area law; 0 for the potential law)
};

/// Rate of change of the overlap area [m^2/s] under the bodies' rigid motion, exact (geometry.hpp):
/// dA/dt = (v_i - v_j) . (c_y, -c_x) - omega_i (s + r_i . c) + omega_j (s + r_j . c), r = C - x.
inline double areaRate(const Overlap& o, const BodyState& bi, const BodyState& bj) {
    const V2 grad{{o.chord[1], -o.chord[0]}};
    return dot(bi.v - bj.v, grad) - bi.w * (o.spin + dot(o.centroid - bi.x, o.chord)) +
           bj.w * (o.spin + dot(o.centroid - bj.x, o.chord));
}

/// The polygon laws as types, so that a force pass is instantiated per law (as the disk laws, contact/laws.hpp).
struct OverlapAreaLaw {
    static constexpr bool kPotential = false;  ///< the overlap-area law (G.3)
};
struct PotentialLaw {
    static constexpr bool kPotential = true;  ///< the energy-conserving variant, U = Y A^2 / (2 L^2)
};

/// Evaluates the law for an overlap `o` of body i (its outline gave o.chord and o.spin) with body j.
/// `wallNormal` (unit, pointing to i) replaces the chord's normal and makes j a wall: then l = 4 |r_i|.
/// xi: the tangential spring [m], stored as a vector along t so that it changes sign with the pair's order.
/// When the chord vanishes (one body inside the other) the normal falls back to the line of centres, and to +x
/// when the centres coincide; the potential law's force then vanishes with |c| (a depth that max_overlap stops).
/// Always inlined: as a call, its frame, register saves and the copies of its arguments cost the polygon force
/// pass more instructions than the call saves.
/// Law: OverlapAreaLaw or PotentialLaw (the normal force); kFriction: the tangential spring (TangentialLaw::Spring).
template <class Law, bool kFriction>
[[gnu::always_inline]] inline ContactForce polygonContact(const PolygonCoeffs& c, const Overlap& o, const BodyState& bi,
                                                          const BodyState& bj, const V2* wallNormal,
                                                          const PairLengths& len, bool attraction, double dt, V2& xi) {
    ContactForce out;
    const double clen = norm(o.chord);
    const bool hasChord = clen > 1e-12 * std::sqrt(o.area);
    V2 n;
    if (wallNormal) {
        n = *wallNormal;
    } else if (hasChord) {
        n = perp(o.chord) / clen;
    } else {
        const V2 d = bi.x - bj.x;
        const double dl = norm(d);
        n = dl > 0 ? d / dl : V2{{1.0, 0.0}};
    }
    // Elastic force [N] and force point; l (overlap-area law) or |c| / L^2 (potential law) [1/m].
    constexpr bool potential = Law::kPotential;
    double fel, l = 0, cOverL2 = 0;
    V2 at = o.centroid;
    if constexpr (potential) {
        if (hasChord) at += o.chord * (o.spin / (clen * clen));
        cOverL2 = clen / len.potential;
        fel = c.young * o.area * cOverL2;
    } else {
        const double li = norm(at - bi.x);
        if (wallNormal) {
            l = 4 * li;
        } else {
            const double lj = norm(at - bj.x);
            l = li + lj > 0 ? 4 * li * lj / (li + lj) : 0.0;
        }
        l = std::max(l, len.lMin);
        fel = c.young * o.area / l;
    }
    out.length = l;
    const V2 ri = at - bi.x, rj = at - bj.x;

    // Relative velocity of the force point, and the rate of change of the overlap area.
    const V2 g = bi.v + perp(ri) * bi.w - bj.v - perp(rj) * bj.w;
    const double dAdt = areaRate(o, bi, bj);
    const double invM = bi.invMass + bj.invMass;
    const double meff = invM > 0 ? 1.0 / invM : 0.0;
    const double damping = c.gamma * std::sqrt(meff * c.young) * dAdt;
    double fd = potential ? damping * cOverL2 : damping / l;
    if (fd > 2 * fel) fd = fel;
    double fn = fel + fd;
    if (!attraction && fn < 0) fn = 0;
    V2 f = n * fn;

    if (kFriction && c.kt > 0) {
        const V2 t = perp(n);
        // The contact line turns with the pair: keep the spring's length, take its sign along the new tangent.
        const double xl = norm(xi);
        double s = dot(xi, t) >= 0 ? xl : -xl;
        const V2 gs = bi.vStep + perp(ri) * bi.wStep - bj.vStep - perp(rj) * bj.wStep;
        s += dot(gs, t) * dt;
        const double gt = dot(g, t);
        const double invMt = invM + norm2(ri) * bi.invInertia + norm2(rj) * bj.invInertia;
        const double ct = invMt > 0 ? c.gammaT * std::sqrt(c.kt / invMt) : 0.0;
        double ft = -c.kt * s - ct * gt;
        const double fmax = c.mu * fn;
        if (std::abs(ft) > fmax) {
            ft = ft > 0 ? fmax : -fmax;
            s = -(ft + ct * gt) / c.kt;
        }
        xi = t * s;
        out.ft = t * ft;
        f += out.ft;
    }
    out.f = f;
    out.torqueI = cross2(ri, f);
    out.torqueJ = -cross2(rj, f);
    out.fn = fn;
    out.normal = n;
    out.point = at;
    return out;
}

/// Elastic energy of a contact [J]. The potential law's is exact, Y A^2 / (2 L^2). The overlap-area law has no
/// potential (docs/physics.md G.3); its energy is estimated as Y A^2 / (2 l |c|): exact for a flat contact
/// (A = |c| depth), 3/4 of the work done for a vertex contact (A ~ depth^2).
template <class Law>
inline double polygonContactEnergy(const PolygonCoeffs& c, const Overlap& o, const ContactForce& f,
                                   const PairLengths& len) {
    if constexpr (Law::kPotential) {
        return c.young * o.area * o.area / (2 * len.potential);
    } else {
        const double clen = norm(o.chord);
        return clen > 0 && f.length > 0 ? c.young * o.area * o.area / (2 * f.length * clen) : 0.0;
    }
}

/// The law of c.law and friction chosen at run time (tests, set-up): polygonContact<Law, kFriction>.
inline ContactForce polygonContact(const PolygonCoeffs& c, const Overlap& o, const BodyState& bi, const BodyState& bj,
                                   const V2* wallNormal, const PairLengths& len, bool attraction, bool friction,
                                   double dt, V2& xi) {
    if (c.law == PolygonLaw::Potential)
        return friction ? polygonContact<PotentialLaw, true>(c, o, bi, bj, wallNormal, len, attraction, dt, xi)
                        : polygonContact<PotentialLaw, false>(c, o, bi, bj, wallNormal, len, attraction, dt, xi);
    return friction ? polygonContact<OverlapAreaLaw, true>(c, o, bi, bj, wallNormal, len, attraction, dt, xi)
                    : polygonContact<OverlapAreaLaw, false>(c, o, bi, bj, wallNormal, len, attraction, dt, xi);
}
inline double polygonContactEnergy(const PolygonCoeffs& c, const Overlap& o, const ContactForce& f,
                                   const PairLengths& len) {
    return c.law == PolygonLaw::Potential ? polygonContactEnergy<PotentialLaw>(c, o, f, len)
                                          : polygonContactEnergy<OverlapAreaLaw>(c, o, f, len);
}

}  // namespace haet::polygon
