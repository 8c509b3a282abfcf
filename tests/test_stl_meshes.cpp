// The committed meshes of examples/meshes/ are what tools/make_stl.py writes (run into a temporary folder, compared
// byte for byte), the reader takes each, and each has the shape and orientation the script's documentation says.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "io/stl.hpp"

namespace haet {
namespace {

namespace fs = std::filesystem;

const fs::path kMeshes = fs::path(HAET_SOURCE_DIR) / "examples" / "meshes";

std::string bytesOf(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

Vec<3> areaVector(const StlTriangle& t) { return cross(t[1] - t[0], t[2] - t[0]) * 0.5; }
Vec<3> centroid(const StlTriangle& t) { return (t[0] + t[1] + t[2]) / 3.0; }

/// Volume enclosed by a closed mesh (divergence theorem): positive for outward normals.
double signedVolume(const std::vector<StlTriangle>& tris) {
    double v = 0;
    for (const auto& t : tris) v += dot(t[0], cross(t[1], t[2])) / 6;
    return v;
}

/// Every directed edge of a closed, consistently oriented mesh appears once, and its reverse once.
bool closedAndOriented(const std::vector<StlTriangle>& tris) {
    std::map<std::pair<std::array<double, 3>, std::array<double, 3>>, int> edges;
    for (const auto& t : tris)
        for (int k = 0; k < 3; ++k) ++edges[{t[k].c, t[(k + 1) % 3].c}];
    for (const auto& [e, n] : edges) {
        const auto back = edges.find({e.second, e.first});
        if (n != 1 || back == edges.end() || back->second != 1) return false;
    }
    return true;
}

TEST(StlMeshes, CommittedFilesAreWhatTheScriptWrites) {
    const fs::path out = fs::temp_directory_path() / ("haet_make_stl_" + std::to_string(getpid()));
    fs::remove_all(out);
    const std::string cmd = "python3 '" + (fs::path(HAET_SOURCE_DIR) / "tools" / "make_stl.py").string() + "' --out '" +
                            out.string() + "' > /dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::set<std::string> made, committed;
    for (const auto& e : fs::directory_iterator(out)) made.insert(e.path().filename().string());
    for (const auto& e : fs::directory_iterator(kMeshes)) committed.insert(e.path().filename().string());
    EXPECT_EQ(made, committed) << "run tools/make_stl.py and commit examples/meshes/";
    for (const auto& name : made) {
        EXPECT_TRUE(bytesOf(out / name) == bytesOf(kMeshes / name))
            << "examples/meshes/" << name << " differs from what tools/make_stl.py writes";
        EXPECT_LT(fs::file_size(kMeshes / name), 1u << 20) << name;
        EXPECT_GT(readStl(kMeshes / name).triangles.size(), 100u) << name;
    }
    fs::remove_all(out);
}

TEST(StlMeshes, Incline) {
    const StlMesh m = readStl(kMeshes / "incline.stl");
    EXPECT_TRUE(m.binary);
    EXPECT_EQ(m.triangles.size(), 2u * 40 * 20);
    double area = 0;
    std::set<long> directions;  // edge directions, to 1e-6 rad: jittered, so (almost) all differ
    for (const auto& t : m.triangles) {
        const Vec<3> a = areaVector(t);
        EXPECT_GT(a[2], 0);
        EXPECT_EQ(a[0], 0);
        EXPECT_EQ(a[1], 0);
        area += a[2];
        for (int k = 0; k < 3; ++k) {
            const Vec<3> e = t[(k + 1) % 3] - t[k];
            directions.insert(std::lround(std::fmod(std::atan2(e[1], e[0]) + M_PI, M_PI) * 1e6));
        }
    }
    EXPECT_NEAR(area, 0.1 * 0.05, 1e-9);
    EXPECT_GT(directions.size(), 2000u);  // a regular grid would have 3
}

TEST(StlMeshes, CylinderAndHopperFaceTheAxis) {
    const StlMesh c = readStl(kMeshes / "cylinder.stl");
    const StlMesh h = readStl(kMeshes / "hopper.stl");
    for (const StlMesh* m : {&c, &h}) {
        double rMin = 1, rMax = 0, zMin = 1, zMax = -1;
        for (const auto& t : m->triangles) {
            const Vec<3> a = areaVector(t), x = centroid(t);
            EXPECT_LT(a[0] * x[0] + a[1] * x[1], 0) << m->path;  // inward
            for (const auto& p : t) {
                const double r = std::hypot(p[0], p[1]);
                rMin = std::min(rMin, r);
                rMax = std::max(rMax, r);
                zMin = std::min(zMin, p[2]);
                zMax = std::max(zMax, p[2]);
            }
        }
        EXPECT_NEAR(rMax, 0.02, 1e-9) << m->path;
        EXPECT_EQ(zMin, 0.0) << m->path;
        EXPECT_FALSE(closedAndOriented(m->triangles)) << m->path;  // open at both ends
        if (m == &c) {
            EXPECT_NEAR(rMin, 0.02, 1e-9);
            EXPECT_NEAR(zMax, 0.06, 1e-12);
        } else {
            EXPECT_NEAR(rMin, 0.004, 1e-9);
            EXPECT_NEAR(zMax, 0.016, 1e-12);
        }
    }
}

TEST(StlMeshes, DrumAndMixerAreClosed) {
    const StlMesh d = readStl(kMeshes / "drum.stl");
    EXPECT_TRUE(closedAndOriented(d.triangles));
    // Inward normals: the volume comes out negative, that of the 96-gon prism.
    const double polygon = 0.5 * 96 * 0.05 * 0.05 * std::sin(2 * M_PI / 96);
    EXPECT_NEAR(signedVolume(d.triangles), -polygon * 0.03, 1e-6 * polygon * 0.03);  // float32 coordinates
    const StlMesh m = readStl(kMeshes / "mixer.stl");
    EXPECT_TRUE(closedAndOriented(m.triangles));
    EXPECT_GT(signedVolume(m.triangles), 0);  // outward: the grains are outside
    double reach = 0;
    for (const auto& t : m.triangles)
        for (const auto& p : t) reach = std::max(reach, std::abs(p[0]));
    EXPECT_NEAR(reach, 0.018, 1e-12);
}

}  // namespace
}  // namespace haet
