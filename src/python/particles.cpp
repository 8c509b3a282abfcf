// The particles as numpy arrays that view the store (core/particles.hpp) without copying, and the changes made
// through them: each view remembers the bytes it showed; before the run goes on, a view whose bytes differ makes the
// engine start again from the changed state (RunSession::stateChanged), as after any outside change.
#include <pybind11/stl.h>

#include <algorithm>
#include <cstring>
#include <unordered_map>

#include "python/simulation.hpp"
#include "world/world.hpp"

namespace haet::python {
namespace {

struct Layout {
    void* data;
    std::size_t count;       // particles
    std::size_t components;  // per particle: 1 (a scalar), D, or the angular dimension
    std::size_t itemBytes;   // of one component
    py::dtype dtype;
};

template <class T>
py::dtype dtypeOf() {
    return py::dtype::of<T>();
}

template <class V>
Layout layoutOf(std::vector<V>& a, std::size_t components, py::dtype dt, std::size_t item) {
    return {a.data(), a.size(), components, item, dt};
}

template <int D>
Layout fieldLayout(Particles<D>& p, Field f) {
    constexpr std::size_t A = kAngDim<D>;
    switch (f) {
        case Field::Positions:
            return layoutOf(p.x, D, dtypeOf<double>(), 8);
        case Field::Velocities:
            return layoutOf(p.v, D, dtypeOf<double>(), 8);
        case Field::Spins:
            return layoutOf(p.w, A, dtypeOf<double>(), 8);
        case Field::Radii:
            return layoutOf(p.radius, 1, dtypeOf<double>(), 8);
        case Field::Masses:
            return layoutOf(p.mass, 1, dtypeOf<double>(), 8);
        case Field::Materials:
            return layoutOf(p.material, 1, dtypeOf<std::uint16_t>(), 2);
        case Field::Flags:
            return layoutOf(p.flags, 1, dtypeOf<std::uint8_t>(), 1);
        case Field::Forces:
            return layoutOf(p.f, D, dtypeOf<double>(), 8);
        case Field::Torques:
            return layoutOf(p.torque, A, dtypeOf<double>(), 8);
        case Field::Count:
            break;
    }
    throw std::logic_error("unknown field");
}

std::string bytesOf(const Layout& l) {
    return std::string(static_cast<const char*>(l.data), l.count * l.components * l.itemBytes);
}

template <int D>
World<D>& worldOf(Simulation& s) {
    World<D>* w = s.session().world<D>();
    if (!w) throw std::logic_error("simulation: no World of this dimension");
    return *w;
}

}  // namespace

template <int D>
py::object Simulation::viewOf(py::object self, Field f) {
    RunSession& s = session();
    current();
    Particles<D>& p = worldOf<D>(*this).particles;
    if ((f == Field::Forces || f == Field::Torques) && !p.hasTdmState()) return py::none();
    const Layout l = fieldLayout(p, f);
    // A scalar per particle is (N,); a vector (N, k) with the store's strides (a Vec<k> is k packed doubles).
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(l.count)};
    std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(l.components * l.itemBytes)};
    if (l.components > 1 || f == Field::Positions || f == Field::Velocities || f == Field::Forces) {
        shape.push_back(static_cast<py::ssize_t>(l.components));
        strides.push_back(static_cast<py::ssize_t>(l.itemBytes));
    }
    py::array a(l.dtype, shape, strides, l.data, self);
    // The hybrid does not follow changes in place (Driver::stateChanged): its views are read-only.
    const bool writable = std::string(s.method()) != "haet";
    if (!writable)
        a.attr("setflags")(py::arg("write") = false);
    else if (shown_[static_cast<int>(f)].empty())
        shown_[static_cast<int>(f)] = bytesOf(l);
    return a;
}

py::object Simulation::view(py::object self, Field f) {
    return dimension() == 2 ? viewOf<2>(self, f) : viewOf<3>(self, f);
}

template <int D>
void Simulation::commitOf() {
    Particles<D>& p = worldOf<D>(*this).particles;
    bool changed = changed_, inverse = false;
    for (int k = 0; k < static_cast<int>(Field::Count); ++k) {
        std::string& was = shown_[k];
        if (was.empty()) continue;
        const Field f = static_cast<Field>(k);
        const Layout l = fieldLayout(p, f);
        const bool differs =
            was.size() != l.count * l.components * l.itemBytes || std::memcmp(was.data(), l.data, was.size()) != 0;
        std::string().swap(was);
        if (!differs) continue;
        changed = true;
        inverse = inverse || f == Field::Masses || f == Field::Radii || f == Field::Flags;
    }
    changed_ = false;
    if (!changed) return;
    if (inverse)  // 1/m and 1/I as Particles::add computes them; a frozen particle has none
        for (std::size_t i = 0; i < p.size(); ++i) {
            p.invMass[i] = p.frozen(i) ? 0.0 : 1.0 / p.mass[i];
            p.invInertia[i] = p.frozen(i) ? 0.0 : 1.0 / p.inertia(i);
        }
    session().stateChanged();
}

