#include "tdm/engine.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "tdm/halo.hpp"

namespace haet {

template <int D>
TdmEngine<D>::TdmEngine(World<D>& world, const TdmSettings& s) : w_(world), s_(s), t0_(world.time) {
    if (!w_.particles.hasTdmState())
        throw std::invalid_argument("time-driven engine: the particle store has dropped forces and torques");
    if constexpr (D == 2)
        if (w_.particles.hasPolygons()) shapes_ = makeShapePass(w_.contact);
    if (s.integrator == IntegratorKind::Gear5) {
        integ_ = std::make_unique<Gear5<D>>();
    } else {
        auto vv = std::make_unique<VelocityVerlet<D>>();
        verlet_ = vv.get();
        integ_ = std::move(vv);
    }
    if (s.ranks && s.ranks->size() > 1) scatterToSlabs();
    wallHistory_.assign(w_.particles.tdmCount() * w_.walls.size(), Vec<D>::zero());
    surf_.setWalls(&w_.surfaces);
    for (const SurfaceWall<D>& wall : w_.surfaces) staticSurfaces_ = staticSurfaces_ && !wall.motion.moves();
    if (s_.planeLoads) planeForce_.assign(w_.particles.tdmCount() * w_.walls.size(), Vec<D>::zero());
    moveWalls();
    rebuild(s_.sortEvery > 0);
    motion_.v = w_.particles.v;
    motion_.w = w_.particles.w;
    computeForces(false);
    integ_->start(w_.particles, s_.dt);
}

template <int D>
TdmEngine<D>::~TdmEngine() = default;

template <int D>
ForceContext<D> TdmEngine<D>::context(const Vec<D>* sv, const Ang<D>* sw) const {
    // A force pass writes the pair list's and the walls' springs; the energy pass (const) only reads them.
    ForceContext<D> ctx =
        forceContext(w_.particles, const_cast<PairList<D>&>(pairs_), w_.walls,
                     const_cast<std::vector<Vec<D>>&>(wallHistory_), w_.contact, w_.domain, w_.time, s_.dt, sv, sw);
    if (!planeForce_.empty()) ctx.planeForce = const_cast<Vec<D>*>(planeForce_.data());
    if (!surf_.empty()) ctx.surfaces = const_cast<SurfaceState<D>*>(&surf_);
    ctx.contacts = recordNow_;
    if (!nearPlanes_.empty() && nearPlanes_.size() == w_.particles.tdmCount()) ctx.nearPlanes = nearPlanes_.data();
    return ctx;
}

template <int D>
void TdmEngine<D>::computeForces(bool correct, std::atomic<bool>* nextMoved) {
    const ContactSetup& cs = w_.contact;
    if constexpr (D == 2) {
        if (shapes_) {  // polygons present: their pass also serves the disks among them
            stats_ = shapes_->forces(context(motion_.v.data(), motion_.w.data()));
            if (correct) integ_->correct(w_.particles, s_.dt, motion_);
            return;
        }
    }
    bool corrected = false;
    auto run = [&](auto normal, auto tangential) {
        using N = decltype(normal);
        using T = decltype(tangential);
        const ForceContext<D> ctx = context(motion_.v.data(), motion_.w.data());
        auto forces = [&](auto then) { stats_ = computeForcesIn<D, N, T>(ctx, scratch_, then); };
        // Verlet's corrector needs nothing but the particle's own new force: it runs inside the force pass, and
        // so does the next step's predictor when that step follows at once (advanceTo).
        if (correct && verlet_ && nextMoved) {
            forces(verlet_->correctPredict(w_.particles, s_.dt, motion_, xAtBuild_.data(), driftLimit2(), nextMoved));
            corrected = true;
        } else if (correct && verlet_) {
            forces(verlet_->corrector(w_.particles, s_.dt, motion_));
            corrected = true;
        } else {
            forces([](std::size_t, const Vec<D>&, const Ang<D>&) {});
        }
    };
    auto withTangential = [&](auto normal) {
        if (cs.tangential == TangentialLaw::Spring)
            run(normal, SpringTangential{});
        else
            run(normal, NoTangential{});
    };
    if (cs.normal == NormalLaw::Linear)
        withTangential(LinearNormal{});
    else if (cs.hertzDamping == HertzDamping::Tsuji)
        withTangential(HertzTsujiNormal{});
    else
        withTangential(HertzViscoNormal{});  // A* = 0 is the undamped Hertz law
    if (correct && !corrected) integ_->correct(w_.particles, s_.dt, motion_);
}

template <int D>
void TdmEngine<D>::rebuild(bool sort) {
    if (halo_) {
        rebuildAcrossRanks(sort);
        return;
    }
    Particles<D>& p = w_.particles;
    const std::size_t n = p.tdmCount();
    wrapPositions(p, w_.domain);
    // Only the contacts' springs carry over into the new list: the old list shrinks to them first, so that it
    // never coexists in full with the new one, nor with the copies a sort makes.
    keepTouchingPairs(pairs_);
    std::vector<std::uint32_t> sortOrder;
    if (sort) {
        double rmax = 0;
        for (std::size_t i = 0; i < n; ++i) rmax = std::max(rmax, p.radius[i]);
        const auto order = spatialOrder(p, w_.domain, 2 * rmax + s_.skin);
        p.permute(order);
        permutePairList(pairs_, order);
        if (integ_ && steps_ > 0) integ_->permute(order);
        if (!motion_.v.empty()) {
            auto mv = motion_.v;
            for (std::size_t k = 0; k < n; ++k) motion_.v[k] = mv[order[k]];
            std::vector<Vec<D>>().swap(mv);
            auto mw = motion_.w;
            for (std::size_t k = 0; k < n; ++k) motion_.w[k] = mw[order[k]];
        }
        const std::size_t nw = w_.walls.size();
        if (nw > 0) {
            std::vector<Vec<D>> wh(wallHistory_.size());
            for (std::size_t k = 0; k < n; ++k)
                for (std::size_t q = 0; q < nw; ++q) wh[k * nw + q] = wallHistory_[order[k] * nw + q];
            wallHistory_.swap(wh);
        }
        lastSort_ = steps_;
        if (!surf_.empty()) sortOrder.assign(order.begin(), order.end());
    }
    PairList<D> fresh;
    buildPairList(p, w_.domain, NeighborSettings{s_.skin, true}, pairs_, fresh);
    pairs_ = std::move(fresh);
    xAtBuild_.assign(p.x.begin(), p.x.begin() + static_cast<std::ptrdiff_t>(n));
    ++rebuilds_;
    // Until the next build no particle moves more than skin/2 from here; a moving wall may close in by the other
    // half (moveWalls), so only a scene whose walls of any shape all stand still can do with candidates within
    // the radius plus half the skin (docs/physics.md H.4; a hair more, for the rounding of the drift test).
    if (!surf_.empty())
        buildCandidates(sortOrder.empty() ? nullptr : sortOrder.data(),
                        staticSurfaces_ ? 0.5 * (1 + 1e-9) * s_.skin : s_.skin);
    markNearPlanes();
}

template <int D>
void TdmEngine<D>::markNearPlanes() {
    nearPlanes_.clear();
    planesAtMark_.clear();
    const std::size_t nw = w_.walls.size();
    if (nw == 0 || shapes_ || !s_.markPlanes) return;
    for (const Wall<D>& wall : w_.walls)
        if (!(wall.velocity == Vec<D>::zero()) || wall.oscillates()) return;
    const Particles<D>& p = w_.particles;
    const std::size_t n = p.tdmCount();
    // The drift test rebuilds before any particle is more than skin/2 from xAtBuild_ (a hair more, for its
    // rounding, as the candidates of walls of any shape).
    const double margin = 0.5 * (1 + 1e-9) * s_.skin;
    nearPlanes_.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        bool near = false;
        for (const Wall<D>& wall : w_.walls) near = near || wall.distanceNow(xAtBuild_[i]) <= p.radius[i] + margin;
        if (near) {
            nearPlanes_[i] = 1;
            continue;
        }
        for (std::size_t q = 0; q < nw; ++q) {
            wallHistory_[i * nw + q] = Vec<D>::zero();
            if (!planeForce_.empty()) planeForce_[i * nw + q] = Vec<D>::zero();
        }
    }
    for (const Wall<D>& wall : w_.walls) {
        planesAtMark_.push_back(wall.pointNow);
        planesAtMark_.push_back(wall.normal);
    }
}

