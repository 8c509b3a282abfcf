#pragma once
// What the contact physics is made from: the material properties of each particle kind and the choice and
// parameters of the contact laws, with their units. The scenario's definition structs extend these with what only
// the file needs (names, source positions), so the contact set-up never sees the scenario.
#include <optional>

#include "contact/kinds.hpp"

namespace haet {

/// One material's properties, as the mixing rules of the contact laws read them (contact/setup.hpp).
struct MaterialProps {
    double density = 2500;                  ///< [kg/m^3] (2D: [kg/m^2], areal)
    double young = 1e7;                     ///< Young's modulus [Pa] (2D: stiffness per length [N/m]); Hertz only
    double poisson = 0.3;                   ///< Poisson ratio [-]; Hertz only
    double restitution = 0.9;               ///< normal coefficient of restitution e [-], 0 < e <= 1
    double friction = 0.5;                  ///< Coulomb friction coefficient mu [-]
    double tangentialRestitution = 1.0;     ///< beta0 of Walton's rule (event-driven engine) [-], -1..1
    std::optional<double> dissipationTime;  ///< viscoelastic Hertz A* [s]; default: from e at impact_velocity
};

/// The contact laws and their parameters (the scenario's [contact] section).
struct ContactModelDef {
    NormalLaw normal = NormalLaw::Linear;
    /// Linear law from (e, t_c): contact duration [s]. Either duration, or kn (+ gamma_n), must be set.
    std::optional<double> duration;
    std::optional<double> kn;      ///< linear normal stiffness [N/m], overrides duration
    std::optional<double> gammaN;  ///< normal damping, LAMMPS convention F = -m_eff gamma_n v_n [1/s]
    HertzDamping hertzDamping = HertzDamping::Viscoelastic;
    TangentialLaw tangential = TangentialLaw::Spring;
    std::optional<double> kt;       ///< tangential stiffness [N/m]; default kt_ratio * kn
    std::optional<double> ktRatio;  ///< kt/kn [-]; default q/(1+q): 2/7 spheres, 1/3 disks
    double gammaT = 0;              ///< tangential damping, LAMMPS convention [1/s]
    bool attraction = false;        ///< false: normal force clipped at zero (no attraction while separating)
    double impactVelocity = 1.0;    ///< Hertz: impact speed used for t_c and the time-step rule [m/s]
    /// Polygon contacts: dimensionless normal damping gamma of docs/physics.md G.3; default from the restitution
    std::optional<double> polygonDamping;
    /// Polygon contacts: F = Y A / l at the overlap centroid (G.3), or the energy-conserving F = Y A |c| / L^2
    PolygonLaw polygonLaw = PolygonLaw::OverlapArea;
};

}  // namespace haet
