#pragma once
// Editing scenario text in tests: where a key is, and a variant with one piece replaced.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <string>

namespace haet::testing {

/// 1-based line of the first occurrence of `needle` in `text`.
inline int lineOf(const std::string& text, const std::string& needle) {
    const auto at = text.find(needle);
    EXPECT_NE(at, std::string::npos) << needle;
    return 1 + int(std::count(text.begin(), text.begin() + std::ptrdiff_t(at), '\n'));
}

/// `text` with the first occurrence of `from` replaced by `to`.
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

}  // namespace haet::testing