template <int D>
void TdmEngine<D>::moveWalls() {
    for (Wall<D>& wall : w_.walls) wall.moveTo(w_.time);
    // A plane changed from outside since the marks (a script, say): every particle tests the planes again.
    for (std::size_t q = 0; q < w_.walls.size() && !planesAtMark_.empty(); ++q)
        if (!(w_.walls[q].pointNow == planesAtMark_[2 * q]) || !(w_.walls[q].normal == planesAtMark_[2 * q + 1])) {
            nearPlanes_.clear();
            planesAtMark_.clear();
        }
    if (surf_.empty()) return;
    const auto& walls = w_.surfaces;
    surf_.poses.resize(walls.size());
    bool far = false;
    for (std::size_t q = 0; q < walls.size(); ++q) {
        const Motion<D>& m = walls[q].motion;
        surf_.poses[q] = m.at(w_.time);
        // Particles move up to skin/2 before the pair list (and with it the candidates) is rebuilt; a wall may
        // close in by the other half (surface_list.hpp).
        if (m.moves() && !surf_.candidates.first.empty() &&
            m.maxDisplacement(surf_.candidatesTime, w_.time, surf_.reach[q]) > 0.5 * s_.skin)
            far = true;
    }
    if (far && surf_.slotOf.size() == w_.particles.tdmCount()) buildCandidates(nullptr, s_.skin);
}

