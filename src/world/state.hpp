#pragma once
// The World's part of a checkpoint (ARCHITECTURE.md, "Checkpoints"): the time and every array of the particle store,
// in its current order (the engines' saved state refers to particles by index), and the motion of the walls a script
// changed (Simulation.set_wall). The box, the other walls and the contact table are not saved: they come from the
// scenario, which a resume must leave unchanged in them; their places follow from the time alone (moving and
// oscillating walls are functions of t).
#include "io/checkpoint.hpp"
#include "world/world.hpp"

namespace haet {

/// Writes world.time and the particle store. The store must hold its positions (Particles::hasMotion).
template <int D>
void saveWorld(ByteWriter& out, const World<D>& w);

/// Replaces world.time and the particle store of a World built from the same scenario with the saved ones. Throws
/// CheckpointError (Corrupt) when the saved arrays do not fit together (sizes, indices into the shape table,
/// materials outside the contact table). The store keeps forces and torques as the saved one did (a pure
/// event-driven run's has none).
template <int D>
void loadWorld(ByteReader& in, World<D>& w);

}  // namespace haet
