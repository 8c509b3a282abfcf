// `haet check`: what a scenario would run, per method (particles, walls, contact law and time step, memory, the
// sections of docs/physics.md behind it).
#include <fmt/format.h>
#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>

#include "core/version.hpp"
#include "edm/engine.hpp"
#include "haet/engine.hpp"
#include "io/atomic_file.hpp"
#include "io/checkpoint.hpp"
#include "io/frame.hpp"
#include "io/json.hpp"
#include "io/series.hpp"
#include "io/vtk.hpp"
#include "polygon/output.hpp"
#include "run/checkpoint.hpp"
#include "run/export.hpp"
#include "run/flow.hpp"
#include "run/picture.hpp"
#include "run/progress.hpp"
#include "run/run_dir.hpp"
#include "run/runner.hpp"
#include "run/schedule.hpp"
#include "run/stop.hpp"
#include "run/walls_output.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world/state.hpp"

namespace haet {
namespace {

/// The sections of docs/physics.md behind what `haet check` prints for the time-driven side of a run.
std::string tdmReferences(const Scenario& sc, IntegratorKind integrator, bool polygons) {
    std::string r = sc.contact.normal == NormalLaw::Linear ? "B.2 linear spring-dashpot" : "B.3 Hertz";
    if (sc.contact.tangential == TangentialLaw::Spring) r += ", B.4 tangential spring";
    if (polygons) r += ", G polygons";
    r += integrator == IntegratorKind::Gear5 ? ", F.1 Gear predictor-corrector" : ", F.2 velocity Verlet";
    return r + ", F.3 time step";
}

/// The restitution the soft law really gives (contact-ending rule included; the event-driven engine's e): each
/// material's pair of two mean particles, then each material of particles against each material of walls (their
/// own calibration, docs/physics.md B.3). `what` names it as the method's lines always have.
template <int D>
void describeRestitution(const Scenario& sc, const World<D>& world, const char* what, std::ostream& out) {
    const std::size_t nm = sc.materials.size();
    for (std::size_t a = 0; a < nm; ++a)
        out << fmt::format("material   {}: {} {:.5f} (incl. contact-end rule)\n", sc.materials[a].name, what,
                           world.contact.pair(int(a), int(a)).restitution);
    std::vector<bool> particles(nm, false), walls(nm, false);
    for (std::uint16_t m : world.particles.material) particles[m] = true;
    for (const InletDef& in : sc.inlets) particles[std::size_t(in.particles.material)] = true;
    for (const WallDef& w : sc.walls) walls[std::size_t(w.material)] = true;
    for (std::size_t a = 0; a < nm; ++a)
        for (std::size_t b = 0; b < nm; ++b)
            if (particles[a] && walls[b])
                out << fmt::format("material   {} on walls of {}: {} {:.5f} (a particle against a wall, m_eff = m)\n",
                                   sc.materials[a].name, sc.materials[b].name, what,
                                   world.contact.wallPair(int(a), int(b)).restitution);
}

template <int D>
void describeTdm(const Scenario& sc, std::ostream& out) {
    World<D> world = buildWorld<D>(sc);
    std::string dtNote;
    const TdmSettings ts = tdmSettings<D>(sc, world, &dtNote);
    TdmEngine<D> eng(world, ts);
    const std::size_t n = world.particles.size();
    const std::size_t pairs = eng.pairs().size();
    // Memory: particle arrays (x, v, f, mean velocity over the step, position at the list build; w, torque,
    // mean spin, and a polygon's orientation; radius, mass, 1/m, 1/I, id; image flags; list offset, material, flags) +
    // integrator history (Gear's higher derivatives; velocity Verlet keeps none) + pair list (partner, owner,
    // shift, spring).
    const std::size_t gearHistory = 4 * (sizeof(Vec<D>) + sizeof(Ang<D>));
    const std::size_t perParticle = sizeof(Vec<D>) * 5 + sizeof(Ang<D>) * (world.particles.hasPolygons() ? 4 : 3) +
                                    8 * 5 + 4 * D + 8 + (ts.integrator == IntegratorKind::Gear5 ? gearHistory : 0);
    const std::size_t perPair = 4 + 4 + 1 + sizeof(Vec<D>);
    const double steps = std::ceil(sc.duration / ts.dt);
    out << fmt::format("scenario   {} ({})\n", sc.name, sc.path);
    out << fmt::format("method     tdm, {}D, integrator {}\n", D,
                       ts.integrator == IntegratorKind::Gear5 ? "gear5" : "verlet");
    out << fmt::format("particles  {} ({} frozen), {} materials, {} walls\n", n,
                       std::count_if(world.particles.flags.begin(), world.particles.flags.end(),
                                     [](std::uint8_t f) { return f & kFrozen; }),
                       sc.materials.size(), world.walls.size() + world.surfaces.size());
    describeWalls(world, out);
    if (world.particles.hasPolygons())
        out << fmt::format("polygons   {} ({}; the rest are disks)\n", world.particles.shapes.size(),
                           sc.contact.polygonLaw == PolygonLaw::Potential
                               ? "potential law Y A |c| / L^2 at the chord midpoint, energy-conserving"
                               : "overlap-area law Y A / l, docs/physics.md G.3");
    out << fmt::format("contact    {} normal law, {} tangential; contact duration t_c = {:.4g} s ({})\n",
                       sc.contact.normal == NormalLaw::Linear ? "linear" : "hertz",
                       sc.contact.tangential == TangentialLaw::Spring ? "spring" : "no", world.contact.contactTime,
                       world.contact.contactTimeNote);
    out << fmt::format("time step  dt = {:.4g} s ({}); {:.0f} steps for {:.4g} s\n", ts.dt, dtNote, steps, sc.duration);
    out << fmt::format("neighbours skin {:.4g} m, {} pairs in the initial list\n", ts.skin, pairs);
    out << fmt::format("memory     about {:.1f} MB ({} bytes per particle)\n",
                       (n * perParticle + pairs * perPair) / 1e6, n ? (n * perParticle + pairs * perPair) / n : 0);
    describeRestitution(sc, world, "restitution of the soft law", out);
    out << fmt::format("physics    docs/physics.md {}\n",
                       tdmReferences(sc, ts.integrator, world.particles.hasPolygons()));
}

template <int D>
void describeEdm(const Scenario& sc, std::ostream& out) {
    World<D> world = buildWorld<D>(sc);
    const double tc = sc.edm.tcTime.value_or(world.contact.contactTime);
    out << fmt::format("scenario   {} ({})\n", sc.name, sc.path);
    out << fmt::format("method     edm (event-driven), {}D, tangential {}\n", D,
                       sc.edm.tangential == EdmTangential::Constant ? "constant beta" : "Walton's rule");
    out << fmt::format("particles  {}, {} materials, {} walls\n", world.particles.size(), sc.materials.size(),
                       world.walls.size() + world.surfaces.size());
    describeWalls(world, out);
    out << fmt::format("collapse   TC model {} (tc_time = {:.4g} s)\n", sc.edm.tcModel ? "on" : "off", tc);
    describeRestitution(sc, world, "restitution (the soft law's)", out);
    out << fmt::format(
        "physics    docs/physics.md C.1-C.2 collision rule, D.2-D.4 event times, D.6 invalid states{}{}\n",
        sc.edm.tcModel ? ", D.7 TC model" : "", world.surfaces.empty() ? "" : ", D.8 mesh walls");
}

template <int D>
void describeHaet(const Scenario& sc, std::ostream& out) {
    World<D> world = buildWorld<D>(sc);
    std::string dtNote;
    const TdmSettings ts = tdmSettings<D>(sc, world, &dtNote);
    const HaetEngine<D> eng(world, ts, edmSettings(sc), haetSettings<D>(sc));
    const HaetSettings& hs = eng.settings();
    out << fmt::format("scenario   {} ({})\n", sc.name, sc.path);
    out << fmt::format("method     haet (time-driven where dense, event-driven where dilute), {}D, integrator {}\n", D,
                       ts.integrator == IntegratorKind::Gear5 ? "gear5" : "verlet");
    out << fmt::format("particles  {}: {} time-driven, {} event-driven at the start; {} walls\n",
                       world.particles.size(), eng.nTdm(), eng.nEdm(), world.walls.size() + world.surfaces.size());
    describeWalls(world, out);
    out << fmt::format("contact    t_c = {:.4g} s ({})\n", world.contact.contactTime, world.contact.contactTimeNote);
    out << fmt::format("time step  dt = {:.4g} s ({}); {:.0f} steps for {:.4g} s\n", ts.dt, dtNote,
                       std::ceil(sc.duration / ts.dt), sc.duration);
    const ZoneGrid<D>& z = eng.zones();
    std::string dims;
    for (int k = 0; k < D; ++k) dims += (k ? " x " : "") + std::to_string(z.dims()[k]);
    out << fmt::format(
        "zones      edge {:.4g} m ({} zones), phi_on {:.3g}, phi_off {:.3g}, buffer {}, "
        "relabel every {} steps, dilute_steps {}\n",
        hs.zones.size, dims, hs.zones.phiOn, hs.zones.phiOff, hs.zones.buffer, hs.relabelEvery, hs.diluteSteps);
    out << fmt::format("events     cell edge {:.4g} m ({})\n", eng.edm().cellSize(),
                       sc.edm.cellSize ? "[edm] cell_size, at least one diameter plus the skin"
                                       : "from the event-driven particles' density, docs/haet.md");
    out << fmt::format(
        "collapse   modified EDM: dt_min = {:.4g} s (a collision sooner hands both particles to the TDM)\n",
        eng.dtMin());
    describeRestitution(sc, world, "restitution in both engines (the soft law's)", out);
    out << fmt::format(
        "physics    docs/physics.md A.1 one physics, A.2 zones, A.4 modified EDM; {}; C.1-C.2 collision rule, "
        "D.2-D.4 event times{}\n",
        tdmReferences(sc, ts.integrator, false),
        world.surfaces.empty() ? "" : ", D.8 mesh walls, H.6 walls the event-driven part leaves to the time-driven");
}

void describeMethod(const Scenario& sc, std::ostream& out) {
    if (sc.method == Method::Haet) {
        if (sc.dimension == 2)
            describeHaet<2>(sc, out);
        else
            describeHaet<3>(sc, out);
        return;
    }
    if (sc.method == Method::Edm) {
        if (sc.dimension == 2)
            describeEdm<2>(sc, out);
        else
            describeEdm<3>(sc, out);
        return;
    }
    if (sc.dimension == 2)
        describeTdm<2>(sc, out);
    else
        describeTdm<3>(sc, out);
}

}  // namespace

void describeScenario(const Scenario& sc, std::ostream& out) {
    describeMethod(sc, out);
    describeFlows(sc, out);
}

}  // namespace haet
