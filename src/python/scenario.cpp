// from_dict: a scenario given as Python values becomes TOML text for the one loader (scenario/loader.hpp), so that it
// gets the same checks and errors as a file.
#include <toml++/toml.h>

#include <sstream>

#include "python/simulation.hpp"

namespace haet::python {
namespace {

toml::table tableOf(const py::dict& d, const std::string& where);

std::string keyPath(const std::string& where, const std::string& key) {
    return where.empty() ? key : where + "." + key;
}

toml::array arrayOf(const py::handle& seq, const std::string& where);

// One value, given to `sink`: bool before int (a Python bool is an int), numpy values through float() and tolist().
template <class Sink>
void emit(Sink&& sink, const py::handle& v, const std::string& at) {
    if (py::isinstance<py::bool_>(v))
        sink(v.cast<bool>());
    else if (py::isinstance<py::int_>(v))
        sink(v.cast<std::int64_t>());
    else if (py::isinstance<py::str>(v))
        sink(v.cast<std::string>());
    else if (py::isinstance<py::dict>(v))
        sink(tableOf(v.cast<py::dict>(), at));
    else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v))
        sink(arrayOf(v, at));
    else if (py::hasattr(v, "tolist") && !py::isinstance<py::float_>(v))
        emit(sink, v.attr("tolist")(), at);
    else if (py::isinstance<py::float_>(v) || py::hasattr(v, "__float__"))
        sink(py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>());
    else
        throw py::type_error("from_dict: " + at + ": a " + std::string(py::str(v.get_type().attr("__name__"))) +
                             " is no TOML value (bool, int, float, str, dict, list)");
}

toml::array arrayOf(const py::handle& seq, const std::string& where) {
    toml::array a;
    std::size_t k = 0;
    for (const py::handle& v : seq)
        emit([&](auto&& x) { a.push_back(std::forward<decltype(x)>(x)); }, v, where + "[" + std::to_string(++k) + "]");
    return a;
}

toml::table tableOf(const py::dict& d, const std::string& where) {
    toml::table t;
    for (const auto& [k, v] : d) {
        if (!py::isinstance<py::str>(k)) throw py::type_error("from_dict: " + where + ": keys are strings");
        const std::string key = k.cast<std::string>();
        emit([&](auto&& x) { t.insert_or_assign(key, std::forward<decltype(x)>(x)); }, v, keyPath(where, key));
    }
    return t;
}

}  // namespace

std::string tomlOfDict(const py::dict& d) {
    std::ostringstream os;
    os << tableOf(d, "");
    return os.str() + "\n";
}

}  // namespace haet::python
