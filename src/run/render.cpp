#include "run/render.hpp"

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "io/atomic_file.hpp"
#include "io/frame.hpp"
#include "io/spheres.hpp"
#include "run/picture.hpp"

extern char** environ;

namespace haet {

namespace {

namespace fs = std::filesystem;

/// What the run's run.json says about its pictures.
struct RunInfo {
    PictureBox box;
    std::vector<std::string> materials;
    PictureOptions picture;
};

[[noreturn]] void bad(const fs::path& file, const std::string& what) {
    throw std::invalid_argument(file.string() + ": " + what);
}

RunInfo readRunInfo(const fs::path& dir) {
    const fs::path file = dir / "run.json";
    std::ifstream in(file, std::ios::binary);
    if (!in) bad(dir, "not a run directory: no run.json");
    std::ostringstream text;
    text << in.rdbuf();
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text.str());
    } catch (const nlohmann::json::exception& e) {
        bad(file, std::string("not valid JSON: ") + e.what());
    }
    RunInfo info;
    try {
        info.box.dimension = j.at("dimension").get<int>();
        if (info.box.dimension != 2 && info.box.dimension != 3) bad(file, "dimension must be 2 or 3");
        if (!j.contains("domain"))
            bad(file, "no \"domain\": written by an earlier version of haet; run the scenario again to render it");
        const auto& d = j.at("domain");
        for (const char* key : {"lo", "hi", "gravity"}) {
            const auto v = d.at(key).get<std::vector<double>>();
            if (static_cast<int>(v.size()) != info.box.dimension)
                bad(file, fmt::format("domain.{} must hold {} numbers", key, info.box.dimension));
            auto& to = std::string(key) == "lo"   ? info.box.lo
                       : std::string(key) == "hi" ? info.box.hi
                                                  : info.box.gravity;
            for (std::size_t k = 0; k < v.size(); ++k) to[k] = v[k];
        }
        if (j.contains("materials")) info.materials = j.at("materials").get<std::vector<std::string>>();
        if (j.contains("picture")) {
            const auto& p = j.at("picture");
            if (p.contains("color_by")) info.picture.colorBy = p.at("color_by").get<std::string>();
            if (p.contains("color_range")) {
                const auto r = p.at("color_range").get<std::vector<double>>();
                if (r.size() != 2 || !(r[1] > r[0])) bad(file, "picture.color_range must be [lo, hi] with hi > lo");
                info.picture.range = std::array<double, 2>{r[0], r[1]};
            }
            if (p.contains("view")) {
                const auto v = p.at("view").get<std::vector<double>>();
                if (v.size() != 3) bad(file, "picture.view must hold 3 numbers");
                info.picture.view = {v[0], v[1], v[2]};
            }
            if (p.contains("width")) info.picture.widthPx = p.at("width").get<int>();
        }
    } catch (const nlohmann::json::exception& e) {
        bad(file, std::string("unexpected content: ") + e.what());
    }
    return info;
}

/// The file of the same snapshot with another prefix: particles_000003.vtu -> walls_000003.vtp.
fs::path sibling(const fs::path& dir, const std::string& particlesFile, const std::string& prefix,
                 const std::string& extension) {
    const std::string stem = fs::path(particlesFile).stem().string();
    const std::string number = stem.rfind("particles_", 0) == 0 ? stem.substr(10) : stem;
    return dir / fs::path(particlesFile).parent_path() / (prefix + number + extension);
}

void removeEarlierRender(const fs::path& out) {
    static const std::regex names(R"((frame_[0-9]{6,}\.png|movie\.mp4)(\.tmp\.[0-9]+)?)");
    std::error_code ec;
    std::vector<fs::path> old;
    for (fs::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec))
        if (std::regex_match(it->path().filename().string(), names)) old.push_back(it->path());
    if (ec) throw IoError(out, "cannot read the output directory: " + ec.message());
    for (const fs::path& p : old)
        if (!fs::remove(p, ec) && ec) throw IoError(p, "cannot remove an earlier render's file: " + ec.message());
}

/// Encodes the frames as H.264 in an MP4 (even sizes, as yuv420p needs), written beside the target and renamed.
void writeMovie(const fs::path& ffmpeg, const fs::path& out, double fps) {
    const fs::path target = out / "movie.mp4";
    const fs::path temp = out / ("movie.mp4.tmp." + std::to_string(getpid()));
    std::vector<std::string> args = {ffmpeg.string(),
                                     "-hide_banner",
                                     "-loglevel",
                                     "error",
                                     "-nostdin",
                                     "-y",
                                     "-framerate",
                                     fmt::format("{}", fps),
                                     "-i",
                                     (out / "frame_%06d.png").string(),
                                     "-vf",
                                     "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white",
                                     "-c:v",
                                     "libx264",
                                     "-pix_fmt",
                                     "yuv420p",
                                     "-f",
                                     "mp4",
                                     temp.string()};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    if (posix_spawn(&pid, ffmpeg.c_str(), nullptr, nullptr, argv.data(), environ) != 0)
        throw IoError(target, "cannot start " + ffmpeg.string());
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) throw IoError(target, "lost ffmpeg");
    std::error_code ec;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        fs::remove(temp, ec);
        throw IoError(target, WIFEXITED(status) ? fmt::format("ffmpeg failed (exit code {})", WEXITSTATUS(status))
                                                : std::string("ffmpeg was killed"));
    }
    fs::rename(temp, target, ec);
    if (ec) throw IoError(target, "cannot rename the movie into place: " + ec.message());
}

}  // namespace

