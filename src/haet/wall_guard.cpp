#include "haet/wall_guard.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace haet {

namespace {

/// The plane's motion as a Motion (translation and oscillation; planes do not rotate).
template <int D>
Motion<D> planeMotion(const Wall<D>& w) {
    Motion<D> m;
    m.velocity = w.velocity;
    if (w.oscillates()) {
        m.amplitude = w.amplitude;
        m.frequency = w.frequency;
        m.phase = w.phase;
    }
    return m;
}

}  // namespace

template <int D>
void WallGuard<D>::collect(const World<D>& world) {
    world_ = &world;
    planes_.clear();
    surfaces_.clear();
    speed_ = 0;
    moving_ = false;
    binned_ = false;
    for (std::size_t q = 0; q < world.walls.size(); ++q) {
        const Wall<D>& w = world.walls[q];
        if (!w.oscillates()) continue;  // the event-driven engine predicts it (D.3)
        planes_.push_back(static_cast<std::uint32_t>(q));
        moving_ = true;
        speed_ = std::max(speed_, norm(w.velocity) + 2 * std::numbers::pi * w.frequency * norm(w.amplitude));
    }
    for (std::size_t q = 0; q < world.surfaces.size(); ++q) {
        const SurfaceWall<D>& w = world.surfaces[q];
        const Motion<D>& m = w.motion;
        if (w.kind == SurfaceKind::Mesh && !m.moves()) continue;  // the event-driven engine predicts it (D.8)
        surfaces_.push_back(static_cast<std::uint32_t>(q));
        moving_ = moving_ || m.moves();
        speed_ = std::max(speed_, norm(m.velocity) + 2 * std::numbers::pi * m.frequency * norm(m.amplitude) +
                                      std::abs(m.omega) * w.reachFrom(m.centre));
    }
}

// A path-length bound, not the displacement between the two ends: an oscillation may go and come back within the
// interval.
template <int D>
double WallGuard<D>::sweep(const Motion<D>& m, double ahead, double reach) {
    double s = norm(m.velocity) * ahead;
    if (m.oscillates())
        s += std::min(2 * norm(m.amplitude), 2 * std::numbers::pi * m.frequency * norm(m.amplitude) * ahead);
    if (m.rotates()) s += std::min(std::abs(m.omega) * ahead, std::numbers::pi) * reach;
    return s;
}

template <int D>
void WallGuard<D>::refresh(const CellGrid<D>& cells, double t, double ahead, double rmax, double margin) {
    // Static walls once per grid (a grid of another size is another grid).
    if (empty() || (binned_ && !moving_ && first_.size() == static_cast<std::size_t>(cells.count()) + 1)) return;
    bin(cells, t, ahead, rmax, margin);
    binned_ = true;
}

template <int D>
void WallGuard<D>::moveTo(double t) {
    const World<D>& w = *world_;
    poses_.resize(surfaces_.size());
    for (std::size_t k = 0; k < surfaces_.size(); ++k) poses_[k] = w.surfaces[surfaces_[k]].motion.at(t);
    planePoints_.resize(planes_.size());
    for (std::size_t k = 0; k < planes_.size(); ++k) planePoints_[k] = w.walls[planes_[k]].pointAt(t);
}

