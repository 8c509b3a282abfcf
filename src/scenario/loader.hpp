#pragma once
// Scenario files: TOML in SI units (format and every key: docs/scenario.md). This is the only place that parses a
// scenario; everything below works on the validated definition structs.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "scenario/definition.hpp"

namespace haet {

/// Reads, parses and validates a scenario file. Relative `file` paths of [[insert]] blocks are resolved against the
/// scenario file's directory. Throws ScenarioError ("file:line: key: what is wrong") on the first problem found;
/// keys are dotted paths with 1-based indices into arrays of tables, e.g. "insert[2].radius".
///
/// `overrides` ("KEY=VALUE", the command line's `--set`) replace or add values of the file before it is validated,
/// in order: KEY is a key path as the errors write it ("tdm.dt", "insert[2].count", "domain.hi"), VALUE a TOML
/// value ("1e-5", "[0.04, 0.06]", "\"gear5\"", or a bare word taken as a string: "edm"). They are validated like the
/// file's values; an error in one names the override, "file (--set KEY=VALUE): key: what is wrong". A relative
/// `file` path given by an override is resolved against the working directory. Scenario::overrides records them.
Scenario loadScenario(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

/// Same as loadScenario, for text already in memory; `file` names the source in messages and locates relative paths.
Scenario parseScenario(std::string_view text, const std::filesystem::path& file,
                       const std::vector<std::string>& overrides = {});

/// The text of a scenario file, read to at most kMaxScenarioBytes. Throws ScenarioError for a directory, a file that
/// cannot be read, a longer one (a device such as /dev/zero) or one that holds NUL bytes.
inline constexpr std::size_t kMaxScenarioBytes = std::size_t(16) << 20;
std::string readScenarioText(const std::filesystem::path& file);

/// FNV-1a 64-bit hash of `bytes` as 16 lower-case hex digits (Scenario::hash).
std::string fnv1a64Hex(std::string_view bytes);

}  // namespace haet
