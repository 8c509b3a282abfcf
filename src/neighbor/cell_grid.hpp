#pragma once
// One cell grid for every neighbour search of the project: a box cut into n[k] cells along each axis k, the cell
// of a point, the linear index of a cell (x fastest), the index offsets of the 3^D cells around a cell away from
// the grid's faces, and the walk over the neighbour cells of any cell with the periodic image through which each
// is reached. The grid holds geometry only; each user keeps the members of the cells in its own storage
// (cell-sorted arrays, linked lists) and decides which cells to visit (a half or a full stencil, a clipped box).
//
// Codes. The 3^D cells around cell c are numbered by an offset code q in base 3, axis 0 the lowest digit, digit k
// = o[k] + 1 for the offset o[k] in {-1, 0, 1} along axis k; q = kCentre is the cell itself. A neighbour reached
// across a periodic face is given with its image code, digit k = image[k] + 1: a member stored at x in the box
// neighbours c at x + image[k] L along axis k (image -1 across the lower face, +1 across the upper one). The
// image code of a neighbour reached inside the box is kCentre.
#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>

#include "core/vec.hpp"

namespace haet {

template <int D>
class CellGrid {
public:
    static constexpr int kStencil = D == 2 ? 9 : 27;  ///< cells in the 3^D block around a cell
    static constexpr int kCentre = kStencil / 2;      ///< offset code of the cell itself; image code of no image
    static constexpr int kSide = kStencil / 3;        ///< cells of one face layer of the block, 3^(D-1)
    /// The offset tables are padded with zeros to whole groups of eight, for loads of eight offsets at a time.
    static constexpr int kStencilPad = (kStencil + 7) / 8 * 8, kSidePad = (kSide + 7) / 8 * 8;

    CellGrid() = default;
    /// n[k] cells of width[k] [m] along axis k, from lo [m]; on a periodic axis the box length is n[k] width[k].
    CellGrid(const Vec<D>& lo, const std::array<int, D>& n, const Vec<D>& width, const std::array<bool, D>& periodic)
        : n_(n), lo_(lo), width_(width), periodic_(periodic) {
        total_ = 1;
        for (int k = 0; k < D; ++k) {
            stride_[k] = total_;
            total_ *= n_[k];
        }
        std::array<int, 2 * D> sideCount{};
        for (int q = 0; q < kStencil; ++q) {
            const std::array<int, D> o = offsetsOf(q);
            int delta = 0;
            for (int k = 0; k < D; ++k) delta += o[k] * stride_[k];
            offset_[q] = delta;
            for (int k = 0; k < D; ++k)
                if (o[k] != 0) {
                    const int s = 2 * k + (o[k] > 0 ? 1 : 0);
                    sideOffset_[s][sideCount[s]++] = delta;
                }
        }
    }
    /// Cells no narrower than `edge` [m] spanning [lo, hi] exactly: floor(L / edge) cells (at least one) of width
    /// L / n along each axis, so a point's neighbours within `edge` lie in the 3^D cells around its own. With
    /// unitFlatAxes an axis of zero length (a flat box) is one cell of width 1 [m] instead of width 0, so that the
    /// cell of a point on it is a finite quotient, 0, rather than 0 / 0.
    static CellGrid spanning(const Vec<D>& lo, const Vec<D>& hi, double edge, const std::array<bool, D>& periodic,
                             bool unitFlatAxes = false) {
        const std::array<int, D> n = spanningDims(lo, hi, edge, unitFlatAxes);
        Vec<D> width;
        for (int k = 0; k < D; ++k) {
            const double L = hi[k] - lo[k];
            width[k] = unitFlatAxes && !(L > 0) ? 1.0 : L / n[k];
        }
        return CellGrid(lo, n, width, periodic);
    }
    /// The cells per axis of spanning(lo, hi, edge, ., unitFlatAxes), without building the grid (a caller that caps
    /// the number of cells tries edges whose product of cells may not fit in an int).
    /// Each axis holds at most kMaxAxisCells cells (a fine edge over a huge box: the quotient would not fit an int).
    static std::array<int, D> spanningDims(const Vec<D>& lo, const Vec<D>& hi, double edge, bool unitFlatAxes = false) {
        std::array<int, D> n;
        for (int k = 0; k < D; ++k) {
            const double L = hi[k] - lo[k];
            const double q = std::min(std::floor(L / edge), double(kMaxAxisCells));
            n[k] = unitFlatAxes && !(L > 0) ? 1 : std::max(1, static_cast<int>(q > 0 ? q : 0));
        }
        return n;
    }
    static constexpr int kMaxAxisCells = 1 << 30;
    /// The smallest edge >= `edge` (in steps of 1.25) whose spanning grid has at most maxCells cells (counted in
    /// double), so that a grid's size follows its particles, not its box: a periodic box of 1e6 m with cells of a
    /// millimetre would hold more cells than an int counts.
    static double cappedEdge(const Vec<D>& lo, const Vec<D>& hi, double edge, double maxCells,
                             bool unitFlatAxes = false) {
        maxCells = std::min(maxCells, double(1 << 30));
        for (;; edge *= 1.25) {
            const std::array<int, D> n = spanningDims(lo, hi, edge, unitFlatAxes);
            double total = 1;
            for (int k = 0; k < D; ++k) total *= n[k];
            if (total <= maxCells) return edge;
        }
    }

