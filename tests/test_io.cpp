// Output writers: atomic replacement, VTK files read back byte by byte, CSV/JSON text, PNG headers.
#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"
#include "io/json.hpp"
#include "io/png.hpp"
#include "io/series.hpp"
#include "io/vtk.hpp"
#include "temp_dir.hpp"

namespace haet {
namespace {

namespace fs = std::filesystem;

// A fresh directory per test, removed afterwards.
class IoTest : public testing::TempDirTest {
protected:
    IoTest() : TempDirTest("io") {}
    std::vector<fs::path> listDir() const {
        std::vector<fs::path> out;
        for (const auto& e : fs::directory_iterator(dir_)) out.push_back(e.path().filename());
        return out;
    }
};

template <class T>
T readRaw(const std::string& bytes, std::size_t at) {
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof v);
    return v;
}

/// The value of attribute `attr` in the first tag after `anchor` in `xml`.
std::string attributeAfter(const std::string& xml, const std::string& anchor, const std::string& attr) {
    const std::size_t a = xml.find(anchor);
    if (a == std::string::npos) return {};
    const std::size_t b = xml.find(attr + "=\"", a);
    const std::size_t end = xml.find('"', b + attr.size() + 2);
    return xml.substr(b + attr.size() + 2, end - b - attr.size() - 2);
}

using IoAtomicFile = IoTest;

TEST_F(IoAtomicFile, ReplacesContentAndLeavesNoTempFile) {
    const fs::path target = dir_ / "out.txt";
    writeFileAtomic(target, "first version, longer than the second\n");
    writeFileAtomic(target, "second\n");
    EXPECT_EQ(slurp(target), "second\n");
    EXPECT_EQ(listDir(), std::vector<fs::path>{"out.txt"});
}

TEST_F(IoAtomicFile, UncommittedStreamKeepsOldFile) {
    const fs::path target = dir_ / "big.bin";
    writeFileAtomic(target, "old");
    {
        AtomicOfstream out(target);
        out << "partial new content";
        EXPECT_TRUE(fs::exists(out.tempPath()));
        EXPECT_EQ(out.tempPath().filename().string(), "big.bin.tmp." + std::to_string(::getpid()));
        // destroyed without commit(), as when an exception unwinds a writer
    }
    EXPECT_EQ(slurp(target), "old");
    EXPECT_EQ(listDir(), std::vector<fs::path>{"big.bin"});
}

TEST_F(IoAtomicFile, CommittedStreamReplacesFile) {
    const fs::path target = dir_ / "big.bin";
    writeFileAtomic(target, "old");
    AtomicOfstream out(target);
    const std::uint32_t word = 0xdeadbeef;
    out.write(&word, sizeof word);
    out.commit();
    EXPECT_EQ(slurp(target), std::string(reinterpret_cast<const char*>(&word), sizeof word));
    EXPECT_EQ(listDir(), std::vector<fs::path>{"big.bin"});
}

TEST_F(IoAtomicFile, FailureThrowsIoErrorNamingThePath) {
    const fs::path target = dir_ / "missing_dir" / "x.txt";
    try {
        writeFileAtomic(target, "x");
        FAIL() << "expected IoError";
    } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
        EXPECT_EQ(e.path(), target);
    }
}

using IoVtk = IoTest;

