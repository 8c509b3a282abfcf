#include "edm/engine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "core/lanes.hpp"
#include "edm/predict.hpp"

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

// Arithmetic is canonical on purpose: a pair's collision time is computed from the two particles' stored states
// extrapolated to the later of their two clocks (never to "now"), in a form that is bit-identical for (a, b) and
// (b, a); the collision operator always takes the particle of lower World index as body 1. The prediction of a pair
// therefore does not depend on when, or by which of the two, it was made, and the fast engine and the brute-force
// reference produce bit-identical event sequences (tests/test_edm_engine.cpp). Stored states change only at
// collisions and at the synchronisation at the end of advanceTo, never at cell crossings or stale events.

template <int D>
EdmEngine<D>::EdmEngine(World<D>& world, const EdmSettings& settings) : w_(world), s_(settings) {
    const ContactSetup& cs = w_.contact;
    if (cs.nMaterials <= 0 || cs.table.size() < static_cast<std::size_t>(cs.nMaterials * cs.nMaterials))
        throw std::invalid_argument("event-driven engine: the world has no contact table (world.contact)");
    if (s_.tcTime < 0) throw std::invalid_argument("event-driven engine: tcTime must be >= 0");
    if (s_.maxEventRate < 0) throw std::invalid_argument("event-driven engine: maxEventRate must be >= 0");
    if (s_.cellSize < 0) throw std::invalid_argument("event-driven engine: cellSize must be >= 0");
    if (!(s_.shell >= 0)) throw std::invalid_argument("event-driven engine: shell must be >= 0");
    if (s_.holdState && s_.firstParticle > 0)
        throw std::invalid_argument("event-driven engine: holdState needs every particle (firstParticle = 0)");
    if (w_.particles.hasPolygons())
        throw std::invalid_argument("event-driven engine: polygons are for the time-driven engine only");
    tcRef_ = s_.tcTime > 0 ? s_.tcTime : cs.contactTime;
    tc_ = (s_.tcModel && tcRef_ > 0) ? tcRef_ : 0;
    g_ = w_.domain.gravity;
    boxLen_ = w_.domain.length();
    for (int k = 0; k < D; ++k) periodic_ = periodic_ || w_.domain.periodic[k];
    for (std::size_t k = 0; k < w_.walls.size(); ++k) {
        const Wall<D>& wl = w_.walls[k];
        if (wl.material < 0 || wl.material >= cs.nMaterials)
            throw std::invalid_argument("event-driven engine: wall " + std::to_string(k) + " has no material");
        for (int a = 0; a < D; ++a)
            if (w_.domain.periodic[a] && std::abs(wl.normal[a]) > 1e-12)
                throw std::invalid_argument("event-driven engine: wall " + std::to_string(k) +
                                            " is not parallel to periodic axis " + std::to_string(a));
    }
    reset();
}

// ---------------------------------------------------------------------------------------------------------------
// set-up

template <int D>
void EdmEngine<D>::requireKnownMaterial(std::size_t i) const {
    if (w_.particles.material[i] >= w_.contact.nMaterials)
        throw std::invalid_argument("event-driven engine: particle material outside the contact table");
}

template <int D>
void EdmEngine<D>::reset() {
    Particles<D>& p = w_.particles;
    if (!p.hasMotion())
        throw std::logic_error("event-driven engine: reset while it holds the state (synchronise first)");
    const std::size_t n = p.size();
    const std::size_t first = std::min(s_.firstParticle, n);
    if (n >= (1u << kTypeShift)) throw std::invalid_argument("event-driven engine: too many particles");
    rmax_ = 0;
    nMoving_ = 0;
    // Every particle sizes the grid (those of another engine may join later).
    for (std::size_t i = 0; i < n; ++i) {
        if (!(p.radius[i] > 0)) throw std::invalid_argument("event-driven engine: particle with radius <= 0");
        requireKnownMaterial(i);
        rmax_ = std::max(rmax_, p.radius[i]);
        if (i >= first && !p.frozen(i)) ++nMoving_;
    }
    for (int k = 0; k < D; ++k)
        if (w_.domain.periodic[k] && boxLen_[k] < 4 * rmax_)
            throw std::invalid_argument("event-driven engine: periodic axis " + std::to_string(k) +
                                        " is shorter than two particle diameters");
    // Periodic positions into the box (frozen particles too: they never move afterwards).
    for (std::size_t i = first; i < n; ++i) wrapIntoBox(i);
    // Event-rate bound (docs/edm.md): as given; else 1000 per TC time; else 10^4 per d_min/u, u the larger of
    // the rms speed, sqrt(|g| d_min) and the fastest wall speed. Physical event rates stay far below.
    if (s_.maxEventRate > 0) {
        maxRate_ = s_.maxEventRate;
    } else if (tcRef_ > 0) {
        maxRate_ = 1000.0 / tcRef_;
    } else {
        double dmin = kNever, v2 = 0;
        for (std::size_t i = first; i < n; ++i) {
            dmin = std::min(dmin, 2 * p.radius[i]);
            if (!p.frozen(i)) v2 += norm2(p.v[i]);
        }
        double u = nMoving_ > 0 ? std::sqrt(v2 / static_cast<double>(nMoving_)) : 0;
        if (n > 0) u = std::max(u, std::sqrt(norm(g_) * dmin));
        for (const Wall<D>& wl : w_.walls) u = std::max(u, norm(wl.velocity));
        maxRate_ = (n > 0 && u > 0) ? 1e4 * u / dmin : 0;
    }
    window_ = std::max<std::uint64_t>(1000000, 100 * static_cast<std::uint64_t>(nMoving_));
    winEvents_ = events_;
    winTime_ = w_.time;
    chooseShell();

    // Slots in World order first, then sorted cell by cell.
    buildGrid();
    hot_.resize(n);
    link_.assign(n, Link{kNil, 0, packWraps(Shift{})});
    rec_.assign(n, Rec{Kept{}, 0, 0, 0, 0});
    if (tc_ > 0)
        tLast_.assign(n, -std::numeric_limits<double>::infinity());
    else
        std::vector<double>().swap(tLast_);
    const std::uint32_t freeCell = static_cast<std::uint32_t>(head_.size());
    for (std::uint32_t i = 0; i < n; ++i) {
        const bool fz = p.frozen(i);
        if (i < first) {  // a free slot, for a particle that joins later
            hot_[i] = Hot{p.x[i], kNever, Vec<D>::zero(), p.radius[i]};
            rec_[i].idx = kNil;
            rec_[i].cell = freeCell;
            continue;
        }
        // A frozen particle's velocity is taken as zero (posAt, velAt); its slot keeps the World's for holdState.
        hot_[i] = Hot{p.x[i], fz ? kNever : w_.time, p.v[i], p.radius[i]};
        rec_[i].idx = i;
        rec_[i].cell = cellOf(p.x[i]);
    }
    nLive_ = n - first;
    queue_.reset(n);
    if (shells_) {
        // Shell centres where the particles are; the grid holds centres.
        centre_.assign(n, Centre{Vec<D>::zero(), 0.0});
        for (std::uint32_t i = static_cast<std::uint32_t>(first); i < n; ++i) {
            centre_[i] = Centre{p.x[i], p.radius[i]};
            rec_[i].cell = cellOf(p.x[i]);
        }
        nbr_.clear();
        rowLen_ = 0;
    }
    resort();  // also links the cells, numbers slotOf_ and free_
    if (shells_) buildLists();
    if (zoned_) attachZones(zone_);
    if (s_.reference) return;
    for (std::uint32_t s = 0; s < n; ++s)
        if (!frozen(s)) predict(s, w_.time);
}

template <int D>
void EdmEngine<D>::wrapIntoBox(std::size_t i) {
    Particles<D>& p = w_.particles;
    for (int k = 0; k < D; ++k) {
        if (!w_.domain.periodic[k]) continue;
        double& x = p.x[i][k];
        const double lo = w_.domain.lo[k], L = boxLen_[k];
        if (x >= lo && x < lo + L) continue;
        const double sh = std::floor((x - lo) / L);
        x -= sh * L;
        p.image[i][k] += static_cast<std::int32_t>(sh);
    }
}

// Neighbour shells or cell crossings (EdmSettings::shell).
template <int D>
void EdmEngine<D>::chooseShell() {
    shells_ = s_.shell > 0 && !s_.reference && w_.particles.size() <= kSlotMask && rmax_ > 0;
    shellHalf_ = shells_ ? s_.shell * rmax_ : 0;  // half of shell * (2 rmax)
}

