#pragma once
// The event grid of the event-driven engine (docs/edm.md): cells of at least a particle diameter, each with a
// singly linked list of the slots in it, and the cell crossings that keep the lists current. Its interface to the
// event loop is that of a broad phase, shared with the neighbour shells (edm/shells.hpp):
//   where(s)                     what a prediction of slot s needs of the grid (its cell's coordinates),
//   exit(where, s, now, x, v)    s's next crossing of a cell face (an event of type kCell),
//   forEachBatch(where, s, ...)  the candidate partners of s, four at a time, for the scan (edm/scan.hpp).
// Its geometry is a CellGrid (neighbor/cell_grid.hpp), the one cell grid of the project, which the engine also hands
// to an observer (edm/observer.hpp) so that a coupled engine can keep data per cell. What the event grid adds: a cap
// on the number of cells (Rec::cell has kCellBits bits), and an axis of zero length as one cell of width 1.
#include <array>
#include <cstdint>
#include <vector>

#include "core/lanes_scan.hpp"
#include "edm/scan.hpp"
#include "edm/slots.hpp"
#include "neighbor/cell_grid.hpp"
#include "world/world.hpp"

namespace haet {

namespace edm {

template <int D>
class EventGrid {
public:
    using Sl = Slots<D>;
    using Shift = typename Sl::Shift;
    using Cells = CellGrid<D>;
    static constexpr int kNbrCells = Cells::kStencil, kSideCells = Cells::kSide;
    static_assert(Cells::kStencilPad % 8 == 0 && Cells::kSidePad % 8 == 0, "compactHeads loads eight offsets");

    /// Cells of edge >= `edge` [m] over the domain's box (CellGrid::spanning; an axis of zero length is one cell of
    /// width 1), at most maxCells of them and fewer than 2^kCellBits - 1 (the edge grows by 1.25 until they fit);
    /// every list empty.
    void build(const Domain<D>& dom, double edge, double maxCells);
    const Cells& cells() const { return cells_; }
    std::uint32_t count() const { return static_cast<std::uint32_t>(head_.size()); }
    std::uint32_t cellOf(const Vec<D>& x) const { return static_cast<std::uint32_t>(cells_.cellOf(x)); }
    double smallestEdge() const;
    /// Whether a crossing may scan only the newly adjacent cells (7 cells or more on every periodic axis, so that
    /// the kept event's partner is at its minimum image: EdmEngine::keptTime).
    bool partialScans() const { return partialScans_; }
    std::size_t memoryBytes() const { return head_.capacity() * sizeof(std::uint32_t); }

    // ---- the lists ----
    void insert(Sl& sl, std::uint32_t s, std::uint32_t c) {
        sl.rec[s].cell = c;
        sl.link[s].next = head_[c];
        head_[c] = s;
    }
    // A cell holds a few particles (about one with the default edge of one diameter), so walking its list costs
    // less than a back link per slot would: no predecessor to keep, 4 bytes per particle fewer.
    void remove(Sl& sl, std::uint32_t s) {
        std::uint32_t* at = &head_[sl.rec[s].cell];
        while (*at != s) at = &sl.link[*at].next;
        *at = sl.link[s].next;
    }
    /// Every list anew from the slots' cells, each in increasing slot order.
    void relink(Sl& sl);
    /// Calls f(slot) for every slot in cell c.
    template <class F>
    void forEachIn(const Sl& sl, std::uint32_t c, F&& f) const {
        for (std::uint32_t j = head_[c]; j != kNil; j = sl.link[j].next) f(j);
    }
    /// Calls f(cell, image) for cell c and its 3^D - 1 neighbours (CellGrid::forEachNeighbour): periodic axes wrap,
    /// open ones end; image: -1 or +1 box lengths on the axes crossed (-1 across a lower face).
    template <class F>
    void forEachCellAround(std::uint32_t c, F&& f) const {
        cells_.forEachNeighbour(static_cast<int>(c), [&](int cell, int image) {
            const std::array<int, D> o = Cells::offsetsOf(image);
            Shift sh;
            for (int k = 0; k < D; ++k) sh[k] = o[k];
            f(static_cast<std::uint32_t>(cell), static_cast<const Shift&>(sh));
        });
    }
    /// Calls f(slot, image) for every slot in the cells around c (forEachCellAround).
    template <class F>
    void forEachAround(const Sl& sl, std::uint32_t c, F&& f) const {
        forEachCellAround(c, [&](std::uint32_t cell, const Shift& image) {
            for (std::uint32_t j = head_[cell]; j != kNil; j = sl.link[j].next) f(j, image);
        });
    }

