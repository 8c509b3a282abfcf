#include "haet/zones.hpp"

#include <algorithm>
#include <cmath>

namespace haet {

template <int D>
ZoneGrid<D>::ZoneGrid(const Domain<D>& dom, const ZoneSettings& s) : s_(s) {
    lo_ = dom.lo;
    for (int k = 0; k < D; ++k) {
        const double L = dom.hi[k] - dom.lo[k];
        n_[k] = std::max(1, static_cast<int>(std::floor(L / s.size)));
        width_[k] = L / n_[k];
        periodic_[k] = dom.periodic[k];
        total_ *= n_[k];
        cellVolume_ *= width_[k];
    }
    phi_.assign(total_, 0.0);
    phiSmooth_.assign(total_, 0.0);
    dense_.assign(total_, 0);
    tdm_.assign(total_, 0);
    buildNeighbours();
}

template <int D>
void ZoneGrid<D>::buildNeighbours() {
    auto build = [&](int radius, std::vector<int>& first, std::vector<int>& list) {
        first.assign(total_ + 1, 0);
        list.clear();
        for (int z = 0; z < total_; ++z) {
            forNeighbours(z, radius, [&](int q) { list.push_back(q); });
            first[z + 1] = static_cast<int>(list.size());
        }
    };
    build(1, nb1First_, nb1_);
    build(s_.buffer, nbBFirst_, nbB_);
}

template <int D>
int ZoneGrid<D>::zoneOf(const Vec<D>& x) const {
    int idx = 0;
    for (int k = D - 1; k >= 0; --k) {
        int c = static_cast<int>(std::floor((x[k] - lo_[k]) / width_[k]));
        if (periodic_[k]) c = ((c % n_[k]) + n_[k]) % n_[k];
        c = std::clamp(c, 0, n_[k] - 1);
        idx = idx * n_[k] + c;
    }
    return idx;
}

template <int D>
template <class F>
void ZoneGrid<D>::forNeighbours(int z, int radius, F&& f) const {
    std::array<int, D> c;
    int t = z;
    for (int k = 0; k < D; ++k) {
        c[k] = t % n_[k];
        t /= n_[k];
    }
    const int side = 2 * radius + 1;
    int m = 1;
    for (int k = 0; k < D; ++k) m *= side;
    // At most (2r+1)^D zones; small for the radii used (1 for smoothing, `buffer` for the buffer).
    std::vector<int> seen;
    seen.reserve(m);
    for (int code = 0; code < m; ++code) {
        int q = code, idx = 0, mul = 1;
        bool ok = true;
        for (int k = 0; k < D; ++k) {
            int ck = c[k] + q % side - radius;
            q /= side;
            if (ck < 0 || ck >= n_[k]) {
                if (!periodic_[k]) { ok = false; break; }
                ck = ((ck % n_[k]) + n_[k]) % n_[k];
            }
            idx += ck * mul;
            mul *= n_[k];
        }
        if (!ok || std::find(seen.begin(), seen.end(), idx) != seen.end()) continue;
        seen.push_back(idx);
        f(idx);
    }
}

template <int D>
void ZoneGrid<D>::relabel(const Particles<D>& p, const std::vector<std::uint8_t>& sticky) {
    std::vector<double> vol(total_, 0.0);
    for (std::size_t i = 0; i < p.size(); ++i) vol[zoneOf(p.x[i])] += Particles<D>::volumeOf(p.radius[i]);
    relabel(vol, sticky);
}

template <int D>
void ZoneGrid<D>::relabel(const std::vector<double>& volume, const std::vector<std::uint8_t>& sticky) {
    for (int z = 0; z < total_; ++z) phi_[z] = volume[z] / cellVolume_;
    // Smoothing over the zone and its neighbours damps the noise of a few particles crossing a zone edge.
    for (int z = 0; z < total_; ++z) {
        double sum = 0;
        for (int k = nb1First_[z]; k < nb1First_[z + 1]; ++k) sum += phi_[nb1_[k]];
        phiSmooth_[z] = sum / (nb1First_[z + 1] - nb1First_[z]);
    }
    for (int z = 0; z < total_; ++z) {
        const bool stick = z < static_cast<int>(sticky.size()) && sticky[z];
        if (dense_[z])
            dense_[z] = stick || phiSmooth_[z] >= s_.phiOff;
        else
            dense_[z] = stick || phiSmooth_[z] > s_.phiOn;
    }
    changed_ = 0;
    for (int z = 0; z < total_; ++z) {
        bool any = false;
        for (int k = nbBFirst_[z]; k < nbBFirst_[z + 1] && !any; ++k) any = dense_[nbB_[k]];
        if (any != static_cast<bool>(tdm_[z])) ++changed_;
        tdm_[z] = any;
    }
}

template class ZoneGrid<2>;
template class ZoneGrid<3>;

}  // namespace haet