template <int D>
void TdmEngine<D>::buildCandidates(const std::uint32_t* from, double margin) {
    const Particles<D>& p = w_.particles;
    const std::size_t n = p.tdmCount();
    buildSurfaceCandidates(p, n, w_.domain, w_.surfaces, surf_.poses, margin, surf_.candidates);
    surf_.candidatesTime = w_.time;
    std::vector<std::uint32_t> slotOf(n, SurfaceState<D>::kNoSlots);
    std::vector<std::uint8_t> count(n, 0);
    std::vector<SurfaceContact<D>> slots;
    for (std::size_t k = 0; k < n; ++k) {
        if (surf_.candidates.first[k + 1] == surf_.candidates.first[k]) continue;
        slotOf[k] = static_cast<std::uint32_t>(slots.size());
        slots.resize(slots.size() + kSurfaceSlots);
        const std::uint32_t o = from ? from[k] : static_cast<std::uint32_t>(k);
        if (o == kFresh || o >= surf_.slotOf.size() || surf_.slotOf[o] == SurfaceState<D>::kNoSlots) continue;
        count[k] = surf_.count[o];
        std::copy_n(surf_.slots.begin() + surf_.slotOf[o], kSurfaceSlots, slots.begin() + slotOf[k]);
    }
    surf_.slotOf.swap(slotOf);
    surf_.count.swap(count);
    surf_.slots.swap(slots);
}

template <int D>
typename TdmEngine<D>::WallLoad TdmEngine<D>::planeLoad(std::size_t w) const {
    WallLoad l{};
    if (planeForce_.empty()) return l;
    const Particles<D>& p = w_.particles;
    const Wall<D>& wall = w_.walls[w];
    const std::size_t nw = w_.walls.size();
    for (std::size_t i = 0; i < owned(); ++i) {
        const Vec<D>& f = planeForce_[i * nw + w];
        if (f == Vec<D>::zero()) continue;
        const Vec<D> at = p.x[i] - wall.normal * wall.distanceNow(p.x[i]);  // the contact point on the plane
        l.force -= f;
        l.torque -= cross(at - wall.pointNow, f);
    }
    return l;
}

