// Particles that come and go (docs/physics.md K): inlets deliver their rate
// without overlap and report a shortfall, outlets remove exactly the particles
// inside them, the counts balance in every method, the hybrid's books stay
// balanced, results do not depend on the thread count, and bad input stops with
// file:line: key. The scene is examples/pour3d.toml, with overrides.
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

/// A world that does not move: the flows act on it alone (no engine), so each
/// batch can be inspected.
template <int D>
class StaticHost final : public FlowHost<D> {
public:
    explicit StaticHost(World<D>& w) : w_(w) {}
    std::size_t eager() const override { return w_.particles.size(); }
    void synchronise() override {}
    void remove(const std::vector<std::uint32_t>& which) override {
        removed += which.size();
        dropParticles(w_.particles, which);
    }
    void added(std::size_t first) override { firsts.push_back(first); }
    std::size_t removed = 0;
    std::vector<std::size_t> firsts;

private:
    World<D>& w_;
};

/// Overlaps of particles [first, size()) with any other particle or a wall
/// plane, by brute force.
template <int D>
int overlapsAtBirth(const World<D>& w, std::size_t first) {
    const Particles<D>& p = w.particles;
    int bad = 0;
    for (std::size_t i = first; i < p.size(); ++i) {
        for (std::size_t j = 0; j < p.size(); ++j)
            if (j != i && norm(p.x[i] - p.x[j]) < (p.radius[i] + p.radius[j]) * (1 - 1e-12)) ++bad;
        for (const Wall<D>& wl : w.walls)
            if (wl.distance(p.x[i], w.time) < p.radius[i]) ++bad;
    }
    return bad;
}

/// Runs the flows of `sc` on a world that does not move, batch by batch, to the
/// end of the run; checks that no particle is born overlapping another or a
/// wall.
Flow<3> runStatic(const Scenario& sc, World<3>& w, StaticHost<3>& host) {
    Flow<3> flow(sc, w, 0.0);
    for (double t = flow.nextTime(); t <= sc.duration; t = flow.nextTime()) {
        w.time = t;
        const std::size_t before = w.particles.size();
        flow.act(w, host, 1e-12);
        if (w.particles.size() > before) {
            EXPECT_EQ(overlapsAtBirth(w, before), 0) << "batch at t = " << t;
        }
    }
    return flow;
}

TEST(Inlet, DeliversItsRateInParticlesWithoutOverlap) {
    // 4000 particles/s for 0.2 s, a batch every 0.0307 s: 800 particles, the last
    // batch at the end itself.
    const Scenario sc = pour({"duration=0.2"});
    World<3> w = buildWorld<3>(sc);
    StaticHost<3> host(w);
    Flow<3> flow = runStatic(sc, w, host);
    const auto row = flow.row(w.time);  // feed_particles, feed_mass, feed_shortfall,
                                        // drain_particles, drain_mass, drain_rate
    EXPECT_FALSE(row[5].has_value());   // the first row has no interval for a rate
    // A later row: the mass removed in between over the time in between (none here: the run is over).
    EXPECT_EQ(*flow.row(w.time + 0.5)[5], 0.0);
    EXPECT_NEAR(*row[0], 4000 * 0.2, 0.01 * 4000 * 0.2);
    EXPECT_EQ(*row[0], 800);
    EXPECT_EQ(*row[2], 0);
    EXPECT_EQ(w.particles.size(), 400 + 800 - host.removed);
    EXPECT_GE(host.firsts.size(), 6u);  // batches
    // Ids are unique and new ones continue after the initial ones.
    std::set<std::uint64_t> ids(w.particles.id.begin(), w.particles.id.end());
    EXPECT_EQ(ids.size(), w.particles.size());
    EXPECT_EQ(*ids.rbegin(), 400u + 800u - 1u);
}

