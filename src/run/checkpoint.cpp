#include "run/checkpoint.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <ostream>
#include <sstream>
#include <system_error>

#include "io/atomic_file.hpp"

namespace haet {

namespace {

/// The sequence number of a checkpoint's file name, or 0 when the name is not one.
std::uint64_t sequenceOf(const std::string& name) {
    constexpr std::string_view pre = "checkpoint_", post = ".haet";
    if (name.size() <= pre.size() + post.size() || name.compare(0, pre.size(), pre) != 0 ||
        name.compare(name.size() - post.size(), post.size(), post) != 0)
        return 0;
    const std::string digits = name.substr(pre.size(), name.size() - pre.size() - post.size());
    if (digits.size() > 18 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
        return 0;
    return std::stoull(digits);
}

std::map<std::string, std::string> keyLines(const std::string& text) {
    std::map<std::string, std::string> m;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        const std::size_t eq = line.find(" = ");
        if (eq != std::string::npos) m[line.substr(0, eq)] = line.substr(eq + 3);
    }
    return m;
}

std::string readWhole(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    if (!in) throw CheckpointError(CheckpointFault::Corrupt, "cannot be read");
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
}

}  // namespace

std::string readFileText(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
}

void savePvd(ByteWriter& out, const PvdCollection& c) {
    out.put<std::uint64_t>(c.entries().size());
    for (const PvdCollection::Entry& e : c.entries()) {
        out.put<double>(e.time);
        out.putString(e.file);
        out.put<std::int32_t>(e.part);
    }
}

void loadPvd(ByteReader& in, PvdCollection& c) {
    const auto n = in.get<std::uint64_t>();
    if (n > in.rest().size() / 20) in.fail("more snapshots than the bytes left hold");
    std::vector<PvdCollection::Entry> entries(n);
    for (PvdCollection::Entry& e : entries) {
        e.time = in.get<double>();
        e.file = in.getString();
        e.part = in.get<std::int32_t>();
    }
    c.assign(std::move(entries));
}

void saveSeriesMark(ByteWriter& out, const SeriesWriter& series) {
    out.put<std::uint64_t>(series.text().size());
    out.put<std::uint64_t>(series.rows());
    out.put<std::uint32_t>(crc32Of(series.text()));
}

SeriesMark loadSeriesMark(ByteReader& in) {
    SeriesMark m;
    m.bytes = in.get<std::uint64_t>();
    m.rows = in.get<std::uint64_t>();
    m.crc = in.get<std::uint32_t>();
    return m;
}

std::string seriesAtCheckpoint(std::string text, const SeriesMark& mark, const std::filesystem::path& series,
                               const std::filesystem::path& checkpoint) {
    if (text.size() < mark.bytes || crc32Of(std::string_view(text).substr(0, mark.bytes)) != mark.crc)
        throw std::invalid_argument(series.string() + ": --resume: the file does not begin with the " +
                                    std::to_string(mark.rows) + " rows written before " +
                                    checkpoint.filename().string() + " (changed or replaced since)");
    text.resize(mark.bytes);
    return text;
}

std::string checkpointFileName(std::uint64_t sequence) { return fmt::format("checkpoint_{:06d}.haet", sequence); }

std::vector<std::filesystem::path> listCheckpoints(const std::filesystem::path& dir) {
    std::vector<std::pair<std::uint64_t, std::filesystem::path>> found;
    std::error_code ec;
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
        if (const std::uint64_t s = sequenceOf(it->path().filename().string()); s > 0 && it->is_regular_file(ec))
            found.emplace_back(s, it->path());
    std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<std::filesystem::path> out;
    for (auto& f : found) out.push_back(std::move(f.second));
    return out;
}

void writeCheckpoint(const std::filesystem::path& dir, std::uint64_t sequence, std::string_view bytes) {
    writeFileAtomic(dir / checkpointFileName(sequence), bytes);
    for (const std::filesystem::path& p : listCheckpoints(dir)) {
        if (sequenceOf(p.filename().string()) + 1 >= sequence) continue;  // this one and the one before stay
        std::error_code ec;
        if (!std::filesystem::remove(p, ec) && ec) throw IoError(p, "cannot remove an old checkpoint: " + ec.message());
    }
}

void checkStateKeys(const std::string& saved, const Scenario& sc) {
    if (saved == sc.stateKeys) return;
    const auto a = keyLines(saved), b = keyLines(sc.stateKeys);
    auto differ = [&](const std::string& key, const std::string& was, const std::string& now) {
        // A file the scenario names (Scenario::stateKeys: "KEY (contents) = fnv1a64 HASH of PATH").
        constexpr std::string_view contents = " (contents)";
        if (key.size() > contents.size() && key.compare(key.size() - contents.size(), contents.size(), contents) == 0) {
            const std::size_t of = now.find(" of ");
            const std::string file = of != std::string::npos ? now.substr(of + 4) : key;
            throw CheckpointError(CheckpointFault::OtherScenario,
                                  fmt::format("{}: the file of {} has changed since the checkpoint was written "
                                              "(checkpoint: {}, now: {}); a resumed run would not be the same run",
                                              file, key.substr(0, key.size() - contents.size()),
                                              was.substr(0, was.find(" of ")), now.substr(0, of)));
        }
        throw CheckpointError(CheckpointFault::OtherScenario,
                              fmt::format("the checkpoint is of another scenario, or of this one with {} changed "
                                          "(checkpoint: {}, scenario: {}); only duration and [output] may change "
                                          "on resume (docs/scenario.md, \"Resuming\")",
                                          key, was, now));
    };
    for (const auto& [key, value] : a) {
        const auto it = b.find(key);
        if (it == b.end()) differ(key, value, "not set");
        if (it->second != value) differ(key, value, it->second);
    }
    for (const auto& [key, value] : b)
        if (!a.count(key)) differ(key, "not set", value);
    differ("the order of its tables", "", "");  // same lines, another text: cannot happen for the loader's text
}

namespace {

/// A checkpoint file read and parsed (CheckpointError when it cannot be read or is not whole).
ResumePoint parsedCheckpoint(const std::filesystem::path& file) {
    ResumePoint r;
    r.path = file;
    r.bytes = readWhole(file);
    r.file = parseCheckpoint(r.bytes);
    return r;
}

void checkScenarioOf(const ResumePoint& r, const Scenario& sc) {
    try {
        ByteReader keys = r.file.section("SCEN");
        checkStateKeys(keys.getString(), sc);
        if (r.file.header.scenarioHash != sc.stateHash)
            throw CheckpointError(CheckpointFault::OtherScenario, "the checkpoint is of another scenario (hash " +
                                                                      r.file.header.scenarioHash + ", this one's " +
                                                                      sc.stateHash + ")");
    } catch (const CheckpointError& e) {
        throw CheckpointError(e.fault(), r.path.string() + ": " + e.what());
    }
}

}  // namespace

ResumePoint readCheckpoint(const std::filesystem::path& file, const Scenario& sc) {
    ResumePoint r;
    try {
        r = parsedCheckpoint(file);
    } catch (const CheckpointError& e) {
        throw CheckpointError(e.fault(), file.string() + ": " + e.what());
    }
    checkScenarioOf(r, sc);
    return r;
}

ResumePoint findCheckpoint(const std::filesystem::path& dir, const Scenario& sc, std::ostream& log) {
    const std::vector<std::filesystem::path> all = listCheckpoints(dir);
    if (all.empty())
        throw std::invalid_argument(dir.string() +
                                    ": --resume: no checkpoint (checkpoint_NNNNNN.haet) in the directory");
    std::string why;
    for (const std::filesystem::path& p : all) {
        ResumePoint r;
        try {
            r = parsedCheckpoint(p);
        } catch (const CheckpointError& e) {
            if (e.fault() == CheckpointFault::FutureVersion)
                throw CheckpointError(e.fault(), p.string() + ": " + e.what());
            // A write that never finished, or a damaged file: the one before it may be whole.
            log << "warning: " << p.string() << ": " << e.what() << "; trying the checkpoint before it\n";
            why += "\n  " + p.string() + ": " + e.what();
            continue;
        }
        checkScenarioOf(r, sc);
        return r;
    }
    throw CheckpointError(CheckpointFault::Corrupt, dir.string() + ": no whole checkpoint to resume from:" + why);
}

}  // namespace haet
