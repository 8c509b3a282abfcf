#include "haet/engine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

namespace haet {

namespace {
constexpr std::uint32_t kNil = 0xFFFFFFFFu;

template <int D>
double largestRadius(const Particles<D>& p) {
    double r = 0;
    for (double x : p.radius) r = std::max(r, x);
    return r;
}

/// Defaults that depend on the particles: the zone edge is 4 largest diameters, never below one.
template <int D>
HaetSettings resolved(const World<D>& w, HaetSettings hs) {
    const double d = 2 * std::max(largestRadius(w.particles), hs.radiusBound);
    if (!(hs.zones.size > 0)) hs.zones.size = 4 * d;
    hs.zones.size = std::max(hs.zones.size, d);
    if (!(hs.zones.size > 0)) hs.zones.size = 1;
    // At most max(2^20, 8 N) zones: grains of 10 um in a box of 2 cm would otherwise make 249^3 zones (1 GB); the
    // zones then grow, each still holding few particles.
    const double maxZones = std::max(1048576.0, 8.0 * static_cast<double>(w.particles.size()));
    hs.zones.size = CellGrid<D>::cappedEdge(w.domain.lo, w.domain.hi, hs.zones.size, maxZones);
    hs.relabelEvery = std::max(1, hs.relabelEvery);
    hs.diluteSteps = std::max(0, hs.diluteSteps);
    return hs;
}
}  // namespace

template <int D>
HaetEngine<D>::HaetEngine(World<D>& world, const TdmSettings& tdm, EdmSettings edm, const HaetSettings& hs)
    : w_(world), ts_(tdm), hs_(resolved(world, hs)), zones_(world.domain, hs_.zones), book_(zones_, guard_) {
    Particles<D>& p = w_.particles;
    const std::size_t n = p.size();
    const double rmax = std::max(largestRadius(p), hs_.radiusBound);

    // Initial labels from every particle, then the split: time-driven particles first.
    zones_.relabel(p, {});
    lastTdmStep_.assign(zones_.count(), 0);
    denseUntil_.assign(zones_.count(), 0);
    std::vector<std::uint32_t> order;
    order.reserve(n);
    for (std::uint32_t i = 0; i < n; ++i)
        if (zones_.timeDriven(zones_.zoneOf(p.x[i]))) order.push_back(i);
    const std::size_t nT = order.size();
    for (std::uint32_t i = 0; i < n; ++i)
        if (!zones_.timeDriven(zones_.zoneOf(p.x[i]))) order.push_back(i);
    p.permute(order);
    p.nTdm = nT;

    // The event grid's cells hold at least one particle diameter plus the TDM skin: a particle in a cell next to a
    // TDM particle's cell is at least a skin's width from touching it (docs/haet.md). Unless the scenario sets it,
    // the edge balances cell crossings against candidates per prediction for the event-driven particles' density.
    edm.firstParticle = nT;
    edm.radiusBound = rmax;
    edm.tcTime = hs_.dtMin > 0 ? hs_.dtMin : w_.contact.contactTime;
    edm.tcModel = true;
    // Curved and moving walls are the time-driven engine's: the guard keeps event-driven particles away from them.
    walls_.collect(w_);
    edm.guardedWalls = true;
    if (!(edm.cellSize > 0)) edm.cellSize = eventCellEdge(nT);
    edm.cellSize = std::max(edm.cellSize, 2 * rmax + ts_.skin);
    // The engine tells the book its grid and every particle's cell (EdmObserver): zone volumes, occupants, guard
    // entries and TC hand-overs are the book's from then on.
    edm_ = std::make_unique<EdmEngine<D>>(w_, edm, &book_);
    guard_.assign(book_.cells().count(), 0);
    binHead_.assign(book_.cells().count(), kNil);
    tdm_ = std::make_unique<TdmEngine<D>>(w_, ts_);
    margin_ = std::max(ts_.skin, 0.1 * rmax);
    rmax_ = rmax;
    quiet_.assign(n, Quiet{});

    // Energy baselines, then the first relabel (guard, stragglers).
    for (std::size_t i = 0; i < n; ++i) e0_ += particleEnergy(i);
    e0_ += tdm_->contactEnergy();
    tdm0_ = tdmEnergy();
    relabel({}, true);
}

template <int D>
HaetEngine<D>::~HaetEngine() = default;

// An event-driven particle flying a distance L crosses about L / h cells of edge h, and each crossing scans the
// 3^(D-1) newly adjacent cells, n h^D particles each at number density n. With a crossing's fixed cost worth
// kCrossingCost candidate tests, the cost per distance, (kCrossingCost + 3^(D-1) n h^D) / h, is least at
// n h^D = kCrossingCost / ((D - 1) 3^(D-1)) particles per cell. n: the event-driven particles per volume of the
// zones they occupy at the start. The edge stays within [largest diameter + skin, zone edge] (docs/haet.md).
template <int D>
double HaetEngine<D>::eventCellEdge(std::size_t nT) const {
    const Particles<D>& p = w_.particles;
    const std::size_t n = p.size();
    if (n == nT) return 0;
    std::vector<std::uint8_t> occupied(static_cast<std::size_t>(zones_.count()), 0);
    std::size_t zones = 0;
    for (std::size_t i = nT; i < n; ++i) {
        std::uint8_t& o = occupied[zones_.zoneOf(p.x[i])];
        zones += o == 0;
        o = 1;
    }
    const double density = static_cast<double>(n - nT) / (static_cast<double>(zones) * zones_.zoneVolume());
    constexpr double kCrossingCost = 20;
    const double perCell = kCrossingCost / ((D - 1) * (D == 2 ? 3.0 : 9.0));
    return std::min(std::pow(perCell / density, 1.0 / D), hs_.zones.size);
}

// ---------------------------------------------------------------------------------------------------------------

template <int D>
void HaetEngine<D>::step() {
    const double t1 = tdm_->timeAfter(1);  // where the time-driven step ends, bit for bit
    edm_->advanceEvents(t1);
    const std::uint64_t rebuilds = tdm_->rebuilds();
    tdm_->step();
    ++steps_;
    std::vector<std::uint32_t> arrivals;
    for (const std::uint32_t i : book_.takeTcHandovers()) {
        if (frozenModes_ || !edm_->owns(i)) continue;
        arrivals.push_back(i);
        ++counters_.tcHandovers;
        denseUntil_[zones_.zoneOf(edm_->positionAt(i, w_.time))] = steps_ + hs_.diluteSteps + hs_.relabelEvery;
    }
    for (const std::uint32_t i : book_.takeGuardEntries())
        if (!frozenModes_ && edm_->owns(i) && guard_[book_.cellOf(i)] != 0) watch_.push_back(i);
    if (frozenModes_) return;
    // Mode changes wait for every relabelEvery-th step (each costs a pair-list rebuild), unless a particle would
    // touch a TDM particle before then. TDM particles move less than skin/2 between pair-list builds: relabelling
    // at each build too keeps the guard's picture of them within that distance.
    const bool due = steps_ % static_cast<std::uint64_t>(hs_.relabelEvery) == 0;
    if (due || tdm_->rebuilds() != rebuilds) {
        relabel(std::move(arrivals), due);
        return;
    }
    checkWatched(arrivals, false);
    if (!arrivals.empty()) convert(std::move(arrivals), {});
}

template <int D>
void HaetEngine<D>::advanceTo(double t) {
    while (w_.time + 0.5 * ts_.dt <= t) {
        step();
        if (hs_.stop && hs_.stop->load(std::memory_order_relaxed)) return;  // after a whole step
    }
}

template <int D>
void HaetEngine<D>::synchronise() {
    edm_->synchronise(w_.time);
}

// ---------------------------------------------------------------------------------------------------------------
// the guard

template <int D>
void HaetEngine<D>::bin(const Vec<D>& x, double r) {
    const auto c = static_cast<std::uint32_t>(book_.cells().cellOf(x));
    if (binHead_[c] == kNil) binCells_.push_back(c);
    const auto b = static_cast<std::uint32_t>(bins_.size());
    bins_.push_back(Binned{x, r, binHead_[c], kNil});
    binHead_[c] = b;
    if (near_.valid) {
        const int idx = near_.grid.wrappedCellOf(x);
        bins_[b].nextNear = near_.head[idx];
        near_.head[idx] = b;
    }
}

template <int D>
void HaetEngine<D>::markAround(std::uint32_t cell, std::uint8_t level) {
    book_.cells().forEachNeighbour(static_cast<int>(cell), [&](int nb, int) {
        const auto idx = static_cast<std::uint32_t>(nb);
        std::uint8_t& g = guard_[idx];
        const std::uint8_t oldLevel = g & 3, newLevel = g >> 2;
        if (newLevel >= level) return;
        if (newLevel == 0) newList_.push_back(idx);
        g = static_cast<std::uint8_t>(oldLevel | (level << 2));
        if (level > oldLevel)  // occupants of a cell that became stricter are watched
            book_.forEachIn(idx, [&](std::uint32_t i) { watch_.push_back(i); });
    });
}

template <int D>
void HaetEngine<D>::buildNearGrid() {
    const double edge = 2 * rmax_ + margin_;
    Vec<D> a = Vec<D>::filled(std::numeric_limits<double>::max()),
           b = Vec<D>::filled(-std::numeric_limits<double>::max());
    for (const Binned& q : bins_)
        for (int k = 0; k < D; ++k) {
            a[k] = std::min(a[k], q.x[k]);
            b[k] = std::max(b[k], q.x[k]);
        }
    // At most max(4096, 4 bins) cells: a few far-flung TDM particles give larger cells, not a huge grid.
    const double maxCells = std::max(4096.0, 4.0 * static_cast<double>(bins_.size()));
    std::array<int, D> n{};
    Vec<D> lo, width;
    for (double h = edge;; h *= 1.25) {
        double total = 1;
        for (int k = 0; k < D; ++k) {
            if (w_.domain.periodic[k]) {  // whole cells over the box
                const double L = w_.domain.hi[k] - w_.domain.lo[k];
                n[k] = std::max(1, static_cast<int>(std::floor(L / h)));
                lo[k] = w_.domain.lo[k];
                width[k] = L / n[k];
            } else {  // cells of edge h over the bins
                const double span = bins_.empty() ? 0.0 : b[k] - a[k];
                n[k] = std::max(1, static_cast<int>(std::ceil(span / h)));
                lo[k] = bins_.empty() ? 0.0 : a[k];
                width[k] = h;
            }
            total *= n[k];
        }
        if (total <= maxCells) break;
    }
    near_.grid = CellGrid<D>(lo, n, width, w_.domain.periodic);
    near_.head.assign(static_cast<std::size_t>(near_.grid.count()), kNil);
    near_.valid = true;
    for (std::uint32_t i = 0; i < bins_.size(); ++i) {
        const int idx = near_.grid.wrappedCellOf(bins_[i].x);
        bins_[i].nextNear = near_.head[idx];
        near_.head[idx] = i;
    }
}

// Positions outside the near grid on an open axis fall into its outer cells, bins and queries alike: clamping
// never separates two points less than a cell apart by more than one cell.
template <int D>
double HaetEngine<D>::gapToTdm(const Vec<D>& x, double r, double* bound) const {
    double gap = kNever;
    if (bound) *bound = 0;
    if (!near_.valid) return gap;
    // Every bin outside the 3^D cells around x is at least a cell width away on some axis.
    double lowest = kNever;
    if (bound) {
        double width = kNever;
        for (int k = 0; k < D; ++k) width = std::min(width, near_.grid.width()[k]);
        lowest = width - r - rmax_;
    }
    // A periodic axis of one or two cells visits a cell more than once: harmless for a minimum.
    near_.grid.forEachNeighbour(near_.grid.wrappedCoordsOf(x), [&](int cell, int) {
        for (std::uint32_t b = near_.head[cell]; b != kNil; b = bins_[b].nextNear) {
            const Vec<D> d = w_.domain.minimumImage(x - bins_[b].x);
            const double reach = r + bins_[b].r + margin_, d2 = norm2(d);
            if (d2 < reach * reach && d2 > 0) gap = std::min(gap, std::sqrt(d2) - r - bins_[b].r);
            if (bound && d2 > 0) lowest = std::min(lowest, std::sqrt(d2) - r - bins_[b].r);
        }
    });
    if (bound) *bound = lowest;
    return gap;
}

// Event-driven particles in guard cells: handed over once within reach of a TDM particle or inside a time-driven
// zone; before the next due step only if they could touch a TDM particle before it.
template <int D>
void HaetEngine<D>::checkWatched(std::vector<std::uint32_t>& arrivals, bool due) {
    // watch_[0, watchSorted_) is sorted and unique; what came since is sorted and merged in.
    const auto mid = watch_.begin() + static_cast<std::ptrdiff_t>(std::min(watchSorted_, watch_.size()));
    std::sort(mid, watch_.end());
    std::inplace_merge(watch_.begin(), mid, watch_.end());
    watch_.erase(std::unique(watch_.begin(), watch_.end()), watch_.end());
    const std::uint64_t R = static_cast<std::uint64_t>(hs_.relabelEvery);
    const double horizon = ts_.dt * static_cast<double>(R - steps_ % R + 1);
    const double g = norm(w_.domain.gravity);
    std::size_t keep = 0;
    if (!walls_.empty()) walls_.moveTo(w_.time);
    for (const std::uint32_t i : watch_) {
        if (!edm_->owns(i)) continue;
        const std::uint8_t level = guard_[book_.cellOf(i)] & 3;
        if (level == 0) continue;
        if (walls_.near(book_.cellOf(i)) &&
            nearGuardedWall(book_.cellOf(i), edm_->positionAt(i, w_.time), w_.particles.radius[i],
                            norm(edm_->velocityAt(i, w_.time)), due)) {
            arrivals.push_back(i);
            ++counters_.nearWall;
            continue;
        }
        // Near a TDM particle only: skipped while it provably stays beyond the margin (below).
        const Quiet& q = quiet_[i];
        if (level == 1 && q.epoch == binsEpoch_ && w_.time < q.until && q.collisions == edm_->collisionCount(i)) {
            watch_[keep++] = i;
            continue;
        }
        double bound;
        const double gap = gapToTdm(edm_->positionAt(i, w_.time), w_.particles.radius[i], &bound);
        const double speed = norm(edm_->velocityAt(i, w_.time));
        if (level >= 2 || gap < margin_) {
            const double reach = (speed + vTdmMax_) * horizon;
            if (due || gap < reach) {
                arrivals.push_back(i);
                if (level < 2) ++counters_.nearTdm;
                continue;
            }
        } else {
            // The bins stay put until the next relabel or hand-over (a new epoch), and the particle flies
            // ballistically until it collides (its collision count changes): its gap to them cannot fall below the
            // margin sooner than tau, when speed tau + g tau^2 / 2 = bound - margin.
            const double room = bound - margin_;
            const double tau = room > 0 ? 2 * room / (speed + std::sqrt(speed * speed + 2 * g * room)) : 0.0;
            quiet_[i] = Quiet{w_.time + tau, edm_->collisionCount(i), binsEpoch_};
        }
        watch_[keep++] = i;
    }
    watch_.resize(keep);
    watchSorted_ = keep;
}

// The cells from which an event-driven particle could come near a wall the event-driven engine does not predict,
// before the next refresh (a due relabel at the latest: relabelEvery + 1 steps), are guarded like the cells around a
// TDM particle: their occupants are watched, and entering them is reported (docs/haet.md).
template <int D>
void HaetEngine<D>::guardWalls(bool due) {
    if (walls_.empty()) return;
    // Binned on due steps, over the time to the step after the next one: a relabel between them (a pair-list
    // build) keeps the cells.
    if (due) walls_.refresh(book_.cells(), w_.time, ts_.dt * (hs_.relabelEvery + 1), rmax_, margin_);
    walls_.moveTo(w_.time);
    for (const std::uint32_t c : walls_.cells()) {
        std::uint8_t& g = guard_[c];
        const std::uint8_t oldLevel = g & 3, newLevel = g >> 2;
        if (newLevel >= 1) continue;
        newList_.push_back(c);
        g = static_cast<std::uint8_t>(oldLevel | (1 << 2));
        if (oldLevel < 1) book_.forEachIn(c, [&](std::uint32_t i) { watch_.push_back(i); });
    }
}

// Hand-overs wait for the due step, as near TDM particles, unless the gap could close before it: the particle flies
// at most speed h + g h^2 / 2 and the wall's points move at most its speed h in the time h to the step after it.
template <int D>
bool HaetEngine<D>::nearGuardedWall(std::uint32_t cell, const Vec<D>& x, double r, double speed, bool due) const {
    const double gap = walls_.gap(cell, x, r);
    const std::uint64_t R = static_cast<std::uint64_t>(hs_.relabelEvery);
    const double h = ts_.dt * static_cast<double>(R - steps_ % R + 1);
    const double reach = (speed + walls_.speed()) * h + 0.5 * norm(w_.domain.gravity) * h * h;
    return gap < reach || (due && gap < margin_);
}

// ---------------------------------------------------------------------------------------------------------------
// zones and mode changes

template <int D>
void HaetEngine<D>::relabel(std::vector<std::uint32_t> arrivals, bool due) {
    Particles<D>& p = w_.particles;
    const std::size_t nT = p.tdmCount();
    const int nz = zones_.count();

    double v2 = 0;
    for (std::size_t i = 0; i < nT; ++i)
        if (!p.frozen(i)) v2 = std::max(v2, norm2(p.v[i]));
    vTdmMax_ = std::sqrt(v2);
    // Zone labels (due steps only) from the volume per zone: the event-driven part is kept current by the
    // engine's crossings.
    std::vector<int> zoneOf;
    if (due) {
        ++counters_.relabels;
        std::vector<double> vol = book_.zoneVolume();
        zoneOf.resize(nT);
        for (std::size_t i = 0; i < nT; ++i) {
            zoneOf[i] = zones_.zoneOf(p.x[i]);
            vol[zoneOf[i]] += Particles<D>::volumeOf(p.radius[i]);
        }
        tdm_->contactCounts(contact_);
        sticky_.assign(nz, 0);
        for (int z = 0; z < nz; ++z)
            if (denseUntil_[z] > steps_) sticky_[z] = 1;
        // Contacts keep a zone dense, and make it dense where a particle rests on a wall or touches two others:
        // the smoothed fraction misses a packing thinner than about two zones, such as a bed of a few layers
        // (A.2, docs/haet.md). A single pair contact (a binary collision) only keeps a dense zone dense.
        for (std::size_t i = 0; i < nT; ++i)
            if (contact_[i] >= 2 || (contact_[i] == 1 && zones_.dense(zoneOf[i]))) sticky_[zoneOf[i]] = 1;
        zones_.relabel(vol, sticky_);
        for (int z = 0; z < nz; ++z)
            if (zones_.timeDriven(z)) lastTdmStep_[z] = steps_;
    }

    // Leaving the TDM: no contact, the zone event-driven for diluteSteps and its own (unsmoothed) fraction below
    // phi_off (a loose packing whose particles happen not to touch at this instant stays), and no staying TDM
    // particle within the margin: the particles of a dilute cluster leave together (A.3, docs/haet.md).
    while (!binCells_.empty()) {
        binHead_[binCells_.back()] = kNil;
        binCells_.pop_back();
    }
    bins_.clear();
    near_.valid = false;
    ++binsEpoch_;
    std::vector<std::uint32_t> candidates;
    for (std::size_t i = 0; i < nT; ++i) {
        const std::uint64_t last = due ? lastTdmStep_[zoneOf[i]] : steps_;
        const bool leave = due && !frozenModes_ && !contact_[i] && last < steps_ &&
                           steps_ - last >= static_cast<std::uint64_t>(hs_.diluteSteps) &&
                           zones_.fraction(zoneOf[i]) < hs_.zones.phiOff;
        if (leave)
            candidates.push_back(static_cast<std::uint32_t>(i));
        else
            bin(p.x[i], p.radius[i]);
    }

    buildNearGrid();

    // The new guard: level 2 in time-driven zones, level 1 around the staying TDM particles.
    newList_.clear();
    const std::array<int, D>& zd = zones_.dims();
    for (int z = 0; z < nz; ++z) {
        if (!zones_.timeDriven(z)) continue;
        std::array<int, D> zc;
        int t = z;
        for (int k = 0; k < D; ++k) {
            zc[k] = t % zd[k];
            t /= zd[k];
        }
        std::array<std::uint32_t, D> lo, hi, at;
        bool empty = false;
        for (int k = 0; k < D; ++k) {
            lo[k] = book_.zoneCellBegin()[k][zc[k]];
            hi[k] = book_.zoneCellBegin()[k][zc[k] + 1];
            empty = empty || lo[k] >= hi[k];
            at[k] = lo[k];
        }
        if (empty) continue;
        const std::array<int, D>& nc = book_.cells().dims();
        for (;;) {
            std::uint32_t idx = 0, stride = 1;
            for (int k = 0; k < D; ++k) {
                idx += at[k] * stride;
                stride *= static_cast<std::uint32_t>(nc[k]);
            }
            std::uint8_t& g = guard_[idx];
            if ((g >> 2) < 2) {
                if ((g >> 2) == 0) newList_.push_back(idx);
                if ((g & 3) < 2) book_.forEachIn(idx, [&](std::uint32_t i) { watch_.push_back(i); });
                g = static_cast<std::uint8_t>((g & 3) | (2 << 2));
            }
            int k = 0;
            while (k < D && ++at[k] == hi[k]) {
                at[k] = lo[k];
                ++k;
            }
            if (k == D) break;
        }
    }
    for (std::size_t b = 0, nb = binCells_.size(); b < nb; ++b) markAround(binCells_[b], 1);
    guardWalls(due);
    // A candidate within reach of a staying TDM particle, or whose event-grid cell belongs to a time-driven zone,
    // stays (it would be handed back at once); so may its neighbours then: a candidate that stays puts the
    // candidates of the cells around it back on the work list.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> byCell;  // (cell, candidate), sorted
    byCell.reserve(candidates.size());
    for (const std::uint32_t i : candidates)
        byCell.emplace_back(static_cast<std::uint32_t>(book_.cells().cellOf(p.x[i])), i);
    std::sort(byCell.begin(), byCell.end());
    std::vector<std::uint8_t> stays(byCell.size(), 0);
    std::vector<std::size_t> work(byCell.size());
    for (std::size_t q = 0; q < work.size(); ++q) work[q] = work.size() - 1 - q;
    while (!work.empty()) {
        const std::size_t q = work.back();
        work.pop_back();
        if (stays[q]) continue;
        const auto [c, i] = byCell[q];
        if ((guard_[c] >> 2) < 2 && gapToTdm(p.x[i], p.radius[i]) >= margin_ &&
            !(walls_.near(c) && nearGuardedWall(c, p.x[i], p.radius[i], norm(p.v[i]), true)))
            continue;
        stays[q] = 1;
        const bool fresh = binHead_[c] == kNil;
        bin(p.x[i], p.radius[i]);
        if (fresh) markAround(c, 1);
        book_.cells().forEachNeighbour(static_cast<int>(c), [&](int cell, int) {
            const auto idx = static_cast<std::uint32_t>(cell);
            auto at = std::lower_bound(byCell.begin(), byCell.end(), std::make_pair(idx, std::uint32_t{0}));
            for (; at != byCell.end() && at->first == idx; ++at) {
                const std::size_t r = static_cast<std::size_t>(at - byCell.begin());
                if (!stays[r]) work.push_back(r);
            }
        });
    }
    std::vector<std::uint32_t> departures;
    for (std::size_t q = 0; q < byCell.size(); ++q)
        if (!stays[q]) departures.push_back(byCell[q].second);
    // Settle the guard: new levels replace old ones.
    for (const std::uint32_t c : guardList_) guard_[c] = static_cast<std::uint8_t>(guard_[c] & ~3u);
    for (const std::uint32_t c : newList_) guard_[c] = static_cast<std::uint8_t>(guard_[c] >> 2);
    guardList_.clear();
    for (const std::uint32_t c : newList_) guardList_.push_back(c);
    checkWatched(arrivals, due);
    if (!arrivals.empty() || !departures.empty()) convert(std::move(arrivals), std::move(departures));
}

template <int D>
void HaetEngine<D>::convert(std::vector<std::uint32_t> arrivals, std::vector<std::uint32_t> departures) {
    Particles<D>& p = w_.particles;
    const double t = w_.time;
    std::sort(arrivals.begin(), arrivals.end());
    arrivals.erase(std::unique(arrivals.begin(), arrivals.end()), arrivals.end());
    arrivals.erase(std::remove_if(arrivals.begin(), arrivals.end(), [&](std::uint32_t i) { return !edm_->owns(i); }),
                   arrivals.end());
    std::sort(departures.begin(), departures.end());
    departures.erase(std::unique(departures.begin(), departures.end()), departures.end());
    if (arrivals.empty() && departures.empty()) return;

    std::size_t nT = p.tdmCount();
    std::vector<std::uint32_t> from(nT);
    for (std::size_t k = 0; k < nT; ++k) from[k] = static_cast<std::uint32_t>(k);
    // Where the particles that move end up (watch_ holds World indices): current index -> original index.
    std::unordered_map<std::uint32_t, std::uint32_t> origin;
    auto swapAt = [&](std::uint32_t a, std::uint32_t b) {
        if (a == b) return;
        p.swapEntries(a, b);
        edm_->swapIndices(a, b);
        book_.swapped(a, b);
        std::swap(quiet_[a], quiet_[b]);
        auto oa = origin.find(a), ob = origin.find(b);
        const std::uint32_t ia = oa != origin.end() ? oa->second : a, ib = ob != origin.end() ? ob->second : b;
        origin[a] = ib;
        origin[b] = ia;
    };
    // Event-driven -> time-driven, in increasing index order: each exchanges places with the first EDM particle.
    for (const std::uint32_t a : arrivals) {
        edm_->remove(a, t);
        const double e = particleEnergy(a);
        tdmIn_ += e;
        swapAt(a, static_cast<std::uint32_t>(nT));
        from.push_back(TdmEngine<D>::kFresh);
        ++nT;
    }
    // Time-driven -> event-driven, in decreasing index order: each exchanges places with the last TDM particle.
    for (auto it = departures.rbegin(); it != departures.rend(); ++it) {
        const std::uint32_t d = *it;
        tdmOut_ += particleEnergy(d);
        const std::uint32_t last = static_cast<std::uint32_t>(nT - 1);
        swapAt(d, last);
        from[d] = from[last];
        from.pop_back();
        --nT;
    }
    p.nTdm = nT;
    counters_.toTdm += arrivals.size();
    counters_.toEdm += departures.size();
    // Watched indices follow their particles (before the departed ones join the list with their new indices).
    if (!origin.empty() && !watch_.empty()) {
        std::unordered_map<std::uint32_t, std::uint32_t> now;  // original index -> current index
        for (const auto& [cur, orig] : origin) now[orig] = cur;
        for (std::uint32_t& i : watch_) {
            auto f = now.find(i);
            if (f != now.end()) i = f->second;
        }
        watchSorted_ = 0;  // renumbered: sorted anew at the next check
    }
    for (std::size_t k = 0; k < departures.size(); ++k) {
        edm_->add(nT + k, t);
        watch_.push_back(static_cast<std::uint32_t>(nT + k));
    }
    tdm_->remap(from);
    ++binsEpoch_;
    // The new TDM particles guard their surroundings until the next relabel.
    for (std::size_t k = 0; k < nT; ++k) {
        if (from[k] != TdmEngine<D>::kFresh) continue;
        bin(p.x[k], p.radius[k]);
        book_.cells().forEachNeighbour(book_.cells().cellOf(p.x[k]), [&](int nb, int) {
            const auto idx = static_cast<std::uint32_t>(nb);
            if (guard_[idx] != 0) return;
            guard_[idx] = 1;
            guardList_.push_back(idx);
            book_.forEachIn(idx, [&](std::uint32_t i) { watch_.push_back(i); });
        });
    }
}

template <int D>
void HaetEngine<D>::forceModes(const std::vector<std::uint32_t>& toTdm, const std::vector<std::uint32_t>& toEdm) {
    convert(toTdm, toEdm);
}

template <int D>
std::size_t HaetEngine<D>::unwatchedInGuard() const {
    std::vector<std::uint32_t> watched = watch_;
    std::sort(watched.begin(), watched.end());
    std::size_t missing = 0;
    for (std::size_t i = nTdm(); i < w_.particles.size(); ++i)
        if (guard_[book_.cellOf(static_cast<std::uint32_t>(i))] != 0 &&
            !std::binary_search(watched.begin(), watched.end(), static_cast<std::uint32_t>(i)))
            ++missing;
    return missing;
}

// ---------------------------------------------------------------------------------------------------------------
// energy

template <int D>
double HaetEngine<D>::particleEnergy(std::size_t i) const {
    const Particles<D>& p = w_.particles;
    double e = -p.mass[i] * dot(w_.domain.gravity, w_.domain.unwrap(p.x[i], p.image[i]));
    if (!p.frozen(i)) e += 0.5 * p.mass[i] * norm2(p.v[i]) + 0.5 * p.inertia(i) * norm2(p.w[i]);
    return e;
}

template <int D>
double HaetEngine<D>::tdmEnergy() const {
    double e = tdm_->contactEnergy();
    for (std::size_t i = 0; i < w_.particles.tdmCount(); ++i) e += particleEnergy(i);
    return e;
}

template <int D>
HaetEnergy HaetEngine<D>::energy() const {
    HaetEnergy e;
    e.initial = e0_;
    e.total = tdm_->contactEnergy();
    for (std::size_t i = 0; i < w_.particles.size(); ++i) e.total += particleEnergy(i);
    e.dissipatedEdm = edm_->stats().dissipated;
    e.dissipatedTdm = tdm0_ - tdmEnergy() + tdmIn_ - tdmOut_;
    e.inflow = inflow_;
    e.outflow = outflow_;
    e.unaccounted = e.initial + e.inflow - e.outflow - e.total - e.dissipatedTdm - e.dissipatedEdm;
    return e;
}

template class HaetEngine<2>;
template class HaetEngine<3>;

}  // namespace haet
