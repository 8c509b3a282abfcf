#pragma once
// The run directory: made if missing, and cleared of what an earlier run of HAET wrote there, so that no old
// run.json, snapshot or picture sits beside the new run's (docs/scenario.md, "Outputs"). Only files whose names HAET
// writes are removed (run.json, series.csv, final.png, the .pvd collections and their numbered snapshots, temporary
// files of atomic writes); anything else in the directory is left alone.
#include <filesystem>
#include <string>

namespace haet {

/// Whether `name` (a file name, no directory) is one HAET's run writes.
bool isRunOutputName(const std::string& name);

/// Creates `dir` (and its parents) and removes the files of an earlier run in it. Throws IoError naming the path.
void prepareRunDirectory(const std::filesystem::path& dir);

}  // namespace haet
