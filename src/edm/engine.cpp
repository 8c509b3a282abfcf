#include "edm/engine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "edm/predict.hpp"
#include "edm/reference.hpp"
#include "edm/scan.hpp"

namespace haet {

// Arithmetic is canonical on purpose: a pair's collision time is computed from the two particles' stored states
// extrapolated to the later of their two clocks (never to "now"), in a form that is bit-identical for (a, b) and
// (b, a); the collision operator always takes the particle of lower World index as body 1. The prediction of a pair
// therefore does not depend on when, or by which of the two, it was made, and the fast engine and the brute-force
// reference produce bit-identical event sequences (tests/test_edm_engine.cpp). Stored states change only at
// collisions and at the synchronisation at the end of advanceTo, never at cell crossings or stale events.

template <int D>
EdmEngine<D>::EdmEngine(World<D>& world, const EdmSettings& settings, EdmObserver<D>* observer)
    : w_(world), s_(settings) {
    const ContactSetup& cs = w_.contact;
    if (cs.nMaterials <= 0 || cs.table.size() < static_cast<std::size_t>(cs.nMaterials * cs.nMaterials) ||
        cs.wallTable.size() < cs.table.size())
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
    tc_ = edm::TcModel((s_.tcModel && tcRef_ > 0) ? tcRef_ : 0);
    sl_.world = &w_;
    sl_.g = w_.domain.gravity;
    sl_.boxLen = w_.domain.length();
    for (std::size_t k = 0; k < w_.walls.size(); ++k) {
        const Wall<D>& wl = w_.walls[k];
        if (wl.material < 0 || wl.material >= cs.nMaterials)
            throw std::invalid_argument("event-driven engine: wall " + std::to_string(k) + " has no material");
        for (int a = 0; a < D; ++a)
            if (w_.domain.periodic[a] && std::abs(wl.normal[a]) > 1e-12)
                throw std::invalid_argument("event-driven engine: wall " + std::to_string(k) +
                                            " is not parallel to periodic axis " + std::to_string(a));
        // D.3 predicts a plane at constant velocity; an oscillating one is the coupled engine's (guardedWalls).
        if (wl.oscillates()) {
            if (!s_.guardedWalls)
                throw std::invalid_argument("event-driven engine: wall " + std::to_string(k) +
                                            " oscillates: only planes at a constant velocity are predicted");
            continue;
        }
        planes_.push_back(static_cast<std::uint32_t>(k));
    }
    mesh_.collect(w_, s_.guardedWalls);
    if (w_.walls.size() + mesh_.size() >= (std::size_t{1} << kTypeShift))
        throw std::invalid_argument("event-driven engine: too many walls");
    reset();
    if (observer) {
        if (shells_.on())
            throw std::logic_error("event-driven engine: an observer needs cell crossings (EdmSettings::shell = 0)");
        observer_ = observer;
        reportAll();
    }
}

// ---------------------------------------------------------------------------------------------------------------
// set-up

template <int D>
void EdmEngine<D>::requireKnownMaterial(std::size_t i) const {
    if (w_.particles.material[i] >= w_.contact.nMaterials)
        throw std::invalid_argument("event-driven engine: particle material outside the contact table");
}

template <int D>
void EdmEngine<D>::restart() {
    sl_.g = w_.domain.gravity;
    reset();
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
    rmax_ = std::max(rmax_, s_.radiusBound);
    for (int k = 0; k < D; ++k)
        if (w_.domain.periodic[k] && sl_.boxLen[k] < 4 * rmax_)
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
        if (n > 0) u = std::max(u, std::sqrt(norm(sl_.g) * dmin));
        for (const Wall<D>& wl : w_.walls) u = std::max(u, norm(wl.velocity));
        maxRate_ = (n > 0 && u > 0) ? 1e4 * u / dmin : 0;
    }
    window_ = std::max<std::uint64_t>(1000000, 100 * static_cast<std::uint64_t>(nMoving_));
    winEvents_ = events_;
    winTime_ = w_.time;
    chooseShell();

