#include "neighbor/surface_list.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "neighbor/cell_grid.hpp"

namespace haet {

namespace {

/// The world box of element e of wall w at its pose: the box of its body box's corners, moved.
template <int D>
void worldBounds(const SurfaceWall<D>& w, const Pose<D>& pose, std::size_t e, Vec<D>& lo, Vec<D>& hi) {
    Vec<D> blo, bhi;
    w.bounds(e, blo, bhi);
    if (!pose.rotated) {
        lo = blo + pose.shift;
        hi = bhi + pose.shift;
        return;
    }
    for (int c = 0; c < (1 << D); ++c) {
        Vec<D> corner;
        for (int a = 0; a < D; ++a) corner[a] = (c >> a) & 1 ? bhi[a] : blo[a];
        const Vec<D> x = pose.toWorld(corner);
        for (int a = 0; a < D; ++a) {
            lo[a] = c == 0 ? x[a] : std::min(lo[a], x[a]);
            hi[a] = c == 0 ? x[a] : std::max(hi[a], x[a]);
        }
    }
}

}  // namespace

template <int D>
void buildSurfaceCandidates(const Particles<D>& p, std::size_t n, const Domain<D>& dom,
                            const std::vector<SurfaceWall<D>>& walls, const std::vector<Pose<D>>& poses, double skin,
                            SurfaceCandidates& out) {
    out.first.assign(n + 1, 0);
    out.wall.clear();
    out.element.clear();
    if (walls.empty() || n == 0) return;
    double rmax = 0;
    for (std::size_t i = 0; i < n; ++i) rmax = std::max(rmax, p.radius[i]);
    const double reach = rmax + skin;
    // Cells about as wide as a particle's reach, but no more of them than a few per particle (and 2^22 at most):
    // the grid is built anew at every build.
    const double cap = std::min(4.0 * static_cast<double>(n) + 64.0, 4194304.0);
    double edge = 2 * reach;
    for (;;) {
        const auto dims =
            CellGrid<D>::spanningDims(dom.lo - Vec<D>::filled(edge), dom.hi + Vec<D>::filled(edge), edge, true);
        double cells = 1;
        for (int k = 0; k < D; ++k) cells *= dims[k];
        if (cells <= cap) break;
        edge *= 1.5;
    }
    // One layer of cells beyond the box on every side: points beyond it (clamped into the outer layer) are few,
    // so only the outer layer goes without the distance refinement below.
    const CellGrid<D> grid = CellGrid<D>::spanning(dom.lo - Vec<D>::filled(edge), dom.hi + Vec<D>::filled(edge), edge,
                                                   std::array<bool, D>{}, true);
    double half2 = 0;
    for (int k = 0; k < D; ++k) half2 += 0.25 * grid.width()[k] * grid.width()[k];
    const double half = std::sqrt(half2);

    // (cell, wall, element) for every cell an element comes within reach of, in wall then element order.
    std::vector<std::uint32_t> cellCount(static_cast<std::size_t>(grid.count()) + 1, 0);
    struct Binned {
        std::uint32_t cell, wall, element;
    };
    std::vector<Binned> binned;
    for (std::uint32_t w = 0; w < walls.size(); ++w) {
        const SurfaceWall<D>& wall = walls[w];
        const Pose<D>& pose = poses[w];
        for (std::uint32_t e = 0; e < wall.elementCount(); ++e) {
            Vec<D> lo, hi;
            worldBounds(wall, pose, e, lo, hi);
            std::array<int, D> c0, c1;
            for (int k = 0; k < D; ++k) {
                c0[k] = grid.coord(lo - Vec<D>::filled(reach), k);
                c1[k] = grid.coord(hi + Vec<D>::filled(reach), k);
            }
            std::array<int, D> c = c0;
            for (;;) {
                // Cells on the grid's faces hold the points beyond the box too (clamped): no refinement there.
                bool border = false;
                Vec<D> centre;
                for (int k = 0; k < D; ++k) {
                    border |= c[k] == 0 || c[k] == grid.dim(k) - 1;
                    centre[k] = grid.origin()[k] + (c[k] + 0.5) * grid.width()[k];
                }
                if (border || wall.distance(e, pose.toBody(centre)) <= reach + half) {
                    const auto cell = static_cast<std::uint32_t>(grid.index(c));
                    binned.push_back({cell, w, e});
                    ++cellCount[cell + 1];
                }
                int k = 0;  // the next cell of the box, axis 0 fastest
                while (k < D && c[k] == c1[k]) {
                    c[k] = c0[k];
                    ++k;
                }
                if (k == D) break;
                ++c[k];
            }
        }
    }
    for (std::size_t c = 1; c < cellCount.size(); ++c) cellCount[c] += cellCount[c - 1];
    std::vector<std::uint32_t> at(cellCount.begin(), cellCount.end() - 1);
    std::vector<std::uint32_t> cellWall(binned.size()), cellElement(binned.size());
    // Mesh elements with their padded body-frame boxes: a particle's test of an element starts with the distance
    // to its box, a few instructions, and most are ruled out before their closest points are found (the same
    // candidates: the closest point lies inside the box). Other shapes have an infinite box: always tested.
    ElementBox<D> always;
    always.lo = Vec<D>::filled(-std::numeric_limits<double>::infinity());
    always.hi = Vec<D>::filled(std::numeric_limits<double>::infinity());
    std::vector<ElementBox<D>> cellBox(binned.size(), always);
    for (const Binned& b : binned) {  // stable: each cell keeps wall then element order
        const std::uint32_t q = at[b.cell]++;
        cellWall[q] = b.wall;
        cellElement[q] = b.element;
        if (walls[b.wall].kind == SurfaceKind::Mesh) cellBox[q] = walls[b.wall].paddedBox(b.element);
    }

    for (std::size_t i = 0; i < n; ++i) {
        const auto cell = static_cast<std::uint32_t>(grid.cellOf(p.x[i]));
        const double r = p.radius[i] + skin;
        const double beyond2 = r * r * (1 + 1e-9);
        std::uint32_t lastWall = 0xFFFFFFFFu;
        Vec<D> xb;
        for (std::uint32_t q = cellCount[cell]; q < cellCount[cell + 1]; ++q) {
            const std::uint32_t w = cellWall[q];
            if (w != lastWall) {
                xb = poses[w].toBody(p.x[i]);
                lastWall = w;
            }
            if (boxDistance2(cellBox[q], xb) > beyond2) continue;
            if (walls[w].distance(cellElement[q], xb) <= r) {
                out.wall.push_back(w);
                out.element.push_back(cellElement[q]);
            }
        }
        out.first[i + 1] = static_cast<std::uint32_t>(out.wall.size());
    }
}

template <int D>
void buildSurfaceCandidatesBrute(const Particles<D>& p, std::size_t n, const std::vector<SurfaceWall<D>>& walls,
                                 const std::vector<Pose<D>>& poses, double skin, SurfaceCandidates& out) {
    out.first.assign(n + 1, 0);
    out.wall.clear();
    out.element.clear();
    for (std::size_t i = 0; i < n; ++i) {
        for (std::uint32_t w = 0; w < walls.size(); ++w) {
            const Vec<D> xb = poses[w].toBody(p.x[i]);
            for (std::uint32_t e = 0; e < walls[w].elementCount(); ++e)
                if (walls[w].distance(e, xb) <= p.radius[i] + skin) {
                    out.wall.push_back(w);
                    out.element.push_back(e);
                }
        }
        out.first[i + 1] = static_cast<std::uint32_t>(out.wall.size());
    }
}

template void buildSurfaceCandidates<2>(const Particles<2>&, std::size_t, const Domain<2>&,
                                        const std::vector<SurfaceWall<2>>&, const std::vector<Pose<2>>&, double,
                                        SurfaceCandidates&);
template void buildSurfaceCandidates<3>(const Particles<3>&, std::size_t, const Domain<3>&,
                                        const std::vector<SurfaceWall<3>>&, const std::vector<Pose<3>>&, double,
                                        SurfaceCandidates&);
template void buildSurfaceCandidatesBrute<2>(const Particles<2>&, std::size_t, const std::vector<SurfaceWall<2>>&,
                                             const std::vector<Pose<2>>&, double, SurfaceCandidates&);
template void buildSurfaceCandidatesBrute<3>(const Particles<3>&, std::size_t, const std::vector<SurfaceWall<3>>&,
                                             const std::vector<Pose<3>>&, double, SurfaceCandidates&);

}  // namespace haet
