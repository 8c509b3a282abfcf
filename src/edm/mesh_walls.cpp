#include "edm/mesh_walls.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "geometry/closest.hpp"

namespace haet::edm {

namespace {

/// "wall k (name)" as the scenario numbers its walls (1-based).
template <int D>
std::string wallName(const SurfaceWall<D>& w) {
    return "wall " + std::to_string(w.id + 1) + (w.name.empty() ? "" : " (\"" + w.name + "\")");
}

}  // namespace

template <int D>
void MeshWalls<D>::collect(const World<D>& world, bool othersGuarded) {
    *this = MeshWalls{};
    for (std::size_t q = 0; q < world.surfaces.size(); ++q) {
        const SurfaceWall<D>& w = world.surfaces[q];
        if (w.kind != SurfaceKind::Mesh || w.motion.moves()) {
            if (othersGuarded) continue;
            throw std::invalid_argument("event-driven engine: " + wallName(w) +
                                        (w.kind != SurfaceKind::Mesh ? " is curved" : " moves") +
                                        ": only planes and static meshes are predicted (docs/physics.md H.6)");
        }
        if (w.material < 0 || w.material >= world.contact.nMaterials)
            throw std::invalid_argument("event-driven engine: " + wallName(w) + " has no material");
        for (std::size_t e = 0; e < w.elements.size(); ++e) {
            std::array<Vec<D>, D> c;
            for (int k = 0; k < D; ++k) c[k] = w.vertices[w.elements[e][k]];
            Element el;
            if constexpr (D == 2) {
                if (!(norm(c[1] - c[0]) > 0))
                    throw std::invalid_argument("event-driven engine: " + wallName(w) + " has a segment of length 0");
                el = makeMeshSegment(c[0], c[1]);
            } else {
                if (!(norm(cross(c[1] - c[0], c[2] - c[0])) > 0))
                    throw std::invalid_argument("event-driven engine: " + wallName(w) + " has a triangle of area 0");
                el = makeMeshTriangle(c);
            }
            Vec<D> lo = c[0], hi = c[0], mid = Vec<D>::zero();
            for (int k = 0; k < D; ++k) {
                mid += c[k] * (1.0 / D);
                for (int a = 0; a < D; ++a) {
                    lo[a] = std::min(lo[a], c[k][a]);
                    hi[a] = std::max(hi[a], c[k][a]);
                }
            }
            double r = 0;
            for (int k = 0; k < D; ++k) r = std::max(r, norm(c[k] - mid));
            elem_.push_back(el);
            centre_.push_back(mid);
            reach_.push_back(r * (1 + 1e-12));
            lo_.push_back(lo);
            hi_.push_back(hi);
            material_.push_back(w.material);
            wall_.push_back(static_cast<std::uint32_t>(q));
            local_.push_back(static_cast<std::uint32_t>(e));
        }
    }
    if (elem_.size() >= (1u << 29)) throw std::invalid_argument("event-driven engine: too many mesh elements");
}

// An element goes into every cell whose box (widened by pad) comes within rmax of it: the cells its box widened by
// rmax + pad overlaps, less those whose centre is farther from it than rmax plus the widened cell's half diagonal
// (a point of the box within rmax of the element is at most that far from the centre). The outer cells of open axes
// hold everything beyond the grid (CellGrid::coord clamps): they keep every element of the first test.
template <int D>
void MeshWalls<D>::bin(const CellGrid<D>& cells, double rmax, double pad) {
    const std::size_t nc = static_cast<std::size_t>(cells.count());
    first_.assign(nc + 1, 0);
    items_.clear();
    if (elem_.empty()) return;
    const double reach = rmax + pad;
    double diag2 = 0;
    for (int k = 0; k < D; ++k) diag2 += (cells.width()[k] + 2 * pad) * (cells.width()[k] + 2 * pad);
    const double far = rmax + 0.5 * std::sqrt(diag2);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> binned;  // (cell, element), element-major
    for (std::uint32_t e = 0; e < size(); ++e) {
        std::array<int, D> c0, c1;
        for (int k = 0; k < D; ++k) {
            c0[k] = cells.coord(lo_[e] - Vec<D>::filled(reach), k);
            c1[k] = cells.coord(hi_[e] + Vec<D>::filled(reach), k);
        }
        std::array<int, D> c = c0;
        for (;;) {
            bool outer = false;
            Vec<D> mid;
            for (int k = 0; k < D; ++k) {
                outer = outer || (!cells.periodic(k) && (c[k] == 0 || c[k] == cells.dim(k) - 1));
                mid[k] = cells.origin()[k] + (c[k] + 0.5) * cells.width()[k];
            }
            bool keep = outer;
            if (!keep) {
                ClosestPoint<D> q;
                if constexpr (D == 2)
                    q = closestOnSegment<2>(mid, elem_[e].p, elem_[e].q);
                else
                    q = closestOnTriangle(mid, elem_[e].p[0], elem_[e].p[1], elem_[e].p[2]);
                keep = norm(mid - q.point) <= far * (1 + 1e-12);
            }
            if (keep) binned.emplace_back(static_cast<std::uint32_t>(cells.index(c)), e);
            int k = 0;
            while (k < D && c[k] == c1[k]) {
                c[k] = c0[k];
                ++k;
            }
            if (k == D) break;
            ++c[k];
        }
    }
    for (const auto& b : binned) ++first_[b.first + 1];
    for (std::size_t c = 0; c < nc; ++c) first_[c + 1] += first_[c];
    items_.resize(binned.size());
    std::vector<std::uint32_t> at(first_.begin(), first_.end() - 1);
    for (const auto& b : binned) items_[at[b.first]++] = b.second;  // stable: each cell in element order
}

template <int D>
Vec<D> MeshWalls<D>::boxFrame(const Sl& sl, std::uint32_t s, const Vec<D>& x) {
    const typename Sl::Shift ws = Sl::wrapsOf(sl.link[s].wrap);
    Vec<D> y = x;
    for (int k = 0; k < D; ++k)
        if (ws[k] != 0) y[k] -= ws[k] * sl.boxLen[k];
    return y;
}

template <int D>
MeshContact<D> MeshWalls<D>::predictFrom(const Vec<D>& y, const Vec<D>& v, const Vec<D>& g, double a, std::uint32_t e,
                                         double cap) const {
    const Element& el = elem_[e];
    Vec<D> p0;
    if constexpr (D == 2)
        p0 = el.p;
    else
        p0 = el.p[0];
    // Every feature lies in the element's plane: no contact once the centre has left the band |s| <= a for good.
    const double last = std::min(lastInBand(dot(el.n, y - p0), dot(el.n, v), 0.5 * dot(el.n, g), a), cap);
    if (last < 0) return MeshContact<D>{};
    if constexpr (D == 2)
        return predictSegment(y, v, g, a, el, last);
    else
        return predictTriangle(y, v, g, a, el, last);
}

// From the stored state; but when the particle has crossed a periodic face since its clock (its box frame moved by a
// box length, and its stored position lies outside the box in the new frame), from where it entered the box: the part
// of its path before lies on the other side, where the walls are not repeated (docs/physics.md H.4). The entry is
// worked out from the stored state too, so the start is as canonical as the state.
template <int D>
double MeshWalls<D>::start(const Sl& sl, std::uint32_t s, Vec<D>& y, Vec<D>& v) {
    const typename Sl::Hot& h = sl.hot[s];
    const Domain<D>& dom = sl.world->domain;
    y = boxFrame(sl, s, h.x);
    v = h.v;
    double entry = 0;
    for (int k = 0; k < D; ++k) {
        if (!dom.periodic[k]) continue;
        const double lo = dom.lo[k], hi = dom.lo[k] + sl.boxLen[k];
        if (y[k] < lo) entry = std::max(entry, firstRootFalling(lo - y[k], -v[k], -sl.g[k]));
        if (y[k] >= hi) entry = std::max(entry, firstRootFalling(y[k] - hi, v[k], sl.g[k]));
    }
    if (!(entry > 0 && entry < kNever)) return h.t;
    y += (v + sl.g * (0.5 * entry)) * entry;
    v += sl.g * entry;
    return h.t + entry;
}

template <int D>
MeshContact<D> MeshWalls<D>::contact(const Sl& sl, std::uint32_t s, std::uint32_t e, double now) const {
    const typename Sl::Hot& h = sl.hot[s];
    Vec<D> y, v;
    const double t0 = start(sl, s, y, v);
    MeshContact<D> c = predictFrom(y, v, sl.g, h.r, e);
    c.time = t0 + c.time;
    if (c.time >= now) return c;
    // Invalid state at the stored clock: decided by the state now, as for pairs and planes.
    c = predictFrom(boxFrame(sl, s, sl.posAt(h, now)), sl.velAt(h, now), sl.g, h.r, e);
    c.time = now + c.time;
    return c;
}

template <int D>
double MeshWalls<D>::time(const Sl& sl, std::uint32_t s, std::uint32_t e, double now, double horizon) const {
    const typename Sl::Hot& h = sl.hot[s];
    if (horizon < kNever) {
        // A conservative test whether s can reach the element (its bounding sphere, its plane) before the horizon.
        const Vec<D> y = boxFrame(sl, s, sl.posAt(h, now));
        const Element& el = elem_[e];
        Vec<D> p0;
        if constexpr (D == 2)
            p0 = el.p;
        else
            p0 = el.p[0];
        const double gap = std::max(norm(y - centre_[e]) - reach_[e], std::abs(dot(el.n, y - p0))) - h.r;
        if (gap > 0) {
            const double tau = horizon - now;
            const double reach = norm(sl.velAt(h, now)) * tau + 0.5 * norm(sl.g) * tau * tau;
            if (gap > reach * (1 + 1e-9) + 1e-12 * h.r) return kNever;
        }
        // The same search up to the horizon only, which the quick bounds of the root isolation end for most features
        // (poly_roots.hpp): no root before it, no event before it, and the canonical search is not needed. A graze
        // by less than rounding may be found by one search and not by the other; nothing else differs.
        Vec<D> y0, v0;
        const double t0 = start(sl, s, y0, v0);
        if (predictFrom(y0, v0, sl.g, h.r, e, (horizon - t0) * (1 + 1e-9)).time == kNever) return kNever;
    }
    return contact(sl, s, e, now).time;
}

template <int D>
std::size_t MeshWalls<D>::memoryBytes() const {
    auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
    return bytes(elem_) + bytes(centre_) + bytes(reach_) + bytes(lo_) + bytes(hi_) + bytes(material_) + bytes(wall_) +
           bytes(local_) + bytes(first_) + bytes(items_);
}

template class MeshWalls<2>;
template class MeshWalls<3>;

}  // namespace haet::edm
