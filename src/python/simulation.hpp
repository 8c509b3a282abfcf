#pragma once
// The Python module's Simulation (docs/python.md): a RunSession driven from a script, its particles as numpy arrays
// that view the store. Shared by the binding files: simulation.cpp (making, running, outputs), particles.cpp (the
// views and the changes made through them), walls.cpp (the walls and changes of their motion), module.cpp (the
// module, its exceptions).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "run/runner.hpp"
#include "run/session.hpp"
#include "scenario/definition.hpp"

namespace haet::python {

namespace py = pybind11;

/// The store's arrays a script may view, one entry each in the change book.
enum class Field { Positions, Velocities, Spins, Radii, Masses, Materials, Flags, Forces, Torques, Count };

class Simulation {
public:
    /// Opens the run of `sc`; out empty: a temporary directory, removed by close().
    Simulation(const Scenario& sc, const std::filesystem::path& out, int threads, const std::filesystem::path& from);
    ~Simulation();

    /// Runs to time `until` [s] (GIL released); raises on a blow-up, a stop by a signal, an output that failed.
    void run(double until);
    /// n time steps of the time-driven engine.
    void step(std::uint64_t n);
    std::string finish();
    void close();

    RunSession& session();
    const RunSession& session() const;
    bool closed() const { return !run_; }
    const std::filesystem::path& directory() const { return dir_; }
    int dimension() const { return sc_.dimension; }
    const Scenario& scenario() const { return sc_; }

    // ---- the store's arrays (particles.cpp) ----
    /// A numpy array viewing `f` of the store, owned by `self` (the array's base keeps it alive). Valid until the
    /// next call that advances or changes the particles. Remembers the bytes it shows, so that a write is seen.
    py::object view(py::object self, Field f);
    /// 1 for a time-driven particle, 0 for an event-driven one (a copy).
    py::array modes();
    py::array ids();
    /// Tells the engine of any write made through the views since they were handed out (before the run goes on).
    void commit();
    /// Brings the World's particles to the run's time, once after each change of the run.
    void current();
    void markChanged() { changed_ = true; }
    void addParticles(py::array_t<double> positions, py::array_t<double> radii, py::object velocities,
                      py::object material);
    void remove(py::array_t<std::uint64_t> ids);
    py::array gravity();
    void setGravity(py::array_t<double> g);

private:
    template <int D>
    py::object viewOf(py::object self, Field f);
    template <int D>
    void commitOf();
    template <int D>
    void addOf(py::array_t<double> positions, py::array_t<double> radii, py::object velocities, int material);
    template <int D>
    void removeOf(py::array_t<std::uint64_t> ids);
    void requireOpen() const;

    Scenario sc_;
    std::filesystem::path dir_;
    bool temporary_ = false;
    std::unique_ptr<RunSession> run_;
    /// What each view showed when it was handed out (empty: not handed out since the last commit).
    std::vector<std::string> shown_ = std::vector<std::string>(static_cast<int>(Field::Count));
    bool changed_ = false;  ///< gravity or a wall's motion set, or particles changed by the module itself
    /// The World's particles are at the run's time (synchronised since it last went on): a second synchronise
    /// would overwrite what a view wrote with the event-driven engine's own copy.
    bool current_ = false;
};

/// The Python exception types (module.cpp).
struct Errors {
    static py::object& scenario();
    static py::object& simulation();
    static py::object& checkpoint();
};

void bindSimulation(py::module_& m);
void bindParticles(py::class_<Simulation>& c);
void bindWalls(py::class_<Simulation>& c);
/// A scenario from a Python dict: its TOML text (a dict of tables, lists of tables as [[arrays of tables]]).
std::string tomlOfDict(const py::dict& d);

}  // namespace haet::python
