#pragma once
// A small JSON writer for run metadata (run.json): build a JsonObject, then dump() it.
// Keys keep insertion order; adding an existing key replaces its value in place. Non-finite numbers
// (NaN, ±inf) have no JSON form and are written as null. Strings are expected to be UTF-8 and are
// passed through, with quotes, backslashes and control characters escaped.
#include <concepts>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace haet {

class JsonObject {
public:
    JsonObject();
    ~JsonObject();
    JsonObject(const JsonObject&);
    JsonObject(JsonObject&&) noexcept;
    JsonObject& operator=(const JsonObject&);
    JsonObject& operator=(JsonObject&&) noexcept;

    JsonObject& add(std::string_view key, double value);
    JsonObject& add(std::string_view key, bool value);
    JsonObject& add(std::string_view key, std::string_view value);
    /// Without this overload a string literal would convert to bool.
    JsonObject& add(std::string_view key, const char* value) { return add(key, std::string_view(value)); }
    JsonObject& add(std::string_view key, const JsonObject& value);
    JsonObject& add(std::string_view key, const std::vector<double>& values);
    JsonObject& add(std::string_view key, const std::vector<std::string>& values);
    /// Any integer type, written exactly (not through double).
    template <std::integral T>
    requires(!std::same_as<T, bool>) JsonObject& add(std::string_view key, T value) {
        if constexpr (std::is_signed_v<T>)
            return addSigned(key, static_cast<std::int64_t>(value));
        else
            return addUnsigned(key, static_cast<std::uint64_t>(value));
    }

    /// Pretty-printed with `indent` spaces per level; indent <= 0 gives one compact line. No final newline.
    std::string dump(int indent = 2) const;

    bool empty() const;
    std::size_t size() const;

private:
    struct Member;  // defined in json.cpp, where JsonObject is complete (objects nest)
    JsonObject& addSigned(std::string_view key, std::int64_t value);
    JsonObject& addUnsigned(std::string_view key, std::uint64_t value);
    Member& slot(std::string_view key);
    void dumpTo(std::string& out, int indent, int depth) const;

    std::vector<Member> members_;
};

/// `s` as a quoted JSON string literal.
std::string jsonQuote(std::string_view s);

}  // namespace haet
