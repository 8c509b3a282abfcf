// Pictures from the command line: final.png of a 3D run as [output] asks (view, color_by, color_range,
// picture_width) and the errors of those keys; `haet render` on a run directory (a PNG per snapshot, the same bytes
// twice, a movie when ffmpeg is there, exit 2 on a missing or broken run); `haet plot` of a run's series.
#include <png.h>

#include "cli_util.hpp"

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

}  // namespace
}  // namespace haet::testing::cli
