#include "edm/shells.hpp"

#include <algorithm>
#include <cmath>

namespace haet::edm {

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

template <int D>
void Shells<D>::permute(const std::vector<std::uint32_t>& order, const std::vector<std::uint32_t>& newSlot) {
    const std::size_t n = order.size();
    std::vector<Centre> c(n);
    for (std::size_t k = 0; k < n; ++k) c[k] = centre_[order[k]];
    centre_.swap(c);
    if (nbr_.empty()) return;
    std::vector<std::uint32_t> rows(nbr_.size());
    for (std::size_t k = 0; k < n; ++k) {
        const std::uint32_t* from = row(order[k]);
        std::uint32_t* to = &rows[k * rowLen_];
        to[0] = from[0];
        for (std::uint32_t q = 1; q <= from[0]; ++q) to[q] = (from[q] & ~kSlotMask) | newSlot[from[q] & kSlotMask];
    }
    nbr_.swap(rows);
}

// Whether particles s and j (image `image` of j) can touch while each stays in its cube: the two cubes, grown by
// the radii, overlap.
template <int D>
bool Shells<D>::meet(const Sl& sl, std::uint32_t s, std::uint32_t j, const Shift& image) const {
    const double reach = 2 * half_;
    double gap2 = 0;
    for (int k = 0; k < D; ++k) {
        const double gap = std::abs(centre_[s].c[k] - centre_[j].c[k] - image[k] * sl.boxLen[k]) - reach;
        if (gap > 0) gap2 += gap * gap;
    }
    const double sigma = (centre_[s].r + centre_[j].r) * (1 + 1e-9);
    return gap2 <= sigma * sigma;
}

template <int D>
bool Shells<D>::link(const Sl& sl, const EventGrid<D>& grid, std::uint32_t s) {
    bool ok = true;
    grid.forEachCellAround(sl.rec[s].cell, [&](std::uint32_t c, const Shift& image) {
        if (!ok) return;
        grid.forEachIn(sl, c, [&](std::uint32_t j) {
            if (!ok || j == s || !meet(sl, s, j, image)) return;
            std::uint32_t* a = row(s);
            std::uint32_t* b = row(j);
            if (a[0] + 1 >= rowLen_ || b[0] + 1 >= rowLen_) {
                ok = false;
                return;
            }
            a[++a[0]] = j | (imageCode<D>(image, 1) << kImageShift);
            b[++b[0]] = s | (imageCode<D>(image, -1) << kImageShift);
        });
    });
    return ok;
}

template <int D>
void Shells<D>::unlink(std::uint32_t s) {
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

// The new centre is the box-frame position now, brought into the box on periodic axes by changing the wrap count,
// which leaves the stored state alone.
template <int D>
bool Shells<D>::move(Sl& sl, EventGrid<D>& grid, std::uint32_t s, double now) {
    unlink(s);
    const Domain<D>& dom = sl.world->domain;
    const Vec<D> x = sl.posAt(sl.hot[s], now);
    Shift ws = Sl::wrapsOf(sl.link[s].wrap);
    Vec<D> c;
    for (int k = 0; k < D; ++k) {
        c[k] = x[k] - ws[k] * sl.boxLen[k];
        const double lo = dom.lo[k], L = sl.boxLen[k];
        if (!dom.periodic[k] || (c[k] >= lo && c[k] < lo + L)) continue;
        ws[k] += static_cast<std::int32_t>(std::floor((c[k] - lo) / L));
        c[k] = x[k] - ws[k] * sl.boxLen[k];
    }
    sl.setWraps(s, ws);
    centre_[s].c = c;
    const std::uint32_t cell = grid.cellOf(c);
    if (cell != sl.rec[s].cell) {
        grid.remove(sl, s);
        grid.insert(sl, s, cell);
    }
    if (link(sl, grid, s)) return false;
    buildLists(sl, grid);
    return true;
}

// First the longest list, then rows with room to grow, then each row from its own scan (the lists are symmetric, so
// no row needs another's).
template <int D>
void Shells<D>::buildLists(const Sl& sl, const EventGrid<D>& grid) {
    const std::uint32_t n = static_cast<std::uint32_t>(sl.size());
    auto scan = [&](std::uint32_t s, auto&& take) {
        grid.forEachAround(sl, sl.rec[s].cell, [&](std::uint32_t j, const Shift& image) {
            if (j != s && meet(sl, s, j, image)) take(j, image);
        });
    };
    std::uint32_t longest = 0;
    for (std::uint32_t s = 0; s < n; ++s) {
        if (sl.rec[s].idx == kNil) continue;
        std::uint32_t count = 0;
        scan(s, [&](std::uint32_t, const Shift&) { ++count; });
        longest = std::max(longest, count);
    }
    // Room for fluctuations: a list grows when a neighbour's new shell meets the particle's.
    const std::size_t len = std::max<std::size_t>(rowLen_ + 4, longest + 5);
    rowLen_ = (len + 3) / 4 * 4;
    nbr_.assign(static_cast<std::size_t>(n) * rowLen_, 0);
    for (std::uint32_t s = 0; s < n; ++s) {
        if (sl.rec[s].idx == kNil) continue;
        std::uint32_t* a = row(s);
        scan(s, [&](std::uint32_t j, const Shift& image) { a[++a[0]] = j | (imageCode<D>(image, 1) << kImageShift); });
    }
}

template <int D>
void Shells<D>::save(ByteWriter& out) const {
    out.put<std::uint64_t>(centre_.size());
    for (const Centre& c : centre_) {  // field by field: the record is padded to 32 bytes
        out.put(c.c);
        out.put(c.r);
    }
    out.put<std::uint64_t>(rowLen_);
    out.putVector(nbr_);
}

template <int D>
void Shells<D>::load(ByteReader& in, std::size_t n) {
    if (in.get<std::uint64_t>() != n) in.fail("the neighbour shells are of another number of slots");
    if (n > in.rest().size() / sizeof(Centre)) in.fail("more shells than the bytes left hold");
    std::vector<Centre> centres(n);
    for (Centre& c : centres) {
        c.c = in.get<Vec<D>>();
        c.r = in.get<double>();
    }
    const auto len = in.get<std::uint64_t>();
    std::vector<std::uint32_t> rows;
    if (n > 0 && (len == 0 || len > in.rest().size() / (n * sizeof(std::uint32_t))))
        in.fail("the neighbour lists' rows do not fit the bytes left");
    in.getVector(rows, n * len, "the neighbour lists");
    // Every row's count within its row, every entry a slot: the scans read no further.
    for (std::size_t s = 0; s < n; ++s) {
        const std::uint32_t* a = &rows[s * len];
        if (a[0] >= len) in.fail("a neighbour list longer than its row");
        for (std::uint32_t q = 1; q <= a[0]; ++q)
            if ((a[q] & kSlotMask) >= n) in.fail("a neighbour list names a slot out of range");
    }
    centre_.swap(centres);
    rowLen_ = len;
    nbr_.swap(rows);
}

template class Shells<2>;
template class Shells<3>;

}  // namespace haet::edm
