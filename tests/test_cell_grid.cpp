// CellGrid's neighbour walk against its reference twin: every cell of the grid under every image, kept when it lies
// within one cell of the cell on each axis (2D and 3D, periodic and open, with the degenerate periodic axes of one
// and two cells where a neighbour comes more than once); and against points: the minimum image of a near pair is
// among the images the walk gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "geometry/domain.hpp"
#include "neighbor/cell_grid.hpp"

namespace haet {
namespace {

using Visit = std::pair<int, int>;  // (cell index, image code)

/// Brute force: every cell c2 under every image (nonzero only on periodic axes) whose imaged coordinate lies within
/// one cell of c on each axis.
template <int D>
std::multiset<Visit> bruteNeighbours(const CellGrid<D>& g, const std::array<int, D>& c) {
    std::multiset<Visit> out;
    for (int cell = 0; cell < g.count(); ++cell) {
        const std::array<int, D> c2 = g.coords(cell);
        for (int image = 0; image < CellGrid<D>::kStencil; ++image) {
            const std::array<int, D> im = CellGrid<D>::offsetsOf(image);
            bool near = true;
            for (int k = 0; k < D; ++k) {
                if (im[k] != 0 && !g.periodic(k)) near = false;
                const int d = c2[k] + im[k] * g.dim(k) - c[k];
                if (d < -1 || d > 1) near = false;
            }
            if (near) out.emplace(cell, image);
        }
    }
    return out;
}

template <int D>
void checkGrid(const std::array<int, D>& n, const std::array<bool, D>& periodic) {
    Vec<D> lo, width;
    for (int k = 0; k < D; ++k) {
        lo[k] = -0.5 * k;
        width[k] = 0.25 + 0.125 * k;
    }
    const CellGrid<D> g(lo, n, width, periodic);
    int total = 1;
    for (int k = 0; k < D; ++k) total *= n[k];
    ASSERT_EQ(g.count(), total);
    for (int cell = 0; cell < g.count(); ++cell) {
        const std::array<int, D> c = g.coords(cell);
        ASSERT_EQ(g.index(c), cell);
        std::multiset<Visit> walk;
        std::vector<int> order;
        g.forEachNeighbour(cell, [&](int idx, int image) {
            ASSERT_GE(idx, 0);
            ASSERT_LT(idx, g.count());
            walk.emplace(idx, image);
            order.push_back(idx);
        });
        EXPECT_EQ(walk, bruteNeighbours<D>(g, c)) << "cell " << cell;
        // The distinct neighbours: the walk's cells, once each, in increasing order.
        int cells[CellGrid<D>::kStencil];
        const int nc = g.distinctNeighbours(c, cells);
        std::sort(order.begin(), order.end());
        order.erase(std::unique(order.begin(), order.end()), order.end());
        EXPECT_EQ(std::vector<int>(cells, cells + nc), order);
        // An interior cell: the offset table, in offset-code order, all without images; and after a step of one
        // cell, the new neighbours are the side table's.
        if (g.interior(c)) {
            int q = 0;
            g.forEachNeighbour(cell, [&](int idx, int image) {
                EXPECT_EQ(idx, cell + g.offsets()[q++]);
                EXPECT_EQ(image, CellGrid<D>::kCentre);
            });
            for (int k = 0; k < D; ++k)
                for (const bool up : {false, true}) {
                    const int next = cell + (up ? 1 : -1) * g.stride(k);
                    if (!g.interior(g.coords(next))) continue;  // both blocks inside: indices do not fold
                    std::set<int> before, after, side;
                    for (int o = 0; o < CellGrid<D>::kStencil; ++o) {
                        before.insert(cell + g.offsets()[o]);
                        after.insert(next + g.offsets()[o]);
                    }
                    for (int o = 0; o < CellGrid<D>::kSide; ++o) side.insert(next + g.sideOffsets(k, up)[o]);
                    std::set<int> fresh;
                    std::set_difference(after.begin(), after.end(), before.begin(), before.end(),
                                        std::inserter(fresh, fresh.end()));
                    EXPECT_EQ(fresh, side);
                    for (int o = CellGrid<D>::kSide; o < CellGrid<D>::kSidePad; ++o)
                        EXPECT_EQ(g.sideOffsets(k, up)[o], 0);
                }
        }
    }
    EXPECT_EQ(g.imagesExact(), [&] {
        for (int k = 0; k < D; ++k)
            if (periodic[k] && n[k] < 3) return false;
        return true;
    }());
}

TEST(CellGrid, WalkMatchesBruteForce2D) {
    for (int a = 1; a <= 5; ++a)
        for (int b = 1; b <= 5; ++b)
            for (int per = 0; per < 4; ++per) checkGrid<2>({a, b}, {(per & 1) != 0, (per & 2) != 0});
}

TEST(CellGrid, WalkMatchesBruteForce3D) {
    for (int a = 1; a <= 4; ++a)
        for (int b = 1; b <= 4; ++b)
            for (int c = 1; c <= 4; ++c)
                for (int per = 0; per < 8; ++per)
                    checkGrid<3>({a, b, c}, {(per & 1) != 0, (per & 2) != 0, (per & 4) != 0});
}

/// Random pairs of points closer than a cell width (minimum image): the second's cell is among the first's
/// neighbours, with the minimum image among the images it comes with.
template <int D>
void checkPoints(const std::array<int, D>& n, const std::array<bool, D>& periodic, unsigned seed) {
    Domain<D> dom;
    std::array<int, D> cells = n;
    double edge = 1e300;
    for (int k = 0; k < D; ++k) {
        dom.lo[k] = -1.0 + 0.3 * k;
        dom.hi[k] = dom.lo[k] + 0.7 * n[k] + 0.01 + 0.05 * k;
        edge = std::min(edge, (dom.hi[k] - dom.lo[k]) / n[k]);
    }
    dom.periodic = periodic;
    const CellGrid<D> g = CellGrid<D>::spanning(dom.lo, dom.hi, 0.7, periodic);
    ASSERT_EQ(g.dims(), cells);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    int tested = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        Vec<D> x, y;
        for (int k = 0; k < D; ++k) {
            x[k] = dom.lo[k] + u(rng) * (dom.hi[k] - dom.lo[k]);
            y[k] = dom.lo[k] + u(rng) * (dom.hi[k] - dom.lo[k]);
        }
        const Vec<D> d = dom.minimumImage(y - x);
        if (norm(d) >= edge) continue;
        ++tested;
        const int cy = g.cellOf(y);
        bool found = false;
        g.forEachNeighbour(g.cellOf(x), [&](int idx, int image) {
            if (idx != cy) return;
            const std::array<int, D> im = CellGrid<D>::offsetsOf(image);
            Vec<D> seen = y;
            for (int k = 0; k < D; ++k) seen[k] += im[k] * (dom.hi[k] - dom.lo[k]);
            found = found || norm(seen - x - d) < 1e-12;
        });
        EXPECT_TRUE(found) << "trial " << trial;
    }
    EXPECT_GT(tested, 0);
}

TEST(CellGrid, MinimumImageAmongWalkImages) {
    unsigned seed = 1;
    for (int a = 1; a <= 4; ++a)
        for (int b = 1; b <= 4; ++b)
            for (int per = 0; per < 4; ++per) checkPoints<2>({a, b}, {(per & 1) != 0, (per & 2) != 0}, seed++);
    for (int a = 1; a <= 3; ++a)
        for (int per = 0; per < 8; ++per)
            checkPoints<3>({a, 3, 4 - a}, {(per & 1) != 0, (per & 2) != 0, (per & 4) != 0}, seed++);
}

TEST(CellGrid, CoordinatesClampOrWrap) {
    const CellGrid<2> g(Vec<2>{{0.0, 0.0}}, {4, 3}, Vec<2>{{0.5, 1.0}}, {true, false});
    EXPECT_EQ(g.coord(Vec<2>{{-0.1, 0.0}}, 0), 0);         // clamped
    EXPECT_EQ(g.wrappedCoord(Vec<2>{{-0.1, 0.0}}, 0), 3);  // periodic: wrapped
    EXPECT_EQ(g.wrappedCoord(Vec<2>{{2.2, 0.0}}, 0), 0);   // past the upper face
    EXPECT_EQ(g.wrappedCoord(Vec<2>{{0.0, -5.0}}, 1), 0);  // open: clamped
    EXPECT_EQ(g.wrappedCoord(Vec<2>{{0.0, 7.0}}, 1), 2);
    EXPECT_EQ(g.cellOf(Vec<2>{{1.2, 1.5}}), 2 + 4 * 1);  // x fastest
    EXPECT_EQ(g.stride(1), 4);
    EXPECT_EQ(g.coord(2 + 4 * 1, 0), 2);  // a cell's coordinate along one axis
    EXPECT_EQ(g.coord(2 + 4 * 1, 1), 1);
    const CellGrid<3> s = CellGrid<3>::spanning(Vec<3>::zero(), Vec<3>{{1.0, 2.5, 0.1}}, 0.3, {false, true, false});
    EXPECT_EQ(s.dims(), (std::array<int, 3>{3, 8, 1}));
    EXPECT_DOUBLE_EQ(s.width()[1], 2.5 / 8);
    // A flat axis (zero length): one cell of width 0 by default, of width 1 with unitFlatAxes (the event grid's
    // rule), whose cell of a point on it is 0.
    const Vec<3> flatHi{{1.0, 2.5, 0.0}};
    const CellGrid<3> f = CellGrid<3>::spanning(Vec<3>::zero(), flatHi, 0.3, {false, true, false}, true);
    EXPECT_EQ(f.dims(), (std::array<int, 3>{3, 8, 1}));
    EXPECT_EQ(CellGrid<3>::spanningDims(Vec<3>::zero(), flatHi, 0.3, true), f.dims());
    EXPECT_EQ(f.width()[2], 1.0);
    EXPECT_EQ(f.width()[1], s.width()[1]);
    EXPECT_EQ(f.cellOf(Vec<3>{{0.5, 1.3, 0.0}}), 1 + 3 * 4);
    EXPECT_EQ(CellGrid<3>::spanning(Vec<3>::zero(), flatHi, 0.3, {false, true, false}).width()[2], 0.0);
    // The offset tables are padded to whole groups of eight with zeros.
    EXPECT_EQ(CellGrid<3>::kStencilPad % 8, 0);
    EXPECT_EQ(CellGrid<2>::kSidePad, 8);
    EXPECT_EQ(f.offsets()[CellGrid<3>::kStencil], 0);
    EXPECT_EQ(f.sideOffsets(2, true)[CellGrid<3>::kSide], 0);
    EXPECT_EQ(CellGrid<3>::mirror(CellGrid<3>::kCentre), CellGrid<3>::kCentre);
    EXPECT_EQ(CellGrid<2>::mirror(0), 8);
}

}  // namespace
}  // namespace haet