TEST(Outlet, CounterCountsEachParticleOnceAndKeepsIt) {
    // A counter (remove = false) before the drain: a particle is counted the first time its centre is inside, again
    // never, however often it crosses; it stays in the run and the drain still removes it later.
    const std::string text = replaced(sceneText("pour3d.toml"), "[[outlet]]\nname = \"drain\"",
                                      "[[outlet]]\nname = \"low\"\nremove = false\n"
                                      "plane = { point = [0.0, 0.0, 0.01], normal = [0.0, 0.0, -1.0] }\n\n"
                                      "[[outlet]]\nname = \"drain\"");
    const Scenario sc = pour({"inlet[1].start=10", "inlet[1].end=11"}, text);
    ASSERT_EQ(sc.outlets.size(), 2u);
    EXPECT_FALSE(sc.outlets[0].remove);
    World<3> w = buildWorld<3>(sc);
    Particles<3>& p = w.particles;
    StaticHost<3> host(w);
    Flow<3> flow(sc, w, 1e-4);
    for (std::size_t i = 0; i < p.size(); ++i) p.x[i] = Vec<3>{{0.02, 0.02, 0.015}};  // above the counter, off the pit
    const double m0 = p.mass[0];
    const std::uint64_t id0 = p.id[0];
    for (int k = 0; k < 6; ++k) {  // particle 0 crosses the counter's plane down and up three times
        p.x[0][2] = k % 2 == 0 ? 0.005 : 0.015;
        w.time += 1e-4;
        flow.act(w, host, 1e-9);
    }
    auto row = flow.row(w.time);  // feed x3, low_particles, low_mass, low_rate, drain x3
    EXPECT_EQ(*row[3], 1);
    EXPECT_EQ(*row[4], m0);
    EXPECT_EQ(host.removed, 0u);
    EXPECT_EQ(p.size(), 400u);
    // Into the pit: the drain removes it; the counter, already past, does not count it again.
    p.x[0] = Vec<3>{{0.004, 0.004, 0.002}};
    w.time += 1e-4;
    flow.act(w, host, 1e-9);
    row = flow.row(w.time);
    EXPECT_EQ(*row[3], 1);
    EXPECT_EQ(*row[6], 1);
    EXPECT_EQ(host.removed, 1u);
    EXPECT_EQ(std::count(p.id.begin(), p.id.end(), id0), 0);
    EXPECT_EQ(flow.remembered(0), 0u) << "a removed particle is forgotten: the counter's memory stays bounded";
    // Every other particle below the plane now: each counted once.
    for (std::size_t i = 0; i < p.size(); ++i) p.x[i][2] = 0.005;
    w.time += 1e-4;
    flow.act(w, host, 1e-9);
    EXPECT_EQ(*flow.row(w.time)[3], 400);
    EXPECT_EQ(flow.remembered(0), 399u);
}

TEST(Inlet, DeliversItsRateInKilogramsPerSecond) {
    const std::string text = replaced(sceneText("pour3d.toml"), "rate = 4000", "mass_rate = 0.004");
    const Scenario sc = pour({"duration=0.2"}, text);
    World<3> w = buildWorld<3>(sc);
    StaticHost<3> host(w);
    Flow<3> flow = runStatic(sc, w, host);
    const auto row = flow.row(w.time);
    EXPECT_NEAR(*row[1], 0.004 * 0.2, 0.01 * 0.004 * 0.2);
    EXPECT_GT(*row[0], 100);
}

TEST(Inlet, CrowdedRegionReportsItsShortfall) {
    // 2 x 10^5 particles/s into a region that holds about 2000: the due ones that find no room wait, counted.
    const Scenario sc = pour({"duration=0.02", "inlet[1].rate=2e5"});
    World<3> w = buildWorld<3>(sc);
    StaticHost<3> host(w);
    Flow<3> flow = runStatic(sc, w, host);
    const auto row = flow.row(w.time);
    EXPECT_GT(*row[2], 1000);
    // Nothing is lost: what was inserted and what waits make what fell due.
    EXPECT_EQ(*row[0] + *row[2], std::floor(2e5 * 0.02 * (1 + 1e-12)));
    JsonObject j;
    flow.describe(j);
    EXPECT_NE(j.dump().find("\"shortfall\": " + std::to_string(std::int64_t(*row[2]))), std::string::npos) << j.dump();
}

