#include "world/build.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/rng.hpp"
#include "scenario/checks.hpp"
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

/// The materials a run can bring into contact: those of its particles, its walls and its inserts (a source of
/// particles that adds them later must list its material here too). Only their pairs are calibrated.
static std::vector<bool> usedMaterials(const Scenario& sc, const std::vector<MaterialStats>& stats) {
    std::vector<bool> used(sc.materials.size(), false);
    for (std::size_t m = 0; m < stats.size() && m < used.size(); ++m) used[m] = stats[m].count > 0;
    for (const WallDef& w : sc.walls) used[w.material] = true;
    for (const InsertDef& in : sc.inserts) used[in.material] = true;
    for (const InletDef& in : sc.inlets) used[in.particles.material] = true;
    return used;
}

/// A reference head-on collision that does not end, or overlaps by more than the effective radius, means a contact
/// law the scene's speeds break (Hertz with a tiny Young's modulus at impact_velocity): bad input, named. So is a
/// restitution the damped Hertz law cannot give under the contact-ending rule.
static void checkHeadOn(const Scenario& sc, const ContactSetup& cs) {
    const ContactSetup::WorstHeadOn& w = cs.worstHeadOn;
    const bool hertz = sc.contact.normal == NormalLaw::Hertz;
    auto contactOf = [&](int a, int b, bool wall) {
        return "a head-on collision of " + sc.materials[a].name + " with " + (wall ? "a wall of " : "") +
               sc.materials[b].name;
    };
    if (w.a >= 0 && w.overlapRatio > 1 && (hertz || !std::isfinite(w.overlapRatio))) {
        // (the linear law's t_c is the user's; its e still holds)
        const MaterialDef& m = sc.materials[w.a];
        std::ostringstream os;
        os << contactOf(w.a, w.b, w.wall) << " at impact_velocity " << sc.contact.impactVelocity << " m/s ";
        if (std::isfinite(w.overlapRatio))
            os << "overlaps by " << w.overlapRatio << " effective radii: the modulus is too small for contacts at "
               << "this speed (Hertz needs overlaps well below the radius, docs/physics.md B.3)";
        else
            os << "does not end or is not finite: the contact law cannot be calibrated (docs/physics.md B.3)";
        throw ScenarioError(hertz ? m.pos : sc.contact.pos,
                            hertz ? "materials." + m.name + ".young" : std::string("contact"), os.str());
    }
    const ContactSetup::CalibrationMiss& miss = cs.calibrationMiss;
    if (miss.a < 0) return;
    // Blame the material whose restitution is the lower (the one that asks for the most damping).
    const int m = sc.materials[miss.b].restitution < sc.materials[miss.a].restitution ? miss.b : miss.a;
    std::ostringstream os;
    os << "the " << (sc.contact.hertzDamping == HertzDamping::Tsuji ? "Tsuji" : "viscoelastic")
       << " Hertz law cannot give " << contactOf(miss.a, miss.b, miss.wall) << " the restitution " << miss.asked
       << " (sqrt(e_a e_b)) at impact_velocity " << sc.contact.impactVelocity
       << " m/s with attraction = " << (sc.contact.attraction ? "true" : "false") << ": ";
    if (std::isnan(miss.obtained))
        os << "the damping that would give it holds the bodies together";
    else
        os << "the closest it comes is " << miss.obtained;
    os << " (docs/physics.md B.3)";
    throw ScenarioError(sc.materials[m].pos, "materials." + sc.materials[m].name + ".restitution", os.str());
}

template <int D>
ContactSetup buildContactSetup(const Scenario& sc, const std::vector<MaterialStats>& stats) {
    const std::vector<MaterialProps> props(sc.materials.begin(), sc.materials.end());
    std::vector<bool> walls(sc.materials.size(), false);
    for (const WallDef& w : sc.walls) walls[w.material] = true;
    ContactSetup cs = buildContactSetup<D>(static_cast<const ContactModelDef&>(sc.contact), props, stats,
                                           usedMaterials(sc, stats), walls);
    checkHeadOn(sc, cs);
    return cs;
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
    checkParticles<D>(sc, w.particles);  // what the engines cannot run, with the key (scenario/checks.hpp)
    std::vector<MaterialStats> stats = materialStats(w.particles, static_cast<int>(sc.materials.size()));
    inletStats<D>(sc, stats);
    w.contact = buildContactSetup<D>(sc, stats);
    return w;
}

/// The time step against the contact duration and the run's length: a hand-set dt beyond t_c leaves every contact
/// unresolved (velocity Verlet is unstable from dt = 2 t_c / pi on, docs/physics.md F.2) and makes the kick that
/// blows a system up; a step longer than the run takes no step at all.
static void checkTimeStep(const Scenario& sc, double dt, double contactTime, bool polygons) {
    auto fmtNum = [](double v) {
        std::ostringstream os;
        os << v;
        return os.str();
    };
    if (!(dt > 0 && dt < 1e300))  // a contact duration that overflowed (a radius of 1e300 m from a file)
        throw ScenarioError(sc.tdm.dtPos, "tdm.dt",
                            "the time step " + fmtNum(dt) + " s is not a usable number (check the particle sizes)");
    if (sc.tdm.dt && !polygons && contactTime > 0 && dt > contactTime)
        throw ScenarioError(sc.tdm.dtPos, "tdm.dt",
                            "the time step " + fmtNum(dt) +
                                " s is longer than the contact duration t_c = " + fmtNum(contactTime) +
                                " s: contacts are not resolved and a touch becomes a kick "
                                "(give dt <= t_c / 10, or dt = \"auto\")");
    if (dt > sc.duration)
        throw ScenarioError(sc.tdm.dtPos, sc.tdm.dt ? "tdm.dt" : "tdm.steps_per_contact",
                            "the time step " + fmtNum(dt) + " s (" +
                                (sc.tdm.dt ? "given" : "auto: t_c / " + fmtNum(sc.tdm.stepsPerContact)) +
                                ") is longer than the duration " + fmtNum(sc.duration) +
                                " s: the run would take no step");
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
    checkTimeStep(sc, s.dt, w.contact.contactTime, polygons > 0);
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
