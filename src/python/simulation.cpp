// Simulation: making a run (a file, TOML text, a dict), running it in pieces with the GIL released and the stop
// signals caught only meanwhile, its outputs (series, run.json) and its checkpoints (docs/python.md).
#include "python/simulation.hpp"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <stdlib.h>

#include <cmath>
#include <iostream>
#include <optional>
#include <system_error>

#include "io/table.hpp"
#include "scenario/loader.hpp"
#include "world/world.hpp"

namespace haet::python {
namespace {

/// The thread the module was imported on: Python runs its signal handlers there only, so only a run advanced there
/// catches Ctrl-C itself.
unsigned long gMainThread = 0;

std::filesystem::path temporaryDirectory() {
    std::string pattern = (std::filesystem::temp_directory_path() / "haet-XXXXXX").string();
    if (!mkdtemp(pattern.data()))
        throw std::system_error(errno, std::generic_category(), "cannot make a temporary output directory");
    return pattern;
}

}  // namespace

Simulation::Simulation(const Scenario& sc, const std::filesystem::path& out, int threads,
                       const std::filesystem::path& from)
    : sc_(sc), dir_(out) {
    if (dir_.empty()) {
        dir_ = temporaryDirectory();
        temporary_ = true;
    }
    RunOptions opt;
    opt.outDir = dir_;
    opt.threads = threads;
    opt.quiet = true;
    opt.progress = ProgressDisplay::Off;
    opt.stopSignals = StopScope::Advance;
    opt.startFrom = from;
    try {
        py::gil_scoped_release free;
        run_ = RunSession::open(sc_, opt, std::cerr);
    } catch (...) {
        if (temporary_) std::filesystem::remove_all(dir_);
        throw;
    }
}

Simulation::~Simulation() {
    try {
        close();
    } catch (const std::exception& e) {  // a destructor cannot raise: say it
        std::cerr << "haet: closing a simulation: " << e.what() << "\n";
    }
}

void Simulation::requireOpen() const {
    if (!run_) throw std::invalid_argument("the simulation is closed");
}

RunSession& Simulation::session() {
    requireOpen();
    return *run_;
}
const RunSession& Simulation::session() const {
    requireOpen();
    return *run_;
}

void Simulation::run(double until) {
    RunSession& s = session();
    if (!std::isfinite(until)) throw std::invalid_argument("run: until must be a finite time [s]");
    commit();
    s.setStopScope(PyThread_get_thread_ident() == gMainThread ? StopScope::Advance : StopScope::Never);
    bool going;
    current_ = false;
    {
        py::gil_scoped_release free;
        going = s.advance(until);
    }
    if (going) return;
    switch (s.status()) {
        case RunStatus::BlewUp:
            throw SimulationError(s.statusText());
        case RunStatus::Interrupted:  // Ctrl-C: the state is whole, at the end of a step; the run may go on
            PyErr_SetNone(PyExc_KeyboardInterrupt);
            throw py::error_already_set();
        case RunStatus::Terminated:
            PyErr_SetObject(PyExc_SystemExit, py::int_(143).ptr());  // SIGTERM: end the script, as by default
            throw py::error_already_set();
        default:
            throw std::invalid_argument("run: the run is finished");
    }
}

void Simulation::step(std::uint64_t n) {
    const double dt = session().dt();
    if (dt <= 0) throw std::invalid_argument("step: a pure event-driven run has no time steps; use run(until=...)");
    run(session().time() + static_cast<double>(n) * dt);
}

std::string Simulation::finish() {
    RunSession& s = session();
    commit();
    current_ = false;
    {
        py::gil_scoped_release free;
        s.finish();
    }
    return s.statusText();
}

void Simulation::close() {
    if (!run_) return;
    std::unique_ptr<RunSession> r = std::move(run_);
    r->finish();
    r.reset();
    if (temporary_) {
        std::error_code ec;
        std::filesystem::remove_all(dir_, ec);
    }
}

namespace {

py::dict seriesOf(Simulation& sim) {
    sim.session().flush();
    const CsvTable t = readCsvTable(sim.directory() / "series.csv");
    py::dict d;
    for (std::size_t c = 0; c < t.columns.size(); ++c) {
        const std::vector<double> v = t.values(static_cast<int>(c));
        d[py::str(t.columns[c])] = py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
    }
    return d;
}

py::object runInfoOf(Simulation& sim) {
    const py::object json = py::module_::import("json");
    const py::object open = py::module_::import("builtins").attr("open");
    py::object f = open((sim.directory() / "run.json").string());
    py::object j = json.attr("load")(f);
    f.attr("close")();
    return j;
}

std::unique_ptr<Simulation> make(const Scenario& sc, const std::optional<std::filesystem::path>& out, int threads,
                                 const std::filesystem::path& from = {}) {
    return std::make_unique<Simulation>(sc, out.value_or(std::filesystem::path()), threads, from);
}

using OptPath = std::optional<std::filesystem::path>;
using Sets = std::vector<std::string>;

}  // namespace

void bindSimulation(py::module_& m) {
    gMainThread = py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
    py::class_<Simulation> c(m, "Simulation", R"(A run of a scenario, advanced from Python.

Made by from_file, from_string, from_dict or load. The outputs of `haet run` (series.csv, snapshots, run.json,
final.csv, final.png) go to `out` on their schedules; without `out` to a temporary directory that close() removes.
Use it as a context manager, or call finish() and close().)");
    c.def_static(
         "from_file",
         [](const std::filesystem::path& path, const OptPath& out, int threads, const Sets& set) {
             return make(loadScenario(path, set), out, threads);
         },
         py::arg("path"), py::kw_only(), py::arg("out") = py::none(), py::arg("threads") = 0, py::arg("set") = Sets{},
         "The run of a scenario file; `set`: overrides 'KEY=VALUE' as `haet run --set` takes them.")
        .def_static(
            "from_string",
            [](const std::string& toml, const OptPath& out, int threads, const Sets& set,
               const std::filesystem::path& path) { return make(parseScenario(toml, path, set), out, threads); },
            py::arg("toml"), py::kw_only(), py::arg("out") = py::none(), py::arg("threads") = 0,
            py::arg("set") = Sets{}, py::arg("path") = std::filesystem::path("<string>"),
            "The run of a scenario given as TOML text; `path` names it in errors and locates relative files.")
        .def_static(
            "from_dict",
            [](const py::dict& d, const OptPath& out, int threads, const Sets& set) {
                const std::string toml = tomlOfDict(d);
                std::optional<Scenario> sc;
                try {
                    sc = parseScenario(toml, "<dict>", set);
                } catch (const ScenarioError& e) {
                    // A line of the TOML text made from the dict would point nowhere the caller can see (an
                    // override's error names the override instead, and stays as it is).
                    if (e.pos().file != "<dict>") throw;
                    throw ScenarioError({"<dict>", 0}, e.key(), e.message());
                }
                return make(*sc, out, threads);
            },
            py::arg("scenario"), py::kw_only(), py::arg("out") = py::none(), py::arg("threads") = 0,
            py::arg("set") = Sets{},
            "The run of a scenario given as a dict of its TOML tables (lists of dicts: arrays of tables).")
        .def_static(
            "load",
            [](const std::filesystem::path& checkpoint, const std::filesystem::path& scenario, const OptPath& out,
               int threads, const Sets& set) { return make(loadScenario(scenario, set), out, threads, checkpoint); },
            py::arg("checkpoint"), py::arg("scenario"), py::kw_only(), py::arg("out") = py::none(),
            py::arg("threads") = 0, py::arg("set") = Sets{},
            "The run of `scenario` from the state save() wrote; new outputs from the saved time on.")
        .def("run", &Simulation::run, py::arg("until"),
             "Runs to simulated time `until` [s]. Ctrl-C stops it at the end of a step and raises KeyboardInterrupt "
             "(the run may go on); a blow-up raises SimulationError, an output that cannot be written OSError.")
        .def("step", &Simulation::step, py::arg("n") = 1,
             "n time steps (time-driven and hybrid runs; a pure event-driven run raises ValueError: use run()).")
        .def("finish", &Simulation::finish,
             "Writes the last state as `haet run` does at its end; returns run.json's status. Once.")
        .def("close", &Simulation::close, "finish(), then removes a temporary output directory. Idempotent.")
        .def(
            "save",
            [](Simulation& s, const std::filesystem::path& p) {
                s.commit();
                s.session().save(p);
            },
            py::arg("path"), "Writes a checkpoint of the state now to `path`, for Simulation.load.")
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](Simulation& s, py::args) { s.close(); })
        .def_property_readonly(
            "time", [](const Simulation& s) { return s.session().time(); }, "simulated time [s]")
        .def_property_readonly(
            "steps", [](const Simulation& s) { return s.session().steps(); },
            "time steps taken (0 for a pure event-driven run)")
        .def_property_readonly(
            "dt", [](const Simulation& s) { return s.session().dt(); },
            "the time step [s] (0 for a pure event-driven run)")
        .def_property_readonly("method", [](const Simulation& s) { return std::string(s.session().method()); })
        .def_property_readonly("dimension", &Simulation::dimension)
        .def_property_readonly("directory", &Simulation::directory, "where the outputs go")
        .def_property_readonly("status", [](const Simulation& s) { return s.session().statusText(); })
        .def_property_readonly("closed", &Simulation::closed)
        .def_property_readonly("series", &seriesOf,
                               "series.csv's rows so far: a dict of numpy arrays by column (NaN: empty cell)")
        .def_property_readonly("run_info", &runInfoOf, "run.json as last written (at the start, at finish())");
    bindParticles(c);
    bindWalls(c);
}

}  // namespace haet::python
