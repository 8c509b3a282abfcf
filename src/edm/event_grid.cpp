#include "edm/event_grid.hpp"

#include <algorithm>
#include <cmath>

namespace haet {
namespace edm {

template <int D>
void EventGrid<D>::build(const Domain<D>& dom, double edge, double maxCells) {
    // Below 2^kCellBits - 1 cells in any case: the free slots' cell is the one past the last.
    maxCells = std::min(maxCells, double((1u << Sl::kCellBits) - 2));
    for (;;) {  // the cells counted in double: a fine edge over a large box may give more than an int holds
        const std::array<int, D> n = Cells::spanningDims(dom.lo, dom.hi, edge, true);
        double total = 1;
        for (int k = 0; k < D; ++k) total *= n[k];
        if (total <= maxCells) break;
        edge *= 1.25;
    }
    cells_ = Cells::spanning(dom.lo, dom.hi, edge, dom.periodic, true);
    partialScans_ = true;
    for (int k = 0; k < D; ++k)
        if (dom.periodic[k] && cells_.dim(k) < 7) partialScans_ = false;  // keptTime's minimum image
    head_.assign(cells_.count(), kNil);
}

template <int D>
double EventGrid<D>::smallestEdge() const {
    double c = kNever;
    for (int k = 0; k < D; ++k) c = std::min(c, cells_.width()[k]);
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

}  // namespace haet
