#include "scenario/insert.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "core/polygon_shape.hpp"
#include "neighbor/cell_grid.hpp"
#include "scenario/checks.hpp"
#include "scenario/text.hpp"
#include "scenario/walls.hpp"

namespace haet {
namespace {

std::string insertKey(std::size_t k) { return "insert[" + std::to_string(k + 1) + "]"; }

std::vector<std::string_view> splitOn(std::string_view s, char sep) {
    std::vector<std::string_view> out;
    std::size_t start = 0;
    while (true) {
        const auto at = s.find(sep, start);
        out.push_back(trim(s.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start)));
        if (at == std::string_view::npos) return out;
        start = at + 1;
    }
}

std::vector<std::string_view> whitespaceTokens(std::string_view s) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
        const std::size_t start = i;
        while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\r') ++i;
        if (i > start) out.push_back(s.substr(start, i - start));
    }
    return out;
}

/// A finite number taking the whole of `s` (a leading '+' is allowed), or nothing.
std::optional<double> parseDouble(std::string_view s) {
    if (!s.empty() && s[0] == '+') s.remove_prefix(1);
    double v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

std::optional<long long> parseInteger(std::string_view s) {
    if (!s.empty() && s[0] == '+') s.remove_prefix(1);
    long long v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
    return v;
}

/// The lines of a particle file one at a time, each without a trailing '\r' (files written on Windows). A line is
/// at most kMaxParticleLineBytes long and holds no NUL byte: anything else is not a particle file (a binary file, a
/// device such as /dev/zero), and a line is never read whole into memory before that is known.
class LineReader {
public:
    LineReader(std::istream& in, const std::string& name, const std::string& key) : in_(in), name_(name), key_(key) {}
    /// The next line into `line`; false at the end of the file. lineNumber() is then its number, from 1.
    bool next(std::string& line) {
        line.clear();
        std::streambuf* buf = in_.rdbuf();
        bool any = false;
        for (int c = buf->sbumpc(); c != std::char_traits<char>::eof(); c = buf->sbumpc()) {
            any = true;
            if (c == '\n') break;
            if (c == '\0') fail("a NUL byte: not a text file");
            if (line.size() == kMaxParticleLineBytes)
                fail("line longer than " + std::to_string(kMaxParticleLineBytes >> 20) + " MiB: not a particle file");
            line.push_back(char(c));
        }
        if (!any) return false;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        ++number_;
        return true;
    }
    int lineNumber() const { return number_; }

private:
    [[noreturn]] void fail(const std::string& what) const { throw ScenarioError({name_, number_ + 1}, key_, what); }

    std::istream& in_;
    const std::string& name_;
    const std::string& key_;
    int number_ = 0;
};

std::vector<std::string> readLines(std::istream& in, const std::string& name, const std::string& key) {
    LineReader reader(in, name, key);
    std::vector<std::string> lines;
    for (std::string line; reader.next(line);) lines.push_back(std::move(line));
    return lines;
}

/// Opens a particle file for the readers below (binary: the '\r' of a line end is the reader's).
std::ifstream openParticleFile(const std::filesystem::path& file, const std::string& key) {
    std::ifstream in(file, std::ios::binary);
    std::error_code ec;
    if (!in || std::filesystem::is_directory(file, ec))
        throw ScenarioError({file.string(), 0}, key, "cannot open the particle file");
    return in;
}

/// The polygon of an insert with shape = "polygon", circumradius r, drawn after the particle's position.
template <int D>
void makePolygon(const InsertDef& in, NewParticle<D>& p, Rng& rng) {
    if (in.shape != ShapeKind::Polygon) return;
    const double twoPi = 2 * 3.14159265358979323846;
    const int sides = in.sidesMin + int(rng.uniform() * (in.sidesMax - in.sidesMin + 1));
    p.orientation = in.orientation ? *in.orientation : rng.uniform(0, twoPi);
    switch (in.polygon) {
        case PolygonKind::Regular:
            p.body = polygon::regularPolygon(sides, p.radius, 0.0);
            break;
        case PolygonKind::Rectangle:
            p.body = polygon::rectangle(in.aspect, p.radius, 0.0);
            break;
        case PolygonKind::Random:
            p.body = polygon::randomConvexPolygon(rng, sides, p.radius, in.aspect, 0.0);
            break;
    }
}

}  // namespace

template <int D>
void finishParticle(const Scenario& s, const InsertDef& in, NewParticle<D>& p, Rng& rng) {
    makePolygon(in, p, rng);
    p.density = s.materials[std::size_t(in.material)].density;
    p.material = std::uint16_t(in.material);
    p.flags = in.frozen ? kFrozen : 0;
}

