#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <regex>
#include <sstream>

#include "io/frame.hpp"

namespace haet {

const FrameField* ParticleFrame::field(const std::string& name) const {
    for (const FrameField& f : fields)
        if (f.name == name) return &f;
    return nullptr;
}

FrameField& ParticleFrame::add(std::string name, int components, VtkField::Type type) {
    fields.push_back({std::move(name), components, type, std::vector<double>(size() * components, 0.0)});
    return fields.back();
}

void writeFrameVtu(const std::filesystem::path& path, const ParticleFrame& frame) {
    // The integer arrays are stored as the file declares them; they live until the write returns.
    std::vector<std::shared_ptr<void>> keep;
    auto typed = [&]<class T>(const FrameField& f, T) -> const void* {
        auto v = std::make_shared<std::vector<T>>(f.values.size());
        std::transform(f.values.begin(), f.values.end(), v->begin(), [](double x) { return static_cast<T>(x); });
        keep.push_back(v);
        return v->data();
    };
    std::vector<VtkField> fields;
    for (const FrameField& f : frame.fields) {
        const void* data = f.values.data();
        if (f.type == VtkField::Int32) data = typed(f, std::int32_t{});
        if (f.type == VtkField::Int64) data = typed(f, std::int64_t{});
        if (f.type == VtkField::UInt8) data = typed(f, std::uint8_t{});
        fields.push_back({f.name, f.components, f.type, data});
    }
    writeVtuPoints(path, frame.size(), frame.xyz.data(), fields, frame.time);
}

namespace {

static_assert(std::endian::native == std::endian::little, "VTK raw input assumes a little-endian host");

/// One array of a file, with the section (PointData, Points, Cells, Lines, Polys, CellData, FieldData) it is in.
struct RawArray {
    std::string section, name;
    int components = 1;
    std::vector<double> values;
};

struct VtkFile {
    std::filesystem::path path;
    std::size_t points = 0, cells = 0, lines = 0, polys = 0;
    std::vector<RawArray> arrays;

