#pragma once
// Neighbour shells of the event-driven engine (Donev, Torquato & Stillinger 2005; Smallenburg 2022; docs/edm.md),
// the broad phase that replaces cell crossings in dense states. Its interface to the event loop is that of the
// event grid (edm/event_grid.hpp): where, exit, forEachBatch; the grid then holds the shells' centres.
//
// Each particle has a centre (its box-frame position when its list was made) and stays within the cube of half-edge
// h around it: leaving the cube is an event (the same per-axis exit times as a cell crossing, so gravity costs
// nothing extra). Two particles can touch before either leaves its cube only if the cubes, widened by the sum of
// the radii, meet: per axis the gap max(0, |c_i - c_j| - 2h), and the sum of the squared gaps at most the squared
// sum of the radii. The lists hold exactly these pairs, in both particles' lists; a particle that leaves its cube
// takes itself out of its neighbours' lists, takes a new centre and a new list from the grid of centres, and puts
// itself into its new neighbours' lists. A collision is found by whichever of the two predicts after the pair
// became listed: its prediction sees the other, as in the cell scheme.
#include <cstdint>
#include <vector>

#include "edm/event_grid.hpp"
#include "edm/scan.hpp"
#include "edm/slots.hpp"
#include "io/checkpoint.hpp"

namespace haet::edm {

template <int D>
class Shells {
public:
    using Sl = Slots<D>;
    using Shift = typename Sl::Shift;
    // A list entry: a slot with the periodic image of the neighbour's centre (2 bits per axis, image + 1).
    static constexpr std::uint32_t kImageShift = 26, kSlotMask = (1u << kImageShift) - 1;

    /// Shells of half-edge `half` [m] (0: off).
    void configure(double half, bool periodic) {
        half_ = half;
        periodic_ = periodic;
    }
    bool on() const { return half_ > 0; }
    double half() const { return half_; }
    /// n slots, no lists yet.
    void clear(std::size_t n) {
        centre_.assign(n, Centre{Vec<D>::zero(), 0.0});
        nbr_.clear();
        rowLen_ = 0;
    }
    void setCentre(std::uint32_t s, const Vec<D>& c, double r) { centre_[s] = Centre{c, r}; }

    /// Slots renumbered: slot k is old slot order[k], old slot s is newSlot[s] now.
    void permute(const std::vector<std::uint32_t>& order, const std::vector<std::uint32_t>& newSlot);
    /// Every list from the centres in the grid.
    void buildLists(const Sl& sl, const EventGrid<D>& grid);
    /// Puts s into the lists of the particles whose shells its shell meets, and them into its list; false: a list
    /// is full (the caller rebuilds every list, longer).
    bool link(const Sl& sl, const EventGrid<D>& grid, std::uint32_t s);
    /// Takes s out of its neighbours' lists and empties its own.
    void unlink(std::uint32_t s);
    /// Slot s leaves its shell at time now: a new centre and a new list. Returns whether every list was rebuilt
    /// (a list was full).
    bool move(Sl& sl, EventGrid<D>& grid, std::uint32_t s, double now);
    /// Calls f(slot) for every slot in s's list.
    template <class F>
    void forEachListed(std::uint32_t s, F&& f) const {
        const std::uint32_t* a = row(s);
        for (std::uint32_t q = 1; q <= a[0]; ++q) f(a[q] & kSlotMask);
    }
    /// The centres and the lists as they are (a checkpoint: rebuilt, the lists would hold the same pairs in another
    /// order, and another row length would change when a list is full).
    void save(ByteWriter& out) const;
    /// Takes saved centres and lists for n slots; throws CheckpointError (Corrupt) when they do not fit.
    void load(ByteReader& in, std::size_t n);
    std::size_t memoryBytes() const {
        return centre_.capacity() * sizeof(Centre) + nbr_.capacity() * sizeof(std::uint32_t);
    }

