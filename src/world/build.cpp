#include "world/build.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/rng.hpp"
#include "scenario/insert.hpp"
#include "scenario/walls.hpp"

namespace haet {

template <int D>
std::vector<MaterialStats> materialStats(const Particles<D>& p, int nMaterials) {
    std::vector<MaterialStats> st(nMaterials);
    for (std::size_t i = 0; i < p.size(); ++i) {
        MaterialStats& s = st[p.material[i]];
        s.meanRadius += p.radius[i];
        s.meanMass += p.mass[i];
        s.minRadius = s.count ? std::min(s.minRadius, p.radius[i]) : p.radius[i];
        s.minMass = s.count ? std::min(s.minMass, p.mass[i]) : p.mass[i];
        ++s.count;
        if (p.isPolygon(i)) {
            s.minPolygonMass = s.polygons ? std::min(s.minPolygonMass, p.mass[i]) : p.mass[i];
            ++s.polygons;
        }
    }
    for (auto& s : st)
        if (s.count) {
            s.meanRadius /= s.count;
            s.meanMass /= s.count;
        }
    return st;
}

/// A material that only inlets bring (none of it at the start) takes its statistics from the inlets' size
/// distributions, so that the laws that depend on sizes and masses (Hertz's contact duration, the polygon step)
/// see the particles that will come. Materials present at the start keep theirs.
template <int D>
void inletStats(const Scenario& sc, std::vector<MaterialStats>& stats) {
    std::vector<std::size_t> inlets(stats.size(), 0);
    for (const InletDef& in : sc.inlets) {
        const InsertDef& p = in.particles;
        MaterialStats& s = stats[std::size_t(p.material)];
        if (s.count > 0 && inlets[std::size_t(p.material)] == 0) continue;
        const double density = sc.materials[std::size_t(p.material)].density;
        const double mean = 0.5 * summarize(p.size, D).meanByNumber;
        const double mMin = density * Particles<D>::volumeOf(p.radiusMin);
        const double n = double(inlets[std::size_t(p.material)]++);
        s.meanRadius = (s.meanRadius * n + mean) / (n + 1);
        s.meanMass = (s.meanMass * n + density * Particles<D>::volumeOf(mean)) / (n + 1);
        s.minRadius = n > 0 ? std::min(s.minRadius, p.radiusMin) : p.radiusMin;
        s.minMass = n > 0 ? std::min(s.minMass, mMin) : mMin;
        s.count = std::max<std::size_t>(s.count, 1);
        if (p.shape == ShapeKind::Polygon) {
            // A lower bound of the lightest polygon's area, r^2 times: the regular one of the fewest sides, the
            // rectangle of the aspect, a triangle squeezed by the largest stretch.
            const double pi = 3.14159265358979323846, a = p.aspect;
            const double factor =
                p.polygon == PolygonKind::Regular
                    ? 0.5 * p.sidesMin * std::sin(2 * pi / p.sidesMin)
                    : (p.polygon == PolygonKind::Rectangle ? 4 * a / (1 + a * a) : 0.75 * std::sqrt(3.0) / a);
            const double mPoly = density * factor * p.radiusMin * p.radiusMin;
            s.minPolygonMass = s.polygons ? std::min(s.minPolygonMass, mPoly) : mPoly;
            s.polygons = std::max<std::size_t>(s.polygons, 1);
        }
    }
}

template <int D>
ContactSetup buildContactSetup(const Scenario& sc, const std::vector<MaterialStats>& stats) {
    const std::vector<MaterialProps> props(sc.materials.begin(), sc.materials.end());
    return buildContactSetup<D>(static_cast<const ContactModelDef&>(sc.contact), props, stats);
}

template <int D>
World<D> buildWorld(const Scenario& sc) {
    World<D> w;
    w.domain.lo = toVec<D>(sc.domain.lo);
    w.domain.hi = toVec<D>(sc.domain.hi);
    w.domain.gravity = toVec<D>(sc.domain.gravity);
    for (int k = 0; k < D; ++k) w.domain.periodic[k] = sc.domain.periodic[k];
    for (std::size_t q = 0; q < sc.walls.size(); ++q) {
        const WallDef& wd = sc.walls[q];
        if (wd.isPlane()) {
            w.walls.push_back(makePlane<D>(wd));
            w.walls.back().id = static_cast<int>(q);
        } else {
            w.surfaces.push_back(makeSurfaceWall<D>(wd));
            w.surfaces.back().id = static_cast<int>(q);
        }
    }
    insertParticles<D>(sc, w.particles, Rng(sc.seed, RngStream::Insert));
    std::vector<MaterialStats> stats = materialStats(w.particles, static_cast<int>(sc.materials.size()));
    inletStats<D>(sc, stats);
    w.contact = buildContactSetup<D>(sc, stats);
    return w;
}

template <int D>
TdmSettings tdmSettings(const Scenario& sc, const World<D>& w, std::string* dtNote) {
    TdmSettings s;
    s.integrator = sc.tdm.integrator;
    const Particles<D>& p = w.particles;
    std::size_t polygons = 0;
    if constexpr (D == 2)
        for (std::size_t i = 0; i < p.size(); ++i) polygons += p.isPolygon(i);
    // Polygons: Gear's predictor-corrector unless the scenario names an integrator (docs/physics.md F.3).
    if (polygons > 0 && !sc.tdm.integratorGiven) s.integrator = IntegratorKind::Gear5;
    s.maxOverlap = sc.tdm.maxOverlap;
    s.sortEvery = sc.tdm.sortEvery;
    for (const WallDef& wd : sc.walls) s.planeLoads = s.planeLoads || (wd.isPlane() && !wd.name.empty());
    std::ostringstream note;
    if (sc.tdm.dt) {
        s.dt = *sc.tdm.dt;
        note << "given; t_c/dt = " << w.contact.contactTime / s.dt;
    } else if (polygons > 0) {
        // The polygon rule; disks among them also keep their t_c / steps_per_contact.
        s.dt = w.contact.polygonStep;
        note << "auto: polygons, (pi/10) sqrt(m_min/Y)";
        if (w.contact.polygonStepFactor < 1)
            note << " x " << w.contact.polygonStepFactor << " (0.2/gamma: Gear's limit for strong damping)";
        if (polygons < p.size() && w.contact.diskContactTime / sc.tdm.stepsPerContact < s.dt) {
            s.dt = w.contact.diskContactTime / sc.tdm.stepsPerContact;
            note.str("");
            note << "auto: t_c / " << sc.tdm.stepsPerContact << " of the disks (shorter than the polygons' rule)";
        }
    } else {
        s.dt = w.contact.contactTime / sc.tdm.stepsPerContact;
        note << "auto: t_c / " << sc.tdm.stepsPerContact << " (" << w.contact.contactTimeNote << ")";
    }
    if (dtNote) *dtNote = note.str();
    double dmax = 0;
    for (double r : w.particles.radius) dmax = std::max(dmax, 2 * r);
    for (const InletDef& in : sc.inlets) dmax = std::max(dmax, 2 * in.particles.radiusMax);  // particles to come
    // Default skin: a tenth of the largest diameter (LAMMPS granular inputs typically use 0.1 d).
    s.skin = sc.tdm.skin ? *sc.tdm.skin : (dmax > 0 ? 0.1 * dmax : 1e-3);
    return s;
}

EdmSettings edmSettings(const Scenario& sc) {
    EdmSettings es;
    es.cellSize = sc.edm.cellSize.value_or(0.0);
    es.tangential = sc.edm.tangential == EdmTangential::Constant ? EdmSettings::Tangential::Constant
                                                                 : EdmSettings::Tangential::Walton;
    es.tcModel = sc.edm.tcModel;
    es.tcTime = sc.edm.tcTime.value_or(0.0);
    return es;
}

template <int D>
HaetSettings haetSettings(const Scenario& sc) {
    HaetSettings hs;
    hs.zones.size = sc.haet.zoneSize.value_or(0.0);
    // Default thresholds (docs/haet.md): disks pack denser than spheres, so their dense phase starts higher.
    hs.zones.phiOn = sc.haet.phiOn.value_or(D == 2 ? 0.45 : 0.30);
    hs.zones.phiOff = sc.haet.phiOff.value_or(D == 2 ? 0.40 : 0.25);
    hs.zones.buffer = sc.haet.buffer;
    hs.relabelEvery = sc.haet.relabelEvery;
    hs.diluteSteps = sc.haet.diluteSteps;
    hs.dtMin = sc.haet.dtMin.value_or(0.0);
    return hs;
}

template World<2> buildWorld<2>(const Scenario&);
template World<3> buildWorld<3>(const Scenario&);
template TdmSettings tdmSettings<2>(const Scenario&, const World<2>&, std::string*);
template TdmSettings tdmSettings<3>(const Scenario&, const World<3>&, std::string*);
template std::vector<MaterialStats> materialStats<2>(const Particles<2>&, int);
template std::vector<MaterialStats> materialStats<3>(const Particles<3>&, int);
template HaetSettings haetSettings<2>(const Scenario&);
template HaetSettings haetSettings<3>(const Scenario&);
template ContactSetup buildContactSetup<2>(const Scenario&, const std::vector<MaterialStats>&);
template ContactSetup buildContactSetup<3>(const Scenario&, const std::vector<MaterialStats>&);

}  // namespace haet
