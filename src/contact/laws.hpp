#pragma once
// Contact laws as pure functions of explicit inputs (docs/physics.md B). One law serves particle-particle and
// particle-wall contacts: a wall is a partner of infinite mass and radius (m_eff = m, R_eff = a).
#include <cmath>
#include <cstring>

#include "core/lanes.hpp"
#include "core/vec.hpp"

namespace haet {

/// Coefficients of one material pair, precomputed once at set-up. Only the members of the chosen laws are used.
struct PairCoeffs {
    // Linear spring-dashpot (B.2): k_n = knConst + knPerMeff * m_eff, gamma_n = gnPerMeff * m_eff.
    // (e, t_c) gives knPerMeff = (pi^2 + ln^2 e)/t_c^2 and gnPerMeff = -2 ln(e)/t_c, so every pair, whatever
    // its masses, has the requested e and t_c. A fixed kn (LAMMPS style) goes into knConst.
    double knConst = 0;    ///< [N/m]
    double knPerMeff = 0;  ///< [1/s^2]
    double gnPerMeff = 0;  ///< [1/s]
    // Hertz (B.3): F_el = hertzK sqrt(R_eff) delta^{3/2}, hertzK = (4/3) E_eff.
    double hertzK = 0;           ///< [Pa]
    double dissipationTime = 0;  ///< viscoelastic A* [s]: F_d = A* hertzK sqrt(R_eff delta) delta_dot
    double tsujiAlpha = 0;       ///< Tsuji: F_d = alpha sqrt(2 m_eff k_H) delta^{1/4} delta_dot (B.3 pitfall)
    // Tangential (B.4)
    double ktRatio = 0;    ///< k_t / k_n [-] (used when ktConst == 0)
    double ktConst = 0;    ///< fixed k_t [N/m]
    double gtPerMeff = 0;  ///< gamma_t / m_eff [1/s]
    double mu = 0;         ///< Coulomb friction [-]
    // Collision-operator view of the same pair (event-driven engine, docs/physics.md A.1, C)
    double restitution = 1;  ///< e that the soft law produces (incl. the contact-ending rule)
    double beta0 = 1;        ///< Walton's sticking tangential restitution
};

/// Whether the force law of every pair of the table is the same, bit for bit (the fields LanePairCoeffs reads):
/// then the force loop takes the first entry for every contact instead of looking up the pair's materials.
inline bool uniformForceLaw(const PairCoeffs* table, std::size_t n) {
    constexpr double PairCoeffs::*kFields[] = {
        &PairCoeffs::knConst,         &PairCoeffs::knPerMeff,  &PairCoeffs::gnPerMeff, &PairCoeffs::hertzK,
        &PairCoeffs::dissipationTime, &PairCoeffs::tsujiAlpha, &PairCoeffs::ktRatio,   &PairCoeffs::ktConst,
        &PairCoeffs::gtPerMeff,       &PairCoeffs::mu};
    for (std::size_t k = 1; k < n; ++k)
        for (const auto f : kFields)
            if (std::memcmp(&(table[k].*f), &(table[0].*f), sizeof(double)) != 0) return false;
    return true;
}

/// The coefficients of four material pairs side by side, one per lane (the force loop's four contacts at once).
struct LanePairCoeffs {
    Lanes knConst, knPerMeff, gnPerMeff, hertzK, dissipationTime, tsujiAlpha, ktRatio, ktConst, gtPerMeff, mu;