namespace {

/// A grid over the insert's region, expanded by one cell, holding the store's particles that could touch it.
template <int D>
OverlapGrid<D> gridWithExisting(const Particles<D>& store, const Vec<D>& lo, const Vec<D>& hi, double radiusMax,
                                std::size_t expected) {
    double maxR = radiusMax;
    for (double r : store.radius) maxR = std::max(maxR, r);
    const double margin = 2 * maxR;  // farther than this from the region, nothing can overlap a new particle
    OverlapGrid<D> grid(lo - Vec<D>::filled(margin), hi + Vec<D>::filled(margin), maxR, store.size() + expected);
    for (std::size_t i = 0; i < store.size(); ++i) {
        bool near = true;
        for (int k = 0; k < D; ++k) near = near && store.x[i][k] >= lo[k] - margin && store.x[i][k] <= hi[k] + margin;
        if (near) grid.add(store.x[i], store.radius[i]);
    }
    return grid;
}

}  // namespace

template <int D>
RandomPlacer<D>::RandomPlacer(const Scenario& s, const InsertDef& in, const Particles<D>& store, std::size_t expected)
    : s_(s),
      in_(in),
      lo_(toVec<D>(in.regionLo)),
      hi_(toVec<D>(in.regionHi)),
      grid_(gridWithExisting(store, lo_, hi_, in.radiusMax, expected)),
      walls_(std::make_unique<const WallClearance<D>>(s.walls)) {}

template <int D>
RandomPlacer<D>::~RandomPlacer() = default;
template <int D>
RandomPlacer<D>::RandomPlacer(RandomPlacer&&) noexcept = default;

template <int D>
std::uint64_t RandomPlacer<D>::place(NewParticle<D>& p, Rng& rng, std::uint64_t tries) {
    const double r = p.radius;
    for (std::uint64_t t = 1; t <= tries; ++t) {
        if (in_.slab) {  // a surface inlet's slab: uniform in its own frame, a disc face by rejection
            Vec<D> local;
            for (int a = 0; a < D; ++a) local[a] = (2 * rng.uniform() - 1) * (in_.slabHalf[std::size_t(a)] - r);
            if (in_.slabRound) {
                const double room = in_.slabHalf[0] - r;
                double rho2 = 0;
                for (int a = 0; a + 1 < D; ++a) rho2 += local[a] * local[a];
                if (rho2 > room * room) continue;
            }
            for (int k = 0; k < D; ++k) {
                p.x[k] = in_.slabCentre[std::size_t(k)];
                for (int a = 0; a < D; ++a) p.x[k] += local[a] * in_.slabAxes[std::size_t(a)][std::size_t(k)];
            }
            if (walls_->clear(p.x, r) && !grid_.overlaps(p.x, r)) {
                grid_.add(p.x, r);
                return t;
            }
            continue;
        }
        for (int a = 0; a < D; ++a) p.x[a] = lo_[a] + r + (hi_[a] - lo_[a] - 2 * r) * rng.uniform();
        if (in_.cylinder) {  // a vertical cylinder: the centre within R - r of the axis
            const double dx = p.x[0] - in_.cylinderCentre[0], dy = p.x[1] - in_.cylinderCentre[1];
            const double room = in_.cylinderRadius - r;
            if (dx * dx + dy * dy > room * room) continue;
        }
        if (walls_->clear(p.x, r) && !grid_.overlaps(p.x, r)) {
            grid_.add(p.x, r);
            return t;
        }
    }
    return 0;
}

template <int D>
void thermalVelocity(const InsertDef& in, NewParticle<D>& p, Rng& rng) {
    p.v = toVec<D>(in.velocity);
    if (in.temperature > 0 && !in.frozen) {
        const double sigma = std::sqrt(in.temperature);
        for (int k = 0; k < D; ++k) p.v[k] += sigma * rng.normal();
    }
}

