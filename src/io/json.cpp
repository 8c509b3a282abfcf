#include "io/json.hpp"

#include <fmt/format.h>

#include <cmath>
#include <iterator>
#include <variant>

namespace haet {

struct JsonObject::Member {
    std::string key;
    std::variant<bool, std::int64_t, std::uint64_t, double, std::string, std::vector<double>, std::vector<std::string>,
                 JsonObject>
        value;
};

JsonObject::JsonObject() = default;
JsonObject::~JsonObject() = default;
JsonObject::JsonObject(const JsonObject&) = default;
JsonObject::JsonObject(JsonObject&&) noexcept = default;
JsonObject& JsonObject::operator=(const JsonObject&) = default;
JsonObject& JsonObject::operator=(JsonObject&&) noexcept = default;

bool JsonObject::empty() const { return members_.empty(); }
std::size_t JsonObject::size() const { return members_.size(); }

JsonObject::Member& JsonObject::slot(std::string_view key) {
    for (Member& m : members_)
        if (m.key == key) return m;
    members_.push_back(Member{std::string(key), false});
    return members_.back();
}

JsonObject& JsonObject::add(std::string_view key, double value) {
    slot(key).value = value;
    return *this;
}
JsonObject& JsonObject::add(std::string_view key, bool value) {
    slot(key).value = value;
    return *this;
}
JsonObject& JsonObject::add(std::string_view key, std::string_view value) {
    slot(key).value = std::string(value);
    return *this;
}
JsonObject& JsonObject::add(std::string_view key, const JsonObject& value) {
    JsonObject copy = value;  // value may be *this or nested in it; copy before slot() can reallocate
    slot(key).value = std::move(copy);
    return *this;
}
JsonObject& JsonObject::add(std::string_view key, const std::vector<double>& values) {
    slot(key).value = values;
    return *this;
}
JsonObject& JsonObject::add(std::string_view key, const std::vector<std::string>& values) {
    slot(key).value = values;
    return *this;
}
JsonObject& JsonObject::addSigned(std::string_view key, std::int64_t value) {
    slot(key).value = value;
    return *this;
}
JsonObject& JsonObject::addUnsigned(std::string_view key, std::uint64_t value) {
    slot(key).value = value;
    return *this;
}

std::string jsonQuote(std::string_view s) {
    std::string out = "\"";
    for (char c : s) {
        switch (c) {
            case '"':
                out += "\\\"";
                break;
            case '\\':
                out += "\\\\";
                break;
            case '\b':
                out += "\\b";
                break;
            case '\f':
                out += "\\f";
                break;
            case '\n':
                out += "\\n";
                break;
            case '\r':
                out += "\\r";
                break;
            case '\t':
                out += "\\t";
                break;
            default:
                if (static_cast<unsigned char>(c) < 0x20)
                    out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
                else
                    out += c;
        }
    }
    return out + "\"";
}

namespace {

// Shortest round-trip form; a ".0" keeps integral values typed as floating point for readers that care
// (Python's json turns "1" into an int).
void appendNumber(std::string& out, double v) {
    if (!std::isfinite(v)) {
        out += "null";
        return;
    }
    const std::string s = fmt::format("{}", v);
    out += s;
    if (s.find_first_not_of("-0123456789") == std::string::npos) out += ".0";
}

}  // namespace

void JsonObject::dumpTo(std::string& out, int indent, int depth) const {
    if (members_.empty()) {
        out += "{}";
        return;
    }
    const bool pretty = indent > 0;
    std::string inner;  // what starts each member's line
    if (pretty) inner.append(1, '\n').append(static_cast<std::size_t>(indent * (depth + 1)), ' ');
    out += '{';
    for (std::size_t k = 0; k < members_.size(); ++k) {
        const Member& m = members_[k];
        if (k > 0) out += ',';
        out += inner;
        out += jsonQuote(m.key);
        out += pretty ? ": " : ":";
        std::visit(
            [&](const auto& v) {
                using T = std::decay_t<decltype(v)>;
                if constexpr (std::is_same_v<T, bool>)
                    out += v ? "true" : "false";
                else if constexpr (std::is_same_v<T, std::int64_t> || std::is_same_v<T, std::uint64_t>)
                    fmt::format_to(std::back_inserter(out), "{}", v);
                else if constexpr (std::is_same_v<T, double>)
                    appendNumber(out, v);
                else if constexpr (std::is_same_v<T, std::string>)
                    out += jsonQuote(v);
                else if constexpr (std::is_same_v<T, std::vector<double>>) {
                    out += '[';
                    for (std::size_t i = 0; i < v.size(); ++i) {
                        if (i > 0) out += pretty ? ", " : ",";
                        appendNumber(out, v[i]);
                    }
                    out += ']';
                } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
                    out += '[';
                    for (std::size_t i = 0; i < v.size(); ++i) {
                        if (i > 0) out += pretty ? ", " : ",";
                        out += jsonQuote(v[i]);
                    }
                    out += ']';
                } else
                    v.dumpTo(out, indent, depth + 1);
            },
            m.value);
    }
    if (pretty) out.append(1, '\n').append(static_cast<std::size_t>(indent * depth), ' ');
    out += '}';
}

std::string JsonObject::dump(int indent) const {
    std::string out;
    dumpTo(out, indent, 0);
    return out;
}

}  // namespace haet