    // Slots in World order first, then sorted cell by cell.
    buildGrid();
    // A particle's centre stays in its cell until it crosses (with shells: within the shell's half-edge of its
    // centre's cell), so its cell's elements are all it can touch until its next such event.
    mesh_.bin(grid_.cells(), rmax_, shells_.half());
    sl_.hot.resize(n);
    sl_.link.assign(n, Link{kNil, 0, Sl::packWraps(Shift{})});
    sl_.rec.assign(n, Rec{Kept{}, 0, 0, 0, 0});
    tc_.reset(n);
    const std::uint32_t freeCell = grid_.count();
    for (std::uint32_t i = 0; i < n; ++i) {
        const bool fz = p.frozen(i);
        if (i < first) {  // a free slot, for a particle that joins later
            sl_.hot[i] = Hot{p.x[i], kNever, Vec<D>::zero(), p.radius[i]};
            sl_.rec[i].idx = kNil;
            sl_.rec[i].cell = freeCell;
            continue;
        }
        // A frozen particle's velocity is taken as zero (posAt, velAt); its slot keeps the World's for holdState.
        sl_.hot[i] = Hot{p.x[i], fz ? kNever : w_.time, p.v[i], p.radius[i]};
        sl_.rec[i].idx = i;
        sl_.rec[i].cell = grid_.cellOf(p.x[i]);
    }
    nLive_ = n - first;
    queue_.reset(n);
    if (shells_.on()) {
        // Shell centres where the particles are; the grid holds centres.
        shells_.clear(n);
        for (std::uint32_t i = static_cast<std::uint32_t>(first); i < n; ++i) {
            shells_.setCentre(i, p.x[i], p.radius[i]);
            sl_.rec[i].cell = grid_.cellOf(p.x[i]);
        }
    }
    resort();  // also links the cells, numbers slotOf_ and free_
    if (shells_.on()) shells_.buildLists(sl_, grid_);
    if (observer_) reportAll();
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
        const double lo = w_.domain.lo[k], L = sl_.boxLen[k];
        if (x >= lo && x < lo + L) continue;
        const double sh = std::floor((x - lo) / L);
        x -= sh * L;
        p.image[i][k] += static_cast<std::int32_t>(sh);
    }
}

// Neighbour shells or cell crossings (EdmSettings::shell).
template <int D>
void EdmEngine<D>::chooseShell() {
    bool periodic = false;
    for (int k = 0; k < D; ++k) periodic = periodic || w_.domain.periodic[k];
    const bool on = s_.shell > 0 && !s_.reference && w_.particles.size() <= edm::Shells<D>::kSlotMask && rmax_ > 0;
    shells_.configure(on ? s_.shell * rmax_ : 0, periodic);  // half of shell * (2 rmax)
}

template <int D>
void EdmEngine<D>::buildGrid() {
    const double least = 2 * rmax_ + 2 * shells_.half();
    double edge = s_.cellSize > 0 ? s_.cellSize : least;
    // A dilute 3D gas without gravity (no heap forms, the density stays near its mean): cells of at least the edge
    // that gives kCellsPerParticle cells per particle. At phi = 0.1 cells of one diameter are 5.2 per particle (21
    // bytes of list heads each) and most events are cell crossings; 1.28 diameters take 2.5 (docs/edm.md).
    if (!(s_.cellSize > 0) && D == 3 && norm2(sl_.g) == 0 && !shells_.on() && w_.particles.size() > 0) {
        constexpr double kCellsPerParticle = 2.5;
        double vol = 1;
        for (int k = 0; k < D; ++k) vol *= sl_.boxLen[k];
        const double mean = std::cbrt(vol / (kCellsPerParticle * static_cast<double>(w_.particles.size())));
        if (std::isfinite(mean)) edge = std::max(edge, mean);
    }
    if (s_.cellSize > 0 && s_.cellSize < least * (1 - 1e-12))
        throw std::invalid_argument(shells_.on()
                                        ? "event-driven engine: cellSize is smaller than the largest diameter "
                                          "plus the neighbour shell"
                                        : "event-driven engine: cellSize is smaller than the largest diameter");
    if (!(edge > 0)) edge = 1;
    // At most max(2^20, 8 N) cells: a huge open box with few particles gets larger cells (the grid adds the cap of
    // Rec::cell's bits).
    const double maxCells = std::max(1048576.0, 8.0 * static_cast<double>(w_.particles.size()));
    grid_.build(w_.domain, edge, maxCells);
    gridEdge_ = edge;
    gridCap_ = maxCells;
}