    /// Every lane holds c.
    explicit LanePairCoeffs(const PairCoeffs& c)
        : knConst(c.knConst),
          knPerMeff(c.knPerMeff),
          gnPerMeff(c.gnPerMeff),
          hertzK(c.hertzK),
          dissipationTime(c.dissipationTime),
          tsujiAlpha(c.tsujiAlpha),
          ktRatio(c.ktRatio),
          ktConst(c.ktConst),
          gtPerMeff(c.gtPerMeff),
          mu(c.mu) {}
    /// Lane l holds table[idx[l]].
    LanePairCoeffs(const PairCoeffs* table, LaneIndex idx) {
        static_assert(sizeof(PairCoeffs) % sizeof(double) == 0);
        const double* base = reinterpret_cast<const double*>(table);
        const LaneIndex at = idx * static_cast<std::int32_t>(sizeof(PairCoeffs) / sizeof(double));
        auto field = [&](const double PairCoeffs::*m) {
            return gather(base + (reinterpret_cast<const double*>(&(table->*m)) - base), at);
        };
        knConst = field(&PairCoeffs::knConst);
        knPerMeff = field(&PairCoeffs::knPerMeff);
        gnPerMeff = field(&PairCoeffs::gnPerMeff);
        hertzK = field(&PairCoeffs::hertzK);
        dissipationTime = field(&PairCoeffs::dissipationTime);
        tsujiAlpha = field(&PairCoeffs::tsujiAlpha);
        ktRatio = field(&PairCoeffs::ktRatio);
        ktConst = field(&PairCoeffs::ktConst);
        gtPerMeff = field(&PairCoeffs::gtPerMeff);
        mu = field(&PairCoeffs::mu);
    }
};

/// Eight lanes' coefficients: two groups of four (Lanes2).
struct LanePairCoeffs2 {
    Lanes2 knConst, knPerMeff, gnPerMeff, hertzK, dissipationTime, tsujiAlpha, ktRatio, ktConst, gtPerMeff, mu;

