#pragma once
// The static mesh walls of the event-driven engine (docs/physics.md D.8, H.6; docs/edm.md, "Mesh walls"): the
// segments (2D) and triangles (3D) of the World's walls of kind Mesh that do not move, each with its frame worked out
// once (edm/predict_mesh.hpp), binned into the cells of the event grid. A cell lists every element that a particle can
// touch while its centre stays in the cell (with neighbour shells: within the shell's half-edge of it), so a
// prediction tries only the elements of its particle's cell, and a cell crossing (a shell exit) predicts again.
//
// The time of a particle and an element is canonical, like the pair and plane times (edm/slots.hpp; docs/edm.md,
// "Canonical arithmetic"): a function of the particle's stored state at its clock, its box-frame position and the
// element only, searched up to the last time the particle is within its radius of the element's plane (no feature of
// the element lies off that plane), never up to a horizon that depends on when or by whom the question is asked.
// So a prediction made at a collision, at a crossing, or by the reference twin gives the same bits. A horizon (the
// best event so far) only skips elements the particle cannot reach before it, as the frozen-partner test of
// Slots::pairTime does: such an element's time could not be the earliest.
#include <cstdint>
#include <type_traits>
#include <vector>

#include "edm/predict_mesh.hpp"
#include "edm/slots.hpp"
#include "neighbor/cell_grid.hpp"
#include "world/world.hpp"

namespace haet::edm {

/// The last time t >= 0 at which |s0 + s1 t + s2 t^2| <= a: kNever if always (no motion across the plane), a
/// negative value if never. With a margin of 1e-6 relative: a bound, not a root.
inline double lastInBand(double s0, double s1, double s2, double a) {
    if (s2 == 0 && s1 == 0) return std::abs(s0) <= a ? kNever : -1.0;
    double last = std::abs(s0) <= a ? 0.0 : -1.0;
    for (const double side : {a, -a}) {
        const double c0 = s0 - side;
        if (s2 == 0) {
            last = std::max(last, -c0 / s1);
            continue;
        }
        const double disc = s1 * s1 - 4 * s2 * c0;
        if (disc < 0) continue;
        const double q = -0.5 * (s1 + std::copysign(std::sqrt(disc), s1));
        last = std::max(last, q / s2);
        if (q != 0) last = std::max(last, c0 / q);
    }
    return last < 0 ? -1.0 : last * (1 + 1e-6);
}

template <int D>
class MeshWalls {
public:
    using Sl = Slots<D>;
    using Element = std::conditional_t<D == 2, MeshSegment, MeshTriangle>;

    /// The static meshes of world.surfaces. Any other wall of any shape (curved, or moving) is an error
    /// (std::invalid_argument naming it) unless `othersGuarded`: then a coupled engine keeps the particles away from
    /// it (the hybrid's guard) and it is left out here.
    void collect(const World<D>& world, bool othersGuarded);
    bool empty() const { return elem_.empty(); }
    std::uint32_t size() const { return static_cast<std::uint32_t>(elem_.size()); }
    int material(std::uint32_t e) const { return material_[e]; }
    std::uint32_t wall(std::uint32_t e) const { return wall_[e]; }    ///< its index in World::surfaces
    std::uint32_t local(std::uint32_t e) const { return local_[e]; }  ///< its index among that wall's elements

    /// Bins every element into the cells from which a particle of radius <= rmax [m], its centre within `pad` [m]
    /// of the cell on every axis, can touch it (the outer cells of open axes reach to infinity).
    void bin(const CellGrid<D>& cells, double rmax, double pad);
    /// The elements binned into cell c, in increasing order.
    const std::uint32_t* cellBegin(std::uint32_t c) const { return items_.data() + first_[c]; }
    const std::uint32_t* cellEnd(std::uint32_t c) const { return items_.data() + first_[c + 1]; }

    /// The canonical contact time of moving slot s with element e [s], no earlier than now: from the stored state,
    /// or, when that gives a time before now (an invalid state, docs/physics.md D.6), from the state now. kNever if
    /// none, or if the particle cannot reach the element before `horizon`.
    double time(const Sl& sl, std::uint32_t s, std::uint32_t e, double now, double horizon) const;
    /// The same contact with its feature, point and normal (time absolute) [s].
    MeshContact<D> contact(const Sl& sl, std::uint32_t s, std::uint32_t e, double now) const;
    std::size_t memoryBytes() const;

private:
    /// The first contact of a centre at y (box frame), velocity v, radius a with element e, after the time of y and
    /// no later than `cap` after it [s].
    MeshContact<D> predictFrom(const Vec<D>& y, const Vec<D>& v, const Vec<D>& g, double a, std::uint32_t e,
                               double cap = kNever) const;
    /// Where slot s's search starts: its stored state in its box frame (y, v), or where that state's path enters the
    /// box after a periodic crossing; returns the time [s].
    static double start(const Sl& sl, std::uint32_t s, Vec<D>& y, Vec<D>& v);
    static Vec<D> boxFrame(const Sl& sl, std::uint32_t s, const Vec<D>& x);

    std::vector<Element> elem_;
    std::vector<Vec<D>> centre_;   // bounding sphere [m]
    std::vector<double> reach_;    // its radius [m]
    std::vector<Vec<D>> lo_, hi_;  // bounding box [m]
    std::vector<int> material_;
    std::vector<std::uint32_t> wall_, local_;
    std::vector<std::uint32_t> first_, items_;  // CSR over the cells
};

extern template class MeshWalls<2>;
extern template class MeshWalls<3>;

}  // namespace haet::edm
