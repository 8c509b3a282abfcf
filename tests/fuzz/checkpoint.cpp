// Fuzz target: the checkpoint reader (io/checkpoint.hpp, parseCheckpoint) and what a resume then reads from the
// sections, as `haet run --resume` does (run/runner.cpp): the scenario's keys (SCEN), the World's particles (WRLD,
// loadWorld) and the time- or event-driven engine's state (ENGN, made on the loaded World as a resumed run makes
// it). The scenes are examples/drop3d_tiny.toml (3D) and examples/elastic_gas2d.toml (2D, with 8 particles), as
// "tdm" or "edm"; the seeds are checkpoints of their runs, which tests/fuzz/make_checkpoint_seeds.py writes anew after
// a change of the format (kCheckpointVersion).
//
// The first byte picks how the rest is taken: odd, as a whole file (magic, version, length, CRC-32, body), which
// exercises the checks of the header; even, as a body that the target seals with a valid header and checksum, so
// that the fuzzer reaches the sections, which a random change would otherwise never get past the checksum to.
// Bad input is a CheckpointError, or a std::invalid_argument from an engine made on the loaded World (a state the
// engine refuses, such as radii longer than a periodic axis): the two errors `haet run --resume` reports with exit
// code 2. Anything else escaping, a crash, a hang or a sanitizer report is a finding.
#include "io/checkpoint.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "edm/engine.hpp"
#include "run/checkpoint.hpp"
#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world/state.hpp"

namespace {

/// A scene's scenario and world as built for a run, to load a checkpoint's state into (a copy each time).
template <int D>
struct Scene {
    haet::Scenario sc;
    haet::World<D> world;
    haet::TdmSettings tdm;

    explicit Scene(const char* file, std::vector<std::string> sets = {})
        : sc(haet::loadScenario(std::filesystem::path(HAET_SOURCE_DIR) / "examples" / file, sets)),
          world(haet::buildWorld<D>(sc)),
          tdm(haet::tdmSettings<D>(sc, world)) {}
};

/// What a resume reads after the header (findCheckpoint, then runScenario): the scenario's keys and hash, then the
/// World and the engine. The scene is the one of the checkpoint's dimension and method.
template <int D>
void resume(const Scene<D>& scene, const haet::CheckpointFile& f) {
    haet::ByteReader keys = f.section("SCEN");
    haet::checkStateKeys(keys.getString(), scene.sc);
    if (f.header.scenarioHash != scene.sc.stateHash) return;  // refused as of another scenario
    haet::World<D> world = scene.world;
    haet::ByteReader in = f.section("WRLD");
    haet::loadWorld(in, world);
    in.expectEnd();
    haet::ByteReader eng = f.section("ENGN");
    if (f.header.method == "edm") {
        world.particles.dropTdmState();
        haet::EdmSettings es = haet::edmSettings(scene.sc);
        es.holdState = true;
        haet::EdmEngine<D> engine(world, es);
        engine.loadState(eng);
    } else if (f.header.method == "tdm") {
        haet::TdmEngine<D> engine(world, scene.tdm);
        engine.loadState(eng);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const Scene<3> tdm3("drop3d_tiny.toml"), edm3("drop3d_tiny.toml", {"method=edm"});
    static const Scene<2> tdm2("elastic_gas2d.toml", {"insert[1].count=8"}),
        edm2("elastic_gas2d.toml", {"insert[1].count=8", "method=edm"});
    if (size == 0) return 0;
    const std::string_view input(reinterpret_cast<const char*>(data) + 1, size - 1);
    std::string sealed;
    if (!(data[0] & 1)) {
        // encodeCheckpoint's layout: magic, version, body length, CRC-32 of the body, body.
        sealed.append(haet::kCheckpointMagic);
        const std::uint32_t version = haet::kCheckpointVersion;
        const std::uint64_t length = input.size();
        const std::uint32_t crc = haet::crc32Of(input);
        sealed.append(reinterpret_cast<const char*>(&version), sizeof version);
        sealed.append(reinterpret_cast<const char*>(&length), sizeof length);
        sealed.append(reinterpret_cast<const char*>(&crc), sizeof crc);
        sealed.append(input);
    }
    const std::string_view bytes = (data[0] & 1) ? input : std::string_view(sealed);
    try {
        const haet::CheckpointFile f = haet::parseCheckpoint(bytes);
        for (const auto& [tag, body] : f.sections)  // the views lie inside the bytes given
            if (tag.size() != 4 || body.data() < bytes.data() ||
                body.data() + body.size() > bytes.data() + bytes.size())
                __builtin_trap();
        const bool edm = f.header.method == "edm";
        if (f.header.dimension == 3)
            resume(edm ? edm3 : tdm3, f);
        else
            resume(edm ? edm2 : tdm2, f);
    } catch (const haet::CheckpointError&) {
    } catch (const std::invalid_argument&) {
    }
    return 0;
}
