#pragma once
// Root isolation for the polynomials of degree <= 4 of the mesh predictions (docs/physics.md D.8): the first time a
// gap f(t) = c0 + c1 t + c2 t^2 + c3 t^3 + c4 t^4 falls through zero, with a test of each candidate.
//
// Method (the derivative cascade, as in Collins & Loos's isolation by the derivative's roots): the sign changes of
// a polynomial p in [lo, hi] are isolated by those of p', found the same way, down to a linear p^(n-1); between two
// consecutive critical points p is monotone, so it has at most one sign change there, found by bracketed false
// position with the Anderson-Bjorck step (every fourth step a bisection, so the bracket at least halves every four
// evaluations) until the bracket is two adjacent doubles. No closed-form root is used, so nothing cancels and no
// leading coefficient is divided by: a vanishing c4 (no gravity, gravity along an edge) or c3 only lowers the degree,
// and a grazing double root is a critical point where the sign of f decides. Every branch is a comparison of
// evaluated signs, so the result is deterministic. Accuracy: the returned time is within one double of a sign change
// of f as evaluated by Horner's rule, whose error is at most about 2 n eps sum |c_k| t^k (Higham 2002, 5.1).
#include <algorithm>
#include <cmath>

#include "edm/predict.hpp"

namespace haet::roots {

/// p(t) with coefficients c[0..n], lowest first (Horner).
inline double eval(const double* c, int n, double t) {
    double s = c[n];
    for (int k = n - 1; k >= 0; --k) s = s * t + c[k];
    return s;
}

/// The point of [a, b] where p (degree n) leaves the sign class of pa for that of pb, classes "> 0" and "<= 0":
/// the smallest double found in pb's class, with the double before it in pa's class (pa and pb of different
/// classes). Bracketed false position, Anderson-Bjorck (1973), with a bisection every fourth step.
inline double signChange(const double* c, int n, double a, double b, double pa, double pb) {
    const bool aPositive = pa > 0;
    int side = 0;  // which end moved last: -1 a, +1 b
    for (int it = 0; it < 400; ++it) {
        double t = (it % 4 == 3) ? 0.5 * (a + b) : (a * pb - b * pa) / (pb - pa);
        if (!(t > a && t < b)) t = 0.5 * (a + b);
        if (!(t > a && t < b)) break;  // a and b are adjacent doubles
        const double pt = eval(c, n, t);
        if ((pt > 0) == aPositive) {
            if (side == -1) {  // a moved twice: scale the value kept at b (Anderson-Bjorck)
                const double m = 1 - pt / pa;
                pb *= m > 0 ? m : 0.5;
            }
            a = t;
            pa = pt;
            side = -1;
        } else {
            if (side == +1) {
                const double m = 1 - pt / pb;
                pa *= m > 0 ? m : 0.5;
            }
            b = t;
            pb = pt;
            side = +1;
        }
    }
    return b;
}

/// The points in (lo, hi) where p (degree <= N, coefficients c[0..N]) changes sign class, increasing; returns
/// their count (at most N). Found by the cascade: the sign changes of p' split [lo, hi] into monotone pieces.
/// An exact zero of p at a piece's end may be reported twice or as a change where p only touches zero: the
/// caller uses them as cuts into monotone pieces, which extra cuts do not spoil.
template <int N>
int signChanges(const double* c, double lo, double hi, double* out) {
    if constexpr (N == 0) {
        return 0;
    } else {
        double cuts[N + 1];
        int nc = 0;
        cuts[nc++] = lo;
        if constexpr (N >= 2) {
            double d[N];
            for (int k = 0; k < N; ++k) d[k] = (k + 1) * c[k + 1];
            nc += signChanges<N - 1>(d, lo, hi, cuts + 1);
        }
        cuts[nc++] = hi;
        int m = 0;
        double pa = eval(c, N, lo);
        for (int k = 0; k + 1 < nc; ++k) {
            const double b = cuts[k + 1], pb = eval(c, N, b);
            if ((pa > 0) != (pb > 0)) {
                const double r = signChange(c, N, cuts[k], b, pa, pb);
                if (r < hi && (m == 0 || r > out[m - 1])) out[m++] = r;
            }
            pa = pb;
        }
        return m;
    }
}

/// Fujiwara's bound on the moduli of the roots of c[0..n] (c[n] != 0): 2 max |c_k / c_n|^(1/(n-k)), the last
/// term with c_0 / 2. Scale-covariant: it moves with the time unit, unlike Cauchy's 1 + max |c_k / c_n|.
inline double rootBound(const double* c, int n) {
    double b = 0;
    for (int k = 0; k < n; ++k) {
        double q = std::abs(c[k] / c[n]);
        if (k == 0) q *= 0.5;
        const int e = n - k;
        b = std::max(b, e == 1 ? q : e == 2 ? std::sqrt(q) : e == 3 ? std::cbrt(q) : std::sqrt(std::sqrt(q)));
    }
    return 2 * b;
}

/// The polynomial's degree: the highest k with c[k] != 0 (0 for a constant, also for 0).
inline int degree(const double c[5]) {
    int n = 4;
    while (n > 0 && c[n] == 0) --n;
    return n;
}

namespace detail {
template <int N, class Accept>
double firstFalling(const double* c, double T, Accept& accept) {
    // Critical points: the sign changes of f' in (0, T); f is monotone between them.
    double pts[N + 1];
    int np = 0;
    pts[np++] = 0;
    if constexpr (N >= 1) {
        double d[N];
        for (int k = 0; k < N; ++k) d[k] = (k + 1) * c[k + 1];
        np += signChanges<N - 1>(d, 0.0, T, pts + 1);
    }
    pts[np++] = T;
    double fa = eval(c, N, 0.0);
    for (int k = 0; k + 1 < np; ++k) {
        const double a = pts[k], b = pts[k + 1], fb = eval(c, N, b);
        bool decreasing = fb < fa;
        if (fb == fa && N >= 1) {  // flat to rounding over the piece: the slope at its start decides
            double d[N];
            for (int j = 0; j < N; ++j) d[j] = (j + 1) * c[j + 1];
            decreasing = eval(d, N - 1, a) < 0;
        }
        if (decreasing) {
            // f <= 0 already at the piece's start (an invalid state, D.6, or a top below zero): the event is at
            // the start, when the state begins to get worse; else at the sign change, if the piece reaches zero.
            if (fa <= 0) {
                if (accept(a)) return a;
            } else if (fb <= 0) {
                const double t = signChange(c, N, a, b, fa, fb);
                if (accept(t)) return t;
            }
        }
        fa = fb;
    }
    return kNever;
}
}  // namespace detail

/// The first time t in [0, tMax] at which the gap f(t) = c[0] + ... + c[4] t^4 falls through zero and accept(t)
/// holds, or kNever. The candidates, in increasing time, are the starts of the pieces where f decreases from
/// f <= 0 (the invalid-state rule of docs/physics.md D.6: now when f <= 0 and decreasing; the top of the curve
/// when f <= 0 is receding but turns back before it is out) and the sign changes of the pieces where f falls from
/// > 0 to <= 0. accept(t) decides whether a candidate counts (a mesh feature: whether the contact point lies in the
/// feature at t); a rejected candidate is skipped for the next. With tMax = kNever the search ends at the bound of
/// the roots of f and f' (no candidate lies beyond), cut at 1e64 (the powers t^4 stay finite).
template <class Accept>
double firstFalling(const double c[5], double tMax, Accept&& accept) {
    const int n = degree(c);
    double T = tMax > 0 ? tMax : 0.0;
    // Quick exit: on [0, T], f >= c0 + sum_k min(c_k, 0) T^k; if that is > 0, f never reaches zero. Most features
    // far from a particle end here, before any root is isolated.
    double low = c[0], tk = 1;
    for (int k = 1; k <= n; ++k) {
        tk *= T;
        if (c[k] < 0) low += c[k] * tk;
    }
    if (low > 0) return kNever;
    if (n >= 1 && !(T < 1e64)) {
        // No horizon: no candidate lies beyond the roots of f and f'. Fujiwara's bound is attained (a linear f:
        // the bound is its root), so the search runs a little past it.
        const double d[4] = {c[1], 2 * c[2], 3 * c[3], 4 * c[4]};
        T = std::min(T, 1.5 * std::max(rootBound(c, n), n >= 2 ? rootBound(d, n - 1) : 0.0));
    }
    T = std::min(T, 1e64);
    switch (n) {
        case 0:
            return kNever;  // constant: never decreasing
        case 1:
            return detail::firstFalling<1>(c, T, accept);
        case 2:
            return detail::firstFalling<2>(c, T, accept);
        case 3:
            return detail::firstFalling<3>(c, T, accept);
        default:
            return detail::firstFalling<4>(c, T, accept);
    }
}

}  // namespace haet::roots