template <int D>
void EdmEngine<D>::buildGrid() {
    const double least = 2 * rmax_ + (shells_ ? 2 * shellHalf_ : 0);
    double edge = s_.cellSize > 0 ? s_.cellSize : least;
    // A dilute 3D gas without gravity (no heap forms, the density stays near its mean): cells of at least the edge
    // that gives kCellsPerParticle cells per particle. At phi = 0.1 cells of one diameter are 5.2 per particle (21
    // bytes of list heads each) and most events are cell crossings; 1.28 diameters take 2.5 (docs/edm.md).
    if (!(s_.cellSize > 0) && D == 3 && norm2(g_) == 0 && !shells_ && w_.particles.size() > 0) {
        constexpr double kCellsPerParticle = 2.5;
        double vol = 1;
        for (int k = 0; k < D; ++k) vol *= boxLen_[k];
        const double mean = std::cbrt(vol / (kCellsPerParticle * static_cast<double>(w_.particles.size())));
        if (std::isfinite(mean)) edge = std::max(edge, mean);
    }
    if (s_.cellSize > 0 && s_.cellSize < least * (1 - 1e-12))
        throw std::invalid_argument(shells_ ? "event-driven engine: cellSize is smaller than the largest diameter "
                                              "plus the neighbour shell"
                                            : "event-driven engine: cellSize is smaller than the largest diameter");
    if (!(edge > 0)) edge = 1;
    // At most max(2^20, 8 N) cells: a huge open box with few particles gets larger cells. Below 2^29 - 1 in any
    // case: Rec::cell has 29 bits and the free slots' cell is the one past the last.
    const double maxCells =
        std::min(double((1u << kCellBits) - 2), std::max(1048576.0, 8.0 * static_cast<double>(w_.particles.size())));
    for (;;) {
        double total = 1;
        for (int k = 0; k < D; ++k) {
            const double L = boxLen_[k];
            nCell_[k] = L > 0 ? std::max(1, static_cast<int>(std::floor(L / edge))) : 1;
            total *= nCell_[k];
        }
        if (total <= maxCells) break;
        edge *= 1.25;
    }
    std::uint32_t total = 1;
    partialScans_ = true;
    for (int k = 0; k < D; ++k) {
        if (w_.domain.periodic[k] && nCell_[k] < 7) partialScans_ = false;  // keptTime's minimum image
        cellW_[k] = boxLen_[k] > 0 ? boxLen_[k] / nCell_[k] : 1;
        stride_[k] = total;
        total *= static_cast<std::uint32_t>(nCell_[k]);
    }
    head_.assign(total, kNil);
    // Index offsets of the 3^D neighbours of a cell away from the faces, and of the 3^(D-1) new neighbours after a
    // step along axis a in direction d (deltaSide_[2 a + (d > 0)]).
    std::array<int, 2 * D> sideCount{};
    constexpr int m = D == 3 ? 27 : 9;
    for (int code = 0; code < m; ++code) {
        std::array<int, D> o;
        int t = code;
        std::int32_t delta = 0;
        for (int k = 0; k < D; ++k) {
            o[k] = t % 3 - 1;
            t /= 3;
            delta += o[k] * static_cast<std::int32_t>(stride_[k]);
        }
        deltaFull_[code] = delta;
        for (int k = 0; k < D; ++k)
            if (o[k] != 0) {
                const int side = 2 * k + (o[k] > 0 ? 1 : 0);
                deltaSide_[side][sideCount[side]++] = delta;
            }
    }
}

template <int D>
std::uint32_t EdmEngine<D>::cellOf(const Vec<D>& x) const {
    std::uint32_t c = 0;
    for (int k = 0; k < D; ++k) {
        int ck = static_cast<int>(std::floor((x[k] - w_.domain.lo[k]) / cellW_[k]));
        ck = std::clamp(ck, 0, nCell_[k] - 1);
        c += static_cast<std::uint32_t>(ck) * stride_[k];
    }
    return c;
}

template <int D>
void EdmEngine<D>::insertCell(std::uint32_t s, std::uint32_t c) {
    rec_[s].cell = c;
    link_[s].next = head_[c];
    head_[c] = s;
}

// A cell holds a few particles (about one with the default edge of one diameter), so walking its list costs less than
// a back link per slot would: no predecessor to keep, 4 bytes per particle fewer.
template <int D>
void EdmEngine<D>::removeCell(std::uint32_t s) {
    std::uint32_t* at = &head_[rec_[s].cell];
    while (*at != s) at = &link_[*at].next;
    *at = link_[s].next;
}

template <int D>
void EdmEngine<D>::setWraps(std::uint32_t s, Shift w) {
    for (int k = 0; k < D; ++k) {
        if (std::abs(w[k]) <= kWrapLimit) continue;
        // Whole box lengths from the stored position into Particles::image, as syncSlot does; the box-frame
        // position and so the cell and the pending events stay (the stored x is rounded, as at a synchronisation).
        hot_[s].x[k] -= w[k] * boxLen_[k];
        w_.particles.image[rec_[s].idx][k] += w[k];
        w[k] = 0;
    }
    link_[s].wrap = packWraps(w);
}

template <int D>
void EdmEngine<D>::linkCells() {
    std::fill(head_.begin(), head_.end(), kNil);
    // Inserted from the last slot down, so each cell's list runs in increasing slot order.
    for (std::uint32_t s = static_cast<std::uint32_t>(hot_.size()); s-- > 0;)
        if (rec_[s].idx != kNil) insertCell(s, rec_[s].cell);
}

// Reorders the slots cell by cell (stable in the current order): neighbours in space become neighbours in memory.
// Pending events move with their slots; the partners of pair events are renumbered.
template <int D>
void EdmEngine<D>::resort() {
    const std::size_t n = hot_.size();
    std::vector<std::uint32_t> start(head_.size() + 2, 0);  // the last bucket: free slots
    for (std::size_t s = 0; s < n; ++s) ++start[rec_[s].cell + 1];
    for (std::size_t c = 0; c + 1 < start.size(); ++c) start[c + 1] += start[c];
    std::vector<std::uint32_t> order(n), newSlot(n);  // order[new] = old
    for (std::uint32_t s = 0; s < n; ++s) {
        const std::uint32_t ns = start[rec_[s].cell]++;
        order[ns] = s;
        newSlot[s] = ns;
    }
    auto permute = [&](auto& arr) {
        auto tmp = arr;
        for (std::size_t k = 0; k < n; ++k) tmp[k] = arr[order[k]];
        arr.swap(tmp);
    };
    permute(hot_);
    permute(link_);
    permute(rec_);
    if (!tLast_.empty()) permute(tLast_);
    if (shells_) {
        permute(centre_);
        if (!nbr_.empty()) {
            std::vector<std::uint32_t> rows(nbr_.size());
            for (std::size_t k = 0; k < n; ++k) {
                const std::uint32_t* from = row(order[k]);
                std::uint32_t* to = &rows[k * rowLen_];
                to[0] = from[0];
                for (std::uint32_t q = 1; q <= from[0]; ++q)
                    to[q] = (from[q] & ~kSlotMask) | newSlot[from[q] & kSlotMask];
            }
            nbr_.swap(rows);
        }
    }
    std::vector<double> times(n);
    for (std::size_t k = 0; k < n; ++k) times[k] = queue_.time(order[k]);
    auto renumber = [&](std::uint32_t& code) {
        if ((code >> kTypeShift) == kPair) code = (kPair << kTypeShift) | newSlot[code & kIndexMask];
    };
    for (std::size_t k = 0; k < n; ++k) renumber(rec_[k].coll.code);
    queue_.build(times);
    linkCells();
    // The World-to-slot table serves the hybrid's questions about single particles; a run with holdState asks none.
    if (s_.holdState)
        std::vector<std::uint32_t>().swap(slotOf_);
    else
        slotOf_.assign(w_.particles.size(), kNil);
    free_.clear();
    for (std::uint32_t k = static_cast<std::uint32_t>(n); k-- > 0;) {
        if (rec_[k].idx == kNil)
            free_.push_back(k);
        else if (!slotOf_.empty())
            slotOf_[rec_[k].idx] = k;
    }
    sortedAt_ = events_;
}

// ---------------------------------------------------------------------------------------------------------------
// motion and predictions

template <int D>
inline Vec<D> EdmEngine<D>::posAt(const Hot& h, double t) const {
    if (h.t == kNever) return h.x;
    const double dt = t - h.t;
    Vec<D> x;
    for (int k = 0; k < D; ++k) x[k] = h.x[k] + (h.v[k] + 0.5 * g_[k] * dt) * dt;
    return x;
}

template <int D>
inline Vec<D> EdmEngine<D>::velAt(const Hot& h, double t) const {
    if (h.t == kNever) return Vec<D>::zero();
    const double dt = t - h.t;
    Vec<D> v;
    for (int k = 0; k < D; ++k) v[k] = h.v[k] + g_[k] * dt;
    return v;
}

template <int D>
void EdmEngine<D>::advance(std::uint32_t s, double t) {
    Hot& h = hot_[s];
    if (h.t == kNever) return;
    const double dt = t - h.t;
    if (dt != 0) {
        h.x = posAt(h, t);
        h.v = velAt(h, t);
    }
    h.t = t;
}

// Collision time of slots a (moving) and b, b seen through the periodic image shift m (multiples of the box
// lengths), no earlier than now. horizon: an event already found; a frozen partner beyond reach before it is skipped.
template <int D>
inline double EdmEngine<D>::pairTime(std::uint32_t a, std::uint32_t b, const Shift& m, double now,
                                     double horizon) const {
    const Hot& ha = hot_[a];
    const Hot& hb = hot_[b];
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
            for (int k = 0; k < D; ++k) r0[k] = (xn[k] - hb.x[k]) + m[k] * boxLen_[k];
            const double reach = norm(velAt(ha, now)) * tau + 0.5 * norm(g_) * tau * tau;
            if (norm(r0) - sigma > reach * (1 + 1e-9) + 1e-12 * sigma) return kNever;
        }
        Vec<D> r;
        for (int k = 0; k < D; ++k) r[k] = (ha.x[k] - hb.x[k]) + m[k] * boxLen_[k];
        t = ha.t + fixedSphereCollisionTime(r, ha.v, g_, sigma, kNever);
    } else {
        // Both extrapolated to the later clock (one of the two extrapolations is by zero: exact).
        const double tr = std::max(ha.t, hb.t);
        const Vec<D> xa = posAt(ha, tr), xb = posAt(hb, tr);
        const Vec<D> va = velAt(ha, tr), vb = velAt(hb, tr);
        Vec<D> r;
        for (int k = 0; k < D; ++k) r[k] = (xa[k] - xb[k]) + m[k] * boxLen_[k];
        t = tr + pairCollisionTime(r, va - vb, sigma);
    }
    return t < now ? pairTimeFromNow(a, b, m, now) : t;
}

