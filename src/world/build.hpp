#pragma once
// From a validated Scenario to the runtime objects: World<D> (particles, box, walls, contact table) and the
// engine settings (time step rule, skin). The only place where definition structs become runtime state.
#include <string>

#include "scenario/definition.hpp"
#include "tdm/engine.hpp"
#include "world/world.hpp"

namespace haet {

template <int D>
World<D> buildWorld(const Scenario& sc);

/// Time-step and neighbour settings for the time-driven engine; dtNote says how dt was chosen.
template <int D>
TdmSettings tdmSettings(const Scenario& sc, const World<D>& w, std::string* dtNote = nullptr);

template <int D>
std::vector<MaterialStats> materialStats(const Particles<D>& p, int nMaterials);

}  // namespace haet
