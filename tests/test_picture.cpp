// Pictures: the orthographic projection of spheres (where a sphere lands, which of two covers the other, the walls
// clipped to the box), the colour bar's map and ticks, the plot's axis ticks, the colouring of a frame by its fields,
// the snapshot files read back as written, and the same bytes from the same scene.
#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "io/colour.hpp"
#include "io/frame.hpp"
#include "io/png.hpp"
#include "io/spheres.hpp"
#include "run/picture.hpp"
#include "temp_dir.hpp"

namespace haet {
namespace {

namespace fs = std::filesystem;

class Picture : public testing::TempDirTest {
protected:
    Picture() : TempDirTest("pic") {}
};

/// The unit cube seen along +y (x to the right, z up) at 900 px: 884 px/m inside an 8 px margin.
SphereScene cube() {
    SphereScene s;
    s.lo = {0, 0, 0};
    s.hi = {1, 1, 1};
    s.view = {0, 1, 0};
    s.up = {0, 0, 1};
    s.widthPx = 900;
    return s;
}

std::uint32_t pixel(const SphereImage& img, int x, int y) {
    return img.rgb[static_cast<std::size_t>(y) * img.width + x];
}
int red(std::uint32_t c) { return (c >> 16) & 0xff; }
int blue(std::uint32_t c) { return c & 0xff; }

TEST_F(Picture, ProjectionPlacesASphereOnItsPixels) {
    SphereScene s = cube();
    s.spheres = {{{0.25, 0.5, 0.75}, 0.05, 0xcc3366}};
    const OrthoView view(s);
    EXPECT_EQ(view.width(), 900);
    EXPECT_EQ(view.height(), 900);
    EXPECT_DOUBLE_EQ(view.scale(), 884.0);
    const auto c = view.toScreen({0.25, 0.5, 0.75});
    EXPECT_DOUBLE_EQ(c[0], 8 + 0.25 * 884);  // x to the right
    EXPECT_DOUBLE_EQ(c[1], 8 + 0.25 * 884);  // z up: 0.25 below the top
    const SphereImage img = renderSpheres(s);
    const double rp = 0.05 * 884;  // 44.2 px
    int covered = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const double dx = x + 0.5 - c[0], dy = y + 0.5 - c[1], d = std::sqrt(dx * dx + dy * dy);
            const bool sphere = std::isfinite(img.depth[static_cast<std::size_t>(y) * img.width + x]);
            covered += sphere;
            if (d < rp - 0.01) EXPECT_TRUE(sphere) << x << "," << y;
            if (d > rp + 0.01) EXPECT_FALSE(sphere) << x << "," << y;
        }
    EXPECT_NEAR(covered, 3.14159265 * rp * rp, 2 * 3.14159265 * rp);
    // The nearest point of the sphere, at its centre pixel, is r in front of the centre.
    EXPECT_NEAR(img.depth[static_cast<std::size_t>(229) * 900 + 229], (0.5 - 0.05) * 884, 0.05);
    // Looking along -y mirrors x.
    s.view = {0, -1, 0};
    EXPECT_DOUBLE_EQ(OrthoView(s).toScreen({0.25, 0.5, 0.75})[0], 8 + 0.75 * 884);
}

TEST_F(Picture, NearerSphereCoversFartherWhateverTheOrder) {
    SphereScene s = cube();
    const SphereScene::Sphere nearRed{{0.5, 0.3, 0.5}, 0.1, 0xff0000}, farBlue{{0.5, 0.7, 0.5}, 0.1, 0x0000ff};
    for (int order = 0; order < 2; ++order) {
        s.spheres = order == 0 ? std::vector{nearRed, farBlue} : std::vector{farBlue, nearRed};
        const SphereImage img = renderSpheres(s);
        const std::uint32_t c = pixel(img, 450, 450);
        EXPECT_GT(red(c), blue(c) + 100) << "order " << order;
        EXPECT_NEAR(img.depth[450 * 900 + 450], (0.3 - 0.1) * 884, 0.05);
    }
    // Side by side in depth but apart on screen, a smaller far sphere peeks out beside the near one.
    s.spheres = {nearRed, {{0.7, 0.9, 0.5}, 0.05, 0x0000ff}};
    const SphereImage img = renderSpheres(s);
    EXPECT_GT(blue(pixel(img, static_cast<int>(8 + 0.72 * 884), 450)), 100);
}

TEST_F(Picture, WallsAreClippedToTheBoxAndOutlined) {
    SphereScene s = cube();
    // A horizontal plane at z = 0.5 as a patch far larger than the box.
    const auto a = s.walls.point(-5, -5, 0.5), b = s.walls.point(5, -5, 0.5), c = s.walls.point(5, 5, 0.5),
               d = s.walls.point(-5, 5, 0.5);
    s.walls.poly({a, b, c, d}, 0);
    // Seen from above (along -z, y up), it tints the box and nothing outside it.
    s.view = {0, 0, -1};
    s.up = {0, 1, 0};
    const SphereImage top = renderSpheres(s);
    EXPECT_NE(pixel(top, 450, 450), 0xffffffu);
    EXPECT_EQ(pixel(top, 3, 450), 0xffffffu);  // in the margin, outside the box
    EXPECT_EQ(pixel(top, 450, 896), 0xffffffu);
    // Edge on (along +y), it is the line where it cuts the box, drawn dark.
    s.view = {0, 1, 0};
    s.up = {0, 0, 1};
    const SphereImage side = renderSpheres(s);
    const std::uint32_t mid = pixel(side, 450, 450);
    EXPECT_LT(red(mid), 0x60);
    EXPECT_EQ(pixel(side, 450, 300), 0xffffffu);
    // A patch over the back half of the box only: a sphere in front of its line hides it.
    SphereScene back = cube();
    const auto e = back.walls.point(-5, 0.5, 0.5), f = back.walls.point(5, 0.5, 0.5), g = back.walls.point(5, 5, 0.5),
               h = back.walls.point(-5, 5, 0.5);
    back.walls.poly({e, f, g, h}, 0);
    EXPECT_LT(red(pixel(renderSpheres(back), 450, 450)), 0x60);
    back.spheres = {{{0.5, 0.2, 0.5}, 0.05, 0xff0000}};
    EXPECT_GT(red(pixel(renderSpheres(back), 450, 450)), 150);
}

// A closed mesh (a cube of twelve triangles, wound outwards) is outlined where it turns away from the camera, not
// along the diagonals of its faces.
TEST_F(Picture, ClosedMeshesShowTheirSilhouette) {
    SphereScene s = cube();
    std::array<std::int64_t, 8> v{};
    for (int c = 0; c < 8; ++c) v[c] = s.walls.point(c & 1 ? 0.7 : 0.3, c & 2 ? 0.7 : 0.3, c & 4 ? 0.7 : 0.3);
    const int faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
    for (const auto& f : faces) {
        // Wound so that the normal points out of the cube (away from its centre).
        const auto& p = s.walls.points;
        std::array<double, 3> a = p[v[f[0]]], b = p[v[f[1]]], c = p[v[f[2]]], mid{0, 0, 0};
        for (int k = 0; k < 4; ++k)
            for (int d = 0; d < 3; ++d) mid[d] += p[v[f[k]]][d] / 4;
        const std::array<double, 3> u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const std::array<double, 3> n{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        const bool out = n[0] * (mid[0] - 0.5) + n[1] * (mid[1] - 0.5) + n[2] * (mid[2] - 0.5) > 0;
        const std::int64_t q0 = v[f[0]], q1 = v[f[out ? 1 : 3]], q2 = v[f[2]], q3 = v[f[out ? 3 : 1]];
        s.walls.poly({q0, q1, q2}, 0);
        s.walls.poly({q0, q2, q3}, 0);
    }
    const SphereImage img = renderSpheres(s);
    EXPECT_LT(red(pixel(img, 273, 450)), 0x60);  // the left side, x = 0.3: 8 + 0.3 * 884 = 273.2 px
    EXPECT_LT(red(pixel(img, 450, 626)), 0x60);  // the bottom, z = 0.3
    EXPECT_GT(red(pixel(img, 450, 450)), 0xa0);  // on the front face's diagonal: tinted, not outlined
    EXPECT_GT(red(pixel(img, 350, 400)), 0xa0);
    EXPECT_LT(red(pixel(img, 350, 400)), 0xff);
}

TEST_F(Picture, ViewSizeIsCapped) {
    SphereScene s = cube();
    s.hi = {1, 1, 40};  // a tall column: its height, not its width, sets the scale
    const OrthoView v(s);
    EXPECT_LE(v.height(), 4096);
    EXPECT_LT(v.width(), 900);
    s.hi = {1, 1, 1};
    s.widthPx = 100000;
    EXPECT_LE(OrthoView(s).width(), 4096);
    s.view = {0, 0, 0};
    EXPECT_THROW(OrthoView{s}, std::invalid_argument);
    s.view = {0, 0, 1};  // up parallel to the view
    EXPECT_THROW(OrthoView{s}, std::invalid_argument);
}

TEST_F(Picture, ColourBarMapsValuesOntoViridis) {
    const ColourBar bar{0, 10};
    EXPECT_EQ(bar.rgb(0), 0x440154u);   // viridis at 0
    EXPECT_EQ(bar.rgb(10), 0xfde725u);  // at 1
    EXPECT_EQ(bar.rgb(5), 0x21918cu);   // the middle sample
    EXPECT_EQ(bar.rgb(-3), bar.rgb(0));
    EXPECT_EQ(bar.rgb(1e9), bar.rgb(10));
    EXPECT_EQ(bar.rgb(std::nan("")), kNoValueColour);
    // Between two samples, linearly: 1/16 of the way is half-way from sample 0 to sample 1.
    EXPECT_EQ(bar.rgb(10.0 / 16), (70u << 16) | (23u << 8) | 104u);
    EXPECT_EQ(colourBarTicks(0, 1), (std::vector<double>{0, 0.2, 0.4, 0.6000000000000001, 0.8, 1}));
    const auto t = colourBarTicks(0.13, 0.87);
    ASSERT_EQ(t.size(), 7u);
    EXPECT_NEAR(t.front(), 0.2, 1e-12);
    EXPECT_NEAR(t.back(), 0.8, 1e-12);
    EXPECT_EQ(colourBarTicks(2, 2), std::vector<double>{2});
}

TEST_F(Picture, PlotAxisTicks) {
    const PlotAxis a = plotAxis(0.3, 9.7, false);
    EXPECT_EQ(a.lo, 0);
    EXPECT_EQ(a.hi, 10);
    EXPECT_EQ(a.ticks, (std::vector<double>{0, 2, 4, 6, 8, 10}));
    EXPECT_DOUBLE_EQ(a.fraction(5), 0.5);
    const PlotAxis n = plotAxis(-0.034, 0.012, false);  // step 0.01: -0.04 ... 0.02, with an exact zero
    EXPECT_NEAR(n.lo, -0.04, 1e-15);
    EXPECT_NEAR(n.hi, 0.02, 1e-15);
    ASSERT_EQ(n.ticks.size(), 7u);
    EXPECT_EQ(n.ticks[4], 0.0);
    const PlotAxis g = plotAxis(3, 2000, true);
    EXPECT_EQ(g.ticks, (std::vector<double>{1, 10, 100, 1000, 10000}));
    EXPECT_DOUBLE_EQ(g.fraction(100), 0.5);
    const PlotAxis e = plotAxis(1, 0, false);  // no data
    EXPECT_EQ(e.lo, 0);
    EXPECT_EQ(e.hi, 1);
}

ParticleFrame threeParticles() {
    ParticleFrame f;
    f.time = 0.5;
    f.xyz = {0, 0, 0, 1, 0, 0, 2, 0, 0};
    f.add("radius", 1, VtkField::Float64).values = {0.1, 0.1, 0.2};
    f.add("velocity", 3, VtkField::Float64).values = {3, 4, 0, 0, 0, -2, 0, 0, 0};
    f.add("material", 1, VtkField::Int32).values = {0, 1, 1};
    f.add("mode", 1, VtkField::Int32).values = {1, 0, 1};
    return f;
}

TEST_F(Picture, FramesAreColouredByTheirFields) {
    const ParticleFrame f = threeParticles();
    EXPECT_EQ(defaultColorBy(f), "mode");
    const ParticleColours m = colourParticles(f, "mode", std::nullopt, {});
    ASSERT_EQ(m.key.categories.size(), 2u);
    EXPECT_EQ(m.key.categories[0].label, "time-driven");
    EXPECT_EQ(m.rgb[0], m.key.categories[0].rgb);
    EXPECT_EQ(m.rgb[1], m.key.categories[1].rgb);
    const ParticleColours mat = colourParticles(f, "material", std::nullopt, {"glass", "steel"});
    ASSERT_EQ(mat.key.categories.size(), 2u);
    EXPECT_EQ(mat.key.categories[1].label, "steel");
    EXPECT_EQ(mat.rgb[2], categoryColour(1));
    // Speed: the magnitude 5, 2, 0 over the data's range [0, 5].
    const ParticleColours v = colourParticles(f, "velocity", std::nullopt, {});
    EXPECT_EQ(v.key.title, "|velocity| [m/s]");
    EXPECT_EQ(v.key.bar.lo, 0);
    EXPECT_EQ(v.key.bar.hi, 5);
    EXPECT_EQ(v.rgb[0], viridis(1));
    EXPECT_EQ(v.rgb[1], viridis(0.4));
    // A component, and a range given.
    const ParticleColours vz = colourParticles(f, "velocity_z", std::array<double, 2>{-4, 0}, {});
    EXPECT_EQ(vz.key.title, "velocity_z [m/s]");
    EXPECT_EQ(vz.rgb[1], viridis(0.5));
    EXPECT_EQ(*colourRange(f, "velocity_x"), (std::array<double, 2>{0, 3}));
    try {
        colourParticles(f, "pressure", std::nullopt, {});
        ADD_FAILURE() << "an unknown field must throw";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("velocity"), std::string::npos) << e.what();
    }
}

TEST_F(Picture, ScreenUpIsTheBoxAxisAgainstGravity) {
    using A = std::array<double, 3>;
    EXPECT_EQ(screenUp({0, 1, 0}, {0, 0, -9.81}), (A{0, 0, 1}));
    EXPECT_EQ(screenUp({0, 0, -1}, {0, 0, -9.81}), (A{0, 1, 0}));  // looking down: y up
    EXPECT_EQ(screenUp({0, 1, 0}, {4.9, 0, -8.5}), (A{0, 0, 1}));  // a chute's tilted gravity: the box stays upright
    EXPECT_EQ(screenUp({1, 0, 0}, {0, 0, 0}), (A{0, 0, 1}));
    EXPECT_EQ(screenUp({0, 1, 0}, {0, 9.81, 0}), (A{0, 0, 1}));  // along gravity: the first axis not parallel
    EXPECT_EQ(screenUp({1, 0, 0}, {0, -9.81, 0}), (A{0, 1, 0}));
}

TEST_F(Picture, SameSceneSameBytes) {
    SphereScene s = cube();
    for (int k = 0; k < 200; ++k)
        s.spheres.push_back({{0.05 + 0.9 * ((k * 37) % 200) / 200.0, 0.05 + 0.9 * ((k * 91) % 200) / 200.0,
                              0.05 + 0.9 * ((k * 53) % 200) / 200.0},
                             0.04,
                             viridis(k / 200.0)});
    s.caption = "t = 1 s";
    s.key.title = "x";
    s.key.bar = {0, 1};
    writeSpherePng(dir_ / "a.png", s);
    writeSpherePng(dir_ / "b.png", s);
    const std::string a = slurp(dir_ / "a.png");
    EXPECT_GT(a.size(), 1000u);
    EXPECT_EQ(a, slurp(dir_ / "b.png"));
    // The key widens the picture; the view keeps its size.
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    ASSERT_TRUE(png_image_begin_read_from_file(&image, (dir_ / "a.png").c_str()));
    EXPECT_EQ(image.width, 900u + 170u);
    EXPECT_EQ(image.height, 900u);
    png_image_free(&image);
}

TEST_F(Picture, SnapshotFilesReadBackAsWritten) {
    const ParticleFrame f = threeParticles();
    writeFrameVtu(dir_ / "p.vtu", f);
    const ParticleFrame g = readFrameVtu(dir_ / "p.vtu");
    EXPECT_EQ(g.time, f.time);
    EXPECT_EQ(g.xyz, f.xyz);
    ASSERT_EQ(g.fields.size(), f.fields.size());
    for (std::size_t k = 0; k < f.fields.size(); ++k) {
        EXPECT_EQ(g.fields[k].name, f.fields[k].name);
        EXPECT_EQ(g.fields[k].components, f.fields[k].components);
        EXPECT_EQ(g.fields[k].values, f.fields[k].values);
    }
    WallShapes w;
    const auto p0 = w.point(0, 0, 0), p1 = w.point(1, 0, 0), p2 = w.point(0, 1, 0);
    w.poly({p0, p1, p2}, 3);
    w.line({p0, p2}, 1);
    writeVtpShapes(dir_ / "w.vtp", w);
    const WallShapes v = readVtpShapes(dir_ / "w.vtp");
    EXPECT_EQ(v.points, w.points);
    EXPECT_EQ(v.polyIndex, w.polyIndex);
    EXPECT_EQ(v.polyFirst, w.polyFirst);
    EXPECT_EQ(v.polyWall, w.polyWall);
    EXPECT_EQ(v.lineIndex, w.lineIndex);
    EXPECT_EQ(v.lineWall, w.lineWall);
    // A file cut short, or not a snapshot, is an error naming it.
    const std::string bytes = slurp(dir_ / "p.vtu");
    std::ofstream(dir_ / "cut.vtu", std::ios::binary) << bytes.substr(0, bytes.size() - 80);
    EXPECT_THROW(readFrameVtu(dir_ / "cut.vtu"), VtkReadError);
    EXPECT_THROW(readFrameVtu(dir_ / "w.vtp"), VtkReadError);
    EXPECT_THROW(readFrameVtu(dir_ / "missing.vtu"), VtkReadError);
}

}  // namespace
}  // namespace haet
