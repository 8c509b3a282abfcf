// Polygons in scenarios and outputs: the [[insert]] keys shape / polygon / sides / aspect / orientation, polygon
// CSV files, their errors ("file:line: key: what", exit code 2), the polygon defaults (gear5, the thesis time
// step), and the files `haet run` writes for a polygon scene (polygons.pvd with VTK polygon cells, final.png).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "polygon/geometry.hpp"
#include "scenario/insert.hpp"
#include "scenario/loader.hpp"
#include "scenario_text.hpp"
#include "world/build.hpp"

namespace fs = std::filesystem;

namespace haet {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Hexagons on a lattice and random polygons above them, no disks: the linear law needs no duration
// (examples/polygon_mix2d.toml).
const std::string kPolygons = testing::sceneText("polygon_mix2d.toml");

using haet::testing::lineOf;
using haet::testing::replaced;

class PolygonScenario : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ =
            fs::temp_directory_path() / ("haet_polyscn_" + std::string(info->name()) + "_" + std::to_string(getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
    }
    fs::path write(const std::string& name, const std::string& text) const {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
    /// Expects a ScenarioError naming `file` (default: the scenario), `line` and `key`; returns its message.
    std::string expectError(const std::string& text, int line, const std::string& key, std::string file = "") const {
        const fs::path p = write("bad.toml", text);
        if (file.empty()) file = p.string();
        try {
            const Scenario sc = loadScenario(p);
            buildWorld<2>(sc);
        } catch (const ScenarioError& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(file + ":" + std::to_string(line) + ": " + key + ": "), std::string::npos) << msg;
            return msg;
        }
        ADD_FAILURE() << "no ScenarioError for " << key;
        return {};
    }
    int run(const std::string& args, std::string* err = nullptr) const {
        const fs::path e = dir_ / "stderr.txt";
        const std::string cmd = std::string("timeout 60 '") + HAET_BINARY + "' " + args + " > /dev/null 2> '" +
                                e.string() + "' < /dev/null";
        const int status = std::system(cmd.c_str());
        if (err) {
            std::ifstream in(e);
            std::stringstream ss;
            ss << in.rdbuf();
            *err = ss.str();
        }
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    fs::path dir_;
};

TEST_F(PolygonScenario, InsertsRegularRandomAndRectanglePolygons) {
    const Scenario sc = loadScenario(write("poly.toml", kPolygons));
    ASSERT_EQ(sc.inserts.size(), 2u);
    EXPECT_EQ(sc.inserts[0].shape, ShapeKind::Polygon);
    EXPECT_EQ(sc.inserts[0].polygon, PolygonKind::Regular);
    EXPECT_EQ(sc.inserts[0].sidesMin, 6);
    EXPECT_EQ(*sc.inserts[0].orientation, 0.25);
    EXPECT_EQ(sc.inserts[1].polygon, PolygonKind::Random);
    EXPECT_EQ(sc.inserts[1].sidesMin, 4);
    EXPECT_EQ(sc.inserts[1].sidesMax, 9);
    EXPECT_FALSE(sc.inserts[1].orientation.has_value());
    const World<2> w = buildWorld<2>(sc);
    const Particles<2>& p = w.particles;
    ASSERT_EQ(p.size(), 70u);
    ASSERT_TRUE(p.hasPolygons());
    bool distinctAngles = false;
    for (std::size_t i = 0; i < p.size(); ++i) {
        ASSERT_TRUE(p.isPolygon(i));
        const int n = p.shapes.count(p.shape[i]);
        const polygon::Moments m = polygon::polygonMoments(p.shapes.of(p.shape[i]), n);
        EXPECT_TRUE(polygon::isConvexCcw(p.shapes.of(p.shape[i]), n));
        EXPECT_NEAR(p.mass[i], 2.0 * m.area, 1e-15);
        EXPECT_NEAR(p.radius[i], polygon::circumradius(p.shapes.of(p.shape[i]), n, Vec<2>::zero()), 1e-15);
        if (i < 40) {
            EXPECT_EQ(n, 6);
            EXPECT_EQ(p.angle[i][0], 0.25);
            EXPECT_NEAR(p.radius[i], 0.002, 1e-15);
        } else {
            EXPECT_GE(n, 4);
            EXPECT_LE(n, 9);
            EXPECT_GE(p.radius[i], 0.0015);
            EXPECT_LE(p.radius[i], 0.002);
            distinctAngles = distinctAngles || p.angle[i][0] != p.angle[40][0];
        }
    }
    EXPECT_TRUE(distinctAngles) << "orientation = \"random\"";
    // The same seed gives the same shapes.
    const World<2> again = buildWorld<2>(sc);
    EXPECT_EQ(again.particles.shapes.vertices, p.shapes.vertices);

    // Polygon defaults: Gear5 and the thesis step (pi/10) sqrt(m_min/Y) (e = 0.9: no damping reduction).
    const TdmSettings ts = tdmSettings<2>(sc, w);
    EXPECT_EQ(ts.integrator, IntegratorKind::Gear5);
    double mmin = 1e9;
    for (double m : p.mass) mmin = std::min(mmin, m);
    EXPECT_NEAR(ts.dt, kPi / 10 * std::sqrt(mmin / 2000), 1e-15);

    // A rectangle: 4 sides, side ratio `aspect`, half-diagonal `radius`.
    const std::string rect = replaced(kPolygons, "sides = 6\n", "polygon = \"rectangle\"\naspect = 3\n");
    const World<2> wr = buildWorld<2>(loadScenario(write("rect.toml", rect)));
    const Vec<2>* v = wr.particles.shapes.of(0);
    EXPECT_NEAR(norm(v[1] - v[0]) * 3, norm(v[2] - v[1]), 1e-15);  // rectangle(): x side first is the long one
    EXPECT_NEAR(norm(v[0]), 0.002, 1e-15);
}

TEST_F(PolygonScenario, PolygonsFromACsvFile) {
    write("shapes.csv",
          "# two polygons, world coordinates\n"
          "vertices,vx,vy,w,material,frozen\n"
          "0.01 0.01 0.014 0.01 0.012 0.0135,0.1,0,0,grain,0\n"
          "0.03 0.01 0.03 0.015 0.025 0.015 0.025 0.01,0,0,5,0,1\n");  // clockwise: re-ordered
    const std::string t = kPolygons.substr(0, kPolygons.find("[[insert]]")) +
                          "[[insert]]\narrangement = \"file\"\nshape = \"polygon\"\nfile = \"shapes.csv\"\n"
                          "material = \"grain\"\n";
    const World<2> w = buildWorld<2>(loadScenario(write("file.toml", t)));
    const Particles<2>& p = w.particles;
    ASSERT_EQ(p.size(), 2u);
    EXPECT_NEAR(p.x[0][0], 0.012, 1e-15);
    EXPECT_NEAR(p.x[0][1], 0.01 + 0.0035 / 3, 1e-15);
    EXPECT_NEAR(p.mass[0], 2.0 * 0.5 * 0.004 * 0.0035, 1e-18);
    EXPECT_EQ(p.v[0][0], 0.1);
    EXPECT_NEAR(p.x[1][0], 0.0275, 1e-15);
    EXPECT_NEAR(p.inertia(1), p.mass[1] * (0.005 * 0.005 * 2) / 12, 1e-20);  // square: m s^2 / 6
    EXPECT_TRUE(p.frozen(1));
    EXPECT_EQ(p.w[1][0], 5.0);

    // Errors name the polygon file and its line.
    const std::string csv = (dir_ / "shapes.csv").string();
    write("shapes.csv", "vertices\n0 0 1 0 1 1 0 1\n0.01 0.01 0.02 0.02 0.01 0.02 0.02 0.01\n");  // a bow tie
    EXPECT_NE(expectError(t, 3, "insert[1].file", csv).find("not convex"), std::string::npos);
    write("shapes.csv", "vertices\n0.01 0.01 0.02\n");
    EXPECT_NE(expectError(t, 2, "insert[1].file", csv).find("expected 3 to 20 vertices"), std::string::npos);
    write("shapes.csv", "vertices,radius\n0.01 0.01 0.02 0.01 0.02 0.02,1\n");
    EXPECT_NE(expectError(t, 1, "insert[1].file", csv).find("unknown column \"radius\""), std::string::npos);
}

TEST_F(PolygonScenario, BadPolygonKeysNameFileLineAndKey) {
    const std::string a = replaced(kPolygons, "sides = 6", "sides = 2");
    EXPECT_NE(expectError(a, lineOf(a, "sides = 2"), "insert[1].sides").find("from 3 to 20"), std::string::npos);
    const std::string b = replaced(kPolygons, "sides = [4, 9]", "sides = [9, 4]");
    EXPECT_NE(expectError(b, lineOf(b, "sides = [9, 4]"), "insert[2].sides").find("3 <= min <= max <= 20"),
              std::string::npos);
    const std::string c = replaced(kPolygons, "orientation = 0.25", "orientation = \"any\"");
    expectError(c, lineOf(c, "orientation = \"any\""), "insert[1].orientation");
    const std::string d = replaced(kPolygons, "aspect = 1.8", "aspect = 0.5");
    EXPECT_NE(expectError(d, lineOf(d, "aspect = 0.5"), "insert[2].aspect").find(">= 1"), std::string::npos);
    const std::string e = replaced(kPolygons, "shape = \"polygon\"\nsides = 6", "sides = 6");
    EXPECT_NE(expectError(e, lineOf(e, "sides = 6"), "insert[1].sides").find("only for shape = \"polygon\""),
              std::string::npos);
    const std::string f = replaced(kPolygons, "shape = \"polygon\"\nsides = 6", "shape = \"polygon\"");
    EXPECT_NE(expectError(f, lineOf(f, "[[insert]]"), "insert[1].sides").find("is required"), std::string::npos);
    const std::string g = replaced(kPolygons, "seed = 3", "seed = 3\nmethod = \"edm\"");
    EXPECT_NE(expectError(g, lineOf(g, "shape = \"polygon\""), "insert[1].shape").find("method = \"tdm\""),
              std::string::npos);
    const std::string h = replaced(kPolygons, "polygon = \"random\"", "polygon = \"star\"");
    expectError(h, lineOf(h, "polygon = \"star\""), "insert[2].polygon");
    const std::string law = replaced(kPolygons, "[[walls]]", "[contact]\npolygon_law = \"exact\"\n\n[[walls]]");
    EXPECT_NE(expectError(law, lineOf(law, "polygon_law"), "contact.polygon_law").find("\"potential\""),
              std::string::npos);
    // A disk insert brings back the linear law's duration.
    const std::string disks = replaced(kPolygons, "[[walls]]", "[contact]\ntangential = \"spring\"\n\n[[walls]]") +
                              "\n[[insert]]\ncount = 3\nradius = 0.001\nmaterial = \"grain\"\n";
    const std::string msg = expectError(disks, lineOf(disks, "[contact]"), "contact.duration");
    EXPECT_NE(msg.find("needs a contact duration"), std::string::npos) << msg;
    // Exit code 2 from the command line.
    std::string err;
    EXPECT_EQ(run("check '" + write("bad2.toml", a).string() + "'", &err), 2);
    EXPECT_NE(err.find("insert[1].sides"), std::string::npos) << err;
    EXPECT_EQ(run("check '" + write("bad3.toml", law).string() + "'", &err), 2);
    EXPECT_NE(err.find("contact.polygon_law"), std::string::npos) << err;
}

// contact.polygon_law picks the normal law of every polygon pair; the default is the overlap-area law (G.3).
TEST_F(PolygonScenario, PolygonLawKey) {
    const Scenario byDefault = loadScenario(write("a.toml", kPolygons));
    EXPECT_EQ(byDefault.contact.polygonLaw, PolygonLaw::OverlapArea);
    World<2> w = buildWorld<2>(byDefault);
    EXPECT_EQ(w.contact.polygonPair(0, 0).law, PolygonLaw::OverlapArea);
    const Scenario pot = loadScenario(
        write("b.toml", replaced(kPolygons, "[[walls]]", "[contact]\npolygon_law = \"potential\"\n\n[[walls]]")));
    EXPECT_EQ(pot.contact.polygonLaw, PolygonLaw::Potential);
    World<2> wp = buildWorld<2>(pot);
    EXPECT_EQ(wp.contact.polygonPair(0, 0).law, PolygonLaw::Potential);
    EXPECT_EQ(wp.contact.polygonStep, w.contact.polygonStep);
}

TEST_F(PolygonScenario, RunWritesPolygonCellsAndPicture) {
    const fs::path scn = write("poly.toml", kPolygons);
    std::string err;
    ASSERT_EQ(run("run -q '" + scn.string() + "' --out '" + (dir_ / "out").string() + "'", &err), 0) << err;
    EXPECT_TRUE(fs::exists(dir_ / "out" / "final.png"));
    EXPECT_TRUE(fs::exists(dir_ / "out" / "polygons.pvd"));
    std::ifstream in(dir_ / "out" / "polygons_000002.vtu", std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string vtu = ss.str();
    EXPECT_NE(vtu.find("NumberOfCells=\"70\""), std::string::npos);
    EXPECT_NE(vtu.find("Name=\"angle\""), std::string::npos);
    std::ifstream pvd(dir_ / "out" / "polygons.pvd");
    std::stringstream ps;
    ps << pvd.rdbuf();
    EXPECT_NE(ps.str().find("polygons_000002.vtu"), std::string::npos);
}

}  // namespace
}  // namespace haet
