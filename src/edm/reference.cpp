#include "edm/reference.hpp"

#include <algorithm>
#include <cmath>

namespace haet::edm {

template <int D>
typename Reference<D>::Event Reference<D>::next(double now) const {
    using Shift = typename Slots<D>::Shift;
    const Domain<D>& dom = sl_.world->domain;
    const auto base = static_cast<std::uint32_t>(sl_.world->walls.size());
    const std::uint32_t n = static_cast<std::uint32_t>(sl_.size());
    // Within the horizon every particle moves less than delta, so a pair that collides is at its minimum image now
    // (|r| <= sigma + 2 delta <= L/2): the minimum image is enough.
    double lmin = kNever;
    for (int k = 0; k < D; ++k)
        if (dom.periodic[k]) lmin = std::min(lmin, sl_.boxLen[k]);
    const double delta = 0.5 * (0.5 * lmin - 2 * rmax_);
    double horizon = kNever;
    if (lmin < kNever) {
        double vmax = 0;
        for (std::uint32_t s = 0; s < n; ++s)
            if (!sl_.frozen(s)) vmax = std::max(vmax, norm(sl_.velAt(sl_.hot[s], now)));
        horizon = now + 2 * delta / (vmax + std::sqrt(vmax * vmax + 2 * norm(sl_.g) * delta));
    }
    Event best;
    for (std::uint32_t s = 0; s < n; ++s) {
        if (sl_.frozen(s)) continue;
        Candidate c;
        for (const std::uint32_t w : planes_) {
            const double tw = sl_.wallTime(s, w, now);
            const std::uint32_t code = (kWall << kTypeShift) | w;
            if (c.better(tw, code)) c = {tw, code, 0};
        }
        const Vec<D> xs = sl_.posAt(sl_.hot[s], now);
        for (std::uint32_t j = 0; j < n; ++j) {
            if (j == s) continue;
            const Vec<D> d = xs - sl_.posAt(sl_.hot[j], now);
            Shift m{};  // the image count itself (pairTime's shift), not the displacement minimumImage gives
            for (int k = 0; k < D; ++k)
                if (dom.periodic[k]) m[k] = -static_cast<std::int32_t>(std::nearbyint(d[k] / sl_.boxLen[k]));
            const double tp = sl_.pairTime(s, j, m, now, c.time);
            const std::uint32_t code = (kPair << kTypeShift) | j;
            if (c.better(tp, code)) c = {tp, code, 0};
        }
        // The mesh after the pairs, so that the best so far skips the elements out of reach (MeshWalls::time).
        for (std::uint32_t e = 0; e < mesh_.size(); ++e) {
            const double tm = mesh_.time(sl_, s, e, now, c.time);
            const std::uint32_t code = (kWall << kTypeShift) | (base + e);
            if (c.better(tm, code)) c = {tm, code, 0};
        }
        if (c.time < best.time) best = {c.time, s, c.code};
    }
    if (horizon < best.time) best = {horizon, 0, kNone << kTypeShift};
    if (!mesh_.empty() && lmin < kNever) {
        // The box frame of a slot moves by a box length where its centre crosses a periodic face.
        for (std::uint32_t s = 0; s < n; ++s) {
            if (sl_.frozen(s)) continue;
            const Shift ws = Slots<D>::wrapsOf(sl_.link[s].wrap);
            const Vec<D> x = sl_.posAt(sl_.hot[s], now), v = sl_.velAt(sl_.hot[s], now);
            for (int k = 0; k < D; ++k) {
                if (!dom.periodic[k]) continue;
                const CellExit ex =
                    cellExitTime(x[k] - ws[k] * sl_.boxLen[k], v[k], sl_.g[k], dom.lo[k], dom.lo[k] + sl_.boxLen[k]);
                if (now + ex.time < best.time)
                    best = {now + ex.time, s, (kCell << kTypeShift) | static_cast<std::uint32_t>(2 * k + ex.up)};
            }
        }
    }
    return best;
}

template class Reference<2>;
template class Reference<3>;

}  // namespace haet::edm
