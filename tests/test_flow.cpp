// Particles that leave the run (docs/physics.md H): outlets remove exactly the particles inside them, the counts
// balance in every method, the hybrid's books stay balanced, and bad input stops with file:line: key.
// The scene is examples/pour3d.toml, with overrides.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "haet/engine.hpp"
#include "run/flow.hpp"
#include "run/runner.hpp"
#include "scenario/loader.hpp"
#include "scenario_text.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"

namespace haet {
namespace {

namespace fs = std::filesystem;
using testing::lineOf;
using testing::replaced;
using testing::sceneText;

Scenario pour(std::vector<std::string> overrides, const std::string& text = sceneText("pour3d.toml")) {
    return parseScenario(text, "pour3d.toml", overrides);
}

/// A time-driven run driven by hand: after every step the outlet is checked; removed particles were inside, and
/// no particle is left inside.
class TdmHost final : public FlowHost<3> {
public:
    TdmHost(World<3>& w, TdmEngine<3>& e, const OutletDef& o) : w_(w), e_(e), o_(o) {}
    std::size_t eager() const override { return w_.particles.size(); }
    void synchronise() override {}
    void remove(const std::vector<std::uint32_t>& which) override {
        for (const std::uint32_t i : which) {
            EXPECT_TRUE(inside(w_.particles.x[i])) << "particle " << w_.particles.id[i] << " removed outside";
            removed.insert(w_.particles.id[i]);
        }
        removeTimeDriven(w_, e_, which);
    }
    void added(std::size_t first) override { addTimeDriven(w_, e_, first); }
    bool inside(const Vec<3>& x) const {
        double s = 0;
        for (int k = 0; k < 3; ++k) s += (x[k] - o_.point[k]) * o_.normal[k];
        return s >= 0;
    }
    std::set<std::uint64_t> removed;

private:
    World<3>& w_;
    TdmEngine<3>& e_;
    const OutletDef& o_;
};

TEST(Outlet, RemovesExactlyTheParticlesThatCrossIt) {
    // The bed settles through the plane z = 0.006: every particle whose centre is below it after a step leaves at
    // that step, and none other. No batch within the run.
    const std::string text =
        replaced(sceneText("pour3d.toml"), "region = { lo = [0.0, 0.0, 0.0], hi = [0.008, 0.008, 0.003] }",
                 "plane = { point = [0.0, 0.0, 0.006], normal = [0.0, 0.0, -1.0] }");
    const Scenario sc = pour({"duration=0.02"}, text);
    World<3> w = buildWorld<3>(sc);
    TdmEngine<3> eng(w, tdmSettings<3>(sc, w));
    TdmHost host(w, eng, sc.outlets[0]);
    Flow<3> flow(sc, w, eng.settings().dt);
    std::size_t below0 = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i) below0 += host.inside(w.particles.x[i]);
    ASSERT_GT(below0, 20u);
    flow.act(w, host, 0.5 * eng.settings().dt);
    EXPECT_EQ(host.removed.size(), below0);  // at the start: those inside already
    while (w.time < sc.duration) {
        eng.advanceTo(flow.nextTime());
        flow.act(w, host, 0.5 * eng.settings().dt);
        for (std::size_t i = 0; i < w.particles.size(); ++i)
            ASSERT_FALSE(host.inside(w.particles.x[i])) << "left inside at t = " << w.time;
    }
    EXPECT_GT(host.removed.size(), below0);                  // more crossed as the bed settled
    EXPECT_EQ(*flow.row()[0], double(host.removed.size()));  // drain_particles
    EXPECT_EQ(w.particles.size(), 400 - host.removed.size());
    for (const std::uint64_t id : w.particles.id) EXPECT_EQ(host.removed.count(id), 0u);
}

std::vector<std::vector<std::string>> readCsv(const fs::path& p) {
    std::ifstream in(p);
    std::vector<std::vector<std::string>> rows;
    for (std::string line; std::getline(in, line);) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        rows.push_back(cells);
    }
    return rows;
}

/// initial + inserted - removed = present, at every row of series.csv.
void expectBalanced(const fs::path& series, const std::string& method) {
    const auto rows = readCsv(series);
    ASSERT_GT(rows.size(), 5u);
    const auto& h = rows[0];
    auto col = [&](const std::string& name) { return std::size_t(std::find(h.begin(), h.end(), name) - h.begin()); };
    const std::size_t n = col("n_particles"), out = col("drain_particles");
    ASSERT_LT(std::max({n, out}), h.size());
    double removed = 0;
    for (std::size_t r = 1; r < rows.size(); ++r) {
        EXPECT_EQ(std::stod(rows[r][n]), 400 - std::stod(rows[r][out])) << method << " row " << r;
        removed = std::stod(rows[r][out]);
    }
    EXPECT_GT(removed, 5) << method;
    if (method == "haet") {  // the hybrid's energy books: what came in and what left is counted
        const std::size_t u = col("energy_unaccounted"), tot = col("total_energy"), eout = col("energy_out");
        for (std::size_t r = 1; r < rows.size(); ++r)
            EXPECT_LT(std::abs(std::stod(rows[r][u])), 1e-9 * std::stod(rows[r][tot])) << "row " << r;
        EXPECT_GT(std::stod(rows.back()[eout]), 0);
    }
}

