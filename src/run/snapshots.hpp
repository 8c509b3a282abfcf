#pragma once
// The snapshots of a run (particles, polygons, walls, zones as VTK collections) and its final picture.
#include <fmt/format.h>

#include <filesystem>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "haet/engine.hpp"
#include "io/checkpoint.hpp"
#include "io/frame.hpp"
#include "io/vtk.hpp"
#include "polygon/output.hpp"
#include "run/checkpoint.hpp"
#include "run/picture.hpp"
#include "run/walls_output.hpp"
#include "scenario/definition.hpp"
#include "world/build.hpp"

namespace haet {

template <int D>
ParticleFrame snapshotFrame(const World<D>& w, double time, const HaetEngine<D>* hybrid) {
    const Particles<D>& p = w.particles;
    const std::size_t n = p.size();
    ParticleFrame fr;
    fr.time = time;
    fr.xyz.assign(3 * n, 0.0);
    for (const auto& [name, comps, type] : {std::tuple{"radius", 1, VtkField::Float64},
                                            {"velocity", 3, VtkField::Float64},
                                            {"angular_velocity", 3, VtkField::Float64},
                                            {"force", 3, VtkField::Float64},
                                            {"material", 1, VtkField::Int32},
                                            {"id", 1, VtkField::Int64}})
        fr.add(name, comps, type);
    if (hybrid) fr.add("mode", 1, VtkField::Int32);
    // Every field added: the references stay valid.
    FrameField &rad = fr.fields[0], &vel = fr.fields[1], &spin = fr.fields[2], &force = fr.fields[3],
               &mat = fr.fields[4], &ids = fr.fields[5];
    const bool forces = p.hasTdmState();
    for (std::size_t i = 0; i < n; ++i) {
        for (int k = 0; k < D; ++k) {
            fr.xyz[3 * i + k] = p.x[i][k];
            vel.values[3 * i + k] = p.v[i][k];
            if (forces) force.values[3 * i + k] = p.f[i][k];
        }
        if constexpr (D == 2)
            spin.values[3 * i + 2] = p.w[i][0];
        else
            for (int k = 0; k < 3; ++k) spin.values[3 * i + k] = p.w[i][k];
        rad.values[i] = p.radius[i];
        ids.values[i] = static_cast<double>(p.id[i]);
        mat.values[i] = p.material[i];
    }
    if (hybrid)  // 1: time-driven, 0: event-driven
        for (std::size_t i = 0; i < n; ++i) fr.fields[6].values[i] = i < p.tdmCount() ? 1 : 0;
    return fr;
}

template <int D>
class SnapshotWriter {
public:
    SnapshotWriter(const std::filesystem::path& dir)
        : dir_(dir), pvd_(dir / "particles.pvd"), walls_(dir / "walls.pvd"), zones_(dir / "zones.pvd") {}

    void write(const World<D>& w, double time, const HaetEngine<D>* hybrid) {
        const Particles<D>& p = w.particles;
        const std::string name = fmt::format("particles_{:06d}.vtu", count_);
        writeFrameVtu(dir_ / name, snapshotFrame(w, time, hybrid));
        pvd_.add(time, name);
        if (hybrid) writeZones(*hybrid, time);
        if constexpr (D == 2) {
            if (p.hasPolygons()) {  // the real shapes, as polygon cells (polygons.pvd)
                if (!polys_) polys_.emplace(dir_ / "polygons.pvd");
                const std::string pname = fmt::format("polygons_{:06d}.vtu", count_);
                polygon::writePolygonVtu(dir_ / pname, p, time);
                polys_->add(time, pname);
            }
        }
        if (!w.walls.empty() || !w.surfaces.empty()) {
            const std::string wname = fmt::format("walls_{:06d}.vtp", count_);
            writeVtpShapes(dir_ / wname, wallShapes(w, time));
            walls_.add(time, wname);
        }
        ++count_;
    }

