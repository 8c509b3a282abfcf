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
    // 1 / the number of zones each zone's smoothing averages (the 3^D block, clipped at open faces).
    std::vector<double> one(total_, 1.0), count = one;
    for (int k = 0; k < D; ++k) {
        alongAxis(k, 1, count, one, [](double a, double b) { return a + b; });
        count.swap(one);
    }
    invCount_.resize(total_);
    for (int z = 0; z < total_; ++z) invCount_[z] = 1.0 / count[z];
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
template <class T, class Op>
void ZoneGrid<D>::alongAxis(int k, int radius, const std::vector<T>& in, std::vector<T>& out, Op op) const {
    const int n = n_[k], stride = this->stride(k), lines = total_ / (stride * n);
    // Offsets -radius..radius reach each zone of a periodic axis once at most: at most n of them.
    const int lo = periodic_[k] ? -std::min(radius, (n - 1) / 2) : -radius;
    const int hi = periodic_[k] ? std::min(radius, n / 2) : radius;
    for (int line = 0; line < lines; ++line)
        for (int inner = 0; inner < stride; ++inner) {
            const T* a = in.data() + line * stride * n + inner;
            T* b = out.data() + line * stride * n + inner;
            // Zones whose window stays inside the axis, then the ones at its ends (clipped or wrapped).
            const int c0 = std::min(n, -lo), c1 = std::max(c0, n - hi);
            for (int c = c0; c < c1; ++c) {
                const T* w = a + (c + lo) * stride;
                T acc = w[0];
                for (int o = 1; o <= hi - lo; ++o) acc = op(acc, w[o * stride]);
                b[c * stride] = acc;
            }
            auto edge = [&](int c) {
                T acc{};
                bool first = true;
                for (int o = lo; o <= hi; ++o) {
                    int q = c + o;
                    if (q < 0 || q >= n) {
                        if (!periodic_[k]) continue;
                        q = q < 0 ? q + n : q - n;
                    }
                    acc = first ? a[q * stride] : op(acc, a[q * stride]);
                    first = false;
                }
                b[c * stride] = acc;
            };
            for (int c = 0; c < c0; ++c) edge(c);
            for (int c = c1; c < n; ++c) edge(c);
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
    // Smoothing over the zone and its neighbours damps the noise of a few particles crossing a zone edge: the mean
    // over the 3^D block (clipped at open faces), summed axis by axis.
    sum_ = phi_;
    for (int k = 0; k < D; ++k) {
        alongAxis(k, 1, sum_, phiSmooth_, [](double a, double b) { return a + b; });
        sum_.swap(phiSmooth_);
    }
    for (int z = 0; z < total_; ++z) phiSmooth_[z] = sum_[z] * invCount_[z];
    for (int z = 0; z < total_; ++z) {
        const bool stick = z < static_cast<int>(sticky.size()) && sticky[z];
        if (dense_[z])
            dense_[z] = stick || phiSmooth_[z] >= s_.phiOff;
        else
            dense_[z] = stick || phiSmooth_[z] > s_.phiOn;
    }
    // Time-driven: a dense zone within `buffer` on every axis (a dilation, axis by axis).
    mark_ = dense_;
    markNext_.resize(total_);
    for (int k = 0; k < D && s_.buffer > 0; ++k) {
        alongAxis(k, s_.buffer, mark_, markNext_, [](std::uint8_t a, std::uint8_t b) -> std::uint8_t { return a | b; });
        mark_.swap(markNext_);
    }
    changed_ = 0;
    for (int z = 0; z < total_; ++z) {
        const std::uint8_t any = mark_[z] != 0;
        if (any != tdm_[z]) ++changed_;
        tdm_[z] = any;
    }
}

template class ZoneGrid<2>;
template class ZoneGrid<3>;

}  // namespace haet
