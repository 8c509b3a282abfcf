#include "scenario/checks.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "geometry/domain.hpp"
#include "neighbor/cell_grid.hpp"
#include "scenario/loader.hpp"
#include "scenario/text.hpp"

namespace haet {
namespace {

std::string wallKey(std::size_t i, const char* key) { return "walls[" + std::to_string(i + 1) + "]." + key; }
std::string insertKey(std::size_t k, const char* key) { return "insert[" + std::to_string(k + 1) + "]." + key; }

/// A wall that leaves no room in an insert's region (its normal points out of it: every point of the region is
/// behind the wall's plane or closer to it than the smallest radius) is named, not reported as a region too small
/// once the insertion has tried for long.
void checkWallsAgainstRegions(const Scenario& s) {
    const int dim = s.dimension;
    for (std::size_t k = 0; k < s.inserts.size(); ++k) {
        const InsertDef& in = s.inserts[k];
        if (in.arrangement == Arrangement::File) continue;
        for (std::size_t i = 0; i < s.walls.size(); ++i) {
            const WallDef& w = s.walls[i];
            if (!w.isPlane()) continue;  // a wall of another shape is a thin surface: insertion places around it
            double best = -std::numeric_limits<double>::infinity();  // the region's farthest point in front
            for (int corner = 0; corner < (1 << dim); ++corner) {
                double d = 0;
                for (int a = 0; a < dim; ++a)
                    d += ((corner >> a & 1 ? in.regionHi[a] : in.regionLo[a]) - w.point[a]) * w.normal[a];
                best = std::max(best, d);
            }
            if (best < in.radiusMin)
                throw ScenarioError(w.pos, wallKey(i, "normal"),
                                    "leaves no room for insert[" + std::to_string(k + 1) +
                                        "]: its region lies behind the wall or within one radius of it (the normal "
                                        "points into the domain, toward the particles)");
        }
    }
}

/// Particles a lattice insert can place at most: its sites.
double latticeSites(const InsertDef& in, int dim) {
    const double a = in.spacing.value_or(2 * in.radiusMax);
    double n = 1;
    for (int k = 0; k < dim; ++k) n *= std::floor((in.regionHi[k] - in.regionLo[k] - 2 * in.radiusMax) / a) + 1;
    return std::max(n, 0.0);
}

double physicalMemoryBytes() {
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? double(pages) * double(size) : 0;
}

/// The particle counts: each below what the engines index (32-bit), their sum within the machine's memory, so that a
/// count of 1e12 or one that needs 11 GB stops at the key instead of in std::bad_alloc.
void checkCounts(const Scenario& s) {
    double total = 0;
    std::size_t largest = 0;
    double largestCount = -1;
    for (std::size_t k = 0; k < s.inserts.size(); ++k) {
        const InsertDef& in = s.inserts[k];
        if (in.arrangement == Arrangement::File) continue;
        const SourcePos pos{in.pos.file, in.pos.line};
        if (in.count > kMaxParticles)
            throw ScenarioError(pos, insertKey(k, "count"),
                                formatNumber(double(in.count)) + " particles: at most " +
                                    formatNumber(double(kMaxParticles)) + " in a run");
        const double n = in.arrangement == Arrangement::Lattice
                             ? std::min(double(in.count), latticeSites(in, s.dimension))
                             : double(in.count);
        total += n;
        if (n > largestCount) largestCount = n, largest = k;
    }
    if (largestCount < 0) return;
    if (total > double(kMaxParticles))
        throw ScenarioError(s.inserts[largest].pos, insertKey(largest, "count"),
                            "the inserts make " + formatNumber(total) + " particles: at most " +
                                formatNumber(double(kMaxParticles)) + " in a run");
    const double need = estimatedBytes(s, total), have = physicalMemoryBytes();
    if (have > 0 && need > have)
        throw ScenarioError(s.inserts[largest].pos, insertKey(largest, "count"),
                            formatNumber(total) + " particles need about " + formatNumber(std::ceil(need / 1e9)) +
                                " GB, more than this machine's " + formatNumber(std::floor(have / 1e9)) + " GB");
}

template <int D>
Domain<D> domainOf(const Scenario& s) {
    Domain<D> d;
    for (int k = 0; k < D; ++k) {
        d.lo[k] = s.domain.lo[k];
        d.hi[k] = s.domain.hi[k];
        d.periodic[k] = s.domain.periodic[k];
    }
    return d;
}

/// The first pair of hard spheres (disks) that overlap, by minimum image on periodic axes: cells of the largest
/// diameter (capped by the count), each particle against the 3^D cells around its own. nullopt: none.
template <int D>
std::optional<std::pair<std::size_t, std::size_t>> firstOverlap(const Domain<D>& dom, const std::vector<Vec<D>>& x,
                                                                const std::vector<double>& r) {
    const std::size_t n = x.size();
    if (n < 2) return std::nullopt;
    const double rmax = *std::max_element(r.begin(), r.end());
    const double edge = CellGrid<D>::cappedEdge(dom.lo, dom.hi, 2 * rmax, std::max(4096.0, 2.0 * double(n)));
    const CellGrid<D> grid = CellGrid<D>::spanning(dom.lo, dom.hi, edge, dom.periodic);
    constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::vector<std::size_t> head(static_cast<std::size_t>(grid.count()), kNone), next(n, kNone);
    std::vector<int> cell(n);
    for (std::size_t i = 0; i < n; ++i) {
        cell[i] = grid.cellOf(x[i]);
        next[i] = head[cell[i]];
        head[cell[i]] = i;
    }
    for (std::size_t i = 0; i < n; ++i) {
        std::optional<std::pair<std::size_t, std::size_t>> hit;
        grid.forEachNeighbour(cell[i], [&](int c, int) {
            for (std::size_t j = head[c]; j != kNone; j = next[j]) {
                if (j <= i) continue;
                const double contact = (r[i] + r[j]) * (1 - 1e-9);  // touching is allowed (a lattice at 2 r)
                if (norm2(dom.minimumImage(x[j] - x[i])) < contact * contact) {
                    hit = std::pair{i, j};
                    return true;
                }
            }
            return false;
        });
        if (hit) return hit;
    }
    return std::nullopt;
}

bool hardParticles(const Scenario& s) { return s.method == Method::Edm || s.method == Method::Haet; }

}  // namespace

template <int D>
void checkFileParticles(const Scenario& s, std::size_t k, const ParticleFile& pf) {
    const InsertDef& in = s.inserts[k];
    const std::string key = insertKey(k, "file");
    // Centres first: the overlap test below bins them into cells of the domain, which a centre far outside it
    // (1e92 m) would take beyond any cell index.
    for (const FileParticle& fp : pf.particles)
        for (int a = 0; a < D; ++a)
            if (!(fp.x[a] >= s.domain.lo[a] && fp.x[a] <= s.domain.hi[a]))
                throw ScenarioError({in.file, fp.line}, key, "particle centre lies outside the domain");
    double largest = 0;
    for (int a = 0; a < D; ++a) largest = std::max(largest, s.domain.hi[a] - s.domain.lo[a]);
    for (const FileParticle& fp : pf.particles)
        if (!(fp.radius > 0 && 2 * fp.radius <= largest))
            throw ScenarioError({in.file, fp.line}, key,
                                "radius " + formatNumber(fp.radius) + " m: a particle must fit in the domain (" +
                                    formatNumber(largest) + " m across)");
    if (pf.boxLo && pf.boxHi)
        for (int a = 0; a < D; ++a) {
            if (!s.domain.periodic[a]) continue;  // an open axis: the domain bounds the particles, whatever the box
            const double lo = (*pf.boxLo)[a], hi = (*pf.boxHi)[a], L = s.domain.hi[a] - s.domain.lo[a];
            if (std::abs(lo - s.domain.lo[a]) > 1e-9 * L || std::abs(hi - s.domain.hi[a]) > 1e-9 * L)
                throw ScenarioError({in.file, 0}, key,
                                    std::string("the file's box on periodic axis ") + "xyz"[a] + ", [" +
                                        formatNumber(lo) + ", " + formatNumber(hi) + "], is not the domain's [" +
                                        formatNumber(s.domain.lo[a]) + ", " + formatNumber(s.domain.hi[a]) +
                                        "]: positions wrap and image flags unwrap by the box (set [domain] lo and "
                                        "hi to the file's box)");
        }
    if (!hardParticles(s)) return;  // soft particles may start overlapped: the contact law pushes them apart
    std::vector<Vec<D>> x(pf.particles.size());
    std::vector<double> r(pf.particles.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        for (int a = 0; a < D; ++a) x[i][a] = pf.particles[i].x[a];
        r[i] = pf.particles[i].radius;
    }
    if (const auto hit = firstOverlap(domainOf<D>(s), x, r)) {
        const FileParticle &a = pf.particles[hit->first], &b = pf.particles[hit->second];
        throw ScenarioError({in.file, b.line}, key,
                            "overlaps the particle of line " + std::to_string(a.line) +
                                ": hard particles (method = \"" + (s.method == Method::Edm ? "edm" : "haet") +
                                "\") must start apart; relax the packing with method = \"tdm\" first");
    }
}

template <int D>
void checkParticles(const Scenario& s, const Particles<D>& p) {
    if (!hardParticles(s)) return;
    double rmax = 0;
    for (std::size_t i = 0; i < p.size(); ++i) rmax = std::max(rmax, p.radius[i]);
    // The event-driven engine's constraints (edm/engine.cpp), with the key and line to blame.
    for (std::size_t i = 0; i < s.walls.size(); ++i)
        for (int a = 0; a < D; ++a)
            if (s.walls[i].isPlane() && s.domain.periodic[a] && std::abs(s.walls[i].normal[a]) > 1e-12)
                throw ScenarioError(s.walls[i].pos, wallKey(i, "normal"),
                                    std::string("is not perpendicular to periodic axis ") + "xyz"[a] +
                                        ": the event-driven engine's walls lie along the periodic axes");
    for (int a = 0; a < D; ++a)
        if (s.domain.periodic[a] && s.domain.hi[a] - s.domain.lo[a] < 4 * rmax)
            throw ScenarioError(s.domain.pos, "domain.hi",
                                std::string("periodic axis ") + "xyz"[a] + " is " +
                                    formatNumber(s.domain.hi[a] - s.domain.lo[a]) +
                                    " m long, shorter than two largest diameters (" + formatNumber(4 * rmax) +
                                    " m): the event-driven engine needs at least that");
    if (s.method == Method::Edm && s.edm.cellSize && *s.edm.cellSize < 2 * rmax * (1 - 1e-12))
        throw ScenarioError(
            s.edm.cellPos, "edm.cell_size",
            formatNumber(*s.edm.cellSize) + " m is smaller than the largest diameter " + formatNumber(2 * rmax) + " m");
    // Hard particles that overlap pass through each other for the whole run: across inserts too.
    if (const auto hit = firstOverlap(domainOf<D>(s), p.x, p.radius))
        throw ScenarioError({s.path, 0}, "insert",
                            "particles id " + std::to_string(p.id[hit->first]) + " and id " +
                                std::to_string(p.id[hit->second]) + " overlap: hard particles (method = \"" +
                                (s.method == Method::Edm ? "edm" : "haet") + "\") must start apart");
}

template void checkFileParticles<2>(const Scenario&, std::size_t, const ParticleFile&);
template void checkFileParticles<3>(const Scenario&, std::size_t, const ParticleFile&);
template void checkParticles<2>(const Scenario&, const Particles<2>&);
template void checkParticles<3>(const Scenario&, const Particles<3>&);

double estimatedBytes(const Scenario& s, double n) {
    // Per particle: the store's arrays and integrator history (about 250 bytes in 3D), the pair list at the
    // contacts of a dense packing with its springs (12 pairs of 33 bytes), the event-driven engine's slots and
    // queue, and the insertion's grid: 1 kB in 3D, 0.6 kB in 2D, an upper bound of what `haet check` itemises.
    return n * (s.dimension == 3 ? 1000.0 : 600.0);
}

/// A material's restitution is required unless the linear law has kn and gamma_n (which give the restitution
/// themselves: `haet check` prints it) and no polygon's damping derives from it; then it is 1 and unused.
static void resolveRestitution(Scenario& s) {
    bool polygons = false;
    for (const InsertDef& in : s.inserts) polygons = polygons || in.shape == ShapeKind::Polygon;
    const bool unused = s.contact.normal == NormalLaw::Linear && s.contact.kn && s.contact.gammaN && !polygons;
    for (MaterialDef& m : s.materials) {
        if (m.restitution != kRestitutionUnset) continue;
        if (!unused)
            throw ScenarioError(m.pos, "materials." + m.name + ".restitution",
                                "is required (optional only with normal = \"linear\", kn and gamma_n)");
        m.restitution = 1;
    }
}

void checkScenario(Scenario& s) {
    resolveRestitution(s);
    checkWallsAgainstRegions(s);
    checkCounts(s);
}

std::string readScenarioText(const std::filesystem::path& file) {
    const SourcePos pos{file.string(), 0};
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec)) throw ScenarioError(pos, "", "is a directory, not a scenario file");
    std::ifstream in(file, std::ios::binary);
    if (!in) throw ScenarioError(pos, "", "cannot open the scenario file");
    // Read in pieces up to a bound: a device (/dev/zero) or a runaway pipe must not take all memory.
    std::string text;
    char buf[65536];
    while (in.read(buf, sizeof buf) || in.gcount() > 0) {
        text.append(buf, static_cast<std::size_t>(in.gcount()));
        if (text.size() > kMaxScenarioBytes)
            throw ScenarioError(pos, "",
                                "longer than " + std::to_string(kMaxScenarioBytes >> 20) +
                                    " MiB: not a scenario file (particles belong in an [[insert]] file)");
    }
    if (in.bad()) throw ScenarioError(pos, "", "cannot read the scenario file");
    if (text.find('\0') != std::string::npos)
        throw ScenarioError(pos, "", "holds NUL bytes: not a text file, not a scenario");
    return text;
}

}  // namespace haet