    int dim(int k) const { return n_[k]; }
    const std::array<int, D>& dims() const { return n_; }
    int count() const { return total_; }            ///< number of cells
    int stride(int k) const { return stride_[k]; }  ///< index step of one cell along axis k
    const Vec<D>& origin() const { return lo_; }    ///< lower corner [m]
    const Vec<D>& width() const { return width_; }  ///< cell widths [m]
    bool periodic(int k) const { return periodic_[k]; }
    /// Every neighbour cell comes once and through one image: each periodic axis has at least 3 cells. Otherwise
    /// offsets -1 and +1 fold onto the same cell (two cells), or onto the cell itself (one).
    bool imagesExact() const {
        for (int k = 0; k < D; ++k)
            if (periodic_[k] && n_[k] < 3) return false;
        return true;
    }

    /// Cell coordinate of x along axis k; points beyond the grid fall into its outer cells (clamped).
    int coord(const Vec<D>& x, int k) const {
        const int c = static_cast<int>(std::floor((x[k] - lo_[k]) / width_[k]));
        return std::clamp(c, 0, n_[k] - 1);
    }
    /// The same, but a point beyond a periodic axis is wrapped into the box (open axes clamp).
    int wrappedCoord(const Vec<D>& x, int k) const {
        const int c = static_cast<int>(std::floor((x[k] - lo_[k]) / width_[k]));
        if (periodic_[k]) return ((c % n_[k]) + n_[k]) % n_[k];
        return std::clamp(c, 0, n_[k] - 1);
    }
    std::array<int, D> coordsOf(const Vec<D>& x) const {
        std::array<int, D> c;
        for (int k = 0; k < D; ++k) c[k] = coord(x, k);
        return c;
    }
    std::array<int, D> wrappedCoordsOf(const Vec<D>& x) const {
        std::array<int, D> c;
        for (int k = 0; k < D; ++k) c[k] = wrappedCoord(x, k);
        return c;
    }
    int index(const std::array<int, D>& c) const {
        int idx = 0;
        for (int k = D - 1; k >= 0; --k) idx = idx * n_[k] + c[k];
        return idx;
    }
    int cellOf(const Vec<D>& x) const { return index(coordsOf(x)); }
    int wrappedCellOf(const Vec<D>& x) const { return index(wrappedCoordsOf(x)); }
    /// The coordinates of cell index `cell` in [0, count()).
    std::array<int, D> coords(int cell) const {
        std::array<int, D> c;
        for (int k = 0; k < D - 1; ++k) {  // index() is x fastest
            c[k] = cell % n_[k];
            cell /= n_[k];
        }
        c[D - 1] = cell;  // what is left is below n[D-1] for a cell of the grid: no division needed
        return c;
    }
    /// Coordinate of a cell along axis k alone (coords(cell)[k] without the other axes' divisions).
    int coord(int cell, int k) const {
        return static_cast<int>(static_cast<unsigned>(cell) / static_cast<unsigned>(stride_[k]) %
                                static_cast<unsigned>(n_[k]));
    }
    /// No face of the grid within one cell: the 3^D cells around are cell + offsets()[q], none through an image.
    bool interior(const std::array<int, D>& c) const {
        // 1 <= c <= n - 2 as one unsigned comparison, c - 1 < n - 2 (false for every c when n <= 2), and the axes
        // combined without branches: a prediction of the event-driven engine asks this of every particle.
        bool in = true;
        for (int k = 0; k < D; ++k) in &= static_cast<unsigned>(c[k] - 1) < static_cast<unsigned>(n_[k] - 2);
        return in;
    }