// Reorders the slots cell by cell (stable in the current order): neighbours in space become neighbours in memory.
// Pending events move with their slots; the partners of pair events are renumbered.
template <int D>
void EdmEngine<D>::resort() {
    const std::size_t n = sl_.size();
    std::vector<std::uint32_t> start(grid_.count() + 2, 0);  // the last bucket: free slots
    for (std::size_t s = 0; s < n; ++s) ++start[sl_.rec[s].cell + 1];
    for (std::size_t c = 0; c + 1 < start.size(); ++c) start[c + 1] += start[c];
    std::vector<std::uint32_t> order(n), newSlot(n);  // order[new] = old
    for (std::uint32_t s = 0; s < n; ++s) {
        const std::uint32_t ns = start[sl_.rec[s].cell]++;
        order[ns] = s;
        newSlot[s] = ns;
    }
    auto permute = [&](auto& arr) {
        auto tmp = arr;
        for (std::size_t k = 0; k < n; ++k) tmp[k] = arr[order[k]];
        arr.swap(tmp);
    };
    permute(sl_.hot);
    permute(sl_.link);
    permute(sl_.rec);
    tc_.permute(order);
    if (shells_.on()) shells_.permute(order, newSlot);
    std::vector<double> times(n);
    for (std::size_t k = 0; k < n; ++k) times[k] = queue_.time(order[k]);
    auto renumber = [&](std::uint32_t& code) {
        if ((code >> kTypeShift) == kPair) code = (kPair << kTypeShift) | newSlot[code & kIndexMask];
    };
    for (std::size_t k = 0; k < n; ++k) renumber(sl_.rec[k].coll.code);
    queue_.build(times);
    grid_.relink(sl_);
    // The World-to-slot table serves the hybrid's questions about single particles; a run with holdState asks none.
    if (s_.holdState)
        std::vector<std::uint32_t>().swap(slotOf_);
    else
        slotOf_.assign(w_.particles.size(), kNil);
    free_.clear();
    for (std::uint32_t k = static_cast<std::uint32_t>(n); k-- > 0;) {
        if (sl_.rec[k].idx == kNil)
            free_.push_back(k);
        else if (!slotOf_.empty())
            slotOf_[sl_.rec[k].idx] = k;
    }
    sortedAt_ = events_;
}

template <int D>
void EdmEngine<D>::reportAll() {
    observer_->restart(grid_.cells());
    for (std::uint32_t s = 0; s < sl_.size(); ++s)
        if (sl_.rec[s].idx != kNil) observer_->joined(sl_.rec[s].idx, sl_.rec[s].cell, sl_.hot[s].r);
}

// ---------------------------------------------------------------------------------------------------------------
// predictions

// The two broad phases' predictions are separate functions, so that neither shares registers and stack with the
// other's inlined scan.
template <int D>
void EdmEngine<D>::predict(std::uint32_t s, double now, int axis, int dir) {
    if (shells_.on()) {
        predictShells(s, now);
        return;
    }
    predictWith(grid_, s, now, axis, dir);
}

template <int D>
void EdmEngine<D>::predictShells(std::uint32_t s, double now) {
    predictWith(shells_, s, now, -1, 0);
}