namespace {

/// Velocities of a lattice or random insert: the mean `velocity` plus, when temperature > 0, a Maxwellian with
/// variance `temperature` per component whose net momentum is then removed, so the insert moves with `velocity`.
/// Frozen particles get `velocity` alone.
template <int D>
void assignVelocities(const InsertDef& in, std::vector<NewParticle<D>>& out, Rng& rng) {
    const Vec<D> mean = toVec<D>(in.velocity);
    const bool thermal = in.temperature > 0 && !in.frozen;
    for (auto& p : out) thermalVelocity(in, p, rng);
    if (!thermal || out.empty()) return;
    Vec<D> momentum = Vec<D>::zero();  // of the thermal part [kg m/s]
    double massSum = 0;
    for (const auto& p : out) {
        const double m = p.mass();
        momentum += m * (p.v - mean);
        massSum += m;
    }
    const Vec<D> drift = momentum / massSum;
    for (auto& p : out) p.v -= drift;
}

template <int D>
std::vector<NewParticle<D>> insertLattice(const Scenario& s, std::size_t k, const Particles<D>& store, Rng& rng) {
    const InsertDef& in = s.inserts[k];
    const double spacing = in.spacing.value_or(2 * in.radiusMax);
    if (!(spacing >= 2 * in.radiusMax))
        throw ScenarioError(
            in.pos, insertKey(k) + ".spacing",
            "lattice overlaps: spacing " + formatNumber(spacing) + " < 2 x radius " + formatNumber(2 * in.radiusMax));
    const Vec<D> lo = toVec<D>(in.regionLo), hi = toVec<D>(in.regionHi);
    std::array<std::uint64_t, D> n{};
    for (int a = 0; a < D; ++a) {
        const double room = hi[a] - lo[a] - 2 * in.radiusMax;  // span available to centres [m]
        // The small tolerance keeps a site that lands on the far edge up to rounding.
        n[a] = room < 0 ? 0 : std::uint64_t(std::floor(room / spacing + 1e-9)) + 1;
    }
    OverlapGrid<D> grid = gridWithExisting(store, lo, hi, in.radiusMax, in.count);
    const MaterialDef& mat = s.materials[std::size_t(in.material)];
    const WallClearance<D> walls(s.walls);
    std::vector<NewParticle<D>> out;
    std::array<std::uint64_t, D> site{};  // axis 0 runs fastest, so a lattice under gravity fills from the bottom up
    bool sitesLeft = true;
    for (int a = 0; a < D; ++a) sitesLeft = sitesLeft && n[a] > 0;
    while (sitesLeft && out.size() < in.count) {
        NewParticle<D> p;
        for (int a = 0; a < D; ++a)
            p.x[a] = std::min(lo[a] + in.radiusMax + double(site[a]) * spacing, hi[a] - in.radiusMax);
        p.radius = in.size.sample(rng);
        if (walls.clear(p.x, p.radius) && !grid.overlaps(p.x, p.radius)) {
            makePolygon(in, p, rng);
            p.density = mat.density;
            p.material = std::uint16_t(in.material);
            p.flags = in.frozen ? kFrozen : 0;
            out.push_back(p);
        }
        int a = 0;
        while (a < D && ++site[a] == n[a]) site[a++] = 0;
        sitesLeft = a < D;
    }
    assignVelocities(in, out, rng);
    return out;
}

template <int D>
std::vector<NewParticle<D>> insertRandom(const Scenario& s, std::size_t k, const Particles<D>& store, Rng& rng) {
    const InsertDef& in = s.inserts[k];
    RandomPlacer<D> placer(s, in, store, in.count);
    // Random sequential addition slows down sharply near its jamming limit (~0.38 volume fraction in 3D, ~0.55 area
    // fraction in 2D); these bounds end a hopeless insert in well under a second instead of running on.
    const std::uint64_t maxConsecutive = 20000;
    const std::uint64_t maxTotal = 200 * std::uint64_t(in.count) + 100000;
    std::uint64_t attempts = 0;
    std::vector<NewParticle<D>> out;
    out.reserve(in.count);
    for (std::size_t i = 0; i < in.count; ++i) {
        NewParticle<D> p;
        p.radius = in.size.sample(rng);
        const std::uint64_t tries = std::min(maxConsecutive, maxTotal - std::min(maxTotal, attempts));
        const std::uint64_t used = placer.place(p, rng, tries);
        attempts += used ? used : tries;
        if (!used)
            throw ScenarioError(in.pos, insertKey(k) + ".count",
                                "could not place " + std::to_string(in.count) +
                                    " particles without overlap: region too small (placed " + std::to_string(i) +
                                    " in " + std::to_string(attempts) + " attempts)");
        finishParticle(s, in, p, rng);
        out.push_back(p);
    }
    assignVelocities(in, out, rng);
    return out;
}

template <int D>
std::vector<NewParticle<D>> insertPolygonsFromFile(const Scenario& s, std::size_t k) {
    const InsertDef& in = s.inserts[k];
    const std::string key = insertKey(k) + ".file";
    std::vector<NewParticle<D>> out;
    for (const FilePolygon& fp : readPolygonCsv(in.file, s.materials, key)) {
        NewParticle<D> p;
        const polygon::Moments m = polygon::polygonMoments(fp.vertices.data(), int(fp.vertices.size()));
        for (int a = 0; a < D; ++a) {
            p.x[a] = m.centroid[a];
            if (p.x[a] < s.domain.lo[std::size_t(a)] || p.x[a] > s.domain.hi[std::size_t(a)])
                throw ScenarioError({in.file, fp.line}, key, "polygon centroid lies outside the domain");
            p.v[a] = fp.v[std::size_t(a)];
        }
        p.w[0] = fp.w;
        p.body = fp.vertices;
        for (Vec<2>& v : p.body) v -= m.centroid;
        p.radius = polygon::circumradius(p.body.data(), int(p.body.size()), Vec<2>::zero());
        const int mat = fp.material >= 0 ? fp.material : in.material;
        p.material = std::uint16_t(mat);
        p.density = s.materials[std::size_t(mat)].density;
        p.flags = (in.frozen || fp.frozen) ? kFrozen : 0;
        out.push_back(p);
    }
    return out;
}

template <int D>
std::vector<NewParticle<D>> insertFromFile(const Scenario& s, std::size_t k) {
    const InsertDef& in = s.inserts[k];
    if constexpr (D == 2)
        if (in.shape == ShapeKind::Polygon) return insertPolygonsFromFile<D>(s, k);
    const std::string key = insertKey(k) + ".file";
    const ParticleFile pf =
        in.format == FileFormat::Csv ? readParticleCsv(in.file, D, s.materials, key) : readLammpsData(in.file, key);
    checkFileParticles<D>(s, k, pf);  // sizes, box, overlaps of hard particles (scenario/checks.hpp)
    std::vector<NewParticle<D>> out;
    out.reserve(pf.particles.size());
    for (const FileParticle& fp : pf.particles) {
        NewParticle<D> p;
        p.x = toVec<D>(fp.x);
        p.v = toVec<D>(fp.v);
        if constexpr (D == 3) {
            p.w = toVec<3>(fp.w);
        } else {
            p.w[0] = fp.w[2];
        }
        p.radius = fp.radius;
        int mat = in.material;
        if (fp.material >= 0) mat = fp.material;
        if (fp.type > 0 && std::size_t(fp.type) <= s.materials.size()) mat = fp.type - 1;
        p.material = std::uint16_t(mat);
        if (fp.density) {
            // LAMMPS computes mass = density (4/3) pi r^3 in 2D as well; the areal density keeps that mass.
            p.density = (D == 3) ? *fp.density : *fp.density * (4.0 / 3.0) * fp.radius;
        } else {
            p.density = s.materials[std::size_t(mat)].density;
        }
        const bool frozenType =
            std::find(in.frozenTypes.begin(), in.frozenTypes.end(), fp.type) != in.frozenTypes.end();
        p.flags = (in.frozen || fp.frozen || frozenType) ? kFrozen : 0;
        for (int a = 0; a < D; ++a) p.image[a] = fp.image[std::size_t(a)];
        out.push_back(p);
    }
    return out;
}

/// The header row of a particle file: col[j] = the cell holding column names[j], or -1. An unknown or repeated
/// name fails; `known` lists the names for the message.
template <std::size_t N, class Fail>
std::array<int, N> headerColumns(const std::vector<std::string_view>& cells, const char* const (&names)[N],
                                 const char* known, const Fail& fail) {
    std::array<int, N> col;
    col.fill(-1);
    for (std::size_t c = 0; c < cells.size(); ++c) {
        int which = -1;
        for (std::size_t j = 0; j < N; ++j)
            if (cells[c] == names[j]) which = int(j);
        if (which < 0) fail("unknown column " + inQuotes(cells[c]) + " (" + known + ")");
        if (col[std::size_t(which)] >= 0) fail("column " + inQuotes(cells[c]) + " appears twice");
        col[std::size_t(which)] = int(c);
    }
    return col;
}

/// The material column of a particle file: a material name or its index.
template <class Fail>
int materialCell(std::string_view text, const std::vector<MaterialDef>& materials, const Fail& fail) {
    for (std::size_t m = 0; m < materials.size(); ++m)
        if (materials[m].name == text) return int(m);
    const auto idx = parseInteger(text);
    if (idx && *idx >= 0 && std::size_t(*idx) < materials.size()) return int(*idx);
    fail("column material: unknown material " + inQuotes(text));
    return -1;
}

/// The frozen column of a particle file: 0, 1, true or false.
template <class Fail>
bool frozenCell(std::string_view text, const Fail& fail) {
    if (text == "1" || text == "true") return true;
    if (text == "0" || text == "false") return false;
    fail("column frozen: expected 0, 1, true or false, got " + inQuotes(text));
    return false;
}

/// One record of a column file (readColumnFile): its fields, line, and the column of each name (-1: absent).
template <std::size_t N>
struct ColumnRecord {
    const std::vector<std::string_view>& cells;
    int line;
    const std::array<int, N>& col;
    const char* const (&names)[N];
    const std::function<void(const std::string&)>& fail;

