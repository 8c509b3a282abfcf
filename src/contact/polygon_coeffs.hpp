#pragma once
// The coefficients of the overlap-area law of polygon contacts (docs/physics.md G.3) for one material pair. They
// live with the other laws' coefficients so that the contact set-up (contact/setup.cpp) builds them without
// reaching up into polygon/; the law itself, which needs the overlap geometry, is polygon/contact.hpp.
#include "contact/kinds.hpp"

namespace haet::polygon {

/// Coefficients of the polygon law for one material pair (built once, contact/setup.cpp).
struct PolygonCoeffs {
    double young = 0;                          ///< Y [N/m] (2D: stiffness per length), F_el = Y A / l
    double gamma = 0;                          ///< normal damping, dimensionless (docs/physics.md G.3)
    double kt = 0;                             ///< tangential spring stiffness [N/m]; 0 = no tangential force
    double gammaT = 0;                         ///< tangential damping: F = -gammaT sqrt(k_t m_t) g_t [-]
    double mu = 0;                             ///< Coulomb friction [-]
    PolygonLaw law = PolygonLaw::OverlapArea;  ///< normal force: G.3, or the energy-conserving variant
};

}  // namespace haet::polygon