namespace {

/// Exactly n numbers separated by commas, in brackets or not.
std::optional<std::vector<double>> numberList(std::string t, std::size_t n) {
    if (t.size() >= 2 && t.front() == '[' && t.back() == ']') t = t.substr(1, t.size() - 2);
    std::vector<double> v;
    std::istringstream in(t);
    for (std::string part; std::getline(in, part, ',');) {
        char* end = nullptr;
        const double x = std::strtod(part.c_str(), &end);
        while (*end == ' ') ++end;
        if (end == part.c_str() || *end != '\0' || !std::isfinite(x)) return std::nullopt;
        v.push_back(x);
    }
    if (v.size() != n || (!t.empty() && t.back() == ',')) return std::nullopt;
    return v;
}

}  // namespace

std::optional<std::array<double, 3>> parseView(const std::string& text) {
    if (const auto axis = axisView(text)) return axis;
    const auto v = numberList(text, 3);
    if (!v || ((*v)[0] == 0 && (*v)[1] == 0 && (*v)[2] == 0)) return std::nullopt;
    return std::array<double, 3>{(*v)[0], (*v)[1], (*v)[2]};
}

std::optional<std::array<double, 2>> parseRange(const std::string& text) {
    const auto v = numberList(text, 2);
    if (!v || !((*v)[1] > (*v)[0])) return std::nullopt;
    return std::array<double, 2>{(*v)[0], (*v)[1]};
}

fs::path findOnPath(const std::string& program) {
    const char* path = std::getenv("PATH");
    if (!path) return {};
    std::istringstream dirs(path);
    for (std::string d; std::getline(dirs, d, ':');) {
        if (d.empty()) continue;
        const fs::path p = fs::path(d) / program;
        std::error_code ec;
        if (fs::is_regular_file(p, ec) && access(p.c_str(), X_OK) == 0) return p;
    }
    return {};
}

RenderSummary renderRun(const RenderOptions& o, std::ostream& log) {
    std::error_code ec;
    if (!fs::is_directory(o.runDir, ec)) bad(o.runDir, "no such run directory");
    const RunInfo info = readRunInfo(o.runDir);
    const fs::path pvd = o.runDir / "particles.pvd";
    if (!fs::exists(pvd, ec)) bad(o.runDir, "not a run directory: no particles.pvd");
    const std::vector<PvdEntry> entries = readPvd(pvd);
    if (entries.empty()) bad(pvd, "no snapshots");
    if (info.box.dimension == 2 && o.view) bad(o.runDir, "--view: a 2D run is drawn in its plane");
    if (!(o.fps > 0 && o.fps <= 1000)) throw std::invalid_argument("--fps must be in (0, 1000]");

    PictureOptions pic = info.picture;
    if (o.field) pic.colorBy = *o.field;
    if (o.view) pic.view = *o.view;
    if (o.range) pic.range = o.range;
    if (o.widthPx) pic.widthPx = *o.widthPx;
    if (pic.widthPx < 64 || pic.widthPx > 4096) throw std::invalid_argument("--width must be 64 to 4096 px");
    auto frameAt = [&](std::size_t k) { return readFrameVtu(o.runDir / entries[k].file); };
    {
        const ParticleFrame first = frameAt(0);
        if (pic.colorBy.empty()) pic.colorBy = defaultColorBy(first);
        try {
            colourValues(first, pic.colorBy);
        } catch (const VtkReadError&) {
            throw;
        } catch (const std::invalid_argument& e) {
            bad(o.runDir / entries[0].file, e.what());
        }
    }
    // One colour bar for the whole run: the field's range over every snapshot, unless given.
    if (!pic.range && pic.colorBy != "mode" && pic.colorBy != "material") {
        for (std::size_t k = 0; k < entries.size(); ++k)
            if (const auto r = colourRange(frameAt(k), pic.colorBy))
                pic.range = pic.range ? std::array<double, 2>{std::min((*pic.range)[0], (*r)[0]),
                                                              std::max((*pic.range)[1], (*r)[1])}
                                      : *r;
    }

    RenderSummary sum;
    sum.outDir = o.outDir.empty() ? o.runDir / "render" : o.outDir;
    fs::create_directories(sum.outDir, ec);
    if (ec || !fs::is_directory(sum.outDir, ec)) throw IoError(sum.outDir, "cannot create the output directory");
    removeEarlierRender(sum.outDir);
    for (std::size_t k = 0; k < entries.size(); ++k) {
        const ParticleFrame frame = frameAt(k);
        const fs::path wallsFile = sibling(o.runDir, entries[k].file, "walls_", ".vtp");
        const fs::path polyFile = sibling(o.runDir, entries[k].file, "polygons_", ".vtu");
        const WallShapes walls = fs::exists(wallsFile, ec) ? readVtpShapes(wallsFile) : WallShapes{};
        PolygonOutlines polygons;
        if (info.box.dimension == 2 && fs::exists(polyFile, ec)) polygons = readPolygonVtu(polyFile);
        writeFramePicture(sum.outDir / fmt::format("frame_{:06d}.png", k), frame, walls, info.box, pic, info.materials,
                          &polygons);
        ++sum.frames;
    }
    log << fmt::format("{} frames in {}\n", sum.frames, sum.outDir.string());
    if (!o.movie) return sum;
    const fs::path ffmpeg = findOnPath("ffmpeg");
    if (ffmpeg.empty()) {
        log << "ffmpeg not found on PATH: no movie (install ffmpeg for movie.mp4)\n";
        return sum;
    }
    writeMovie(ffmpeg, sum.outDir, o.fps);
    sum.movie = true;
    log << fmt::format("movie: {}\n", (sum.outDir / "movie.mp4").string());
    return sum;
}

}  // namespace haet