// A root before now means an invalid state at the stored clocks (an overlap that round-off, or a bug, let pass).
// Its dynamics are decided by the state now (PHYSICS.md D.6): approaching now -> now; receding -> the next root
// from now. Deciding from the older state could schedule a collision that collidePair then finds receding.
template <int D>
double EdmEngine<D>::pairTimeFromNow(std::uint32_t a, std::uint32_t b, const Shift& m, double now) const {
    const Hot& ha = hot_[a];
    const Hot& hb = hot_[b];
    const Vec<D> xa = posAt(ha, now), xb = posAt(hb, now);
    Vec<D> r;
    for (int k = 0; k < D; ++k) r[k] = (xa[k] - xb[k]) + m[k] * boxLen_[k];
    const Vec<D> va = velAt(ha, now);
    const double tau = hb.t == kNever ? fixedSphereCollisionTime(r, va, g_, ha.r + hb.r, kNever)
                                      : pairCollisionTime(r, va - velAt(hb, now), ha.r + hb.r);
    return now + tau;
}

template <int D>
double EdmEngine<D>::wallTime(std::uint32_t s, std::size_t w, double now) const {
    const Hot& h = hot_[s];
    const Wall<D>& wl = w_.walls[w];
    const double t = h.t + wallCollisionTime(h.x, h.v, h.r, wl.pointAt(h.t), wl.velocity, wl.normal, g_);
    if (t >= now) return t;
    // Invalid state at the stored clock: decided by the state now, as for pairs.
    return now + wallCollisionTime(posAt(h, now), velAt(h, now), h.r, wl.pointAt(now), wl.velocity, wl.normal, g_);
}

// The canonical form of pairTime for moving slot s (state hs) and slot j seen through the image shift m, written
// out for speed: the older of the two states is extrapolated to the other's clock (an extrapolation by zero leaves a
// state unchanged, so skipping it gives the same bits). A candidate whose root cannot come before bestTime gives
// kNever without the square root or the division. The scalar twin of candidates4, which evaluates four candidates
// side by side with the same arithmetic and hands it the lanes it does not finish (frozen partner, root before now).
template <int D>
inline double EdmEngine<D>::candidateTime(const Hot& hs, std::uint32_t s, std::uint32_t j, const Shift& m, double now,
                                          double bestTime) const {
    const Hot& hj = hot_[j];
    if (hj.t == kNever) return pairTime(s, j, m, now, bestTime);
    const double ts = hs.t;
    double r[D], v[D], tr;
    if (hj.t <= ts) {
        tr = ts;
        const double db = ts - hj.t;
        for (int k = 0; k < D; ++k) {
            const double xb = hj.x[k] + (hj.v[k] + 0.5 * g_[k] * db) * db;
            r[k] = (hs.x[k] - xb) + m[k] * boxLen_[k];
            v[k] = hs.v[k] - (hj.v[k] + g_[k] * db);
        }
    } else {
        tr = hj.t;
        const double da = hj.t - ts;
        for (int k = 0; k < D; ++k) {
            const double xa = hs.x[k] + (hs.v[k] + 0.5 * g_[k] * da) * da;
            r[k] = (xa - hj.x[k]) + m[k] * boxLen_[k];
            v[k] = (hs.v[k] + g_[k] * da) - hj.v[k];
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

namespace {
/// The heads hc[deltas[q]] of N cells (q < N) that are not empty (kNil: empty), in order, to heads; returns how
/// many. With AVX2, eight cells at a time: one gathered load, the empty ones dropped by a lane permutation made from
/// the mask (pdep/pext), a store of all eight lanes (heads has room for eight past the last). deltas is padded to a
/// multiple of eight with offsets that stay inside the array (zeros).
template <int N>
[[gnu::always_inline]] inline int loadHeads(const std::uint32_t* hc, const std::int32_t* deltas, std::uint32_t* heads) {
    int nc = 0;
#if defined(__AVX2__) && defined(__BMI2__)
    for (int g = 0; g < N; g += 8) {
        const __m256i idx = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(deltas + g));
        const __m256i h = _mm256_i32gather_epi32(reinterpret_cast<const int*>(hc), idx, 4);
        const __m256i empty = _mm256_cmpeq_epi32(h, _mm256_set1_epi32(-1));
        unsigned m = ~static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(empty))) & 0xFFu;
        if (N - g < 8) m &= (1u << (N - g)) - 1;
        const std::uint64_t spread = _pdep_u64(m, 0x0101010101010101ull) * 0xFF;
        const std::uint64_t order = _pext_u64(0x0706050403020100ull, spread);
        const __m256i perm = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(static_cast<long long>(order)));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(heads + nc), _mm256_permutevar8x32_epi32(h, perm));
        nc += __builtin_popcount(m);
    }
#else
    for (int q = 0; q < N; ++q) {
        const std::uint32_t h = hc[deltas[q]];
        heads[nc] = h;
        nc += h != 0xFFFFFFFFu;
    }
#endif
    return nc;
}

/// Whether some lane of a comparison's result is set.
template <class M>
inline bool anyLane(M m) {
#ifdef __AVX__
    return _mm256_movemask_pd(reinterpret_cast<__m256d>(m)) != 0;
#else
    return (m[0] | m[1] | m[2] | m[3]) != 0;
#endif
}
}  // namespace

// The scanning slot's state and the constants, one value per lane (candidates4).
template <int D>
typename EdmEngine<D>::ScanState EdmEngine<D>::scanState(const Hot& hs) const {
    ScanState sc;
    for (int k = 0; k < D; ++k) {
        sc.x[k] = Lanes(hs.x[k]).v;
        sc.v[k] = Lanes(hs.v[k]).v;
        sc.gh[k] = Lanes(0.5 * g_[k]).v;
        sc.g[k] = Lanes(g_[k]).v;
        sc.len[k] = Lanes(boxLen_[k]).v;
    }
    sc.t = Lanes(hs.t).v;
    sc.r = Lanes(hs.r).v;
    return sc;
}

// Four candidates side by side: the arithmetic of candidateTime lane by lane (the same correctly rounded operations in
// the same order, no fused multiply-add), so a lane gives the bits candidateTime gives. Both states are extrapolated
// to the later clock tr, one of them by zero, which leaves it unchanged (x + (v + g/2 0) 0 = x), as candidateTime's
// two branches do. The tests a lane can fail cheaply (receding, b >= 0; root beyond the best event so far by the
// lower bound c / (-2 b)) are taken for all four at once; most batches end there. A lane that needs more than the
// quadratic (a frozen partner, a root before now, no relative speed) goes to candidateTime. The lanes are then
// offered to best in order, as the scalar loop would: the result is the minimum of (time, code), which does not
// depend on the order, and a skip against the best time before the batch (not the best within it) only skips
// less.
template <int D>
[[gnu::always_inline]] inline void EdmEngine<D>::candidates4(const ScanState& sc, const Hot& hs, std::uint32_t s,
                                                             const Batch& bt, std::uint32_t wsPacked,
                                                             const Shift* plainBase, double now, Candidate& best,
                                                             std::uint32_t& bestJ) const {
    using V = Lanes::Values;
    const std::uint32_t* j = bt.j;
    // Plain: no candidate needs an image shift (the same wraps as s, a cell that crosses no box face): most batches.
#ifdef __AVX2__
    // The same test, four lanes at once.
    const __m128i wraps = _mm_loadu_si128(reinterpret_cast<const __m128i*>(bt.wrap));
    const __m256i bases = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(bt.base));
    const __m128i sameWraps = _mm_cmpeq_epi32(wraps, _mm_set1_epi32(static_cast<int>(wsPacked)));
    const __m256i sameBase = _mm256_cmpeq_epi64(bases, _mm256_set1_epi64x(reinterpret_cast<long long>(plainBase)));
    const bool plain =
        (_mm_movemask_ps(_mm_castsi128_ps(sameWraps)) & _mm256_movemask_pd(_mm256_castsi256_pd(sameBase))) == 15;
#else
    const bool plain =
        ((bt.wrap[0] ^ wsPacked) | (bt.wrap[1] ^ wsPacked) | (bt.wrap[2] ^ wsPacked) | (bt.wrap[3] ^ wsPacked)) == 0 &&
        bt.base[0] == plainBase && bt.base[1] == plainBase && bt.base[2] == plainBase && bt.base[3] == plainBase;
