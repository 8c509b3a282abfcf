// The event-driven engine's state in a checkpoint (EdmEngine::saveState, loadState; ARCHITECTURE.md, "Checkpoints").
// The neighbour shells are saved with their lists as they are, which a rebuild from the centres would order
// otherwise. The slots are saved as they are, each particle at its own clock with its pending event: synchronising them
// first would move every clock to one time, and the events then pending, predicted from the earlier states, would not
// be the ones a prediction from the synchronised states finds (their last bits differ), so the run would not go on as
// the one that was never stopped.
#include <cmath>

#include "edm/engine.hpp"

namespace haet {

template <int D>
void EdmEngine<D>::saveState(ByteWriter& out) const {
    if (!restartable()) throw std::logic_error("event-driven engine: no checkpoint in reference mode");
    // The grid as the last reset made it (from the particles then, which inlets and outlets change since).
    out.put<double>(gridEdge_);
    out.put<double>(gridCap_);
    out.put<double>(rmax_);
    out.put<std::uint64_t>(grid_.count());
    out.putVector(sl_.hot);
    out.putVector(sl_.link);
    out.putVector(sl_.rec);
    std::vector<double> times(sl_.size());
    for (std::size_t s = 0; s < times.size(); ++s) times[s] = queue_.time(static_cast<std::uint32_t>(s));
    out.putVector(times);
    out.putVector(tc_.lastCollisions());
    out.putVector(free_);
    out.put<std::uint8_t>(shells_.on());
    if (shells_.on()) shells_.save(out);
    out.put<std::uint64_t>(nLive_);
    out.put<std::uint64_t>(nMoving_);
    out.put<double>(maxRate_);
    out.put<std::uint64_t>(events_);
    out.put<std::uint64_t>(sortedAt_);
    out.put<std::uint64_t>(window_);
    out.put<std::uint64_t>(winEvents_);
    out.put<double>(winTime_);
    out.put<double>(virial_);
    for (std::uint64_t c : {stats_.pairCollisions, stats_.wallCollisions, stats_.cellCrossings, stats_.shellExits,
                            stats_.listGrowths, stats_.stale, stats_.tcElastic, stats_.restHops, stats_.grazing})
        out.put<std::uint64_t>(c);
    out.put<double>(stats_.dissipated);
}

template <int D>
void EdmEngine<D>::loadState(ByteReader& in) {
    if (!restartable()) in.fail("an event-driven engine in reference mode cannot be resumed");
    // The grid as the saved one was made, from the parameters of its last reset: the engine made on the loaded
    // World has counted other particles if inlets or outlets changed them since.
    const double edge = in.get<double>(), cap = in.get<double>(), rmax = in.get<double>();
    if (!(edge > 0) || !(cap >= 1) || !(rmax > 0) || !std::isfinite(edge + cap + rmax))
        in.fail("the event grid's parameters are not positive numbers");
    const bool regrid = edge != gridEdge_ || cap != gridCap_ || rmax != rmax_;
    edm::EventGrid<D> grid = grid_;
    if (regrid) grid.build(w_.domain, edge, cap);
    if (in.get<std::uint64_t>() != grid.count()) in.fail("the event grid has another number of cells");
    Sl sl = sl_;
    in.getVector(sl.hot);
    const std::size_t n = sl.hot.size();
    in.getVector(sl.link, n, "the slots' links");
    in.getVector(sl.rec, n, "the slots' records");
    std::vector<double> times;
    in.getVector(times, n, "the pending events' times");
    std::vector<double> last;
    in.getVector(last, tc_.on() ? n : 0, "the TC model's clocks");
    std::vector<std::uint32_t> freeSlots;
    in.getVector(freeSlots);
    const std::size_t nWorld = w_.particles.size();
    const std::uint32_t walls = static_cast<std::uint32_t>(w_.walls.size() + mesh_.size());
    if (n >= (1u << kTypeShift)) in.fail("too many slots");
    std::vector<std::uint8_t> seen(nWorld, 0);
    for (std::size_t s = 0; s < n; ++s) {
        const Rec& r = sl.rec[s];
        const std::uint32_t code = r.coll.code, k = code & kIndexMask;
        if (r.idx == kNil) {
            if (r.cell != grid.count()) in.fail("a free slot in a cell");
        } else if (r.idx >= nWorld || seen[r.idx]++) {
            in.fail("a slot's particle is out of range or has two slots");
        } else if (r.cell >= grid.count()) {
            in.fail("a slot's cell is out of range");
        }
        if (((code >> kTypeShift) == kPair && k >= n) || ((code >> kTypeShift) == kWall && k >= walls))
            in.fail("a pending event's partner is out of range");
        if ((r.exit >> 1) >= unsigned(D)) in.fail("a pending crossing's face is out of range");
        if (std::isnan(times[s]) || std::isnan(sl.hot[s].t)) in.fail("a clock is not a number");
    }
    for (std::uint32_t f : freeSlots)
        if (f >= n || sl.rec[f].idx != kNil) in.fail("a free slot is out of range or taken");
    if ((in.get<std::uint8_t>() != 0) != shells_.on()) in.fail("neighbour shells saved for a run without, or not");
    edm::Shells<D> shells = shells_;
    if (shells.on()) shells.load(in, n);
    const auto live = in.get<std::uint64_t>();
    if (live + freeSlots.size() != n) in.fail("the live and free slots do not add up");
    nLive_ = live;
    nMoving_ = in.get<std::uint64_t>();
    maxRate_ = in.get<double>();
    events_ = in.get<std::uint64_t>();
    sortedAt_ = in.get<std::uint64_t>();
    window_ = in.get<std::uint64_t>();
    winEvents_ = in.get<std::uint64_t>();
    winTime_ = in.get<double>();
    virial_ = in.get<double>();
    for (std::uint64_t* c : {&stats_.pairCollisions, &stats_.wallCollisions, &stats_.cellCrossings, &stats_.shellExits,
                             &stats_.listGrowths, &stats_.stale, &stats_.tcElastic, &stats_.restHops, &stats_.grazing})
        *c = in.get<std::uint64_t>();
    stats_.dissipated = in.get<double>();
    in.expectEnd();
    if (window_ == 0) in.fail("an event-rate window of no events");

    for (std::size_t s = 0; s < n; ++s)
        if (sl.rec[s].idx != kNil && sl.hot[s].r > rmax * (1 + 1e-12)) in.fail("a particle larger than the grid");

    if (regrid) {  // everything read and checked: the state changes from here on
        rmax_ = rmax;
        gridEdge_ = edge;
        gridCap_ = cap;
        grid_ = std::move(grid);
        mesh_.bin(grid_.cells(), rmax_, shells_.half());
    }

    sl_.hot.swap(sl.hot);
    sl_.link.swap(sl.link);
    sl_.rec.swap(sl.rec);
    tc_.setLastCollisions(std::move(last));
    free_.swap(freeSlots);
    shells_ = std::move(shells);
    queue_.reset(n);
    queue_.build(times);
    grid_.relink(sl_);
    if (s_.holdState) {
        std::vector<std::uint32_t>().swap(slotOf_);
    } else {
        slotOf_.assign(nWorld, kNil);
        for (std::uint32_t s = 0; s < n; ++s)
            if (sl_.rec[s].idx != kNil) slotOf_[sl_.rec[s].idx] = s;
    }
    if (observer_) reportAll();
}

template <int D>
void EdmEngine<D>::exposeHeldState() {
    Particles<D>& p = w_.particles;
    if (p.hasMotion()) return;
    p.restoreMotion();
    for (std::uint32_t s = 0; s < sl_.size(); ++s) {
        const std::uint32_t i = sl_.rec[s].idx;
        if (i == kNil) continue;
        p.x[i] = sl_.hot[s].x;
        p.v[i] = sl_.hot[s].v;
        p.radius[i] = sl_.hot[s].r;
    }
}

template void EdmEngine<2>::saveState(ByteWriter&) const;
template void EdmEngine<3>::saveState(ByteWriter&) const;
template void EdmEngine<2>::loadState(ByteReader&);
template void EdmEngine<3>::loadState(ByteReader&);
template void EdmEngine<2>::exposeHeldState();
template void EdmEngine<3>::exposeHeldState();

}  // namespace haet