    // ---- the broad phase ----
    struct Where {
        std::array<int, D> cc;  // cell coordinates
        bool interior;          // away from the box faces on every axis
    };
    Where where(const Sl& sl, std::uint32_t s) const {
        Where at;
        at.cc = cells_.coords(static_cast<int>(sl.rec[s].cell));
        at.interior = cells_.interior(at.cc);
        return at;
    }
    /// The next crossing of a face of s's cell, from its box-frame state now (x, v). From the older stored state
    /// the quadratic could also find a crossing that already happened (through a face and back under gravity).
    Candidate exit(const Sl& sl, const Where& at, std::uint32_t /*s*/, const Shift& ws, double now, const Vec<D>& x,
                   const Vec<D>& v) const {
        Candidate cross;
        for (int k = 0; k < D; ++k) {
            const int c = at.cc[k];
            const bool per = cells_.periodic(k);
            const double lo = (c == 0 && !per) ? -kNever : cells_.origin()[k] + c * cells_.width()[k];
            const double hi =
                (c == cells_.dim(k) - 1 && !per) ? kNever : cells_.origin()[k] + (c + 1) * cells_.width()[k];
            const CellExit ex = cellExitTime(x[k] - ws[k] * sl.boxLen[k], v[k], sl.g[k], lo, hi);
            if (ex.time < kNever) {
                const double t = now + ex.time;
                const std::uint32_t code = (kCell << kTypeShift) | static_cast<std::uint32_t>(2 * k + (ex.up ? 1 : 0));
                if (cross.better(t, code)) cross = {t, code, 0};
            }
        }
        return cross;
    }
    /// Slot s crosses the face of its cell (axis, up): into the neighbour cell, a wrap more or less on a periodic
    /// axis. Returns the cell it left.
    std::uint32_t cross(Sl& sl, std::uint32_t s, int axis, bool up);