    const RawArray* find(const std::string& section, const std::string& name) const {
        for (const RawArray& a : arrays)
            if (a.section == section && a.name == name) return &a;
        return nullptr;
    }
    const RawArray& need(const std::string& section, const std::string& name, int components,
                         std::size_t tuples) const {
        const RawArray* a = find(section, name);
        if (!a) throw VtkReadError(path, fmt::format("no array {} in {}", name, section));
        if (a->components != components || a->values.size() != tuples * static_cast<std::size_t>(components))
            throw VtkReadError(path, fmt::format("array {} in {} holds {} values in {} components, expected {} x {}",
                                                 name, section, a->values.size(), a->components, tuples, components));
        return *a;
    }
    double time() const {
        const RawArray* t = find("FieldData", "TimeValue");
        return t && !t->values.empty() ? t->values[0] : 0.0;
    }
};

std::string readAll(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw VtkReadError(path, "cannot be read");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// The value of attribute `key` in a tag's text, or "" (with found = false).
std::string attribute(const std::string& tag, const std::string& key, bool* found = nullptr) {
    const std::string pat = " " + key + "=\"";
    const std::size_t a = tag.find(pat);
    if (found) *found = a != std::string::npos;
    if (a == std::string::npos) return {};
    const std::size_t b = a + pat.size(), e = tag.find('"', b);
    std::string v = tag.substr(b, e == std::string::npos ? std::string::npos : e - b);
    static const std::pair<const char*, char> entities[] = {
        {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}, {"&amp;", '&'}};
    for (const auto& [ent, c] : entities)
        for (std::size_t k; (k = v.find(ent)) != std::string::npos;) v.replace(k, std::strlen(ent), 1, c);
    return v;
}

std::size_t count(const std::filesystem::path& path, const std::string& tag, const std::string& key) {
    bool found = false;
    const std::string v = attribute(tag, key, &found);
    if (!found) return 0;
    char* end = nullptr;
    const unsigned long long n = std::strtoull(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0') throw VtkReadError(path, fmt::format("{}=\"{}\" is not a count", key, v));
    return static_cast<std::size_t>(n);
}

/// Copies `n` values of type T from the block into doubles.
template <class T>
void convert(const char* src, std::size_t n, std::vector<double>& out) {
    out.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        T v;
        std::memcpy(&v, src + k * sizeof(T), sizeof(T));
        out[k] = static_cast<double>(v);
    }
}

VtkFile parseVtk(const std::filesystem::path& path, const std::string& kind) {
    const std::string text = readAll(path);
    VtkFile f;
    f.path = path;
    if (text.find("<VTKFile") == std::string::npos || text.find("type=\"" + kind + "\"") == std::string::npos)
        throw VtkReadError(path, "not a VTK " + kind + " file");
    if (text.find("header_type=\"UInt64\"") == std::string::npos ||
        text.find("byte_order=\"LittleEndian\"") == std::string::npos)
        throw VtkReadError(path, "only little-endian files with UInt64 headers are read (as HAET writes them)");
    const std::size_t appended = text.find("<AppendedData");
    const std::size_t marker = appended == std::string::npos ? appended : text.find('_', text.find('>', appended));
    if (marker == std::string::npos) throw VtkReadError(path, "no appended data section");
    const std::size_t data = marker + 1;
    const std::string head = text.substr(0, appended);
    std::string section;
    for (std::size_t i = head.find('<'); i != std::string::npos; i = head.find('<', i + 1)) {
        const std::size_t j = head.find('>', i);
        if (j == std::string::npos) throw VtkReadError(path, "unterminated XML tag");
        const std::string tag = head.substr(i + 1, j - i - 1);
        const std::string name = tag.substr(0, tag.find_first_of(" /\n"));
        if (name == "Piece") {
            f.points = count(path, tag, "NumberOfPoints");
            f.cells = count(path, tag, "NumberOfCells");
            f.lines = count(path, tag, "NumberOfLines");
            f.polys = count(path, tag, "NumberOfPolys");
        } else if (name == "PointData" || name == "CellData" || name == "Points" || name == "Cells" ||
                   name == "Lines" || name == "Polys" || name == "FieldData" || name == "Verts" || name == "Strips") {
            section = tag.back() == '/' ? std::string() : name;
        } else if (name == "DataArray") {
            RawArray a;
            a.section = section;
            a.name = attribute(tag, "Name");
            const std::string type = attribute(tag, "type");
            const std::string comps = attribute(tag, "NumberOfComponents");
            a.components = comps.empty() ? 1 : std::atoi(comps.c_str());
            if (attribute(tag, "format") != "appended")
                throw VtkReadError(path, "array " + a.name + ": only appended raw arrays are read");
            const std::size_t size = type == "Float64" || type == "Int64" ? 8 : type == "Int32" ? 4 : 1;
            if (type != "Float64" && type != "Int64" && type != "Int32" && type != "UInt8")
                throw VtkReadError(path, "array " + a.name + ": type " + type + " is not read");
            if (a.components < 1) throw VtkReadError(path, "array " + a.name + ": bad NumberOfComponents");
            const std::size_t at = data + count(path, tag, "offset");
            std::uint64_t bytes = 0;
            if (at + sizeof bytes > text.size()) throw VtkReadError(path, "array " + a.name + ": file cut short");
            std::memcpy(&bytes, text.data() + at, sizeof bytes);
            if (bytes > text.size() - at - sizeof bytes || bytes % (size * a.components) != 0)
                throw VtkReadError(path, "array " + a.name + ": file cut short or block of a wrong size");
            const char* src = text.data() + at + sizeof bytes;
            const std::size_t n = bytes / size;
            if (type == "Float64") convert<double>(src, n, a.values);
            if (type == "Int64") convert<std::int64_t>(src, n, a.values);
            if (type == "Int32") convert<std::int32_t>(src, n, a.values);
            if (type == "UInt8") convert<std::uint8_t>(src, n, a.values);
            f.arrays.push_back(std::move(a));
        } else if (!name.empty() && name[0] == '/') {
            section.clear();
        }
    }
    return f;
}

/// Cell ranges from VTK's end offsets: first = {0, end...}, checked against the connectivity.
std::vector<std::int64_t> cellFirst(const VtkFile& f, const RawArray& offsets, std::size_t connectivity) {
    std::vector<std::int64_t> first{0};
    for (double e : offsets.values) {
        if (!(e >= static_cast<double>(first.back()) && e <= static_cast<double>(connectivity)))
            throw VtkReadError(f.path, "cell offsets out of order or beyond the connectivity");
        first.push_back(static_cast<std::int64_t>(e));
    }
    return first;
}

std::vector<std::int64_t> indices(const VtkFile& f, const RawArray& conn) {
    std::vector<std::int64_t> idx(conn.values.size());
    for (std::size_t k = 0; k < idx.size(); ++k) {
        const double v = conn.values[k];
        if (!(v >= 0 && v < static_cast<double>(f.points)))
            throw VtkReadError(f.path, "a cell refers to a point that does not exist");
        idx[k] = static_cast<std::int64_t>(v);
    }
    return idx;
}

}  // namespace

ParticleFrame readFrameVtu(const std::filesystem::path& path) {
    const VtkFile f = parseVtk(path, "UnstructuredGrid");
    ParticleFrame fr;
    fr.time = f.time();
    fr.xyz = f.need("Points", "Points", 3, f.points).values;
    for (const RawArray& a : f.arrays) {
        if (a.section != "PointData") continue;
        f.need("PointData", a.name, a.components, f.points);
        fr.fields.push_back({a.name, a.components, VtkField::Float64, a.values});
    }
    return fr;
}

WallShapes readVtpShapes(const std::filesystem::path& path) {
    const VtkFile f = parseVtk(path, "PolyData");
    WallShapes sh;
    const RawArray& pts = f.need("Points", "Points", 3, f.points);
    for (std::size_t p = 0; p < f.points; ++p)
        sh.point(pts.values[3 * p], pts.values[3 * p + 1], pts.values[3 * p + 2]);
    const RawArray& ids = f.need("CellData", "wall_id", 1, f.lines + f.polys);
    auto cells = [&](const char* section, std::size_t n, std::vector<std::int64_t>& index,
                     std::vector<std::int64_t>& first) {
        const RawArray* conn = f.find(section, "connectivity");
        const RawArray* offs = f.find(section, "offsets");
        if (!conn || !offs) throw VtkReadError(path, std::string("no cells in ") + section);
        f.need(section, "offsets", 1, n);
        index = indices(f, *conn);
        first = cellFirst(f, *offs, index.size());
    };
    cells("Lines", f.lines, sh.lineIndex, sh.lineFirst);
    cells("Polys", f.polys, sh.polyIndex, sh.polyFirst);
    for (std::size_t c = 0; c < f.lines + f.polys; ++c)
        (c < f.lines ? sh.lineWall : sh.polyWall).push_back(static_cast<std::int32_t>(ids.values[c]));
    return sh;
}

PolygonOutlines readPolygonVtu(const std::filesystem::path& path) {
    const VtkFile f = parseVtk(path, "UnstructuredGrid");
    const RawArray& pts = f.need("Points", "Points", 3, f.points);
    const RawArray* conn = f.find("Cells", "connectivity");
    if (!conn) throw VtkReadError(path, "no cells");
    const std::vector<std::int64_t> idx = indices(f, *conn);
    const std::vector<std::int64_t> first = cellFirst(f, f.need("Cells", "offsets", 1, f.cells), idx.size());
    const RawArray& id = f.need("CellData", "id", 1, f.cells);
    PolygonOutlines out;
    for (std::size_t c = 0; c < f.cells; ++c) {
        out.id.push_back(static_cast<std::int64_t>(id.values[c]));
        auto& o = out.outline.emplace_back();
        for (std::int64_t k = first[c]; k < first[c + 1]; ++k)
            o.push_back({pts.values[3 * idx[k]], pts.values[3 * idx[k] + 1]});
    }
    return out;
}

std::vector<PvdEntry> readPvd(const std::filesystem::path& path) {
    const std::string text = readAll(path);
    if (text.find("type=\"Collection\"") == std::string::npos) throw VtkReadError(path, "not a VTK collection");
    static const std::regex tag(R"(<DataSet\b[^>]*>)");
    std::vector<PvdEntry> out;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), tag); it != std::sregex_iterator(); ++it) {
        const std::string t = " " + it->str().substr(8);
        bool hasTime = false, hasFile = false;
        const std::string time = attribute(t, "timestep", &hasTime), file = attribute(t, "file", &hasFile);
        char* end = nullptr;
        const double v = std::strtod(time.c_str(), &end);
        if (!hasTime || !hasFile || file.empty() || time.empty() || *end != '\0')
            throw VtkReadError(path, "a DataSet without a time or a file: " + it->str());
        out.push_back({v, file});
    }
    return out;
}

}  // namespace haet