TEST_F(IoVtk, VtuPointsReadBack) {
    const std::vector<double> xyz = {0.0, 0.1, 0.2, 1.5, -2.25, 3e-7, 1e300, 4.0, -0.0};
    const std::vector<double> vel = {1, 2, 3, 4, 5, 6, 7, 8, 9.5};
    const std::vector<std::int64_t> ids = {10, -20, (std::int64_t{1} << 40)};
    const double time = 0.125;
    const fs::path file = dir_ / "p.vtu";
    writeVtuPoints(file, 3, xyz.data(),
                   {{"velocity", 3, VtkField::Float64, vel.data()}, {"id", 1, VtkField::Int64, ids.data()}}, time);

    const std::string bytes = slurp(file);
    const std::size_t marker = bytes.find("<AppendedData encoding=\"raw\">");
    ASSERT_NE(marker, std::string::npos);
    const std::string xml = bytes.substr(0, marker);
    EXPECT_NE(xml.find("type=\"UnstructuredGrid\""), std::string::npos);
    EXPECT_NE(xml.find("header_type=\"UInt64\""), std::string::npos);
    EXPECT_NE(xml.find("byte_order=\"LittleEndian\""), std::string::npos);
    EXPECT_NE(xml.find("NumberOfPoints=\"3\""), std::string::npos);
    EXPECT_NE(xml.find("NumberOfCells=\"3\""), std::string::npos);
    const std::size_t start = bytes.find('_', marker) + 1;  // offsets count from the byte after '_'

    // First block: the TimeValue field data, one Float64.
    EXPECT_EQ(attributeAfter(xml, "Name=\"TimeValue\"", "offset"), "0");
    // Without NumberOfTuples, VTK's reader silently returns an empty TimeValue array.
    EXPECT_EQ(attributeAfter(xml, "Name=\"TimeValue\"", "NumberOfTuples"), "1");
    ASSERT_EQ(readRaw<std::uint64_t>(bytes, start), sizeof(double));
    EXPECT_EQ(readRaw<double>(bytes, start + 8), time);

    auto block = [&](const std::string& name, std::uint64_t expectBytes) {
        const std::size_t at = start + std::stoull(attributeAfter(xml, "Name=\"" + name + "\"", "offset"));
        EXPECT_EQ(readRaw<std::uint64_t>(bytes, at), expectBytes) << name;
        return at + 8;
    };
    const std::size_t points = block("Points", 9 * sizeof(double));
    for (int k = 0; k < 9; ++k) EXPECT_EQ(readRaw<double>(bytes, points + 8 * k), xyz[k]) << k;
    const std::size_t velocity = block("velocity", 9 * sizeof(double));
    for (int k = 0; k < 9; ++k) EXPECT_EQ(readRaw<double>(bytes, velocity + 8 * k), vel[k]) << k;
    EXPECT_EQ(attributeAfter(xml, "Name=\"velocity\"", "NumberOfComponents"), "3");
    const std::size_t id = block("id", 3 * sizeof(std::int64_t));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(readRaw<std::int64_t>(bytes, id + 8 * k), ids[k]) << k;
    const std::size_t types = block("types", 3);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(static_cast<int>(bytes[types + k]), 1);  // VTK_VERTEX
    const std::size_t offsets = block("offsets", 3 * sizeof(std::int64_t));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(readRaw<std::int64_t>(bytes, offsets + 8 * k), k + 1);

    EXPECT_EQ(bytes.substr(bytes.size() - 30), "\n  </AppendedData>\n</VTKFile>\n");
    EXPECT_EQ(listDir(), std::vector<fs::path>{"p.vtu"});
}

TEST_F(IoVtk, VtuPolygonsWriteCsrCells) {
    // A triangle and a square.
    const std::vector<double> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 3, 1, 0, 2, 1, 0};
    const std::vector<std::uint32_t> csr = {0, 3, 7};
    const std::vector<std::int32_t> material = {4, 5};
    const fs::path file = dir_ / "poly.vtu";
    writeVtuPolygons(file, xyz, csr, {{"material", 1, VtkField::Int32, material.data()}}, 1.0);
    const std::string bytes = slurp(file);
    const std::string xml = bytes.substr(0, bytes.find("<AppendedData"));
    EXPECT_NE(xml.find("NumberOfPoints=\"7\" NumberOfCells=\"2\""), std::string::npos);
    const std::size_t start = bytes.find('_', xml.size()) + 1;
    const std::size_t offsets = start + std::stoull(attributeAfter(xml, "Name=\"offsets\"", "offset"));
    EXPECT_EQ(readRaw<std::uint64_t>(bytes, offsets), 16u);
    EXPECT_EQ(readRaw<std::int64_t>(bytes, offsets + 8), 3);
    EXPECT_EQ(readRaw<std::int64_t>(bytes, offsets + 16), 7);
    const std::size_t types = start + std::stoull(attributeAfter(xml, "Name=\"types\"", "offset"));
    EXPECT_EQ(static_cast<int>(bytes[types + 8]), 7);  // VTK_POLYGON

    const std::vector<std::uint32_t> bad = {0, 2, 7};
    EXPECT_THROW(writeVtuPolygons(file, xyz, bad, {}, 1.0), std::invalid_argument);
}

TEST_F(IoVtk, VtpWallsHaveOnePolygonPerWall) {
    WallQuad floor{{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}}, 3};
    WallQuad side{{{{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}}, 8};
    const fs::path file = dir_ / "walls.vtp";
    writeVtpWalls(file, {floor, side});
    const std::string bytes = slurp(file);
    const std::string xml = bytes.substr(0, bytes.find("<AppendedData"));
    EXPECT_NE(xml.find("type=\"PolyData\""), std::string::npos);
    EXPECT_NE(xml.find("NumberOfPoints=\"8\""), std::string::npos);
    EXPECT_NE(xml.find("NumberOfPolys=\"2\""), std::string::npos);
    const std::size_t start = bytes.find('_', xml.size()) + 1;
    const std::size_t ids = start + std::stoull(attributeAfter(xml, "Name=\"wall_id\"", "offset"));
    EXPECT_EQ(readRaw<std::uint64_t>(bytes, ids), 8u);
    EXPECT_EQ(readRaw<std::int32_t>(bytes, ids + 8), 3);
    EXPECT_EQ(readRaw<std::int32_t>(bytes, ids + 12), 8);
}

