// The walls from a script (docs/python.md, "Walls"): what each is and how it moves now, and a change of a wall's
// translation or angular velocity between runs. A change takes effect from the current time with the wall where it
// is: a plane goes on from its point now (Wall::setVelocity), a wall of any other shape from its pose now
// (Motion::rebase); the engine then starts again from the changed state, as after a change of the particles.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "python/simulation.hpp"
#include "world/world.hpp"

namespace haet::python {
namespace {

template <int D>
World<D>& worldOf(Simulation& s) {
    World<D>* w = s.session().world<D>();
    if (!w) throw std::logic_error("simulation: no World of this dimension");
    return *w;
}

const char* kindName(SurfaceKind k) {
    switch (k) {
        case SurfaceKind::Mesh:
            return "mesh";
        case SurfaceKind::Arc:
            return "arc";
        case SurfaceKind::Cylinder:
            return "cylinder";
        case SurfaceKind::Disc:
            return "disc";
    }
    return "wall";
}

template <int N>
py::array_t<double> arrayOf(const Vec<N>& v) {
    return py::array_t<double>(static_cast<py::ssize_t>(N), v.c.data());
}

template <int N>
Vec<N> vecOf(const py::object& o, const char* what) {
    const py::array_t<double> a = o.cast<py::array_t<double>>();
    if (a.ndim() != 1 || a.shape(0) != N)
        throw std::invalid_argument(std::string("set_wall: ") + what + " has " + std::to_string(N) + " components");
    Vec<N> v;
    for (int k = 0; k < N; ++k) {
        v[k] = a.at(k);
        if (!std::isfinite(v[k])) throw std::invalid_argument(std::string("set_wall: ") + what + " is not finite");
    }
    return v;
}

template <class W>
std::string labelOf(const W& w) {
    return "wall " + std::to_string(w.id + 1) + (w.name.empty() ? std::string() : " (\"" + w.name + "\")");
}

template <int D>
py::list wallsOf(Simulation& s) {
    World<D>& w = worldOf<D>(s);
    const double t = s.session().time();
    std::vector<std::pair<int, py::dict>> all;
    for (const Wall<D>& wl : w.walls) {
        py::dict d;
        d["name"] = wl.name;
        d["index"] = wl.id + 1;
        d["kind"] = "plane";
        d["velocity"] = arrayOf(wl.velocity);
        d["angular_velocity"] = py::none();
        d["point"] = arrayOf(wl.pointAt(t));
        d["normal"] = arrayOf(wl.normal);
        all.emplace_back(wl.id, std::move(d));
    }
    for (const SurfaceWall<D>& sw : w.surfaces) {
        const Motion<D>& m = sw.motion;
        const Pose<D> pose = m.at(t);
        py::dict d;
        d["name"] = sw.name;
        d["index"] = sw.id + 1;
        d["kind"] = kindName(sw.kind);
        d["velocity"] = arrayOf(m.velocity);
        if constexpr (D == 2)
            d["angular_velocity"] = m.omega;
        else
            d["angular_velocity"] = arrayOf(m.axis * m.omega);
        d["shift"] = arrayOf(pose.shift);
        py::array_t<double> rot({D, D});
        auto r = rot.mutable_unchecked<2>();
        for (int i = 0; i < D; ++i)
            for (int k = 0; k < D; ++k) r(i, k) = pose.rot.m[i][k];
        d["rotation"] = rot;
        all.emplace_back(sw.id, std::move(d));
    }
    std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    py::list out;
    for (auto& [id, d] : all) out.append(d);
    return out;
}

template <int D>
void setWallOf(Simulation& s, const py::object& which, const py::object& velocity, const py::object& spin) {
    World<D>& w = worldOf<D>(s);
    const std::string method = s.session().method();
    // The hybrid's wall guard takes the walls' speeds and the planes it watches at its start (haet/wall_guard.hpp).
    if (method == "haet") throw std::invalid_argument("set_wall: hybrid runs take no change of a wall's motion yet");
    if (velocity.is_none() && spin.is_none())
        throw std::invalid_argument("set_wall: give velocity, angular_velocity or both");
    Wall<D>* plane = nullptr;
    SurfaceWall<D>* surface = nullptr;
    if (py::isinstance<py::str>(which)) {
        const std::string name = which.cast<std::string>();
        for (Wall<D>& wl : w.walls)
            if (wl.name == name && !plane) plane = &wl;
        for (SurfaceWall<D>& sw : w.surfaces)
            if (sw.name == name && !plane && !surface) surface = &sw;
        if (!plane && !surface) throw std::invalid_argument("set_wall: no wall named \"" + name + "\"");
    } else {
        const int index = which.cast<int>();  // walls[index] of the scenario, 1-based as there
        for (Wall<D>& wl : w.walls)
            if (wl.id + 1 == index) plane = &wl;
        for (SurfaceWall<D>& sw : w.surfaces)
            if (sw.id + 1 == index) surface = &sw;
        if (!plane && !surface)
            throw std::invalid_argument("set_wall: the scenario has no walls[" + std::to_string(index) + "]");
    }
    s.current();
    const double t = s.session().time();
    if (plane) {
        if (!spin.is_none())
            throw std::invalid_argument("set_wall: " + labelOf(*plane) + " is a plane: planes do not rotate");
        plane->setVelocity(vecOf<D>(velocity, "velocity"), t);
    } else {
        // The event-driven engine predicts collisions with planes and static meshes only (docs/physics.md H.6).
        if (method == "edm")
            throw std::invalid_argument("set_wall: " + labelOf(*surface) +
                                        " is no plane: an event-driven run moves only planes");
        Motion<D>& m = surface->motion;
        const Vec<D> v = velocity.is_none() ? m.velocity : vecOf<D>(velocity, "velocity");
        Ang<D> axis = m.axis;
        double omega = m.omega;
        if (!spin.is_none()) {
            if constexpr (D == 2) {
                omega = spin.cast<double>();
                if (!std::isfinite(omega)) throw std::invalid_argument("set_wall: angular_velocity is not finite");
            } else {
                const Vec<3> o = vecOf<3>(spin, "angular_velocity");
                omega = norm(o);
                if (omega > 0) axis = o * (1 / omega);
            }
        }
        m.rebase(t);
        m.velocity = v;
        m.axis = axis;
        m.omega = omega;
    }
    s.markChanged();
}

}  // namespace

void bindWalls(py::class_<Simulation>& c) {
    c.def_property_readonly(
         "walls", [](Simulation& s) { return s.dimension() == 2 ? wallsOf<2>(s) : wallsOf<3>(s); },
         "The scenario's walls in its order, a dict each (a copy): name, index (k of walls[k], from 1), kind "
         "(\"plane\", \"mesh\", \"arc\", \"cylinder\", \"disc\"), velocity (D,) [m/s] (the translation, without an "
         "oscillation), angular_velocity [rad/s] (a plane's: None; 2D: about z; 3D: (3,)); a plane's point now "
         "and normal, another wall's pose now: shift (D,) [m] and rotation (D, D), body point b at rotation b + "
         "shift.")
        .def(
            "set_wall",
            [](Simulation& s, const py::object& wall, const py::object& velocity, const py::object& spin) {
                if (s.dimension() == 2)
                    setWallOf<2>(s, wall, velocity, spin);
                else
                    setWallOf<3>(s, wall, velocity, spin);
            },
            py::arg("wall"), py::kw_only(), py::arg("velocity") = py::none(), py::arg("angular_velocity") = py::none(),
            "Sets the translation velocity (D,) [m/s] and/or the angular velocity [rad/s] (2D: a number, about z; "
            "3D: (3,), its direction the axis) of the wall named `wall` (or walls[wall], from 1), from the current "
            "time on: the wall goes on from where it is, an oscillation goes on in phase, a rotation turns about "
            "the material point that was its centre. Planes translate only; an event-driven run moves planes "
            "only; a hybrid run takes no change. Saved in checkpoints.");
}

}  // namespace haet::python
