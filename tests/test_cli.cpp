// The `haet` command line, run as a real process (HAET_BINARY) on scenario files written to a temporary directory:
// exit codes (0 ok, 2 bad input, 3 blew up), error messages "file:line: key: ...", and the files a run writes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "scenario_text.hpp"

namespace fs = std::filesystem;

namespace {

/// 1-based line of the first line of `text` that starts with `prefix`.
int lineOf(const std::string& text, const std::string& prefix) {
    std::istringstream in(text);
    std::string line;
    for (int k = 1; std::getline(in, line); ++k)
        if (line.rfind(prefix, 0) == 0) return k;
    ADD_FAILURE() << "no line starts with " << prefix;
    return 0;
}

/// A fresh directory per test, removed at the end.
class Cli : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("haet_cli_" + std::string(info->name()) + "_" + std::to_string(getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);  // keep the evidence of a failure
    }

    struct Result {
        int code = -1;
        std::string out, err;
    };

    /// Runs `haet ARGS` with stdout and stderr captured to files. Every run here takes well under a second; the
    /// timeout turns a hang into a failure (exit code 124) instead of a stuck test suite.
    Result haet(const std::string& args) {
        const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
        const std::string cmd = std::string("timeout 60 '") + HAET_BINARY + "' " + args + " > '" + out.string() +
                                "' 2> '" + err.string() + "' < /dev/null";
        const int status = std::system(cmd.c_str());
        Result r;
        r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        EXPECT_NE(r.code, 124) << "haet " << args << ": timed out after 60 s";
        r.out = read(out);
        r.err = read(err);
        return r;
    }

    fs::path write(const std::string& name, const std::string& text) {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }

    /// Writes `text` and expects `haet check` and `haet run` to exit with code 2 and "FILE:LINE: KEY" on stderr,
    /// LINE being the line of `text` that starts with `linePrefix`.
    void expectBadInput(const std::string& text, const std::string& linePrefix, const std::string& key) {
        const fs::path f = write("bad.toml", text);
        const std::string where = f.string() + ":" + std::to_string(lineOf(text, linePrefix)) + ": " + key;
        const Result c = haet("check '" + f.string() + "'");
        EXPECT_EQ(c.code, 2) << c.err;
        EXPECT_NE(c.err.find(where), std::string::npos) << "expected \"" << where << "\" in: " << c.err;
        const Result r = haet("run -q '" + f.string() + "' --out '" + (dir_ / "out").string() + "'");
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_NE(r.err.find(where), std::string::npos) << "expected \"" << where << "\" in: " << r.err;
        EXPECT_FALSE(fs::exists(dir_ / "out" / "run.json")) << "nothing is run on bad input";
    }

    static std::string read(const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
    }

    fs::path dir_;
};

// A tiny valid scenario: 8 spheres on a lattice drop onto a floor (examples/drop3d_tiny.toml).
const std::string kTiny = haet::testing::sceneText("drop3d_tiny.toml");

/// kTiny with the first line that starts with `from` replaced by `to` (which may hold several lines).
std::string edit(const std::string& from, const std::string& to) {
    std::string s = kTiny;
    const std::size_t at = s.find("\n" + from);
    EXPECT_NE(at, std::string::npos) << from;
    const std::size_t end = s.find('\n', at + 1);
    return s.substr(0, at + 1) + to + s.substr(end);
}

/// kTiny with the body of its [[insert]] block replaced by `body`.
std::string withInsert(const std::string& body, const std::string& text = kTiny) {
    const std::size_t a = text.find("[[insert]]\n") + 11, b = text.find("\n[output]");
    return text.substr(0, a) + body + text.substr(b);
}

// ---- a small JSON syntax checker for run.json (objects, arrays, strings, numbers, true/false/null) ----

class JsonCheck {
public:
    explicit JsonCheck(const std::string& s) : s_(s) {}
    bool valid() {
        ws();
        if (!value()) return false;
        ws();
        return i_ == s_.size();
    }

private:
    void ws() {
        while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
    }
    bool lit(const char* w) {
        const std::string t(w);
        if (s_.compare(i_, t.size(), t) != 0) return false;
        i_ += t.size();
        return true;
    }
    bool string() {
        if (i_ >= s_.size() || s_[i_] != '"') return false;
        for (++i_; i_ < s_.size(); ++i_) {
            const unsigned char c = s_[i_];
            if (c == '"') return ++i_, true;
            if (c < 0x20) return false;
            if (c == '\\') ++i_;
        }
        return false;
    }
    bool number() {
        static const std::regex re(R"(^-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?)");
        std::smatch m;
        const std::string rest = s_.substr(i_, 64);
        if (!std::regex_search(rest, m, re) || m.length(0) == 0) return false;
        i_ += m.length(0);
        return true;
    }
    bool value() {
        if (i_ >= s_.size()) return false;
        const char c = s_[i_];
        if (c == '{') return container('}', true);
        if (c == '[') return container(']', false);
        if (c == '"') return string();
        if (c == 't') return lit("true");
        if (c == 'f') return lit("false");
        if (c == 'n') return lit("null");
        return number();
    }
    bool container(char close, bool object) {
        ++i_;
        ws();
        if (i_ < s_.size() && s_[i_] == close) return ++i_, true;
        for (;;) {
            ws();
            if (object) {
                if (!string()) return false;
                ws();
                if (i_ >= s_.size() || s_[i_++] != ':') return false;
                ws();
            }
            if (!value()) return false;
            ws();
            if (i_ >= s_.size()) return false;
            if (s_[i_] == ',') {
                ++i_;
                continue;
            }
            if (s_[i_] == close) return ++i_, true;
            return false;
        }
    }