template <int D>
typename TdmEngine<D>::WallLoad TdmEngine<D>::surfaceLoad(std::size_t w) const {
    WallLoad l{};
    if (surf_.empty()) return l;
    const Vec<D> c = surf_.poses[w].centre;
    for (std::size_t i = 0; i < surf_.slotOf.size(); ++i) {
        if (surf_.slotOf[i] == SurfaceState<D>::kNoSlots) continue;
        for (int q = 0; q < surf_.count[i]; ++q) {
            const SurfaceContact<D>& k = surf_.slots[surf_.slotOf[i] + q];
            if (k.wall != w) continue;
            l.force -= k.force;
            l.torque -= cross(k.point - c, k.force);
        }
    }
    return l;
}

template <int D>
std::size_t TdmEngine<D>::wallContacts() const {
    std::size_t n = 0;
    const Particles<D>& p = w_.particles;
    for (std::size_t i = 0; i < p.tdmCount(); ++i)
        for (const Wall<D>& wall : w_.walls) n += wall.distanceNow(p.x[i]) < p.radius[i];
    for (std::size_t i = 0; i < surf_.count.size(); ++i) n += surf_.count[i];
    return n;
}

template <int D>
void TdmEngine<D>::remap(const std::vector<std::uint32_t>& from) {
    pristine_ = false;
    Particles<D>& p = w_.particles;
    const std::size_t n = p.tdmCount();
    if (from.size() != n) throw std::invalid_argument("TdmEngine::remap: map size differs from tdmCount()");
    const std::size_t nw = w_.walls.size();
    std::vector<Vec<D>> wh(n * nw, Vec<D>::zero());
    std::vector<Vec<D>> mv(n);
    std::vector<Ang<D>> mw(n);
    for (std::size_t k = 0; k < n; ++k) {
        const std::uint32_t o = from[k];
        if (o == kFresh) {
            // Free flight: the force of gravity alone, no spin change.
            p.f[k] = p.frozen(k) ? Vec<D>::zero() : w_.domain.gravity * p.mass[k];
            p.torque[k] = Ang<D>::zero();
            mv[k] = p.v[k];
            mw[k] = p.w[k];
            continue;
        }
        for (std::size_t q = 0; q < nw; ++q) wh[k * nw + q] = wallHistory_[o * nw + q];
        if (o < motion_.v.size()) {
            mv[k] = motion_.v[o];
            mw[k] = motion_.w[o];
        }
    }
    wallHistory_.swap(wh);
    motion_.v.swap(mv);
    motion_.w.swap(mw);
    integ_->remap(p, from, s_.dt);
    // The pair list follows incrementally (kept pairs, plus the new particles' pairs found now); the drift check
    // then measures each particle from where it entered the list.
    std::vector<Vec<D>> xb(n);
    for (std::size_t k = 0; k < n; ++k) xb[k] = from[k] == kFresh ? p.x[k] : xAtBuild_[from[k]];
    xAtBuild_.swap(xb);
    remapPairList(p, w_.domain, NeighborSettings{s_.skin, true}, from, pairs_, xAtBuild_.data());
    if (s_.planeLoads) planeForce_.assign(n * nw, Vec<D>::zero());
    if (!surf_.empty()) buildCandidates(from.data(), s_.skin);  // kept particles drifted from xAtBuild_ already
    markNearPlanes();
}

template <int D>
void TdmEngine<D>::restart() {
    pristine_ = false;
    // The constructor's sequence without its sort (the particles keep their places). The walls are where they were
    // at this time, but their motion may have changed (Motion::rebase, Wall::setVelocity): their velocities now, and
    // whether all stand still (the candidates' margin), anew.
    staticSurfaces_ = true;
    for (const SurfaceWall<D>& wall : w_.surfaces) staticSurfaces_ = staticSurfaces_ && !wall.motion.moves();
    for (Wall<D>& wall : w_.walls) wall.moveTo(w_.time);
    for (std::size_t q = 0; q < surf_.poses.size(); ++q) surf_.poses[q] = w_.surfaces[q].motion.at(w_.time);
    rebuild(false);
    motion_.v = w_.particles.v;
    motion_.w = w_.particles.w;
    computeForces(false);
    integ_->start(w_.particles, s_.dt);
}

