#include "neighbor/pair_list.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "neighbor/cell_grid.hpp"

namespace haet {
namespace {

/// The pair list's grid: over the box on periodic axes and over the particles [0, tdmCount()) on open ones (a
/// hybrid run's time-driven particles may fill a small part of a tall box), cells no narrower than cellSize.
template <int D>
CellGrid<D> pairGrid(const Domain<D>& dom, double cellSize, const Particles<D>& p) {
    Vec<D> lo = dom.lo, hi = dom.hi;
    const std::size_t np = p.tdmCount();
    for (int k = 0; k < D; ++k) {
        if (dom.periodic[k] || np == 0) continue;
        double a = p.x[0][k], b = a;
        for (std::size_t i = 1; i < np; ++i) {
            a = std::min(a, p.x[i][k]);
            b = std::max(b, p.x[i][k]);
        }
        // Within the box: particles beyond it (an open axis) fall into the outer cells, as before.
        lo[k] = std::clamp(a, dom.lo[k], dom.hi[k]);
        hi[k] = std::max(std::clamp(b, dom.lo[k], dom.hi[k]), lo[k] + cellSize);
    }
    // At most max(2^20, 8 N) cells: a huge box with few particles gets larger cells, not more than an int counts.
    const double maxCells = std::max(1048576.0, 8.0 * static_cast<double>(np));
    return CellGrid<D>::spanning(lo, hi, CellGrid<D>::cappedEdge(lo, hi, cellSize, maxCells), dom.periodic);
}

/// The neighbour cells of a cell, each with the image-shift code of its particles, computed for one cell at a
/// time and kept until asked for another (particles come mostly cell by cell, so each cell's are computed about
/// once; a table for the whole grid would hold 27 entries per occupied cell, megabytes at the rebuild's peak).
/// When every periodic axis has at least 3 cells (each no narrower than the cutoff), a neighbour cell reached
/// across a periodic face holds only images shifted by one box length, and the code is exact. Otherwise offsets
/// fold onto the same cell (CellGrid::distinctNeighbours de-duplicates them) and the code is kAnyShift: the pair
/// test finds the minimum image itself. One per thread.
template <int D>
struct CellNeighbours {
    static constexpr std::uint8_t kAnyShift = 0xFF;
    struct Entry {
        int cell;
        std::uint8_t code;
    };
    const CellGrid<D>* g;
    bool exact;
    int cell = -1;  ///< the cell whose neighbours list holds
    int count = 0;
    Entry list[27];

    explicit CellNeighbours(const CellGrid<D>& grid) : g(&grid), exact(grid.imagesExact()) {}

