#include "run/export.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>

#include "io/atomic_file.hpp"
#include "neighbor/pair_list.hpp"

namespace haet {

namespace {

/// The store's indices in the order of the particles' ids.
template <int D>
std::vector<std::size_t> byId(const Particles<D>& p) {
    if (p.hasPolygons()) throw std::invalid_argument("a store of polygons has no CSV or LAMMPS data file of its state");
    std::vector<std::size_t> order(p.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
    return order;
}

/// The store with every position in the box on periodic axes (the crossings in the image flags), as a rebuild of the
/// pair list wraps them: a time-driven run leaves them up to skin/2 outside between rebuilds, and a particle file's
/// centres must lie inside the domain.
template <int D>
Particles<D> wrapped(const World<D>& w) {
    Particles<D> p = w.particles;
    p.nTdm = static_cast<std::size_t>(-1);
    wrapPositions(p, w.domain);
    return p;
}

}  // namespace

template <int D>
void writeStateCsv(const std::filesystem::path& path, const World<D>& w, const std::vector<MaterialDef>& materials) {
    const Particles<D> p = wrapped(w);
    const std::vector<std::size_t> order = byId(p);
    std::string text =
        fmt::format("# HAET state at t = {} s: {} particles, in the order of their ids\n", w.time, p.size());
    text += D == 3 ? "x,y,z,radius,vx,vy,vz,wx,wy,wz,ix,iy,iz,material,frozen\n"
                   : "x,y,radius,vx,vy,wz,ix,iy,material,frozen\n";
    auto out = std::back_inserter(text);
    for (const std::size_t i : order) {
        // "{}" is the shortest text that reads back to the same double.
        if constexpr (D == 3)
            fmt::format_to(out, "{},{},{},{},{},{},{},{},{},{},{},{},{},", p.x[i][0], p.x[i][1], p.x[i][2], p.radius[i],
                           p.v[i][0], p.v[i][1], p.v[i][2], p.w[i][0], p.w[i][1], p.w[i][2], p.image[i][0],
                           p.image[i][1], p.image[i][2]);
        else
            fmt::format_to(out, "{},{},{},{},{},{},{},{},", p.x[i][0], p.x[i][1], p.radius[i], p.v[i][0], p.v[i][1],
                           p.w[i][0], p.image[i][0], p.image[i][1]);
        text += materials[p.material[i]].name;
        text += p.frozen(i) ? ",1\n" : ",0\n";
    }
    writeFileAtomic(path, text);
}

template <int D>
void writeLammpsData(const std::filesystem::path& path, const World<D>& w, const std::vector<MaterialDef>& materials) {
    const Particles<D> p = wrapped(w);
    const std::vector<std::size_t> order = byId(p);
    constexpr double pi = 3.14159265358979323846;
    std::string text = fmt::format("LAMMPS data file via HAET, t = {} s, atom_style sphere\n\n", w.time);
    auto out = std::back_inserter(text);
    fmt::format_to(out, "{} atoms\n{} atom types\n\n", p.size(), materials.size());
    const char* axis[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
        const double lo = k < D ? w.domain.lo[k] : -0.5, hi = k < D ? w.domain.hi[k] : 0.5;
        fmt::format_to(out, "{} {} {}lo {}hi\n", lo, hi, axis[k], axis[k]);
    }
    text += "\nAtoms # sphere\n\n";
    for (std::size_t k = 0; k < order.size(); ++k) {
        const std::size_t i = order[k];
        const double r = p.radius[i];
        const double density = p.mass[i] / ((4.0 / 3.0) * pi * r * r * r);
        const double z = D == 3 ? p.x[i][D - 1] : 0.0;
        const int iz = D == 3 ? p.image[i][D - 1] : 0;
        fmt::format_to(out, "{} {} {} {} {} {} {} {} {} {}\n", k + 1, p.material[i] + 1, 2 * r, density, p.x[i][0],
                       p.x[i][1], z, p.image[i][0], p.image[i][1], iz);
    }
    text += "\nVelocities\n\n";
    for (std::size_t k = 0; k < order.size(); ++k) {
        const std::size_t i = order[k];
        if constexpr (D == 3)
            fmt::format_to(out, "{} {} {} {} {} {} {}\n", k + 1, p.v[i][0], p.v[i][1], p.v[i][2], p.w[i][0], p.w[i][1],
                           p.w[i][2]);
        else
            fmt::format_to(out, "{} {} {} 0 0 0 {}\n", k + 1, p.v[i][0], p.v[i][1], p.w[i][0]);
    }
    writeFileAtomic(path, text);
}

template void writeStateCsv<2>(const std::filesystem::path&, const World<2>&, const std::vector<MaterialDef>&);
template void writeStateCsv<3>(const std::filesystem::path&, const World<3>&, const std::vector<MaterialDef>&);
template void writeLammpsData<2>(const std::filesystem::path&, const World<2>&, const std::vector<MaterialDef>&);
template void writeLammpsData<3>(const std::filesystem::path&, const World<3>&, const std::vector<MaterialDef>&);

}  // namespace haet
