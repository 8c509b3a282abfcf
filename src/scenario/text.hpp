#pragma once
// Small text helpers shared by the scenario loader and the particle-file readers (error messages).
#include <sstream>
#include <string>
#include <string_view>

namespace haet {

/// `s` without the blanks (spaces, tabs, line ends) at its ends.
inline std::string_view trim(std::string_view s) {
    const auto first = s.find_first_not_of(" \t\r\n");
    if (first == std::string_view::npos) return {};
    const auto last = s.find_last_not_of(" \t\r\n");
    return s.substr(first, last - first + 1);
}

inline std::string inQuotes(std::string_view s) { return "\"" + std::string(s) + "\""; }

/// A number as an error message shows it: 6 significant digits.
inline std::string formatNumber(double v) {
    std::ostringstream os;
    os.precision(6);
    os << v;
    return os.str();
}

}  // namespace haet
