#pragma once
// The `haet` command line run as a real process (HAET_BINARY) in a fresh directory per test, and checkers of what a
// run writes (series.csv, .pvd collections, run.json). Shared by the command line's tests.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "scenario_text.hpp"

namespace haet::testing::cli {

namespace fs = std::filesystem;

/// 1-based line of the first line of `text` that starts with `prefix`.
inline int lineOf(const std::string& text, const std::string& prefix) {
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

    /// Starts `haet ARGS` as a child process, its stdout and stderr to files in the test's directory, with the
    /// environment changed by `env`; returns its pid for signals and wait(). fileSizeLimit [bytes]: no file the child
    /// writes may grow beyond it (RLIMIT_FSIZE, with SIGXFSZ ignored: a write past it fails with EFBIG, as on a full
    /// disk), for the tests of failed writes without a full file system.
    pid_t spawn(const std::vector<std::string>& args, const std::vector<std::string>& env = {},
                rlim_t fileSizeLimit = RLIM_INFINITY) {
        const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
        std::vector<std::string> argv = {HAET_BINARY};
        argv.insert(argv.end(), args.begin(), args.end());
        std::fflush(stdout);  // or the child's freopen writes the parent's buffered output a second time
        std::fflush(stderr);
        const pid_t pid = fork();
        if (pid == 0) {
            std::freopen(out.c_str(), "w", stdout);
            std::freopen(err.c_str(), "w", stderr);
            if (fileSizeLimit != RLIM_INFINITY) {
                std::signal(SIGXFSZ, SIG_IGN);  // kept across exec
                const rlimit lim{fileSizeLimit, fileSizeLimit};
                setrlimit(RLIMIT_FSIZE, &lim);
            }
            for (const std::string& e : env)  // NAME=VALUE sets, NAME alone unsets
                if (e.find('=') == std::string::npos)
                    unsetenv(e.c_str());
                else
                    setenv(e.substr(0, e.find('=')).c_str(), e.substr(e.find('=') + 1).c_str(), 1);
            std::vector<char*> a;
            for (std::string& s : argv) a.push_back(s.data());
            a.push_back(nullptr);
            execv(a[0], a.data());
            _exit(127);
        }
        return pid;
    }
    /// Waits for a child of spawn(): its exit code, or 128 + the signal that killed it (as a shell reports it).
    static int wait(pid_t pid) {
        int status = 0;
        waitpid(pid, &status, 0);
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
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
inline const std::string kTiny = haet::testing::sceneText("drop3d_tiny.toml");

/// kTiny with the first line that starts with `from` replaced by `to` (which may hold several lines).
inline std::string edit(const std::string& from, const std::string& to) {
    std::string s = kTiny;
    const std::size_t at = s.find("\n" + from);
    EXPECT_NE(at, std::string::npos) << from;
    const std::size_t end = s.find('\n', at + 1);
    return s.substr(0, at + 1) + to + s.substr(end);
}

/// kTiny with the body of its [[insert]] block replaced by `body`.
inline std::string withInsert(const std::string& body, const std::string& text = kTiny) {
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
inline std::string jsonString(const std::string& json, const std::string& key) {
    const std::regex re("\"" + key + "\"\\s*:\\s*\"((?:[^\"\\\\]|\\\\.)*)\"");
    std::smatch m;
    return std::regex_search(json, m, re) ? m[1].str() : std::string("<missing>");
}

/// Checks series.csv: a header with the expected first columns, then rows of as many numeric (or empty) cells.
/// Returns the number of data rows.
inline int checkSeries(const fs::path& file) {
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
inline int checkPvd(const fs::path& pvdFile, const std::string& extension = ".vtu") {
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

}  // namespace haet::testing::cli