TEST(Inlet, CylinderRegionHoldsItsNewborns) {
    // A vertical cylinder of radius 8 mm about the box's axis, z in [0.06, 0.08].
    const std::string text =
        replaced(sceneText("pour3d.toml"), "region = { lo = [0.005, 0.005, 0.06], hi = [0.025, 0.025, 0.08] }",
                 "cylinder = { center = [0.015, 0.015], radius = 0.008, z = [0.06, 0.08] }");
    const Scenario sc = pour({"duration=0.1"}, text);
    World<3> w = buildWorld<3>(sc);
    StaticHost<3> host(w);
    Flow<3> flow = runStatic(sc, w, host);
    EXPECT_EQ(*flow.row(w.time)[0], 400);
    std::size_t born = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i) {
        if (w.particles.id[i] < 400) continue;
        ++born;
        const Vec<3>& x = w.particles.x[i];
        const double r = w.particles.radius[i];
        EXPECT_LE(std::hypot(x[0] - 0.015, x[1] - 0.015), 0.008 - r);
        EXPECT_GE(x[2], 0.06 + r);
        EXPECT_LE(x[2], 0.08 - r);
    }
    EXPECT_EQ(born, 400u);
}

/// examples/pour3d.toml with its inlet's box replaced by a disc in the lid, crossed downwards at 0.5 m/s.
std::string surfaceText() {
    return replaced(sceneText("pour3d.toml"), "region = { lo = [0.005, 0.005, 0.06], hi = [0.025, 0.025, 0.08] }",
                    "surface = { center = [0.015, 0.015, 0.08], normal = [0.0, 0.0, -1.0], radius = 0.008 }");
}

TEST(Inlet, SurfaceInletFillsTheSlabDownstreamOfItsFace) {
    // As LIGGGHTS insert/stream: each batch fills the slab the flow crosses in one interval, 0.5 m/s x 0.016 s =
    // 8 mm below the face (the default interval: a slab of four largest diameters).
    const std::string text = surfaceText();
    const Scenario sc = pour({"duration=0.032"}, text);
    ASSERT_NEAR(sc.inlets[0].interval, 8 * 0.001 / 0.5, 1e-15);
    World<3> w = buildWorld<3>(sc);
    StaticHost<3> host(w);
    Flow<3> flow = runStatic(sc, w, host);
    EXPECT_EQ(*flow.row(w.time)[0], 128);
    for (std::size_t i = 0; i < w.particles.size(); ++i) {
        if (w.particles.id[i] < 400) continue;
        const Vec<3>& x = w.particles.x[i];
        const double r = w.particles.radius[i];
        EXPECT_LE(std::hypot(x[0] - 0.015, x[1] - 0.015), 0.008 - r + 1e-15);
        EXPECT_GE(x[2], 0.072 + r - 1e-15);
        EXPECT_LE(x[2], 0.08 - r + 1e-15);
    }
    // A face the velocity does not cross is bad input.
    const std::string up = replaced(text, "velocity = [0.0, 0.0, -0.5]", "velocity = [0.0, 0.0, 0.5]");
    try {
        pour({}, up);
        ADD_FAILURE() << "no error";
    } catch (const ScenarioError& e) {
        EXPECT_EQ(e.key(), "inlet[1].velocity") << e.what();
        EXPECT_EQ(e.pos().line, lineOf(up, "velocity = [0.0, 0.0, 0.5]")) << e.what();
    }
}