// Predicts the next event of slot s at time now: the earliest of its exit (from its cell or its shell), its wall
// collisions and its collisions with the candidate partners the broad phase names (edm/scan.hpp). After a cell
// crossing (axis >= 0, dir = +-1) with a still valid earlier result in rec[s].coll, only the newly adjacent cells
// are scanned: the others were scanned before and their particles' trajectories are unchanged (a particle that
// changed since re-predicted itself).
template <int D>
template <class Broad>
[[gnu::always_inline]] inline void EdmEngine<D>::predictWith(const Broad& broad, std::uint32_t s, double now, int axis,
                                                             int dir) {
    const Hot& hs = sl_.hot[s];
    const typename Broad::Where at = broad.where(sl_, s);
    const Shift ws = Sl::wrapsOf(sl_.link[s].wrap);
    // The exit is computed from the state at "now": from the older stored state the quadratic can also find a
    // crossing that already happened (through a face and back under gravity).
    const Vec<D> xNow = sl_.posAt(hs, now), vNow = sl_.velAt(hs, now);
    const Candidate cross = broad.exit(sl_, at, s, ws, now, xNow, vNow);
    Candidate best;
    if (axis >= 0) {
        best = {keptTime(s, now), sl_.rec[s].coll.code, sl_.rec[s].coll.stamp};
    } else {
        for (const std::uint32_t w : planes_) {
            const double t = sl_.wallTime(s, w, now);
            const std::uint32_t code = (kWall << kTypeShift) | w;
            if (best.better(t, code)) best = {t, code, 0};
        }
    }
    // The elements of s's cell: after a crossing its new cell's, which the kept event does not know.
    if (!mesh_.empty()) predictMesh(s, now, best);
    edm::Scanner<D> scan(sl_, hs, s, now, best);
    broad.forEachBatch(sl_, at, s, ws, axis, dir, scan);
    if (scan.bestJ != kNil) scan.best.stamp = sl_.link[scan.bestJ].count;
    setPending(s, scan.best, cross);
}

template <int D>
void EdmEngine<D>::predictMesh(std::uint32_t s, double now, Candidate& best) const {
    const std::uint32_t cell = sl_.rec[s].cell;
    const std::uint32_t base = static_cast<std::uint32_t>(w_.walls.size());
    for (const std::uint32_t* q = mesh_.cellBegin(cell); q != mesh_.cellEnd(cell); ++q) {
        const double t = mesh_.time(sl_, s, *q, now, best.time);
        const std::uint32_t code = (kWall << kTypeShift) | (base + *q);
        if (best.better(t, code)) best = {t, code, 0};
    }
}

template <int D>
void EdmEngine<D>::setPending(std::uint32_t s, const Candidate& best, const Candidate& cross) {
    Rec& r = sl_.rec[s];
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
    if (!grid_.partialScans()) return false;
    const Kept& c = sl_.rec[s].coll;
    if ((c.code >> kTypeShift) != kPair) return true;
    const std::uint32_t j = c.code & kIndexMask;
    return sl_.link[j].count == c.stamp && !frozen(j);
}

