#pragma once
// CSV files as HAET writes them (series.csv, fields_NAME.csv, contacts_K.csv, final.csv), read for tests: lines
// split at commas, '#' comment lines skipped, the first line the header. An empty cell (a column a row has no value
// for, such as the pressure of a box with walls) and a cell that is no number read as NaN.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace haet::testing {

/// Every line of the file (comment lines too), split at commas: row 0 is the header of a HAET file.
inline std::vector<std::vector<std::string>> csvRows(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::vector<std::vector<std::string>> rows;
    for (std::string line; std::getline(in, line);) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        if (!line.empty() && line.back() == ',') cells.emplace_back();
        rows.push_back(cells);
    }
    return rows;
}

/// A CSV file with a header: its columns by name, its rows as numbers.
struct CsvTable {
    std::vector<std::string> header;
    std::vector<std::vector<double>> rows;

    /// The index of column `name`; a failure of the test when there is none.
    std::size_t col(const std::string& name) const {
        const auto it = std::find(header.begin(), header.end(), name);
        EXPECT_NE(it, header.end()) << "no column " << name;
        return it == header.end() ? 0 : static_cast<std::size_t>(it - header.begin());
    }
    double at(std::size_t row, const std::string& name) const { return rows.at(row).at(col(name)); }
    std::vector<double> column(const std::string& name) const {
        const std::size_t c = col(name);
        std::vector<double> v;
        for (const auto& r : rows) v.push_back(c < r.size() ? r[c] : std::nan(""));
        return v;
    }
};

/// The file at p: its first line not starting with '#' the header, every later one a row of numbers.
inline CsvTable readCsv(const std::filesystem::path& p) {
    CsvTable t;
    bool head = true;
    for (auto& cells : csvRows(p)) {
        if (!cells.empty() && !cells[0].empty() && cells[0][0] == '#') continue;
        if (head) {
            t.header = std::move(cells);
            head = false;
            continue;
        }
        std::vector<double> r;
        for (const std::string& c : cells) {  // a cell that is not a number (a material's name) reads as NaN
            char* end = nullptr;
            const double v = std::strtod(c.c_str(), &end);
            r.push_back(c.empty() || *end != '\0' ? std::nan("") : v);
        }
        t.rows.push_back(std::move(r));
    }
    return t;
}

}  // namespace haet::testing
