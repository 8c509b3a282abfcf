// The include layers of ARCHITECTURE.md ("Layers"): a source file includes project headers only from its own
// folder and from folders of lower layers. A change that reaches up (an engine including the scenario's
// definitions, say) fails here with the file, the line and the include.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>

namespace {

namespace fs = std::filesystem;

/// Layer of a project header or source, by its path below src/ ("tdm/engine.hpp"). World's state
/// (world/world.hpp) sits below the engines that share it; building a world from definitions sits above them.
/// io/ sits just above core/: a file format may hold core's vectors (an STL mesh's triangles), nothing else.
int layerOf(const std::string& path) {
    if (path == "world/world.hpp") return 3;
    static const std::map<std::string, int> kLayers = {
        {"core", 0},     {"io", 1},    {"geometry", 1}, {"contact", 2}, {"neighbor", 3},
        {"tdm", 4},      {"edm", 4},   {"polygon", 5},  {"haet", 6},    {"measure", 7},
        {"scenario", 8}, {"world", 9}, {"run", 10},     {"app", 11},    {"python", 11},
    };
    const auto it = kLayers.find(path.substr(0, path.find('/')));
    return it == kLayers.end() ? -1 : it->second;
}

TEST(Layers, IncludesRunOneWay) {
    const fs::path src = fs::path(HAET_SOURCE_DIR) / "src";
    const std::regex include(R"re(^\s*#\s*include\s+"([^"]+)")re");
    int files = 0;
    for (const auto& entry : fs::recursive_directory_iterator(src)) {
        if (!entry.is_regular_file()) continue;
        const std::string ext = entry.path().extension().string();
        if (ext != ".hpp" && ext != ".cpp" && ext != ".in") continue;
        const std::string self = fs::relative(entry.path(), src).generic_string();
        const int own = layerOf(self);
        ASSERT_GE(own, 0) << "src/" << self << ": its folder has no layer in tests/test_layers.cpp (and "
                          << "ARCHITECTURE.md, Layers)";
        ++files;
        std::ifstream in(entry.path());
        std::string line;
        for (int n = 1; std::getline(in, line); ++n) {
            std::smatch m;
            if (!std::regex_search(line, m, include)) continue;
            const std::string target = m[1].str();
            const int other = layerOf(target);
            if (other < 0) continue;  // a header of the same folder named without its folder, or generated
            const bool sameFolder = target.substr(0, target.find('/')) == self.substr(0, self.find('/'));
            EXPECT_TRUE(sameFolder || other < own)
                << "src/" << self << ":" << n << " includes \"" << target << "\" (layer " << other << ") from layer "
                << own << ": ARCHITECTURE.md, Layers";
        }
    }
    EXPECT_GT(files, 50);
}

/// Every project source below src/, with its path relative to src/.
template <class F>
void forEachSource(F&& f) {
    const fs::path src = fs::path(HAET_SOURCE_DIR) / "src";
    for (const auto& entry : fs::recursive_directory_iterator(src)) {
        if (!entry.is_regular_file()) continue;
        const std::string ext = entry.path().extension().string();
        if (ext == ".hpp" || ext == ".cpp") f(entry.path(), fs::relative(entry.path(), src).generic_string());
    }
}

// Files small enough to read as one job (ARCHITECTURE.md): a file that grows past this wants splitting by job.
TEST(Layers, NoSourceOver900Lines) {
    forEachSource([](const fs::path& file, const std::string& rel) {
        std::ifstream in(file);
        std::string line;
        int n = 0;
        while (std::getline(in, line)) ++n;
        EXPECT_LE(n, 900) << "src/" << rel << " has " << n << " lines";
    });
}

// SIMD lives in the lane layer (src/core/), each primitive with a portable twin: an algorithm file holds no
// intrinsic and no instruction-set #if, so a port (AVX-512, NEON) touches core/ only.
TEST(Layers, SimdOnlyInCore) {
    const std::regex simd(R"re((\b_mm\d*_\w+|\b__m(128|256|512)[di]?\b|immintrin\.h|#\s*if.*__(AVX|SSE|BMI)))re");
    forEachSource([&](const fs::path& file, const std::string& rel) {
        if (rel.rfind("core/", 0) == 0) return;
        std::ifstream in(file);
        std::string line;
        for (int n = 1; std::getline(in, line); ++n)
            EXPECT_FALSE(std::regex_search(line, simd)) << "src/" << rel << ":" << n << ": " << line;
    });
}

}  // namespace