    /// Calls four(batch, plain wraps, plain base) for the candidate partners of s (all slots but s in the 3^D cells
    /// around its cell; after a crossing, axis >= 0 and dir = +-1, only the 3^(D-1) newly adjacent ones), in batches
    /// of four, the last one padded with repeats of its first candidate.
    template <class F>
    [[gnu::always_inline]] inline void forEachBatch(const Sl& sl, const Where& at, std::uint32_t s, const Shift& ws,
                                                    int axis, int dir, F&& four) const;

private:
    Cells cells_;
    std::vector<std::uint32_t> head_;
    bool partialScans_ = true;
};

template <int D>
inline std::uint32_t EventGrid<D>::cross(Sl& sl, std::uint32_t s, int axis, bool up) {
    const std::uint32_t oldCell = sl.rec[s].cell;
    const int n = cells_.dim(axis), c = cells_.coord(static_cast<int>(oldCell), axis);
    int cn = c + (up ? 1 : -1);
    if (cn >= n || cn < 0) {  // only on periodic axes: outer cells of open axes are unbounded
        cn = cn < 0 ? n - 1 : 0;
        Shift ws = Sl::wrapsOf(sl.link[s].wrap);
        ws[axis] += up ? 1 : -1;
        sl.setWraps(s, ws);
    }
    const std::uint32_t newCell = oldCell + (static_cast<std::uint32_t>(cn) - static_cast<std::uint32_t>(c)) *
                                                static_cast<std::uint32_t>(cells_.stride(axis));
    remove(sl, s);
    insert(sl, s, newCell);
    return oldCell;
}

// Neighbour cells: the heads of those that are not empty, loaded first and their first members prefetched, so that
// the cache misses overlap instead of following each other. A cell away from the box faces takes its neighbours from
// a table of index offsets; one at a face (open or periodic) goes through the per-axis lists, with the image shift of
// each cell (base: minus s's wraps, minus the box lengths crossed).
//
// The candidates are collected four at a time and evaluated side by side (candidates4): the arithmetic of
// candidateTime lane by lane. Candidates later than the best pair or wall event so far are skipped before the
// square root, but never because they are later than the cell exit: rec[s].coll must stay the earliest over all
// neighbours for the partial scans after a crossing. A batch is plain when no candidate needs an image shift (same
// wraps as s, a cell that crosses no box face): most are. The lists are walked first (only the links), in chunks of
// at most kChunk candidates (a cell of a coarse grid can hold many).
template <int D>
template <class F>
[[gnu::always_inline]] inline void EventGrid<D>::forEachBatch(const Sl& sl, const Where& at, std::uint32_t s,
                                                              const Shift& ws, int axis, int dir, F&& four) const {
    constexpr int kMaxCells = kNbrCells;
    std::uint32_t heads[kMaxCells + 8];  // compactHeads stores whole groups of eight
    Shift bases[kMaxCells];
    bool plainCell[kMaxCells];  // base = -ws: no box length crossed
    int nc = 0;
    Shift negWs;
    for (int k = 0; k < D; ++k) negWs[k] = -ws[k];
    if (at.interior) {
        const std::uint32_t* hc = &head_[sl.rec[s].cell];
        nc = axis < 0 ? compactHeads<kNbrCells>(hc, cells_.offsets(), heads)
                      : compactHeads<kSideCells>(hc, cells_.sideOffsets(axis, dir > 0), heads);
    } else {
        std::array<std::array<int, 3>, D> nbr, omega;
        std::array<int, D> nbrCount;
        bool any = true;
        for (int k = 0; k < D; ++k) {
            const bool per = cells_.periodic(k);
            const int dk = cells_.dim(k);
            int m = 0;
            for (int o = -1; o <= 1; ++o) {
                if (k == axis && o != dir) continue;
                int cn = at.cc[k] + o, om = 0;
                if (cn < 0) {
                    if (!per) continue;
                    cn += dk;
                    om = -1;
                } else if (cn >= dk) {
                    if (!per) continue;
                    cn -= dk;
                    om = 1;
                }
                nbr[k][m] = cn;
                omega[k][m] = om;
                ++m;
            }
            nbrCount[k] = m;
            any = any && m > 0;
        }
        std::array<int, D> it{};
        while (any) {
            std::uint32_t cellIndex = 0;
            bool plain = true;
            for (int k = 0; k < D; ++k) {
                cellIndex += static_cast<std::uint32_t>(nbr[k][it[k]] * cells_.stride(k));
                bases[nc][k] = -ws[k] - omega[k][it[k]];
                plain = plain && omega[k][it[k]] == 0;
            }
            const std::uint32_t h = head_[cellIndex];
            heads[nc] = h;
            plainCell[nc] = plain;
            nc += h != kNil;
            int k = 0;
            while (k < D && ++it[k] == nbrCount[k]) it[k++] = 0;
            if (k == D) break;
        }
    }
    for (int q = 0; q < nc; ++q) {
        __builtin_prefetch(&sl.hot[heads[q]]);
        __builtin_prefetch(&sl.link[heads[q]]);
    }
    constexpr int kChunk = 64;
    const std::uint32_t wsPacked = sl.link[s].wrap;
    std::uint32_t cand[kChunk + 4], wrap[kChunk + 4];
    const Shift* base[kChunk + 4];
    // Evaluates the candidates of the buffer in fours (all: also the last one to three); returns how many are left.
    auto evaluate = [&](int n, bool all) {
        int i = 0;
        for (; i + 4 <= n; i += 4) four(Batch<D>{cand + i, wrap + i, base + i}, wsPacked, &negWs);
        if (all && i < n) {
            // The last lanes repeat the first candidate: the same time and code, never better than itself.
            for (int l = n; l < i + 4; ++l) {
                cand[l] = cand[i];
                wrap[l] = wrap[i];
                base[l] = base[i];
            }
            four(Batch<D>{cand + i, wrap + i, base + i}, wsPacked, &negWs);
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
        const Shift* b = (at.interior || plainCell[q]) ? &negWs : &bases[q];
        std::uint32_t j = heads[q];
        for (;;) {
            do {
                const typename Sl::Link& lj = sl.link[j];
                if (lj.next != kNil) __builtin_prefetch(&sl.hot[lj.next]);
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
}

}  // namespace edm
}  // namespace haet
