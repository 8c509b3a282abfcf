#include "tdm/integrators.hpp"

#include <cstring>
#include <utility>

#include "core/lane_shuffle.hpp"

namespace haet {

template <class T>
static void permuteVec(std::vector<T>& a, const std::vector<std::uint32_t>& order) {
    if (a.empty()) return;
    std::vector<T> tmp(a);  // entries beyond order.size() stay
    for (std::size_t k = 0; k < order.size(); ++k) tmp[k] = a[order[k]];
    a.swap(tmp);
}

/// a[k] = old a[from[k]]; entries for new particles (from[k] = kNew) are value-initialised.
template <class T>
static void remapVec(std::vector<T>& a, const std::vector<std::uint32_t>& from) {
    constexpr std::uint32_t kNew = 0xFFFFFFFFu;
    std::vector<T> tmp(from.size(), T{});
    for (std::size_t k = 0; k < from.size(); ++k)
        if (from[k] != kNew && from[k] < a.size()) tmp[k] = a[from[k]];
    a.swap(tmp);
}

/// Restarts every new particle of a remap.
template <class I, class P>
static void restartNew(I& integ, const P& p, const std::vector<std::uint32_t>& from, double dt) {
    for (std::size_t k = 0; k < from.size(); ++k)
        if (from[k] == 0xFFFFFFFFu) integ.restart(p, k, dt);
}

// ---- velocity Verlet ----

// The state is the store's: nothing to start, reorder or restart.
template <int D>
void VelocityVerlet<D>::start(const Particles<D>&, double) {}

template <int D>
typename VelocityVerlet<D>::Predictor VelocityVerlet<D>::predictor(Particles<D>& p, double dt, StepMotion<D>& m,
                                                                   const Vec<D>* ref, double limit2) {
    const std::size_t n = p.tdmCount();
    m.v.resize(n);
    m.w.resize(n);
    Ang<D>* ang = p.angle.empty() ? nullptr : p.angle.data();
    return {p.x.data(),
            p.v.data(),
            ang,
            p.w.data(),
            m.v.data(),
            m.w.data(),
            p.f.data(),
            p.torque.data(),
            p.invMass.data(),
            p.invInertia.data(),
            p.flags.data(),
            ref,
            dt,
            limit2};
}

template <int D>
bool VelocityVerlet<D>::predict(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2) {
    const std::size_t n = p.tdmCount();
    const Predictor pr = predictor(p, dt, m, ref, limit2);
    bool moved = false;
    // The pointers as restrict locals: stores through them cannot change the pointers, so the loop stays tight.
    Vec<D>* __restrict x = pr.x;
    Vec<D>* __restrict v = pr.v;
    Ang<D>* __restrict ang = pr.ang;
    Ang<D>* __restrict w = pr.w;
    Vec<D>* __restrict mv = pr.mv;
    Ang<D>* __restrict mw = pr.mw;
    const Vec<D>* __restrict f = pr.f;
    const Ang<D>* __restrict torque = pr.torque;
    const double* __restrict invMass = pr.invMass;
    const double* __restrict invInertia = pr.invInertia;
    const std::uint8_t* __restrict flags = pr.flags;
#pragma omp parallel for schedule(static) reduction(|| : moved) if (n >= kParallelMin)
    for (std::size_t i = 0; i < n; ++i)
        moved |= Predictor::one(i, x, v, ang, w, mv, mw, f, torque, invMass, invInertia, flags, ref, dt, limit2);
    return moved;
}

namespace {

using V4 = double __attribute__((vector_size(32)));
using V4i = std::int64_t __attribute__((vector_size(32)));

inline V4 load4(const double* p) {
    V4 r;
    std::memcpy(&r, p, sizeof r);
    return r;
}
inline void store4(double* p, V4 v) { std::memcpy(p, &v, sizeof v); }
inline V4 splat(double s) { return V4{s, s, s, s}; }

/// Four particles with W components each fill W registers; element k of register R belongs to particle (4R + k) / W:
/// the four particles' values v spread over register R's elements.
template <int W, int R, class V>
[[gnu::always_inline]] inline V spread(V v) {
    return shuffleLanes<(4 * R) / W, (4 * R + 1) / W, (4 * R + 2) / W, (4 * R + 3) / W>(v);
}

/// Velocity Verlet on four particles' W-component quantity (position, velocity, mean velocity, force; or angle,
/// spin, ...): Corrector then Predictor element by element; frozen particles (fz) keep everything and get mv = v.
/// With ref (positions), sq gets the squares of (new position - ref) element by element. Without kPos only the
/// velocities (the spin of a particle whose orientation is not kept).
template <int W, bool kAnyFrozen, bool kDrift = false, bool kPos = true>
[[gnu::always_inline]] inline void correctPredict4(const double* f, double* x, double* v, double* mv, V4 scale, V4i fz,
                                                   double dt, double h, double h2, const double* ref = nullptr,
                                                   V4* sq = nullptr) {
    [&]<int... R>(std::integer_sequence<int, R...>) {
        (
            [&] {
                const V4 s = spread<W, R>(scale);
                const V4 mv0 = load4(mv + 4 * R);
                const V4 a = load4(f + 4 * R) * s;
                const V4 vi = mv0 + a * splat(h);   // the corrector: v(t + dt)
                V4 mvn = vi + a * splat(0.5 * dt);  // the predictor of the next step
                V4 vn = vi + a * splat(dt);
                if constexpr (kAnyFrozen) {
                    const V4i z = spread<W, R>(fz);
                    const V4 v0 = load4(v + 4 * R);
                    vn = z ? v0 : vn;
                    mvn = z ? v0 : mvn;
                }
                if constexpr (kPos) {
                    const V4 x0 = load4(x + 4 * R);
                    V4 xn = x0 + (vi * splat(dt) + a * splat(h2));
                    if constexpr (kAnyFrozen) xn = spread<W, R>(fz) ? x0 : xn;
                    store4(x + 4 * R, xn);
                    if constexpr (kDrift) {
                        const V4 d = xn - load4(ref + 4 * R);
                        sq[R] = d * d;
                    }
                }
                store4(v + 4 * R, vn);
                store4(mv + 4 * R, mvn);
            }(),
            ...);
    }
    (std::make_integer_sequence<int, W>{});
}

/// The squared lengths of four particles' D-vectors from the squares of their components (in D registers, the
/// particles' components one after the other), summed left to right as norm2().
template <int D>
[[gnu::always_inline]] inline V4 norms4(const V4* sq) {
    if constexpr (D == 2) {
        return shuffleLanes<0, 2, 4, 6>(sq[0], sq[1]) + shuffleLanes<1, 3, 5, 7>(sq[0], sq[1]);
    } else {
        static_assert(D == 3);
        const V4 x = shuffleLanes<0, 1, 2, 5>(shuffleLanes<0, 3, 6, 6>(sq[0], sq[1]), sq[2]);
        const V4 y = shuffleLanes<0, 1, 2, 6>(shuffleLanes<1, 4, 7, 7>(sq[0], sq[1]), sq[2]);
        const V4 z = shuffleLanes<0, 1, 4, 7>(shuffleLanes<2, 5, 5, 5>(sq[0], sq[1]), sq[2]);
        return (x + y) + z;
    }
}

}  // namespace

template <int D>
void VelocityVerlet<D>::CorrectPredict::finishBlock(std::size_t b, std::size_t e) const {
    constexpr int A = kAngDim<D>;
    const Predictor& pr = predict;
    const double dt = pr.dt, h2 = 0.5 * dt * dt;
    bool far = false;
    std::size_t i = b;
    // Four particles at a time, with (kAnyFrozen) or without the frozen ones blended back, with (kAng) or without
    // orientations.
    auto fours = [&]<bool kAng>() {
        auto four = [&]<bool kAnyFrozen>(V4i fz) {
            V4 sq[D];
            correctPredict4<D, kAnyFrozen, true>(pr.f[i].c.data(), pr.x[i].c.data(), pr.v[i].c.data(),
                                                 pr.mv[i].c.data(), load4(correct.invMass + i), fz, dt, correct.h, h2,
                                                 pr.ref[i].c.data(), sq);
            correctPredict4<A, kAnyFrozen, false, kAng>(pr.torque[i].c.data(), kAng ? pr.ang[i].c.data() : nullptr,
                                                        pr.w[i].c.data(), pr.mw[i].c.data(),
                                                        load4(correct.invInertia + i), fz, dt, correct.h, h2);
            const V4i beyond = (norms4<D>(sq) > splat(pr.limit2)) & ~fz;
            far |= (beyond[0] | beyond[1] | beyond[2] | beyond[3]) != 0;
        };
        for (; i + 4 <= e; i += 4) {
            const std::uint8_t* fl = pr.flags + i;
            std::uint32_t fl4;
            std::memcpy(&fl4, fl, sizeof fl4);
            if ((fl4 & 0x01010101u * kFrozen) == 0) {
                four.template operator()<false>(V4i{0, 0, 0, 0});
            } else {
                four.template operator()<true>(V4i{-std::int64_t(fl[0] & kFrozen), -std::int64_t(fl[1] & kFrozen),
                                                   -std::int64_t(fl[2] & kFrozen), -std::int64_t(fl[3] & kFrozen)});
            }
        }
    };
    if (pr.ang)
        fours.template operator()<true>();
    else
        fours.template operator()<false>();
    for (; i < e; ++i) {
        correct(i, pr.f[i], pr.torque[i]);
        far |= pr(i);
    }
    if (far) moved->store(true, std::memory_order_relaxed);
}

template <int D>
void VelocityVerlet<D>::correct(Particles<D>& p, double dt, const StepMotion<D>& m) {
    const std::size_t n = p.tdmCount();
    const Corrector c = corrector(p, dt, m);
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
    for (std::size_t i = 0; i < n; ++i) c(i, p.f[i], p.torque[i]);
}

template <int D>
void VelocityVerlet<D>::permute(const std::vector<std::uint32_t>&) {}

template <int D>
void VelocityVerlet<D>::remap(const Particles<D>&, const std::vector<std::uint32_t>&, double) {}

template <int D>
void VelocityVerlet<D>::restart(const Particles<D>&, std::size_t, double) {}

// ---- Gear ----

template <int D>
void Gear5<D>::start(const Particles<D>& p, double dt) {
    const std::size_t n = p.tdmCount();
    for (auto& a : y_) a.assign(n, Vec<D>::zero());
    for (auto& a : r_) a.assign(n, Ang<D>::zero());
    for (std::size_t i = 0; i < n; ++i) restart(p, i, dt);
}

template <int D>
void Gear5<D>::remap(const Particles<D>& p, const std::vector<std::uint32_t>& from, double dt) {
    for (auto& a : y_) remapVec(a, from);
    for (auto& a : r_) remapVec(a, from);
    restartNew(*this, p, from, dt);
}

template <int D>
void Gear5<D>::restart(const Particles<D>& p, std::size_t i, double dt) {
    if (y_[0].size() < p.tdmCount()) {
        for (auto& a : y_) a.resize(p.tdmCount(), Vec<D>::zero());
        for (auto& a : r_) a.resize(p.tdmCount(), Ang<D>::zero());
    }
    // Higher derivatives from the current force with zero jerk: exact for free flight under gravity, and the
    // best local guess for a particle not yet in contact (docs/physics.md F.1).
    const double h2 = 0.5 * dt * dt;
    y_[0][i] = p.f[i] * (p.invMass[i] * h2);
    r_[0][i] = p.torque[i] * (p.invInertia[i] * h2);
    for (int k = 1; k < 4; ++k) {
        y_[k][i] = Vec<D>::zero();
        r_[k][i] = Ang<D>::zero();
    }
}

template <int D>
void Gear5<D>::setDerivatives(std::size_t i, const Vec<D>& a, const Vec<D>& j3, const Vec<D>& j4, const Vec<D>& j5,
                              double dt) {
    const double h2 = dt * dt / 2, h3 = h2 * dt / 3, h4 = h3 * dt / 4, h5 = h4 * dt / 5;
    y_[0][i] = a * h2;
    y_[1][i] = j3 * h3;
    y_[2][i] = j4 * h4;
    y_[3][i] = j5 * h5;
}

namespace {
/// Pascal-triangle predictor on (x, y1 = v dt, y2..y5).
template <int N>
inline void gearPredict(Vec<N>& x, Vec<N>& v, Vec<N>& y2, Vec<N>& y3, Vec<N>& y4, Vec<N>& y5, double dt,
                        Vec<N>& stepVel) {
    Vec<N> y1 = v * dt;
    const Vec<N> dx = y1 + y2 + y3 + y4 + y5;
    stepVel = dx * (1.0 / dt);
    x += dx;
    y1 += y2 * 2.0 + y3 * 3.0 + y4 * 4.0 + y5 * 5.0;
    y2 += y3 * 3.0 + y4 * 6.0 + y5 * 10.0;
    y3 += y4 * 4.0 + y5 * 10.0;
    y4 += y5 * 5.0;
    v = y1 * (1.0 / dt);
}

template <int N>
inline void gearCorrect(Vec<N>& x, Vec<N>& v, Vec<N>& y2, Vec<N>& y3, Vec<N>& y4, Vec<N>& y5, const Vec<N>& acc,
                        double dt) {
    const Vec<N> delta = acc * (0.5 * dt * dt) - y2;
    const double* c = Gear5<3>::kC;
    x += delta * c[0];
    v += delta * (c[1] / dt);
    y2 += delta * c[2];
    y3 += delta * c[3];
    y4 += delta * c[4];
    y5 += delta * c[5];
}
}  // namespace

template <int D>
bool Gear5<D>::predict(Particles<D>& p, double dt, StepMotion<D>& m, const Vec<D>* ref, double limit2) {
    const std::size_t n = p.tdmCount();
    m.v.resize(n);
    m.w.resize(n);
    bool moved = false;
    const bool angles = !p.angle.empty();
#pragma omp parallel for schedule(static) reduction(|| : moved) if (n >= kParallelMin)
    for (std::size_t i = 0; i < n; ++i) {
        if (p.flags[i] & kFrozen) {
            m.v[i] = p.v[i];
            m.w[i] = p.w[i];
            continue;
        }
        gearPredict(p.x[i], p.v[i], y_[0][i], y_[1][i], y_[2][i], y_[3][i], dt, m.v[i]);
        Ang<D> turned{};  // the orientation when kept, else a stand-in the predictor moves
        gearPredict(angles ? p.angle[i] : turned, p.w[i], r_[0][i], r_[1][i], r_[2][i], r_[3][i], dt, m.w[i]);
        moved |= norm2(p.x[i] - ref[i]) > limit2;
    }
    return moved;
}

template <int D>
void Gear5<D>::correct(Particles<D>& p, double dt, const StepMotion<D>&) {
    const std::size_t n = p.tdmCount();
    const bool angles = !p.angle.empty();
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
    for (std::size_t i = 0; i < n; ++i) {
        if (p.flags[i] & kFrozen) continue;
        gearCorrect(p.x[i], p.v[i], y_[0][i], y_[1][i], y_[2][i], y_[3][i], p.f[i] * p.invMass[i], dt);
        Ang<D> turned{};
        gearCorrect(angles ? p.angle[i] : turned, p.w[i], r_[0][i], r_[1][i], r_[2][i], r_[3][i],
                    p.torque[i] * p.invInertia[i], dt);
    }
}

template <int D>
void Gear5<D>::permute(const std::vector<std::uint32_t>& order) {
    for (auto& a : y_) permuteVec(a, order);
    for (auto& a : r_) permuteVec(a, order);
}

template class VelocityVerlet<2>;
template class VelocityVerlet<3>;
template class Gear5<2>;
template class Gear5<3>;

}  // namespace haet
