#pragma once
// The batched candidate scan of the event-driven engine (docs/edm.md, "Four candidates at a time"): the collision
// times of four candidate partners side by side in lanes (core/lanes.hpp, core/lanes_scan.hpp), with the arithmetic
// of the scalar Slots::candidateTime lane by lane. Both broad phases (the event grid and the neighbour shells) feed
// it batches of four.
#include <cstdint>

#include "core/lanes.hpp"
#include "core/lanes_scan.hpp"
#include "edm/slots.hpp"

namespace haet::edm {

/// The scanning slot's state and the constants, one value per lane.
template <int D>
struct ScanState {
    using V = Lanes::Values;
    V x[D], v[D], gh[D], g[D], len[D], t, r;
};

/// Four candidates: their slots, packed wraps and image bases (the image shift in box lengths is base +
/// wrapsOf(wrap)). A batch whose wraps all equal the scan's plain wraps and whose bases are all its plain base
/// needs no shift.
template <int D>
struct Batch {
    using Shift = typename Slots<D>::Shift;
    const std::uint32_t* j;
    const std::uint32_t* wrap;
    const Shift* const* base;
};

template <int D>
ScanState<D> scanState(const Slots<D>& sl, const typename Slots<D>::Hot& hs) {
    ScanState<D> sc;
    for (int k = 0; k < D; ++k) {
        sc.x[k] = Lanes(hs.x[k]).v;
        sc.v[k] = Lanes(hs.v[k]).v;
        sc.gh[k] = Lanes(0.5 * sl.g[k]).v;
        sc.g[k] = Lanes(sl.g[k]).v;
        sc.len[k] = Lanes(sl.boxLen[k]).v;
    }
    sc.t = Lanes(hs.t).v;
    sc.r = Lanes(hs.r).v;
    return sc;
}

// Four candidates side by side: the arithmetic of candidateTime lane by lane (the same correctly rounded operations in
// the same order, no fused multiply-add), so a lane gives the bits candidateTime gives. Both states are extrapolated
// to the later clock tr, one of them by zero, which leaves it unchanged (x + (v + g/2 0) 0 = x), as candidateTime's
// two branches do. The tests a lane can fail cheaply (receding, b >= 0; root beyond the best event so far by the
// lower bound c / (-2 b)) are taken for all four at once; most batches end there. A lane that needs more than the
// quadratic (a frozen partner, a root before now, no relative speed) goes to candidateTime. The lanes are then
// offered to best in order, as the scalar loop would: the result is the minimum of (time, code), which does not
// depend on the order, and a skip against the best time before the batch (not the best within it) only skips
// less. best (and bestJ, the slot of a pair event in it) updated as candidateTime and Candidate::better, one
// candidate after the other, would.
template <int D>
[[gnu::always_inline]] inline void candidates4(const Slots<D>& sl, const ScanState<D>& sc,
                                               const typename Slots<D>::Hot& hs, std::uint32_t s, const Batch<D>& bt,
                                               std::uint32_t wsPacked, const typename Slots<D>::Shift* plainBase,
                                               double now, Candidate& best, std::uint32_t& bestJ) {
    using V = Lanes::Values;
    using Shift = typename Slots<D>::Shift;
    const auto& hot = sl.hot;
    const std::uint32_t* j = bt.j;
    // Plain: no candidate needs an image shift (the same wraps as s, a cell that crosses no box face): most batches.
    const bool plain = fourMatch(bt.wrap, wsPacked, reinterpret_cast<const void* const*>(bt.base), plainBase);
    V X[D], Vv[D], T, R;
    if constexpr (D == 3) {
        Lanes a[4], b[4];
        transpose4(hot[j[0]].x.c.data(), hot[j[1]].x.c.data(), hot[j[2]].x.c.data(), hot[j[3]].x.c.data(), a);
        transpose4(hot[j[0]].v.c.data(), hot[j[1]].v.c.data(), hot[j[2]].v.c.data(), hot[j[3]].v.c.data(), b);
        for (int k = 0; k < 3; ++k) {
            X[k] = a[k].v;
            Vv[k] = b[k].v;
        }
        T = a[3].v;
        R = b[3].v;
    } else {
        // 2D: a record is (x0, x1, t, v0, v1, r), 48 bytes, 16-aligned.
        V rows[6];
        transpose4x6(hot[j[0]].x.c.data(), hot[j[1]].x.c.data(), hot[j[2]].x.c.data(), hot[j[3]].x.c.data(), rows);
        X[0] = rows[0];
        X[1] = rows[1];
        T = rows[2];
        Vv[0] = rows[3];
        Vv[1] = rows[4];
        R = rows[5];
    }
    const V zero = {0, 0, 0, 0};
    const V tsL = sc.t;
    const auto frozenL = T == kNever;
    const V Tm = frozenL ? tsL : T;  // a frozen lane goes to candidateTime; no infinities in the arithmetic
    const V tr = tsL < Tm ? Tm : tsL;
    const V da = tr - tsL, db = tr - Tm;
    // Image shifts (base + wraps of the candidate) in box lengths, unless the batch is plain (all zero; the
    // scalar form adds 0 L, which changes at most the sign of a zero difference).
    std::int32_t m[D][4];
    if (!plain) {
        for (int l = 0; l < 4; ++l) {
            const Shift w = Slots<D>::wrapsOf(bt.wrap[l]);
            for (int k = 0; k < D; ++k) m[k][l] = (*bt.base[l])[k] + w[k];
        }
    }
    V r[D], v[D];
    for (int k = 0; k < D; ++k) {
        const V xa = sc.x[k] + (sc.v[k] + sc.gh[k] * da) * da;
        const V xb = X[k] + (Vv[k] + sc.gh[k] * db) * db;
        r[k] = xa - xb;
        if (!plain) {
            LaneIndex mk;
            __builtin_memcpy(&mk, m[k], sizeof mk);
            r[k] += __builtin_convertvector(mk, V) * sc.len[k];
        }
        v[k] = (sc.v[k] + sc.g[k] * da) - (Vv[k] + sc.g[k] * db);
    }
    V b = r[0] * v[0], r2 = r[0] * r[0], v2 = v[0] * v[0];
    for (int k = 1; k < D; ++k) {
        b += r[k] * v[k];
        r2 += r[k] * r[k];
        v2 += v[k] * v[k];
    }
    const V sigma = sc.r + R;
    const V c = r2 - sigma * sigma;
    const V left = best.time - tr;
    const auto far = (c > 0) & (c > -2.0 * b * left * (1 + 1e-12));
    const auto todo = (b < 0) & ~far & ~frozenL;
    // Nothing to offer: every lane receding or beyond the best event (then kNever is not better than it either).
    if (best.time < kNever && !anyOf(LaneMask{(LaneMask::Bits)(todo | frozenL)})) return;
    // f(t) = c + 2 b t + v2 t^2 with f2 = 2 v2 > 0 and f1 = 2 b < 0 (firstRootFalling's second branch)
    const V f1 = 2.0 * b, f2 = 2.0 * v2;
    const V arg = f1 * f1 - 2.0 * f2 * c;
    const V sq = sqrtOf(Lanes(arg > 0 ? arg : zero)).v;
    const V q = (2.0 * c) / (-f1 + sq);
    const V root = tr + (0 < q ? q : zero);
    const auto hit = todo & (arg > 0) & (f2 > 0);
    const auto special = frozenL | (todo & ~(f2 > 0)) | (hit & (root < now));
    const V t = hit ? root : zero + kNever;
    for (int l = 0; l < 4; ++l) {
        double tl = t[l];
        if (special[l]) {
            Shift ml{};  // a plain batch's shifts are zero
            if (!plain)
                for (int k = 0; k < D; ++k) ml[k] = m[k][l];
            tl = sl.candidateTime(hs, s, j[l], ml, now, best.time);
        }
        const std::uint32_t code = (kPair << kTypeShift) | j[l];
        if (best.better(tl, code)) {
            best = {tl, code, 0};
            bestJ = j[l];
        }
    }
}

/// A scan of slot s at time now: the batches a broad phase names go to candidates4, which keeps the best event in
/// best (bestJ: the slot of a pair event in it). Its call is inlined where the broad phase makes it, so a batch costs
/// no call, and the scan's state is one object, reached as directly as the scanning loop's own variables.
template <int D>
struct Scanner {
    // A constructor, not aggregate initialisation: GCC clears a whole aggregate (the lanes of sc too) before it
    // fills it.
    Scanner(const Slots<D>& sl_, const typename Slots<D>::Hot& hs_, std::uint32_t s_, double now_,
            const Candidate& best_)
        : sl(sl_), hs(hs_), sc(scanState(sl_, hs_)), s(s_), now(now_), best(best_), bestJ(kNil) {}
    const Slots<D>& sl;
    const typename Slots<D>::Hot& hs;
    ScanState<D> sc;
    std::uint32_t s;
    double now;
    Candidate best;
    std::uint32_t bestJ;
    [[gnu::always_inline]] inline void operator()(const Batch<D>& bt, std::uint32_t wsPacked,
                                                  const typename Slots<D>::Shift* plainBase) {
        candidates4(sl, sc, hs, s, bt, wsPacked, plainBase, now, best, bestJ);
    }
};

}  // namespace haet::edm
