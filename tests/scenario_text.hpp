#pragma once
// Editing scenario text in tests: where a key is, and a variant with one piece replaced.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <fstream>
#include <sstream>
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

/// The text of the scene examples/NAME (tests run the scenes users have, or variants edited from them).
inline std::string sceneText(const std::string& name) {
    std::ifstream in(std::string(HAET_SOURCE_DIR) + "/examples/" + name);
    EXPECT_TRUE(in.good()) << "examples/" << name;
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

}  // namespace haet::testing
