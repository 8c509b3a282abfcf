#include "haet/zones.hpp"

#include <algorithm>
#include <cmath>

namespace haet {

template <int D>
ZoneGrid<D>::ZoneGrid(const Domain<D>& dom, const ZoneSettings& s)
    : s_(s), grid_(CellGrid<D>::spanning(dom.lo, dom.hi, s.size, dom.periodic)) {
    for (int k = 0; k < D; ++k) cellVolume_ *= grid_.width()[k];
    phi_.assign(count(), 0.0);
    phiSmooth_.assign(count(), 0.0);
    dense_.assign(count(), 0);
    tdm_.assign(count(), 0);
    // 1 / the number of zones each zone's smoothing averages (the 3^D block, clipped at open faces).
    std::vector<double> one(count(), 1.0), zones = one;
    for (int k = 0; k < D; ++k) {
        alongAxis(k, 1, zones, one, [](double a, double b) { return a + b; });
        zones.swap(one);
    }
    invCount_.resize(count());
    for (int z = 0; z < count(); ++z) invCount_[z] = 1.0 / zones[z];
}

template <int D>
template <class T, class Op>
void ZoneGrid<D>::alongAxis(int k, int radius, const std::vector<T>& in, std::vector<T>& out, Op op) const {
    const int n = grid_.dim(k), stride = grid_.stride(k), lines = grid_.count() / (stride * n);
    const bool periodic = grid_.periodic(k);
    // Offsets -radius..radius reach each zone of a periodic axis once at most: at most n of them.
    const int lo = periodic ? -std::min(radius, (n - 1) / 2) : -radius;
    const int hi = periodic ? std::min(radius, n / 2) : radius;
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
                        if (!periodic) continue;
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
    std::vector<double> vol(count(), 0.0);
    for (std::size_t i = 0; i < p.size(); ++i) vol[zoneOf(p.x[i])] += Particles<D>::volumeOf(p.radius[i]);
    relabel(vol, sticky);
}

template <int D>
void ZoneGrid<D>::relabel(const std::vector<double>& volume, const std::vector<std::uint8_t>& sticky) {
    for (int z = 0; z < count(); ++z) phi_[z] = volume[z] / cellVolume_;
    // Smoothing over the zone and its neighbours damps the noise of a few particles crossing a zone edge: the mean
    // over the 3^D block (clipped at open faces), summed axis by axis.
    sum_ = phi_;
    for (int k = 0; k < D; ++k) {
        alongAxis(k, 1, sum_, phiSmooth_, [](double a, double b) { return a + b; });
        sum_.swap(phiSmooth_);
    }
    for (int z = 0; z < count(); ++z) phiSmooth_[z] = sum_[z] * invCount_[z];
    for (int z = 0; z < count(); ++z) {
        const bool stick = z < static_cast<int>(sticky.size()) && sticky[z];
        if (dense_[z])
            dense_[z] = stick || phiSmooth_[z] >= s_.phiOff;
        else
            dense_[z] = stick || phiSmooth_[z] > s_.phiOn;
    }
    // Time-driven: a dense zone within `buffer` on every axis (a dilation, axis by axis).
    mark_ = dense_;
    markNext_.resize(count());
    for (int k = 0; k < D && s_.buffer > 0; ++k) {
        alongAxis(k, s_.buffer, mark_, markNext_, [](std::uint8_t a, std::uint8_t b) -> std::uint8_t { return a | b; });
        mark_.swap(markNext_);
    }
    changed_ = 0;
    for (int z = 0; z < count(); ++z) {
        const std::uint8_t any = mark_[z] != 0;
        if (any != tdm_[z]) ++changed_;
        tdm_[z] = any;
    }
}

template class ZoneGrid<2>;
template class ZoneGrid<3>;

}  // namespace haet
