#include "io/table.hpp"

#include <charconv>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "io/atomic_file.hpp"

namespace haet {

namespace {
std::vector<std::string> splitCells(const std::string& line) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream in(line);
    while (std::getline(in, cell, ',')) {
        while (!cell.empty() && (cell.back() == '\r' || cell.back() == ' ')) cell.pop_back();
        while (!cell.empty() && cell.front() == ' ') cell.erase(cell.begin());
        cells.push_back(cell);
    }
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    return cells;
}
}  // namespace

int CsvTable::column(const std::string& name) const {
    for (std::size_t c = 0; c < columns.size(); ++c)
        if (columns[c] == name) return static_cast<int>(c);
    return -1;
}

std::vector<double> CsvTable::values(int c) const {
    std::vector<double> v;
    v.reserve(rows.size());
    for (const auto& r : rows) v.push_back(r[static_cast<std::size_t>(c)]);
    return v;
}

CsvTable readCsvTable(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) throw IoError(path, "cannot be read");
    CsvTable t;
    std::string line;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        if (line.empty() || line == "\r") continue;
        std::vector<std::string> cells = splitCells(line);
        if (t.columns.empty()) {
            t.columns = std::move(cells);
            continue;
        }
        if (cells.size() != t.columns.size())
            throw std::invalid_argument(path.string() + ":" + std::to_string(lineNo) + ": " +
                                        std::to_string(cells.size()) + " cells, the header has " +
                                        std::to_string(t.columns.size()));
        std::vector<double> row(cells.size(), std::numeric_limits<double>::quiet_NaN());
        for (std::size_t c = 0; c < cells.size(); ++c) {
            if (cells[c].empty()) continue;
            const char* b = cells[c].data();
            const char* e = b + cells[c].size();
            auto [ptr, ec] = std::from_chars(b, e, row[c]);
            if (ec != std::errc() || ptr != e)
                throw std::invalid_argument(path.string() + ":" + std::to_string(lineNo) + ": column " + t.columns[c] +
                                            ": not a number: " + cells[c]);
        }
        t.rows.push_back(std::move(row));
    }
    if (t.columns.empty()) throw std::invalid_argument(path.string() + ": empty file, no header row");
    return t;
}

}  // namespace haet