    // ---- the broad phase ----
    struct Where {};
    /// The list's partners prefetched.
    Where where(const Sl& sl, std::uint32_t s) const {
        const std::uint32_t* a = row(s);
        const std::uint32_t count = a[0];
        for (std::uint32_t q = 1; q <= count; ++q) {
            __builtin_prefetch(&sl.hot[a[q] & kSlotMask]);
            if (periodic_) __builtin_prefetch(&sl.link[a[q] & kSlotMask]);
        }
        return {};
    }
    /// The next exit of s from its cube, from its box-frame state now (x, v).
    Candidate exit(const Sl& sl, const Where&, std::uint32_t s, const Shift& ws, double now, const Vec<D>& x,
                   const Vec<D>& v) const {
        const Vec<D>& c = centre_[s].c;
        Candidate cross;
        for (int k = 0; k < D; ++k) {
            const CellExit ex = cellExitTime(x[k] - ws[k] * sl.boxLen[k], v[k], sl.g[k], c[k] - half_, c[k] + half_);
            const double t = now + ex.time;
            const std::uint32_t code = (kCell << kTypeShift) | static_cast<std::uint32_t>(2 * k + (ex.up ? 1 : 0));
            if (cross.better(t, code)) cross = {t, code, 0};
        }
        return cross;
    }
    /// Calls four(batch, plain wraps, plain base) for the partners of s's list, four at a time, the last batch
    /// padded with repeats of its first; the image of a list entry is a base per entry. A list holds every partner
    /// that can reach s before it leaves its cube, so there are no partial scans (axis, dir unused).
    template <class F>
    [[gnu::always_inline]] inline void forEachBatch(const Sl& sl, const Where&, std::uint32_t s, const Shift& ws,
                                                    int /*axis*/, int /*dir*/, F&& four) const {
        const std::uint32_t* a = row(s);
        const std::uint32_t count = a[0];
        const std::uint32_t zeroWraps = Sl::packWraps(Shift{});
        const Shift none{};
        std::uint32_t cand[4], wrap[4] = {zeroWraps, zeroWraps, zeroWraps, zeroWraps};
        Shift bases[4];
        const Shift* base[4];
        int nb = 0;
        for (std::uint32_t q = 1; q <= count; ++q) {
            const std::uint32_t j = a[q] & kSlotMask;
            cand[nb] = j;
            base[nb] = &none;
            if (periodic_) {
                const std::uint32_t image = a[q] >> kImageShift;
                const Shift wj = Sl::wrapsOf(sl.link[j].wrap);
                bool zero = true;
                for (int k = 0; k < D; ++k) {
                    bases[nb][k] = wj[k] - ws[k] - (static_cast<std::int32_t>((image >> (2 * k)) & 3u) - 1);
                    zero = zero && bases[nb][k] == 0;
                }
                if (!zero) base[nb] = &bases[nb];
            }
            if (++nb == 4) {
                four(Batch<D>{cand, wrap, base}, zeroWraps, &none);
                nb = 0;
            }
        }
        if (nb > 0) {
            for (int l = nb; l < 4; ++l) {
                cand[l] = cand[0];
                base[l] = base[0];
            }
            four(Batch<D>{cand, wrap, base}, zeroWraps, &none);
        }
    }

private:
    struct alignas(32) Centre {
        Vec<D> c;  // box-frame centre of the shell [m]
        double r;  // radius [m], a copy of Hot::r: a list rebuild reads one record per candidate
    };
    std::uint32_t* row(std::uint32_t s) { return &nbr_[static_cast<std::size_t>(s) * rowLen_]; }
    const std::uint32_t* row(std::uint32_t s) const { return &nbr_[static_cast<std::size_t>(s) * rowLen_]; }
    bool meet(const Sl& sl, std::uint32_t s, std::uint32_t j, const Shift& image) const;

    double half_ = 0;
    bool periodic_ = false;  // some axis is periodic
    // Per slot the box-frame centre of its cube (edge 2 half_) and a row of rowLen_ words in nbr_: the count, then
    // the neighbours. The grid holds the centres; its cells are at least a diameter plus the shell wide.
    std::vector<Centre> centre_;
    std::vector<std::uint32_t> nbr_;
    std::size_t rowLen_ = 0;
};

}  // namespace haet::edm