    /// Makes list[0, count) the neighbours of cell c.
    void of(int c) {
        if (c == cell) return;
        cell = c;
        const std::array<int, D> cc = g->coords(c);
        int nc = 0;
        if (!exact) {
            int cells[27];
            const int nd = g->distinctNeighbours(cc, cells);
            for (int q = 0; q < nd; ++q) list[nc++] = {cells[q], kAnyShift};
        } else {
            // d = x_i - x_j + shift L with x_j seen at x_j + image L: the shift is -image, its code the mirror.
            g->forEachNeighbour(cc, [&](int idx, int image) {
                list[nc++] = {idx, static_cast<std::uint8_t>(CellGrid<D>::mirror(image))};
            });
        }
        count = nc;
    }
};

/// The distinct neighbour cells of the cell of x, for remapPairList's grid path (rare). Out of line: inlined, the
/// walk made the compiler spend more instructions on remapPairList's loops over partners.
template <int D>
[[gnu::noinline]] int neighbourCells(const CellGrid<D>& g, const Vec<D>& x, int* cells) {
    return g.distinctNeighbours(g.coordsOf(x), cells);
}

/// Particles sorted by cell: cellStart (size total+1) and the particle indices in cell order.
template <int D>
void sortIntoCells(const Particles<D>& p, const CellGrid<D>& g, std::vector<std::uint32_t>& cellStart,
                   std::vector<std::uint32_t>& members, std::vector<int>& cellOf) {
    const std::size_t n = p.tdmCount();
    cellOf.resize(n);
    cellStart.assign(g.count() + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
        cellOf[i] = g.cellOf(p.x[i]);
        ++cellStart[cellOf[i] + 1];
    }
    for (int c = 0, nc = g.count(); c < nc; ++c) cellStart[c + 1] += cellStart[c];
    members.resize(n);
    std::vector<std::uint32_t> fill(cellStart.begin(), cellStart.end() - 1);
    for (std::size_t i = 0; i < n; ++i) members[fill[cellOf[i]]++] = static_cast<std::uint32_t>(i);
}

template <int D>
std::vector<Vec<D>> makeShiftVectors(const Domain<D>& dom) {
    constexpr int m = CellGrid<D>::kStencil;
    std::vector<Vec<D>> sv(m);
    for (int code = 0; code < m; ++code) {
        const std::array<int, D> s = CellGrid<D>::offsetsOf(code);
        for (int k = 0; k < D; ++k) sv[code][k] = s[k] * (dom.hi[k] - dom.lo[k]);
    }
    return sv;
}

/// Tests pair (i, j); on success appends it with its minimum-image shift code.
template <int D>
inline bool testPair(const Particles<D>& p, const Domain<D>& dom, const NeighborSettings& s, std::uint32_t i,
                     std::uint32_t j, std::uint8_t& code, double extra = 0) {
    if (s.excludeFrozenPairs && (p.flags[i] & p.flags[j] & kUnpaired)) return false;
    // Domain::minimumImage, keeping the number of box lengths added for the shift code.
    Vec<D> d = p.x[i] - p.x[j];
    int cd = 0, mul = 1;
    for (int k = 0; k < D; ++k) {
        int sk = 0;
        if (dom.periodic[k]) {
            const double L = dom.hi[k] - dom.lo[k];
            sk = -static_cast<int>(std::nearbyint(d[k] / L));
            sk = std::clamp(sk, -1, 1);
            d[k] += sk * L;
        }
        cd += (sk + 1) * mul;
        mul *= 3;
    }
    const double cut = p.radius[i] + p.radius[j] + s.skin + extra;
    if (norm2(d) >= cut * cut) return false;
    code = static_cast<std::uint8_t>(cd);
    return true;
}

/// Lists for each particle i the pairs that candidates(i, add) reports (add(j, code) for each partner j > i and
/// its image-shift code) into out's first/partner/shift, each particle's sorted by j. Threads take contiguous
/// particle ranges into partner and shift arrays of their own (5 bytes a pair), which one thread hands over
/// as they are and several copy into place in order: no per-particle vectors.
template <int D, class Candidates>
void collectPairs(std::size_t n, const Candidates& candidates, PairList<D>& out) {
    out.first.assign(n + 1, 0);
    struct Part {
        std::vector<std::uint32_t> partner;
        std::vector<std::uint8_t> shift;
    };
    std::vector<Part> parts(static_cast<std::size_t>(omp_get_max_threads()));
    std::size_t used = 1;
#pragma omp parallel if (n >= kParallelMin)
    {
        const std::size_t nt = static_cast<std::size_t>(omp_get_num_threads());
        const std::size_t t = static_cast<std::size_t>(omp_get_thread_num());
        const std::size_t i0 = n * t / nt, i1 = n * (t + 1) / nt;
        Part& part = parts[t];
        std::vector<std::uint64_t> row;  // partner << 8 | code: sorting sorts by partner
        for (std::size_t i = i0; i < i1; ++i) {
            row.clear();
            candidates(i, [&](std::uint32_t j, std::uint8_t code) { row.push_back(std::uint64_t{j} << 8 | code); });
            std::sort(row.begin(), row.end());
            for (const std::uint64_t c : row) {
                part.partner.push_back(static_cast<std::uint32_t>(c >> 8));
                part.shift.push_back(static_cast<std::uint8_t>(c & 0xFF));
            }
            out.first[i + 1] = static_cast<std::uint32_t>(row.size());
        }
#pragma omp single
        used = nt;
    }
    for (std::size_t i = 0; i < n; ++i) out.first[i + 1] += out.first[i];
    if (used == 1) {
        out.partner.swap(parts[0].partner);
        out.shift.swap(parts[0].shift);
        if (out.partner.capacity() > out.partner.size() + out.partner.size() / 4) {  // growth slack
            out.partner.shrink_to_fit();
            out.shift.shrink_to_fit();
        }
        return;
    }
    out.partner.resize(out.first[n]);
    out.shift.resize(out.first[n]);
    std::size_t o = 0;
    for (std::size_t t = 0; t < used; ++t) {
        std::copy(parts[t].partner.begin(), parts[t].partner.end(),
                  out.partner.begin() + static_cast<std::ptrdiff_t>(o));
        std::copy(parts[t].shift.begin(), parts[t].shift.end(), out.shift.begin() + static_cast<std::ptrdiff_t>(o));
        o += parts[t].partner.size();
        parts[t] = Part{};
    }
}

/// Carries history from old (same particle numbering) into out; the thread split and owners are left to be made.
template <int D>
void finishList(std::size_t n, const PairList<D>& old, PairList<D>& out) {
    const std::size_t np = out.first[n];
    out.history.assign(np, Vec<D>::zero());
    const bool carry = old.first.size() == n + 1 && !old.history.empty();
    if (carry) {
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
        for (std::size_t i = 0; i < n; ++i) {  // merge two j-sorted lists
            std::uint32_t a = old.first[i], ae = old.first[i + 1], b = out.first[i], be = out.first[i + 1];
            while (a < ae && b < be) {
                if (old.partner[a] < out.partner[b])
                    ++a;
                else if (old.partner[a] > out.partner[b])
                    ++b;
                else
                    out.history[b++] = old.history[a++];
            }
        }
    }
    out.dropDerived();
}

}  // namespace

template <int D>
void wrapPositions(Particles<D>& p, const Domain<D>& dom) {
    for (int k = 0; k < D; ++k) {
        if (!dom.periodic[k]) continue;
        const double L = dom.hi[k] - dom.lo[k];
        for (std::size_t i = 0; i < p.tdmCount(); ++i) {
            double& x = p.x[i][k];
            if (x >= dom.lo[k] && x < dom.hi[k]) continue;
            const double s = std::floor((x - dom.lo[k]) / L);
            x -= s * L;
            if (x >= dom.hi[k]) x -= L;  // round-off at the upper edge
            if (x < dom.lo[k]) x = dom.lo[k];
            p.image[i][k] += static_cast<std::int32_t>(s);
        }
    }
}

template <int D>
void buildPairList(const Particles<D>& p, const Domain<D>& dom, const NeighborSettings& s, const PairList<D>& old,
                   PairList<D>& out) {
    const std::size_t n = p.tdmCount();
    if (n == 0) {  // no particles (a hybrid run whose particles are all event-driven): no grid either
        out.shiftVec = makeShiftVectors(dom);
        out.first.assign(1, 0);
        out.partner.clear();
        out.shift.clear();
        finishList(0, old, out);
        return;
    }
    double rmax = 0;
    for (std::size_t i = 0; i < n; ++i) rmax = std::max(rmax, p.radius[i]);
    const CellGrid<D> g = pairGrid(dom, std::max(2 * rmax + s.skin, 1e-300), p);
    std::vector<std::uint32_t> cellStart, members;
    std::vector<int> cellOf;
    sortIntoCells(p, g, cellStart, members, cellOf);
    out.shiftVec = makeShiftVectors(dom);

    std::vector<CellNeighbours<D>> nbs(static_cast<std::size_t>(omp_get_max_threads()), CellNeighbours<D>(g));
    // A cell's members are in increasing index order: the partners j > i of each cell start after i.
    auto candidates = [&](std::size_t i, auto&& add) {
        CellNeighbours<D>& nb = nbs[static_cast<std::size_t>(omp_get_thread_num())];
        nb.of(cellOf[i]);
        const auto* cells = nb.list;
        const std::uint32_t* m = members.data();
        const std::uint8_t unpaired = s.excludeFrozenPairs ? p.flags[i] & kUnpaired : 0;
        for (int q = 0, nc = nb.count; q < nc; ++q) {
            const std::uint32_t* end = m + cellStart[cells[q].cell + 1];
            const std::uint32_t* a = std::upper_bound(m + cellStart[cells[q].cell], end, static_cast<std::uint32_t>(i));
            const std::uint8_t code = cells[q].code;
            if (code == CellNeighbours<D>::kAnyShift) {
                for (; a != end; ++a) {
                    std::uint8_t found;
                    if (testPair(p, dom, s, static_cast<std::uint32_t>(i), *a, found)) add(*a, found);
                }
                continue;
            }
            const Vec<D> xi = p.x[i] + out.shiftVec[code];
            for (; a != end; ++a) {
                const std::uint32_t j = *a;
                if (unpaired & p.flags[j]) continue;
                const double cut = p.radius[i] + p.radius[j] + s.skin;
                if (norm2(xi - p.x[j]) < cut * cut) add(j, code);
            }
        }
    };
    collectPairs(n, candidates, out);
    finishList(n, old, out);
}

template <int D>
void keepTouchingPairs(PairList<D>& list) {
    const std::size_t n = list.first.empty() ? 0 : list.first.size() - 1;
    std::uint32_t o = 0, k = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t end = list.first[i + 1];
        list.first[i] = o;
        for (; k < end; ++k) {
            if (list.history.empty() || norm2(list.history[k]) == 0) continue;
            list.partner[o] = list.partner[k];
            list.shift[o] = list.shift[k];
            list.history[o] = list.history[k];
            ++o;
        }
    }
    if (n > 0) list.first[n] = o;
    // New arrays of the kept size: resize alone would keep the capacity.
    list.partner = std::vector<std::uint32_t>(list.partner.begin(), list.partner.begin() + o);
    list.shift = std::vector<std::uint8_t>(list.shift.begin(), list.shift.begin() + o);
    list.history = list.history.empty() ? std::vector<Vec<D>>{}
                                        : std::vector<Vec<D>>(list.history.begin(), list.history.begin() + o);
    list.dropDerived();
}