TEST(Inlet, SurfaceInletIn2DFillsTheStripBelowItsSegment) {
    // examples/box2d_polygons.toml with a stream of hexagons through a 6 cm segment of its top, down at 0.5 m/s:
    // the strip one interval thick (8 r_max / v = 0.032 s, 1.6 cm) below it.
    const std::string inlet =
        "[[inlet]]\nmaterial = \"grain\"\nshape = \"polygon\"\nsides = 6\nradius = [0.0015, 0.002]\nrate = 1000\n"
        "velocity = [0.0, -0.5]\n"
        "surface = { center = [0.05, 0.15], normal = [0.0, -1.0], length = 0.06 }\n\n[output]";
    const std::string text = replaced(sceneText("box2d_polygons.toml"), "[output]", inlet);
    const Scenario sc =
        parseScenario(text, "box2d_polygons.toml", {"duration=0.032", "insert[2].count=20", "insert[1].count=50"});
    World<2> w = buildWorld<2>(sc);
    StaticHost<2> host(w);
    Flow<2> flow(sc, w, 0.0);
    for (double t = flow.nextTime(); t <= sc.duration; t = flow.nextTime()) {
        w.time = t;
        const std::size_t before = w.particles.size();
        flow.act(w, host, 1e-12);
        EXPECT_EQ(overlapsAtBirth(w, before), 0);
        for (std::size_t i = before; i < w.particles.size(); ++i) {
            const Vec<2>& x = w.particles.x[i];
            const double r = w.particles.radius[i];
            EXPECT_GE(x[0], 0.02 + r - 1e-15);
            EXPECT_LE(x[0], 0.08 - r + 1e-15);
            EXPECT_GE(x[1], 0.15 - 0.016 + r - 1e-15);
            EXPECT_LE(x[1], 0.15 - r + 1e-15);
        }
    }
    EXPECT_EQ(*flow.row(w.time)[0], 32);
}

TEST(Inlet, PolygonsWithTheInsertsShapeOptions) {
    // examples/box2d_polygons.toml with an inlet of random convex polygons at its top, turned at random.
    const std::string inlet =
        "[[inlet]]\nmaterial = \"grain\"\nshape = \"polygon\"\npolygon = \"random\"\nsides = [4, 8]\n"
        "aspect = 1.6\norientation = \"random\"\nradius = [0.0015, 0.002]\nrate = 1000\n"
        "region = { lo = [0.0, 0.12], hi = [0.1, 0.15] }\n\n[output]";
    const std::string text = replaced(sceneText("box2d_polygons.toml"), "[output]", inlet);
    const Scenario sc =
        parseScenario(text, "box2d_polygons.toml", {"duration=0.1", "insert[2].count=20", "insert[1].count=50"});
    World<2> w = buildWorld<2>(sc);
    StaticHost<2> host(w);
    Flow<2> flow(sc, w, 0.0);
    std::set<int> sides;
    std::set<double> angles;
    for (double t = flow.nextTime(); t <= sc.duration; t = flow.nextTime()) {
        w.time = t;
        const std::size_t before = w.particles.size();
        flow.act(w, host, 1e-12);
        EXPECT_EQ(overlapsAtBirth(w, before), 0);  // bounding circles: no overlap of the shapes either
        for (std::size_t i = before; i < w.particles.size(); ++i) {
            ASSERT_TRUE(w.particles.isPolygon(i));
            sides.insert(w.particles.shapes.count(w.particles.shape[i]));
            angles.insert(w.particles.angle[i][0]);
        }
    }
    EXPECT_EQ(*flow.row(w.time)[0], 100);
    EXPECT_GE(sides.size(), 4u);
    EXPECT_EQ(*sides.begin(), 4);
    EXPECT_EQ(*sides.rbegin(), 8);
    EXPECT_EQ(angles.size(), 100u);
    // The polygons of an inlet run in the time-driven engine like any other.
    RunOptions o;
    o.outDir = fs::temp_directory_path() / ("haet_flow_poly_" + std::to_string(::getpid()));
    o.quiet = true;
    std::ostringstream log;
    EXPECT_EQ(
        runScenario(parseScenario(text, "box2d_polygons.toml",
                                  {"duration=0.004", "insert[2].count=20", "insert[1].count=50", "inlet[1].rate=20000",
                                   "inlet[1].interval=0.001", "output.snapshot_period=-1"}),
                    o, log),
        RunStatus::Completed)
        << log.str();
    fs::remove_all(o.outDir);
}