#endif
    V X[D], Vv[D], T, R;
    if constexpr (D == 3) {
        Lanes a[4], b[4];
        transpose4(hot_[j[0]].x.c.data(), hot_[j[1]].x.c.data(), hot_[j[2]].x.c.data(), hot_[j[3]].x.c.data(), a);
        transpose4(hot_[j[0]].v.c.data(), hot_[j[1]].v.c.data(), hot_[j[2]].v.c.data(), hot_[j[3]].v.c.data(), b);
        for (int k = 0; k < 3; ++k) {
            X[k] = a[k].v;
            Vv[k] = b[k].v;
        }
        T = a[3].v;
        R = b[3].v;
    } else {
        const Hot &h0 = hot_[j[0]], &h1 = hot_[j[1]], &h2 = hot_[j[2]], &h3 = hot_[j[3]];
#ifdef __AVX__
        // 2D: (x0, x1, t, v0) and (v1, r) of each record (48 bytes, 16-aligned), transposed into lanes.
        const __m256d a0 = _mm256_loadu_pd(h0.x.c.data()), a1 = _mm256_loadu_pd(h1.x.c.data()),
                      a2 = _mm256_loadu_pd(h2.x.c.data()), a3 = _mm256_loadu_pd(h3.x.c.data());
        const __m256d lo01 = _mm256_unpacklo_pd(a0, a1), hi01 = _mm256_unpackhi_pd(a0, a1);
        const __m256d lo23 = _mm256_unpacklo_pd(a2, a3), hi23 = _mm256_unpackhi_pd(a2, a3);
        X[0] = _mm256_permute2f128_pd(lo01, lo23, 0x20);
        X[1] = _mm256_permute2f128_pd(hi01, hi23, 0x20);
        T = _mm256_permute2f128_pd(lo01, lo23, 0x31);
        Vv[0] = _mm256_permute2f128_pd(hi01, hi23, 0x31);
        const __m256d b02 = _mm256_set_m128d(_mm_load_pd(h2.v.c.data() + 1), _mm_load_pd(h0.v.c.data() + 1));
        const __m256d b13 = _mm256_set_m128d(_mm_load_pd(h3.v.c.data() + 1), _mm_load_pd(h1.v.c.data() + 1));
        Vv[1] = _mm256_unpacklo_pd(b02, b13);
        R = _mm256_unpackhi_pd(b02, b13);
#else
        for (int k = 0; k < D; ++k) {
            X[k] = V{h0.x[k], h1.x[k], h2.x[k], h3.x[k]};
            Vv[k] = V{h0.v[k], h1.v[k], h2.v[k], h3.v[k]};
        }
        T = V{h0.t, h1.t, h2.t, h3.t};
        R = V{h0.r, h1.r, h2.r, h3.r};
#endif
    }
    const V zero = {0, 0, 0, 0};
    const V tsL = sc.t;
    const auto frozenL = T == kNever;
    const V Tm = frozenL ? tsL : T;  // a frozen lane goes to candidateTime; no infinities in the arithmetic
    const V tr = tsL < Tm ? Tm : tsL;
    const V da = tr - tsL, db = tr - Tm;
    // Image shifts (base + wraps of the candidate) in box lengths, unless the batch is plain (all zero; the
    // scalar form adds 0 L, which changes at most the sign of a zero difference).
    std::int32_t m[D][4];
    if (!plain) {
        for (int l = 0; l < 4; ++l) {
            const Shift w = wrapsOf(bt.wrap[l]);
            for (int k = 0; k < D; ++k) m[k][l] = (*bt.base[l])[k] + w[k];
        }
    }
    V r[D], v[D];
    for (int k = 0; k < D; ++k) {
        const V xa = sc.x[k] + (sc.v[k] + sc.gh[k] * da) * da;
        const V xb = X[k] + (Vv[k] + sc.gh[k] * db) * db;
        r[k] = xa - xb;
        if (!plain) {
            LaneIndex mk;
            __builtin_memcpy(&mk, m[k], sizeof mk);
            r[k] += __builtin_convertvector(mk, V) * sc.len[k];
        }
        v[k] = (sc.v[k] + sc.g[k] * da) - (Vv[k] + sc.g[k] * db);
    }
    V b = r[0] * v[0], r2 = r[0] * r[0], v2 = v[0] * v[0];
    for (int k = 1; k < D; ++k) {
        b += r[k] * v[k];
        r2 += r[k] * r[k];
        v2 += v[k] * v[k];
    }
    const V sigma = sc.r + R;
    const V c = r2 - sigma * sigma;
    const V left = best.time - tr;
    const auto far = (c > 0) & (c > -2.0 * b * left * (1 + 1e-12));
    const auto todo = (b < 0) & ~far & ~frozenL;
    // Nothing to offer: every lane receding or beyond the best event (then kNever is not better than it either).
    if (best.time < kNever && !anyLane(todo | frozenL)) return;
    // f(t) = c + 2 b t + v2 t^2 with f2 = 2 v2 > 0 and f1 = 2 b < 0 (firstRootFalling's second branch)
    const V f1 = 2.0 * b, f2 = 2.0 * v2;
    const V arg = f1 * f1 - 2.0 * f2 * c;
    V sq;
#ifdef __AVX__
    sq = _mm256_sqrt_pd(arg > 0 ? arg : zero);
#else
    for (int l = 0; l < 4; ++l) sq[l] = std::sqrt(arg[l] > 0 ? arg[l] : 0.0);
#endif
    const V q = (2.0 * c) / (-f1 + sq);
    const V root = tr + (0 < q ? q : zero);
    const auto hit = todo & (arg > 0) & (f2 > 0);
    const auto special = frozenL | (todo & ~(f2 > 0)) | (hit & (root < now));
    const V t = hit ? root : zero + kNever;
    for (int l = 0; l < 4; ++l) {
        double tl = t[l];
        if (special[l]) {
            Shift ml{};  // a plain batch's shifts are zero
            if (!plain)
                for (int k = 0; k < D; ++k) ml[k] = m[k][l];
            tl = candidateTime(hs, s, j[l], ml, now, best.time);
        }
        const std::uint32_t code = (kPair << kTypeShift) | j[l];
        if (best.better(tl, code)) {
            best = {tl, code, 0};
            bestJ = j[l];
        }
    }
}

// Predicts the next event of slot s at time now: the earliest of its cell exit, its wall collisions and its
// collisions with the particles of the 3^D neighbour cells. After a cell crossing (axis >= 0, dir = +-1) with a
// still valid earlier result in rec_[s].coll, only the newly adjacent cells are scanned: the others were scanned
// before and their particles' trajectories are unchanged (a particle that changed since re-predicted itself).
template <int D>
void EdmEngine<D>::predict(std::uint32_t s, double now, int axis, int dir) {
    if (shells_) {
        predictShell(s, now);
        return;
    }
    const Domain<D>& dom = w_.domain;
    const Hot& hs = hot_[s];
    const Shift ws = wrapsOf(link_[s].wrap);
    // Cell coordinates and the faces s can leave through. The exit is computed from the state at "now": from the
    // older stored state the quadratic can also find a crossing that already happened (through a face and back
    // under gravity).
    const Vec<D> xNow = posAt(hs, now), vNow = velAt(hs, now);
    Candidate cross;
    std::array<int, D> cc;
    bool interior = true;
    for (int k = 0; k < D; ++k) {
        const int c = static_cast<int>((rec_[s].cell / stride_[k]) % static_cast<std::uint32_t>(nCell_[k]));
        cc[k] = c;
        interior = interior && c >= 1 && c <= nCell_[k] - 2;
        const bool per = dom.periodic[k];
        const double lo = (c == 0 && !per) ? -kNever : dom.lo[k] + c * cellW_[k];
        const double hi = (c == nCell_[k] - 1 && !per) ? kNever : dom.lo[k] + (c + 1) * cellW_[k];
        const CellExit ex = cellExitTime(xNow[k] - ws[k] * boxLen_[k], vNow[k], g_[k], lo, hi);
        if (ex.time < kNever) {
            const double t = now + ex.time;
            const std::uint32_t code = (kCell << kTypeShift) | static_cast<std::uint32_t>(2 * k + (ex.up ? 1 : 0));
            if (cross.better(t, code)) cross = {t, code, 0};
        }
    }
    Candidate best;
    if (axis >= 0) {
        best = {keptTime(s, now), rec_[s].coll.code, rec_[s].coll.stamp};
    } else {
        for (std::size_t w = 0; w < w_.walls.size(); ++w) {
            const double t = wallTime(s, w, now);
            const std::uint32_t code = (kWall << kTypeShift) | static_cast<std::uint32_t>(w);
            if (best.better(t, code)) best = {t, code, 0};
        }
    }
    // Neighbour cells: the heads of those that are not empty, loaded first and their first members prefetched, so
    // that the cache misses overlap instead of following each other. A cell away from the box faces takes its
    // neighbours from a table of index offsets; one at a face (open or periodic) goes through the per-axis lists,
    // with the image shift of each cell (base: minus s's wraps, minus the box lengths crossed).
    constexpr int kMaxCells = D == 3 ? 27 : 9;
    std::uint32_t heads[kMaxCells + 8];  // loadHeads stores whole groups of eight
    Shift bases[kMaxCells];
    bool plainCell[kMaxCells];  // base = -ws: no box length crossed
    int nc = 0;
    Shift negWs;
    for (int k = 0; k < D; ++k) negWs[k] = -ws[k];
    if (interior) {
        const std::uint32_t* hc = &head_[rec_[s].cell];
        nc = axis < 0 ? loadHeads<kNbrCells>(hc, deltaFull_.data(), heads)
                      : loadHeads<kSideCells>(hc, deltaSide_[2 * axis + (dir > 0 ? 1 : 0)].data(), heads);
    } else {
        std::array<std::array<int, 3>, D> nbr, omega;
        std::array<int, D> nbrCount;
        bool any = true;
        for (int k = 0; k < D; ++k) {
            const bool per = dom.periodic[k];
            int m = 0;
            for (int o = -1; o <= 1; ++o) {
                if (k == axis && o != dir) continue;
                int cn = cc[k] + o, om = 0;
                if (cn < 0) {
                    if (!per) continue;
                    cn += nCell_[k];
                    om = -1;
                } else if (cn >= nCell_[k]) {
                    if (!per) continue;
                    cn -= nCell_[k];
                    om = 1;
                }
                nbr[k][m] = cn;
                omega[k][m] = om;
                ++m;
            }
            nbrCount[k] = m;
            any = any && m > 0;
        }
        std::array<int, D> at{};
        while (any) {
            std::uint32_t cellIndex = 0;
            bool plain = true;
            for (int k = 0; k < D; ++k) {
                cellIndex += static_cast<std::uint32_t>(nbr[k][at[k]]) * stride_[k];
                bases[nc][k] = -ws[k] - omega[k][at[k]];
                plain = plain && omega[k][at[k]] == 0;
            }
            const std::uint32_t h = head_[cellIndex];
            heads[nc] = h;
            plainCell[nc] = plain;
            nc += h != kNil;
            int k = 0;
            while (k < D && ++at[k] == nbrCount[k]) at[k++] = 0;
            if (k == D) break;
        }
    }
    for (int q = 0; q < nc; ++q) {
        __builtin_prefetch(&hot_[heads[q]]);
        __builtin_prefetch(&link_[heads[q]]);
    }
    // The candidates are collected four at a time and evaluated side by side (candidates4): the arithmetic of
    // candidateTime lane by lane. Candidates later than the best pair or wall event so far are skipped before the
    // square root, but never because they are later than the cell exit: rec_[s].coll must stay the earliest over
    // all neighbours for the partial scans after a crossing. A batch is plain when no candidate needs an image
    // shift (same wraps as s, a cell that crosses no box face): most are. The lists are walked first (only the
    // links), in chunks of at most kChunk candidates (a cell of a coarse grid can hold many).
    constexpr int kChunk = 64;
    const ScanState sc = scanState(hs);
    const std::uint32_t wsPacked = link_[s].wrap;
    std::uint32_t cand[kChunk + 4], wrap[kChunk + 4];
    const Shift* base[kChunk + 4];
    std::uint32_t bestJ = kNil;
    // Evaluates the candidates of the buffer in fours (all: also the last one to three); returns how many are left.
    auto evaluate = [&](int n, bool all) {
        int i = 0;
        for (; i + 4 <= n; i += 4)
            candidates4(sc, hs, s, Batch{cand + i, wrap + i, base + i}, wsPacked, &negWs, now, best, bestJ);
        if (all && i < n) {
            // The last lanes repeat the first candidate: the same time and code, never better than itself.
            for (int l = n; l < i + 4; ++l) {
                cand[l] = cand[i];
                wrap[l] = wrap[i];
                base[l] = base[i];
            }
            candidates4(sc, hs, s, Batch{cand + i, wrap + i, base + i}, wsPacked, &negWs, now, best, bestJ);
            i = n;
        }
        for (int l = i; l < n; ++l) {  // fewer than four left: to the front
            cand[l - i] = cand[l];
            wrap[l - i] = wrap[l];
            base[l - i] = base[l];
        }
        return n - i;
    };
    int n = 0;
    for (int q = 0; q < nc; ++q) {
        const Shift* b = (interior || plainCell[q]) ? &negWs : &bases[q];
        std::uint32_t j = heads[q];
        for (;;) {
            do {
                const Link& lj = link_[j];
                if (lj.next != kNil) __builtin_prefetch(&hot_[lj.next]);
                cand[n] = j;
                wrap[n] = lj.wrap;
                base[n] = b;
                n += j != s;
                j = lj.next;
            } while (j != kNil && n < kChunk);
            if (j == kNil) break;
            n = evaluate(n, false);
        }
    }
    evaluate(n, true);
    if (bestJ != kNil) best.stamp = link_[bestJ].count;
    setPending(s, best, cross);
}

