#pragma once
// The force pass of disks and spheres: the pair pass (tdm/pair_pass.hpp) over the disk kernel
// (tdm/disk_kernel.hpp) and its walls (tdm/wall_kernel.hpp), instantiated per (normal law, tangential law).
#include <vector>

#include "contact/setup.hpp"
#include "core/lanes_pack.hpp"
#include "core/particles.hpp"
#include "geometry/domain.hpp"
#include "neighbor/pair_list.hpp"
#include "tdm/disk_kernel.hpp"
#include "tdm/force_stats.hpp"
#include "tdm/pair_pass.hpp"

namespace haet {

/// Buffers of the disk pass, kept between steps so that no step allocates.
template <int D>
using ForceScratch = PairPassScratch<D, DiskEntry>;

/// Forces at the predicted state. sv/sw: mean velocities over the last step (StepMotion), which increment
/// the tangential springs; the damping terms use the predicted velocities p.v, p.w. then(i) runs once particle
/// i's force and torque are final, with them: then(i, f, torque) (it may change i's velocities, not its position;
/// nothing reads them after). kLanes: the law on four pairs at once (kLanePairs) or one by one, for tests that
/// hold the two to the same bits.
template <int D, class Normal, class Tangential, bool kLanes = kLanePairs, class Then>
ForceStats computeForces(Particles<D>& p, PairList<D>& pl, const std::vector<Wall<D>>& walls,
                         std::vector<Vec<D>>& wallHistory, const ContactSetup& cs, const Domain<D>& dom, double time,
                         double dt, const Vec<D>* sv, const Ang<D>* sw, ForceScratch<D>& s, Then then) {
    const ForceContext<D> ctx = forceContext(p, pl, walls, wallHistory, cs, dom, time, dt, sv, sw);
    const DiskKernel<D, Normal, Tangential, kLanes> kernel(ctx);
    return runPairPass(ctx, kernel, s, then);
}

/// The same on a context made by the caller (the engine's, with its walls of any shape and plane loads).
template <int D, class Normal, class Tangential, class Then>
ForceStats computeForcesIn(const ForceContext<D>& ctx, ForceScratch<D>& s, Then then) {
    const DiskKernel<D, Normal, Tangential, kLanePairs> kernel(ctx);
    return runPairPass(ctx, kernel, s, then);
}

/// The elastic energy of the contacts of disks or spheres at the state ctx holds [J] (the normal law's).
template <int D, class Normal>
double diskContactEnergy(const ForceContext<D>& ctx) {
    return contactEnergy(ctx, DiskKernel<D, Normal, NoTangential, false>(ctx));
}

}  // namespace haet
