#include "io/stl.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <istream>
#include <string_view>

namespace haet {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kHeader = 84;  // 80 bytes of text, a uint32 count
constexpr std::size_t kRecord = 50;  // 12 float32 and a uint16 attribute

std::string errorText(const fs::path& path, const std::string& what, std::size_t triangle, int line) {
    std::string s = path.string();
    if (line > 0) s += ":" + std::to_string(line);
    s += ": ";
    if (triangle > 0) s += "triangle " + std::to_string(triangle) + ": ";
    return s + what;
}

bool isSpace(unsigned char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; }
/// A byte that plain text never holds (NUL and the other control codes but whitespace): the mark of binary data.
bool isControl(unsigned char c) { return (c < 0x20 && !isSpace(c)) || c == 0x7f; }
bool isControl(char c) { return isControl(static_cast<unsigned char>(c)); }

bool equalsNoCase(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t k = 0; k < a.size(); ++k)
        if (std::tolower(static_cast<unsigned char>(a[k])) != std::tolower(static_cast<unsigned char>(b[k])))
            return false;
    return true;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && isSpace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && isSpace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
}

/// Whether the text starts (after whitespace) with the keyword `solid` as a whole word.
bool startsWithSolid(std::string_view head) {
    std::size_t k = 0;
    while (k < head.size() && isSpace(static_cast<unsigned char>(head[k]))) ++k;
    if (head.size() - k < 5 || !equalsNoCase(head.substr(k, 5), "solid")) return false;
    return head.size() == k + 5 || isSpace(static_cast<unsigned char>(head[k + 5]));
}

std::uint32_t le32(const unsigned char* b) {
    return std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24;
}
double leFloat(const unsigned char* b) { return static_cast<double>(std::bit_cast<float>(le32(b))); }
void putLe32(std::string& out, std::uint32_t u) {
    for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((u >> (8 * k)) & 0xff));
}
void putFloat(std::string& out, double x) { putLe32(out, std::bit_cast<std::uint32_t>(static_cast<float>(x))); }

bool allFinite(const StlTriangle& t) {
    for (const auto& p : t)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(p[k])) return false;
    return true;
}

/// kStlDegenerateRatio: twice the area against the square of the longest edge.
bool degenerate(const StlTriangle& t) {
    const Vec<3> e0 = t[1] - t[0], e1 = t[2] - t[0], e2 = t[2] - t[1];
    const double longest2 = std::max({norm2(e0), norm2(e1), norm2(e2)});
    return !(norm(cross(e0, e1)) > kStlDegenerateRatio * longest2);
}

Vec<3> unitNormal(const StlTriangle& t) {
    const Vec<3> n = cross(t[1] - t[0], t[2] - t[0]);
    const double l = norm(n);
    return l > 0 ? n / l : Vec<3>{};
}

/// Reads a binary file of n = count triangles whose size has been checked to be 84 + 50 n.
void readBinary(std::istream& in, const fs::path& path, std::uint32_t count, StlMesh& mesh) {
    mesh.triangles.reserve(count);
    constexpr std::size_t kChunk = 1024;  // records read at once: bounded buffer whatever the count
    std::vector<unsigned char> buf(kChunk * kRecord);
    in.seekg(static_cast<std::streamoff>(kHeader));
    for (std::size_t done = 0; done < count;) {
        const std::size_t n = std::min<std::size_t>(kChunk, count - done);
        if (!in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n * kRecord)))
            throw StlError(path, "read error (binary STL)", done + 1);
        for (std::size_t r = 0; r < n; ++r) {
            const unsigned char* rec = buf.data() + r * kRecord + 12;  // skip the stored normal
            StlTriangle t;
            for (int v = 0; v < 3; ++v)
                for (int k = 0; k < 3; ++k) t[v][k] = leFloat(rec + 12 * v + 4 * k);
            const std::size_t index = done + r + 1;
            if (!allFinite(t)) throw StlError(path, "a vertex coordinate is not finite (NaN or inf)", index);
            if (degenerate(t)) throw StlError(path, "zero area (degenerate triangle)", index);
            mesh.triangles.push_back(t);
        }
        done += n;
    }
}