template <int D>
void EdmEngine<D>::setPending(std::uint32_t s, const Candidate& best, const Candidate& cross) {
    Rec& r = rec_[s];
    r.coll = Kept{best.code, best.stamp};
    r.exit = cross.code & 7u;
    const bool crossing = !cross.better(best.time, best.code);  // a tie goes to the pair or wall event
    r.crossing = crossing;
    queue_.update(s, crossing ? cross.time : best.time);
}

// Whether the best pair or wall event of slot s's last scan is still its best among the cells scanned then, so that a
// crossing needs to scan only the new neighbour cells: its partner has not collided since (walls and frozen partners
// never change), and its time can be recomputed (keptTime). Not for a frozen partner: under gravity its path relative
// to s is a parabola, which can carry s far away and back, beyond the reach of the minimum image.
template <int D>
bool EdmEngine<D>::keepsColl(std::uint32_t s) const {
    if (!partialScans_) return false;
    const Kept& c = rec_[s].coll;
    if ((c.code >> kTypeShift) != kPair) return true;
    const std::uint32_t j = c.code & kIndexMask;
    return link_[j].count == c.stamp && !frozen(j);
}

// The time of slot s's kept event, recomputed at a crossing (now) in the canonical form, so the same bits as when the
// scan found it, unless a synchronisation has rounded the stored states since or the state is invalid (PHYSICS.md
// D.6: decided afresh from the state now); docs/edm.md, "Canonical arithmetic". The partner's periodic
// image is the minimum image now: the pair approaches, so the two are no farther apart than when the scan found them
// in neighbouring cells (sqrt(D) times two cell edges), which is less than half the box with 7 cells per axis.
template <int D>
double EdmEngine<D>::keptTime(std::uint32_t s, double now) const {
    const Kept& c = rec_[s].coll;
    const std::uint32_t k = c.code & kIndexMask;
    switch (c.code >> kTypeShift) {
        case kWall:
            return wallTime(s, k, now);
        case kPair: {
            const Vec<D> d = posAt(hot_[s], now) - posAt(hot_[k], now);
            Shift m{};
            for (int a = 0; a < D; ++a)
                if (w_.domain.periodic[a]) m[a] = -static_cast<std::int32_t>(std::nearbyint(d[a] / boxLen_[a]));
            return pairTime(s, k, m, now, kNever);
        }
        default:
            return kNever;
    }
}

// ---------------------------------------------------------------------------------------------------------------
// neighbour shells (Donev, Torquato & Stillinger 2005; Smallenburg 2022), docs/edm.md
//
// Each particle has a centre (its box-frame position when its list was made) and stays within the cube of half-edge
// h around it: leaving the cube is an event (the same per-axis exit times as a cell crossing, so gravity costs
// nothing extra). Two particles can touch before either leaves its cube only if the cubes, widened by the sum of
// the radii, meet: per axis the gap max(0, |c_i - c_j| - 2h), and the sum of the squared gaps at most the squared
// sum of the radii. The lists hold exactly these pairs, in both particles' lists; a particle that leaves its cube
// takes itself out of its neighbours' lists, takes a new centre and a new list from the grid of centres, and puts
// itself into its new neighbours' lists. A collision is found by whichever of the two predicts after the pair
// became listed: its prediction sees the other, as in the cell scheme.

namespace {
/// Image code of a list entry: 2 bits per axis, image + 1 (image in -1, 0, 1).
template <std::size_t D>
std::uint32_t imageCode(const std::array<std::int32_t, D>& image, int sign) {
    std::uint32_t code = 0;
    for (std::size_t k = 0; k < D; ++k) code |= static_cast<std::uint32_t>(sign * image[k] + 1) << (2 * k);
    return code;
}
/// The same entry as seen from the partner: every image negated.
template <int D>
std::uint32_t mirrorImage(std::uint32_t code) {
    std::uint32_t out = 0;
    for (int k = 0; k < D; ++k) out |= (2 - ((code >> (2 * k)) & 3u)) << (2 * k);
    return out;
}
}  // namespace

// Puts s into the lists of the particles whose shells its new shell meets, and them into its list.
// Whether particles s and j (image `image` of j) can touch while each stays in its cube: the two cubes, grown by
// the radii, overlap.
template <int D>
bool EdmEngine<D>::shellsMeet(std::uint32_t s, std::uint32_t j, const Shift& image) const {
    const double reach = 2 * shellHalf_;
    double gap2 = 0;
    for (int k = 0; k < D; ++k) {
        const double gap = std::abs(centre_[s].c[k] - centre_[j].c[k] - image[k] * boxLen_[k]) - reach;
        if (gap > 0) gap2 += gap * gap;
    }
    const double sigma = (centre_[s].r + centre_[j].r) * (1 + 1e-9);
    return gap2 <= sigma * sigma;
}

// false: a list is full (nothing is undone; the caller rebuilds every list with longer rows).
template <int D>
bool EdmEngine<D>::linkShell(std::uint32_t s) {
    bool ok = true;
    forEachCellAround(rec_[s].cell, [&](std::uint32_t c, const Shift& image) {
        for (std::uint32_t j = head_[c]; j != kNil && ok; j = link_[j].next) {
            if (j == s || !shellsMeet(s, j, image)) continue;
            std::uint32_t* a = row(s);
            std::uint32_t* b = row(j);
            if (a[0] + 1 >= rowLen_ || b[0] + 1 >= rowLen_) {
                ok = false;
                return;
            }
            a[++a[0]] = j | (imageCode<D>(image, 1) << kImageShift);
            b[++b[0]] = s | (imageCode<D>(image, -1) << kImageShift);
        }
    });
    return ok;
}

// Takes s out of its neighbours' lists and empties its own.
template <int D>
void EdmEngine<D>::unlinkShell(std::uint32_t s) {
    std::uint32_t* a = row(s);
    for (std::uint32_t q = 1; q <= a[0]; ++q) {
        const std::uint32_t j = a[q] & kSlotMask;
        const std::uint32_t mine = s | (mirrorImage<D>(a[q] >> kImageShift) << kImageShift);
        std::uint32_t* b = row(j);
        for (std::uint32_t u = 1; u <= b[0]; ++u) {
            if (b[u] != mine) continue;
            b[u] = b[b[0]--];
            break;
        }
    }
    a[0] = 0;
}

// Slot s leaves its shell at time now: a new centre (its box-frame position now, brought into the box on periodic
// axes by changing its wrap count, which leaves its stored state alone) and a new list.
template <int D>
void EdmEngine<D>::moveShell(std::uint32_t s, double now) {
    unlinkShell(s);
    const Vec<D> x = posAt(hot_[s], now);
    Shift ws = wrapsOf(link_[s].wrap);
    Vec<D> c;
    for (int k = 0; k < D; ++k) {
        c[k] = x[k] - ws[k] * boxLen_[k];
        const double lo = w_.domain.lo[k], L = boxLen_[k];
        if (!w_.domain.periodic[k] || (c[k] >= lo && c[k] < lo + L)) continue;
        ws[k] += static_cast<std::int32_t>(std::floor((c[k] - lo) / L));
        c[k] = x[k] - ws[k] * boxLen_[k];
    }
    setWraps(s, ws);
    centre_[s].c = c;
    const std::uint32_t cell = cellOf(c);
    if (cell != rec_[s].cell) {
        removeCell(s);
        insertCell(s, cell);
    }
    if (!linkShell(s)) {
        ++stats_.listGrowths;
        buildLists();
    }
}

