#pragma once
// The event-driven engine's particle state, shared by its parts (the event loop, the event grid, the neighbour
// shells, the candidate scan, the reference twin): per slot the records a prediction reads, the motion between
// events and the canonical pair and wall times (docs/physics.md D.2-D.4, D.6; docs/edm.md, "Canonical arithmetic").
//
// The engine works on slots, its own order of the particles (cell by cell, for memory locality); Rec::idx maps a
// slot to the particle's index in the World. What a prediction reads of a neighbour is in two records: Hot (one
// 64-byte cache line in 3D) and Link. The World's x and v are written at synchronisation only.
#include <array>
#include <cstdint>
#include <vector>

#include "edm/predict.hpp"
#include "world/world.hpp"

namespace haet::edm {

/// Event codes: the type in the top two bits, a slot, wall or face below.
enum Type : std::uint32_t { kPair = 0, kWall = 1, kCell = 2, kNone = 3 };
inline constexpr std::uint32_t kTypeShift = 30, kIndexMask = (1u << kTypeShift) - 1;
inline constexpr std::uint32_t kNil = 0xFFFFFFFFu;

/// A candidate event: time, code and the partner's collision counter when it was found.
struct Candidate {
    double time = kNever;
    std::uint32_t code = kNone << kTypeShift;
    std::uint32_t stamp = 0;
    bool better(double t, std::uint32_t c) const { return t < time || (t == time && c < code); }
};

template <int D>
struct Slots {
    using Shift = std::array<std::int32_t, D>;

    struct alignas(D == 3 ? 64 : 16) Hot {
        Vec<D> x;  // position at time t [m]; raw: the periodic wraps since the last synchronisation are in wrap
        double t;  // the particle's clock [s]; kNever marks a frozen particle (never moves)
        Vec<D> v;  // velocity at time t [m/s]
        double r;  // radius [m]
    };
    struct Link {
        std::uint32_t next;   // next slot in the same cell
        std::uint32_t count;  // collision counter (stale-event test)
        std::uint32_t wrap;   // box-frame position = x - wrap * L on periodic axes; packed, wrapsOf
    };
    // What an event of the slot itself needs (16 bytes). The pending event's time is the queue's; the time of coll
    // is not kept: while the crossing is pending it is recomputed when needed (EdmEngine::keptTime).
    static constexpr std::uint32_t kCellBits = 28;
    struct Kept {
        std::uint32_t code = kNone << kTypeShift;
        std::uint32_t stamp = 0;
    };
    struct Rec {
        Kept coll;                       // earliest pair or wall event found by the last scan: code, partner's counter
        std::uint32_t cell : kCellBits;  // cell index (free slot: the grid's cell count)
        std::uint32_t exit : 3;          // face of the cell crossing (shell exit) found by the last scan: 2 axis + up
        std::uint32_t crossing : 1;      // the pending event is that crossing, not coll
        std::uint32_t idx;               // slot -> World index
    };

    // Periodic wraps since the last synchronisation, kWrapBits per axis with a bias. One that would leave the field
    // moves the whole box lengths from the stored position into Particles::image, as a synchronisation does.
    static constexpr int kWrapBits = D == 3 ? 10 : 16;
    static constexpr std::int32_t kWrapBias = 1 << (kWrapBits - 1), kWrapLimit = kWrapBias - 2;
    static Shift wrapsOf(std::uint32_t packed) {
        Shift w;
        for (int k = 0; k < D; ++k)
            w[k] = static_cast<std::int32_t>((packed >> (kWrapBits * k)) & ((1u << kWrapBits) - 1)) - kWrapBias;
        return w;
    }
    static std::uint32_t packWraps(const Shift& w) {
        std::uint32_t packed = 0;
        for (int k = 0; k < D; ++k) packed |= static_cast<std::uint32_t>(w[k] + kWrapBias) << (kWrapBits * k);
        return packed;
    }

    World<D>* world = nullptr;
    Vec<D> g;       // gravity [m/s^2]
    Vec<D> boxLen;  // box lengths [m]
    std::vector<Hot> hot;
    std::vector<Link> link;
    std::vector<Rec> rec;