void Simulation::commit() {
    requireOpen();
    if (dimension() == 2)
        commitOf<2>();
    else
        commitOf<3>();
}

void Simulation::current() {
    if (current_) return;
    session().synchronise();
    current_ = true;
}

py::array Simulation::ids() {
    current();
    auto copy = [](const auto& v) { return py::array_t<std::uint64_t>(static_cast<py::ssize_t>(v.size()), v.data()); };
    return dimension() == 2 ? copy(worldOf<2>(*this).particles.id) : copy(worldOf<3>(*this).particles.id);
}

py::array Simulation::modes() {
    current();
    auto of = [](const auto& p) {
        py::array_t<std::uint8_t> m(static_cast<py::ssize_t>(p.size()));
        auto r = m.mutable_unchecked<1>();
        for (std::size_t i = 0; i < p.size(); ++i) r(i) = i < p.tdmCount() ? 1 : 0;
        return m;
    };
    return dimension() == 2 ? of(worldOf<2>(*this).particles) : of(worldOf<3>(*this).particles);
}

template <int D>
void Simulation::addOf(py::array_t<double> positions, py::array_t<double> radii, py::object velocities, int material) {
    World<D>& w = worldOf<D>(*this);
    Particles<D>& p = w.particles;
    const auto x = positions.unchecked<2>();
    const auto r = radii.unchecked<1>();
    const py::ssize_t n = x.shape(0);
    if (x.shape(1) != D || r.shape(0) != n)
        throw std::invalid_argument("add_particles: positions (N, " + std::to_string(D) + ") and radii (N,)");
    py::array_t<double> vel = velocities.is_none() ? py::array_t<double>(std::vector<py::ssize_t>{n, D})
                                                   : velocities.cast<py::array_t<double>>();
    if (velocities.is_none()) std::fill(vel.mutable_data(), vel.mutable_data() + n * D, 0.0);
    const auto v = vel.unchecked<2>();
    if (v.shape(0) != n || v.shape(1) != D)
        throw std::invalid_argument("add_particles: velocities (N, " + std::to_string(D) + ")");
    for (py::ssize_t i = 0; i < n; ++i)
        if (!(r(i) > 0)) throw std::invalid_argument("add_particles: radii must be > 0");
    std::uint64_t next = session().takeIds(static_cast<std::uint64_t>(n));
    const std::size_t first = p.size();
    const double density = sc_.materials[material].density;
    for (py::ssize_t i = 0; i < n; ++i) {
        Vec<D> xi, vi;
        for (int k = 0; k < D; ++k) {
            xi[k] = x(i, k);
            vi[k] = v(i, k);
        }
        p.add(xi, vi, Ang<D>::zero(), r(i), density, static_cast<std::uint16_t>(material), next++);
    }
    session().added(first);
}

void Simulation::addParticles(py::array_t<double> positions, py::array_t<double> radii, py::object velocities,
                              py::object material) {
    commit();
    current();
    int mat = 0;
    if (py::isinstance<py::str>(material)) {
        const std::string name = material.cast<std::string>();
        mat = -1;
        for (std::size_t k = 0; k < sc_.materials.size(); ++k)
            if (sc_.materials[k].name == name) mat = static_cast<int>(k);
        if (mat < 0) throw std::invalid_argument("add_particles: no material \"" + name + "\"");
    } else if (!material.is_none()) {
        mat = material.cast<int>();
        if (mat < 0 || mat >= static_cast<int>(sc_.materials.size()))
            throw std::invalid_argument("add_particles: material index out of range");
    }
    if (dimension() == 2)
        addOf<2>(positions, radii, velocities, mat);
    else
        addOf<3>(positions, radii, velocities, mat);
}