// Every list from the centres: first the longest list, then rows with room to grow, then each row from its own scan
// (the lists are symmetric, so no row needs another's).
template <int D>
void EdmEngine<D>::buildLists() {
    const std::uint32_t n = static_cast<std::uint32_t>(hot_.size());
    auto scan = [&](std::uint32_t s, auto&& take) {
        forEachCellAround(rec_[s].cell, [&](std::uint32_t c, const Shift& image) {
            for (std::uint32_t j = head_[c]; j != kNil; j = link_[j].next)
                if (j != s && shellsMeet(s, j, image)) take(j, image);
        });
    };
    std::uint32_t longest = 0;
    for (std::uint32_t s = 0; s < n; ++s) {
        if (rec_[s].idx == kNil) continue;
        std::uint32_t count = 0;
        scan(s, [&](std::uint32_t, const Shift&) { ++count; });
        longest = std::max(longest, count);
    }
    // Room for fluctuations: a list grows when a neighbour's new shell meets the particle's.
    const std::size_t len = std::max<std::size_t>(rowLen_ + 4, longest + 5);
    rowLen_ = (len + 3) / 4 * 4;
    nbr_.assign(static_cast<std::size_t>(n) * rowLen_, 0);
    for (std::uint32_t s = 0; s < n; ++s) {
        if (rec_[s].idx == kNil) continue;
        std::uint32_t* a = row(s);
        scan(s, [&](std::uint32_t j, const Shift& image) { a[++a[0]] = j | (imageCode<D>(image, 1) << kImageShift); });
    }
}

// Next event of slot s with neighbour shells: its shell exit, its walls, the particles of its list.
template <int D>
void EdmEngine<D>::predictShell(std::uint32_t s, double now) {
    const Hot& hs = hot_[s];
    const std::uint32_t* a = row(s);
    const std::uint32_t count = a[0];
    for (std::uint32_t q = 1; q <= count; ++q) {
        __builtin_prefetch(&hot_[a[q] & kSlotMask]);
        if (periodic_) __builtin_prefetch(&link_[a[q] & kSlotMask]);
    }
    const Shift ws = wrapsOf(link_[s].wrap);
    const Vec<D> xNow = posAt(hs, now), vNow = velAt(hs, now);
    const Vec<D>& c = centre_[s].c;
    Candidate cross;
    for (int k = 0; k < D; ++k) {
        const CellExit ex =
            cellExitTime(xNow[k] - ws[k] * boxLen_[k], vNow[k], g_[k], c[k] - shellHalf_, c[k] + shellHalf_);
        const double t = now + ex.time;
        const std::uint32_t code = (kCell << kTypeShift) | static_cast<std::uint32_t>(2 * k + (ex.up ? 1 : 0));
        if (cross.better(t, code)) cross = {t, code, 0};
    }
    Candidate best;
    for (std::size_t w = 0; w < w_.walls.size(); ++w) {
        const double t = wallTime(s, w, now);
        const std::uint32_t code = (kWall << kTypeShift) | static_cast<std::uint32_t>(w);
        if (best.better(t, code)) best = {t, code, 0};
    }
    // Four partners at a time, as in the cell scan (candidates4); the image of a list entry is a base per entry.
    const ScanState sc = scanState(hs);
    const std::uint32_t zeroWraps = packWraps(Shift{});
    const Shift none{};
    std::uint32_t cand[4], wrap[4] = {zeroWraps, zeroWraps, zeroWraps, zeroWraps};
    Shift bases[4];
    const Shift* base[4];
    int nb = 0;
    std::uint32_t bestJ = kNil;
    for (std::uint32_t q = 1; q <= count; ++q) {
        const std::uint32_t j = a[q] & kSlotMask;
        cand[nb] = j;
        base[nb] = &none;
        if (periodic_) {
            const std::uint32_t image = a[q] >> kImageShift;
            const Shift wj = wrapsOf(link_[j].wrap);
            bool zero = true;
            for (int k = 0; k < D; ++k) {
                bases[nb][k] = wj[k] - ws[k] - (static_cast<std::int32_t>((image >> (2 * k)) & 3u) - 1);
                zero = zero && bases[nb][k] == 0;
            }
            if (!zero) base[nb] = &bases[nb];
        }
        if (++nb == 4) {
            candidates4(sc, hs, s, Batch{cand, wrap, base}, zeroWraps, &none, now, best, bestJ);
            nb = 0;
        }
    }
    if (nb > 0) {
        for (int l = nb; l < 4; ++l) {
            cand[l] = cand[0];
            base[l] = base[0];
        }
        candidates4(sc, hs, s, Batch{cand, wrap, base}, zeroWraps, &none, now, best, bestJ);
    }
    if (bestJ != kNil) best.stamp = link_[bestJ].count;
    setPending(s, best, cross);
}

template <int D>
void EdmEngine<D>::crossCell(std::uint32_t s, int axis, bool up) {
    const int c = static_cast<int>((rec_[s].cell / stride_[axis]) % static_cast<std::uint32_t>(nCell_[axis]));
    int cn = c + (up ? 1 : -1);
    if (cn >= nCell_[axis] || cn < 0) {  // only on periodic axes: outer cells of open axes are unbounded
        cn = cn < 0 ? nCell_[axis] - 1 : 0;
        Shift ws = wrapsOf(link_[s].wrap);
        ws[axis] += up ? 1 : -1;
        setWraps(s, ws);
    }
    const std::uint32_t newCell =
        rec_[s].cell + (static_cast<std::uint32_t>(cn) - static_cast<std::uint32_t>(c)) * stride_[axis];
    const std::uint32_t oldCell = rec_[s].cell;
    removeCell(s);
    insertCell(s, newCell);
    if (zoned_) {
        const std::uint32_t za = zoneOfCell(oldCell), zb = zoneOfCell(newCell);
        if (za != zb) {
            const double vol = Particles<D>::volumeOf(hot_[s].r);
            zoneVolume_[za] -= vol;
            zoneVolume_[zb] += vol;
        }
        if ((*zone_.guard)[newCell]) guardEntries_.push_back(rec_[s].idx);
    }
}

// ---------------------------------------------------------------------------------------------------------------
// collisions

