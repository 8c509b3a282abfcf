#pragma once
// The rough-particle hard collision operator of the event-driven engine (docs/physics.md C.1) with the tangential
// restitution from Walton's rule or a constant (C.2). One operator serves pairs and walls: a wall, like a frozen
// particle, is a body of zero inverse mass and inertia moving with its own velocity.
//
// Convention: n is the unit normal from body 2 to body 1 (for a wall: the wall normal into the domain),
// g = v1 - v2 - (a1 w1 + a2 w2) x n is the relative velocity of the contact points, g_n = g . n < 0 approaching.
// The impulse P acts on body 1; body 2 receives -P.
#include <algorithm>
#include <cmath>

#include "core/vec.hpp"

namespace haet {

/// What the operator needs of one colliding body.
template <int D>
struct CollisionBody {
    Vec<D> v;               ///< velocity of the centre [m/s] (a wall: its translation velocity)
    Ang<D> w;               ///< angular velocity [rad/s]
    double radius = 0;      ///< [m] (a wall: 0)
    double invMass = 0;     ///< 1/m [1/kg]; 0 = infinitely heavy (wall, frozen particle)
    double invInertia = 0;  ///< 1/I [1/(kg m^2)]; 0 = infinite inertia
};

/// Kinetic energy of a body, translation and rotation [J]; 0 for an infinitely heavy one.
template <int D>
inline double kineticEnergy(const CollisionBody<D>& b) {
    double e = 0;
    if (b.invMass > 0) e += 0.5 * norm2(b.v) / b.invMass;
    if (b.invInertia > 0) e += 0.5 * norm2(b.w) / b.invInertia;
    return e;
}

/// How beta is chosen (docs/physics.md C.2).
enum class BetaRule {
    Walton,    ///< beta = min(beta0, -1 + mu (1+e) (m_eff/m_t) |g_n|/|g_t|): sticking or Coulomb sliding
    Constant,  ///< beta = beta0 always
};

/// Restitution parameters of one collision.
struct CollisionLaw {
    double e = 1;       ///< normal restitution [-], 0..1 (larger only for the engine's rest hop)
    double mu = 0;      ///< Coulomb friction [-]
    double beta0 = -1;  ///< tangential restitution (Walton: the sticking value) [-], -1..1
    BetaRule rule = BetaRule::Walton;
};

/// The outcome of the operator: the impulse and what went into it.
template <int D>
struct CollisionImpulse {
    Vec<D> impulse;        ///< P, on body 1 [N s]
    double gn = 0;         ///< normal relative velocity of the contact points before [m/s] (< 0 approaching)
    Vec<D> gt;             ///< tangential relative velocity of the contact points before [m/s]
    double meff = 0;       ///< normal effective mass [kg]
    double mt = 0;         ///< tangential effective mass [kg] (docs/physics.md B.4)
    double e = 1;          ///< normal restitution used [-]
    double beta = -1;      ///< tangential restitution used [-]
    bool sliding = false;  ///< Walton's Coulomb branch was taken

    /// Change of kinetic energy, docs/physics.md C.1: -1/2 m_eff (1-e^2) g_n^2 - 1/2 m_t (1-beta^2) |g_t|^2 [J].
    double energyChange() const {
        return -0.5 * meff * (1 - e * e) * gn * gn - 0.5 * mt * (1 - beta * beta) * norm2(gt);
    }
};

/// Relative velocity of the contact points, g = v1 - v2 - (a1 w1 + a2 w2) x n.
template <int D>
Vec<D> contactVelocity(const CollisionBody<D>& b1, const CollisionBody<D>& b2, const Vec<D>& n) {
    return b1.v - b2.v - cross(b1.w * b1.radius + b2.w * b2.radius, n);
}

/// Walton's tangential restitution (docs/physics.md C.2). kappa = m_eff / m_t = 1 + m_eff sum a^2/I.
inline double waltonBeta(double e, double mu, double beta0, double kappa, double gnAbs, double gtAbs) {
    if (!(gtAbs > 0)) return beta0;
    return std::min(beta0, -1 + mu * (1 + e) * kappa * gnAbs / gtAbs);
}

/// The impulse of the operator C.1 for bodies 1, 2 touching along n (not applied). At least one body must
/// have a finite mass.
template <int D>
CollisionImpulse<D> collisionImpulse(const CollisionBody<D>& b1, const CollisionBody<D>& b2, const Vec<D>& n,
                                     const CollisionLaw& law) {
    CollisionImpulse<D> r;
    const Vec<D> g = contactVelocity(b1, b2, n);
    r.gn = dot(g, n);
    r.gt = g - n * r.gn;
    const double invMeff = b1.invMass + b2.invMass;
    const double invMt = invMeff + b1.radius * b1.radius * b1.invInertia + b2.radius * b2.radius * b2.invInertia;
    r.meff = 1.0 / invMeff;
    r.mt = 1.0 / invMt;
    r.e = law.e;
    if (law.rule == BetaRule::Walton) {
        const double gtAbs = norm(r.gt);
        r.beta = waltonBeta(law.e, law.mu, law.beta0, invMt / invMeff, std::abs(r.gn), gtAbs);
        r.sliding = r.beta < law.beta0;
    } else {
        r.beta = law.beta0;
    }
    const double pn = -(1 + r.e) * r.meff * r.gn;  // normal impulse, >= 0 when approaching
    if (r.sliding) {
        // Coulomb: |P_t| = mu |P_n| directly; (1 + beta) m_t |g_t| would lose digits when beta is near -1.
        r.impulse = n * pn - r.gt * (law.mu * std::abs(pn) / norm(r.gt));
    } else {
        r.impulse = n * pn - r.gt * ((1 + r.beta) * r.mt);
    }
    return r;
}

/// Applies impulse P (on body 1, -P on body 2) at the contact point, docs/physics.md C.1:
/// v1 += P/m1, v2 -= P/m2, w1 -= (a1/I1) n x P, w2 -= (a2/I2) n x P.
template <int D>
void applyImpulse(CollisionBody<D>& b1, CollisionBody<D>& b2, const Vec<D>& n, const Vec<D>& P) {
    const Ang<D> nxP = cross(n, P);
    b1.v += P * b1.invMass;
    b2.v -= P * b2.invMass;
    b1.w -= nxP * (b1.radius * b1.invInertia);
    b2.w -= nxP * (b2.radius * b2.invInertia);
}

}  // namespace haet
