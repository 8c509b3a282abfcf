#include "contact/setup.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>

namespace haet {
namespace {

constexpr double kPi = 3.14159265358979323846;

double normalForce(NormalLaw law, HertzDamping damping, const PairCoeffs& c, double delta, double ddot, double meff,
                   double reff) {
    if (law == NormalLaw::Linear) return LinearNormal::eval(c, delta, ddot, meff, reff).fn;
    if (delta <= 0) return 0;
    switch (damping) {
        case HertzDamping::Tsuji:
            return HertzTsujiNormal::eval(c, delta, ddot, meff, reff).fn;
        case HertzDamping::Viscoelastic:
            return HertzViscoNormal::eval(c, delta, ddot, meff, reff).fn;
        case HertzDamping::None:
            break;
    }
    return c.hertzK * std::sqrt(reff) * delta * std::sqrt(delta);
}

/// Finds the damping coefficient x >= 0 of a law for which a head-on collision at speed v gives
/// restitution e, with the contact-ending rule in force (bisection: e falls as x grows). `set` stores x in the
/// coefficients; `scale` is a first guess of its size. NaN when even the undamped collision does not end; when e
/// cannot be reached the result gives another e, which the caller sees in the measured restitution.
template <class Set>
double solveDamping(NormalLaw normal, const PairCoeffs& base, HertzDamping law, Set set, double scale, double e,
                    double meff, double reff, double v, bool attraction) {
    if (e >= 1) return 0;
    PairCoeffs c = base;
    auto restitutionAt = [&](double x) {
        set(c, x);
        return simulateHeadOn(normal, law, c, meff, reff, v, attraction, e).restitution;
    };
    if (std::isnan(restitutionAt(0))) return std::numeric_limits<double>::quiet_NaN();  // no collision to calibrate on
    // A NaN restitution of a damped collision: the bodies stick (attraction = true lets the damping hold them), e
    // is 0 in effect, below the e asked.
    double lo = 0, hi = scale;
    for (double r = restitutionAt(hi); r >= e; r = restitutionAt(hi)) {
        hi *= 2;
        if (hi > 1e6 * scale) return hi;
    }
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (restitutionAt(mid) > e ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

}  // namespace

HeadOnResult simulateHeadOn(NormalLaw law, HertzDamping damping, const PairCoeffs& c, double meff, double reff,
                            double v, bool attraction, double stopBelow) {
    // Overlap equation m_eff delta'' = -F(delta, delta'), delta(0) = 0, delta'(0) = v.
    // Step from the elastic estimate of the contact time.
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    double tEst;
    if (law == NormalLaw::Linear) {
        const double kn = c.knConst + c.knPerMeff * meff;
        tEst = kPi * std::sqrt(meff / kn);
    } else {
        const double eEff = 0.75 * c.hertzK;
        tEst = 2.868 * std::pow(meff * meff / (reff * eEff * eEff * v), 0.2);
    }
    // A law without a usable time scale (a Young's modulus so small that E_eff^2 underflows) has no collision.
    if (!(tEst > 0 && tEst < std::numeric_limits<double>::infinity())) return {kNaN, kNaN, kNaN};
    const double h = tEst / 20000.0;
    auto acc = [&](double d, double dd) { return -normalForce(law, damping, c, d, dd, meff, reff) / meff; };
    double d = 0, dd = v, t = 0, dmax = 0;
    // A contact lasts about 20000 steps; one that has not ended after 50 times as many never will (or its state
    // is no longer finite): the set-up reports it instead of spinning (docs/physics.md B.3).
    for (long step = 0; step < 1000000; ++step) {
        const double k1x = dd, k1v = acc(d, dd);
        const double k2x = dd + 0.5 * h * k1v, k2v = acc(d + 0.5 * h * k1x, dd + 0.5 * h * k1v);
        const double k3x = dd + 0.5 * h * k2v, k3v = acc(d + 0.5 * h * k2x, dd + 0.5 * h * k2v);
        const double k4x = dd + h * k3v, k4v = acc(d + h * k3x, dd + h * k3v);
        const double dn = d + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
        const double ddn = dd + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
        if (!std::isfinite(dn) || !std::isfinite(ddn)) return {kNaN, t, dmax};
        dmax = std::max(dmax, dn);
        if (dn <= 0) {  // overlap returned to zero: interpolate the crossing linearly
            const double frac = d / (d - dn);
            return {-(dd + frac * (ddn - dd)) / v, t + frac * h, dmax};
        }
        if (attraction && stopBelow > 0 && ddn < 0 && -ddn < stopBelow * v &&
            normalForce(law, damping, c, dn, ddn, meff, reff) < 0) {
            // Separating and pulled back: the force stays attractive until the overlap ends (where F = 0 while
            // separating, dF/dt < 0 for every law here), so the speed only falls: e < -delta'/v already.
            return {-ddn / v, t + h, dmax};
        }
        if (!attraction && step > 0) {
            const double fOld = normalForce(law, damping, c, d, dd, meff, reff);
            const double fNew = normalForce(law, damping, c, dn, ddn, meff, reff);
            if (fNew <= 0 && ddn < 0) {  // force would turn attractive: the particles separate here
                const double frac = fOld / (fOld - fNew);
                return {-(dd + frac * (ddn - dd)) / v, t + frac * h, dmax};
            }
        }
        d = dn;
        dd = ddn;
        t += h;
    }
    return {kNaN, t, dmax};
}

namespace {

/// What every law's set-up reads of one material pair: the two materials, the mixed restitution and the
/// reference contact (two mean particles of the materials) for coefficients that depend on the masses.
struct PairRef {
    const MaterialProps& a;
    const MaterialProps& b;
    double e = 1, lne = 0;            ///< e_ab = sqrt(e_a e_b) and its logarithm
    double meffRef = 0, reffRef = 0;  ///< [kg], [m]
};

/// gamma_n t_c of the linear law from (e, t_c) when the normal force is clipped at zero (attraction = false). The
/// analytic gamma_n = -2 ln(e) / t_c assumes the contact lasts until the overlap returns to zero; with the clipped
/// force the particles separate earlier, while the spring still pushes, and e comes out larger (0.632 for 0.6).
/// So the damping is solved for, by the head-on integration with the clipping rule, so that e is the one asked
/// for. With k_n = (pi^2 + ln^2 e) / t_c^2 per unit effective mass the collision scales with t_c and does not
/// depend on the masses, so gamma_n t_c depends on e alone: solved once per e (in units t_c = 1, m_eff = 1).
double linearClippedDamping(double e) {
    static std::mutex guard;
    static std::map<double, double> solved;
    const std::lock_guard<std::mutex> lock(guard);
    if (const auto it = solved.find(e); it != solved.end()) return it->second;
    const double lne = std::log(e);
    PairCoeffs c;
    c.knPerMeff = kPi * kPi + lne * lne;
    const double x = solveDamping(
        NormalLaw::Linear, c, HertzDamping::None, [](PairCoeffs& pc, double g) { pc.gnPerMeff = g; },
        std::max(-2 * lne, 1e-3), e, 1.0, 1.0, 1.0, false);
    solved.emplace(e, x);
    return x;
}

/// Linear spring-dashpot (docs/physics.md B.2) from a fixed k_n (and gamma_n), or from (e, t_c).
void setUpLinear(PairCoeffs& c, const ContactModelDef& cd, const PairRef& p) {
    if (cd.kn) {
        c.knConst = *cd.kn;
        if (cd.gammaN) {
            c.gnPerMeff = *cd.gammaN;
        } else {
            // gamma_n = -2 ln(e) sqrt(m_eff k_n / (pi^2 + ln^2 e)): exact for the reference pair
            c.gnPerMeff = -2 * p.lne * std::sqrt(*cd.kn / (p.meffRef * (kPi * kPi + p.lne * p.lne)));
        }
    } else if (cd.duration) {
        const double tc = *cd.duration;
        c.knPerMeff = (kPi * kPi + p.lne * p.lne) / (tc * tc);
        c.gnPerMeff = (cd.attraction ? -2 * p.lne : linearClippedDamping(p.e)) / tc;
    }
}

/// Duration of a contact of the linear law between partners of effective mass meff: pi over the damped
/// frequency (the undamped one when the damping is supercritical).
double linearContactTime(const PairCoeffs& c, double meff) {
    const double kn = c.knConst + c.knPerMeff * meff;
    const double eta = 0.5 * c.gnPerMeff;
    const double w2 = kn / meff - eta * eta;
    return w2 > 0 ? kPi / std::sqrt(w2) : kPi * std::sqrt(meff / kn);
}

/// Elastic Hertz contact duration t_c = 2.868 (m_eff^2 / (R_eff E_eff^2 v))^(1/5) (docs/physics.md B.3).
double hertzContactTime(const PairCoeffs& c, double meff, double reff, double v) {
    const double eEff = 0.75 * c.hertzK;
    return 2.868 * std::pow(meff * meff / (reff * eEff * eEff * v), 0.2);
}

/// Hertz with viscoelastic or Tsuji damping (docs/physics.md B.3): E_eff from the two materials, the damping
/// solved for the restitution e_ab at the impact velocity under the contact-ending rule in force.
void setUpHertz(PairCoeffs& c, const ContactModelDef& cd, const PairRef& p) {
    const double ea = (1 - p.a.poisson * p.a.poisson) / p.a.young;
    const double eb = (1 - p.b.poisson * p.b.poisson) / p.b.young;
    c.hertzK = (4.0 / 3.0) / (ea + eb);
    if (cd.hertzDamping == HertzDamping::Tsuji) {
        // Tsuji's polynomial alpha(e) fit is good to about 0.01 in e, and assumes the contact ends at zero overlap;
        // with the force clipped at zero the same alpha gives a larger e still. So alpha is solved for, under the
        // rule in force, starting from the fit. The collision does not depend on the speed, the mass or the
        // radius for this law (its damping scales as sqrt(m_eff k_H)), so pairs and walls share one alpha.
        c.tsujiAlpha = solveDamping(
            NormalLaw::Hertz, c, HertzDamping::Tsuji, [](PairCoeffs& pc, double x) { pc.tsujiAlpha = x; },
            std::max(tsujiAlpha(p.e), 1e-3), p.e, p.meffRef, p.reffRef, cd.impactVelocity, cd.attraction);
    } else if (cd.hertzDamping == HertzDamping::Viscoelastic) {
        if (p.a.dissipationTime && p.b.dissipationTime) {
            c.dissipationTime = 0.5 * (*p.a.dissipationTime + *p.b.dissipationTime);
        } else {
            // The elastic contact time bounds any sensible A*.
            const double tcRef = hertzContactTime(c, p.meffRef, p.reffRef, cd.impactVelocity);
            c.dissipationTime = solveDamping(
                NormalLaw::Hertz, c, HertzDamping::Viscoelastic,
                [](PairCoeffs& pc, double x) { pc.dissipationTime = x; }, tcRef, p.e, p.meffRef, p.reffRef,
                cd.impactVelocity, cd.attraction);
        }
    }
}

/// Cundall-Strack spring (docs/physics.md B.4): k_t fixed, or k_t / k_n = q / (1 + q) with q = 1/2 for disks and
/// 2/5 for spheres (the ratio that makes normal and tangential oscillations of a contact equally fast).
template <int D>
void setUpSpring(PairCoeffs& c, const ContactModelDef& cd) {
    constexpr double q = D == 2 ? 0.5 : 0.4;
    if (cd.kt)
        c.ktConst = *cd.kt;
    else
        c.ktRatio = cd.ktRatio ? *cd.ktRatio : q / (1 + q);
    c.gtPerMeff = cd.gammaT;
}

/// Overlap-area law of polygon contacts (docs/physics.md G.3): Y_ab = 2 Y_a Y_b / (Y_a + Y_b). Damping from e:
/// for a flat contact as wide as l the law is a linear spring-dashpot with damping ratio gamma/2, so
/// gamma = 2 (-ln e)/sqrt(pi^2 + ln^2 e) gives e there.
polygon::PolygonCoeffs polygonCoeffs(const ContactModelDef& cd, const PairRef& p, double mu) {
    polygon::PolygonCoeffs pc;
    pc.young = 2 * p.a.young * p.b.young / (p.a.young + p.b.young);
    pc.gamma = cd.polygonDamping ? *cd.polygonDamping : -2 * p.lne / std::sqrt(kPi * kPi + p.lne * p.lne);
    pc.mu = mu;
    pc.law = cd.polygonLaw;
    if (cd.tangential == TangentialLaw::Spring) {
        pc.kt = cd.kt ? *cd.kt : (cd.ktRatio ? *cd.ktRatio : 2.0 / 7.0) * pc.young;
        pc.gammaT = p.e < 1 ? 0.25 : 0.0;  // Matuttis-Chen's 0.25 sqrt(k_t m_t); none in an elastic scene
    }
    return pc;
}

/// Makes the coefficients of contacts between materials a and b for one reference contact (m_eff, R_eff): a pair of
/// particles, or a particle and a wall (docs/physics.md B.3). Hertz calibrations with the same inputs are done
/// once (`calibrated`: one head-on integration per calibration, some 10^6 force evaluations).
template <int D>
class CoeffMaker {
public:
    CoeffMaker(const ContactModelDef& cd, const ContactSetup& s) : cd_(cd), s_(s) {}

    /// The coefficients of a contact of a with b; `calibrate`: the Hertz damping is solved for and the real
    /// restitution measured (else the mixed values without calibration, and restitution e_ab).
    PairCoeffs make(const MaterialProps& ma, const MaterialProps& mb, double meff, double reff, bool calibrate,
                    HeadOnResult& h) {
        const double e = std::sqrt(ma.restitution * mb.restitution);
        const PairRef p{ma, mb, e, std::log(e), meff, reff};
        PairCoeffs c;
        c.mu = std::sqrt(ma.friction * mb.friction);
        c.beta0 = 0.5 * (ma.tangentialRestitution + mb.tangentialRestitution);
        const double ea = (1 - ma.poisson * ma.poisson) / ma.young, eb = (1 - mb.poisson * mb.poisson) / mb.young;
        if (cd_.normal == NormalLaw::Linear) {
            setUpLinear(c, cd_, p);
        } else if (calibrate) {
            // Tsuji's collision does not depend on m_eff and R_eff (setUpHertz): pairs and walls share one alpha.
            const bool tsuji = cd_.hertzDamping == HertzDamping::Tsuji;
            const std::array<double, 6> key{ea + eb,
                                            e,
                                            tsuji ? 0 : meff,
                                            tsuji ? 0 : reff,
                                            ma.dissipationTime.value_or(-1),
                                            mb.dissipationTime.value_or(-1)};
            if (const auto it = calibrated_.find(key); it != calibrated_.end()) {
                c.hertzK = it->second.hertzK;
                c.tsujiAlpha = it->second.tsujiAlpha;
                c.dissipationTime = it->second.dissipationTime;
            } else {
                setUpHertz(c, cd_, p);
                calibrated_.emplace(key, c);
            }
        } else {
            c.hertzK = (4.0 / 3.0) / (ea + eb);
        }
        if (cd_.tangential == TangentialLaw::Spring) setUpSpring<D>(c, cd_);
        // The restitution the soft law really produces (contact-ending rule included), for the EDM.
        c.restitution = e;
        h = {e, 0, 0};
        // (A polygon-only scene may leave the linear law without coefficients: nothing to simulate.)
        const bool haveDiskLaw = cd_.normal == NormalLaw::Hertz || cd_.kn || cd_.duration;
        if (haveDiskLaw && calibrate) {
            h = simulateHeadOn(s_.normal, s_.hertzDamping, c, meff, reff, cd_.impactVelocity, cd_.attraction);
            c.restitution = h.restitution;
        }
        return c;
    }

private:
    const ContactModelDef& cd_;
    const ContactSetup& s_;
    std::map<std::array<double, 6>, PairCoeffs> calibrated_;
};

}  // namespace

template <int D>
ContactSetup buildContactSetup(const ContactModelDef& cd, const std::vector<MaterialProps>& materials,
                               const std::vector<MaterialStats>& stats, const std::vector<bool>& used,
                               const std::vector<bool>& wallMaterials) {
    ContactSetup s;
    s.normal = cd.normal;
    s.hertzDamping = cd.normal == NormalLaw::Hertz ? cd.hertzDamping : HertzDamping::None;
    s.tangential = cd.tangential;
    s.attraction = cd.attraction;
    const int nm = static_cast<int>(materials.size());
    s.nMaterials = nm;
    s.table.resize(nm * nm);
    s.wallTable.resize(nm * nm);
    s.polygonTable.resize(nm * nm);

    // Reference particle of each material (materials without particles borrow the overall mean).
    MaterialStats all;
    for (const auto& st : stats) {
        if (st.count == 0) continue;
        all.meanRadius += st.meanRadius * st.count;
        all.meanMass += st.meanMass * st.count;
        all.count += st.count;
        all.minRadius = all.minRadius == 0 ? st.minRadius : std::min(all.minRadius, st.minRadius);
        all.minMass = all.minMass == 0 ? st.minMass : std::min(all.minMass, st.minMass);
    }
    if (all.count > 0) {
        all.meanRadius /= all.count;
        all.meanMass /= all.count;
    } else {
        all.meanRadius = all.minRadius = 1;
        all.meanMass = all.minMass = 1;
    }
    auto ref = [&](int m) { return (m < (int)stats.size() && stats[m].count > 0) ? stats[m] : all; };

    // The deepest reference collision, and the first whose calibrated damping misses the restitution asked (the
    // bisection meets it to ~1e-15; a miss means the law cannot give that e under the contact-ending rule).
    const bool solvesDamping = cd.normal == NormalLaw::Hertz && cd.hertzDamping != HertzDamping::None;
    auto record = [&](const HeadOnResult& h, const PairCoeffs& c, const MaterialProps& ma, const MaterialProps& mb,
                      double meff, double reff, int a, int b, bool wall) {
        double ratio = std::isnan(h.restitution) ? std::numeric_limits<double>::infinity() : h.maxOverlap / reff;
        const double e = std::sqrt(ma.restitution * mb.restitution);
        const bool userDamping =
            cd.hertzDamping == HertzDamping::Viscoelastic && ma.dissipationTime && mb.dissipationTime;
        if (solvesDamping && !userDamping && e < 1 && !(std::abs(h.restitution - e) <= 1e-6)) {
            // The law cannot give e here. A collision that does not end although the elastic one does is the
            // damping's doing (the bodies stick), not the modulus'.
            PairCoeffs elastic = c;
            elastic.dissipationTime = elastic.tsujiAlpha = 0;
            const HeadOnResult he =
                simulateHeadOn(NormalLaw::Hertz, HertzDamping::None, elastic, meff, reff, cd.impactVelocity, false);
            if (!std::isnan(he.restitution)) {
                if (std::isnan(h.restitution)) ratio = he.maxOverlap / reff;
                if (s.calibrationMiss.a < 0) s.calibrationMiss = {a, b, wall, e, h.restitution};
            }
        }
        if (!(ratio <= s.worstHeadOn.overlapRatio)) s.worstHeadOn = {ratio, a, b, wall};
    };

    // The table is symmetric (every mixing rule is), so each pair is set up once. A pair of which a material is
    // unused (no particle, no wall, no insert) keeps the mixed values without the head-on calibration, which costs
    // some 10^6 force evaluations per pair (200 materials took 55 s); pairs with the same inputs share one.
    auto isUsed = [&](int m) { return used.empty() || used[m]; };
    auto isWall = [&](int m) { return wallMaterials.empty() || wallMaterials[m]; };
    // A material of particles: used, and not only a wall's.
    auto isParticle = [&](int m) {
        return isUsed(m) && (wallMaterials.empty() || !wallMaterials[m] || (m < (int)stats.size() && stats[m].count));
    };
    CoeffMaker<D> maker(cd, s);
    for (int a = 0; a < nm; ++a) {
        for (int b = a; b < nm; ++b) {
            const MaterialStats ra = ref(a), rb = ref(b);
            const double meff = ra.meanMass * rb.meanMass / (ra.meanMass + rb.meanMass);
            const double reff = ra.meanRadius * rb.meanRadius / (ra.meanRadius + rb.meanRadius);
            const bool pairUsed = isUsed(a) && isUsed(b);
            HeadOnResult h;
            const PairCoeffs c = maker.make(materials[a], materials[b], meff, reff, pairUsed, h);
            if (pairUsed) record(h, c, materials[a], materials[b], meff, reff, a, b, false);
            s.table[a * nm + b] = s.table[b * nm + a] = c;
            const double e = std::sqrt(materials[a].restitution * materials[b].restitution);
            const PairRef p{materials[a], materials[b], e, std::log(e), meff, reff};
            s.polygonTable[a * nm + b] = s.polygonTable[b * nm + a] = polygonCoeffs(cd, p, c.mu);
        }
    }
    // Particle-wall contacts (row: the particle's material, column: the wall's): a wall is a partner of infinite
    // mass and radius, so the reference contact is one mean particle of the material against a flat wall, m_eff = m
    // and R_eff = R (docs/physics.md B.3). The viscoelastic law's e depends on m_eff, R_eff and the speed: its A*
    // is solved for this contact on its own. Combinations that cannot touch keep the pair's coefficients.
    s.wallTable = s.table;
    for (int a = 0; a < nm; ++a) {
        if (!isParticle(a)) continue;
        const MaterialStats ra = ref(a);
        for (int b = 0; b < nm; ++b) {
            if (!isUsed(b) || !isWall(b)) continue;
            HeadOnResult h;
            const PairCoeffs c = maker.make(materials[a], materials[b], ra.meanMass, ra.meanRadius, true, h);
            record(h, c, materials[a], materials[b], ra.meanMass, ra.meanRadius, a, b, true);
            s.wallTable[a * nm + b] = c;
        }
    }

    // Contact time for the time-step rule: the lightest pair (two smallest particles), and the wall contacts (the
    // lightest particle of each material against each wall material, m_eff = m, R_eff = R).
    const double meffMin = 0.5 * all.minMass;
    const double reffMin = 0.5 * all.minRadius;
    double tc = std::numeric_limits<double>::infinity();
    // The linear law from (e, t_c) with the force clipped: its damping is solved for (linearClippedDamping), so
    // its damped period is no longer t_c; the time-step rule keeps the t_c the user gave.
    const bool givenDuration = cd.normal == NormalLaw::Linear && !cd.kn && cd.duration && !cd.attraction;
    auto contactTime = [&](const PairCoeffs& c, double meff, double reff) {
        return givenDuration                    ? *cd.duration
               : cd.normal == NormalLaw::Linear ? linearContactTime(c, meff)
                                                : hertzContactTime(c, meff, reff, cd.impactVelocity);
    };
    for (int k = 0; k < nm * nm; ++k) {
        if (!isUsed(k / nm) || !isUsed(k % nm)) continue;
        tc = std::min(tc, contactTime(s.table[k], meffMin, reffMin));
    }
    bool wallShortest = false;
    for (int a = 0; a < nm; ++a) {
        if (!isParticle(a)) continue;
        const MaterialStats ra = ref(a);
        for (int b = 0; b < nm; ++b) {
            if (!isUsed(b) || !isWall(b)) continue;
            const double t = contactTime(s.wallTable[a * nm + b], ra.minMass, ra.minRadius);
            if (t < tc) {
                tc = t;
                wallShortest = true;
            }
        }
    }
    s.contactTime = tc;
    s.diskContactTime = tc;
    if (cd.normal == NormalLaw::Linear)
        s.contactTimeNote =
            cd.kn ? "linear law, fixed k_n: t_c = pi/omega of the lightest pair" : "linear law: t_c as given";
    else
        s.contactTimeNote =
            "Hertz: t_c = 2.868 (m_eff^2/(R_eff E_eff^2 v))^(1/5) of the smallest pair at impact_velocity";
    if (wallShortest && !givenDuration) s.contactTimeNote += " (a wall contact: the shortest)";

    // Polygons: the thesis rule dt = (pi/10) sqrt(m_min/Y) (docs/physics.md F.3), with the stiffest pair's Y; their
    // contact time is about ten such steps. The rule assumes light damping: the Gear corrector sees the damping
    // force through the predicted velocity and turns unstable once the damping rate per step, gamma (w/l)
    // sqrt(Y/m) dt, exceeds about 0.15 (damped oscillator: stable at 2 zeta omega dt = 0.12, unstable at 0.18; a
    // flat contact has w/l up to ~1.5). So for gamma > 0.2 (e < 0.73) the step shrinks by 0.2/gamma.
    std::size_t polygons = 0;
    double mPoly = 0;
    for (const auto& st : stats)
        if (st.polygons) {
            mPoly = polygons ? std::min(mPoly, st.minPolygonMass) : st.minPolygonMass;
            polygons += st.polygons;
        }
    if (polygons > 0) {
        double yMax = 0, gMax = 0;
        for (const auto& pc : s.polygonTable) {
            yMax = std::max(yMax, pc.young);
            gMax = std::max(gMax, pc.gamma);
        }
        s.polygonStepFactor = std::min(1.0, 0.2 / gMax);
        s.polygonStep = kPi / 10 * std::sqrt(mPoly / yMax) * s.polygonStepFactor;
        const double tcPoly = kPi * std::sqrt(mPoly / yMax);
        if (polygons == all.count || !(tcPoly >= s.contactTime)) {
            s.contactTime = polygons == all.count ? tcPoly : std::min(s.contactTime, tcPoly);
            s.contactTimeNote = "polygons: t_c ~ pi sqrt(m_min/Y) of the lightest polygon";
        }
    }
    return s;
}

template ContactSetup buildContactSetup<2>(const ContactModelDef&, const std::vector<MaterialProps>&,
                                           const std::vector<MaterialStats>&, const std::vector<bool>&,
                                           const std::vector<bool>&);
template ContactSetup buildContactSetup<3>(const ContactModelDef&, const std::vector<MaterialProps>&,
                                           const std::vector<MaterialStats>&, const std::vector<bool>&,
                                           const std::vector<bool>&);

}  // namespace haet
