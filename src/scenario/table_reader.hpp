#pragma once
// The scenario loader's reader of one TOML table (scenario/loader.cpp, scenario/walls.cpp,
// scenario/flow_loader.cpp): typed values with the dotted key path and the line of each, so that every error is
// "file:line: key: what is wrong".
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scenario/definition.hpp"
#include "scenario/text.hpp"

namespace haet {

inline const char* const kAxisName[3] = {"x", "y", "z"};

/// Reads the values of one TOML table and knows the dotted key path of each, so that every error names the key
/// and the line it came from (the value's line, or the table's when the key is missing).
class TableReader {
public:
    TableReader(const toml::table& table, std::string path, std::string file)
        : table_(table), path_(std::move(path)), file_(std::move(file)) {}

    const std::string& path() const { return path_; }
    const std::string& file() const { return file_; }
    const toml::table& table() const { return table_; }

    std::string keyPath(std::string_view key) const {
        return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
    }
    SourcePos tablePos() const { return posOfNode(table_); }
    SourcePos posOf(std::string_view key) const {
        if (const toml::node* n = table_.get(key)) return posOfNode(*n);
        return tablePos();
    }
    /// Whether the value of `key` was given on the command line (`--set`), not in the file.
    bool fromOverride(std::string_view key) const {
        const toml::node* n = table_.get(key);
        return n && n->source().path && *n->source().path != file_;
    }
    bool has(std::string_view key) const { return table_.contains(key); }

    [[noreturn]] void fail(std::string_view key, const std::string& what) const {
        throw ScenarioError(posOf(key), keyPath(key), what);
    }
    [[noreturn]] void failTable(const std::string& what) const { throw ScenarioError(tablePos(), path_, what); }

    /// Rejects any key not in `allowed`; reports the first one in file order so the message is stable.
    void allowOnly(std::initializer_list<std::string_view> allowed) const {
        // An override's key comes first (its value holds the override's name), then the file's in line order.
        const toml::key* first = nullptr;
        auto before = [&](const toml::key& a, const toml::key& b) {
            const bool oa = fromOverride(a.str()), ob = fromOverride(b.str());
            return oa != ob ? oa : a.source().begin.line < b.source().begin.line;
        };
        for (auto&& [k, v] : table_) {
            if (std::find(allowed.begin(), allowed.end(), std::string_view(k.str())) != allowed.end()) continue;
            if (!first || before(k, *first)) first = &k;
        }
        if (first) {
            const SourcePos pos =
                fromOverride(first->str()) ? posOf(first->str()) : SourcePos{file_, int(first->source().begin.line)};
            throw ScenarioError(pos, keyPath(first->str()), "unknown key");
        }
    }

    /// Rejects `key` when present: it does not apply in this configuration (`why` says which one would need it).
    void forbid(std::string_view key, const std::string& why) const {
        if (has(key)) fail(key, why);
    }

    std::optional<double> number(std::string_view key) const {
        const toml::node* n = table_.get(key);
        if (!n) return std::nullopt;
        const std::optional<double> v = asNumber(*n);
        if (!v) fail(key, "expected a number");
        if (!std::isfinite(*v)) fail(key, "must be finite");
        return v;
    }
    double requiredNumber(std::string_view key) const {
        const auto v = number(key);
        if (!v) fail(key, "is required");
        return *v;
    }

    std::optional<std::int64_t> integer(std::string_view key) const {
        const toml::node* n = table_.get(key);
        if (!n) return std::nullopt;
        if (const auto* i = n->as_integer()) return i->get();
        fail(key, "expected an integer");
    }

    std::optional<std::string> string(std::string_view key) const {
        const toml::node* n = table_.get(key);
        if (!n) return std::nullopt;
        if (const auto* s = n->as_string()) return s->get();
        fail(key, "expected a string");
    }
    std::string requiredString(std::string_view key) const {
        auto s = string(key);
        if (!s) fail(key, "is required");
        return *s;
    }

    std::optional<bool> boolean(std::string_view key) const {
        const toml::node* n = table_.get(key);
        if (!n) return std::nullopt;
        if (const auto* b = n->as_boolean()) return b->get();
        fail(key, "expected a boolean (true or false)");
    }

    /// An array of exactly `dim` numbers; components beyond `dim` are zero.
    std::optional<Vec3d> vector(std::string_view key, int dim) const {
        const toml::node* n = table_.get(key);
        if (!n) return std::nullopt;
        const std::string expected = "expected an array of " + std::to_string(dim) + " numbers";
        const toml::array* a = n->as_array();
        if (!a || int(a->size()) != dim) fail(key, expected);
        Vec3d out{0, 0, 0};
        for (int k = 0; k < dim; ++k) {
            const auto v = asNumber(*a->get(std::size_t(k)));
            if (!v) fail(key, expected);
            if (!std::isfinite(*v)) fail(key, "must be finite");
            out[std::size_t(k)] = *v;
        }
        return out;
    }
    Vec3d requiredVector(std::string_view key, int dim) const {
        auto v = vector(key, dim);
        if (!v) fail(key, "is required");
        return *v;
    }

