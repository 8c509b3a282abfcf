#include "polygon/output.hpp"

#include <cmath>
#include <cstdint>

#include "io/vtk.hpp"

namespace haet::polygon {

std::vector<std::array<double, 2>> worldOutline(const Particles<2>& p, std::size_t i) {
    const std::uint32_t s = p.shape[i];
    const Vec<2>* v = p.shapes.of(s);
    const int n = p.shapes.count(s);
    const double c = std::cos(p.angle[i][0]), sn = std::sin(p.angle[i][0]);
    std::vector<std::array<double, 2>> out(n);
    for (int k = 0; k < n; ++k)
        out[k] = {p.x[i][0] + c * v[k][0] - sn * v[k][1], p.x[i][1] + sn * v[k][0] + c * v[k][1]};
    return out;
}

void writePolygonVtu(const std::filesystem::path& path, const Particles<2>& p, double time) {
    std::vector<double> xyz;
    std::vector<std::uint32_t> offsets{0};
    std::vector<std::int64_t> ids;
    std::vector<std::int32_t> mat;
    std::vector<std::uint8_t> frozen;
    std::vector<double> vel, spin, angle;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (!p.isPolygon(i)) continue;
        for (const auto& v : worldOutline(p, i)) xyz.insert(xyz.end(), {v[0], v[1], 0.0});
        offsets.push_back(static_cast<std::uint32_t>(xyz.size() / 3));
        ids.push_back(static_cast<std::int64_t>(p.id[i]));
        mat.push_back(p.material[i]);
        frozen.push_back(p.frozen(i) ? 1 : 0);
        vel.insert(vel.end(), {p.v[i][0], p.v[i][1], 0.0});
        spin.insert(spin.end(), {0.0, 0.0, p.w[i][0]});
        angle.push_back(p.angle[i][0]);
    }
    writeVtuPolygons(path, xyz, offsets,
                     {{"id", 1, VtkField::Int64, ids.data()},
                      {"material", 1, VtkField::Int32, mat.data()},
                      {"velocity", 3, VtkField::Float64, vel.data()},
                      {"angular_velocity", 3, VtkField::Float64, spin.data()},
                      {"angle", 1, VtkField::Float64, angle.data()},
                      {"frozen", 1, VtkField::UInt8, frozen.data()}},
                     time);
}

}  // namespace haet::polygon
