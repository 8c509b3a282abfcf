// The hybrid's state in a checkpoint (HaetEngine::saveState, loadState; ARCHITECTURE.md, "Checkpoints").
//
// What is saved and what is made again: the construction resolves from the particles at the start the zone edge, the
// event grid's edge, the largest radius and the skin; a resumed run has other particles, so these are saved and the
// engines made anew from them. Everything a later step reads is then saved as it is, not recomputed: the zones' labels
// (the hysteresis reads them), the guard's levels, its bins (TDM positions at the last relabel) and the near grid made
// over them, the wall guard's cells (binned at the last due step, for the time until the next), the watch list with
// its quiet times, the per-zone step marks, the counters and the energy books; the book's zone volumes are sums in
// the order the particles came and went, so they are saved too. Scratch of a relabel (sticky zones, contact counts,
// the new guard list) is not: each relabel writes it before it reads it.
#include <cmath>
#include <string>

#include "haet/engine.hpp"

namespace haet {

namespace {

constexpr std::uint32_t kNil = 0xFFFFFFFFu;

/// Linked lists over `count` items, their heads in `head` and item k's successor next(k): every entry is an item
/// or kNil, and walking every list visits each item at most once (no cycle a corrupt file could make the engine
/// loop in). Returns the number of items listed.
template <class Next>
std::size_t checkLists(ByteReader& in, const std::vector<std::uint32_t>& head, std::size_t count, Next next,
                       const char* what) {
    std::vector<std::uint8_t> seen(count, 0);
    std::size_t listed = 0;
    for (std::uint32_t h : head)
        for (std::uint32_t k = h; k != kNil; k = next(k)) {
            if (k >= count || seen[k]++) in.fail(std::string(what) + ": a list entry out of range or listed twice");
            ++listed;
        }
    return listed;
}

template <class T>
void checkBelow(ByteReader& in, const std::vector<T>& v, std::size_t bound, const char* what) {
    for (const T x : v)
        if (static_cast<std::size_t>(x) >= bound) in.fail(std::string(what) + ": an index out of range");
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// the parts

template <int D>
void ZoneGrid<D>::saveState(ByteWriter& out) const {
    out.putVector(phi_);
    out.putVector(phiSmooth_);
    out.putVector(dense_);
    out.putVector(tdm_);
    out.put<std::uint64_t>(changed_);
}

template <int D>
void ZoneGrid<D>::loadState(ByteReader& in) {
    const auto n = static_cast<std::size_t>(count());
    in.getVector(phi_, n, "the zones' fractions");
    in.getVector(phiSmooth_, n, "the zones' smoothed fractions");
    in.getVector(dense_, n, "the zones' dense labels");
    in.getVector(tdm_, n, "the zones' time-driven labels");
    changed_ = in.get<std::uint64_t>();
}

template <int D>
void EdmBook<D>::saveState(ByteWriter& out) const {
    out.putVector(volume_);
    out.putVector(head_);
    out.putVector(next_);
    out.putVector(cell_);
    out.putVector(zone_);
    out.putVector(guardEntries_);
    out.putVector(tcHandovers_);
}

template <int D>
void EdmBook<D>::loadState(ByteReader& in, std::size_t first, std::size_t n) {
    in.getVector(volume_, static_cast<std::size_t>(zones_.count()), "the book's zone volumes");
    in.getVector(head_, static_cast<std::size_t>(cells_.count()), "the book's cells");
    in.getVector(next_);
    in.getVector(cell_, next_.size(), "the book's cell of each particle");
    in.getVector(zone_, next_.size(), "the book's zone of each particle");
    in.getVector(guardEntries_);
    in.getVector(tcHandovers_);
    // Every event-driven particle [first, n) in one list, and only those.
    if (checkLists(
            in, head_, next_.size(), [&](std::uint32_t k) { return next_[k]; }, "the book's cells") != n - first ||
        (n > first && next_.size() < n))
        in.fail("the book does not list the event-driven particles");
    for (std::size_t k = 0; k < cell_.size(); ++k)
        if ((k >= first && k < n) != (cell_[k] != kNone)) in.fail("the book's cells are not the event-driven ones");
    for (std::size_t c = 0; c < head_.size(); ++c)
        for (std::uint32_t k = head_[c]; k != kNone; k = next_[k])
            if (cell_[k] != c) in.fail("the book's cell of a particle is not the cell that lists it");
    for (std::size_t k = 0; k < zone_.size(); ++k)
        if (cell_[k] != kNone && zone_[k] >= static_cast<std::uint32_t>(zones_.count()))
            in.fail("the book's zone of a particle is out of range");
    checkBelow(in, guardEntries_, n, "the book's guard entries");
    checkBelow(in, tcHandovers_, n, "the book's hand-overs");
}

template <int D>
void WallGuard<D>::saveState(ByteWriter& out) const {
    out.put<std::uint8_t>(binned_);
    out.put<double>(listReach_);
    out.putVector(near_);
    out.putVector(list_);
    out.putVector(first_);
    out.putVector(items_);
}

template <int D>
void WallGuard<D>::loadState(ByteReader& in, std::uint32_t cells) {
    binned_ = in.get<std::uint8_t>() != 0;
    listReach_ = in.get<double>();
    in.getVector(near_);
    in.getVector(list_);
    in.getVector(first_);
    in.getVector(items_);
    if (near_.empty() && first_.empty() && list_.empty() && items_.empty()) return;  // never binned
    if (near_.size() != cells || first_.size() != std::size_t{cells} + 1 || first_.front() != 0 ||
        first_.back() != items_.size() || !std::is_sorted(first_.begin(), first_.end()))
        in.fail("the wall guard's cells do not fit the event grid");
    checkBelow(in, list_, cells, "the wall guard's near cells");
    const std::size_t nWalls = planes_.size() + surfaces_.size();
    for (const Item& it : items_) {
        if (it.wall >= nWalls) in.fail("the wall guard lists a wall out of range");
        if (it.wall >= planes_.size() &&
            it.element >= world_->surfaces[surfaces_[it.wall - planes_.size()]].elementCount())
            in.fail("the wall guard lists an element out of range");
    }
}

// ---------------------------------------------------------------------------------------------------------------
// the hybrid

template <int D>
void HaetEngine<D>::saveState(ByteWriter& out) const {
    out.put<std::uint64_t>(w_.particles.size());
    out.put<std::uint64_t>(nTdm());
    // What the construction resolved from the particles at the start.
    out.put<double>(hs_.zones.size);
    out.put<double>(edm_->settings().cellSize);
    out.put<double>(rmax_);
    out.put<double>(margin_);
    out.put<double>(ts_.dt);
    out.put<double>(ts_.skin);

    zones_.saveState(out);
    out.putVector(guard_);
    out.putVector(guardList_);
    out.putVector(binHead_);
    out.putVector(binCells_);
    out.putVector(bins_);
    out.put<std::uint8_t>(near_.valid);
    if (near_.valid) {
        out.put(near_.grid.origin());
        out.put(near_.grid.dims());
        out.put(near_.grid.width());
        out.putVector(near_.head);
    }
    walls_.saveState(out);
    out.putVector(watch_);
    out.put<std::uint64_t>(watchSorted_);
    std::vector<double> until(quiet_.size());
    std::vector<std::uint32_t> collisions(quiet_.size());
    std::vector<std::uint64_t> epoch(quiet_.size());
    for (std::size_t i = 0; i < quiet_.size(); ++i) {  // field by field: the record is padded
        until[i] = quiet_[i].until;
        collisions[i] = quiet_[i].collisions;
        epoch[i] = quiet_[i].epoch;
    }
    out.putVector(until);
    out.putVector(collisions);
    out.putVector(epoch);
    out.put<std::uint64_t>(binsEpoch_);
    out.putVector(lastTdmStep_);
    out.putVector(denseUntil_);
    out.put<double>(vTdmMax_);
    out.put<std::uint64_t>(steps_);
    out.put<std::uint8_t>(frozenModes_);
    for (std::uint64_t c : {counters_.toTdm, counters_.toEdm, counters_.tcHandovers, counters_.nearTdm,
                            counters_.nearWall, counters_.relabels})
        out.put<std::uint64_t>(c);
    for (double e : {e0_, tdmIn_, tdmOut_, tdm0_, inflow_, outflow_}) out.put<double>(e);

    // Each engine's state as a block of its own: its reader checks that it read the whole of it.
    ByteWriter tdm, edm;
    tdm_->saveState(tdm);
    edm_->saveState(edm);
    out.putString(tdm.bytes());
    out.putString(edm.bytes());
    book_.saveState(out);
}

template <int D>
void HaetEngine<D>::loadState(ByteReader& in, const std::function<void()>& reloadWorld) {
    const auto n = in.get<std::uint64_t>();
    const auto nT = in.get<std::uint64_t>();
    const double zoneSize = in.get<double>(), cellSize = in.get<double>(), rmax = in.get<double>();
    const double margin = in.get<double>(), dt = in.get<double>(), skin = in.get<double>();
    for (double v : {zoneSize, cellSize, rmax, margin, dt})
        if (!(v > 0) || !std::isfinite(v)) in.fail("the hybrid's lengths and time step are not positive numbers");
    if (!(skin >= 0) || !std::isfinite(skin)) in.fail("the skin is not a number");
    if (dt != ts_.dt) in.fail("the time step is not this scenario's");
    reloadWorld();
    Particles<D>& p = w_.particles;
    if (p.size() != n || p.tdmCount() != nT) in.fail("the particles and their split are not the World's");
    for (std::size_t i = 0; i < p.size(); ++i)
        if (p.radius[i] > rmax * (1 + 1e-12)) in.fail("a particle larger than the hybrid's largest radius");

    // The engines anew, from the saved configuration and the saved particles, as the start made them.
    hs_.zones.size = zoneSize;
    rmax_ = rmax;
    margin_ = margin;
    ts_.skin = skin;
    zones_ = ZoneGrid<D>(w_.domain, hs_.zones);
    EdmSettings es = edm_->settings();
    es.cellSize = cellSize;
    es.radiusBound = rmax;
    es.firstParticle = nT;
    tdm_.reset();
    edm_.reset();
    edm_ = std::make_unique<EdmEngine<D>>(w_, es, &book_);
    tdm_ = std::make_unique<TdmEngine<D>>(w_, ts_);
    reloadWorld();

    const auto cells = static_cast<std::size_t>(book_.cells().count());
    const auto nz = static_cast<std::size_t>(zones_.count());
    zones_.loadState(in);
    in.getVector(guard_, cells, "the guard's cells");
    for (std::uint8_t g : guard_)
        if (g > 2) in.fail("a guard level out of range");
    in.getVector(guardList_);
    checkBelow(in, guardList_, cells, "the guard's list");
    in.getVector(binHead_, cells, "the bins' cells");
    in.getVector(binCells_);
    checkBelow(in, binCells_, cells, "the bins' cell list");
    in.getVector(bins_);
    checkLists(
        in, binHead_, bins_.size(), [&](std::uint32_t b) { return bins_[b].next; }, "the bins");
    near_ = NearGrid{};
    near_.valid = in.get<std::uint8_t>() != 0;
    if (near_.valid) {
        const Vec<D> lo = in.get<Vec<D>>();
        const std::array<int, D> dims = in.get<std::array<int, D>>();
        const Vec<D> width = in.get<Vec<D>>();
        double total = 1;
        for (int k = 0; k < D; ++k) {
            if (dims[k] < 1 || !(width[k] > 0) || !std::isfinite(lo[k] + width[k])) in.fail("the near grid's cells");
            total *= dims[k];
        }
        if (total > double(in.rest().size())) in.fail("the near grid has more cells than the bytes left hold");
        near_.grid = CellGrid<D>(lo, dims, width, w_.domain.periodic);
        in.getVector(near_.head, static_cast<std::size_t>(near_.grid.count()), "the near grid's cells");
        checkLists(
            in, near_.head, bins_.size(), [&](std::uint32_t b) { return bins_[b].nextNear; }, "the near grid");
    }
    walls_.loadState(in, static_cast<std::uint32_t>(cells));
    in.getVector(watch_);
    checkBelow(in, watch_, n, "the watch list");
    watchSorted_ = in.get<std::uint64_t>();
    if (watchSorted_ > watch_.size()) in.fail("the watch list's sorted part is longer than the list");
    std::vector<double> until;
    std::vector<std::uint32_t> collisions;
    std::vector<std::uint64_t> epoch;
    in.getVector(until, n, "the quiet times");
    in.getVector(collisions, n, "the quiet collision counts");
    in.getVector(epoch, n, "the quiet epochs");
    quiet_.resize(n);
    for (std::size_t i = 0; i < n; ++i) quiet_[i] = Quiet{until[i], collisions[i], epoch[i]};
    binsEpoch_ = in.get<std::uint64_t>();
    in.getVector(lastTdmStep_, nz, "the zones' last time-driven steps");
    in.getVector(denseUntil_, nz, "the zones' dense-until steps");
    vTdmMax_ = in.get<double>();
    steps_ = in.get<std::uint64_t>();
    frozenModes_ = in.get<std::uint8_t>() != 0;
    for (std::uint64_t* c : {&counters_.toTdm, &counters_.toEdm, &counters_.tcHandovers, &counters_.nearTdm,
                             &counters_.nearWall, &counters_.relabels})
        *c = in.get<std::uint64_t>();
    for (double* e : {&e0_, &tdmIn_, &tdmOut_, &tdm0_, &inflow_, &outflow_}) *e = in.get<double>();

    const std::string tdmBytes = in.getString(), edmBytes = in.getString();
    ByteReader tdm(tdmBytes, in.what() + " (time-driven engine)"), edm(edmBytes, in.what() + " (event-driven engine)");
    tdm_->loadState(tdm);
    edm_->loadState(edm);  // tells the book its grid and every particle again (EdmObserver)
    book_.loadState(in, nT, n);
    for (std::size_t i = nT; i < n; ++i)
        if (!edm_->owns(i)) in.fail("an event-driven particle is not the event-driven engine's");
}

template void ZoneGrid<2>::saveState(ByteWriter&) const;
template void ZoneGrid<3>::saveState(ByteWriter&) const;
template void ZoneGrid<2>::loadState(ByteReader&);
template void ZoneGrid<3>::loadState(ByteReader&);
template void EdmBook<2>::saveState(ByteWriter&) const;
template void EdmBook<3>::saveState(ByteWriter&) const;
template void EdmBook<2>::loadState(ByteReader&, std::size_t, std::size_t);
template void EdmBook<3>::loadState(ByteReader&, std::size_t, std::size_t);
template void WallGuard<2>::saveState(ByteWriter&) const;
template void WallGuard<3>::saveState(ByteWriter&) const;
template void WallGuard<2>::loadState(ByteReader&, std::uint32_t);
template void WallGuard<3>::loadState(ByteReader&, std::uint32_t);
template void HaetEngine<2>::saveState(ByteWriter&) const;
template void HaetEngine<3>::saveState(ByteWriter&) const;
template void HaetEngine<2>::loadState(ByteReader&, const std::function<void()>&);
template void HaetEngine<3>::loadState(ByteReader&, const std::function<void()>&);

}  // namespace haet
