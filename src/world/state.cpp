#include "world/state.hpp"

#include <algorithm>
#include <cmath>

namespace haet {

namespace {

template <int N>
bool allFinite(const std::vector<Vec<N>>& values) {
    for (const Vec<N>& a : values)
        for (int k = 0; k < N; ++k)
            if (!std::isfinite(a[k])) return false;
    return true;
}

}  // namespace

template <int D>
void saveWorld(ByteWriter& out, const World<D>& w) {
    const Particles<D>& p = w.particles;
    if (!p.hasMotion()) throw std::logic_error("saveWorld: the particles' positions are held by an engine");
    out.put<double>(w.time);
    out.put<std::uint64_t>(p.size());
    out.put<std::uint64_t>(p.nTdm);  // as set: all (-1) takes in later particles, a count does not
    out.put<std::uint8_t>(p.hasTdmState());
    out.putVector(p.x);
    out.putVector(p.v);
    out.putVector(p.w);
    out.putVector(p.f);
    out.putVector(p.torque);
    out.putVector(p.radius);
    out.putVector(p.invMass);
    out.putVector(p.invInertia);
    out.putVector(p.material);
    out.putVector(p.flags);
    out.putVector(p.mass);
    out.putVector(p.id);
    out.putVector(p.image);
    out.putVector(p.shape);
    out.putVector(p.angle);
    out.putVector(p.shapes.first);
    out.putVector(p.shapes.vertices);
    out.putVector(p.shapes.inertiaPerMass);
    out.putVector(p.shapes.area);
    // The walls whose motion a script changed (Wall::setVelocity, Motion::rebase): the rest follow from the
    // scenario and the time, so that a resume with a changed scenario takes their motion from it.
    for (const Wall<D>& wall : w.walls) {
        out.put<std::uint8_t>(wall.changed);
        if (!wall.changed) continue;
        out.put(wall.point);
        out.put(wall.velocity);
        out.put<double>(wall.phase);
        out.put<double>(wall.origin);
    }
    for (const SurfaceWall<D>& wall : w.surfaces) {
        const Motion<D>& m = wall.motion;
        out.put<std::uint8_t>(m.rebased);
        if (!m.rebased) continue;
        out.put(m.velocity);
        out.put<double>(m.phase);
        out.put(m.axis);
        out.put<double>(m.omega);
        out.put<double>(m.origin);
        out.put(m.baseRot.m);
        out.put(m.baseShift);
        out.put<std::uint8_t>(m.baseRotated);
    }
}

template <int D>
void loadWorld(ByteReader& in, World<D>& w) {
    Particles<D>& p = w.particles;
    const double time = in.get<double>();
    if (!std::isfinite(time)) in.fail("the time is not finite");
    const auto n = in.get<std::uint64_t>();
    const auto nTdm = in.get<std::uint64_t>();
    const bool tdmState = in.get<std::uint8_t>() != 0;
    if (nTdm > n && nTdm != std::uint64_t(-1)) in.fail("more time-driven particles than particles");
    if (n > in.rest().size() / (2 * sizeof(Vec<D>))) in.fail("more particles than the bytes left hold");
    Particles<D> q;
    if (!tdmState) q.dropTdmState();
    in.getVector(q.x, n, "x");
    in.getVector(q.v, n, "v");
    in.getVector(q.w, n, "w");
    in.getVector(q.f, tdmState ? n : 0, "f");
    in.getVector(q.torque, tdmState ? n : 0, "torque");
    in.getVector(q.radius, n, "radius");
    in.getVector(q.invMass, n, "1/m");
    in.getVector(q.invInertia, n, "1/I");
    in.getVector(q.material, n, "material");
    in.getVector(q.flags, n, "flags");
    in.getVector(q.mass, n, "mass");
    in.getVector(q.id, n, "id");
    in.getVector(q.image, n, "image");
    in.getVector(q.shape);
    in.getVector(q.angle, q.shape.size(), "angle");
    if (!q.shape.empty() && q.shape.size() != n) in.fail("shape has " + std::to_string(q.shape.size()) + " entries");
    in.getVector(q.shapes.first);
    in.getVector(q.shapes.vertices);
    in.getVector(q.shapes.inertiaPerMass);
    in.getVector(q.shapes.area, q.shapes.inertiaPerMass.size(), "the shapes' areas");
    const std::size_t nShapes = q.shapes.area.size();
    if (q.shapes.first.size() != nShapes + 1 || q.shapes.first.front() != 0 ||
        q.shapes.first.back() != q.shapes.vertices.size() ||
        !std::is_sorted(q.shapes.first.begin(), q.shapes.first.end()))
        in.fail("the shape table's offsets do not fit its vertices");
    for (std::size_t s = 0; s < nShapes; ++s)
        if (q.shapes.count(std::uint32_t(s)) < 3) in.fail("a polygon with fewer than 3 vertices");
    for (std::uint32_t s : q.shape)
        if (s != kNoShape && s >= nShapes) in.fail("a particle's shape is out of range");
    if constexpr (D == 3)
        if (!q.shape.empty()) in.fail("polygons in a 3D run");
    for (std::uint16_t m : q.material)
        if (int(m) >= w.contact.nMaterials) in.fail("a particle's material is not in the scenario");
    for (double r : q.radius)
        if (!(r > 0) || !std::isfinite(r)) in.fail("a radius is not a positive number");
    // A run stops at the first non-finite state (exit code 3), so a saved one is finite; the engines' grids take a
    // position's cell by a conversion to int that a NaN would make undefined.
    if (!allFinite(q.x) || !allFinite(q.v) || !allFinite(q.w)) in.fail("a position, velocity or spin is not finite");
    // The grids clamp a point beyond the box into their border cells after converting its cell coordinate to int,
    // which a position of 1e294 m overflows. kMaxBoxLengths box lengths from the box is far beyond any flight of a
    // run and within int for every grid of up to 2^21 cells along an axis.
    constexpr double kMaxBoxLengths = 1000;
    double extent = 0;
    for (int k = 0; k < D; ++k) extent = std::max(extent, w.domain.hi[k] - w.domain.lo[k]);
    for (const Vec<D>& x : q.x)
        for (int k = 0; k < D; ++k)
            if (std::abs(x[k] - 0.5 * (w.domain.lo[k] + w.domain.hi[k])) > (kMaxBoxLengths + 0.5) * extent)
                in.fail("a position lies more than 1000 box lengths from the box");
    std::vector<Wall<D>> planes = w.walls;
    for (Wall<D>& wall : planes) {
        if (in.get<std::uint8_t>() == 0) continue;
        wall.point = in.get<Vec<D>>();
        wall.velocity = in.get<Vec<D>>();
        wall.phase = in.get<double>();
        wall.origin = in.get<double>();
        wall.changed = true;
        if (!allFinite(std::vector<Vec<D>>{wall.point, wall.velocity}) || !std::isfinite(wall.phase) ||
            !std::isfinite(wall.origin))
            in.fail("a plane's motion is not finite");
    }
    std::vector<Motion<D>> motions;
    for (const SurfaceWall<D>& wall : w.surfaces) {
        Motion<D> m = wall.motion;
        if (in.get<std::uint8_t>() != 0) {
            m.velocity = in.get<Vec<D>>();
            m.phase = in.get<double>();
            m.axis = in.get<Ang<D>>();
            m.omega = in.get<double>();
            m.origin = in.get<double>();
            m.baseRot.m = in.get<decltype(m.baseRot.m)>();
            m.baseShift = in.get<Vec<D>>();
            m.baseRotated = in.get<std::uint8_t>() != 0;
            m.rebased = true;
            bool finite = allFinite(std::vector<Vec<D>>{m.velocity, m.baseShift}) && std::isfinite(m.phase) &&
                          std::isfinite(m.omega) && std::isfinite(m.origin);
            for (int k = 0; k < kAngDim<D>; ++k) finite = finite && std::isfinite(m.axis[k]);
            for (const auto& row : m.baseRot.m)
                for (double a : row) finite = finite && std::isfinite(a);
            if (!finite) in.fail("a wall's motion is not finite");
        }
        motions.push_back(m);
    }
    q.nTdm = nTdm;
    p = std::move(q);
    w.time = time;
    w.walls = std::move(planes);
    for (std::size_t k = 0; k < motions.size(); ++k) w.surfaces[k].motion = motions[k];
    for (Wall<D>& wall : w.walls) wall.moveTo(time);
}

template void saveWorld<2>(ByteWriter&, const World<2>&);
template void saveWorld<3>(ByteWriter&, const World<3>&);
template void loadWorld<2>(ByteReader&, World<2>&);
template void loadWorld<3>(ByteReader&, World<3>&);

}  // namespace haet