    std::size_t size() const { return hot.size(); }
    bool frozen(std::uint32_t s) const { return hot[s].t == kNever; }  // also true for a free slot

    Vec<D> posAt(const Hot& h, double t) const {
        if (h.t == kNever) return h.x;
        const double dt = t - h.t;
        Vec<D> x;
        for (int k = 0; k < D; ++k) x[k] = h.x[k] + (h.v[k] + 0.5 * g[k] * dt) * dt;
        return x;
    }
    Vec<D> velAt(const Hot& h, double t) const {
        if (h.t == kNever) return Vec<D>::zero();
        const double dt = t - h.t;
        Vec<D> v;
        for (int k = 0; k < D; ++k) v[k] = h.v[k] + g[k] * dt;
        return v;
    }
    void advance(std::uint32_t s, double t) {
        Hot& h = hot[s];
        if (h.t == kNever) return;
        const double dt = t - h.t;
        if (dt != 0) {
            h.x = posAt(h, t);
            h.v = velAt(h, t);
        }
        h.t = t;
    }
    /// Stores slot s's wraps; one beyond the field moves whole box lengths into Particles::image.
    void setWraps(std::uint32_t s, Shift w) {
        for (int k = 0; k < D; ++k) {
            if (std::abs(w[k]) <= kWrapLimit) continue;
            // Whole box lengths from the stored position into Particles::image, as a synchronisation does; the
            // box-frame position and so the cell and the pending events stay (the stored x is rounded, as at a
            // synchronisation).
            hot[s].x[k] -= w[k] * boxLen[k];
            world->particles.image[rec[s].idx][k] += w[k];
            w[k] = 0;
        }
        link[s].wrap = packWraps(w);
    }

    // Collision time of slots a (moving) and b, b seen through the periodic image shift m (multiples of the box
    // lengths), no earlier than now. horizon: an event already found; a frozen partner beyond reach before it is
    // skipped.
    double pairTime(std::uint32_t a, std::uint32_t b, const Shift& m, double now, double horizon) const {
        const Hot& ha = hot[a];
        const Hot& hb = hot[b];
        const double sigma = ha.r + hb.r;
        double t;
        if (hb.t == kNever) {
            // A fixed obstacle: only a accelerates, the gap is a quartic under gravity. The quartic is costly, so
            // first a conservative test whether a can reach the obstacle before the horizon; skipping changes
            // nothing, since such a root could not be the earliest.
            if (horizon < kNever) {
                const double tau = horizon - now;
                const Vec<D> xn = posAt(ha, now);
                Vec<D> r0;
                for (int k = 0; k < D; ++k) r0[k] = (xn[k] - hb.x[k]) + m[k] * boxLen[k];
                const double reach = norm(velAt(ha, now)) * tau + 0.5 * norm(g) * tau * tau;
                if (norm(r0) - sigma > reach * (1 + 1e-9) + 1e-12 * sigma) return kNever;
            }
            Vec<D> r;
            for (int k = 0; k < D; ++k) r[k] = (ha.x[k] - hb.x[k]) + m[k] * boxLen[k];
            t = ha.t + fixedSphereCollisionTime(r, ha.v, g, sigma, kNever);
        } else {
            // Both extrapolated to the later clock (one of the two extrapolations is by zero: exact).
            const double tr = std::max(ha.t, hb.t);
            const Vec<D> xa = posAt(ha, tr), xb = posAt(hb, tr);
            const Vec<D> va = velAt(ha, tr), vb = velAt(hb, tr);
            Vec<D> r;
            for (int k = 0; k < D; ++k) r[k] = (xa[k] - xb[k]) + m[k] * boxLen[k];
            t = tr + pairCollisionTime(r, va - vb, sigma);
        }
        return t < now ? pairTimeFromNow(a, b, m, now) : t;
    }

