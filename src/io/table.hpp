#pragma once
// Numeric CSV tables as written by the runner (series.csv) and the benchmarks: one header row of column names,
// then rows of numbers; an empty cell is a missing value (NaN).
#include <filesystem>
#include <string>
#include <vector>

namespace haet {

struct CsvTable {
    std::vector<std::string> columns;
    std::vector<std::vector<double>> rows;  ///< rows[r][c]; NaN where the cell is empty

    /// Index of a column by name, or -1.
    int column(const std::string& name) const;
    /// All values of one column.
    std::vector<double> values(int c) const;
};

/// Reads a numeric CSV file. Throws IoError when the file cannot be read, std::invalid_argument naming the file,
/// line and column for a cell that is not a number or a row of the wrong width.
CsvTable readCsvTable(const std::filesystem::path& path);

}  // namespace haet
