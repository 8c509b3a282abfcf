// Pictures from the command line: final.png of a 3D run as [output] asks (view, color_by, color_range,
// picture_width) and the errors of those keys; `haet render` on a run directory (a PNG per snapshot, the same bytes
// twice, a movie when ffmpeg is there, exit 2 on a missing or broken run); `haet plot` of a run's series.
#include <png.h>

#include "cli_util.hpp"
#include "run/render.hpp"

namespace haet::testing::cli {
namespace {

std::pair<unsigned, unsigned> pngSize(const fs::path& file) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, file.c_str())) return {0, 0};
    const std::pair<unsigned, unsigned> wh{image.width, image.height};
    png_image_free(&image);
    return wh;
}

TEST_F(Cli, PictureKeysAreChecked) {
    expectBadInput(edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\ncolor_by = \"pressure\""), "color_by",
                   "output.color_by");
    expectBadInput(edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\ncolor_by = \"mode\""), "color_by",
                   "output.color_by");
    expectBadInput(edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\ncolor_by = \"velocity_w\""), "color_by",
                   "output.color_by");
    expectBadInput(edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\nview = \"up\""), "view", "output.view");
    expectBadInput(edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\nview = [0, 0, 0]"), "view", "output.view");
    expectBadInput(edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\nview = [0, 1]"), "view", "output.view");
    expectBadInput(edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\ncolor_range = [1, 0]"), "color_range",
                   "output.color_range");
    expectBadInput(
        edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\ncolor_by = \"material\"\ncolor_range = [0, 1]"),
        "color_range", "output.color_range");
    expectBadInput(edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\npicture_width = 20"), "picture_width",
                   "output.picture_width");
    std::string flat = haet::testing::sceneText("box2d_settle.toml");
    flat = haet::testing::replaced(flat, "snapshot_period = 0.05", "snapshot_period = 0.05\nview = \"x\"");
    const fs::path f = write("flat.toml", flat);
    const Result r = haet("check '" + f.string() + "'");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find(":" + std::to_string(lineOf(flat, "view")) + ": output.view: only for dimension = 3"),
              std::string::npos)
        << r.err;
}

