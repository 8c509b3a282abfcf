#pragma once
// The wall kernel of disks and spheres: a particle against a plane wall (geometry/domain.hpp) with the particles'
// contact law, the wall infinitely heavy and flat (m_eff = m_i, R_eff = r_i). The pair pass (tdm/pair_pass.hpp)
// runs it for every wall of a particle, in wall order, once the particle's pair sums are complete.
#include <cstddef>

#include "contact/laws.hpp"
#include "contact/setup.hpp"
#include "core/particles.hpp"
#include "geometry/domain.hpp"
#include "tdm/pair_pass.hpp"
#include "tdm/surface_kernel.hpp"
#include "tdm/wall_law.hpp"

namespace haet {

template <int D, class Normal, class Tangential>
class DiskWall {
public:
    // Raw views taken once per pass: the stores of the pass cannot alias them, so nothing is reloaded per particle.
    explicit DiskWall(const ForceContext<D>& ctx)
        : walls_(ctx.walls),
          nw_(ctx.nWalls),
          history_(ctx.wallHistory),
          planeForce_(ctx.planeForce),
          x_(ctx.p.x.data()),
          v_(ctx.p.v.data()),
          w_(ctx.p.w.data()),
          sv_(ctx.sv),
          sw_(ctx.sw),
          radius_(ctx.p.radius.data()),
          mass_(ctx.p.mass.data()),
          material_(ctx.p.material.data()),
          table_(ctx.cs.wallTable.data()),
          nMaterials_(ctx.cs.nMaterials),
          dt_(ctx.dt),
          clip_(!ctx.cs.attraction),
          surfaces_(ctx) {}

    /// Adds wall w's contact with particle i to its force f and torque tq, and its overlap / radius to worst;
    /// returns whether they touch. Not touching, the contact's spring is cleared.
    [[gnu::always_inline]] bool add(std::size_t i, std::size_t w, Vec<D>& f, Ang<D>& tq, double& worst) const {
        const Wall<D>& wall = walls_[w];
        Vec<D>& hist = history_[i * nw_ + w];
        const double ri = radius_[i];
        const double delta = ri - wall.distanceNow(x_[i]);
        if (delta <= 0) {
            if constexpr (Tangential::kHasHistory) hist = Vec<D>::zero();
            if (planeForce_) planeForce_[i * nw_ + w] = Vec<D>::zero();
            return false;
        }
        const Vec<D> fw = wallContactLaw<D, Normal, Tangential>(table_[material_[i] * nMaterials_ + wall.material],
                                                                delta, wall.normal, wall.velocityNow, v_[i], w_[i],
                                                                sv_[i], sw_[i], ri, mass_[i], clip_, hist, dt_, f, tq);
        if (planeForce_) planeForce_[i * nw_ + w] = fw;
        worst = std::max(worst, delta / ri);
        return true;
    }

    /// Adds particle i's contacts with walls of any shape (tdm/surface_kernel.hpp); returns how many touch.
    [[gnu::always_inline]] std::uint32_t addSurfaces(std::size_t i, Vec<D>& f, Ang<D>& tq, double& worst) const {
        return surfaces_.add(i, f, tq, worst);
    }
    double surfaceEnergy(std::size_t i) const { return surfaces_.energy(i); }

    /// Elastic energy of wall w's contact with particle i at the current state [J] (the law's).
    double energy(std::size_t i, std::size_t w) const {
        const Wall<D>& wall = walls_[w];
        const double delta = radius_[i] - wall.distanceNow(x_[i]);
        if (delta <= 0) return 0;
        return Normal::energy(table_[material_[i] * nMaterials_ + wall.material], delta, mass_[i], radius_[i]);
    }

private:
    const Wall<D>* walls_;
    std::size_t nw_;
    Vec<D>* history_;
    Vec<D>* planeForce_;  ///< null, or the force of each (particle, wall) contact [N] (named walls' loads)
    const Vec<D>* x_;
    const Vec<D>* v_;
    const Ang<D>* w_;
    const Vec<D>* sv_;
    const Ang<D>* sw_;
    const double* radius_;
    const double* mass_;
    const std::uint16_t* material_;
    const PairCoeffs* table_;  ///< ContactSetup::wallTable: particle material x wall material
    int nMaterials_;
    double dt_;
    bool clip_;
    SurfaceKernel<D, Normal, Tangential> surfaces_;
};

}  // namespace haet