    bool has(std::size_t c) const { return col[c] >= 0; }
    std::string_view cell(std::size_t c) const { return cells[std::size_t(col[c])]; }
    double number(std::size_t c) const {
        const auto v = parseDouble(cell(c));
        if (!v) fail(std::string("column ") + names[c] + ": expected a number, got " + inQuotes(cell(c)));
        return *v;
    }
};

/// A CSV file of named columns: blank lines and lines starting with '#' are skipped, the first other line is the
/// header (names from `names`, `known` listing them for the message), each later line a record with as many
/// fields. header(col, fail) checks the columns present, record(r) reads one record. `what` names a record
/// ("particle", "polygon") in the messages for a file without header or records.
template <std::size_t N, class Header, class Record>
void readColumnFile(std::istream& in, const std::string& name, const std::string& key, const char* const (&names)[N],
                    const char* known, const char* what, Header&& header, Record&& record) {
    const std::vector<std::string> lines = readLines(in, name, key);
    std::array<int, N> col;
    col.fill(-1);
    std::size_t fields = 0, records = 0;
    bool haveHeader = false;
    for (std::size_t li = 0; li < lines.size(); ++li) {
        const int lineNo = int(li + 1);
        const std::string_view line = trim(lines[li]);
        if (line.empty() || line[0] == '#') continue;
        const std::function<void(const std::string&)> fail = [&](const std::string& why) {
            throw ScenarioError({name, lineNo}, key, why);
        };
        const std::vector<std::string_view> cells = splitOn(line, ',');
        if (!haveHeader) {
            haveHeader = true;
            fields = cells.size();
            col = headerColumns(cells, names, known, fail);
            header(col, fail);
            continue;
        }
        if (cells.size() != fields)
            fail("expected " + std::to_string(fields) + " fields, got " + std::to_string(cells.size()));
        record(ColumnRecord<N>{cells, lineNo, col, names, fail});
        ++records;
    }
    if (!haveHeader) throw ScenarioError({name, 0}, key, std::string("empty ") + what + " file: no header line");
    if (records == 0)
        throw ScenarioError({name, int(lines.size())}, key, std::string("the file holds no ") + what + "s");
}

}  // namespace

