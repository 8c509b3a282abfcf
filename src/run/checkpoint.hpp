#pragma once
// A run's checkpoints on disk (docs/scenario.md, "Resuming"; the format: io/checkpoint.hpp): checkpoint_NNNNNN.haet in
// the run directory, each written atomically, the last two kept, so that a run killed while writing one still has the
// one before; and the search of `haet run --resume` for the newest one that is whole.
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "io/checkpoint.hpp"
#include "io/series.hpp"
#include "io/vtk.hpp"
#include "scenario/definition.hpp"

namespace haet {

/// "checkpoint_000007.haet" for sequence number 7.
std::string checkpointFileName(std::uint64_t sequence);

/// The checkpoints in dir, newest (highest sequence number) first.
std::vector<std::filesystem::path> listCheckpoints(const std::filesystem::path& dir);

/// Writes checkpoint `sequence` (the whole file's bytes) atomically, then removes those older than the one before
/// it. Throws IoError.
void writeCheckpoint(const std::filesystem::path& dir, std::uint64_t sequence, std::string_view bytes);

/// A checkpoint read for a resume: its bytes and the parsed view into them.
struct ResumePoint {
    std::filesystem::path path;
    std::string bytes;
    CheckpointFile file;
};

/// The newest checkpoint of dir that is whole: a truncated or corrupt one is reported on log and the one before it
/// taken. Throws CheckpointError when none is whole (naming each and what is wrong with it), when the newest whole
/// one is of a later format (FutureVersion), or of another scenario or of this one changed in a key that is not safe
/// to change (OtherScenario, naming the key); ScenarioError-like std::invalid_argument when dir has no checkpoint.
ResumePoint findCheckpoint(const std::filesystem::path& dir, const Scenario& sc, std::ostream& log);

/// One checkpoint file, to start a run of `sc` from: throws CheckpointError (naming the file) when it is not whole,
/// cannot be read, of a later format or of another scenario.
ResumePoint readCheckpoint(const std::filesystem::path& file, const Scenario& sc);

/// Throws CheckpointError (OtherScenario) naming the first key in which `saved` ("key = value" lines, as
/// Scenario::stateKeys) and the scenario differ.
void checkStateKeys(const std::string& saved, const Scenario& sc);

/// A collection's entries in a checkpoint, and back (the file rewritten).
void savePvd(ByteWriter& out, const PvdCollection& c);
void loadPvd(ByteReader& in, PvdCollection& c);

/// What a checkpoint records of series.csv: the length of its text, its rows and the text's CRC-32.
struct SeriesMark {
    std::uint64_t bytes = 0, rows = 0;
    std::uint32_t crc = 0;
};
void saveSeriesMark(ByteWriter& out, const SeriesWriter& series);
SeriesMark loadSeriesMark(ByteReader& in);
/// The series a resumed run goes on from: the first mark.bytes of `text` (series.csv as the stopped run left it,
/// at least as long: it is flushed before each checkpoint). Throws std::invalid_argument naming the file when it does
/// not begin with the rows the checkpoint counts.
std::string seriesAtCheckpoint(std::string text, const SeriesMark& mark, const std::filesystem::path& series,
                               const std::filesystem::path& checkpoint);
/// A file's bytes; empty when it cannot be read.
std::string readFileText(const std::filesystem::path& p);

}  // namespace haet