/// A time-driven run driven by hand: after every step the outlet is checked;
/// removed particles were inside, and no particle is left inside.
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
    // The bed settles through the plane z = 0.006: every particle whose centre is
    // below it after a step leaves at that step, and none other. No batch within
    // the run.
    const std::string text =
        replaced(sceneText("pour3d.toml"), "region = { lo = [0.0, 0.0, 0.0], hi = [0.008, 0.008, 0.003] }",
                 "plane = { point = [0.0, 0.0, 0.006], normal = [0.0, 0.0, -1.0] }");
    const Scenario sc = pour({"duration=0.02", "inlet[1].start=10", "inlet[1].end=11"}, text);
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
    EXPECT_GT(host.removed.size(), below0);  // more crossed as the bed settled
    EXPECT_EQ(*flow.row(w.time)[3], double(host.removed.size()));
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
    const std::size_t n = col("n_particles"), in = col("feed_particles"), out = col("drain_particles");
    ASSERT_LT(std::max({n, in, out}), h.size());
    double inserted = 0, removed = 0;
    for (std::size_t r = 1; r < rows.size(); ++r) {
        EXPECT_EQ(std::stod(rows[r][n]), 400 + std::stod(rows[r][in]) - std::stod(rows[r][out]))
            << method << " row " << r;
        inserted = std::stod(rows[r][in]);
        removed = std::stod(rows[r][out]);
    }
    EXPECT_GT(inserted, 50) << method;
    EXPECT_GT(removed, 5) << method;
    if (method == "haet") {  // the hybrid's energy books: what came in and what
                             // left is counted
        const std::size_t u = col("energy_unaccounted"), tot = col("total_energy"), ein = col("energy_in");
        for (std::size_t r = 1; r < rows.size(); ++r)
            EXPECT_LT(std::abs(std::stod(rows[r][u])), 1e-9 * std::stod(rows[r][tot])) << "row " << r;
        EXPECT_GT(std::stod(rows.back()[ein]), 0);
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
        const Scenario sc = pour({"duration=0.05", "inlet[1].interval=0.01", "method=" + m,
                                  "output.series_period=0.0025", "output.snapshot_period=-1"});
        expectBalanced(run(sc, m) / "series.csv", m);
    }
    // A stream through a surface: the particles move on out of the slab, so the rate is met with no shortfall.
    const fs::path out = run(pour({"duration=0.04", "output.snapshot_period=-1"}, surfaceText()), "surface");
    const auto rows = readCsv(out / "series.csv");
    const auto col = [&](const std::string& name) {
        return std::size_t(std::find(rows[0].begin(), rows[0].end(), name) - rows[0].begin());
    };
    EXPECT_EQ(std::stod(rows.back()[col("feed_particles")]), 160);
    EXPECT_EQ(std::stod(rows.back()[col("feed_shortfall")]), 0);
}

