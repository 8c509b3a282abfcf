#include "haet/edm_book.hpp"

#include <algorithm>
#include <cmath>

#include "core/particles.hpp"

namespace haet {

template <int D>
void EdmBook<D>::restart(const CellGrid<D>& cells) {
    cells_ = cells;
    for (int k = 0; k < D; ++k) {
        const int nc = cells_.dim(k), nz = zones_.dims()[k];
        zoneCoord_[k].resize(nc);
        zoneCellBegin_[k].assign(nz + 1, static_cast<std::uint32_t>(nc));
        for (int c = nc; c-- > 0;) {
            const double xc = (c + 0.5) * cells_.width()[k];
            const int z = std::clamp(static_cast<int>(std::floor(xc / zones_.zoneWidth()[k])), 0, nz - 1);
            zoneCoord_[k][c] = static_cast<std::uint32_t>(z);
            zoneCellBegin_[k][z] = static_cast<std::uint32_t>(c);
        }
        // Zones holding no cell centre (a zone narrower than a cell): an empty range.
        for (int z = nz; z-- > 0;) zoneCellBegin_[k][z] = std::min(zoneCellBegin_[k][z], zoneCellBegin_[k][z + 1]);
    }
    volume_.assign(static_cast<std::size_t>(zones_.count()), 0.0);
    head_.assign(static_cast<std::size_t>(cells_.count()), kNone);
    std::fill(cell_.begin(), cell_.end(), kNone);
}

template <int D>
std::uint32_t EdmBook<D>::zoneOfCell(std::uint32_t c) const {
    const std::array<int, D> cc = cells_.coords(static_cast<int>(c));
    std::uint32_t z = 0;
    for (int k = 0; k < D; ++k)
        z += zoneCoord_[k][static_cast<std::uint32_t>(cc[k])] * static_cast<std::uint32_t>(zones_.stride(k));
    return z;
}

template <int D>
void EdmBook<D>::grow(std::uint32_t i) {
    if (i < cell_.size()) return;
    cell_.resize(i + 1, kNone);
    next_.resize(i + 1, kNone);
    zone_.resize(i + 1, 0);
}

template <int D>
void EdmBook<D>::link(std::uint32_t i, std::uint32_t c) {
    grow(i);
    cell_[i] = c;
    next_[i] = head_[c];
    head_[c] = i;
}

template <int D>
std::uint32_t* EdmBook<D>::pointerTo(std::uint32_t i) {
    std::uint32_t* at = &head_[cell_[i]];
    while (*at != i) at = &next_[*at];
    return at;
}

template <int D>
void EdmBook<D>::unlink(std::uint32_t i) {
    *pointerTo(i) = next_[i];
    cell_[i] = kNone;
}

template <int D>
void EdmBook<D>::joined(std::uint32_t i, std::uint32_t cell, double r) {
    const std::uint32_t z = zoneOfCell(cell);
    volume_[z] += Particles<D>::volumeOf(r);
    link(i, cell);
    zone_[i] = z;
}

template <int D>
void EdmBook<D>::left(std::uint32_t i, std::uint32_t cell, double r) {
    volume_[zoneOfCell(cell)] -= Particles<D>::volumeOf(r);
    unlink(i);
}

template <int D>
void EdmBook<D>::crossed(std::uint32_t i, std::uint32_t /*from*/, std::uint32_t to, double r) {
    const std::uint32_t za = zone_[i], zb = zoneOfCell(to);  // za: the zone of the cell left
    if (za != zb) {
        const double vol = Particles<D>::volumeOf(r);
        volume_[za] -= vol;
        volume_[zb] += vol;
    }
    if (guard_[to]) guardEntries_.push_back(i);
    unlink(i);
    link(i, to);
    zone_[i] = zb;
}

// Both pointers are found before either is written, so two neighbours in one list swap places correctly.
template <int D>
void EdmBook<D>::swapped(std::uint32_t i, std::uint32_t j) {
    if (i == j) return;
    grow(std::max(i, j));
    std::uint32_t* pi = cell_[i] != kNone ? pointerTo(i) : nullptr;
    std::uint32_t* pj = cell_[j] != kNone ? pointerTo(j) : nullptr;
    if (pi) *pi = j;
    if (pj) *pj = i;
    std::swap(next_[i], next_[j]);
    std::swap(cell_[i], cell_[j]);
    std::swap(zone_[i], zone_[j]);
}

template <int D>
std::vector<std::uint32_t> EdmBook<D>::takeGuardEntries() {
    std::vector<std::uint32_t> out;
    out.swap(guardEntries_);
    return out;
}

template <int D>
std::vector<std::uint32_t> EdmBook<D>::takeTcHandovers() {
    std::vector<std::uint32_t> out;
    out.swap(tcHandovers_);
    return out;
}

template class EdmBook<2>;
template class EdmBook<3>;

}  // namespace haet