TEST_F(IoVtk, PvdListsFilesInOrder) {
    const fs::path pvd = dir_ / "run.pvd";
    PvdCollection collection(pvd);
    EXPECT_NE(slurp(pvd).find("<Collection>"), std::string::npos);  // valid before the first snapshot
    collection.add(0.0, "snap_0000.vtu");
    collection.add(0.5, "snap_0001.vtu");
    collection.add(0.5, "walls_0001.vtp", 1);
    collection.add(1.25, "snap_0002.vtu");
    const std::string text = slurp(pvd);
    const std::size_t a = text.find("timestep=\"0\" group=\"\" part=\"0\" file=\"snap_0000.vtu\"");
    const std::size_t b = text.find("timestep=\"0.5\" group=\"\" part=\"0\" file=\"snap_0001.vtu\"");
    const std::size_t c = text.find("timestep=\"0.5\" group=\"\" part=\"1\" file=\"walls_0001.vtp\"");
    const std::size_t d = text.find("timestep=\"1.25\" group=\"\" part=\"0\" file=\"snap_0002.vtu\"");
    ASSERT_NE(a, std::string::npos);
    ASSERT_NE(d, std::string::npos);
    EXPECT_LT(a, b);
    EXPECT_LT(b, c);
    EXPECT_LT(c, d);
    EXPECT_EQ(text.substr(text.size() - 27), "  </Collection>\n</VTKFile>\n");
    EXPECT_EQ(collection.size(), 4u);
}

using IoSeries = IoTest;

TEST_F(IoSeries, CsvTextWithEmptyCell) {
    const fs::path file = dir_ / "energy.csv";
    {
        SeriesWriter series(file, {"t", "E_kin", "note,quoted"}, std::chrono::hours(1));
        EXPECT_EQ(slurp(file), "t,E_kin,\"note,quoted\"\n");  // header written at once
        series.row({0.0, 1.5, 3.0});
        series.row({0.1, std::nullopt, 1e-300});
        series.row({1.0 / 3.0, -2.0, std::numeric_limits<double>::quiet_NaN()});
        EXPECT_EQ(slurp(file), "t,E_kin,\"note,quoted\"\n");  // not yet flushed
        series.flush();
        const std::string expected =
            "t,E_kin,\"note,quoted\"\n"
            "0,1.5,3\n"
            "0.1,,1e-300\n"
            "0.3333333333333333,-2,nan\n";
        EXPECT_EQ(slurp(file), expected);
        EXPECT_EQ(series.text(), expected);
        EXPECT_THROW(series.row({1.0}), std::invalid_argument);
        series.row({2.0, 2.0, 2.0});
    }
    // The destructor flushes rows added since the last flush.
    EXPECT_NE(slurp(file).find("\n2,2,2\n"), std::string::npos);
    EXPECT_EQ(listDir(), std::vector<fs::path>{"energy.csv"});
}

TEST_F(IoSeries, FlushesAutomaticallyAfterInterval) {
    const fs::path file = dir_ / "s.csv";
    SeriesWriter series(file, {"a"}, std::chrono::milliseconds(0));
    series.row({7.0});
    EXPECT_EQ(slurp(file), "a\n7\n");
}

TEST(IoJson, EscapingAndNonFinite) {
    JsonObject o;
    o.add("quote", "say \"hi\"")
        .add("backslash", std::string("C:\\path"))
        .add("control", std::string("a\nb\tc\x01"))
        .add("nan", std::numeric_limits<double>::quiet_NaN())
        .add("inf", -std::numeric_limits<double>::infinity())
        .add("one", 1.0)
        .add("tenth", 0.1)
        .add("count", 42)
        .add("big", std::uint64_t{18446744073709551615u})
        .add("flag", true)
        .add("vec", std::vector<double>{1.5, std::nan(""), -3});
    EXPECT_EQ(o.dump(0),
              R"({"quote":"say \"hi\"","backslash":"C:\\path","control":"a\nb\tc\u0001","nan":null,"inf":null,)"
              R"("one":1.0,"tenth":0.1,"count":42,"big":18446744073709551615,"flag":true,"vec":[1.5,null,-3.0]})");
}

