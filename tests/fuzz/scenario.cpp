// Fuzz target: a scenario from memory as `haet check` takes it (scenario/loader.hpp, parseScenario, with the checks
// it calls), then what `check` prints (describeScenario: the world built, its particles inserted, the engines set up)
// into a stream that discards it. Every bad input must be a ScenarioError or std::invalid_argument (the two errors
// `haet` reports with exit code 2); anything else escaping, a crash, a hang or a sanitizer report is a finding.
//
// The scenario is named as if it lay in examples/, so that the seeds' relative paths (meshes/*.stl) resolve. A
// scenario that asks for more than kMaxParticles particles is loaded and checked but not described: inserting a
// million particles is work, not a defect, and would only slow the fuzzer down.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <string_view>

#include "run/runner.hpp"
#include "scenario/loader.hpp"

namespace {

constexpr std::size_t kMaxParticles = 4000;

class NullBuffer : public std::streambuf {
protected:
    int overflow(int c) override { return c; }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::filesystem::path file = std::filesystem::path(HAET_SOURCE_DIR) / "examples" / "fuzz.toml";
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const haet::Scenario sc = haet::parseScenario(text, file);
        std::size_t requested = 0;
        for (const haet::InsertDef& in : sc.inserts) requested += in.count;
        if (requested > kMaxParticles) return 0;
        NullBuffer buffer;
        std::ostream out(&buffer);
        haet::describeScenario(sc, out);
    } catch (const haet::ScenarioError&) {
    } catch (const std::invalid_argument&) {
    }
    return 0;
}
