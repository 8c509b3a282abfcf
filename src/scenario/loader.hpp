#pragma once
// Scenario files: TOML in SI units (format and every key: docs/scenario.md). This is the only place that parses a
// scenario; everything below works on the validated definition structs.
#include <filesystem>
#include <string>
#include <string_view>

#include "scenario/definition.hpp"

namespace haet {

/// Reads, parses and validates a scenario file. Relative `file` paths of [[insert]] blocks are resolved against the
/// scenario file's directory. Throws ScenarioError ("file:line: key: what is wrong") on the first problem found;
/// keys are dotted paths with 1-based indices into arrays of tables, e.g. "insert[2].radius".
Scenario loadScenario(const std::filesystem::path& file);

/// Same as loadScenario, for text already in memory; `file` names the source in messages and locates relative paths.
Scenario parseScenario(std::string_view text, const std::filesystem::path& file);

/// FNV-1a 64-bit hash of `bytes` as 16 lower-case hex digits (Scenario::hash).
std::string fnv1a64Hex(std::string_view bytes);

}  // namespace haet