// The time of slot s's kept event, recomputed at a crossing (now) in the canonical form, so the same bits as when the
// scan found it, unless a synchronisation has rounded the stored states since or the state is invalid (docs/physics.md
// D.6: decided afresh from the state now); docs/edm.md, "Canonical arithmetic". The partner's periodic
// image is the minimum image now: the pair approaches, so the two are no farther apart than when the scan found them
// in neighbouring cells (sqrt(D) times two cell edges), which is less than half the box with 7 cells per axis.
template <int D>
double EdmEngine<D>::keptTime(std::uint32_t s, double now) const {
    const Kept& c = sl_.rec[s].coll;
    const std::uint32_t k = c.code & kIndexMask;
    switch (c.code >> kTypeShift) {
        case kWall:
            if (k >= w_.walls.size())
                return mesh_.time(sl_, s, k - static_cast<std::uint32_t>(w_.walls.size()), now, kNever);
            return sl_.wallTime(s, k, now);
        case kPair: {
            const Vec<D> d = sl_.posAt(sl_.hot[s], now) - sl_.posAt(sl_.hot[k], now);
            Shift m{};  // the image count itself (pairTime's shift), not the displacement minimumImage gives
            for (int a = 0; a < D; ++a)
                if (w_.domain.periodic[a]) m[a] = -static_cast<std::int32_t>(std::nearbyint(d[a] / sl_.boxLen[a]));
            return sl_.pairTime(s, k, m, now, kNever);
        }
        default:
            return kNever;
    }
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
        if (!tc_.on()) msg << "; the TC model is off";
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
    const Rec& rs = sl_.rec[s];
    const std::uint32_t code = rs.crossing ? (kCell << kTypeShift) | rs.exit : rs.coll.code;
    const std::uint32_t k = code & kIndexMask;
    switch (code >> kTypeShift) {
        case kPair:
            if (sl_.link[k].count != sl_.rec[s].coll.stamp) {  // the partner collided since: re-predict
                ++stats_.stale;
                predict(s, t);
                return;
            }
            collidePair(s, k, t);
            predict(s, t);
            if (!frozen(k)) predict(k, t);
            return;
        case kWall:
            if (k < w_.walls.size())
                collideWall(s, k, t);
            else
                collideMesh(s, k - static_cast<std::uint32_t>(w_.walls.size()), t);
            predict(s, t);
            return;
        case kCell: {
            if (shells_.on()) {
                ++stats_.shellExits;
                if (shells_.move(sl_, grid_, s, t)) ++stats_.listGrowths;
                predictShells(s, t);
                return;
            }
            ++stats_.cellCrossings;
            const int axis = static_cast<int>(k >> 1);
            const bool up = k & 1;
            const std::uint32_t from = grid_.cross(sl_, s, axis, up);
            if (observer_) observer_->crossed(sl_.rec[s].idx, from, sl_.rec[s].cell, sl_.hot[s].r);
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
    sl_.advance(s, t);
    storeSlot(s);
    const Particles<D>& p = w_.particles;
    const Hot& h = sl_.hot[s];
    const std::uint32_t i = sl_.rec[s].idx;
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
    Hot& h = sl_.hot[s];
    const std::uint32_t i = sl_.rec[s].idx;
    Shift ws = Sl::wrapsOf(sl_.link[s].wrap);
    for (int k = 0; k < D; ++k) {
        if (!dom.periodic[k]) continue;
        double& x = h.x[k];
        const double lo = dom.lo[k], L = sl_.boxLen[k];
        if (x >= lo && x < lo + L) continue;
        const double sh = std::floor((x - lo) / L);
        x -= sh * L;
        p.image[i][k] += static_cast<std::int32_t>(sh);
        // The box-frame position x - wrap L is unchanged, so the cell and the pending events stay valid.
        ws[k] -= static_cast<std::int32_t>(sh);
    }
    sl_.link[s].wrap = Sl::packWraps(ws);
    p.x[i] = h.x;
    p.v[i] = h.v;
}

template <int D>
void EdmEngine<D>::synchronise(double t) {
    Particles<D>& p = w_.particles;
    const bool restore = !p.hasMotion();
    if (restore) p.restoreMotion();
    for (std::uint32_t s = 0; s < sl_.size(); ++s) {
        const std::uint32_t i = sl_.rec[s].idx;
        if (i == kNil) continue;
        if (!frozen(s)) {
            syncSlot(s, t);
        } else if (restore) {
            p.x[i] = sl_.hot[s].x;
            p.v[i] = sl_.hot[s].v;
        }
        if (restore) p.radius[i] = sl_.hot[s].r;
    }
    w_.time = t;
}

// After an error in advanceEvents: the World gets its arrays back with every particle's state at its own clock.
template <int D>
void EdmEngine<D>::putBackState() {
    Particles<D>& p = w_.particles;
    if (p.hasMotion()) return;
    p.restoreMotion();
    for (std::uint32_t s = 0; s < sl_.size(); ++s) {
        const std::uint32_t i = sl_.rec[s].idx;
        if (i == kNil) continue;
        if (!frozen(s)) {
            storeSlot(s);
        } else {
            p.x[i] = sl_.hot[s].x;
            p.v[i] = sl_.hot[s].v;
        }
        p.radius[i] = sl_.hot[s].r;
    }
}

// The reference twin (edm/reference.hpp) names each next event; the collisions are the engine's.
template <int D>
void EdmEngine<D>::advanceReference(double t) {
    const edm::Reference<D> ref(sl_, rmax_, planes_, mesh_);
    double now = w_.time;
    for (;;) {
        const typename edm::Reference<D>::Event e = ref.next(now);
        if (e.time >= t) break;
        now = e.time;
        const std::uint32_t type = e.code >> kTypeShift, k = e.code & kIndexMask;
        if (type == kNone) continue;  // the horizon: look again from there
        if (type == kCell) {          // a periodic face: the box frame wraps, as at the fast engine's crossing
            Shift ws = Sl::wrapsOf(sl_.link[e.slot].wrap);
            ws[k >> 1] += (k & 1) ? 1 : -1;
            sl_.setWraps(e.slot, ws);
            continue;
        }
        countEvent(e.time);
        if (type == kPair)
            collidePair(e.slot, k, e.time);
        else if (k < w_.walls.size())
            collideWall(e.slot, k, e.time);
        else
            collideMesh(e.slot, k - static_cast<std::uint32_t>(w_.walls.size()), e.time);
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
double EdmEngine<D>::advanceEvents(double t) {
    if (s_.reference) throw std::logic_error("event-driven engine: advanceEvents in reference mode");
    if (s_.holdState && w_.particles.hasMotion()) w_.particles.releaseMotion();
    double reached = t;
    try {
        while (queue_.size() > 0 && queue_.topTime() < t) {
            const double now = queue_.topTime();
            processNext();
            if (s_.stop && s_.stop->load(std::memory_order_relaxed)) {
                reached = std::max(now, w_.time);
                break;
            }
        }
    } catch (...) {
        putBackState();
        throw;
    }
    // Particles diffuse away from their sorted neighbours; re-sort after ~20 events per particle. Not after a stop:
    // the run would not have sorted there, and a resumed one goes on from the state as it is (a checkpoint).
    if (reached == t && events_ - sortedAt_ > 20 * static_cast<std::uint64_t>(std::max<std::size_t>(nLive_, 1)))
        resort();
    return reached;
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
    if (shells_.on()) shells_.unlink(s);
    grid_.remove(sl_, s);
    if (observer_) observer_->left(static_cast<std::uint32_t>(i), sl_.rec[s].cell, sl_.hot[s].r);
    ++sl_.link[s].count;  // events of others that name s are stale now
    sl_.hot[s].t = kNever;
    sl_.hot[s].v = Vec<D>::zero();
    sl_.rec[s].idx = kNil;
    sl_.rec[s].cell = grid_.count();
    sl_.rec[s].coll = Kept{};
    sl_.rec[s].crossing = 0;
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
    sl_.hot[s] = Hot{p.x[i], fz ? kNever : t, fz ? Vec<D>::zero() : p.v[i], p.radius[i]};
    sl_.link[s].wrap = Sl::packWraps(Shift{});
    ++sl_.link[s].count;
    sl_.rec[s].coll = Kept{};
    tc_.forget(s);
    sl_.rec[s].idx = static_cast<std::uint32_t>(i);
    grid_.insert(sl_, s, grid_.cellOf(p.x[i]));
    if (observer_) observer_->joined(static_cast<std::uint32_t>(i), sl_.rec[s].cell, sl_.hot[s].r);
    slotOf_[i] = s;
    ++nLive_;
    if (shells_.on()) {
        shells_.setCentre(s, p.x[i], p.radius[i]);
        if (!shells_.link(sl_, grid_, s)) {
            ++stats_.listGrowths;
            shells_.buildLists(sl_, grid_);
        }
    }
    if (!fz) {
        ++nMoving_;
        predict(s, t);
        return;
    }
    // A new obstacle: the moving particles around it (its list, or the cells around its cell) re-predict (their
    // events did not know it).
    std::vector<std::uint32_t> around;
    if (shells_.on())
        shells_.forEachListed(s, [&](std::uint32_t j) {
            if (!frozen(j)) around.push_back(j);
        });
    else
        grid_.forEachAround(sl_, sl_.rec[s].cell, [&](std::uint32_t j, const Shift&) {
            if (!frozen(j)) around.push_back(j);
        });
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end()), around.end());
    for (const std::uint32_t j : around) predict(j, t);
}

template <int D>
void EdmEngine<D>::grow(std::size_t n) {
    if (s_.holdState) throw std::logic_error("event-driven engine: grow needs holdState off");
    if (n >= (1u << kTypeShift)) throw std::invalid_argument("event-driven engine: too many particles");
    if (slotOf_.size() < n) slotOf_.resize(n, kNil);
    const std::size_t old = sl_.size();
    if (n <= old) return;
    // New slots are free (no particle, no event) and belong to no cell: nothing else refers to them yet.
    std::vector<double> times(n, kNever);
    for (std::size_t s = 0; s < old; ++s) times[s] = queue_.time(static_cast<std::uint32_t>(s));
    sl_.hot.resize(n, Hot{Vec<D>::zero(), kNever, Vec<D>::zero(), 0.0});
    sl_.link.resize(n, Link{kNil, 0, Sl::packWraps(Shift{})});
    sl_.rec.resize(n, Rec{Kept{}, 0, 0, 0, 0});
    for (std::size_t s = old; s < n; ++s) {
        sl_.rec[s].idx = kNil;
        sl_.rec[s].cell = grid_.count();
    }
    tc_.grow(n);
    queue_.build(times);
    if (shells_.on()) throw std::logic_error("event-driven engine: grow needs cell crossings (shell = 0)");
    for (std::size_t s = n; s-- > old;) free_.push_back(static_cast<std::uint32_t>(s));
}

template <int D>
void EdmEngine<D>::swapIndices(std::size_t i, std::size_t j) {
    if (i == j) return;
    if (s_.holdState) throw std::logic_error("event-driven engine: swapIndices needs holdState off");
    std::swap(slotOf_[i], slotOf_[j]);
    if (slotOf_[i] != kNil) sl_.rec[slotOf_[i]].idx = static_cast<std::uint32_t>(i);
    if (slotOf_[j] != kNil) sl_.rec[slotOf_[j]].idx = static_cast<std::uint32_t>(j);
}

template <int D>
Vec<D> EdmEngine<D>::positionAt(std::size_t i, double t) const {
    const std::uint32_t s = slotOf_[i];
    Vec<D> x = sl_.posAt(sl_.hot[s], t);
    for (int k = 0; k < D; ++k) {
        if (!w_.domain.periodic[k]) continue;
        x[k] -= Sl::wrapsOf(sl_.link[s].wrap)[k] * sl_.boxLen[k];
        const double lo = w_.domain.lo[k], L = sl_.boxLen[k];
        x[k] -= std::floor((x[k] - lo) / L) * L;
    }
    return x;
}

template <int D>
double EdmEngine<D>::nextEventTime() const {
    return (!s_.reference && queue_.size() > 0) ? queue_.topTime() : kNever;
}

template <int D>
std::size_t EdmEngine<D>::memoryBytes() const {
    auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
    return bytes(sl_.hot) + bytes(sl_.link) + bytes(sl_.rec) + tc_.memoryBytes() + queue_.memoryBytes() +
           grid_.memoryBytes() + bytes(slotOf_) + bytes(free_) + shells_.memoryBytes() + bytes(planes_) +
           mesh_.memoryBytes();
}

template class EdmEngine<2>;
template class EdmEngine<3>;

}  // namespace haet