    LanePairCoeffs2(const LanePairCoeffs& a, const LanePairCoeffs& b)
        : knConst(a.knConst, b.knConst),
          knPerMeff(a.knPerMeff, b.knPerMeff),
          gnPerMeff(a.gnPerMeff, b.gnPerMeff),
          hertzK(a.hertzK, b.hertzK),
          dissipationTime(a.dissipationTime, b.dissipationTime),
          tsujiAlpha(a.tsujiAlpha, b.tsujiAlpha),
          ktRatio(a.ktRatio, b.ktRatio),
          ktConst(a.ktConst, b.ktConst),
          gtPerMeff(a.gtPerMeff, b.gtPerMeff),
          mu(a.mu, b.mu) {}
};

// The laws below are written once for one contact (S = double, C = PairCoeffs, vectors Vec<D> or Wide3) and for
// four in lanes (S = Lanes, C = LanePairCoeffs, vectors LaneVec<D>): core/lanes.hpp. A branch is a select() of
// the values both sides give, and the work of a side is skipped when no lane needs it (anyOf).

/// Normal force magnitude and the contact's secant stiffness (for the tangential spring).
template <class S>
struct NormalResultOf {
    S fn;  ///< normal force on i along n [N]; clipped at 0 unless attraction is allowed
    S k;   ///< secant stiffness F_el/delta [N/m]
};
using NormalResult = NormalResultOf<double>;

/// Linear spring-dashpot, F = k_n delta + gamma_n delta_dot (B.2). deltaDot = -g_n [m/s].
struct LinearNormal {
    template <class C, class S>
    static NormalResultOf<S> eval(const C& c, S delta, S deltaDot, S meff, S /*reff*/) {
        const S kn = c.knConst + c.knPerMeff * meff;
        return {kn * delta + c.gnPerMeff * meff * deltaDot, kn};
    }
    /// Elastic energy of the spring, k_n delta^2 / 2 [J].
    static double energy(const PairCoeffs& c, double delta, double meff, double /*reff*/) {
        return 0.5 * (c.knConst + c.knPerMeff * meff) * delta * delta;
    }
};

/// Elastic energy of a Hertz contact, (2/5) k_H sqrt(R) delta^{5/2} [J]: the work of rho delta^{3/2} (B.3).
inline double hertzEnergy(const PairCoeffs& c, double delta, double reff) {
    return 0.4 * c.hertzK * std::sqrt(reff) * std::pow(delta, 2.5);
}

/// Hertz with viscoelastic damping (Brilliantov et al. 1996; B.3): F = rho delta^{3/2} + A* rho sqrt(delta) delta_dot.
struct HertzViscoNormal {
    template <class C, class S>
    static NormalResultOf<S> eval(const C& c, S delta, S deltaDot, S /*meff*/, S reff) {
        const S k = c.hertzK * sqrtOf(reff * delta);  // secant stiffness rho sqrt(delta)
        return {k * (delta + c.dissipationTime * deltaDot), k};
    }
    static double energy(const PairCoeffs& c, double delta, double, double reff) { return hertzEnergy(c, delta, reff); }
};

/// Hertz with Tsuji damping: F = k_H delta^{3/2} + alpha sqrt(2 m_eff k_H) delta^{1/4} delta_dot, k_H = hertzK sqrt(R).
/// The mass in the damping is 2 m_eff: Tsuji's alpha(e) fit assumes the particle mass (docs/physics.md B.3 pitfall).
struct HertzTsujiNormal {
    template <class C, class S>
    static NormalResultOf<S> eval(const C& c, S delta, S deltaDot, S meff, S reff) {
        const S kH = c.hertzK * sqrtOf(reff);
        const S sd = sqrtOf(delta);
        const S damp = c.tsujiAlpha * sqrtOf(2.0 * meff * kH) * sqrtOf(sd);
        return {kH * delta * sd + damp * deltaDot, kH * sd};
    }
    static double energy(const PairCoeffs& c, double delta, double, double reff) { return hertzEnergy(c, delta, reff); }
};

/// Tsuji's polynomial alpha(e) for the damping coefficient (LAMMPS pair_granular docs).
inline double tsujiAlpha(double e) {
    return 1.2728 - 4.2783 * e + 11.087 * e * e - 22.348 * e * e * e + 27.467 * std::pow(e, 4) -
           18.022 * std::pow(e, 5) + 4.8218 * std::pow(e, 6);
}

/// No tangential force.
struct NoTangential {
    static constexpr bool kHasHistory = false;
    template <class C, class S, class V>
    static V eval(const C&, S, S, S, const V&, const V&, const V&, V&, double) {
        return V::zero();
    }
    template <class C, class S, class V>
    static V eval(const C&, S, S, S, const V&, const V&, S, const V&, const V&, V&, double) {
        return V::zero();
    }
};

/// Cundall-Strack tangential spring with Coulomb limit and history (B.4).
/// xi: the spring elongation [m], kept per contact; gt: tangential relative velocity of the contact points
/// (for the damping); gStep: the relative velocity of the contact points averaged over the last step, normal part
/// included (the law removes it), so that xi grows by the true relative displacement. n: the unit normal, d/|d|
/// for a pair with separation d (dist2 = |d|^2); a wall's normal is its own d (dist2 = 1).
struct SpringTangential {
    static constexpr bool kHasHistory = true;
    template <class C, class S, class V>  // V: Vec<D> or Wide3 (core/wide3.hpp) with S = double; LaneVec<D>, Lanes
    [[gnu::always_inline]] static inline V eval(const C& c, S fn, S kNormal, S meff, const V& n, const V& gt,
                                                const V& gStep, V& xi, double dt) {
        return eval(c, fn, kNormal, meff, n, n, S(1.0), gt, gStep, xi, dt);
    }
    template <class C, class S, class V>
    [[gnu::always_inline]] static inline V eval(const C& c, S fn, S kNormal, S meff, const V& n, const V& d, S dist2,
                                                const V& gt, const V& gStep, V& xi, double dt) {
        // The contact plane turns with the pair: xi is brought into it keeping its length (Luding 2008), then
        // grows by the step's displacement. Both go through one projection P(v) = v - n (n . v), which is linear:
        // P(s xi) + P(g dt) = P(s xi + g dt); and |P(xi)|^2 = |xi|^2 - (n . xi)^2 for a unit n. The length kept
        // is taken from d, not n: |d|^2 |P(xi)|^2 = |xi|^2 |d|^2 - (d . xi)^2, so that its division and square
        // root need not wait for the ones that make n.
        const S len2 = norm2(xi);
        S scale = 1;
        if (anyOf(len2 > 0)) {
            const S along = dot(d, xi);
            const S a2 = len2 * dist2;
            const S l2new = a2 - along * along;
            // A spring along n has no direction left: 0.
            scale = select(len2 > 0, select(l2new > 0, sqrtOf(a2 / l2new), S(0.0)), scale);
        }
        const V grown = xi * scale + gStep * dt;
        xi = grown - n * dot(n, grown);
        const S kt = select(c.ktConst > 0, c.ktConst, c.ktRatio * kNormal);
        const S gammaT = c.gtPerMeff * meff;
        V ft = xi * (-kt) - gt * gammaT;
        const S ft2 = norm2(ft);
        const S fmax = c.mu * fn;
        const auto sliding = ft2 > fmax * fmax;
        if (anyOf(sliding)) {
            // Sliding: the force sits on the Coulomb cone and the spring is shortened to match it.
            const V onCone = ft * (fmax / sqrtOf(ft2));
            ft = select(sliding, onCone, ft);
            xi = select(sliding & (kt > 0), (ft + gt * gammaT) * (-1.0 / kt), xi);
        }
        return ft;
    }
};

}  // namespace haet
