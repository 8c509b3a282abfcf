// Citations of the physics reference: the sources and documents cite docs/physics.md by section ("docs/physics.md
// B.4", "docs/physics.md D.2-D.6", "docs/physics.md section A"). Every section cited must be a heading of that page,
// and every citation must name a file the project has: docs/physics.md (inside docs/, the name alone reads right too).
// The files searched: everything under src/, tests/, docs/, bench/ and examples/, and README.md and ARCHITECTURE.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace {

namespace fs = std::filesystem;

// Assembled from parts so that this file does not cite the page itself.
const std::string kName = std::string("physics") + ".md";

fs::path sourceDir() { return fs::path(HAET_SOURCE_DIR); }

std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// Text files that may cite the reference (a file with a NUL byte, such as a PNG, is skipped).
std::vector<fs::path> citingFiles() {
    const fs::path root = sourceDir();
    std::vector<fs::path> files;
    for (const char* dir : {"src", "tests", "docs", "bench", "examples"})
        for (const auto& e : fs::recursive_directory_iterator(root / dir))
            if (e.is_regular_file()) files.push_back(e.path());
    for (const char* f : {"README.md", "ARCHITECTURE.md"})
        if (fs::exists(root / f)) files.push_back(root / f);
    std::sort(files.begin(), files.end());
    std::erase_if(files, [](const fs::path& p) { return readFile(p).find('\0') != std::string::npos; });
    return files;
}

/// Section ids of the reference: "## B. Soft ..." gives "B", "### B.4 Tangential ..." gives "B.4", "## 0. ..." "0".
std::set<std::string> sections() {
    std::set<std::string> ids;
    std::istringstream in(readFile(sourceDir() / "docs" / kName));
    std::string line;
    while (std::getline(in, line)) {
        std::size_t k = 0;
        while (k < line.size() && line[k] == '#') ++k;
        if (k < 2 || k > 3 || k >= line.size() || line[k] != ' ') continue;
        const std::size_t b = ++k;
        if (k < line.size() && (std::isupper(static_cast<unsigned char>(line[k])) || line[k] == '0')) ++k;
        if (k == b) continue;
        if (k + 1 < line.size() && line[k] == '.' && std::isdigit(static_cast<unsigned char>(line[k + 1]))) {
            ++k;
            while (k < line.size() && std::isdigit(static_cast<unsigned char>(line[k]))) ++k;
        }
        if (k < line.size() && (line[k] == '.' || line[k] == ' ')) ids.insert(line.substr(b, k - b));
    }
    return ids;
}

bool startsWith(std::string_view s, std::size_t at, std::string_view p) { return s.substr(at, p.size()) == p; }

/// A section id at `at` ("B", "B.4", "0"), not followed by a letter or digit; its length, or 0.
std::size_t sectionToken(std::string_view s, std::size_t at) {
    if (at >= s.size()) return 0;
    std::size_t k = at;
    if (std::isupper(static_cast<unsigned char>(s[k])) || s[k] == '0')
        ++k;
    else
        return 0;
    if (k + 1 < s.size() && s[k] == '.' && std::isdigit(static_cast<unsigned char>(s[k + 1]))) {
        ++k;
        while (k < s.size() && std::isdigit(static_cast<unsigned char>(s[k]))) ++k;
    }
    if (k < s.size() && std::isalnum(static_cast<unsigned char>(s[k]))) return 0;
    return k - at;
}

/// Skips blanks and comment markers (//, /*, #), so that a citation may continue on the next comment line.
std::size_t skipBlanks(std::string_view s, std::size_t k) {
    while (k < s.size() && (s[k] == ' ' || s[k] == '\t' || s[k] == '\n' || s[k] == '/' || s[k] == '*' || s[k] == '#'))
        ++k;
    return k;
}

/// The sections cited right after the name at `at`: "B.2, B.4 and C.2", "D.2-D.6" (both ends), "B.2/B.3",
/// "section A", "\u00a70".
std::vector<std::string> citedAfter(std::string_view s, std::size_t at) {
    std::vector<std::string> out;
    std::size_t k = skipBlanks(s, at);
    if (startsWith(s, k, "\u00a7"))
        k += std::string_view("\u00a7").size();
    else if (startsWith(s, k, "sections "))
        k += 9;
    else if (startsWith(s, k, "section "))
        k += 8;
    for (;;) {
        const std::size_t n = sectionToken(s, k);
        if (n == 0) break;
        out.emplace_back(s.substr(k, n));
        k = skipBlanks(s, k + n);
        bool more = false;
        for (std::string_view sep : {",", "/", "-", "\u2013", "and ", "or "})
            if (startsWith(s, k, sep)) {
                k = skipBlanks(s, k + sep.size());
                more = true;
                break;
            }
        if (!more) break;
    }
    return out;
}

/// Positions of the name in `text`, in any letter case.
std::vector<std::size_t> occurrences(const std::string& text) {
    std::string lower(text);
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    std::vector<std::size_t> at;
    for (std::size_t k = lower.find(kName); k != std::string::npos; k = lower.find(kName, k + 1)) at.push_back(k);
    return at;
}

int lineOf(const std::string& text, std::size_t at) {
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

std::string where(const fs::path& file, const std::string& text, std::size_t at) {
    return fs::relative(file, sourceDir()).string() + ":" + std::to_string(lineOf(text, at));
}

}  // namespace

TEST(Docs, CitedPhysicsSectionsExist) {
    const std::set<std::string> ids = sections();
    for (const char* s : {"0", "A", "A.1", "B.4", "C.2", "D.7", "E.2", "F.3", "G.5", "J"})
        ASSERT_TRUE(ids.count(s)) << "docs/" << kName << " has no heading for section " << s;
    std::size_t cited = 0;
    for (const fs::path& file : citingFiles()) {
        const std::string text = readFile(file);
        for (std::size_t at : occurrences(text))
            for (const std::string& id : citedAfter(text, at + kName.size())) {
                ++cited;
                EXPECT_TRUE(ids.count(id)) << where(file, text, at) << " cites section " << id << " of docs/" << kName
                                           << ", which has no such heading";
            }
    }
    EXPECT_GT(cited, 50u) << "the search found too few citations: is HAET_SOURCE_DIR right?";
}

TEST(Docs, PhysicsReferenceIsCitedByItsPath) {
    ASSERT_TRUE(fs::exists(sourceDir() / "docs" / kName));
    const fs::path docs = sourceDir() / "docs";
    for (const fs::path& file : citingFiles()) {
        const std::string text = readFile(file);
        const bool inDocs = file.parent_path() == docs;
        for (std::size_t at : occurrences(text)) {
            // The old upper-case name is a file the project does not have; outside docs/ the page is named by its
            // path from the top of the project.
            const bool exact = text.compare(at, kName.size(), kName) == 0;
            const bool withPath = at >= 5 && text.compare(at - 5, 5, "docs/") == 0;
            EXPECT_TRUE(exact && (inDocs || withPath))
                << where(file, text, at) << " cites " << text.substr(at, kName.size()) << ": cite docs/" << kName;
        }
    }
}