// An element is listed in every cell that comes within R = rmax + margin + its sweep + the widest cell edge of it (at
// time t): the cells its box widened by R overlaps, less those whose centre is farther from it than R and the cell's
// half diagonal. Outer cells of open axes (unbounded) keep every element of the first test.
template <int D>
void WallGuard<D>::bin(const CellGrid<D>& cells, double t, double ahead, double rmax, double margin) {
    const World<D>& w = *world_;
    const std::size_t nc = static_cast<std::size_t>(cells.count());
    double ring = 0, diag2 = 0;
    for (int k = 0; k < D; ++k) {
        ring = std::max(ring, cells.width()[k]);
        diag2 += cells.width()[k] * cells.width()[k];
    }
    const double half = 0.5 * std::sqrt(diag2);
    std::vector<std::pair<std::uint32_t, Item>> binned;
    auto centreOf = [&](const std::array<int, D>& c, bool& outer) {
        Vec<D> mid;
        outer = false;
        for (int k = 0; k < D; ++k) {
            outer = outer || (!cells.periodic(k) && (c[k] == 0 || c[k] == cells.dim(k) - 1));
            mid[k] = cells.origin()[k] + (c[k] + 0.5) * cells.width()[k];
        }
        return mid;
    };
    // Calls f(cell coordinates) for the cells of the box [lo, hi] (clamped into the grid), axis 0 fastest.
    auto forBox = [&](const Vec<D>& lo, const Vec<D>& hi, auto&& f) {
        std::array<int, D> c0, c1;
        for (int k = 0; k < D; ++k) {
            c0[k] = cells.coord(lo, k);
            c1[k] = cells.coord(hi, k);
        }
        std::array<int, D> c = c0;
        for (;;) {
            f(c);
            int k = 0;
            while (k < D && c[k] == c1[k]) {
                c[k] = c0[k];
                ++k;
            }
            if (k == D) break;
            ++c[k];
        }
    };
    for (std::size_t k = 0; k < planes_.size(); ++k) {
        const Wall<D>& pl = w.walls[planes_[k]];
        const double R = rmax + margin + sweep(planeMotion(pl), ahead, 0) + ring;
        const Vec<D> p = pl.pointAt(t);
        Vec<D> lo = cells.origin(), hi = cells.origin();
        for (int a = 0; a < D; ++a) hi[a] += cells.width()[a] * cells.dim(a);
        forBox(lo, hi, [&](const std::array<int, D>& c) {
            bool outer;
            const Vec<D> mid = centreOf(c, outer);
            if (outer || std::abs(dot(pl.normal, mid - p)) <= R + half)
                binned.push_back({static_cast<std::uint32_t>(cells.index(c)), Item{static_cast<std::uint32_t>(k), 0}});
        });
    }
    for (std::size_t k = 0; k < surfaces_.size(); ++k) {
        const SurfaceWall<D>& sw = w.surfaces[surfaces_[k]];
        const Pose<D> pose = sw.motion.at(t);
        const double R = rmax + margin + sweep(sw.motion, ahead, sw.reachFrom(sw.motion.centre)) + ring;
        for (std::uint32_t e = 0; e < sw.elementCount(); ++e) {
            Vec<D> blo, bhi, lo, hi;
            sw.bounds(e, blo, bhi);
            for (int corner = 0; corner < (1 << D); ++corner) {
                Vec<D> b;
                for (int a = 0; a < D; ++a) b[a] = (corner >> a) & 1 ? bhi[a] : blo[a];
                const Vec<D> x = pose.toWorld(b);
                for (int a = 0; a < D; ++a) {
                    lo[a] = corner == 0 ? x[a] : std::min(lo[a], x[a]);
                    hi[a] = corner == 0 ? x[a] : std::max(hi[a], x[a]);
                }
            }
            const Item item{static_cast<std::uint32_t>(planes_.size() + k), e};
            forBox(lo - Vec<D>::filled(R), hi + Vec<D>::filled(R), [&](const std::array<int, D>& c) {
                bool outer;
                const Vec<D> mid = centreOf(c, outer);
                if (outer || sw.distance(e, pose.toBody(mid)) <= R + half)
                    binned.push_back({static_cast<std::uint32_t>(cells.index(c)), item});
            });
        }
    }
    // Every element not listed in a cell is farther than the smallest R from each of its points.
    listReach_ = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < planes_.size(); ++k)
        listReach_ = std::min(listReach_, rmax + margin + sweep(planeMotion(w.walls[planes_[k]]), ahead, 0) + ring);
    for (std::size_t k = 0; k < surfaces_.size(); ++k) {
        const SurfaceWall<D>& sw = w.surfaces[surfaces_[k]];
        listReach_ =
            std::min(listReach_, rmax + margin + sweep(sw.motion, ahead, sw.reachFrom(sw.motion.centre)) + ring);
    }
    first_.assign(nc + 1, 0);
    near_.assign(nc, 0);
    for (const auto& b : binned) ++first_[b.first + 1];
    for (std::size_t c = 0; c < nc; ++c) first_[c + 1] += first_[c];
    items_.resize(binned.size());
    std::vector<std::uint32_t> at(first_.begin(), first_.end() - 1);
    for (const auto& b : binned) items_[at[b.first]++] = b.second;
    list_.clear();
    for (std::size_t c = 0; c < nc; ++c)
        if (first_[c + 1] > first_[c]) {
            near_[c] = 1;
            list_.push_back(static_cast<std::uint32_t>(c));
        }
}

template <int D>
double WallGuard<D>::gap(std::uint32_t cell, const Vec<D>& x, double r) const {
    const World<D>& w = *world_;
    double g = listReach_ - r;
    for (std::uint32_t q = first_[cell]; q < first_[cell + 1]; ++q) {
        const Item& it = items_[q];
        if (it.wall < planes_.size()) {
            g = std::min(g, dot(w.walls[planes_[it.wall]].normal, x - planePoints_[it.wall]) - r);
            continue;
        }
        const std::size_t k = it.wall - planes_.size();
        const SurfaceWall<D>& sw = w.surfaces[surfaces_[k]];
        g = std::min(g, sw.distance(it.element, poses_[k].toBody(x)) - r);
    }
    return g;
}

template class WallGuard<2>;
template class WallGuard<3>;

}  // namespace haet