ParticleFile readParticleCsv(const std::filesystem::path& file, int dimension,
                             const std::vector<MaterialDef>& materials, const std::string& key) {
    std::ifstream in = openParticleFile(file, key);
    return readParticleCsv(in, file.string(), dimension, materials, key);
}

ParticleFile readParticleCsv(std::istream& in, const std::string& name, int dimension,
                             const std::vector<MaterialDef>& materials, const std::string& key) {
    enum Column { X, Y, Z, Radius, Vx, Vy, Vz, Wx, Wy, Wz, Ix, Iy, Iz, Material, Frozen, kColumns };
    static const char* const columnName[kColumns] = {"x",  "y",  "z",  "radius", "vx", "vy",       "vz",    "wx",
                                                     "wy", "wz", "ix", "iy",     "iz", "material", "frozen"};
    ParticleFile out;
    auto header = [&](const std::array<int, kColumns>& col, const auto& fail) {
        if (dimension == 2)
            for (int j : {int(Z), int(Vz), int(Wx), int(Wy), int(Iz)})
                if (col[std::size_t(j)] >= 0)
                    fail(std::string("column ") + inQuotes(columnName[j]) + " is not used in a 2D scenario");
        for (int j : {int(X), int(Y), int(Z), int(Radius)}) {
            if (j == Z && dimension == 2) continue;
            if (col[std::size_t(j)] < 0) fail(std::string("missing column ") + inQuotes(columnName[j]));
        }
        const bool anyV = col[Vx] >= 0 || col[Vy] >= 0 || col[Vz] >= 0;
        const bool allV = col[Vx] >= 0 && col[Vy] >= 0 && (dimension == 2 || col[Vz] >= 0);
        if (anyV && !allV)
            fail(dimension == 3 ? "velocity columns vx, vy, vz go together" : "velocity columns vx, vy go together");
    };
    auto record = [&](const ColumnRecord<kColumns>& r) {
        FileParticle p;
        p.line = r.line;
        p.x[0] = r.number(X);
        p.x[1] = r.number(Y);
        if (dimension == 3) p.x[2] = r.number(Z);
        p.radius = r.number(Radius);
        if (!(p.radius > 0)) r.fail("column radius: must be > 0");
        if (r.has(Vx)) {
            p.v[0] = r.number(Vx);
            p.v[1] = r.number(Vy);
            if (dimension == 3) p.v[2] = r.number(Vz);
        }
        // Spins and image flags (a saved state: final.csv), each column on its own; absent ones are zero.
        for (int a = 0; a < 3; ++a) {
            if (r.has(std::size_t(Wx + a))) p.w[std::size_t(a)] = r.number(std::size_t(Wx + a));
            if (!r.has(std::size_t(Ix + a))) continue;
            const double f = r.number(std::size_t(Ix + a));
            if (!(f == std::floor(f)) || std::abs(f) > 2147483647.0)
                r.fail(std::string("column ") + columnName[Ix + a] + ": expected an integer (box crossings)");
            p.image[std::size_t(a)] = static_cast<int>(f);
        }
        if (r.has(Material)) p.material = materialCell(r.cell(Material), materials, r.fail);
        if (r.has(Frozen)) p.frozen = frozenCell(r.cell(Frozen), r.fail);
        out.particles.push_back(p);
    };
    readColumnFile(in, name, key, columnName,
                   "the header names columns x, y, z, radius, vx, vy, vz, wx, wy, wz, ix, iy, iz, material, frozen",
                   "particle", header, record);
    return out;
}