/// The ASCII grammar as a stream of whitespace-separated words with their line numbers, line by line.
class Words {
public:
    Words(std::istream& in, const fs::path& path) : in_(in), path_(path) {}
    /// The next word, or an empty view at the end of the file.
    std::string_view next() {
        for (;;) {
            while (pos_ < line_.size() && isSpace(static_cast<unsigned char>(line_[pos_]))) ++pos_;
            if (pos_ < line_.size()) {
                const std::size_t b = pos_;
                while (pos_ < line_.size() && !isSpace(static_cast<unsigned char>(line_[pos_]))) ++pos_;
                return std::string_view(line_).substr(b, pos_ - b);
            }
            if (!std::getline(in_, line_)) return {};
            ++lineNo_;
            pos_ = 0;
            for (const char c : line_)
                if (isControl(c))
                    throw StlError(path_, "a binary byte in an ASCII STL (a binary STL of the wrong size?)", 0,
                                   lineNo_);
        }
    }
    /// The rest of the current line (the name after `solid`), consumed.
    std::string_view restOfLine() {
        const std::string_view r = std::string_view(line_).substr(std::min(pos_, line_.size()));
        pos_ = line_.size();
        return trim(r);
    }
    int line() const { return lineNo_; }

private:
    std::istream& in_;
    const fs::path& path_;
    std::string line_;
    std::size_t pos_ = 0;
    int lineNo_ = 0;
};

void readAscii(std::istream& in, const fs::path& path, StlMesh& mesh) {
    in.seekg(0);
    Words w(in, path);
    std::size_t index = 0;  // 1-based index of the triangle being read, 0 outside a facet
    const auto fail = [&](const std::string& what) { throw StlError(path, what, index, w.line()); };
    const auto expect = [&](std::string_view keyword) {
        const std::string_view got = w.next();
        if (got.empty()) fail("unexpected end of file, expected '" + std::string(keyword) + "'");
        if (!equalsNoCase(got, keyword))
            fail("expected '" + std::string(keyword) + "', found '" + std::string(got) + "'");
    };
    // The stored normal is read as a number but not used, so a NaN there (some exporters write one) is let pass.
    const auto number = [&](const char* what, bool finite) {
        std::string_view s = w.next();
        if (s.empty()) fail(std::string("unexpected end of file, expected a number (") + what + ")");
        const std::string_view token = s;
        if (s.size() > 1 && s.front() == '+') s.remove_prefix(1);  // from_chars takes no '+'
        double x = 0;
        const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), x);
        if (ec == std::errc::result_out_of_range && end == s.data() + s.size()) {
            if (!finite) return 0.0;
            fail(std::string(what) + " '" + std::string(token) + "' is out of range (not finite)");
        }
        if (ec != std::errc() || end != s.data() + s.size())
            fail(std::string("expected a number (") + what + "), found '" + std::string(token) + "'");
        if (finite && !std::isfinite(x)) fail(std::string(what) + " '" + std::string(token) + "' is not finite");
        return x;
    };
    bool anySolid = false;
    for (;;) {
        const std::string_view kw = w.next();
        if (kw.empty()) break;
        if (!equalsNoCase(kw, "solid"))
            fail(std::string(anySolid ? "after 'endsolid' expected 'solid' or the end of the file"
                                      : "an ASCII STL starts with 'solid'") +
                 ", found '" + std::string(kw) + "'");
        const std::string_view name = w.restOfLine();
        if (!anySolid) mesh.name = std::string(name);
        anySolid = true;
        for (;;) {
            const std::string_view k = w.next();
            if (k.empty()) fail("unexpected end of file, expected 'facet' or 'endsolid'");
            if (equalsNoCase(k, "endsolid")) {
                w.restOfLine();  // the optional name
                break;
            }
            if (!equalsNoCase(k, "facet")) fail("expected 'facet' or 'endsolid', found '" + std::string(k) + "'");
            index = mesh.triangles.size() + 1;
            const int facetLine = w.line();
            expect("normal");
            for (int c = 0; c < 3; ++c) number("normal component", false);  // not used: the vertex order orients
            expect("outer");
            expect("loop");
            StlTriangle t;
            int nv = 0;
            for (;;) {
                const std::string_view v = w.next();
                if (v.empty()) fail("unexpected end of file, expected 'vertex' or 'endloop'");
                if (equalsNoCase(v, "endloop")) break;
                if (!equalsNoCase(v, "vertex")) fail("expected 'vertex' or 'endloop', found '" + std::string(v) + "'");
                if (nv == 3) fail("a facet with more than 3 vertices");
                for (int c = 0; c < 3; ++c) t[nv][c] = number("vertex coordinate", true);
                ++nv;
            }
            if (nv != 3) fail("a facet with " + std::to_string(nv) + " vertices, expected 3");
            expect("endfacet");
            if (degenerate(t)) throw StlError(path, "zero area (degenerate triangle)", index, facetLine);
            mesh.triangles.push_back(t);
            index = 0;
        }
    }
    if (!anySolid) fail("no 'solid' in an ASCII STL");
}

}  // namespace