    // A root before now means an invalid state at the stored clocks (an overlap that round-off, or a bug, let
    // pass). Its dynamics are decided by the state now (docs/physics.md D.6): approaching now -> now; receding -> the
    // next root from now. Deciding from the older state could schedule a collision that the collision then finds
    // receding.
    double pairTimeFromNow(std::uint32_t a, std::uint32_t b, const Shift& m, double now) const;

    double wallTime(std::uint32_t s, std::size_t w, double now) const {
        const Hot& h = hot[s];
        const Wall<D>& wl = world->walls[w];
        const double t = h.t + wallCollisionTime(h.x, h.v, h.r, wl.pointAt(h.t), wl.velocity, wl.normal, g);
        if (t >= now) return t;
        // Invalid state at the stored clock: decided by the state now, as for pairs.
        return now + wallCollisionTime(posAt(h, now), velAt(h, now), h.r, wl.pointAt(now), wl.velocity, wl.normal, g);
    }

    // The canonical form of pairTime for moving slot s (state hs) and slot j seen through the image shift m,
    // written out for speed: the older of the two states is extrapolated to the other's clock (an extrapolation by
    // zero leaves a state unchanged, so skipping it gives the same bits). A candidate whose root cannot come
    // before bestTime gives kNever without the square root or the division. The scalar twin of candidates4
    // (edm/scan.hpp), which evaluates four candidates side by side with the same arithmetic and hands it the lanes
    // it does not finish (frozen partner, root before now).
    double candidateTime(const Hot& hs, std::uint32_t s, std::uint32_t j, const Shift& m, double now,
                         double bestTime) const {
        const Hot& hj = hot[j];
        if (hj.t == kNever) return pairTime(s, j, m, now, bestTime);
        const double ts = hs.t;
        double r[D], v[D], tr;
        if (hj.t <= ts) {
            tr = ts;
            const double db = ts - hj.t;
            for (int k = 0; k < D; ++k) {
                const double xb = hj.x[k] + (hj.v[k] + 0.5 * g[k] * db) * db;
                r[k] = (hs.x[k] - xb) + m[k] * boxLen[k];
                v[k] = hs.v[k] - (hj.v[k] + g[k] * db);
            }
        } else {
            tr = hj.t;
            const double da = hj.t - ts;
            for (int k = 0; k < D; ++k) {
                const double xa = hs.x[k] + (hs.v[k] + 0.5 * g[k] * da) * da;
                r[k] = (xa - hj.x[k]) + m[k] * boxLen[k];
                v[k] = (hs.v[k] + g[k] * da) - hj.v[k];
            }
        }
        double b = 0;
        for (int k = 0; k < D; ++k) b += r[k] * v[k];
        if (!(b < 0)) return kNever;
        const double sigma = hs.r + hj.r;
        double r2 = 0;
        for (int k = 0; k < D; ++k) r2 += r[k] * r[k];
        const double c = r2 - sigma * sigma;
        // Lower bound of the root: c / (-2 b). Beyond the best event so far: no sqrt, no division.
        const double left = bestTime - tr;
        if (c > 0 && c > -2 * b * left * (1 + 1e-12)) return kNever;
        double v2 = 0;
        for (int k = 0; k < D; ++k) v2 += v[k] * v[k];
        const double t = tr + firstRootFalling(c, 2 * b, 2 * v2);
        return t < now ? pairTimeFromNow(s, j, m, now) : t;
    }
};

template <int D>
double Slots<D>::pairTimeFromNow(std::uint32_t a, std::uint32_t b, const Shift& m, double now) const {
    const Hot& ha = hot[a];
    const Hot& hb = hot[b];
    const Vec<D> xa = posAt(ha, now), xb = posAt(hb, now);
    Vec<D> r;
    for (int k = 0; k < D; ++k) r[k] = (xa[k] - xb[k]) + m[k] * boxLen[k];
    const Vec<D> va = velAt(ha, now);
    const double tau = hb.t == kNever ? fixedSphereCollisionTime(r, va, g, ha.r + hb.r, kNever)
                                      : pairCollisionTime(r, va - velAt(hb, now), ha.r + hb.r);
    return now + tau;
}

}  // namespace haet::edm