template <int D>
CollisionLaw EdmEngine<D>::lawFor(int matA, int matB, bool elastic) const {
    const PairCoeffs& c = w_.contact.pair(matA, matB);
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
bool EdmEngine<D>::tcElastic(std::uint32_t a, std::uint32_t b, double t) const {
    if (!(tc_ > 0)) return false;
    if (t - tLast_[a] < tc_) return true;
    return b != kNil && t - tLast_[b] < tc_;
}

template <int D>
void EdmEngine<D>::notify(double t, std::uint32_t a, std::uint32_t partner, bool wall, bool elastic, bool hop,
                          const Vec<D>& P) {
    if (!observer_) return;
    EdmCollision<D> c;
    c.time = t;
    c.i = rec_[a].idx;
    c.partner = wall ? partner : rec_[partner].idx;
    c.wall = wall;
    c.elastic = elastic;
    c.restHop = hop;
    c.impulse = P;
    observer_(c);
}

template <int D>
void EdmEngine<D>::collidePair(std::uint32_t a, std::uint32_t b, double t) {
    Particles<D>& p = w_.particles;
    // Canonical order: the lower World index is body 1 (a frozen partner always body 2), so the result does not
    // depend on which of the two particles' events found the collision (the operator's sums are not associative).
    if ((rec_[b].idx < rec_[a].idx && !frozen(b)) || frozen(a)) std::swap(a, b);
    const std::uint32_t i = rec_[a].idx, j = rec_[b].idx;
    const bool fb = frozen(b);
    // The state at t, committed only if the collision happens (a skipped event leaves no trace).
    const Vec<D> va = velAt(hot_[a], t), vb = velAt(hot_[b], t);
    Vec<D> d = posAt(hot_[a], t) - posAt(hot_[b], t);
    for (int k = 0; k < D; ++k)
        if (w_.domain.periodic[k]) d[k] += -std::nearbyint(d[k] / boxLen_[k]) * boxLen_[k];
    const double bdot = dot(d, va - vb);
    const Vec<D> n = d * (1.0 / norm(d));
    // Rest hop (docs/edm.md): against a fixed obstacle that gravity pushes the particle into, the normal speed
    // after the collision is at least |n.g| tcTime: it hops with a flight of 2 tcTime instead of coming to rest
    // through infinitely many collisions.
    const double gAcc = fb ? dot(n, g_) : 0;
    const double uRest = (tc_ > 0 && gAcc < 0) ? -gAcc * tc_ : 0;
    const int ma = materialOf(i), mb = materialOf(j);
    // A smooth pair (beta = -1 whatever the velocities) gets an impulse along n, which leaves the spins alone:
    // its bodies go without rotation, so the spins are neither read nor written.
    const bool smooth = smoothPair(ma, mb);
    CollisionBody<D> b1{va, Ang<D>::zero(), hot_[a].r, p.invMass[i], 0.0};
    CollisionBody<D> b2{vb, Ang<D>::zero(), hot_[b].r, fb ? 0.0 : p.invMass[j], 0.0};
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
    advance(a, t);
    advance(b, t);
    const bool elastic = tcElastic(a, fb ? kNil : b, t);
    bool hop = false;
    const Vec<D> P = impulseWithHop(b1, b2, n, lawFor(ma, mb, elastic), approaching, gn, uRest, hop);
    const double before = kineticEnergy(b1) + kineticEnergy(b2);
    applyImpulse(b1, b2, n, P);
    stats_.dissipated += before - kineticEnergy(b1) - kineticEnergy(b2);
    if (elastic && zoned_ && zone_.handoverOnTc) {
        tcHandovers_.push_back(i);
        if (!fb) tcHandovers_.push_back(j);
    }
    hot_[a].v = b1.v;
    if (!smooth) p.w[i] = b1.w;
    ++link_[a].count;
    if (tc_ > 0) tLast_[a] = t;
    if (!fb) {
        hot_[b].v = b2.v;
        if (!smooth) p.w[j] = b2.w;
        ++link_[b].count;
        if (tc_ > 0) tLast_[b] = t;
    }
    virial_ += dot(d, P);
    ++stats_.pairCollisions;
    if (elastic) ++stats_.tcElastic;
    if (hop) ++stats_.restHops;
    notify(t, a, b, false, elastic, hop, P);
}

template <int D>
void EdmEngine<D>::collideWall(std::uint32_t s, std::uint32_t w, double t) {
    Particles<D>& p = w_.particles;
    const std::uint32_t i = rec_[s].idx;
    const Wall<D>& wl = w_.walls[w];
    const Vec<D>& n = wl.normal;
    const double gAcc = dot(n, g_);
    const double uRest = (tc_ > 0 && gAcc < 0) ? -gAcc * tc_ : 0;
    const Vec<D> vs = velAt(hot_[s], t);
    const int ma = materialOf(i);
    const bool smooth = smoothPair(ma, wl.material);  // as in collidePair
    CollisionBody<D> b1{vs, smooth ? Ang<D>::zero() : p.w[i], hot_[s].r, p.invMass[i], smooth ? 0.0 : p.invInertia[i]};
    CollisionBody<D> b2{wl.velocity, Ang<D>::zero(), 0.0, 0.0, 0.0};
    const double gn = dot(vs - wl.velocity, n);
    if (gn >= 0 && !(uRest > gn)) {  // not approaching: nothing happens, no state change
        ++stats_.grazing;
        return;
    }
    advance(s, t);
    const bool elastic = tcElastic(s, kNil, t);
    bool hop = false;
    const Vec<D> P = impulseWithHop(b1, b2, n, lawFor(ma, wl.material, elastic), gn < 0, gn, uRest, hop);
    const double before = kineticEnergy(b1);
    applyImpulse(b1, b2, n, P);
    stats_.dissipated += before - kineticEnergy(b1);
    if (elastic && zoned_ && zone_.handoverOnTc) tcHandovers_.push_back(i);
    hot_[s].v = b1.v;
    if (!smooth) p.w[i] = b1.w;
    ++link_[s].count;
    if (tc_ > 0) tLast_[s] = t;
    ++stats_.wallCollisions;
    if (elastic) ++stats_.tcElastic;
    if (hop) ++stats_.restHops;
    notify(t, s, w, true, elastic, hop, P);
}

// ---------------------------------------------------------------------------------------------------------------
// the event loop

template <int D>
void EdmEngine<D>::checkRate(double t) {
    const double span = t - winTime_;
    const double perParticle = static_cast<double>(window_) / static_cast<double>(std::max<std::size_t>(1, nMoving_));
    const bool tooFast = maxRate_ > 0 ? perParticle > maxRate_ * span : !(span > 0);
    if (tooFast) {
        std::ostringstream msg;
        msg << "event-driven engine: " << window_ << " events in " << span << " s of simulated time before t = " << t
            << " s (" << perParticle / span << " events per particle per second";
        if (maxRate_ > 0) msg << ", bound " << maxRate_;
        msg << "): inelastic collapse or a zero-time loop";
        if (!(tc_ > 0)) msg << "; the TC model is off";
        throw SimulationError(msg.str());
    }
    winEvents_ = events_;
    winTime_ = t;
}

template <int D>
void EdmEngine<D>::processNext() {
    const std::uint32_t s = queue_.top();
    const double t = queue_.topTime();
    countEvent(t);
    const Rec& rs = rec_[s];
    const std::uint32_t code = rs.crossing ? (kCell << kTypeShift) | rs.exit : rs.coll.code;
    const std::uint32_t k = code & kIndexMask;
    switch (code >> kTypeShift) {
        case kPair:
            if (link_[k].count != rec_[s].coll.stamp) {  // the partner collided since: re-predict
                ++stats_.stale;
                predict(s, t);
                return;
            }
            collidePair(s, k, t);
            predict(s, t);
            if (!frozen(k)) predict(k, t);
            return;
        case kWall:
            collideWall(s, k, t);
            predict(s, t);
            return;
        case kCell: {
            if (shells_) {
                ++stats_.shellExits;
                moveShell(s, t);
                predictShell(s, t);
                return;
            }
            ++stats_.cellCrossings;
            const int axis = static_cast<int>(k >> 1);
            const bool up = k & 1;
            crossCell(s, axis, up);
            // The earlier scan's best pair or wall event stays valid unless its partner collided since.
            if (keepsColl(s))
                predict(s, t, axis, up ? 1 : -1);
            else
                predict(s, t);
            return;
        }
        default:
            queue_.update(s, kNever);
            return;
    }
}

template <int D>
void EdmEngine<D>::syncSlot(std::uint32_t s, double t) {
    advance(s, t);
    storeSlot(s);
    const Particles<D>& p = w_.particles;
    const Hot& h = hot_[s];
    const std::uint32_t i = rec_[s].idx;
    if (!std::isfinite(norm2(h.x) + norm2(h.v) + norm2(p.w[i]))) {
        std::ostringstream msg;
        msg << "event-driven engine: particle " << p.id[i] << " (index " << i << ") has a non-finite state at t = " << t
            << " s";
        throw SimulationError(msg.str());
    }
}

// Writes moving slot s's stored state (at its clock) to the World, its position wrapped into the box.
template <int D>
void EdmEngine<D>::storeSlot(std::uint32_t s) {
    Particles<D>& p = w_.particles;
    const Domain<D>& dom = w_.domain;
    Hot& h = hot_[s];
    const std::uint32_t i = rec_[s].idx;
    Shift ws = wrapsOf(link_[s].wrap);
    for (int k = 0; k < D; ++k) {
        if (!dom.periodic[k]) continue;
        double& x = h.x[k];
        const double lo = dom.lo[k], L = boxLen_[k];
        if (x >= lo && x < lo + L) continue;
        const double sh = std::floor((x - lo) / L);
        x -= sh * L;
        p.image[i][k] += static_cast<std::int32_t>(sh);
        // The box-frame position x - wrap L is unchanged, so the cell and the pending events stay valid.
        ws[k] -= static_cast<std::int32_t>(sh);
    }
    link_[s].wrap = packWraps(ws);
    p.x[i] = h.x;
    p.v[i] = h.v;
}

template <int D>
void EdmEngine<D>::synchronise(double t) {
    Particles<D>& p = w_.particles;
    const bool restore = !p.hasMotion();
    if (restore) p.restoreMotion();
    for (std::uint32_t s = 0; s < hot_.size(); ++s) {
        const std::uint32_t i = rec_[s].idx;
        if (i == kNil) continue;
        if (!frozen(s)) {
            syncSlot(s, t);
        } else if (restore) {
            p.x[i] = hot_[s].x;
            p.v[i] = hot_[s].v;
        }
        if (restore) p.radius[i] = hot_[s].r;
    }
    w_.time = t;
}

// After an error in advanceEvents: the World gets its arrays back with every particle's state at its own clock.
template <int D>
void EdmEngine<D>::putBackState() {
    Particles<D>& p = w_.particles;
    if (p.hasMotion()) return;
    p.restoreMotion();
    for (std::uint32_t s = 0; s < hot_.size(); ++s) {
        const std::uint32_t i = rec_[s].idx;
        if (i == kNil) continue;
        if (!frozen(s)) {
            storeSlot(s);
        } else {
            p.x[i] = hot_[s].x;
            p.v[i] = hot_[s].v;
        }
        p.radius[i] = hot_[s].r;
    }
}

template <int D>
void EdmEngine<D>::advanceReference(double t) {
    const Domain<D>& dom = w_.domain;
    const std::uint32_t n = static_cast<std::uint32_t>(hot_.size());
    double now = w_.time;
    // Within the horizon every particle moves less than delta, so a pair that collides is at its minimum
    // image now (|r| <= sigma + 2 delta <= L/2): the minimum image is enough.
    double lmin = kNever;
    for (int k = 0; k < D; ++k)
        if (dom.periodic[k]) lmin = std::min(lmin, boxLen_[k]);
    const double delta = 0.5 * (0.5 * lmin - 2 * rmax_);
    const double gAbs = norm(g_);
    for (;;) {
        double horizon = kNever;
        if (lmin < kNever) {
            double vmax = 0;
            for (std::uint32_t s = 0; s < n; ++s)
                if (!frozen(s)) vmax = std::max(vmax, norm(velAt(hot_[s], now)));
            horizon = now + 2 * delta / (vmax + std::sqrt(vmax * vmax + 2 * gAbs * delta));
        }
        double bestT = kNever;
        std::uint32_t bestS = 0, bestCode = kNone << kTypeShift;
        for (std::uint32_t s = 0; s < n; ++s) {
            if (frozen(s)) continue;
            Candidate c;
            for (std::size_t w = 0; w < w_.walls.size(); ++w) {
                const double tw = wallTime(s, w, now);
                const std::uint32_t code = (kWall << kTypeShift) | static_cast<std::uint32_t>(w);
                if (c.better(tw, code)) c = {tw, code, 0};
            }
            const Vec<D> xs = posAt(hot_[s], now);
            for (std::uint32_t j = 0; j < n; ++j) {
                if (j == s) continue;
                const Vec<D> d = xs - posAt(hot_[j], now);
                Shift m{};
                for (int k = 0; k < D; ++k)
                    if (dom.periodic[k]) m[k] = -static_cast<std::int32_t>(std::nearbyint(d[k] / boxLen_[k]));
                const double tp = pairTime(s, j, m, now, c.time);
                const std::uint32_t code = (kPair << kTypeShift) | j;
                if (c.better(tp, code)) c = {tp, code, 0};
            }
            if (c.time < bestT) {
                bestT = c.time;
                bestS = s;
                bestCode = c.code;
            }
        }
        if (std::min(bestT, horizon) >= t) break;
        if (horizon < bestT) {
            now = horizon;
            continue;
        }
        countEvent(bestT);
        now = bestT;
        const std::uint32_t k = bestCode & kIndexMask;
        if ((bestCode >> kTypeShift) == kPair)
            collidePair(bestS, k, bestT);
        else
            collideWall(bestS, k, bestT);
    }
}

template <int D>
void EdmEngine<D>::advanceTo(double t) {
    if (t < w_.time) throw std::invalid_argument("event-driven engine: advanceTo into the past");
    if (s_.reference) {
        advanceReference(t);
        synchronise(t);
        return;
    }
    advanceEvents(t);
    synchronise(t);
}

template <int D>
void EdmEngine<D>::advanceEvents(double t) {
    if (s_.reference) throw std::logic_error("event-driven engine: advanceEvents in reference mode");
    if (s_.holdState && w_.particles.hasMotion()) w_.particles.releaseMotion();
    try {
        while (queue_.size() > 0 && queue_.topTime() < t) processNext();
    } catch (...) {
        putBackState();
        throw;
    }
    // Particles diffuse away from their sorted neighbours; re-sort after ~20 events per particle.
    if (events_ - sortedAt_ > 20 * static_cast<std::uint64_t>(std::max<std::size_t>(nLive_, 1))) resort();
}

// ---------------------------------------------------------------------------------------------------------------
// particles joining and leaving (hybrid runs)

template <int D>
void EdmEngine<D>::remove(std::size_t i, double t) {
    if (s_.holdState) throw std::logic_error("event-driven engine: particles join and leave only without holdState");
    if (!owns(i)) throw std::logic_error("event-driven engine: remove of a particle it does not own");
    const std::uint32_t s = slotOf_[i];
    const bool fz = frozen(s);
    if (!fz) syncSlot(s, t);
    if (shells_) unlinkShell(s);
    removeCell(s);
    if (zoned_) zoneVolume_[zoneOfCell(rec_[s].cell)] -= Particles<D>::volumeOf(hot_[s].r);
    ++link_[s].count;  // events of others that name s are stale now
    hot_[s].t = kNever;
    hot_[s].v = Vec<D>::zero();
    rec_[s].idx = kNil;
    rec_[s].cell = static_cast<std::uint32_t>(head_.size());
    rec_[s].coll = Kept{};
    rec_[s].crossing = 0;
    queue_.update(s, kNever);
    slotOf_[i] = kNil;
    free_.push_back(s);
    --nLive_;
    if (!fz) --nMoving_;
}

template <int D>
void EdmEngine<D>::add(std::size_t i, double t) {
    Particles<D>& p = w_.particles;
    if (s_.holdState) throw std::logic_error("event-driven engine: particles join and leave only without holdState");
    if (owns(i) || i >= p.size()) throw std::logic_error("event-driven engine: add of an owned or unknown particle");
    if (free_.empty()) throw std::logic_error("event-driven engine: no free slot");
    if (p.radius[i] > rmax_ * (1 + 1e-12)) throw std::logic_error("event-driven engine: particle larger than the grid");
    requireKnownMaterial(i);
    const std::uint32_t s = free_.back();
    free_.pop_back();
    wrapIntoBox(i);
    const bool fz = p.frozen(i);
    hot_[s] = Hot{p.x[i], fz ? kNever : t, fz ? Vec<D>::zero() : p.v[i], p.radius[i]};
    link_[s].wrap = packWraps(Shift{});
    ++link_[s].count;
    rec_[s].coll = Kept{};
    if (tc_ > 0) tLast_[s] = -std::numeric_limits<double>::infinity();
    rec_[s].idx = static_cast<std::uint32_t>(i);
    insertCell(s, cellOf(p.x[i]));
    if (zoned_) zoneVolume_[zoneOfCell(rec_[s].cell)] += Particles<D>::volumeOf(hot_[s].r);
    slotOf_[i] = s;
    ++nLive_;
    if (shells_) {
        centre_[s] = Centre{p.x[i], p.radius[i]};
        if (!linkShell(s)) {
            ++stats_.listGrowths;
            buildLists();
        }
    }
    if (!fz) {
        ++nMoving_;
        predict(s, t);
        return;
    }
    if (shells_) {  // a new obstacle: the moving particles of its list re-predict (their events did not know it)
        std::vector<std::uint32_t> around;
        const std::uint32_t* a = row(s);
        for (std::uint32_t q = 1; q <= a[0]; ++q)
            if (!frozen(a[q] & kSlotMask)) around.push_back(a[q] & kSlotMask);
        std::sort(around.begin(), around.end());
        around.erase(std::unique(around.begin(), around.end()), around.end());
        for (const std::uint32_t j : around) predict(j, t);
        return;
    }
    // A new obstacle: the moving particles around it re-predict (their events did not know it).
    std::vector<std::uint32_t> around;
    forEachNeighbourCell(rec_[s].cell, [&](std::uint32_t cell) {
        for (std::uint32_t j = head_[cell]; j != kNil; j = link_[j].next)
            if (!frozen(j)) around.push_back(j);
    });
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end()), around.end());
    for (const std::uint32_t j : around) predict(j, t);
}