TEST(IoJson, NestedPrettyPrintAndReplace) {
    JsonObject inner;
    inner.add("dt", 1e-5).add("method", "tdm");
    JsonObject o;
    o.add("version", "0.1.0").add("params", inner).add("empty", JsonObject{}).add("version", "0.2.0");
    EXPECT_EQ(o.dump(),
              "{\n"
              "  \"version\": \"0.2.0\",\n"
              "  \"params\": {\n"
              "    \"dt\": 1e-05,\n"
              "    \"method\": \"tdm\"\n"
              "  },\n"
              "  \"empty\": {}\n"
              "}");
    EXPECT_EQ(jsonQuote("\x7f\xc3\xa9"), "\"\x7f\xc3\xa9\"");  // DEL and UTF-8 pass through
}

using IoPng = IoTest;

// Width and height from the IHDR chunk, which PNG requires first, right after the 8-byte signature.
std::pair<std::uint32_t, std::uint32_t> pngSize(const std::string& bytes) {
    auto be32 = [&](std::size_t at) {
        std::uint32_t v = 0;
        for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
        return v;
    };
    return {be32(16), be32(20)};
}

TEST_F(IoPng, SceneHasSignatureAndWidth) {
    PngScene scene;
    scene.lo = {0, 0};
    scene.hi = {2, 1};
    scene.widthPx = 321;
    scene.disks = {{0.5, 0.5, 0.2, 0xcc3333}, {1.5, 0.5, 0.001, 0x3333cc}};
    scene.polygons = {{{{1.0, 0.2}, {1.3, 0.2}, {1.15, 0.6}}, 0x33cc33}};
    scene.walls = {{0, 0, 2, 0}};
    scene.caption = "t = 0.5 s";
    const fs::path file = dir_ / "scene.png";
    writePng(file, scene);
    const std::string bytes = slurp(file);
    ASSERT_GE(bytes.size(), 24u);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_EQ(bytes.substr(12, 4), "IHDR");
    EXPECT_EQ(pngSize(bytes), std::make_pair(321u, 161u));  // 321 * 1/2, rounded
    EXPECT_EQ(listDir(), std::vector<fs::path>{"scene.png"});

    scene.hi = {0, 1};
    EXPECT_THROW(writePng(file, scene), std::invalid_argument);
}

// The pixels read back with libpng: the disk's colour at its centre, white ground in the corner.
TEST_F(IoPng, PixelsReadBack) {
    PngScene scene;
    scene.lo = {0, 0};
    scene.hi = {1, 1};
    scene.widthPx = 200;
    scene.disks = {{0.5, 0.5, 0.25, 0xcc3366}};
    const fs::path file = dir_ / "pixels.png";
    writePng(file, scene);
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    ASSERT_TRUE(png_image_begin_read_from_file(&image, file.c_str())) << image.message;
    image.format = PNG_FORMAT_RGB;
    std::vector<unsigned char> px(PNG_IMAGE_SIZE(image));
    ASSERT_TRUE(png_image_finish_read(&image, nullptr, px.data(), 0, nullptr)) << image.message;
    ASSERT_EQ(image.width, 200u);
    ASSERT_EQ(image.height, 200u);
    auto at = [&](int x, int y) {
        const unsigned char* q = &px[3 * (static_cast<std::size_t>(y) * 200 + x)];
        return (std::uint32_t{q[0]} << 16) | (std::uint32_t{q[1]} << 8) | q[2];
    };
    EXPECT_EQ(at(100, 100), 0xcc3366u);
    EXPECT_EQ(at(190, 190), 0xffffffu);
}

TEST_F(IoPng, LinePlot) {
    PlotSeries a{"cell list", {1e2, 1e3, 1e4, 1e5}, {1e-5, 1.1e-4, 1.2e-3, 1.3e-2}, 0x1f77b4};
    PlotSeries b{"all pairs", {1e2, 1e3, 1e4}, {2e-5, 2e-3, std::nan("")}, 0xd62728};
    const fs::path file = dir_ / "plot.png";
    writeLinePlotPng(file, "time per step", "N", "s", {a, b},
                     {.widthPx = 640, .heightPx = 400, .logX = true, .logY = true});
    const std::string bytes = slurp(file);
    ASSERT_GE(bytes.size(), 24u);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_EQ(pngSize(bytes), std::make_pair(640u, 400u));

    writeLinePlotPng(dir_ / "linear.png", "empty", "x", "y", {});  // no data still gives axes
    EXPECT_TRUE(fs::exists(dir_ / "linear.png"));
}

}  // namespace
}  // namespace haet