    /// An array of arrays of exactly `dim` numbers each (points, vertices); an error names the element, 1-based.
    std::optional<std::vector<Vec3d>> vectors(std::string_view key, int dim) const {
        const toml::node* n = table_.get(key);
        if (!n) return std::nullopt;
        const toml::array* a = n->as_array();
        if (!a) fail(key, "expected an array of points, each an array of " + std::to_string(dim) + " numbers");
        std::vector<Vec3d> out;
        for (std::size_t q = 0; q < a->size(); ++q) {
            const std::string at = "element " + std::to_string(q + 1) + ": ";
            const toml::array* v = a->get(q)->as_array();
            if (!v || int(v->size()) != dim) fail(key, at + "expected an array of " + std::to_string(dim) + " numbers");
            Vec3d p{0, 0, 0};
            for (int k = 0; k < dim; ++k) {
                const auto x = asNumber(*v->get(std::size_t(k)));
                if (!x) fail(key, at + "expected an array of " + std::to_string(dim) + " numbers");
                if (!std::isfinite(*x)) fail(key, at + "must be finite");
                p[std::size_t(k)] = *x;
            }
            out.push_back(p);
        }
        return out;
    }

    std::optional<std::array<bool, 3>> booleans(std::string_view key, int dim) const {
        const toml::node* n = table_.get(key);
        if (!n) return std::nullopt;
        const std::string expected = "expected an array of " + std::to_string(dim) + " booleans";
        const toml::array* a = n->as_array();
        if (!a || int(a->size()) != dim) fail(key, expected);
        std::array<bool, 3> out{false, false, false};
        for (int k = 0; k < dim; ++k) {
            const auto* b = a->get(std::size_t(k))->as_boolean();
            if (!b) fail(key, expected);
            out[std::size_t(k)] = b->get();
        }
        return out;
    }

    /// An array of integers, each at least `min`.
    std::optional<std::vector<int>> integers(std::string_view key, int min) const {
        const toml::node* n = table_.get(key);
        if (!n) return std::nullopt;
        const std::string expected = "expected an array of integers >= " + std::to_string(min);
        const toml::array* a = n->as_array();
        if (!a) fail(key, expected);
        std::vector<int> out;
        for (std::size_t k = 0; k < a->size(); ++k) {
            const auto* v = a->get(k)->as_integer();
            if (!v || v->get() < min || v->get() > 1000000) fail(key, expected);
            out.push_back(static_cast<int>(v->get()));
        }
        return out;
    }

    /// A string that must be one of `options`; returns the matching value.
    template <class E>
    std::optional<E> choice(std::string_view key, std::initializer_list<std::pair<std::string_view, E>> options) const {
        const auto s = string(key);
        if (!s) return std::nullopt;
        for (const auto& [name, value] : options)
            if (*s == name) return value;
        std::string list;
        for (const auto& [name, value] : options) list += (list.empty() ? "" : ", ") + inQuotes(name);
        fail(key, "must be one of " + list + " (got " + inQuotes(*s) + ")");
    }

    const toml::table* subTable(std::string_view key) const {
        const toml::node* n = table_.get(key);
        if (!n) return nullptr;
        if (const auto* t = n->as_table()) return t;
        fail(key, "expected a table");
    }

    /// An array whose every element is a table ([[key]] blocks, or an inline array of inline tables).
    const toml::array* arrayOfTables(std::string_view key) const {
        const toml::node* n = table_.get(key);
        if (!n) return nullptr;
        const toml::array* a = n->as_array();
        if (!a || !a->is_array_of_tables()) fail(key, "expected an array of tables ([[" + std::string(key) + "]])");
        return a;
    }

private:
    /// A value of the file by its line; one set on the command line by the override that set it (its TOML source
    /// is named "--set KEY=VALUE", applyOverride).
    SourcePos posOfNode(const toml::node& n) const {
        const auto& src = n.source();
        if (src.path && *src.path != file_) return {file_ + " (" + *src.path + ")", 0};
        return {file_, int(src.begin.line)};
    }

    static std::optional<double> asNumber(const toml::node& n) {
        if (const auto* i = n.as_integer()) return double(i->get());
        if (const auto* f = n.as_floating_point()) return f->get();
        return std::nullopt;
    }

    const toml::table& table_;
    std::string path_;
    std::string file_;
};

/// Stand-in for an optional table that is absent, so its defaults are read through the same code.
inline const toml::table& emptyTable() {
    static const toml::table empty;
    return empty;
}

/// The unit vector along `key`'s value: scaled by its largest component first, so that [1e200, 1e200] is a
/// direction and not an overflow to infinity. Fails with the key when the vector is zero (or not finite).
inline Vec3d unitVector(const TableReader& r, std::string_view key, Vec3d v) {
    double big = 0;
    for (double c : v) big = std::max(big, std::abs(c));
    if (!(big > 0) || !std::isfinite(big)) r.fail(key, "must be nonzero and finite");
    for (double& c : v) c /= big;
    const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (double& c : v) c /= len;
    return v;
}

}  // namespace haet
