#pragma once
// Small text helpers shared by the scenario loader and the particle-file readers (error messages).
#include <sstream>
#include <string>
#include <string_view>

namespace haet {

inline std::string inQuotes(std::string_view s) { return "\"" + std::string(s) + "\""; }

/// A number as an error message shows it: 6 significant digits.
inline std::string formatNumber(double v) {
    std::ostringstream os;
    os.precision(6);
    os << v;
    return os.str();
}

}  // namespace haet
