#pragma once
// From a validated Scenario to the runtime objects: World<D> (particles, box, walls, contact table) and the
// engine settings (time step rule, skin). The only place where definition structs become runtime state.
#include <string>

#include "haet/engine.hpp"
#include "scenario/definition.hpp"
#include "tdm/engine.hpp"
#include "world/world.hpp"

namespace haet {

template <int D>
World<D> buildWorld(const Scenario& sc);

/// Time-step and neighbour settings for the time-driven engine; dtNote says how dt was chosen.
template <int D>
TdmSettings tdmSettings(const Scenario& sc, const World<D>& w, std::string* dtNote = nullptr);

/// The event-driven engine's settings from the scenario's [edm] section.
EdmSettings edmSettings(const Scenario& sc);

/// The hybrid's settings from the scenario's [haet] section, with the documented defaults (docs/physics.md A).
template <int D>
HaetSettings haetSettings(const Scenario& sc);

template <int D>
std::vector<MaterialStats> materialStats(const Particles<D>& p, int nMaterials);

/// The contact coefficients of the scenario's materials and [contact] section, for particles of these sizes
/// (materialStats).
template <int D>
ContactSetup buildContactSetup(const Scenario& sc, const std::vector<MaterialStats>& stats);

}  // namespace haet