template <int D>
void buildThreadSplit(PairList<D>& list, int ranges) {
    ThreadSplit& s = list.split;
    const std::size_t n = list.first.size() - 1;
    const std::size_t nr = static_cast<std::size_t>(std::max(ranges, 1));
    // Work of particles [0, i): its pair slots, and per particle about as much again as two slots (the
    // particle's own loads, its finishing and its integrator step).
    auto work = [&](std::size_t i) { return std::uint64_t{list.first[i]} + 2 * std::uint64_t{i}; };
    s.start.assign(nr + 1, static_cast<std::uint32_t>(n));
    s.start[0] = 0;
    for (std::size_t r = 1; r < nr; ++r) {
        const std::uint64_t goal = work(n) * r / nr;
        std::size_t lo = s.start[r - 1], hi = n;  // first i with work(i) >= goal
        while (lo < hi) {
            const std::size_t mid = (lo + hi) / 2;
            if (work(mid) < goal)
                lo = mid + 1;
            else
                hi = mid;
        }
        s.start[r] = static_cast<std::uint32_t>(lo);
    }
    s.crossSlot.clear();
    s.crossOwner.clear();
    s.crossIn.clear();
    s.crossFirst.assign(nr + 1, 0);
    for (std::size_t r = 0; r < nr; ++r) {
        s.crossFirst[r] = static_cast<std::uint32_t>(s.crossSlot.size());
        for (std::uint32_t i = s.start[r]; i < s.start[r + 1]; ++i)
            for (std::uint32_t k = list.first[i]; k < list.first[i + 1]; ++k) {
                if (list.partner[k] < s.start[r + 1]) continue;
                s.crossIn.push_back(std::uint64_t{list.partner[k]} << 32 | s.crossSlot.size());
                s.crossSlot.push_back(k);
                s.crossOwner.push_back(i);
            }
    }
    s.crossFirst[nr] = static_cast<std::uint32_t>(s.crossSlot.size());
    std::sort(s.crossIn.begin(), s.crossIn.end());
    s.crossInFirst.assign(nr + 1, 0);
    for (std::size_t r = 0; r <= nr; ++r)
        s.crossInFirst[r] = static_cast<std::uint32_t>(
            std::lower_bound(s.crossIn.begin(), s.crossIn.end(), std::uint64_t{s.start[r]} << 32) - s.crossIn.begin());
    s.crossInFirst[nr] = static_cast<std::uint32_t>(s.crossIn.size());
}

