#pragma once
// The state every engine works on: one particle store, the box, the walls and the contact coefficients.
#include <stdexcept>
#include <string>
#include <vector>

#include "contact/setup.hpp"
#include "core/particles.hpp"
#include "geometry/domain.hpp"
#include "geometry/surface.hpp"

namespace haet {

template <int D>
struct World {
    Particles<D> particles;
    Domain<D> domain;
    std::vector<Wall<D>> walls;            ///< planes
    std::vector<SurfaceWall<D>> surfaces;  ///< walls of any other shape (geometry/surface.hpp)
    ContactSetup contact;
    double time = 0;  ///< simulated time [s]
};

/// A run that cannot go on (NaN, overlap beyond the limit). The message names particle, time and likely cause.
class SimulationError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace haet
