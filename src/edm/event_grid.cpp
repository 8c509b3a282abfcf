#include "edm/event_grid.hpp"

#include <algorithm>
#include <cmath>

namespace haet {

template <int D>
EventCells<D> EventCells<D>::fit(const Domain<D>& dom, double edge, double maxCells) {
    EventCells g;
    const Vec<D> len = dom.length();
    for (;;) {
        double total = 1;
        for (int k = 0; k < D; ++k) {
            const double L = len[k];
            g.dims[k] = L > 0 ? std::max(1, static_cast<int>(std::floor(L / edge))) : 1;
            total *= g.dims[k];
        }
        if (total <= maxCells) break;
        edge *= 1.25;
    }
    std::uint32_t total = 1;
    for (int k = 0; k < D; ++k) {
        g.lo[k] = dom.lo[k];
        g.periodic[k] = dom.periodic[k];
        g.width[k] = len[k] > 0 ? len[k] / g.dims[k] : 1;
        g.stride[k] = total;
        total *= static_cast<std::uint32_t>(g.dims[k]);
    }
    // Index offsets of the 3^D neighbours of a cell away from the faces, and of the 3^(D-1) new neighbours after a
    // step along axis a in direction d (deltaSide[2 a + (d > 0)]).
    std::array<int, 2 * D> sideCount{};
    for (int code = 0; code < kNbrCells; ++code) {
        std::array<int, D> o;
        int t = code;
        std::int32_t delta = 0;
        for (int k = 0; k < D; ++k) {
            o[k] = t % 3 - 1;
            t /= 3;
            delta += o[k] * static_cast<std::int32_t>(g.stride[k]);
        }
        g.deltaFull[code] = delta;
        for (int k = 0; k < D; ++k)
            if (o[k] != 0) {
                const int side = 2 * k + (o[k] > 0 ? 1 : 0);
                g.deltaSide[side][sideCount[side]++] = delta;
            }
    }
    return g;
}

namespace edm {

template <int D>
void EventGrid<D>::build(const Domain<D>& dom, double edge, double maxCells) {
    cells_ = EventCells<D>::fit(dom, edge, maxCells);
    partialScans_ = true;
    for (int k = 0; k < D; ++k)
        if (dom.periodic[k] && cells_.dims[k] < 7) partialScans_ = false;  // keptTime's minimum image
    head_.assign(cells_.count(), kNil);
}

template <int D>
double EventGrid<D>::smallestEdge() const {
    double c = kNever;
    for (int k = 0; k < D; ++k) c = std::min(c, cells_.width[k]);
    return c;
}

template <int D>
void EventGrid<D>::relink(Sl& sl) {
    std::fill(head_.begin(), head_.end(), kNil);
    // Inserted from the last slot down, so each cell's list runs in increasing slot order.
    for (std::uint32_t s = static_cast<std::uint32_t>(sl.size()); s-- > 0;)
        if (sl.rec[s].idx != kNil) insert(sl, s, sl.rec[s].cell);
}

template class EventGrid<2>;
template class EventGrid<3>;

}  // namespace edm

template struct EventCells<2>;
template struct EventCells<3>;

}  // namespace haet