std::vector<FilePolygon> readPolygonCsv(const std::filesystem::path& file, const std::vector<MaterialDef>& materials,
                                        const std::string& key) {
    std::ifstream in = openParticleFile(file, key);
    return readPolygonCsv(in, file.string(), materials, key);
}

std::vector<FilePolygon> readPolygonCsv(std::istream& in, const std::string& name,
                                        const std::vector<MaterialDef>& materials, const std::string& key) {
    enum Column { Vertices, Vx, Vy, W, Material, Frozen, kColumns };
    static const char* const columnName[kColumns] = {"vertices", "vx", "vy", "w", "material", "frozen"};
    std::vector<FilePolygon> out;
    auto header = [&](const std::array<int, kColumns>& col, const auto& fail) {
        if (col[Vertices] < 0) fail("missing column \"vertices\"");
        if ((col[Vx] >= 0) != (col[Vy] >= 0)) fail("velocity columns vx, vy go together");
    };
    auto record = [&](const ColumnRecord<kColumns>& r) {
        FilePolygon p;
        p.line = r.line;
        const std::vector<std::string_view> coords = whitespaceTokens(r.cell(Vertices));
        if (coords.size() % 2 != 0 || coords.size() < 6 || coords.size() > 2 * polygon::kMaxVertices)
            r.fail("column vertices: expected 3 to " + std::to_string(polygon::kMaxVertices) +
                   " vertices as \"x0 y0 x1 y1 ...\", got " + std::to_string(coords.size()) + " numbers");
        for (std::size_t c = 0; c < coords.size(); c += 2) {
            const auto x = parseDouble(coords[c]), y = parseDouble(coords[c + 1]);
            if (!x || !y) r.fail("column vertices: expected numbers, got " + inQuotes(!x ? coords[c] : coords[c + 1]));
            p.vertices.push_back(Vec<2>{{*x, *y}});
        }
        if (polygon::polygonMoments(p.vertices.data(), int(p.vertices.size())).area < 0)
            std::reverse(p.vertices.begin(), p.vertices.end());
        if (!polygon::isConvexCcw(p.vertices.data(), int(p.vertices.size())))
            r.fail("column vertices: the polygon is not convex (or has repeated or collinear vertices)");
        if (r.has(Vx)) {
            p.v[0] = r.number(Vx);
            p.v[1] = r.number(Vy);
        }
        if (r.has(W)) p.w = r.number(W);
        if (r.has(Material)) p.material = materialCell(r.cell(Material), materials, r.fail);
        if (r.has(Frozen)) p.frozen = frozenCell(r.cell(Frozen), r.fail);
        out.push_back(std::move(p));
    };
    readColumnFile(in, name, key, columnName, "a polygon file names columns vertices, vx, vy, w, material, frozen",
                   "polygon", header, record);
    return out;
}

ParticleFile readLammpsData(const std::filesystem::path& file, const std::string& key) {
    std::ifstream in = openParticleFile(file, key);
    return readLammpsData(in, file.string(), key);
}