    /// The snapshot count and the collections' entries, for a checkpoint.
    void saveState(ByteWriter& out) const {
        out.put<std::int64_t>(count_);
        savePvd(out, pvd_);
        savePvd(out, walls_);
        savePvd(out, zones_);
        out.put<std::uint8_t>(polys_.has_value());
        if (polys_) savePvd(out, *polys_);
    }
    /// A resumed run's: the collections as they were at the checkpoint (their files rewritten); the snapshots the
    /// stopped run wrote after it are written again, under the same names.
    void loadState(ByteReader& in) {
        count_ = static_cast<int>(in.get<std::int64_t>());
        if (count_ < 0) in.fail("a negative snapshot count");
        loadPvd(in, pvd_);
        loadPvd(in, walls_);
        loadPvd(in, zones_);
        if (in.get<std::uint8_t>()) {
            if (!polys_) polys_.emplace(dir_ / "polygons.pvd");
            loadPvd(in, *polys_);
        }
    }

private:
    /// Zone labels as an image: label 0 event-driven, 1 time-driven (buffer), 2 dense; smoothed fraction phi.
    void writeZones(const HaetEngine<D>& h, double time) {
        const ZoneGrid<D>& z = h.zones();
        const int nz = z.count();
        std::vector<std::int32_t> label(nz);
        std::vector<double> phi(nz);
        for (int q = 0; q < nz; ++q) {
            label[q] = z.dense(q) ? 2 : (z.timeDriven(q) ? 1 : 0);
            phi[q] = z.smoothed(q);
        }
        std::array<int, 3> dims{1, 1, 1};
        std::array<double, 3> origin{0, 0, 0}, spacing{1, 1, 1};
        for (int k = 0; k < D; ++k) {
            dims[k] = z.dims()[k];
            origin[k] = z.origin()[k];
            spacing[k] = z.zoneWidth()[k];
        }
        const std::string name = fmt::format("zones_{:06d}.vti", count_);
        writeVtiCells(dir_ / name, dims, origin, spacing,
                      {{"label", 1, VtkField::Int32, label.data()}, {"phi", 1, VtkField::Float64, phi.data()}}, time);
        zones_.add(time, name);
    }

    std::filesystem::path dir_;
    PvdCollection pvd_, walls_, zones_;
    std::optional<PvdCollection> polys_;
    int count_ = 0;
};

/// The box of a run, as a picture frames it.
template <int D>
PictureBox pictureBox(const World<D>& w) {
    PictureBox b;
    b.dimension = D;
    b.lo = {0, 0, 0}, b.hi = {0, 0, 0};
    for (int k = 0; k < D; ++k) {
        b.lo[k] = w.domain.lo[k];
        b.hi[k] = w.domain.hi[k];
        b.gravity[k] = w.domain.gravity[k];
    }
    return b;
}

inline PictureOptions pictureOptions(const Scenario& sc) {
    return {sc.output.colorBy, sc.output.colorRange, sc.output.view, sc.output.pictureWidth};
}

inline std::vector<std::string> materialNames(const Scenario& sc) {
    std::vector<std::string> names;
    for (const MaterialDef& m : sc.materials) names.push_back(m.name);
    return names;
}

/// final.png: the last state, as the last snapshot holds it, drawn as [output] asks.
template <int D>
void writeFinalPicture(const Scenario& sc, const World<D>& w, const HaetEngine<D>* hybrid,
                       const std::filesystem::path& path) {
    PolygonOutlines polygons;
    if constexpr (D == 2)
        for (std::size_t i = 0; i < w.particles.size(); ++i)
            if (w.particles.isPolygon(i)) {
                polygons.id.push_back(static_cast<std::int64_t>(w.particles.id[i]));
                polygons.outline.push_back(polygon::worldOutline(w.particles, i));
            }
    writeFramePicture(path, snapshotFrame(w, w.time, hybrid), wallShapes(w, w.time), pictureBox(w), pictureOptions(sc),
                      materialNames(sc), &polygons);
}

}  // namespace haet
