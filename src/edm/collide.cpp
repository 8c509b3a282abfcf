// The collisions of the event-driven engine: the rough-particle collision operator (edm/collision.hpp, docs/physics.md
// C) applied to a pair or a particle and a wall at the time of its event, with the TC model (edm/tc_model.hpp) and the
// rest hop (docs/edm.md).
#include <algorithm>
#include <cmath>

#include "edm/engine.hpp"

namespace haet {

namespace {
/// The impulse on body 1 of a collision along n (gn: normal velocity of body 1's contact point relative to body 2's):
/// the law's, with the normal speed after it raised to uRest when it would be smaller (the rest hop, docs/edm.md);
/// a pair not approaching (only with uRest > gn) gets a normal impulse up to uRest. hop: the speed was raised.
template <int D>
Vec<D> impulseWithHop(const CollisionBody<D>& b1, const CollisionBody<D>& b2, const Vec<D>& n, CollisionLaw law,
                      bool approaching, double gn, double uRest, bool& hop) {
    if (!approaching) {  // resting on the obstacle
        hop = true;
        return n * ((uRest - gn) / (b1.invMass + b2.invMass));
    }
    CollisionImpulse<D> imp = collisionImpulse(b1, b2, n, law);
    if (uRest > 0 && -imp.e * imp.gn < uRest) {
        law.e = uRest / -imp.gn;
        imp = collisionImpulse(b1, b2, n, law);
        hop = true;
    }
    return imp.impulse;
}
}  // namespace

template <int D>
CollisionLaw EdmEngine<D>::lawFor(int matA, int matB, bool wall, bool elastic) const {
    // A wall's restitution is the one the soft law gives a particle against it (its own calibration, m_eff = m).
    const PairCoeffs& c = wall ? w_.contact.wallPair(matA, matB) : w_.contact.pair(matA, matB);
    CollisionLaw law;
    law.mu = c.mu;
    if (elastic) {
        // TC model: elastic in the normal direction, no tangential impulse (beta = -1): the limit of Walton's
        // rule for vanishing normal impulse, which never violates Coulomb's bound (docs/edm.md).
        law.e = 1;
        law.beta0 = -1;
        law.rule = BetaRule::Constant;
    } else {
        law.e = c.restitution;
        law.beta0 = c.beta0;
        law.rule = s_.tangential == EdmSettings::Tangential::Walton ? BetaRule::Walton : BetaRule::Constant;
    }
    return law;
}

template <int D>
bool EdmEngine<D>::smoothPair(int matA, int matB) const {
    const PairCoeffs& c = w_.contact.pair(matA, matB);
    return s_.tangential == EdmSettings::Tangential::Walton ? c.mu == 0 : c.beta0 == -1;
}

template <int D>
void EdmEngine<D>::notify(double t, std::uint32_t a, std::uint32_t partner, bool wall, bool elastic, bool hop,
                          const Vec<D>& P, std::uint32_t element) {
    if (!collisionHook_) return;
    EdmCollision<D> c;
    c.time = t;
    c.i = sl_.rec[a].idx;
    c.partner = wall ? partner : sl_.rec[partner].idx;
    c.wall = wall;
    c.surface = element != kNil;
    c.element = c.surface ? element : 0;
    c.elastic = elastic;
    c.restHop = hop;
    c.impulse = P;
    collisionHook_(c);
}

template <int D>
void EdmEngine<D>::collidePair(std::uint32_t a, std::uint32_t b, double t) {
    Particles<D>& p = w_.particles;
    // Canonical order: the lower World index is body 1 (a frozen partner always body 2), so the result does not
    // depend on which of the two particles' events found the collision (the operator's sums are not associative).
    if ((sl_.rec[b].idx < sl_.rec[a].idx && !frozen(b)) || frozen(a)) std::swap(a, b);
    const std::uint32_t i = sl_.rec[a].idx, j = sl_.rec[b].idx;
    const bool fb = frozen(b);
    // The state at t, committed only if the collision happens (a skipped event leaves no trace).
    const Vec<D> va = sl_.velAt(sl_.hot[a], t), vb = sl_.velAt(sl_.hot[b], t);
    const Vec<D> d = w_.domain.minimumImage(sl_.posAt(sl_.hot[a], t) - sl_.posAt(sl_.hot[b], t));
    const double bdot = dot(d, va - vb);
    const Vec<D> n = d * (1.0 / norm(d));
    // Rest hop (docs/edm.md): against a fixed obstacle that gravity pushes the particle into, the normal speed
    // after the collision is at least |n.g| tcTime: it hops with a flight of 2 tcTime instead of coming to rest
    // through infinitely many collisions.
    const double gAcc = fb ? dot(n, sl_.g) : 0;
    const double uRest = tc_.restSpeed(gAcc);
    const int ma = materialOf(i), mb = materialOf(j);
    // A smooth pair (beta = -1 whatever the velocities) gets an impulse along n, which leaves the spins alone:
    // its bodies go without rotation, so the spins are neither read nor written.
    const bool smooth = smoothPair(ma, mb);
    CollisionBody<D> b1{va, Ang<D>::zero(), sl_.hot[a].r, p.invMass[i], 0.0};
    CollisionBody<D> b2{vb, Ang<D>::zero(), sl_.hot[b].r, fb ? 0.0 : p.invMass[j], 0.0};
    if (!smooth) {
        b1.w = p.w[i];
        b1.invInertia = p.invInertia[i];
        b2.w = p.w[j];
        b2.invInertia = fb ? 0.0 : p.invInertia[j];
    }
    const double gn = dot(contactVelocity(b1, b2, n), n);
    const bool approaching = bdot < 0 && gn < 0;
    if (!approaching && !(uRest > gn)) {  // not approaching (grazing, round-off): nothing happens
        ++stats_.grazing;
        return;
    }
    sl_.advance(a, t);
    sl_.advance(b, t);
    const bool elastic = tc_.elastic(a, fb ? kNil : b, t);
    bool hop = false;
    const Vec<D> P = impulseWithHop(b1, b2, n, lawFor(ma, mb, false, elastic), approaching, gn, uRest, hop);
    const double before = kineticEnergy(b1) + kineticEnergy(b2);
    applyImpulse(b1, b2, n, P);
    stats_.dissipated += before - kineticEnergy(b1) - kineticEnergy(b2);
    if (elastic && observer_) {
        observer_->tcCollision(i);
        if (!fb) observer_->tcCollision(j);
    }
    sl_.hot[a].v = b1.v;
    if (!smooth) p.w[i] = b1.w;
    ++sl_.link[a].count;
    tc_.collided(a, t);
    if (!fb) {
        sl_.hot[b].v = b2.v;
        if (!smooth) p.w[j] = b2.w;
        ++sl_.link[b].count;
        tc_.collided(b, t);
    }
    virial_ += dot(d, P);
    ++stats_.pairCollisions;
    if (elastic) ++stats_.tcElastic;
    if (hop) ++stats_.restHops;
    notify(t, a, b, false, elastic, hop, P);
}

// A particle's collision with an infinitely heavy partner at rest or in motion (b2: a plane, a mesh element), once
// it is known to approach: the particle brought to t, the impulse along n by the law of materials (ma, wallMaterial)
// or elastic by the TC model (with the rest hop), the books.
template <int D>
typename EdmEngine<D>::WallHit EdmEngine<D>::wallImpulse(std::uint32_t s, double t, CollisionBody<D>& b1,
                                                         CollisionBody<D>& b2, const Vec<D>& n, double gn, double uRest,
                                                         int ma, int wallMaterial, bool smooth) {
    Particles<D>& p = w_.particles;
    const std::uint32_t i = sl_.rec[s].idx;
    WallHit h;
    sl_.advance(s, t);
    h.elastic = tc_.elastic(s, kNil, t);
    h.P = impulseWithHop(b1, b2, n, lawFor(ma, wallMaterial, true, h.elastic), gn < 0, gn, uRest, h.hop);
    const double before = kineticEnergy(b1);
    applyImpulse(b1, b2, n, h.P);
    stats_.dissipated += before - kineticEnergy(b1);
    if (h.elastic && observer_) observer_->tcCollision(i);
    sl_.hot[s].v = b1.v;
    if (!smooth) p.w[i] = b1.w;
    ++sl_.link[s].count;
    tc_.collided(s, t);
    ++stats_.wallCollisions;
    if (h.elastic) ++stats_.tcElastic;
    if (h.hop) ++stats_.restHops;
    return h;
}

template <int D>
void EdmEngine<D>::collideWall(std::uint32_t s, std::uint32_t w, double t) {
    Particles<D>& p = w_.particles;
    const std::uint32_t i = sl_.rec[s].idx;
    const Wall<D>& wl = w_.walls[w];
    const Vec<D>& n = wl.normal;
    const double gAcc = dot(n, sl_.g);
    const double uRest = tc_.restSpeed(gAcc);
    const Vec<D> vs = sl_.velAt(sl_.hot[s], t);
    const int ma = materialOf(i);
    const bool smooth = smoothPair(ma, wl.material);  // as in collidePair
    CollisionBody<D> b1{vs, smooth ? Ang<D>::zero() : p.w[i], sl_.hot[s].r, p.invMass[i],
                        smooth ? 0.0 : p.invInertia[i]};
    CollisionBody<D> b2{wl.velocity, Ang<D>::zero(), 0.0, 0.0, 0.0};
    const double gn = dot(vs - wl.velocity, n);
    if (gn >= 0 && !(uRest > gn)) {  // not approaching: nothing happens, no state change
        ++stats_.grazing;
        return;
    }
    const WallHit h = wallImpulse(s, t, b1, b2, n, gn, uRest, ma, wl.material, smooth);
    notify(t, s, w, true, h.elastic, h.hop, h.P);
}

// A mesh element as a plane wall at rest whose normal is the contact's (predict_mesh.hpp: from the contact point to the
// centre, the gradient of the distance; a face's own normal on its inside), so a flat mesh bounces a particle as its
// plane does (docs/physics.md D.8). The contact is the element's canonical one at t (MeshWalls::contact), the same
// computation that scheduled the event.
template <int D>
void EdmEngine<D>::collideMesh(std::uint32_t s, std::uint32_t e, double t) {
    Particles<D>& p = w_.particles;
    const std::uint32_t i = sl_.rec[s].idx;
    const MeshContact<D> hit = mesh_.contact(sl_, s, e, t);
    const Vec<D> n = hit.normal;
    const int wallMaterial = mesh_.material(e);
    const double uRest = tc_.restSpeed(dot(n, sl_.g));
    const Vec<D> vs = sl_.velAt(sl_.hot[s], t);
    const int ma = materialOf(i);
    const bool smooth = smoothPair(ma, wallMaterial);  // as in collidePair
    CollisionBody<D> b1{vs, smooth ? Ang<D>::zero() : p.w[i], sl_.hot[s].r, p.invMass[i],
                        smooth ? 0.0 : p.invInertia[i]};
    CollisionBody<D> b2{Vec<D>::zero(), Ang<D>::zero(), 0.0, 0.0, 0.0};
    const double gn = dot(vs, n);
    if (hit.feature == MeshFeature::None || (gn >= 0 && !(uRest > gn))) {
        // Not approaching (a graze to rounding): no impulse. Unlike a plane's, the state is committed at t, so that
        // the next prediction starts at the contact (touching, not approaching: no event now, D.6) instead of
        // finding this one again; the counter makes the partners' events that knew the older state stale.
        sl_.advance(s, t);
        ++sl_.link[s].count;
        ++stats_.grazing;
        return;
    }
    const WallHit h = wallImpulse(s, t, b1, b2, n, gn, uRest, ma, wallMaterial, smooth);
    notify(t, s, mesh_.wall(e), true, h.elastic, h.hop, h.P, mesh_.local(e));
}

// The members defined here, for both dimensions (the class itself is instantiated in edm/engine.cpp).
#define HAET_EDM_COLLIDE(D)                                                                                          \
    template CollisionLaw EdmEngine<D>::lawFor(int, int, bool, bool) const;                                          \
    template bool EdmEngine<D>::smoothPair(int, int) const;                                                          \
    template void EdmEngine<D>::notify(double, std::uint32_t, std::uint32_t, bool, bool, bool, const Vec<D>&,        \
                                       std::uint32_t);                                                               \
    template void EdmEngine<D>::collidePair(std::uint32_t, std::uint32_t, double);                                   \
    template void EdmEngine<D>::collideWall(std::uint32_t, std::uint32_t, double);                                   \
    template EdmEngine<D>::WallHit EdmEngine<D>::wallImpulse(                                                        \
        std::uint32_t, double, CollisionBody<D>&, CollisionBody<D>&, const Vec<D>&, double, double, int, int, bool); \
    template void EdmEngine<D>::collideMesh(std::uint32_t, std::uint32_t, double);
HAET_EDM_COLLIDE(2)
HAET_EDM_COLLIDE(3)
#undef HAET_EDM_COLLIDE

}  // namespace haet
