#pragma once
// The force pass of 2D scenes that hold shapes (polygons, alone or mixed with disks), as the engine sees it: the
// engine runs it instead of the disk pass when the particle store has shapes. The pass is the pair pass
// (tdm/pair_pass.hpp) over the shapes' kernel, which lives with the shapes' geometry in polygon/ and is made by
// makeShapePass (polygon/shape_pass.cpp). polygon/ sits above tdm/: it includes the pair pass, and tdm/ reaches it
// through this interface only, never by including polygon/.
#include <memory>

#include "contact/setup.hpp"
#include "tdm/force_stats.hpp"
#include "tdm/pair_pass.hpp"

namespace haet {

class ShapePass {
public:
    virtual ~ShapePass() = default;
    /// Forces and torques of every particle at the predicted state, as computeForces for disks.
    virtual ForceStats forces(const ForceContext<2>& ctx) = 0;
    /// The elastic energy of the contacts at the current state [J], as the kernels' laws give it.
    virtual double energy(const ForceContext<2>& ctx) = 0;
};

/// The pass for the scene's laws (normal, tangential, polygon law).
std::unique_ptr<ShapePass> makeShapePass(const ContactSetup& cs);

}  // namespace haet