    const std::string& s_;
    std::size_t i_ = 0;
};

/// The string value of "key" in a JSON text (first occurrence; no unescaping needed for our checks).
std::string jsonString(const std::string& json, const std::string& key) {
    const std::regex re("\"" + key + "\"\\s*:\\s*\"((?:[^\"\\\\]|\\\\.)*)\"");
    std::smatch m;
    return std::regex_search(json, m, re) ? m[1].str() : std::string("<missing>");
}

/// Checks series.csv: a header with the expected first columns, then rows of as many numeric (or empty) cells.
/// Returns the number of data rows.
int checkSeries(const fs::path& file) {
    std::ifstream in(file);
    EXPECT_TRUE(in.good()) << file;
    std::string header;
    std::getline(in, header);
    EXPECT_EQ(header.rfind("time,step,kinetic_energy,", 0), 0u) << header;
    for (const char* col : {"rotational_energy", "elastic_energy", "total_energy", "n_particles", "n_contacts"})
        EXPECT_NE(header.find(col), std::string::npos) << col;
    const auto cells = [](const std::string& line) {
        std::vector<std::string> c;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ',')) c.push_back(cell);
        if (!line.empty() && line.back() == ',') c.push_back("");
        return c;
    };
    const std::size_t ncol = cells(header).size();
    int rows = 0;
    double lastTime = -1;
    for (std::string line; std::getline(in, line);) {
        const auto c = cells(line);
        EXPECT_EQ(c.size(), ncol) << "row " << rows + 1 << ": " << line;
        for (const std::string& v : c) {
            if (v.empty()) continue;
            char* end = nullptr;
            std::strtod(v.c_str(), &end);
            EXPECT_EQ(*end, '\0') << "not a number: " << v;
        }
        const double t = std::strtod(c[0].c_str(), nullptr);
        EXPECT_GT(t, lastTime) << "time must increase";
        lastTime = t;
        ++rows;
    }
    return rows;
}

/// Checks a .pvd collection: every listed file exists and is a VTK XML file of the given extension. Returns the
/// number listed.
int checkPvd(const fs::path& pvdFile, const std::string& extension = ".vtu") {
    std::ifstream in(pvdFile);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string pvd = ss.str();
    EXPECT_NE(pvd.find("<VTKFile"), std::string::npos) << pvdFile;
    EXPECT_NE(pvd.find("</VTKFile>"), std::string::npos) << pvdFile << " is complete";
    const std::regex fileRe("file=\"([^\"]+)\"");
    int listed = 0;
    for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), fileRe); it != std::sregex_iterator(); ++it) {
        const fs::path vtu = pvdFile.parent_path() / (*it)[1].str();
        EXPECT_EQ(vtu.extension(), extension);
        std::ifstream v(vtu);
        std::string head(200, '\0');
        v.read(head.data(), head.size());
        EXPECT_NE(head.find("<VTKFile"), std::string::npos) << vtu;
        ++listed;
    }
    return listed;
}

// ------------------------------------------------------------------------------------------------------------

TEST_F(Cli, VersionExitsZero) {
    const Result r = haet("--version");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE((r.out + r.err).find("haet"), std::string::npos);
}

TEST_F(Cli, NoSubcommandIsBadInput) {
    const Result r = haet("");
    EXPECT_EQ(r.code, 2);
}