StlError::StlError(const std::filesystem::path& path, const std::string& what, std::size_t triangle, int line)
    : std::runtime_error(errorText(path, what, triangle, line)), path_(path), triangle_(triangle), line_(line) {}

StlMesh readStl(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    if (!in || fs::is_directory(path, ec))
        throw StlError(path, fs::exists(path, ec) ? "cannot be read" : "no such file");
    return readStl(in, path);
}

StlMesh readStl(std::istream& in, const std::filesystem::path& path) {
    in.seekg(0, std::ios::end);
    const auto end = in.tellg();
    if (end < 0) throw StlError(path, "cannot be read (size unknown)");
    const auto size = static_cast<std::uint64_t>(end);
    if (size == 0) throw StlError(path, "is empty (0 bytes)");
    unsigned char head[kHeader];
    const std::size_t headBytes = static_cast<std::size_t>(std::min<std::uint64_t>(size, kHeader));
    in.seekg(0);
    if (!in.read(reinterpret_cast<char*>(head), static_cast<std::streamsize>(headBytes)))
        throw StlError(path, "cannot be read");

    StlMesh mesh;
    mesh.path = path;
    const std::string_view headText(reinterpret_cast<const char*>(head), headBytes);
    const std::uint32_t count = size >= kHeader ? le32(head + 80) : 0;
    const std::uint64_t binarySize = kHeader + kRecord * std::uint64_t(count);
    const bool control = std::any_of(head, head + headBytes, [](unsigned char c) { return isControl(c); });
    if (size >= kHeader && size == binarySize) {
        mesh.binary = true;
        std::string_view name = headText.substr(0, 80);
        const auto stop = std::find_if(name.begin(), name.end(), [](char c) { return isControl(c); });
        name = trim(name.substr(0, static_cast<std::size_t>(stop - name.begin())));
        if (startsWithSolid(name)) name = trim(name.substr(5));
        mesh.name = std::string(name);
        if (count == 0) throw StlError(path, "has no triangles (binary STL with a count of 0)");
        in.clear();
        readBinary(in, path, count, mesh);
    } else if (startsWithSolid(headText) && !control) {
        in.clear();
        readAscii(in, path, mesh);
        if (mesh.triangles.empty()) throw StlError(path, "has no triangles (ASCII STL)");
    } else if (size < kHeader) {
        throw StlError(path, "has " + std::to_string(size) +
                                 " bytes: not an ASCII STL (no 'solid' at the start) and too short for a binary "
                                 "STL (84-byte header)");
    } else if (size < binarySize) {
        const std::uint64_t whole = (size - kHeader) / kRecord;
        throw StlError(path,
                       "binary STL truncated: its header counts " + std::to_string(count) + " triangles (84 + 50 n = " +
                           std::to_string(binarySize) + " bytes), the file has " + std::to_string(size) + " bytes",
                       static_cast<std::size_t>(whole + 1));
    } else {
        throw StlError(path, "binary STL of " + std::to_string(count) + " triangles should have 84 + 50 n = " +
                                 std::to_string(binarySize) + " bytes, the file has " + std::to_string(size) + " (" +
                                 std::to_string(size - binarySize) + " bytes after the last triangle)");
    }
    return mesh;
}

