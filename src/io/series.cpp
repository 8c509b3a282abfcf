#include "io/series.hpp"

#include <fmt/format.h>

#include <iterator>
#include <stdexcept>

#include "io/atomic_file.hpp"

namespace haet {

namespace {

// RFC 4180 quoting, only where a name needs it.
std::string csvCell(const std::string& s) {
    if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + "\"";
}

}  // namespace

SeriesWriter::SeriesWriter(std::filesystem::path path, std::vector<std::string> columns,
                           std::chrono::milliseconds autoFlush)
    : path_(std::move(path)), columns_(columns.size()), autoFlush_(autoFlush) {
    if (columns.empty()) throw std::invalid_argument("SeriesWriter " + path_.string() + ": no columns");
    for (std::size_t k = 0; k < columns.size(); ++k) {
        if (k > 0) text_ += ',';
        text_ += csvCell(columns[k]);
    }
    text_ += '\n';
    flush();
}

SeriesWriter::~SeriesWriter() {
    if (!dirty_) return;
    try {
        flush();
    } catch (...) {
    }
}

void SeriesWriter::row(const std::vector<std::optional<double>>& values) {
    if (values.size() != columns_)
        throw std::invalid_argument(
            fmt::format("SeriesWriter {}: row has {} values for {} columns", path_.string(), values.size(), columns_));
    auto out = std::back_inserter(text_);
    for (std::size_t k = 0; k < values.size(); ++k) {
        if (k > 0) text_ += ',';
        if (values[k]) fmt::format_to(out, "{}", *values[k]);
    }
    text_ += '\n';
    ++rows_;
    dirty_ = true;
    if (std::chrono::steady_clock::now() - lastFlush_ >= autoFlush_) flush();
}

void SeriesWriter::resume(std::string text, std::size_t rows) {
    const std::string header = text_.substr(0, text_.find('\n') + 1);
    if (text.compare(0, header.size(), header) != 0)
        throw std::invalid_argument(path_.string() + ": the saved rows have another header than this run's");
    if (text.empty() || text.back() != '\n')
        throw std::invalid_argument(path_.string() + ": the saved rows do not end with a whole row");
    text_ = std::move(text);
    rows_ = rows;
    flush();
}

void SeriesWriter::flush() {
    writeFileAtomic(path_, text_);
    lastFlush_ = std::chrono::steady_clock::now();
    dirty_ = false;
}

}  // namespace haet
