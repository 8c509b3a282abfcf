// The STL reader (src/io/stl.hpp): round trips of ASCII and binary files written here, a binary file whose header
// starts with "solid", free-form ASCII, every kind of bad input with the file, triangle and line it names, and the
// placement transform.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/rng.hpp"
#include "io/stl.hpp"
#include "temp_dir.hpp"

namespace haet {
namespace {

namespace fs = std::filesystem;

class Stl : public testing::TempDirTest {
protected:
    Stl() : TempDirTest("stl", true) {}
    fs::path write(const std::string& name, const std::string& bytes) {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << bytes;
        return p;
    }
    /// The message of the StlError that reading `p` throws (a failure if it throws none).
    std::string errorOf(const fs::path& p) {
        try {
            readStl(p);
        } catch (const StlError& e) {
            last_ = e;
            return e.what();
        }
        ADD_FAILURE() << p << " was read without error";
        return {};
    }
    StlError last_{fs::path(), "", 0, 0};
};

std::vector<StlTriangle> randomTriangles(int n, bool floatExact) {
    Rng rng(7, 19);
    std::vector<StlTriangle> t(static_cast<std::size_t>(n));
    for (auto& tri : t)
        for (auto& p : tri)
            for (int k = 0; k < 3; ++k) {
                const double x = rng.uniform(-5, 5);
                p[k] = floatExact ? std::round(x * 64) / 64 : x;  // k/64 is exact in float32
            }
    return t;
}

std::string oneFacet(const std::string& v0, const std::string& v1, const std::string& v2) {
    return "  facet normal 0 0 1\n    outer loop\n      vertex " + v0 + "\n      vertex " + v1 + "\n      vertex " +
           v2 + "\n    endloop\n  endfacet\n";
}

TEST_F(Stl, AsciiRoundTrip) {
    const auto tris = randomTriangles(200, false);
    const fs::path p = write("a.stl", stlAscii(tris, "my part"));
    const StlMesh m = readStl(p);
    EXPECT_FALSE(m.binary);
    EXPECT_EQ(m.name, "my part");
    EXPECT_EQ(m.path, p);
    ASSERT_EQ(m.triangles.size(), tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i) EXPECT_EQ(m.triangles[i], tris[i]) << "triangle " << i + 1;
}

TEST_F(Stl, BinaryRoundTrip) {
    const auto tris = randomTriangles(300, true);
    const StlMesh m = readStl(write("b.stl", stlBinary(tris, "exported by a CAD program")));
    EXPECT_TRUE(m.binary);
    EXPECT_EQ(m.name, "exported by a CAD program");
    ASSERT_EQ(m.triangles.size(), tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i) EXPECT_EQ(m.triangles[i], tris[i]) << "triangle " << i + 1;
    // Coordinates are float32 in a binary file: a double is rounded to the nearest float.
    std::vector<StlTriangle> one{{Vec<3>{{0.1, 0, 0}}, Vec<3>{{1, 0, 0}}, Vec<3>{{0, 1, 0}}}};
    EXPECT_EQ(readStl(write("c.stl", stlBinary(one, ""))).triangles[0][0][0], double(0.1f));
}

TEST_F(Stl, BinaryThatStartsWithSolid) {
    // Many exporters write "solid NAME" into the binary header; the size 84 + 50 n decides.
    const auto tris = randomTriangles(5, true);
    for (const std::string& header : {std::string("solid part"), std::string("solid"),
                                      "  SOLID x  with text, padded with spaces" + std::string(50, ' ')}) {
        const StlMesh m = readStl(write("s.stl", stlBinary(tris, header)));
        EXPECT_TRUE(m.binary) << header;
        ASSERT_EQ(m.triangles.size(), 5u);
        EXPECT_EQ(m.triangles[4], tris[4]);
    }
    EXPECT_EQ(readStl(write("s.stl", stlBinary(tris, "solid part"))).name, "part");
}

TEST_F(Stl, AsciiFreeForm) {
    // Keywords in any case, words split over lines, '+' signs and exponents, CRLF line ends, two solids.
    const std::string text =
        "SOLID first one\r\nFacet Normal 0 0 +1.0e0\r\nouter\nloop vertex 0 0 0 vertex\n+1e0 0 0\r\n"
        "vertex 0 1.5E-0 0 endloop endfacet\nendsolid first one\nsolid second\n" +
        oneFacet("1 1 1", "2 1 1", "1 2 1") + "endsolid\n";
    const StlMesh m = readStl(write("f.stl", text));
    EXPECT_EQ(m.name, "first one");
    ASSERT_EQ(m.triangles.size(), 2u);
    EXPECT_EQ(m.triangles[0][1], (Vec<3>{{1, 0, 0}}));
    EXPECT_EQ(m.triangles[0][2], (Vec<3>{{0, 1.5, 0}}));
    EXPECT_EQ(m.triangles[1][2], (Vec<3>{{1, 2, 1}}));
    // A NaN in the stored normal, which is not used, is let pass.
    EXPECT_EQ(readStl(write("n.stl",
                            "solid\n  facet normal nan nan nan\n    outer loop\n      vertex 0 0 0\n"
                            "      vertex 1 0 0\n      vertex 0 1 0\n    endloop\n  endfacet\nendsolid\n"))
                  .triangles.size(),
              1u);
}

TEST_F(Stl, MissingEmptyAndNoTriangles) {
    std::string e = errorOf(dir_ / "nothing.stl");
    EXPECT_NE(e.find("nothing.stl: no such file"), std::string::npos) << e;
    e = errorOf(dir_);
    EXPECT_NE(e.find("cannot be read"), std::string::npos) << e;
    e = errorOf(write("empty.stl", ""));
    EXPECT_NE(e.find("empty.stl: is empty"), std::string::npos) << e;
    e = errorOf(write("zero.stl", stlBinary({}, "nothing here")));
    EXPECT_NE(e.find("has no triangles"), std::string::npos) << e;
    e = errorOf(write("zeroa.stl", "solid x\nendsolid x\n"));
    EXPECT_NE(e.find("has no triangles"), std::string::npos) << e;
    e = errorOf(write("short.stl", "hello"));
    EXPECT_NE(e.find("too short for a binary STL"), std::string::npos) << e;
}

TEST_F(Stl, TruncatedAndOversizedBinary) {
    const std::string full = stlBinary(randomTriangles(10, true), "");
    std::string e = errorOf(write("t.stl", full.substr(0, 84 + 50 * 6 + 17)));
    EXPECT_NE(e.find("t.stl: triangle 7: binary STL truncated: its header counts 10 triangles"), std::string::npos)
        << e;
    EXPECT_EQ(last_.triangle(), 7u);
    EXPECT_EQ(last_.line(), 0);
    e = errorOf(write("t2.stl", full.substr(0, 90)));
    EXPECT_NE(e.find("triangle 1: binary STL truncated"), std::string::npos) << e;
    e = errorOf(write("long.stl", full + "xy"));
    EXPECT_NE(e.find("2 bytes after the last triangle"), std::string::npos) << e;
    // A header that starts with "solid" but holds binary bytes, cut short: still reported as a truncated binary.
    const std::string solidHeader = stlBinary(randomTriangles(10, true), "solid cut");
    e = errorOf(write("t3.stl", solidHeader.substr(0, 84 + 50 * 3)));
    EXPECT_NE(e.find("triangle 4: binary STL truncated"), std::string::npos) << e;
}

TEST_F(Stl, HostileCountFailsFast) {
    // A header that claims 4e9 triangles (200 GB) in a file of 134 bytes: the size check comes before any
    // allocation, so this fails at once instead of reserving the claimed count.
    std::string bytes = stlBinary(randomTriangles(1, true), "");
    const std::uint32_t huge = 4000000000u;
    for (int k = 0; k < 4; ++k) bytes[80 + k] = static_cast<char>((huge >> (8 * k)) & 0xff);
    const std::string e = errorOf(write("h.stl", bytes));
    EXPECT_NE(e.find("counts 4000000000 triangles"), std::string::npos) << e;
    EXPECT_EQ(last_.triangle(), 2u);
}

TEST_F(Stl, MalformedAscii) {
    const std::string head = "solid m\n";  // line 1; a facet takes lines 2-8
    const std::string good = oneFacet("0 0 0", "1 0 0", "0 1 0");
    struct Case {
        std::string text, expect;
        std::size_t triangle;
        int line;
    };
    const std::vector<Case> cases = {
        {head + good + "  facet normal 0 0 1\n    outer lop\n", "expected 'loop', found 'lop'", 2, 10},
        {head + good + oneFacet("0 0 0", "1 0 x", "0 1 0"), "expected a number (vertex coordinate), found 'x'", 2, 12},
        {head + good + oneFacet("0 0 0", "1 0 1.5.2", "0 1 0"), "found '1.5.2'", 2, 12},
        {head + oneFacet("0 0 0", "1 0 nan", "0 1 0"), "vertex coordinate 'nan' is not finite", 1, 5},
        {head + oneFacet("0 0 0", "inf 0 0", "0 1 0"), "vertex coordinate 'inf' is not finite", 1, 5},
        {head + oneFacet("0 0 0", "1e999 0 0", "0 1 0"), "'1e999' is out of range", 1, 5},
        {head + good + "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n    endloop\n",
         "a facet with 2 vertices, expected 3", 2, 13},
        {head + "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n      vertex 0 1 0\n"
                "      vertex 1 1 0\n",
         "a facet with more than 3 vertices", 1, 7},
        {head + good + "  facet normal 0 0 1\n    outer loop\n      vertex 0 0", "unexpected end of file", 2, 11},
        {head + good, "unexpected end of file, expected 'facet' or 'endsolid'", 0, 8},
        {head + good + "  facets normal 0 0 1\n", "expected 'facet' or 'endsolid', found 'facets'", 0, 9},
        {head + good + "endsolid m\ngarbage\n", "expected 'solid' or the end of the file, found 'garbage'", 0, 10},
        {head + good + std::string("  facet normal 0 0 1\n    outer loop\0\n", 38), "a binary byte in an ASCII STL", 0,
         10},
        {head + oneFacet("0 0 0", "1 1 1", "2 2 2"), "zero area (degenerate triangle)", 1, 2},
        {head + good + oneFacet("1 2 3", "1 2 3", "4 5 6"), "zero area", 2, 9},
    };
    for (const auto& c : cases) {
        const std::string e = errorOf(write("m.stl", c.text));
        EXPECT_NE(e.find(c.expect), std::string::npos) << e;
        EXPECT_EQ(last_.triangle(), c.triangle) << e;
        EXPECT_EQ(last_.line(), c.line) << e;
        EXPECT_EQ(e.rfind((dir_ / "m.stl").string() + ":" + std::to_string(c.line) + ": ", 0), 0u) << e;
    }
}

TEST_F(Stl, BadBinaryTriangles) {
    auto tris = randomTriangles(9, true);
    tris[4][1][2] = std::numeric_limits<double>::quiet_NaN();
    std::string e = errorOf(write("nan.stl", stlBinary(tris, "")));
    EXPECT_NE(e.find("nan.stl: triangle 5: a vertex coordinate is not finite"), std::string::npos) << e;
    tris = randomTriangles(9, true);
    tris[8][1][0] = std::numeric_limits<double>::infinity();
    e = errorOf(write("inf.stl", stlBinary(tris, "")));
    EXPECT_NE(e.find("triangle 9: a vertex coordinate is not finite"), std::string::npos) << e;
    tris = randomTriangles(9, true);
    tris[2][2] = tris[2][0] + (tris[2][1] - tris[2][0]) * 0.5;  // collinear: exact in float32 (k/128)
    e = errorOf(write("deg.stl", stlBinary(tris, "")));
    EXPECT_NE(e.find("triangle 3: zero area"), std::string::npos) << e;
}

TEST_F(Stl, DegenerateToleranceIsRelative) {
    // The same shape at any size is the same verdict: ratio 1e-9 passes, 1e-11 fails, at scale 1e-6 and 1e6.
    for (const double s : {1e-6, 1.0, 1e6}) {
        const std::vector<StlTriangle> thin{{Vec<3>{{0, 0, 0}}, Vec<3>{{s, 0, 0}}, Vec<3>{{0.5 * s, 1e-9 * s, 0}}}};
        EXPECT_EQ(readStl(write("ok.stl", stlAscii(thin, ""))).triangles.size(), 1u) << s;
        const std::vector<StlTriangle> flat{{Vec<3>{{0, 0, 0}}, Vec<3>{{s, 0, 0}}, Vec<3>{{0.5 * s, 1e-11 * s, 0}}}};
        EXPECT_NE(errorOf(write("bad.stl", stlAscii(flat, ""))).find("zero area"), std::string::npos) << s;
    }
}

TEST_F(Stl, TransformOrder) {
    StlMesh m;
    m.path = "x.stl";
    m.triangles = {{Vec<3>{{1, 0, 0}}, Vec<3>{{0, 1, 0}}, Vec<3>{{0, 0, 1}}}};
    StlTransform t;
    t.scale = Vec<3>{{2, 3, 4}};
    t.axis = Vec<3>{{0, 0, 5}};  // any length
    t.angle_deg = 90;
    t.translate = Vec<3>{{10, 20, 30}};
    transformStl(m, t);
    // scale, then rotate by 90 degrees about z (x -> y, y -> -x), then translate
    const auto near = [](const Vec<3>& a, const Vec<3>& b) { return norm(a - b) < 1e-14; };
    EXPECT_TRUE(near(m.triangles[0][0], Vec<3>{{10, 22, 30}}));
    EXPECT_TRUE(near(m.triangles[0][1], Vec<3>{{7, 20, 30}}));
    EXPECT_TRUE(near(m.triangles[0][2], Vec<3>{{10, 20, 34}}));
    // A rotation keeps lengths and the orientation: R R^T = I, det R = 1, for an arbitrary axis.
    const auto r = stlRotation(Vec<3>{{1, -2, 0.5}}, 37);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(dot(r[i], r[j]), i == j ? 1.0 : 0.0, 1e-15);
    EXPECT_NEAR(dot(cross(r[0], r[1]), r[2]), 1.0, 1e-15);
}

TEST_F(Stl, MirrorKeepsOrientation) {
    StlMesh m;
    m.triangles = {{Vec<3>{{0, 0, 0}}, Vec<3>{{1, 0, 0}}, Vec<3>{{0, 1, 0}}}};  // normal +z
    StlTransform t;
    t.scale = Vec<3>{{-1, 1, 1}};  // mirror in x: the outward side must stay +z
    transformStl(m, t);
    const auto& tri = m.triangles[0];
    EXPECT_GT(cross(tri[1] - tri[0], tri[2] - tri[0])[2], 0);
    t.scale = Vec<3>{{-1, -1, 1}};  // a rotation by 180 degrees: no swap
    const auto before = m.triangles[0];
    transformStl(m, t);
    EXPECT_EQ(m.triangles[0][1], (Vec<3>{{-before[1][0], -before[1][1], 0}}));
}

TEST_F(Stl, BadTransform) {
    StlMesh m;
    m.path = "part.stl";
    m.triangles = {{Vec<3>{{0, 0, 0}}, Vec<3>{{1, 0, 0}}, Vec<3>{{0, 1, 0}}}};
    StlTransform t;
    t.scale = Vec<3>{{1, 0, 1}};
    EXPECT_THROW(transformStl(m, t), std::invalid_argument);
    t.scale = Vec<3>{{1, std::nan(""), 1}};
    EXPECT_THROW(transformStl(m, t), std::invalid_argument);
    t = StlTransform{};
    t.axis = Vec<3>{};
    t.angle_deg = 10;
    EXPECT_THROW(transformStl(m, t), std::invalid_argument);
    t = StlTransform{};
    t.translate[2] = std::numeric_limits<double>::infinity();
    EXPECT_THROW(transformStl(m, t), std::invalid_argument);
    // A scale that squashes a thin triangle flat: an StlError naming the file and the triangle.
    m.triangles.push_back({Vec<3>{{0, 0, 0}}, Vec<3>{{1, 0, 0}}, Vec<3>{{0.5, 1e-6, 0}}});
    t = StlTransform{};
    t.scale = Vec<3>{{1, 1e-6, 1}};
    try {
        transformStl(m, t);
        ADD_FAILURE() << "no error";
    } catch (const StlError& e) {
        EXPECT_EQ(std::string(e.what()), "part.stl: triangle 2: zero area (degenerate) after the transform");
    }
}

}  // namespace
}  // namespace haet
