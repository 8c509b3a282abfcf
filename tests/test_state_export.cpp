// The state at the end of a run for a next stage (run/export.hpp): final.csv, read back by `[[insert]] arrangement =
// "file"` in a new scenario, gives the same particles to the bit (positions, velocities, spins, radii, materials,
// frozen flags, image flags, masses); final.data, a LAMMPS data file, the same but for the frozen flags, which
// LAMMPS keeps in groups, and masses to rounding (LAMMPS stores a density). The state compared with is the run's
// last checkpoint, which holds it whole. Scenes: a 3D chute periodic along the flow with a frozen base and spinning
// grains, a 2D periodic gas with friction.
#include <string>
#include <vector>

#include "cli_util.hpp"
#include "io/checkpoint.hpp"
#include "neighbor/pair_list.hpp"
#include "run/checkpoint.hpp"
#include "scenario/loader.hpp"
#include "world/build.hpp"
#include "world/state.hpp"

namespace {

using namespace haet::testing::cli;
namespace fs = std::filesystem;

class StateExport : public Cli {
protected:
    /// Runs examples/SCENE with the overrides into dir_/run; returns its scenario as loaded.
    haet::Scenario run(const std::string& scene, const std::vector<std::string>& sets) {
        std::string args = "run -q '" + std::string(HAET_SOURCE_DIR) + "/examples/" + scene + "' --out '" +
                           (dir_ / "run").string() + "'";
        for (const std::string& s : sets) args += " --set '" + s + "'";
        const Result r = haet(args);
        EXPECT_EQ(r.code, 0) << r.err;
        return haet::loadScenario(std::string(HAET_SOURCE_DIR) + "/examples/" + scene, sets);
    }

    /// The run's last state, from its last checkpoint, in the order of the ids, wrapped into the box as the files are.
    template <int D>
    haet::Particles<D> finalState(const haet::Scenario& sc) {
        haet::World<D> w = haet::buildWorld<D>(sc);
        const std::string bytes = read(haet::listCheckpoints(dir_ / "run").at(0));
        const haet::CheckpointFile f = haet::parseCheckpoint(bytes);
        haet::ByteReader in = f.section("WRLD");
        haet::loadWorld(in, w);
        haet::Particles<D>& p = w.particles;
        p.nTdm = static_cast<std::size_t>(-1);
        haet::wrapPositions(p, w.domain);
        std::vector<std::uint32_t> order(p.size());
        for (std::uint32_t k = 0; k < order.size(); ++k) order[k] = k;
        std::sort(order.begin(), order.end(), [&](auto a, auto b) { return p.id[a] < p.id[b]; });
        p.permute(order);
        return p;
    }

    /// The scene with its inserts replaced by one that reads `file` (format csv or lammps), loaded and built.
    template <int D>
    haet::Particles<D> readBack(const std::string& scene, const std::vector<std::string>& sets, const fs::path& file,
                                const std::string& format, const std::string& material) {
        std::string text = haet::testing::sceneText(scene);
        const std::size_t a = text.find("[[insert]]"), b = text.find("\n[output]");
        text = text.substr(0, a) + "[[insert]]\narrangement = \"file\"\nfile = \"" + file.string() + "\"\nformat = \"" +
               format + "\"\nmaterial = \"" + material + "\"\n" + text.substr(b);
        std::vector<std::string> kept;  // the overrides of the inserts are of the replaced blocks
        for (const std::string& s : sets)
            if (s.rfind("insert[", 0) != 0) kept.push_back(s);
        const haet::Scenario next = haet::parseScenario(text, dir_ / "next.toml", kept);
        return haet::buildWorld<D>(next).particles;
    }

    template <int D>
    void expectSame(const haet::Particles<D>& a, const haet::Particles<D>& b, bool flagsAndMass) {
        ASSERT_EQ(a.size(), b.size());
        ASSERT_GT(a.size(), 0u);
        int spinning = 0, crossed = 0, frozen = 0;
        for (std::size_t i = 0; i < a.size(); ++i) {
            SCOPED_TRACE("particle " + std::to_string(i));
            EXPECT_TRUE(a.x[i] == b.x[i]);
            EXPECT_TRUE(a.v[i] == b.v[i]);
            EXPECT_TRUE(a.w[i] == b.w[i]);
            EXPECT_EQ(a.radius[i], b.radius[i]);
            EXPECT_EQ(a.material[i], b.material[i]);
            EXPECT_TRUE(a.image[i] == b.image[i]);
            if (flagsAndMass) {
                EXPECT_EQ(a.flags[i], b.flags[i]);
                EXPECT_EQ(a.mass[i], b.mass[i]);
            } else {
                EXPECT_NEAR(a.mass[i], b.mass[i], 4e-16 * a.mass[i]);
            }
            spinning += a.w[i] != haet::Ang<D>::zero();
            crossed += a.image[i] != std::array<std::int32_t, D>{};
            frozen += a.frozen(i);
        }
        // The test would not see a lost spin, image flag or frozen flag if the scene had none.
        EXPECT_GT(spinning, 0);
        EXPECT_GT(crossed, 0);
        if (flagsAndMass && D == 3) EXPECT_GT(frozen, 0);
    }
};

const std::vector<std::string> kChute = {"duration=0.05", "insert[2].count=300", "output.snapshot_period=-1"};
const std::vector<std::string> kGas2d = {"duration=0.1", "insert[1].count=300", "materials.grain.friction=0.5",
                                         "contact.tangential=\"spring\"", "output.snapshot_period=-1"};

TEST_F(StateExport, CsvReadsBackToTheSameParticles) {
    const haet::Scenario sc = run("chute3d.toml", kChute);
    expectSame(finalState<3>(sc), readBack<3>("chute3d.toml", kChute, dir_ / "run" / "final.csv", "csv", "glass"),
               true);
    const haet::Scenario sc2 = run("gas2d.toml", kGas2d);
    expectSame(finalState<2>(sc2), readBack<2>("gas2d.toml", kGas2d, dir_ / "run" / "final.csv", "csv", "grain"), true);
}

TEST_F(StateExport, LammpsDataReadsBackToTheSameParticles) {
    const haet::Scenario sc = run("chute3d.toml", kChute);
    expectSame(finalState<3>(sc), readBack<3>("chute3d.toml", kChute, dir_ / "run" / "final.data", "lammps", "glass"),
               false);
    const haet::Scenario sc2 = run("gas2d.toml", kGas2d);
    expectSame(finalState<2>(sc2), readBack<2>("gas2d.toml", kGas2d, dir_ / "run" / "final.data", "lammps", "grain"),
               false);
}

}  // namespace