template <int D>
void Simulation::removeOf(py::array_t<std::uint64_t> ids) {
    Particles<D>& p = worldOf<D>(*this).particles;
    const auto q = ids.unchecked<1>();
    std::vector<std::uint32_t> which;
    std::unordered_map<std::uint64_t, std::uint32_t> at;
    for (std::size_t i = 0; i < p.size(); ++i) at[p.id[i]] = static_cast<std::uint32_t>(i);
    for (py::ssize_t k = 0; k < q.shape(0); ++k) {
        const auto it = at.find(q(k));
        if (it == at.end()) throw std::invalid_argument("remove: no particle with id " + std::to_string(q(k)));
        which.push_back(it->second);
    }
    std::sort(which.begin(), which.end());
    which.erase(std::unique(which.begin(), which.end()), which.end());
    session().remove(which);
}

void Simulation::remove(py::array_t<std::uint64_t> ids) {
    commit();
    current();
    if (dimension() == 2)
        removeOf<2>(ids);
    else
        removeOf<3>(ids);
}

py::array Simulation::gravity() {
    auto of = [](const auto& w) {
        return py::array_t<double>(static_cast<py::ssize_t>(w.domain.gravity.c.size()), w.domain.gravity.c.data());
    };
    return dimension() == 2 ? of(worldOf<2>(*this)) : of(worldOf<3>(*this));
}

void Simulation::setGravity(py::array_t<double> g) {
    current();
    auto set = [&](auto& w) {
        const auto q = g.unchecked<1>();
        if (static_cast<std::size_t>(q.shape(0)) != w.domain.gravity.c.size())
            throw std::invalid_argument("gravity: one component per dimension");
        for (py::ssize_t k = 0; k < q.shape(0); ++k) w.domain.gravity[k] = q(k);
    };
    if (std::string(session().method()) == "haet")
        throw std::invalid_argument("hybrid runs take no change of gravity yet");
    if (dimension() == 2)
        set(worldOf<2>(*this));
    else
        set(worldOf<3>(*this));
    changed_ = true;
}

void bindParticles(py::class_<Simulation>& c) {
    struct Entry {
        const char* name;
        Field field;
        const char* doc;
    };
    static const Entry entries[] = {
        {"positions", Field::Positions, "centre positions (N, D) [m]"},
        {"velocities", Field::Velocities, "velocities (N, D) [m/s]"},
        {"angular_velocities", Field::Spins, "angular velocities: (N,) about z in 2D, (N, 3) in 3D [rad/s]"},
        {"radii", Field::Radii, "radii (N,) [m] (a polygon's: its circumradius)"},
        {"masses", Field::Masses, "masses (N,) [kg] (2D: per unit depth); 1/m and 1/I follow a write"},
        {"materials", Field::Materials, "material indices (N,) into the scenario's [materials], uint16"},
        {"flags", Field::Flags, "flag bits (N,), uint8: haet.FROZEN (1) for a particle that is not integrated"},
        {"forces", Field::Forces, "forces of the last force pass (N, D) [N]; None in a pure event-driven run"},
        {"torques", Field::Torques, "torques of the last force pass [N m]; None in a pure event-driven run"},
    };
    for (const Entry& e : entries) {
        const Field f = e.field;
        c.def_property_readonly(
            e.name, [f](py::object self) { return self.cast<Simulation&>().view(self, f); },
            (std::string(e.doc) +
             ". A numpy view of the particle store: no copy, valid until the run goes on or particles are added "
             "or removed; writing into it changes the state, and the engine is told before the run goes on.")
                .c_str());
    }
    c.def_property_readonly("ids", &Simulation::ids, "stable particle ids (N,), uint64 (a copy)")
        .def_property_readonly("modes", &Simulation::modes,
                               "1 for a time-driven particle, 0 for an event-driven one (N,), uint8 (a copy)")
        .def_property_readonly("n_particles", [](Simulation& s) { return py::len(s.ids()); })
        .def_property("gravity", &Simulation::gravity, &Simulation::setGravity,
                      "gravitational acceleration (D,) [m/s^2]; set it between runs (a copy)")
        .def("add_particles", &Simulation::addParticles, py::arg("positions"), py::arg("radii"),
             py::arg("velocities") = py::none(), py::arg("material") = py::none(),
             "Adds spheres (disks in 2D) as an inlet does: positions (N, D) [m], radii (N,) [m], velocities "
             "(N, D) [m/s] (default: at rest), material: a name or index (default: the first); mass from its "
             "density. Their ids come from the counter the inlets use: never one a particle of the run had.")
        .def("remove", &Simulation::remove, py::arg("ids"), "Removes the particles with these ids, as an outlet does.");
}

}  // namespace haet::python
