#pragma once
// Turns the user's materials and [contact] section into per-material-pair coefficients (PairCoeffs),
// once, before the run. Mixing rules (documented in docs/scenario.md):
//   E_eff = [(1-nu_a^2)/E_a + (1-nu_b^2)/E_b]^-1 (Hertz), e_ab = sqrt(e_a e_b), mu_ab = sqrt(mu_a mu_b),
//   beta0_ab = (beta0_a + beta0_b)/2, A*_ab = (A*_a + A*_b)/2.
#include <string>
#include <vector>

#include "contact/laws.hpp"
#include "contact/model.hpp"
#include "contact/polygon_coeffs.hpp"

namespace haet {

/// Sizes of the particles of one material, used for reference contacts (time step, derived damping).
struct MaterialStats {
    std::size_t count = 0;
    double meanRadius = 0, meanMass = 0;  ///< [m], [kg]
    double minRadius = 0, minMass = 0;    ///< [m], [kg]
    std::size_t polygons = 0;             ///< how many of them are polygons (2D)
    double minPolygonMass = 0;            ///< lightest polygon [kg] (0 when there is none)
};

struct ContactSetup {
    NormalLaw normal = NormalLaw::Linear;
    HertzDamping hertzDamping = HertzDamping::None;
    TangentialLaw tangential = TangentialLaw::None;
    bool attraction = false;
    int nMaterials = 0;
    std::vector<PairCoeffs> table;  ///< particle pairs: nMaterials x nMaterials, symmetric
    /// Particle-wall contacts: nMaterials (the particle's) x nMaterials (the wall's), not symmetric. Calibrated for
    /// one mean particle of the row's material against a flat wall (m_eff = m, R_eff = R); a combination that no
    /// particle and wall of the run can form holds the pair's coefficients.
    std::vector<PairCoeffs> wallTable;
    double contactTime = 0;       ///< shortest contact duration among particle pairs and walls [s]
    std::string contactTimeNote;  ///< how contactTime was obtained (for `haet check`)

    /// Overlap-area law of polygon contacts (docs/physics.md G.3), nMaterials x nMaterials; used for every contact
    /// that involves a polygon. Y_ab = 2 Y_a Y_b / (Y_a + Y_b) from the materials' `young`.
    std::vector<polygon::PolygonCoeffs> polygonTable;
    /// Polygon time-step rule (docs/physics.md F.3): (pi/10) sqrt(m_min / Y_max) over polygon particles [s]; 0 when the
    /// scene has no polygon.
    double polygonStep = 0;
    double polygonStepFactor = 1;  ///< the factor min(1, 0.2/gamma) in polygonStep (strong damping) [-]
    /// Contact duration of the disk law alone [s] (infinite when it has no coefficients): with polygons present,
    /// contactTime is the shorter of this and the polygons' pi sqrt(m_min/Y).
    double diskContactTime = 0;

    /// The deepest of the reference head-on collisions (two mean particles of the materials, or one and a wall, at
    /// impact_velocity): overlap / R_eff (infinite when a collision does not end or is not finite), and its
    /// materials (wall: b is the wall's).
    struct WorstHeadOn {
        double overlapRatio = 0;
        int a = -1, b = -1;
        bool wall = false;
    } worstHeadOn;
    /// The first reference collision whose Hertz damping, solved for, does not give the restitution asked (the law
    /// cannot reach it under the contact-ending rule; a = -1: none): its materials, the e asked and the one obtained
    /// (NaN: the bodies stick).
    struct CalibrationMiss {
        int a = -1, b = -1;
        bool wall = false;
        double asked = 0, obtained = 0;
    } calibrationMiss;

    const PairCoeffs& pair(int a, int b) const { return table[a * nMaterials + b]; }
    /// A particle of material `particle` against a wall of material `wall`.
    const PairCoeffs& wallPair(int particle, int wall) const { return wallTable[particle * nMaterials + wall]; }
    const polygon::PolygonCoeffs& polygonPair(int a, int b) const { return polygonTable[a * nMaterials + b]; }
};

/// Builds the coefficient table of particles in D dimensions from the contact laws, the materials (one entry per
/// material, in the order of their indices) and the sizes of their particles (stats: one entry per material,
/// count 0 for wall-only materials). Each law mixes the two materials' properties and derives its coefficients
/// in its own set-up function (setup.cpp), with its own contact duration for the time-step rule. `used` (one
/// entry per material; empty: all): only pairs of used materials get the head-on calibration and count for the
/// contact duration; the others keep the mixed values (and restitution e_ab). `wallMaterials` (one entry per
/// material; empty: every used one): the materials of walls; each with each used material of particles gets its
/// own particle-wall calibration in wallTable and counts for the contact duration.
template <int D>
ContactSetup buildContactSetup(const ContactModelDef& cd, const std::vector<MaterialProps>& materials,
                               const std::vector<MaterialStats>& stats, const std::vector<bool>& used = {},
                               const std::vector<bool>& wallMaterials = {});

/// Result of integrating one head-on collision of the soft law (docs/physics.md B.2/B.3).
struct HeadOnResult {
    double restitution;  ///< -g_n after / g_n before
    double duration;     ///< contact duration [s]
    double maxOverlap;   ///< [m]
};

/// Integrates a head-on collision with approach speed v [m/s] accurately (RK4, ~20000 steps per contact).
/// The contact ends when the overlap returns to zero, or (attraction = false) when the force reaches zero.
/// stopBelow > 0 (attraction = true): stops as soon as the restitution is known to be below stopBelow, returning a
/// value below it (a collision that the damping nearly holds together need not be followed to its end).
HeadOnResult simulateHeadOn(NormalLaw law, HertzDamping damping, const PairCoeffs& c, double meff, double reff,
                            double v, bool attraction, double stopBelow = 0);

}  // namespace haet
