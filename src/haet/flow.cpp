// The hybrid's particles that come and go (docs/haet.md, "Inlets and outlets"): removal from either engine, birth
// in the mode of the zone, and the energy they bring and take, so that the books stay balanced.
#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "haet/engine.hpp"

namespace haet {

template <int D>
void HaetEngine<D>::removeParticles(const std::vector<std::uint32_t>& which) {
    if (which.empty()) return;
    Particles<D>& p = w_.particles;
    const double t = w_.time;
    // Where the particles that move end up, for the watch list (World indices): current index -> original one.
    std::unordered_map<std::uint32_t, std::uint32_t> origin;
    std::unordered_set<std::uint32_t> gone;  // original indices of the removed particles
    auto originOf = [&](std::uint32_t i) {
        const auto it = origin.find(i);
        return it != origin.end() ? it->second : i;
    };
    auto swapAt = [&](std::uint32_t a, std::uint32_t b) {
        if (a == b) return;
        p.swapEntries(a, b);
        edm_->swapIndices(a, b);
        book_.swapped(a, b);
        std::swap(quiet_[a], quiet_[b]);
        const std::uint32_t oa = originOf(a), ob = originOf(b);
        origin[a] = ob;
        origin[b] = oa;
    };
    // The last particle of the store leaves it: `i` (unowned by either engine) goes there first.
    auto dropAt = [&](std::uint32_t i) {
        const auto last = static_cast<std::uint32_t>(p.size() - 1);
        swapAt(i, last);
        gone.insert(originOf(last));
        origin.erase(last);
        p.popBack();
        quiet_.pop_back();
    };
    std::size_t nT = p.tdmCount();
    std::vector<std::uint32_t> tdmGone;
    // Event-driven ones first, highest index first: each leaves its engine with its state at t, and the last
    // particle of the store (event-driven, or one removed already) takes its place.
    for (auto it = which.rbegin(); it != which.rend(); ++it) {
        if (*it < nT) {
            tdmGone.push_back(*it);
            continue;
        }
        edm_->remove(*it, t);
        outflow_ += particleEnergy(*it);
        dropAt(*it);
    }
    if (!tdmGone.empty()) {
        // Time-driven ones (tdmGone descending): each exchanges places with the last TDM particle, the TDM range
        // shrinks, and the engine follows (remap). What they take is the change of the TDM's energy, their
        // contacts' elastic energy included.
        const double before = tdmEnergy();
        std::vector<std::uint32_t> from(nT);
        for (std::size_t k = 0; k < nT; ++k) from[k] = static_cast<std::uint32_t>(k);
        const std::size_t nT0 = nT;
        for (const std::uint32_t i : tdmGone) {
            const auto last = static_cast<std::uint32_t>(nT - 1);
            swapAt(i, last);
            from[i] = from[last];
            from.pop_back();
            --nT;
        }
        p.nTdm = nT;
        // [nT, nT0) now holds the removed ones, owned by neither engine.
        for (std::size_t i = nT0; i-- > nT;) dropAt(static_cast<std::uint32_t>(i));
        tdm_->remap(from);
        const double left = before - tdmEnergy();
        tdmOut_ += left;
        outflow_ += left;
    }
    // Watched indices follow their particles; the removed ones leave the list.
    if (!watch_.empty()) {
        std::unordered_map<std::uint32_t, std::uint32_t> now;  // original index -> current one
        for (const auto& [cur, orig] : origin) now[orig] = cur;
        std::vector<std::uint32_t> kept;
        for (const std::uint32_t i : watch_) {
            if (gone.count(i)) continue;
            const auto f = now.find(i);
            kept.push_back(f != now.end() ? f->second : i);
        }
        watch_.swap(kept);
        watchSorted_ = 0;
    }
    ++binsEpoch_;
}

template <int D>
void HaetEngine<D>::addParticles(std::size_t first) {
    Particles<D>& p = w_.particles;
    const std::size_t n = p.size();
    if (first >= n) return;
    const double t = w_.time;
    for (std::size_t i = first; i < n; ++i)
        if (p.radius[i] > rmax_ * (1 + 1e-12))
            throw std::logic_error("hybrid: a particle larger than HaetSettings::radiusBound was added");
    quiet_.resize(n, Quiet{});
    edm_->grow(n);
    // Every newborn joins the event-driven engine; those in a time-driven zone go on to the TDM at once, as an
    // arrival does (convert), so the TDM's books see them arrive.
    std::vector<std::uint32_t> arrivals;
    for (std::size_t i = first; i < n; ++i) {
        edm_->add(i, t);
        inflow_ += particleEnergy(i);
        const auto idx = static_cast<std::uint32_t>(i);
        if (zones_.timeDriven(zones_.zoneOf(p.x[i])))
            arrivals.push_back(idx);
        else if (guard_[book_.cellOf(idx)] != 0)
            watch_.push_back(idx);  // born near a TDM particle: watched as one that entered a guarded cell
    }
    if (!arrivals.empty()) convert(std::move(arrivals), {});
}

template void HaetEngine<2>::removeParticles(const std::vector<std::uint32_t>&);
template void HaetEngine<3>::removeParticles(const std::vector<std::uint32_t>&);
template void HaetEngine<2>::addParticles(std::size_t);
template void HaetEngine<3>::addParticles(std::size_t);

}  // namespace haet