TEST_F(Cli, CheckValidScenarioPrintsTimeStep) {
    const fs::path f = write("tiny.toml", kTiny);
    const Result r = haet("check '" + f.string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    // dt = t_c / steps_per_contact = 1e-4 / 50
    EXPECT_NE(r.out.find("time step"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("dt = 2e-06 s"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("8 "), std::string::npos) << "particle count: " << r.out;
}

TEST_F(Cli, UnknownKey) {
    expectBadInput(edit("friction = 0.5", "friction = 0.5\ncolour = \"green\""), "colour", "materials.glass.colour");
}

TEST_F(Cli, WrongType) {
    expectBadInput(edit("duration = 0.001", "duration = \"short\""), "duration = \"short\"", "duration");
}

TEST_F(Cli, NegativeRadius) { expectBadInput(edit("radius = 0.001", "radius = -0.001"), "radius", "insert[1].radius"); }

TEST_F(Cli, RestitutionAboveOne) {
    expectBadInput(edit("restitution = 0.8", "restitution = 1.2"), "restitution", "materials.glass.restitution");
}

TEST_F(Cli, OverlappingLattice) {
    expectBadInput(edit("radius = 0.001", "radius = 0.001\nspacing = 0.0015"), "spacing", "insert[1].spacing");
}

TEST_F(Cli, MissingParticleFile) {
    expectBadInput(withInsert("arrangement = \"file\"\nfile = \"no_such_file.csv\"\nmaterial = \"glass\"\n"),
                   "file = ", "insert[1].file");
}

TEST_F(Cli, MissingScenarioFile) {
    const fs::path f = dir_ / "does_not_exist.toml";
    const Result r = haet("check '" + f.string() + "'");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(f.string()), std::string::npos) << "the message names the file: " << r.err;
    const Result r2 = haet("run -q '" + f.string() + "'");
    EXPECT_EQ(r2.code, 2) << r2.err;
}

TEST_F(Cli, RunWritesOutputs) {
    const fs::path f = write("tiny.toml", kTiny);
    const fs::path out = dir_ / "run";
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    // series: a row at t = 0 and every series_period up to the duration
    EXPECT_EQ(checkSeries(out / "series.csv"), 11);
    const std::string json = read(out / "run.json");
    EXPECT_TRUE(JsonCheck(json).valid()) << json;
    EXPECT_EQ(jsonString(json, "status"), "completed");
    EXPECT_EQ(jsonString(json, "scenario_name"), "tiny");
    // snapshots at 0, 5e-4 and 1e-3 s, listed in the .pvd collection
    EXPECT_EQ(checkPvd(out / "particles.pvd"), 3);
    int vtuFiles = 0;
    for (const auto& e : fs::directory_iterator(out)) vtuFiles += e.path().extension() == ".vtu";
    EXPECT_EQ(vtuFiles, 3);
}

// --set KEY=VALUE: the run takes the value and records it in run.json; `check` prints it; a bad one exits 2 naming
// the override and the key, for `check` and `run` alike.
TEST_F(Cli, SetOverridesAValueAndIsRecorded) {
    const fs::path f = write("tiny.toml", kTiny);
    const Result c = haet("check '" + f.string() + "' --set tdm.dt=1e-5 --set 'insert[1].count=1'");
    ASSERT_EQ(c.code, 0) << c.err;
    EXPECT_NE(c.out.find("dt = 1e-05 s"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("set        tdm.dt=1e-5"), std::string::npos) << c.out;
    const fs::path out = dir_ / "run";
    const Result r =
        haet("run -q --set duration=5e-4 '" + f.string() + "' --out '" + out.string() + "' --set tdm.dt=1e-5");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(checkSeries(out / "series.csv"), 6);  // 5e-4 s instead of 1e-3 s, a row every 1e-4 s
    const std::string json = read(out / "run.json");
    EXPECT_TRUE(JsonCheck(json).valid()) << json;
    EXPECT_EQ(jsonString(json, "duration"), "5e-4") << json;
    EXPECT_EQ(jsonString(json, "tdm.dt"), "1e-5") << json;
    EXPECT_NE(json.find("\"steps\": 50"), std::string::npos) << json;
}

TEST_F(Cli, SetWithUnknownKeyOrBadValueIsBadInput) {
    const fs::path f = write("tiny.toml", kTiny);
    for (const char* set : {"tdm.dtt=1e-5", "insert[1].count=many", "materials.glass.restitution=2"}) {
        const std::string key = std::string(set).substr(0, std::string(set).find('='));
        const std::string where = f.string() + " (--set " + set + "): " + key + ": ";
        for (const std::string& cmd :
             {"check '" + f.string() + "'", "run -q '" + f.string() + "' --out '" + (dir_ / "out").string() + "'"}) {
            const Result r = haet(cmd + " --set '" + set + "'");
            EXPECT_EQ(r.code, 2) << cmd << " " << set << ": " << r.err;
            EXPECT_NE(r.err.find(where), std::string::npos) << "expected \"" << where << "\" in: " << r.err;
        }
    }
    EXPECT_FALSE(fs::exists(dir_ / "out" / "run.json")) << "nothing is run on bad input";
}

// method = "haet": the hybrid's columns in series.csv, the mode field in the snapshots, the zone images, and
// `haet check` naming the values in force.
TEST_F(Cli, HybridRunWritesModesZonesAndColumns) {
    const std::string text =
        edit("duration = 0.001", "duration = 0.002\nmethod = \"haet\"") + "\n[haet]\nrelabel_every = 20\n";
    const fs::path f = write("hybrid.toml", text);
    const Result c = haet("check '" + f.string() + "'");
    ASSERT_EQ(c.code, 0) << c.err;
    for (const char* key : {"haet", "phi_on", "relabel every 20 steps", "dt_min"})
        EXPECT_NE(c.out.find(key), std::string::npos) << key << " in: " << c.out;
    const fs::path out = dir_ / "run";
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(checkSeries(out / "series.csv"), 21);
    const std::string series = read(out / "series.csv");
    const std::string header = series.substr(0, series.find('\n'));
    for (const char* col :
         {"n_tdm", "n_edm", "events", "tdm_steps", "dissipated_tdm", "dissipated_edm", "energy_unaccounted"})
        EXPECT_NE(header.find(col), std::string::npos) << col << " in: " << header;
    EXPECT_EQ(checkPvd(out / "zones.pvd", ".vti"), 5);
    EXPECT_TRUE(fs::exists(out / "zones_000000.vti"));
    EXPECT_NE(read(out / "particles_000001.vtu").find("Name=\"mode\""), std::string::npos);
    const std::string json = read(out / "run.json");
    EXPECT_EQ(jsonString(json, "method"), "haet");
    EXPECT_EQ(jsonString(json, "status"), "completed");
}

// dt = t_c for 8 hot spheres (about 1 m/s) in a closed box: with omega dt = pi the linear spring is unstable
// (velocity Verlet needs omega dt < 2, docs/physics.md F.2), every contact pumps energy in, and within some 20 steps an
// overlap exceeds max_overlap. The run must stop with exit code 3, name the particle and the time, and keep what
// it wrote before.
TEST_F(Cli, BlowUpExitsThreeAndKeepsOutputs) {
    std::string text = withInsert(
        "arrangement = \"lattice\"\ncount = 8\nradius = 0.001\nspacing = 0.003\nmaterial = \"glass\"\n"
        "region = { lo = [0.002, 0.002, 0.002], hi = [0.008, 0.008, 0.008] }\ntemperature = 1.0\n");
    text = text.replace(text.find("duration = 0.001"), 16, "duration = 0.01");
    text = text.replace(text.find("series_period = 1e-4"), 20, "series_period = 1e-4    # = dt");
    std::string walls = "[tdm]\ndt = 1e-4                  # = t_c\n\n";
    for (const char* w :
         {"[0, 0, 0.01]\nnormal = [0, 0, -1]", "[0, 0, 0]\nnormal = [1, 0, 0]", "[0.01, 0, 0]\nnormal = [-1, 0, 0]",
          "[0, 0, 0]\nnormal = [0, 1, 0]", "[0, 0.01, 0]\nnormal = [0, -1, 0]"})
        walls += std::string("[[walls]]\npoint = ") + w + "\nmaterial = \"glass\"\n";
    text = text.replace(text.find("[[walls]]"), 0, walls);
    const fs::path f = write("blowup.toml", text);
    const fs::path out = dir_ / "run";
    const Result r = haet("run -q '" + f.string() + "' --out '" + out.string() + "'");
    EXPECT_EQ(r.code, 3) << r.out << r.err;
    EXPECT_TRUE(std::regex_search(r.err, std::regex("particle (id )?[0-9]+"))) << r.err;
    EXPECT_TRUE(std::regex_search(r.err, std::regex("t = [0-9.eE+-]+ s"))) << r.err;
    // what was written before the blow-up is still there and readable
    EXPECT_GE(checkSeries(out / "series.csv"), 5);  // a row every step (series_period = dt) until the blow-up
    const std::string json = read(out / "run.json");
    EXPECT_TRUE(JsonCheck(json).valid()) << json;
    EXPECT_EQ(jsonString(json, "status").rfind("failed", 0), 0u) << json;
    EXPECT_GE(checkPvd(out / "particles.pvd"), 1);  // the snapshot at t = 0
}

// The example of particles that come and go (examples/pour3d.toml): `haet check` describes its inlet, sizes and
// outlet; a bad inlet is bad input (exit 2 with file:line: key), in check and run alike.
TEST_F(Cli, CheckDescribesInletAndOutletOfThePourScene) {
    const Result r = haet(std::string("check '") + HAET_SOURCE_DIR + "/examples/pour3d.toml'");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("inlet      feed: 4000 particles/s"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("d50"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("outlet     drain: box"), std::string::npos) << r.out;
    std::string text = read(fs::path(HAET_SOURCE_DIR) / "examples" / "pour3d.toml");
    text.replace(text.find("rate = 4000"), 11, "rate = 0");
    expectBadInput(text, "rate = 0", "inlet[1].rate");
}

}  // namespace