template <int D>
void buildAllPairs(const Particles<D>& p, const Domain<D>& dom, const NeighborSettings& s, PairList<D>& out) {
    const std::size_t n = p.tdmCount();
    out.shiftVec = makeShiftVectors(dom);
    auto candidates = [&](std::size_t i, auto&& add) {
        for (std::size_t j = i + 1; j < n; ++j) {
            std::uint8_t code;
            if (testPair(p, dom, s, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), code))
                add(static_cast<std::uint32_t>(j), code);
        }
    };
    collectPairs(n, candidates, out);
    finishList(n, PairList<D>{}, out);
}

template <int D>
std::vector<std::uint32_t> spatialOrder(const Particles<D>& p, const Domain<D>& dom, double cellSize) {
    if (p.tdmCount() == 0) return {};
    const CellGrid<D> g = pairGrid(dom, cellSize, p);
    std::vector<std::uint32_t> cellStart, members;
    std::vector<int> cellOf;
    sortIntoCells(p, g, cellStart, members, cellOf);
    return members;
}

template <int D>
void remapPairList(const Particles<D>& p, const Domain<D>& dom, const NeighborSettings& s,
                   const std::vector<std::uint32_t>& from, PairList<D>& list, const Vec<D>* ref) {
    constexpr std::uint32_t kNone = 0xFFFFFFFFu;
    const std::size_t n = from.size();
    const std::size_t nOld = list.first.empty() ? 0 : list.first.size() - 1;
    std::vector<std::uint32_t> inv(nOld, kNone);
    std::vector<std::uint8_t> fresh(n, 0);
    std::vector<std::uint32_t> freshList;
    // Only particles added after the kept ones, which keep their numbers (a hybrid step with arrivals only): the
    // kept rows stay as they are and the new pairs go to their ends.
    bool appended = true;
    for (std::size_t k = 0; k < n; ++k) {
        if (from[k] < nOld) {
            inv[from[k]] = static_cast<std::uint32_t>(k);
            appended = appended && from[k] == k;
        } else {
            fresh[k] = 1;
            freshList.push_back(static_cast<std::uint32_t>(k));
        }
    }
    appended = appended && n - freshList.size() == nOld;  // then the kept ones are [0, nOld), the new ones the rest
    struct Entry {
        std::uint32_t a, b;
        std::uint8_t code;
        Vec<D> h;
    };
    std::vector<Entry> entries;
    if (!appended) {
        entries.reserve(list.partner.size() + 8 * freshList.size());
        for (std::size_t i = 0; i < nOld; ++i) {
            const std::uint32_t a = inv[i];
            if (a == kNone) continue;
            for (std::uint32_t k = list.first[i]; k < list.first[i + 1]; ++k) {
                const std::uint32_t b = inv[list.partner[k]];
                if (b == kNone) continue;
                const Vec<D> h = list.history.empty() ? Vec<D>::zero() : list.history[k];
                if (a < b)
                    entries.push_back({a, b, list.shift[k], h});
                else  // the shift of (j, i) is minus that of (i, j): the mirror code
                    entries.push_back({b, a, static_cast<std::uint8_t>(CellGrid<D>::mirror(list.shift[k])), -h});
            }
        }
    }
    // A kept particle j may have drifted by d_j from where its pairs were last searched, and may drift back the
    // other way by skin/2 before the next build: a new particle is paired with it within skin + d_j, so that no
    // pair left out can touch while every particle stays within skin/2 of its reference.
    auto drift = [&](std::uint32_t j) { return ref && !fresh[j] ? norm(p.x[j] - ref[j]) : 0.0; };
    // The largest reach of a new particle: two largest radii, the skin and the largest drift.
    double rmax = 0, dmax = 0;
    if (!freshList.empty())
        for (std::uint32_t i = 0; i < n; ++i) {
            rmax = std::max(rmax, p.radius[i]);
            if (ref) dmax = std::max(dmax, drift(i));
        }
    const double reach = 2 * rmax + s.skin + dmax;
    // Pair (f, j) of new particle f, once per pair of two new ones. On open axes a partner beyond the reach along
    // the axis is skipped before the full test.
    auto consider = [&](std::uint32_t f, std::uint32_t j) {
        if (j == f || (fresh[j] && j < f)) return;
        for (int k = 0; k < D; ++k)
            if (!dom.periodic[k] && std::abs(p.x[f][k] - p.x[j][k]) >= reach) return;
        const std::uint32_t lo = std::min(f, j), hi = std::max(f, j);
        std::uint8_t code;
        if (testPair(p, dom, s, lo, hi, code, drift(j))) entries.push_back({lo, hi, code, Vec<D>::zero()});
    };
    // A few new particles are tested against all (a grid costs O(cells), and a tall box has many); many use a grid.
    if (!freshList.empty() && freshList.size() * 64 <= n) {
        for (const std::uint32_t f : freshList)
            for (std::uint32_t j = 0; j < n; ++j) consider(f, j);
    } else if (!freshList.empty()) {
        const CellGrid<D> g = pairGrid(dom, std::max(reach, 1e-300), p);
        std::vector<std::uint32_t> cellStart, members;
        std::vector<int> cellOf;
        sortIntoCells(p, g, cellStart, members, cellOf);
        for (const std::uint32_t f : freshList) {
            int cells[27];
            const int nc = neighbourCells(g, p.x[f], cells);
            for (int q = 0; q < nc; ++q)
                for (std::uint32_t a = cellStart[cells[q]]; a < cellStart[cells[q] + 1]; ++a) consider(f, members[a]);
        }
    }
    list.shiftVec = makeShiftVectors(dom);
    list.dropDerived();
    if (appended) {
        // Every new pair has a new particle as its second: it comes after the kept partners of its row.
        std::sort(entries.begin(), entries.end(),
                  [](const Entry& x, const Entry& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
        const std::size_t np = list.partner.size() + entries.size();
        std::vector<std::uint32_t> first(n + 1), partner(np);
        std::vector<std::uint8_t> shift(np);
        std::vector<Vec<D>> history(np, Vec<D>::zero());
        std::size_t o = 0, e = 0;
        for (std::size_t i = 0; i < n; ++i) {
            first[i] = static_cast<std::uint32_t>(o);
            if (i < nOld)
                for (std::uint32_t k = list.first[i]; k < list.first[i + 1]; ++k, ++o) {
                    partner[o] = list.partner[k];
                    shift[o] = list.shift[k];
                    if (!list.history.empty()) history[o] = list.history[k];
                }
            for (; e < entries.size() && entries[e].a == i; ++e, ++o) {
                partner[o] = entries[e].b;
                shift[o] = entries[e].code;
            }
        }
        first[n] = static_cast<std::uint32_t>(o);
        list.first.swap(first);
        list.partner.swap(partner);
        list.shift.swap(shift);
        list.history.swap(history);
        return;
    }
    // Counting sort by the first index, then each (short) row by the partner.
    list.first.assign(n + 1, 0);
    for (const Entry& e : entries) ++list.first[e.a + 1];
    for (std::size_t i = 0; i < n; ++i) list.first[i + 1] += list.first[i];
    std::vector<std::uint32_t> fill(list.first.begin(), list.first.end() - 1);
    const std::size_t np = entries.size();
    list.partner.resize(np);
    list.shift.resize(np);
    list.history.resize(np);
    for (const Entry& e : entries) {
        const std::uint32_t o = fill[e.a]++;
        list.partner[o] = e.b;
        list.shift[o] = e.code;
        list.history[o] = e.h;
    }
    for (std::size_t i = 0; i < n; ++i)
        for (std::uint32_t k = list.first[i] + 1; k < list.first[i + 1]; ++k)
            for (std::uint32_t q = k; q > list.first[i] && list.partner[q - 1] > list.partner[q]; --q) {
                std::swap(list.partner[q - 1], list.partner[q]);
                std::swap(list.shift[q - 1], list.shift[q]);
                std::swap(list.history[q - 1], list.history[q]);
            }
}

template <int D>
void permutePairList(PairList<D>& list, const std::vector<std::uint32_t>& order) {
    const std::size_t n = order.size();
    const std::size_t nOld = list.first.empty() ? 0 : list.first.size() - 1;
    constexpr std::uint32_t kNone = 0xFFFFFFFFu;
    std::vector<std::uint32_t> inv(nOld, kNone);
    for (std::size_t k = 0; k < n; ++k)
        if (order[k] < nOld) inv[order[k]] = static_cast<std::uint32_t>(k);
    struct Entry {
        std::uint32_t i, j;
        Vec<D> h;
    };
    std::vector<Entry> kept;
    if (!list.history.empty()) {
        std::size_t touching = 0;
        for (const Vec<D>& h : list.history) touching += norm2(h) != 0;
        kept.reserve(touching);
        for (std::size_t i = 0; i < nOld; ++i)
            for (std::uint32_t k = list.first[i]; k < list.first[i + 1]; ++k) {
                if (norm2(list.history[k]) == 0) continue;
                std::uint32_t a = inv[i], b = list.partner[k] < nOld ? inv[list.partner[k]] : kNone;
                if (a == kNone || b == kNone) continue;  // a particle that left: its contacts end
                Vec<D> h = list.history[k];
                if (a > b) {
                    std::swap(a, b);
                    h = -h;
                }  // xi of (j, i) is -xi of (i, j)
                kept.push_back({a, b, h});
            }
    }
    std::sort(kept.begin(), kept.end(),
              [](const Entry& x, const Entry& y) { return x.i != y.i ? x.i < y.i : x.j < y.j; });
    list.first.assign(n + 1, 0);
    for (const auto& e : kept) ++list.first[e.i + 1];
    for (std::size_t i = 0; i < n; ++i) list.first[i + 1] += list.first[i];
    list.partner = std::vector<std::uint32_t>(kept.size());  // new arrays: resize alone would keep the capacity
    list.history = std::vector<Vec<D>>(kept.size());
    list.shift = std::vector<std::uint8_t>(kept.size(), PairList<D>::kNoShift);
    for (std::size_t k = 0; k < kept.size(); ++k) {
        list.partner[k] = kept[k].j;
        list.history[k] = kept[k].h;
    }
    list.dropDerived();
}

#define HAET_INSTANTIATE(D)                                                                                            \
    template void buildPairList<D>(const Particles<D>&, const Domain<D>&, const NeighborSettings&, const PairList<D>&, \
                                   PairList<D>&);                                                                      \
    template void buildAllPairs<D>(const Particles<D>&, const Domain<D>&, const NeighborSettings&, PairList<D>&);      \
    template void buildThreadSplit<D>(PairList<D>&, int);                                                              \
    template void keepTouchingPairs<D>(PairList<D>&);                                                                  \
    template void wrapPositions<D>(Particles<D>&, const Domain<D>&);                                                   \
    template std::vector<std::uint32_t> spatialOrder<D>(const Particles<D>&, const Domain<D>&, double);                \
    template void permutePairList<D>(PairList<D>&, const std::vector<std::uint32_t>&);                                 \
    template void remapPairList<D>(const Particles<D>&, const Domain<D>&, const NeighborSettings&,                     \
                                   const std::vector<std::uint32_t>&, PairList<D>&, const Vec<D>*);
HAET_INSTANTIATE(2)
HAET_INSTANTIATE(3)
#undef HAET_INSTANTIATE

}  // namespace haet