template <int D>
void EdmEngine<D>::swapIndices(std::size_t i, std::size_t j) {
    if (i == j) return;
    if (s_.holdState) throw std::logic_error("event-driven engine: swapIndices needs holdState off");
    std::swap(slotOf_[i], slotOf_[j]);
    if (slotOf_[i] != kNil) rec_[slotOf_[i]].idx = static_cast<std::uint32_t>(i);
    if (slotOf_[j] != kNil) rec_[slotOf_[j]].idx = static_cast<std::uint32_t>(j);
}

template <int D>
std::uint32_t EdmEngine<D>::zoneOfCell(std::uint32_t c) const {
    std::uint32_t z = 0;
    for (int k = 0; k < D; ++k) {
        const std::uint32_t ck = (c / stride_[k]) % static_cast<std::uint32_t>(nCell_[k]);
        z += zone_.zoneCoord[k][ck] * zone_.zoneStride[k];
    }
    return z;
}

template <int D>
void EdmEngine<D>::attachZones(const EdmZoneLink<D>& link) {
    if (shells_) throw std::logic_error("event-driven engine: zones need cell crossings (EdmSettings::shell = 0)");
    if (link.guard == nullptr || link.guard->size() != head_.size())
        throw std::invalid_argument("event-driven engine: the guard must have one entry per cell");
    for (int k = 0; k < D; ++k)
        if (link.zoneCoord[k].size() != static_cast<std::size_t>(nCell_[k]))
            throw std::invalid_argument("event-driven engine: zone coordinates must cover every cell");
    if (&link != &zone_) zone_ = link;
    zoned_ = true;
    zoneVolume_.assign(zone_.zones, 0.0);
    for (std::uint32_t s = 0; s < hot_.size(); ++s)
        if (rec_[s].idx != kNil) zoneVolume_[zoneOfCell(rec_[s].cell)] += Particles<D>::volumeOf(hot_[s].r);
}

template <int D>
std::vector<std::uint32_t> EdmEngine<D>::takeGuardEntries() {
    std::vector<std::uint32_t> out;
    out.swap(guardEntries_);
    return out;
}

template <int D>
std::vector<std::uint32_t> EdmEngine<D>::takeTcHandovers() {
    std::vector<std::uint32_t> out;
    out.swap(tcHandovers_);
    return out;
}

template <int D>
Vec<D> EdmEngine<D>::positionAt(std::size_t i, double t) const {
    const std::uint32_t s = slotOf_[i];
    Vec<D> x = posAt(hot_[s], t);
    for (int k = 0; k < D; ++k) {
        if (!w_.domain.periodic[k]) continue;
        x[k] -= wrapsOf(link_[s].wrap)[k] * boxLen_[k];
        const double lo = w_.domain.lo[k], L = boxLen_[k];
        x[k] -= std::floor((x[k] - lo) / L) * L;
    }
    return x;
}

template <int D>
double EdmEngine<D>::cellSize() const {
    double c = kNever;
    for (int k = 0; k < D; ++k) c = std::min(c, cellW_[k]);
    return c;
}

template <int D>
double EdmEngine<D>::nextEventTime() const {
    return (!s_.reference && queue_.size() > 0) ? queue_.topTime() : kNever;
}

template <int D>
std::size_t EdmEngine<D>::memoryBytes() const {
    auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
    return bytes(hot_) + bytes(link_) + bytes(rec_) + bytes(tLast_) + queue_.memoryBytes() + bytes(head_) +
           bytes(slotOf_) + bytes(free_) + bytes(zoneVolume_) + bytes(centre_) + bytes(nbr_);
}

template class EdmEngine<2>;
template class EdmEngine<3>;

}  // namespace haet
