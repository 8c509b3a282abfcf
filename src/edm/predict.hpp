#pragma once
// Event-time predictions of the event-driven engine as pure functions (docs/physics.md D.2, D.3, D.4, D.6).
//
// Every prediction reduces to one question: given a "gap" f(t) that is >= 0 while the state is valid
// (distance minus contact distance, height above a wall, distance to a cell face), when does f first fall
// through zero? For ballistic relative motion f is the quadratic f0 + f1 t + f2 t^2/2; only a moving particle
// against a fixed sphere under gravity gives a quartic (firstRootQuartic).
//
// Invalid states (docs/physics.md D.6): round-off can leave f0 slightly negative (overlap, beyond a wall, outside a
// cell). Such a state is given a dynamics instead of an error: if f decreases now, the event is now (t = 0);
// if it increases (receding), there is no event until f has come back and falls again. The smaller root of
// the quadratic (the "exit" time of an overlapping pair) is never used.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/vec.hpp"

namespace haet {

/// "No event": the time of a prediction that never happens.
inline constexpr double kNever = std::numeric_limits<double>::infinity();

/// First time t >= 0 at which f(t) = f0 + f1 t + f2 t^2 / 2 falls through zero, kNever if never
/// (docs/physics.md D.3, DynamO's root selection in stable form: no cancellation in any branch).
///  * f2 < 0 (accelerating towards the face, e.g. a floor under gravity): there is always an event.
///  * f2 > 0 (accelerating away, e.g. a ceiling; or a pair, f2 = 2|v|^2): only if approaching now.
///  * f2 = 0: only if f1 < 0.
/// f0 < 0 (invalid state) with f1 < 0 gives 0; with f2 < 0 and the parabola's top below zero, the time of the
/// top (when the state starts to get worse again). Always inlined: it sits in the innermost loop of the event
/// scans, and GCC stops inlining it once it has many callers (a call costs more than its body).
[[gnu::always_inline]] inline double firstRootFalling(double f0, double f1, double f2) {
    if (f2 < 0) {
        const double arg = f1 * f1 - 2 * f2 * f0;
        if (arg <= 0) return std::max(0.0, -f1 / f2);
        // f1 > 0: going away first; the root on the way back is (-f1 - sqrt)/f2 (both terms add: stable).
        if (f1 > 0) return std::max(0.0, (-f1 - std::sqrt(arg)) / f2);
        return std::max(0.0, 2 * f0 / (-f1 + std::sqrt(arg)));
    }
    if (f2 > 0) {
        if (f1 >= 0) return kNever;
        const double arg = f1 * f1 - 2 * f2 * f0;
        if (arg <= 0) return kNever;
        return std::max(0.0, 2 * f0 / (-f1 + std::sqrt(arg)));
    }
    if (f1 < 0) return std::max(0.0, -f0 / f1);
    return kNever;
}

/// Collision time of two spheres (disks) from their relative position r = r_i - r_j and relative velocity
/// v = v_i - v_j at a common time, sigma = a_i + a_j (docs/physics.md D.2). Under a common gravity the relative
/// motion is ballistic, so this holds with gravity too. Returns the time after that common time, or kNever.
/// Symmetric: (r, v) and (-r, -v) give bit-identical results.
template <int D>
double pairCollisionTime(const Vec<D>& r, const Vec<D>& v, double sigma) {
    const double b = dot(r, v);
    if (b >= 0) return kNever;  // receding (even when overlapping: D.6)
    const double c = norm2(r) - sigma * sigma;
    const double v2 = norm2(v);
    // f(t) = |r + v t|^2 - sigma^2 = c + 2 b t + v2 t^2: f0 = c, f1 = 2 b, f2 = 2 v2.
    return firstRootFalling(c, 2 * b, 2 * v2);
}

/// Time until a particle of radius a hits a plane wall (docs/physics.md D.3). All vectors at a common time:
/// x, v: particle position and velocity; p, u: a point of the plane and the plane's velocity; n: unit normal
/// into the domain; g: the particle's acceleration (gravity). Returns the time after that common time, or kNever.
template <int D>
double wallCollisionTime(const Vec<D>& x, const Vec<D>& v, double a, const Vec<D>& p, const Vec<D>& u, const Vec<D>& n,
                         const Vec<D>& g) {
    return firstRootFalling(dot(n, x - p) - a, dot(n, v - u), dot(n, g));
}

/// Time until a coordinate x (velocity v, acceleration g) leaves the interval [lo, hi] (docs/physics.md D.4),
/// and through which face: up = true for hi. Infinite bounds are allowed (outermost cells of open axes).
/// Under gravity the particle may turn around inside the interval; the quadratic covers that.
struct CellExit {
    double time = kNever;
    bool up = false;
};
inline CellExit cellExitTime(double x, double v, double g, double lo, double hi) {
    CellExit r;
    if (hi < kNever) {  // f = hi - x(t): f0 = hi - x, f1 = -v, f2 = -g
        r.time = firstRootFalling(hi - x, -v, -g);
        r.up = true;
    }
    if (lo > -kNever) {  // f = x(t) - lo
        const double t = firstRootFalling(x - lo, v, g);
        if (t < r.time) {
            r.time = t;
            r.up = false;
        }
    }
    return r;
}

namespace detail {
inline double polyEval(const double* c, int deg, double t) {
    double s = c[deg];
    for (int k = deg - 1; k >= 0; --k) s = s * t + c[k];
    return s;
}
/// Bisection for a sign change of p (degree deg) in [a, b], where p(a) and p(b) have opposite signs
/// (or p(b) == 0). Returns the point where the bracket can shrink no further.
inline double bisect(const double* c, int deg, double a, double b) {
    const bool aPositive = polyEval(c, deg, a) > 0;
    for (int it = 0; it < 200; ++it) {
        const double m = 0.5 * (a + b);
        if (!(m > a && m < b)) break;
        if ((polyEval(c, deg, m) > 0) == aPositive)
            a = m;
        else
            b = m;
    }
    return b;
}
/// Sorted roots of c0 + c1 t + c2 t^2 in (lo, hi), written to out; returns the count (0..2).
inline int quadraticRootsIn(double c0, double c1, double c2, double lo, double hi, double out[2]) {
    int n = 0;
    double r[2];
    if (c2 == 0) {
        if (c1 != 0) r[n++] = -c0 / c1;
    } else {
        const double disc = c1 * c1 - 4 * c2 * c0;
        if (disc >= 0) {
            const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
            if (q != 0) {
                r[n++] = q / c2;
                r[n++] = c0 / q;
            } else {
                r[n++] = 0;  // c0 = c1 = 0
            }
        }
    }
    if (n == 2 && r[1] < r[0]) std::swap(r[0], r[1]);
    int m = 0;
    for (int k = 0; k < n; ++k)
        if (r[k] > lo && r[k] < hi) out[m++] = r[k];
    return m;
}
}  // namespace detail

/// First time t in [0, tMax] at which the quartic f(t) = c[0] + c[1] t + c[2] t^2 + c[3] t^3 + c[4] t^4 falls
/// through zero, with the same invalid-state rule as firstRootFalling (f <= 0 and decreasing: now). kNever if
/// none in [0, tMax]. Used for a moving particle against a fixed (frozen) sphere under gravity, where the
/// relative motion is not ballistic. Method: the critical points of f (roots of the cubic f', found by
/// bisection between the roots of the quadratic f'') split [0, tMax] into monotone pieces; the first
/// decreasing piece that reaches zero holds the root, found by bisection to the last bit. Deterministic.
inline double firstRootQuartic(const double c[5], double tMax) {
    using detail::polyEval;
    if (!(tMax > 0)) tMax = 0;
    const double d1[4] = {c[1], 2 * c[2], 3 * c[3], 4 * c[4]};  // f'
    const double d2[3] = {2 * c[2], 6 * c[3], 12 * c[4]};       // f''
    // Monotone pieces of f' on [0, tMax]: split at the roots of f''.
    double cuts2[2];
    const int n2 = detail::quadraticRootsIn(d2[0], d2[1], d2[2], 0.0, tMax, cuts2);
    double pts2[4];
    int np2 = 0;
    pts2[np2++] = 0;
    for (int k = 0; k < n2; ++k) pts2[np2++] = cuts2[k];
    pts2[np2++] = tMax;
    // Critical points of f (sign changes of f') in (0, tMax).
    double pts[6];
    int np = 0;
    pts[np++] = 0;
    for (int k = 0; k + 1 < np2; ++k) {
        const double a = pts2[k], b = pts2[k + 1];
        const double fa = polyEval(d1, 3, a), fb = polyEval(d1, 3, b);
        if ((fa > 0) != (fb > 0)) {
            const double r = detail::bisect(d1, 3, a, b);
            if (r > pts[np - 1] && r < tMax) pts[np++] = r;
        }
    }
    pts[np++] = tMax;
    // First decreasing piece that reaches zero.
    for (int k = 0; k + 1 < np; ++k) {
        const double a = pts[k], b = pts[k + 1];
        const double fa = polyEval(c, 4, a), fb = polyEval(c, 4, b);
        const bool decreasing = (fb < fa) || (fa == fb && polyEval(d1, 3, a) < 0);
        if (!decreasing) continue;
        if (fa <= 0) return a;  // invalid state, getting worse: now
        if (fb <= 0) return detail::bisect(c, 4, a, b);
    }
    return kNever;
}

/// Collision time of a moving sphere (relative position r = x - x_fixed, velocity v, acceleration g) with a
/// fixed sphere (a frozen particle), sigma = sum of radii, looking no further than tMax. Under gravity the
/// gap |r + v t + g t^2/2|^2 - sigma^2 is a quartic; without gravity this is pairCollisionTime.
template <int D>
double fixedSphereCollisionTime(const Vec<D>& r, const Vec<D>& v, const Vec<D>& g, double sigma, double tMax) {
    const double g2 = norm2(g);
    if (g2 == 0) return pairCollisionTime(r, v, sigma);
    const double c[5] = {norm2(r) - sigma * sigma, 2 * dot(r, v), norm2(v) + dot(r, g), dot(v, g), 0.25 * g2};
    // Beyond the Cauchy bound of the roots there is no sign change left.
    double bound = 0;
    for (int k = 0; k < 4; ++k) bound = std::max(bound, std::abs(c[k] / c[4]));
    return firstRootQuartic(c, std::min(tMax, 1 + bound));
}

}  // namespace haet
