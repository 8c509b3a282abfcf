#pragma once
// The contact law of a particle and a wall (a plane, tdm/wall_kernel.hpp; a wall of any shape,
// tdm/surface_kernel.hpp): the particles' law with the wall as a partner of infinite mass (docs/physics.md B).
#include "contact/laws.hpp"
#include "core/vec.hpp"

namespace haet {

/// The contact law of a particle (velocity vi, spin wi; mean velocities over the last step svi, swi; radius ri, mass
/// meff) and a wall whose surface moves with velocity u at the contact, overlap delta along the unit normal nrm (from
/// the wall to the centre): adds the force to f and its torque to tq, updates the spring hist, and returns the
/// contact's force on the particle. The wall is infinitely heavy and locally flat (m_eff = m_i, R_eff = r_i).
template <int D, class Normal, class Tangential>
[[gnu::always_inline]] inline Vec<D> wallContactLaw(const PairCoeffs& c, double delta, const Vec<D>& nrm,
                                                    const Vec<D>& u, const Vec<D>& vi, const Ang<D>& wi,
                                                    const Vec<D>& svi, const Ang<D>& swi, double ri, double meff,
                                                    bool clip, Vec<D>& hist, double dt, Vec<D>& f, Ang<D>& tq,
                                                    Vec<D>* fnOut = nullptr, Vec<D>* ftOut = nullptr) {
    const Vec<D> dv = vi - u;
    const double gn = dot(dv, nrm);
    NormalResult nr = Normal::eval(c, delta, -gn, meff, ri);
    if (clip && nr.fn < 0) nr.fn = 0;
    f += nrm * nr.fn;
    // The contact network's pass only: the normal and tangential force as computed here.
    if (fnOut) [[unlikely]] {
        *fnOut = nrm * nr.fn;
        *ftOut = Vec<D>::zero();
    }
    if constexpr (Tangential::kHasHistory) {
        const Vec<D> gt = dv - nrm * gn - cross(wi * ri, nrm);
        const Vec<D> gs = svi - u - cross(swi * ri, nrm);
        const Vec<D> ft = Tangential::eval(c, nr.fn, nr.k, meff, nrm, gt, gs, hist, dt);
        f += ft;
        tq += cross(nrm, ft) * (-ri);
        if (ftOut) [[unlikely]]
            *ftOut = ft;
        return nrm * nr.fn + ft;
    } else {
        return nrm * nr.fn;
    }
}

}  // namespace haet