template <int D>
void TdmEngine<D>::contactCounts(std::vector<std::uint8_t>& out) const {
    const Particles<D>& p = w_.particles;
    const std::size_t n = p.tdmCount();
    out.assign(n, 0);
    auto bump = [](std::uint8_t& c, int k) { c = static_cast<std::uint8_t>(std::min(255, c + k)); };
    for (std::size_t i = 0; i < n; ++i) {
        for (std::uint32_t k = pairs_.first[i]; k < pairs_.first[i + 1]; ++k) {
            const std::uint32_t j = pairs_.partner[k];
            const Vec<D> d = p.x[i] - p.x[j] + pairs_.shiftVec[pairs_.shift[k]];
            const double rs = p.radius[i] + p.radius[j];
            if (norm2(d) < rs * rs) {
                bump(out[i], 1);
                bump(out[j], 1);
            }
        }
        for (const Wall<D>& wall : w_.walls)
            if (wall.distanceNow(p.x[i]) < p.radius[i]) bump(out[i], 2);
        if (i < surf_.count.size()) bump(out[i], 2 * surf_.count[i]);
    }
}

template <int D>
void TdmEngine<D>::step() {
    bool moved = integ_->predict(w_.particles, s_.dt, motion_, xAtBuild_.data(), driftLimit2());
    bool stop = false;
    if (halo_) agree(moved, stop);
    finishStep(moved, nullptr);
    if (halo_) agree(moved, stop);  // this step's health, agreed before step() returns
}

template <int D>
void TdmEngine<D>::finishStep(bool moved, std::atomic<bool>* nextMoved) {
    pristine_ = false;
    // The k-th step ends at t0 + k dt exactly: outputs at k x period and moving walls see no drift of summed dt.
    ++steps_;
    w_.time = timeAfter(0);
    moveWalls();
    if (moved) {
        rebuild(s_.sortEvery > 0 && steps_ - lastSort_ >= static_cast<std::uint64_t>(s_.sortEvery));
        // O(N) beside the O(N) rebuild; a system that blows up rebuilds at every step
        if (halo_)
            check([&] { checkSpeeds(); });
        else
            checkSpeeds();
    } else if (halo_) {
        refreshGhosts();
    }
    // The contact network's step (recordContactsAt): one test of a pointer in every other step.
    if (recordSink_ && std::abs(w_.time - recordTime_) < 0.5 * s_.dt) [[unlikely]]
        recordNow_ = recordSink_;
    computeForces(true, nextMoved);
    if (recordNow_) recorded();
    if (halo_)
        check([&] { checkHealth(); });
    else
        checkHealth();
}

template <int D>
void TdmEngine<D>::recorded() {
    // Ids now: a hybrid may reorder its particles before the records are read.
    const Particles<D>& p = w_.particles;
    for (ContactRecord<D>& r : *recordNow_) {
        r.idI = p.id[r.i];
        r.idJ = r.j == ContactRecord<D>::kWall ? 0 : p.id[r.j];
    }
    recordedAt_ = w_.time;
    recordNow_ = nullptr;
}

template <int D>
bool TdmEngine<D>::recordStartContacts(ContactSink<D>* sink) {
    if (!pristine_ || !sink) return false;
    // The springs before the constructor's pass: a new pair list's, no wall contact yet.
    std::fill(pairs_.history.begin(), pairs_.history.end(), Vec<D>::zero());
    std::fill(wallHistory_.begin(), wallHistory_.end(), Vec<D>::zero());
    std::fill(surf_.count.begin(), surf_.count.end(), std::uint8_t{0});
    recordNow_ = sink;
    computeForces(false);
    recorded();
    return true;
}