std::array<Vec<3>, 3> stlRotation(const Vec<3>& axis, double angleDeg) {
    std::array<Vec<3>, 3> r{Vec<3>{{1, 0, 0}}, Vec<3>{{0, 1, 0}}, Vec<3>{{0, 0, 1}}};
    if (angleDeg == 0) return r;
    const Vec<3> u = axis / norm(axis);
    const double th = angleDeg * (3.14159265358979323846 / 180.0);
    const double c = std::cos(th), s = std::sin(th), C = 1 - c;
    // Rodrigues: R = c I + s [u]x + (1 - c) u u^T.
    r[0] = Vec<3>{{c + u[0] * u[0] * C, u[0] * u[1] * C - u[2] * s, u[0] * u[2] * C + u[1] * s}};
    r[1] = Vec<3>{{u[1] * u[0] * C + u[2] * s, c + u[1] * u[1] * C, u[1] * u[2] * C - u[0] * s}};
    r[2] = Vec<3>{{u[2] * u[0] * C - u[1] * s, u[2] * u[1] * C + u[0] * s, c + u[2] * u[2] * C}};
    return r;
}

void transformStl(StlMesh& mesh, const StlTransform& t) {
    for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(t.scale[k]) || t.scale[k] == 0)
            throw std::invalid_argument("STL scale factors must be finite and non-zero");
        if (!std::isfinite(t.translate[k])) throw std::invalid_argument("STL translation must be finite");
    }
    if (!std::isfinite(t.angle_deg)) throw std::invalid_argument("STL rotation angle must be finite");
    if (t.angle_deg != 0 && !(norm(t.axis) > 0 && std::isfinite(norm(t.axis))))
        throw std::invalid_argument("STL rotation axis must be finite and non-zero");
    const auto r = stlRotation(t.axis, t.angle_deg);
    const int negative = (t.scale[0] < 0) + (t.scale[1] < 0) + (t.scale[2] < 0);
    const bool mirror = negative % 2 == 1;
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        StlTriangle& tri = mesh.triangles[i];
        for (auto& p : tri) {
            const Vec<3> s{{t.scale[0] * p[0], t.scale[1] * p[1], t.scale[2] * p[2]}};
            p = Vec<3>{{dot(r[0], s), dot(r[1], s), dot(r[2], s)}} + t.translate;
        }
        if (mirror) std::swap(tri[1], tri[2]);
        if (!allFinite(tri)) throw StlError(mesh.path, "a vertex is not finite after the transform", i + 1);
        if (degenerate(tri)) throw StlError(mesh.path, "zero area (degenerate) after the transform", i + 1);
    }
}

std::string stlAscii(const std::vector<StlTriangle>& triangles, const std::string& name) {
    std::string out = "solid " + name + "\n";
    char buf[160];
    const auto put3 = [&](const char* prefix, const Vec<3>& p) {
        std::snprintf(buf, sizeof buf, "%s %.17g %.17g %.17g\n", prefix, p[0], p[1], p[2]);
        out += buf;
    };
    for (const auto& t : triangles) {
        put3("  facet normal", unitNormal(t));
        out += "    outer loop\n";
        for (const auto& p : t) put3("      vertex", p);
        out += "    endloop\n  endfacet\n";
    }
    return out + "endsolid " + name + "\n";
}

std::string stlBinary(const std::vector<StlTriangle>& triangles, const std::string& header) {
    std::string out = header.substr(0, 80);
    out.resize(80, '\0');
    putLe32(out, static_cast<std::uint32_t>(triangles.size()));
    for (const auto& t : triangles) {
        const Vec<3> n = unitNormal(t);
        for (int k = 0; k < 3; ++k) putFloat(out, n[k]);
        for (const auto& p : t)
            for (int k = 0; k < 3; ++k) putFloat(out, p[k]);
        out.push_back('\0');
        out.push_back('\0');
    }
    return out;
}

}  // namespace haet
