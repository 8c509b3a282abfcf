#pragma once
// The kinds of contact law and integrator a run can use. They belong to the physics, not to the scenario file:
// the definition structs (scenario/definition.hpp) include this header, never the reverse.

namespace haet {

/// Normal force law of disk and sphere contacts (docs/physics.md B.2, B.3).
enum class NormalLaw { Linear, Hertz };
/// Damping of the Hertz law: none, viscoelastic (Brilliantov et al.) or Tsuji's (docs/physics.md B.3).
enum class HertzDamping { None, Viscoelastic, Tsuji };
/// Tangential force: none, or the Cundall-Strack spring with Coulomb's limit (docs/physics.md B.4).
enum class TangentialLaw { None, Spring };
/// Normal force of contacts involving a polygon (docs/physics.md G.3; docs/scenario.md, Polygons).
enum class PolygonLaw { OverlapArea, Potential };
/// Time integrator of the time-driven engine (docs/physics.md F.1, F.2).
enum class IntegratorKind { Verlet, Gear5 };

}  // namespace haet