class FlowRun : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("haet_flow_" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    fs::path run(const Scenario& sc, const std::string& name, int threads = 0) {
        RunOptions o;
        o.outDir = dir_ / name;
        o.quiet = true;
        o.threads = threads;
        std::ostringstream log;
        EXPECT_EQ(runScenario(sc, o, log), RunStatus::Completed) << log.str();
        return o.outDir;
    }
    fs::path dir_;
};

TEST_F(FlowRun, CountsBalanceInEveryMethod) {
    for (const std::string m : {"tdm", "edm", "haet"}) {
        const Scenario sc =
            pour({"duration=0.05", "method=" + m, "output.series_period=0.0025", "output.snapshot_period=-1"});
        expectBalanced(run(sc, m) / "series.csv", m);
    }
}

TEST(HybridFlow, RemovesInBothModesKeepingItsBooks) {
    const Scenario sc = pour({"method=haet"});
    World<3> w = buildWorld<3>(sc);
    std::string note;
    HaetSettings hs = haetSettings<3>(sc);
    hs.radiusBound = 0.001;
    HaetEngine<3> eng(w, tdmSettings<3>(sc, w, &note), edmSettings(sc), hs);
    for (int k = 0; k < 50000 && (eng.nTdm() < 50 || eng.nEdm() < 50); ++k) eng.step();
    ASSERT_GT(eng.nTdm(), 10u);
    ASSERT_GT(eng.nEdm(), 10u);
    eng.synchronise();
    // Every third particle, of either mode.
    std::vector<std::uint32_t> which;
    std::set<std::uint64_t> gone;
    for (std::uint32_t i = 0; i < w.particles.size(); i += 3) {
        which.push_back(i);
        gone.insert(w.particles.id[i]);
    }
    const std::size_t n0 = w.particles.size();
    eng.removeParticles(which);
    EXPECT_EQ(w.particles.size(), n0 - which.size());
    EXPECT_EQ(eng.nTdm() + eng.nEdm(), w.particles.size());
    EXPECT_EQ(eng.edm().size(), eng.nEdm());
    for (const std::uint64_t id : w.particles.id) EXPECT_EQ(gone.count(id), 0u);
    EXPECT_EQ(eng.unwatchedInGuard(), 0u);
    for (int k = 0; k < 500; ++k) eng.step();
    eng.synchronise();
    const HaetEnergy e = eng.energy();
    EXPECT_GT(e.outflow, 0);
    EXPECT_LT(std::abs(e.unaccounted), 1e-9 * std::abs(e.total));
}

TEST(Flows, CheckDescribesThePourScene) {
    std::ostringstream out;
    describeScenario(parseScenario(sceneText("pour3d.toml"), "pour3d.toml"), out);
    const std::string s = out.str();
    EXPECT_NE(s.find("outlet     drain: box"), std::string::npos) << s;
}

/// file:line: key of a bad inlet or outlet.
void expectBad(const std::string& from, const std::string& to, const std::string& key, const std::string& what,
               const std::string& needle = "") {
    const std::string text = replaced(sceneText("pour3d.toml"), from, to);
    try {
        parseScenario(text, "bad.toml");
        ADD_FAILURE() << "no error for " << to;
    } catch (const ScenarioError& e) {
        const int line = lineOf(text, needle.empty() ? to : needle);
        EXPECT_EQ(e.key(), key) << e.what();
        EXPECT_EQ(e.pos().line, line) << e.what();
        EXPECT_NE(std::string(e.what()).find("bad.toml:" + std::to_string(line) + ": " + key + ": " + what),
                  std::string::npos)
            << e.what();
    }
}

TEST(Flows, BadInputNamesFileLineAndKey) {
    expectBad("name = \"drain\"", "name = \"drain\"\nplane = { point = [0, 0, 0], normal = [0, 0, 1] }",
              "outlet[1].region", "give one of region", "region = { lo = [0.0, 0.0, 0.0], hi = [0.008");
    expectBad("region = { lo = [0.0, 0.0, 0.0], hi = [0.008, 0.008, 0.003] }",
              "plane = { point = [0, 0, 0], normal = [0, 0, 0] }", "outlet[1].plane.normal", "must be nonzero");
    expectBad("name = \"drain\"", "name = \"drain\"\ninterval = -1", "outlet[1].interval", "must be > 0",
              "interval = -1");
    expectBad("name = \"drain\"", "name = \"drain 2\"", "outlet[1].name", "letters, digits", "[[outlet]]");
}

}  // namespace
}  // namespace haet