std::string fileText(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

TEST_F(FlowRun, TimeDrivenRunWithInletAndOutletIsBitIdenticalWithOneAndTwoThreads) {
    // Above kParallelMin particles, so the force loop runs threaded; batches and
    // removals happen during the run.
    const Scenario sc =
        pour({"duration=0.006", "insert[1].count=2100", "inlet[1].rate=40000", "inlet[1].interval=0.002",
              "output.series_period=0.0005", "output.snapshot_period=0.003"});
    const int before = omp_get_max_threads();
    const fs::path one = run(sc, "t1", 1), two = run(sc, "t2", 2);
    omp_set_num_threads(before);
    const std::string s1 = fileText(one / "series.csv"), s2 = fileText(two / "series.csv");
    ASSERT_FALSE(s1.empty());
    EXPECT_EQ(s1, s2);
    EXPECT_EQ(fileText(one / "particles_000002.vtu"), fileText(two / "particles_000002.vtu"));
    const auto rows = readCsv(one / "series.csv");
    EXPECT_GT(
        std::stod(
            rows.back()[std::size_t(std::find(rows[0].begin(), rows[0].end(), "drain_particles") - rows[0].begin())]),
        0);
}

TEST(HybridFlow, RemovesAndAddsInBothModesKeepingItsBooks) {
    const Scenario sc = pour({"method=haet", "inlet[1].start=10", "inlet[1].end=11"});
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
    // Newborns: one on the bed (a time-driven zone), one high up in the empty box
    // (event-driven).
    const std::size_t first = w.particles.size();
    w.particles.add(Vec<3>{{0.015, 0.015, 0.07}}, Vec<3>::zero(), Ang<3>::zero(), 0.0009, 2500, 0, 9001);
    double top = 0;
    for (std::size_t i = 0; i < first; ++i) top = std::max(top, w.particles.x[i][2] + w.particles.radius[i]);
    w.particles.add(Vec<3>{{0.015, 0.015, top + 0.0011}}, Vec<3>::zero(), Ang<3>::zero(), 0.0009, 2500, 0, 9002);
    const std::size_t nT = eng.nTdm();
    eng.addParticles(first);
    EXPECT_EQ(eng.nTdm() + eng.nEdm(), first + 2);
    EXPECT_EQ(eng.edm().size(), eng.nEdm());
    bool highIsEdm = false;
    for (std::size_t i = eng.nTdm(); i < w.particles.size(); ++i) highIsEdm = highIsEdm || w.particles.id[i] == 9001;
    EXPECT_TRUE(highIsEdm);
    EXPECT_GE(eng.nTdm(), nT);
    EXPECT_EQ(eng.unwatchedInGuard(), 0u);
    for (int k = 0; k < 500; ++k) eng.step();
    eng.synchronise();
    const HaetEnergy e = eng.energy();
    EXPECT_GT(e.outflow, 0);
    EXPECT_GT(e.inflow, 0);
    EXPECT_LT(std::abs(e.unaccounted), 1e-9 * std::abs(e.total));
}

TEST(Flows, CheckDescribesThePourScene) {
    std::ostringstream out;
    describeScenario(parseScenario(sceneText("pour3d.toml"), "pour3d.toml"), out);
    const std::string s = out.str();
    EXPECT_NE(s.find("inlet      feed: 4000 particles/s in a box from 0 s to 0.5 s"), std::string::npos) << s;
    EXPECT_NE(s.find("sizes      inlet feed: log-normal radius"), std::string::npos) << s;
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
    expectBad("rate = 4000 ", "rate = -5 ", "inlet[1].rate", "must be > 0");
    expectBad("rate = 4000 ", "rate = 4000\nmass_rate = 0.1 ", "inlet[1].mass_rate", "not together with rate",
              "mass_rate = 0.1");
    expectBad("rate = 4000 ", "rate = 4000\nstart = 0.3\nend = 0.2 ", "inlet[1].end", "must be > start", "end = 0.2");
    expectBad("rate = 4000 ", "rate = 4000\ninterval = 0 ", "inlet[1].interval", "must be > 0", "interval = 0");
    expectBad("name = \"drain\"", "name = \"feed\"", "outlet[1].name", "\"feed\" names another inlet or outlet",
              "[[outlet]]");
    expectBad("name = \"drain\"", "name = \"drain\"\nplane = { point = [0, 0, 0], normal = [0, 0, 1] }",
              "outlet[1].region", "give one of region", "region = { lo = [0.0, 0.0, 0.0], hi = [0.008");
    expectBad("region = { lo = [0.0, 0.0, 0.0], hi = [0.008, 0.008, 0.003] }",
              "plane = { point = [0, 0, 0], normal = [0, 0, 0] }", "outlet[1].plane.normal", "must be nonzero");
    expectBad("region = { lo = [0.005, 0.005, 0.06], hi = [0.025, 0.025, 0.08] }",
              "cylinder = { center = [0.015, 0.015], radius = 0.01, z = [0.08, 0.06] }", "inlet[1].cylinder.z",
              "must satisfy lo < hi");
    expectBad("[inlet.distribution]\nkind = \"lognormal\"", "[inlet.distribution]\nkind = \"normal\"",
              "inlet[1].distribution.median", "unknown key", "median = 0.0007");
}

}  // namespace
}  // namespace haet
