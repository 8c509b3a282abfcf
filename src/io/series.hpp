#pragma once
// Time series output as CSV (one row per sample, header line first).
// The whole text is kept in memory and the file is replaced atomically on flush(), so the file on disk is
// always a complete CSV: a crashed or killed run loses at most the rows since the last flush. The cost is
// memory and a full rewrite per flush, which is small for the few columns and thousands of rows a run
// records; it is not meant for per-particle data.
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace haet {

class SeriesWriter {
public:
    /// Starts the series and writes the header at once. Rows are also flushed automatically by row() once
    /// `autoFlush` of wall time has passed since the last flush. Throws IoError.
    SeriesWriter(std::filesystem::path path, std::vector<std::string> columns,
                 std::chrono::milliseconds autoFlush = std::chrono::milliseconds(1000));
    /// Flushes unwritten rows; errors are swallowed here (a destructor must not throw), so call flush()
    /// at the end of a run to see them.
    ~SeriesWriter();
    SeriesWriter(const SeriesWriter&) = delete;
    SeriesWriter& operator=(const SeriesWriter&) = delete;

    /// Appends one row, one value per column; an empty optional is written as an empty cell. Doubles are
    /// printed in the shortest form that reads back to the same value. Throws std::invalid_argument if the
    /// number of values differs from the number of columns, IoError if an automatic flush fails.
    void row(const std::vector<std::optional<double>>& values);

    /// Rewrites the file with every row so far. Throws IoError.
    void flush();

    /// Replaces the rows with those of `text` (header included, as text() had it; a resumed run's series up to its
    /// checkpoint) and rewrites the file. Throws std::invalid_argument unless text starts with this series' header
    /// and ends a row, IoError if the file cannot be written.
    void resume(std::string text, std::size_t rows);

    const std::filesystem::path& path() const { return path_; }
    const std::string& text() const { return text_; }
    std::size_t rows() const { return rows_; }

private:
    std::filesystem::path path_;
    std::size_t columns_;
    std::chrono::milliseconds autoFlush_;
    std::chrono::steady_clock::time_point lastFlush_;
    std::string text_;
    std::size_t rows_ = 0;
    bool dirty_ = false;
};

}  // namespace haet