ParticleFile readLammpsData(std::istream& in, const std::string& name, const std::string& key) {
    // Read line by line, not held whole: a 32 000-atom file is 7 MB of lines, which would set the run's peak.
    LineReader reader(in, name, key);
    ParticleFile out;
    // LAMMPS's default box when the header gives none.
    Vec3d lo{-0.5, -0.5, -0.5}, hi{0.5, 0.5, 0.5};
    std::optional<long long> atomCount;
    enum class Section { Header, Atoms, Velocities, Skip } section = Section::Header;
    bool sawAtoms = false;
    std::map<long long, std::size_t> indexOfId;
    const char* const boxWords[3][2] = {{"xlo", "xhi"}, {"ylo", "yhi"}, {"zlo", "zhi"}};

    // The first line is a title and is skipped, as LAMMPS does.
    std::string line;
    reader.next(line);
    while (reader.next(line)) {
        const int lineNo = reader.lineNumber();
        auto fail = [&](const std::string& what) { throw ScenarioError({name, lineNo}, key, what); };
        const std::string_view raw = line;
        const auto hash = raw.find('#');
        const std::string_view body = trim(raw.substr(0, hash));
        const std::string_view comment =
            hash == std::string_view::npos ? std::string_view{} : trim(raw.substr(hash + 1));
        if (body.empty()) continue;
        const std::vector<std::string_view> tok = whitespaceTokens(body);
        const char lead = tok[0][0];
        const bool isKeyword = std::isalpha(static_cast<unsigned char>(lead));

        if (isKeyword) {
            if (body == "Atoms") {
                if (sawAtoms) fail("second Atoms section");
                if (!comment.empty() && comment != "sphere")
                    fail("atom style " + inQuotes(comment) +
                         " is not supported: write the file with atom_style sphere");
                section = Section::Atoms;
                sawAtoms = true;
            } else if (body == "Velocities") {
                section = Section::Velocities;
            } else if (body == "Masses") {
                section = Section::Skip;  // atom_style sphere takes masses from diameter and density
            } else {
                fail("section " + inQuotes(body) +
                     " is not supported (atom_style sphere files have Atoms and Velocities)");
            }
            continue;
        }

        switch (section) {
            case Section::Header: {
                if (tok.size() == 2 && tok[1] == "atoms") {
                    atomCount = parseInteger(tok[0]);
                    if (!atomCount || *atomCount < 0) fail("bad atom count " + inQuotes(tok[0]));
                    continue;
                }
                if (tok.size() == 3 && tok[1] == "atom" && tok[2] == "types") {
                    const auto n = parseInteger(tok[0]);
                    if (!n || *n < 1 || *n > std::numeric_limits<int>::max())
                        fail("bad atom type count " + inQuotes(tok[0]));
                    out.atomTypes = int(*n);
                    continue;
                }
                bool boxLine = false;
                for (int a = 0; a < 3; ++a) {
                    if (tok.size() == 4 && tok[2] == boxWords[a][0] && tok[3] == boxWords[a][1]) {
                        const auto l = parseDouble(tok[0]), h = parseDouble(tok[1]);
                        if (!l || !h || !(*h > *l))
                            fail(std::string("bad box bounds ") + boxWords[a][0] + " " + boxWords[a][1]);
                        lo[std::size_t(a)] = *l;
                        hi[std::size_t(a)] = *h;
                        boxLine = true;
                    }
                }
                if (boxLine) continue;
                if (tok.size() == 6 && tok[3] == "xy") fail("triclinic boxes are not supported");
                // Other header counts (bonds, ellipsoids, ...) are harmless when zero.
                const auto n = parseInteger(tok[0]);
                if (n && *n == 0) continue;
                fail("unsupported header line " + inQuotes(body));
                continue;
            }
            case Section::Atoms: {
                if (tok.size() != 7 && tok.size() != 10)
                    fail("Atoms line: expected 7 or 10 values (id type diameter density x y z [ix iy iz]), got " +
                         std::to_string(tok.size()));
                FileParticle p;
                p.line = lineNo;
                const auto id = parseInteger(tok[0]);
                const auto type = parseInteger(tok[1]);
                if (!id) fail("Atoms line: bad atom id " + inQuotes(tok[0]));
                if (!type || *type < 1 || *type > std::numeric_limits<int>::max())
                    fail("Atoms line: atom type must be an integer from 1 to " +
                         std::to_string(std::numeric_limits<int>::max()) + ", got " + inQuotes(tok[1]));
                if (out.atomTypes > 0 && *type > out.atomTypes)
                    fail("Atoms line: atom type " + std::to_string(*type) + " > atom types " +
                         std::to_string(out.atomTypes));
                std::array<double, 5> val{};  // diameter, density, x, y, z
                for (std::size_t c = 0; c < 5; ++c) {
                    const auto v = parseDouble(tok[c + 2]);
                    if (!v) fail("Atoms line: expected a number, got " + inQuotes(tok[c + 2]));
                    val[c] = *v;
                }
                if (!(val[0] > 0)) fail("Atoms line: diameter must be > 0");
                if (!(val[1] > 0)) fail("Atoms line: density must be > 0");
                p.type = int(*type);
                p.radius = 0.5 * val[0];
                p.density = val[1];
                p.x = {val[2], val[3], val[4]};
                if (tok.size() == 10) {
                    for (std::size_t c = 0; c < 3; ++c) {
                        const auto f = parseInteger(tok[c + 7]);
                        if (!f || *f < std::numeric_limits<int>::min() || *f > std::numeric_limits<int>::max())
                            fail("Atoms line: image flag must be an integer within +-2^31, got " +
                                 inQuotes(tok[c + 7]));
                        p.image[c] = int(*f);
                    }
                }
                if (!indexOfId.emplace(*id, out.particles.size()).second)
                    fail("Atoms line: atom id " + std::to_string(*id) + " appears twice");
                out.particles.push_back(p);
                continue;
            }
            case Section::Velocities: {
                if (tok.size() != 7)
                    fail("Velocities line: expected 7 values (id vx vy vz wx wy wz), got " +
                         std::to_string(tok.size()));
                const auto id = parseInteger(tok[0]);
                if (!id) fail("Velocities line: bad atom id " + inQuotes(tok[0]));
                const auto it = indexOfId.find(*id);
                if (it == indexOfId.end()) fail("Velocities line: no atom with id " + std::to_string(*id));
                std::array<double, 6> val{};
                for (std::size_t c = 0; c < 6; ++c) {
                    const auto v = parseDouble(tok[c + 1]);
                    if (!v) fail("Velocities line: expected a number, got " + inQuotes(tok[c + 1]));
                    val[c] = *v;
                }
                FileParticle& p = out.particles[it->second];
                p.v = {val[0], val[1], val[2]};
                p.w = {val[3], val[4], val[5]};
                continue;
            }
            case Section::Skip:
                continue;
        }
    }
    if (!atomCount) throw ScenarioError({name, 0}, key, "missing header line \"N atoms\"");
    if (std::size_t(*atomCount) != out.particles.size())
        throw ScenarioError({name, 0}, key,
                            "header says " + std::to_string(*atomCount) + " atoms, the Atoms section has " +
                                std::to_string(out.particles.size()));
    if (out.particles.empty()) throw ScenarioError({name, 0}, key, "the file holds no particles");
    out.boxLo = lo;
    out.boxHi = hi;
    return out;
}