TEST_F(Cli, FinalPictureOfA3dRun) {
    const fs::path f = write("tiny.toml", edit("snapshot_period = 5e-4",
                                               "snapshot_period = 5e-4\nview = \"-z\"\ncolor_by = \"velocity_z\"\n"
                                               "color_range = [-0.02, 0.0]\npicture_width = 400"));
    const Result r = haet("run -q '" + f.string() + "' --out '" + (dir_ / "out").string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    // Seen from above the 1 cm cube is square: 400 px of view and the key's strip beside it.
    EXPECT_EQ(pngSize(dir_ / "out" / "final.png"), (std::pair<unsigned, unsigned>{400 + 170, 400}));
    const std::string json = read(dir_ / "out" / "run.json");
    EXPECT_TRUE(JsonCheck(json).valid()) << json;
    EXPECT_EQ(jsonString(json, "color_by"), "velocity_z");
    EXPECT_NE(json.find("\"hi\": [0.01, 0.01, 0.01]"), std::string::npos) << json;
    EXPECT_NE(json.find("\"materials\": [\"glass\"]"), std::string::npos) << json;
}

/// Runs kTiny (three snapshots) into dir_/run.
class Render : public Cli {
protected:
    fs::path run(const std::string& text = kTiny) {
        const fs::path f = write("tiny.toml", text);
        const Result r = haet("run -q '" + f.string() + "' --out '" + (dir_ / "run").string() + "'");
        EXPECT_EQ(r.code, 0) << r.err;
        return dir_ / "run";
    }
};

TEST_F(Render, EverySnapshotAsTheSameBytesTwice) {
    const fs::path runDir = run();
    fs::create_directories(dir_ / "a");
    write("a/frame_000009.png", "an earlier render's frame");
    const Result a =
        haet("render '" + runDir.string() + "' --no-movie --field velocity --out '" + (dir_ / "a").string() + "'");
    ASSERT_EQ(a.code, 0) << a.err;
    EXPECT_NE(a.err.find("3 frames"), std::string::npos) << a.err;
    const Result b =
        haet("render '" + runDir.string() + "' --no-movie --field velocity --out '" + (dir_ / "b").string() + "'");
    ASSERT_EQ(b.code, 0) << b.err;
    for (int k = 0; k < 3; ++k) {
        const std::string name = "frame_00000" + std::to_string(k) + ".png";
        const std::string bytes = read(dir_ / "a" / name);
        EXPECT_GT(bytes.size(), 1000u) << name;
        EXPECT_TRUE(bytes == read(dir_ / "b" / name)) << name << " differs between two renders";
    }
    EXPECT_FALSE(fs::exists(dir_ / "a" / "frame_000009.png")) << "an earlier render's frames are removed";
    EXPECT_FALSE(fs::exists(dir_ / "a" / "movie.mp4"));
    // Another view and field, into RUNDIR/render by default.
    const Result c = haet("render '" + runDir.string() + "' --no-movie --field material --view=-z --width 300");
    ASSERT_EQ(c.code, 0) << c.err;
    EXPECT_EQ(pngSize(runDir / "render" / "frame_000000.png"), (std::pair<unsigned, unsigned>{300 + 170, 300}));
}

// The last snapshot is the last state, drawn as final.png draws it (a categorical colouring: the colour bar of a
// render spans every snapshot, final.png's only the last state).
TEST_F(Render, LastFrameIsFinalPicture) {
    const fs::path runDir =
        run(edit("snapshot_period = 5e-4", "snapshot_period = 5e-4\ncolor_by = \"material\"\nview = [1, 2, -0.5]"));
    const Result r = haet("render '" + runDir.string() + "' --no-movie");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(read(runDir / "render" / "frame_000002.png") == read(runDir / "final.png"));
}

TEST_F(Render, MovieWhenFfmpegIsInstalled) {
    const fs::path runDir = run();
    // Without ffmpeg on PATH: the frames, and a note.
    const pid_t pid = spawn({"render", runDir.string(), "--out", (dir_ / "nof").string()}, {"PATH=/nonexistent"});
    ASSERT_EQ(wait(pid), 0) << read(dir_ / "stderr.txt");
    EXPECT_NE(read(dir_ / "stderr.txt").find("ffmpeg not found"), std::string::npos);
    EXPECT_TRUE(fs::exists(dir_ / "nof" / "frame_000002.png"));
    EXPECT_FALSE(fs::exists(dir_ / "nof" / "movie.mp4"));
    if (findOnPath("ffmpeg").empty()) GTEST_SKIP() << "ffmpeg is not installed";
    const Result r = haet("render '" + runDir.string() + "' --fps 5 --out '" + (dir_ / "mov").string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string mp4 = read(dir_ / "mov" / "movie.mp4");
    ASSERT_GT(mp4.size(), 100u);
    EXPECT_EQ(mp4.substr(4, 4), "ftyp");  // an MP4 (ISO base media) file
}

TEST_F(Render, BadRunDirectoriesExitWithCode2) {
    auto expectBad = [&](const std::string& args, const std::string& says) {
        const Result r = haet("render " + args);
        EXPECT_EQ(r.code, 2) << args << ": " << r.err;
        EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
    };
    expectBad("'" + (dir_ / "missing").string() + "'", "no such run directory");
    fs::create_directories(dir_ / "empty");
    expectBad("'" + (dir_ / "empty").string() + "'", "no run.json");
    const fs::path runDir = run();
    expectBad("'" + runDir.string() + "' --field pressure", "no such field");
    expectBad("'" + runDir.string() + "' --view up", "--view up");
    expectBad("'" + runDir.string() + "' --range 1,0", "--range");
    expectBad("'" + runDir.string() + "' --width 5", "--width");
    // A snapshot cut short names its file.
    const std::string snap = read(runDir / "particles_000001.vtu");
    write("run/particles_000001.vtu", snap.substr(0, snap.size() / 2));
    expectBad("'" + runDir.string() + "' --no-movie", "particles_000001.vtu");
    // A run.json that is not JSON, or without the box.
    fs::rename(runDir / "particles.pvd", dir_ / "particles.pvd");
    expectBad("'" + runDir.string() + "'", "no particles.pvd");
    fs::rename(dir_ / "particles.pvd", runDir / "particles.pvd");
    write("run/run.json", "{\"dimension\": 3,");
    expectBad("'" + runDir.string() + "'", "not valid JSON");
    write("run/run.json", "{\"dimension\": 3}");
    expectBad("'" + runDir.string() + "'", "no \"domain\"");
}

TEST_F(Render, PlotOfARunsSeries) {
    const fs::path runDir = run();
    const Result r = haet("plot '" + runDir.string() + "' -y kinetic_energy -y potential_energy");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(pngSize(runDir / "kinetic_energy.png"), (std::pair<unsigned, unsigned>{800, 500}));
    const Result o = haet("plot '" + (runDir / "series.csv").string() + "' -x step -y n_contacts -o '" +
                          (dir_ / "c.png").string() + "'");
    ASSERT_EQ(o.code, 0) << o.err;
    EXPECT_TRUE(fs::exists(dir_ / "c.png"));
    const Result bad = haet("plot '" + runDir.string() + "' -y discharge");
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.err.find("no column 'discharge'; it has time, step"), std::string::npos) << bad.err;
    const Result none = haet("plot '" + (dir_ / "nowhere").string() + "' -y time");
    EXPECT_EQ(none.code, 2);
    EXPECT_NE(none.err.find("no such file"), std::string::npos) << none.err;
}

}  // namespace
}  // namespace haet::testing::cli