    /// Index offsets of the 3^D cells around an interior cell, by offset code (zero-padded to kStencilPad).
    const int* offsets() const { return offset_.data(); }
    /// Index offsets of the 3^(D-1) cells that become neighbours after a step of one cell along axis k, up or down
    /// (the layer of the block at offset +1 or -1 along k), in offset-code order (zero-padded to kSidePad).
    const int* sideOffsets(int k, bool up) const { return sideOffset_[2 * k + (up ? 1 : 0)].data(); }

    /// Calls f(cell index, image code) for each cell of the 3^D block around the cell at coordinates c, in
    /// offset-code order: open axes end at the faces (those offsets are skipped), periodic ones wrap. On a periodic
    /// axis of fewer than 3 cells a cell comes more than once (each time with its own image). When f returns a
    /// bool, true ends the walk; the walk returns whether it was ended.
    template <class F>
    bool forEachNeighbour(const std::array<int, D>& c, F&& f) const {
        if (interior(c)) {
            const int base = index(c);
            for (int q = 0; q < kStencil; ++q)
                if (visit(f, base + offset_[q], kCentre)) return true;
            return false;
        }
        for (int q = 0; q < kStencil; ++q) {
            int idx = 0, image = 0, t = q, mul = 1;
            bool inside = true;
            for (int k = 0; k < D && inside; ++k) {
                int ck = c[k] + t % 3 - 1;
                t /= 3;
                int ik = 1;
                if (ck < 0) {
                    ck += n_[k];
                    ik = 0;
                } else if (ck >= n_[k]) {
                    ck -= n_[k];
                    ik = 2;
                }
                inside = ik == 1 || periodic_[k];
                idx += ck * stride_[k];
                image += ik * mul;
                mul *= 3;
            }
            if (inside && visit(f, idx, image)) return true;
        }
        return false;
    }
    template <class F>
    bool forEachNeighbour(int cell, F&& f) const {
        return forEachNeighbour(coords(cell), f);
    }
    /// The distinct cells of the block around c, in increasing index order (a periodic axis with fewer than 3
    /// cells folds offsets together); returns their number, at most 3^D.
    int distinctNeighbours(const std::array<int, D>& c, int* cells) const {
        int nc = 0;
        forEachNeighbour(c, [&](int idx, int) {  // insertion into the sorted cells[0, nc), skipping repeats
            int q = nc;
            while (q > 0 && cells[q - 1] > idx) --q;
            if (q > 0 && cells[q - 1] == idx) return;
            for (int s = nc; s > q; --s) cells[s] = cells[s - 1];
            cells[q] = idx;
            ++nc;
        });
        return nc;
    }

    /// The offsets {-1, 0, 1} per axis of an offset code, or the images of an image code.
    static constexpr std::array<int, D> offsetsOf(int code) {
        std::array<int, D> o{};
        for (int k = 0; k < D; ++k) {
            o[k] = code % 3 - 1;
            code /= 3;
        }
        return o;
    }
    /// The code of the opposite offset (or image): q and kStencil - 1 - q are mirror images.
    static constexpr int mirror(int code) { return kStencil - 1 - code; }

private:
    template <class F>
    static bool visit(F& f, int cell, int image) {
        if constexpr (std::is_same_v<std::invoke_result_t<F&, int, int>, bool>)
            return f(cell, image);
        else {
            f(cell, image);
            return false;
        }
    }

    std::array<int, D> n_{};
    std::array<int, D> stride_{};
    int total_ = 1;
    Vec<D> lo_, width_;
    std::array<bool, D> periodic_{};
    std::array<int, kStencilPad> offset_{};
    std::array<std::array<int, kSidePad>, 2 * D> sideOffset_{};
};

}  // namespace haet
