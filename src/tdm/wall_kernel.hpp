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

namespace haet {

template <int D, class Normal, class Tangential>
class DiskWall {
public:
    // Raw views taken once per pass: the stores of the pass cannot alias them, so nothing is reloaded per particle.
    explicit DiskWall(const ForceContext<D>& ctx)
        : walls_(ctx.walls),
          nw_(ctx.nWalls),
          history_(ctx.wallHistory),
          x_(ctx.p.x.data()),
          v_(ctx.p.v.data()),
          w_(ctx.p.w.data()),
          sv_(ctx.sv),
          sw_(ctx.sw),
          radius_(ctx.p.radius.data()),
          mass_(ctx.p.mass.data()),
          material_(ctx.p.material.data()),
          table_(ctx.cs.table.data()),
          nMaterials_(ctx.cs.nMaterials),
          time_(ctx.time),
          dt_(ctx.dt),
          clip_(!ctx.cs.attraction) {}

    /// Adds wall w's contact with particle i to its force f and torque tq, and its overlap / radius to worst;
    /// returns whether they touch. Not touching, the contact's spring is cleared.
    [[gnu::always_inline]] bool add(std::size_t i, std::size_t w, Vec<D>& f, Ang<D>& tq, double& worst) const {
        const Wall<D>& wall = walls_[w];
        Vec<D>& hist = history_[i * nw_ + w];
        const double ri = radius_[i];
        const double delta = ri - wall.distance(x_[i], time_);
        if (delta <= 0) {
            if constexpr (Tangential::kHasHistory) hist = Vec<D>::zero();
            return false;
        }
        const Vec<D>& nrm = wall.normal;
        const double meff = mass_[i];
        const Vec<D> dv = v_[i] - wall.velocity;
        const double gn = dot(dv, nrm);
        const PairCoeffs& c = table_[material_[i] * nMaterials_ + wall.material];
        NormalResult nr = Normal::eval(c, delta, -gn, meff, ri);
        if (clip_ && nr.fn < 0) nr.fn = 0;
        f += nrm * nr.fn;
        if constexpr (Tangential::kHasHistory) {
            const Vec<D> gt = dv - nrm * gn - cross(w_[i] * ri, nrm);
            const Vec<D> gs = sv_[i] - wall.velocity - cross(sw_[i] * ri, nrm);
            const Vec<D> ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, gt, gs, hist, dt_);
            f += ft;
            tq += cross(nrm, ft) * (-ri);
        }
        worst = std::max(worst, delta / ri);
        return true;
    }

    /// Elastic energy of wall w's contact with particle i at the current state [J] (the law's).
    double energy(std::size_t i, std::size_t w) const {
        const Wall<D>& wall = walls_[w];
        const double delta = radius_[i] - wall.distance(x_[i], time_);
        if (delta <= 0) return 0;
        return Normal::energy(table_[material_[i] * nMaterials_ + wall.material], delta, mass_[i], radius_[i]);
    }

private:
    const Wall<D>* walls_;
    std::size_t nw_;
    Vec<D>* history_;
    const Vec<D>* x_;
    const Vec<D>* v_;
    const Ang<D>* w_;
    const Vec<D>* sv_;
    const Ang<D>* sw_;
    const double* radius_;
    const double* mass_;
    const std::uint16_t* material_;
    const PairCoeffs* table_;
    int nMaterials_;
    double time_, dt_;
    bool clip_;
};

}  // namespace haet