template <int D>
void TdmEngine<D>::advanceTo(double t) {
    // Every step but the last predicts the next one in its force pass when the corrector runs there (velocity
    // Verlet, no polygons): the same arithmetic per particle, so the state at the end is the one of step() after
    // step(), bit for bit, with one pass over the particles a step instead of two.
    const bool fuse = verlet_ != nullptr && !shapes_;
    bool predicted = false, moved = false;
    while (w_.time + 0.5 * s_.dt <= t) {
        if (!predicted) moved = integ_->predict(w_.particles, s_.dt, motion_, xAtBuild_.data(), driftLimit2());
        // After this step, whether another one follows in this call; a stop asked for ends the call after it, so
        // the state is never left holding the next step's prediction.
        bool stop = s_.stop && s_.stop->load(std::memory_order_relaxed);
        if (halo_) agree(moved, stop);  // every rank rebuilds, and stops, at the same step
        const bool more = !stop && timeAfter(1) + 0.5 * s_.dt <= t;
        predicted = fuse && more;
        std::atomic<bool> nextMoved{false};
        finishStep(moved, predicted ? &nextMoved : nullptr);
        moved = nextMoved.load(std::memory_order_relaxed);
        if (stop) break;
    }
    // The last step's health, agreed before the call returns (the moved and stop bits are not used).
    if (halo_) {
        bool stop = false;
        agree(moved, stop);
    }
}

template <int D>
void TdmEngine<D>::checkHealth() const {
    const Particles<D>& p = w_.particles;
    auto fail = [&](std::size_t i, const std::string& what) {
        std::ostringstream os;
        os << what << " at particle id " << p.id[i] << " (t = " << w_.time << " s, step " << steps_
           << "): the time step is probably too large for the contact stiffness (dt = " << s_.dt
           << " s; contact duration " << w_.contact.contactTime << " s)";
        throw SimulationError(os.str());
    };
    if (stats_.maxOverlapRatio > s_.maxOverlap) {
        std::ostringstream os;
        os << "overlap " << stats_.maxOverlapRatio << " x radius exceeds max_overlap = " << s_.maxOverlap;
        fail(stats_.worstParticle, os.str());
    }
    if (stats_.nonFinite != ForceStats::kNone) fail(stats_.nonFinite, "non-finite position or force");
}

// A particle that moves more than its radius in one step passes through contacts the steps never see: either dt is
// far too long for its speed or the system blew up without ever holding an overlap at the end of a step (a stiff
// spring over a step of several contact durations turns a touch into a kick).
template <int D>
void TdmEngine<D>::checkSpeeds() const {
    const Particles<D>& p = w_.particles;
    for (std::size_t i = 0; i < p.tdmCount(); ++i) {
        const double step = norm(p.v[i]) * s_.dt;
        if (!(step <= p.radius[i]) && !p.frozen(i)) {
            std::ostringstream os;
            os << "particle id " << p.id[i] << " moves " << step << " m in one step, more than its radius "
               << p.radius[i] << " m (speed " << norm(p.v[i]) << " m/s, t = " << w_.time << " s, step " << steps_
               << "): the system blew up, or the time step (dt = " << s_.dt << " s; contact duration "
               << w_.contact.contactTime << " s) is too large for this speed";
            throw SimulationError(os.str());
        }
    }
}

template <int D>
double TdmEngine<D>::contactEnergy() const {
    if (halo_) return contactEnergyShare();
    const ForceContext<D> ctx = context(motion_.v.data(), motion_.w.data());
    if constexpr (D == 2)
        if (shapes_) return shapes_->energy(ctx);
    if (w_.contact.normal == NormalLaw::Linear) return diskContactEnergy<D, LinearNormal>(ctx);
    return diskContactEnergy<D, HertzViscoNormal>(ctx);  // both Hertz laws store (2/5) k_H sqrt(R) delta^{5/2}
}

template <int D>
double TdmEngine<D>::pairVirial() const {
    return stats_.virial;
}

template class TdmEngine<2>;
template class TdmEngine<3>;

}  // namespace haet
