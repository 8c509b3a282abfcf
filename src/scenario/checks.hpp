#pragma once
// Checks of a scenario that span its tables or need its particles, each with the key and line to blame: what the
// engines would otherwise find only once the run has started (or never: a wall that leaves no room, an
// event-driven constraint, a run too large for the machine). docs/scenario.md lists them with the keys.
#include <cstddef>
#include <filesystem>
#include <string>

#include "core/particles.hpp"
#include "scenario/definition.hpp"
#include "scenario/insert.hpp"

namespace haet {

/// Across tables, before any particle exists: walls against the insert regions, the particle counts (bounded, and
/// their memory against the machine's), the restitution where it is needed (a material without one gets 1, unused,
/// where the law does not read it). Called by the loader. Throws ScenarioError.
void checkScenario(Scenario& s);

/// MaterialDef::restitution as the loader leaves it when the file gives none (checkScenario resolves it).
inline constexpr double kRestitutionUnset = -1;

/// One particle file of insert k as read (each particle with its line): centres in the domain, radii it can hold, a
/// LAMMPS box that is the domain's on every periodic axis (positions wrap, and image flags unwrap, by that box), and,
/// for the hard particles of an event-driven or hybrid run, no two of the file's particles overlapping (rejected,
/// naming both lines: the engine would let them pass through each other). Called by insertion. Throws ScenarioError.
template <int D>
void checkFileParticles(const Scenario& s, std::size_t k, const ParticleFile& pf);

/// With the particles inserted (D: the scenario's dimension): sizes that no engine can run (a radius beyond the
/// box), hard particles that overlap (event-driven and hybrid runs), the event-driven engine's constraints on walls,
/// cells and periodic axes. Called by buildWorld. Throws ScenarioError.
template <int D>
void checkParticles(const Scenario& s, const Particles<D>& p);

/// The most particles a run holds: what 32-bit indices (pair lists, event-driven slots) count, with room.
inline constexpr std::size_t kMaxParticles = std::size_t(1) << 30;

/// Bytes a run of n particles takes at most, about (for the memory check and `haet check`).
double estimatedBytes(const Scenario& s, double n);

}  // namespace haet