template <int D>
void insertParticles(const Scenario& s, Particles<D>& particles, Rng rng) {
    if (s.dimension != D)
        throw std::invalid_argument("insertParticles: scenario dimension " + std::to_string(s.dimension) +
                                    " does not match the particle store's " + std::to_string(D));
    for (std::size_t k = 0; k < s.inserts.size(); ++k) {
        std::vector<NewParticle<D>> out;
        switch (s.inserts[k].arrangement) {
            case Arrangement::Lattice:
                out = insertLattice(s, k, particles, rng);
                break;
            case Arrangement::Random:
                out = insertRandom(s, k, particles, rng);
                break;
            case Arrangement::File:
                out = insertFromFile<D>(s, k);
                break;
        }
        // Added only once the whole insert succeeded, so a failed insert leaves no partial block behind.
        for (const auto& p : out) addToStore(particles, p, particles.size());
    }
}

template <int D>
std::size_t addToStore(Particles<D>& particles, const NewParticle<D>& p, std::uint64_t id) {
    std::size_t i;
    if constexpr (D == 2) {
        i = p.body.empty()
                ? particles.add(p.x, p.v, p.w, p.radius, p.density, p.material, id, p.flags)
                : particles.addPolygon(p.x, p.v, p.w, p.orientation, p.body, p.density, p.material, id, p.flags);
    } else {
        i = particles.add(p.x, p.v, p.w, p.radius, p.density, p.material, id, p.flags);
    }
    particles.image[i] = p.image;
    return i;
}

template void insertParticles<2>(const Scenario&, Particles<2>&, Rng);
template void insertParticles<3>(const Scenario&, Particles<3>&, Rng);
template class RandomPlacer<2>;
template class RandomPlacer<3>;
template void finishParticle<2>(const Scenario&, const InsertDef&, NewParticle<2>&, Rng&);
template void finishParticle<3>(const Scenario&, const InsertDef&, NewParticle<3>&, Rng&);
template void thermalVelocity<2>(const InsertDef&, NewParticle<2>&, Rng&);
template void thermalVelocity<3>(const InsertDef&, NewParticle<3>&, Rng&);
template std::size_t addToStore<2>(Particles<2>&, const NewParticle<2>&, std::uint64_t);
template std::size_t addToStore<3>(Particles<3>&, const NewParticle<3>&, std::uint64_t);

}  // namespace haet
