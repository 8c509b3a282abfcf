// The module `haet` (docs/python.md): its exceptions and the C++ errors they translate, then the Simulation class.
#include <pybind11/pybind11.h>

#include "io/atomic_file.hpp"
#include "io/checkpoint.hpp"
#include "python/simulation.hpp"
#include "world/world.hpp"

namespace haet::python {

py::object& Errors::scenario() {
    static py::object e;
    return e;
}
py::object& Errors::simulation() {
    static py::object e;
    return e;
}
py::object& Errors::checkpoint() {
    static py::object e;
    return e;
}

namespace {

py::object newException(py::module_& m, const char* name, PyObject* base, const char* doc) {
    py::object e = py::reinterpret_steal<py::object>(
        PyErr_NewExceptionWithDoc((std::string("haet.") + name).c_str(), doc, base, nullptr));
    if (!e) throw py::error_already_set();
    m.attr(name) = e;
    return e;
}

void raise(const py::object& type, const char* what) { PyErr_SetString(type.ptr(), what); }

}  // namespace

}  // namespace haet::python

PYBIND11_MODULE(haet, m) {
    using namespace haet::python;
    m.doc() = "HAET, a granular-flow simulator, driven from Python: docs/python.md.";
    Errors::scenario() = newException(m, "ScenarioError", PyExc_ValueError,
                                      "A scenario that cannot be run; attributes file, line (0: unknown), key and "
                                      "message say where and what.");
    Errors::simulation() = newException(m, "SimulationError", PyExc_RuntimeError,
                                        "The simulation blew up (a NaN, an overlap beyond the limit); the outputs "
                                        "written so far are kept.");
    Errors::checkpoint() = newException(m, "CheckpointError", PyExc_ValueError,
                                        "A checkpoint file that is not whole, of a later format or of another "
                                        "scenario.");
    // Every C++ error a call can end in becomes a Python exception: none ends the interpreter.
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const haet::ScenarioError& e) {
            py::object err = Errors::scenario()(e.what());
            err.attr("file") = e.pos().file;
            err.attr("line") = e.pos().line;
            err.attr("key") = e.key();
            err.attr("message") = e.message();
            PyErr_SetObject(Errors::scenario().ptr(), err.ptr());
        } catch (const haet::SimulationError& e) {
            raise(Errors::simulation(), e.what());
        } catch (const haet::CheckpointError& e) {
            raise(Errors::checkpoint(), e.what());
        } catch (const haet::IoError& e) {
            PyErr_SetString(PyExc_OSError, e.what());
        }
    });
    m.attr("FROZEN") = py::int_(int(haet::kFrozen));
    bindSimulation(m);
}
