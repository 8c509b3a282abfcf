#pragma once
// One contact as the force pass saw it (the contact network, docs/scenario.md "Contacts"; the contact stress of the
// field grids, docs/physics.md L.3). The pair pass fills them only when ForceContext::contacts is set
// (tdm/pair_pass.hpp): an ordinary step pays one null-pointer test.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/vec.hpp"

namespace haet {

template <int D>
struct ContactRecord {
    static constexpr std::uint32_t kWall = 0xFFFFFFFFu;
    std::uint32_t i = 0;      ///< the particle's index in the store at the pass
    std::uint32_t j = kWall;  ///< the partner's index, or kWall for a wall
    std::int32_t wall = -1;   ///< a wall contact: the wall's place among the scenario's walls (Wall::id); else -1
    std::uint64_t idI = 0, idJ = 0;  ///< the particles' ids (Particles::id; idJ 0 for a wall), set after the pass
    Vec<D> position;                 ///< centre of i at the pass [m]
    Vec<D> point;                    ///< contact point: the middle of the overlap (a wall: on the wall's surface) [m]
    Vec<D> normal;                   ///< unit normal, from the partner (or the wall) towards i
    Vec<D> branch;                   ///< x_i - x_j (minimum image), or x_i - point for a wall [m]
    Vec<D> fn, ft;                   ///< the force on i, its normal and tangential parts as the law computed them [N]
    double overlap = 0;              ///< [m]
};

/// Where a force pass puts its contacts, in the pass's order (particle by particle: pairs, then walls).
template <int D>
using ContactSink = std::vector<ContactRecord<D>>;

/// The geometry of a wall contact's record, as every kernel of walls of any shape fills it: the contact point on
/// the wall's surface, the branch from it to the centre. The forces (fn, ft) are the caller's, from its law.
template <int D>
void placeWallRecord(ContactRecord<D>& rec, std::size_t i, std::int32_t wall, const Vec<D>& x, const Vec<D>& point,
                     const Vec<D>& normal, double overlap) {
    rec.i = static_cast<std::uint32_t>(i);
    rec.j = ContactRecord<D>::kWall;
    rec.wall = wall;
    rec.normal = normal;
    rec.position = x;
    rec.point = point;
    rec.branch = x - point;
    rec.overlap = overlap;
}

}  // namespace haet
