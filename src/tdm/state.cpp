// The time-driven engine's state in a checkpoint (TdmEngine::saveState, loadState; ARCHITECTURE.md, "Checkpoints").
// Everything a later step reads and the World does not hold is saved as it is, not rebuilt: a pair list built
// again would list the same pairs in another order after particles moved, and the sums of the pair pass, in list
// order, would differ in their last bits.
#include <algorithm>
#include <cmath>

#include "tdm/engine.hpp"

namespace haet {

namespace {

template <int D>
void putContact(ByteWriter& out, const SurfaceContact<D>& c) {
    out.put(c.normal);
    out.put(c.spring);
    out.put(c.force);
    out.put(c.point);
    out.put(c.overlap);
    out.put(c.wall);
}

template <int D>
SurfaceContact<D> getContact(ByteReader& in) {
    SurfaceContact<D> c;
    c.normal = in.get<Vec<D>>();
    c.spring = in.get<Vec<D>>();
    c.force = in.get<Vec<D>>();
    c.point = in.get<Vec<D>>();
    c.overlap = in.get<double>();
    c.wall = in.get<std::uint32_t>();
    return c;
}

}  // namespace

template <int D>
void TdmEngine<D>::saveState(ByteWriter& out) const {
    out.put<std::uint64_t>(w_.particles.tdmCount());
    // The step and the skin: unless the scenario sets it, the skin follows from the particles at the start (their
    // largest diameter), which a resumed run's World, after outlets, may no longer hold.
    out.put<double>(s_.dt);
    out.put<double>(s_.skin);
    out.put<std::uint64_t>(steps_);
    out.put<std::uint64_t>(rebuilds_);
    out.put<std::uint64_t>(lastSort_);
    out.put<double>(t0_);
    out.putVector(pairs_.first);
    out.putVector(pairs_.partner);
    out.putVector(pairs_.shift);
    out.putVector(pairs_.history);
    out.putVector(xAtBuild_);
    out.putVector(motion_.v);
    out.putVector(motion_.w);
    out.putVector(wallHistory_);
    out.putVector(planeForce_);
    out.put<std::uint64_t>(stats_.contacts);
    out.put<double>(stats_.maxOverlapRatio);
    out.put<std::uint64_t>(stats_.worstParticle);
    out.put<double>(stats_.virial);
    out.put<std::uint64_t>(stats_.nonFinite);
    // Walls of any shape: their poses follow from the time (moveWalls); the candidates and contacts do not.
    out.put<double>(surf_.candidatesTime);
    out.putVector(surf_.candidates.first);
    out.putVector(surf_.candidates.wall);
    out.putVector(surf_.candidates.element);
    out.putVector(surf_.slotOf);
    out.putVector(surf_.count);
    out.put<std::uint64_t>(surf_.slots.size());
    for (const SurfaceContact<D>& c : surf_.slots) putContact(out, c);
    integ_->saveState(out);
}

template <int D>
void TdmEngine<D>::loadState(ByteReader& in) {
    pristine_ = false;
    const std::size_t n = w_.particles.tdmCount();
    const auto saved = in.get<std::uint64_t>();
    if (saved != n)
        in.fail(std::to_string(saved) + " time-driven particles saved, " + std::to_string(n) + " in the World");
    if (in.get<double>() != s_.dt) in.fail("the time step is not this scenario's");
    const double skin = in.get<double>();
    if (!(skin >= 0) || !std::isfinite(skin)) in.fail("the skin is not a number");
    steps_ = in.get<std::uint64_t>();
    rebuilds_ = in.get<std::uint64_t>();
    lastSort_ = in.get<std::uint64_t>();
    t0_ = in.get<double>();
    PairList<D> list;
    in.getVector(list.first, n + 1, "the pair list's offsets");
    in.getVector(list.partner);
    in.getVector(list.shift, list.partner.size(), "the pair list's shifts");
    in.getVector(list.history, list.partner.size(), "the pair list's springs");
    // A list that would make the force pass read outside the store is refused here, not found by a crash.
    if (list.first.front() != 0 || list.first.back() != list.partner.size() ||
        !std::is_sorted(list.first.begin(), list.first.end()))
        in.fail("the pair list's offsets are not those of its pairs");
    for (std::size_t i = 0; i < n; ++i)
        for (std::uint32_t k = list.first[i]; k < list.first[i + 1]; ++k)
            if (list.partner[k] <= i || list.partner[k] >= n) in.fail("a pair's partner is out of range");
    for (std::uint8_t code : list.shift)
        if (code >= pairs_.shiftVec.size()) in.fail("a pair's image shift is out of range");
    list.shiftVec = pairs_.shiftVec;  // from the box, as the engine made it
    pairs_ = std::move(list);
    in.getVector(xAtBuild_, n, "the positions at the list build");
    in.getVector(motion_.v, n, "the step's mean velocities");
    in.getVector(motion_.w, n, "the step's mean spins");
    in.getVector(wallHistory_, n * w_.walls.size(), "the planes' springs");
    in.getVector(planeForce_, s_.planeLoads ? n * w_.walls.size() : 0, "the planes' contact forces");
    stats_.contacts = in.get<std::uint64_t>();
    stats_.maxOverlapRatio = in.get<double>();
    stats_.worstParticle = in.get<std::uint64_t>();
    stats_.virial = in.get<double>();
    stats_.nonFinite = in.get<std::uint64_t>();
    surf_.candidatesTime = in.get<double>();
    const bool surfaces = !surf_.empty();
    in.getVector(surf_.candidates.first);
    in.getVector(surf_.candidates.wall);
    in.getVector(surf_.candidates.element, surf_.candidates.wall.size(), "the candidates' elements");
    in.getVector(surf_.slotOf);
    in.getVector(surf_.count, surf_.slotOf.size(), "the wall contact counts");
    const auto slots = in.get<std::uint64_t>();
    if (slots > in.rest().size() / (4 * sizeof(Vec<D>))) in.fail("more wall contacts than the bytes left hold");
    surf_.slots.resize(slots);
    for (SurfaceContact<D>& c : surf_.slots) c = getContact<D>(in);
    if (surfaces) {
        const auto& cand = surf_.candidates;
        if (cand.first.size() != n + 1 || cand.first.front() != 0 || cand.first.back() != cand.wall.size() ||
            !std::is_sorted(cand.first.begin(), cand.first.end()) || surf_.slotOf.size() != n)
            in.fail("the candidates of walls of any shape do not fit the particles");
        for (std::size_t k = 0; k < cand.wall.size(); ++k)
            if (cand.wall[k] >= w_.surfaces.size() || cand.element[k] >= w_.surfaces[cand.wall[k]].elementCount())
                in.fail("a candidate's wall or element is out of range");
        for (std::size_t i = 0; i < n; ++i) {
            if (surf_.slotOf[i] == SurfaceState<D>::kNoSlots) continue;
            if (surf_.slotOf[i] > surf_.slots.size() || surf_.slots.size() - surf_.slotOf[i] < kSurfaceSlots ||
                surf_.count[i] > kSurfaceSlots)
                in.fail("a particle's wall contacts are out of range");
        }
        for (const SurfaceContact<D>& c : surf_.slots)
            if (c.wall >= w_.surfaces.size()) in.fail("a wall contact's wall is out of range");
    } else if (!surf_.candidates.wall.empty() || !surf_.slotOf.empty() || !surf_.slots.empty()) {
        in.fail("wall contacts saved for a scene without walls of any shape");
    }
    integ_->loadState(in, n);
    in.expectEnd();
    s_.skin = skin;  // the pair list was built with it
    // The walls where the saved state had them (they follow from the time alone), the derived tables of the pair
    // list made again on first use.
    moveWalls();
    pairs_.dropDerived();
    // Every particle tests the planes until the next build marks them again (the same forces: a far particle's
    // plane springs are zero either way).
    nearPlanes_.clear();
    planesAtMark_.clear();
}

template void TdmEngine<2>::saveState(ByteWriter&) const;
template void TdmEngine<3>::saveState(ByteWriter&) const;
template void TdmEngine<2>::loadState(ByteReader&);
template void TdmEngine<3>::loadState(ByteReader&);

}  // namespace haet
