#include "measure/field_grid.hpp"

#include <algorithm>
#include <cmath>

namespace haet {

void gaussLegendre01(int n, double* nodes, double* weights) {
    // Nodes and weights on [-1, 1] (Abramowitz & Stegun 25.4.30), mapped to [0, 1].
    static const double x[6][6] = {{0},
                                   {0.5773502691896257},
                                   {0, 0.7745966692414834},
                                   {0.3399810435848563, 0.8611363115940526},
                                   {0, 0.5384693101056831, 0.9061798459386640},
                                   {0.2386191860831969, 0.6612093864662645, 0.9324695142031521}};
    static const double w[6][6] = {{2},
                                   {1},
                                   {0.8888888888888888, 0.5555555555555556},
                                   {0.6521451548625461, 0.3478548451374538},
                                   {0.5688888888888889, 0.4786286704993665, 0.2369268850561891},
                                   {0.4679139345726910, 0.3607615730481386, 0.1713244923791704}};
    const int m = n - 1;
    int k = 0;
    for (int q = 0; q < (n + 1) / 2; ++q) {
        const bool centre = n % 2 == 1 && q == 0;
        nodes[k] = 0.5 * (1 - x[m][q]);
        weights[k++] = 0.5 * w[m][q];
        if (!centre) {
            nodes[k] = 0.5 * (1 + x[m][q]);
            weights[k++] = 0.5 * w[m][q];
        }
    }
}

namespace {

/// The shares of cells q0..q1 of one axis (lower edge lo, width h, n cells) from below(e), the part of a weight
/// below the edge e: a cell's share is below(its upper edge) - below(its lower edge), so the shares sum to the
/// whole weight exactly; on a periodic axis the cell wraps, on another a cell outside the grid is dropped.
template <class Below>
void cellShares(double lo, double h, int n, bool wraps, long q0, long q1, Below below,
                std::vector<std::pair<int, double>>& out) {
    double prev = below(lo + static_cast<double>(q0) * h);
    for (long q = q0; q <= q1; ++q) {
        const double next = below(lo + static_cast<double>(q + 1) * h);
        const double s = next - prev;
        prev = next;
        long c = q;
        if (wraps)
            c = ((q % n) + n) % n;
        else if (q < 0 || q >= n)
            continue;
        if (s != 0) out.emplace_back(static_cast<int>(c), s);
    }
}

}  // namespace

template <int D>
CgGrid<D>::CgGrid(const CgGridSpec<D>& spec) : spec_(spec) {
    ncells_ = 1;
    cellVolume_ = 1;
    for (int a = 0; a < spec_.nAxes; ++a) {
        const int k = spec_.axis[a];
        inGrid_[k] = true;
        h_[a] = (spec_.hi[k] - spec_.lo[k]) / spec_.cells[a];
        ncells_ *= static_cast<std::size_t>(spec_.cells[a]);
        cellVolume_ *= h_[a];
        k_.emplace_back(spec_.kernel, spec_.width, spec_.cutoff);
    }
    for (int k = 0; k < D; ++k)
        if (!inGrid_[k]) cellVolume_ *= spec_.hi[k] - spec_.lo[k];
    sum_.assign(ncells_ * L::kChannels, 0.0);
}

template <int D>
void CgGrid<D>::pointShares(int a, double p, std::vector<std::pair<int, double>>& out) const {
    out.clear();
    const int k = spec_.axis[a], n = spec_.cells[a];
    const double lo = spec_.lo[k], h = h_[a], r = k_[a].support();
    const long q0 = static_cast<long>(std::floor((p - r - lo) / h));
    const long q1 = static_cast<long>(std::floor((p + r - lo) / h));
    const CgKernel1d& kr = k_[a];
    cellShares(
        lo, h, n, spec_.wraps[k], q0, q1, [&](double e) { return kr.cdf(e - p); }, out);
}

template <int D>
void CgGrid<D>::segmentShares(int a, double p, double db, std::vector<std::pair<int, double>>& out) const {
    const CgKernel1d& kr = k_[a];
    const double h = h_[a];
    // A branch much shorter than the cells and the kernel: its midpoint (the difference quotient below would
    // lose its digits).
    if (std::abs(db) <= 1e-9 * std::max(h, kr.support())) return pointShares(a, p - 0.5 * db, out);
    out.clear();
    const int k = spec_.axis[a], n = spec_.cells[a];
    const double lo = spec_.lo[k], r = kr.support();
    const double pa = p, pb = p - db;
    const long q0 = static_cast<long>(std::floor((std::min(pa, pb) - r - lo) / h));
    const long q1 = static_cast<long>(std::floor((std::max(pa, pb) + r - lo) / h));
    // The share of the segment's kernels below edge e, averaged along it: (I(e - pb) - I(e - pa)) / (pa - pb).
    cellShares(
        lo, h, n, spec_.wraps[k], q0, q1,
        [&](double e) { return (kr.cdfIntegral(e - pb) - kr.cdfIntegral(e - pa)) / db; }, out);
}

template <int D>
bool CgGrid<D>::inTransverse(const Vec<D>& x) const {
    for (int k = 0; k < D; ++k)
        if (!inGrid_[k] && !spec_.wraps[k] && !(x[k] >= spec_.lo[k] && x[k] < spec_.hi[k])) return false;
    return true;
}

template <int D>
bool CgGrid<D>::transverseClip(const Vec<D>& x, const Vec<D>& b, double& s0, double& s1) const {
    s0 = 0, s1 = 1;
    for (int k = 0; k < D; ++k) {
        if (inGrid_[k] || spec_.wraps[k]) continue;
        // x_k - s b_k in [lo, hi)
        if (b[k] == 0) {
            if (!(x[k] >= spec_.lo[k] && x[k] < spec_.hi[k])) return false;
            continue;
        }
        double ta = (x[k] - spec_.lo[k]) / b[k], tb = (x[k] - spec_.hi[k]) / b[k];
        if (ta > tb) std::swap(ta, tb);
        s0 = std::max(s0, ta);
        s1 = std::min(s1, tb);
    }
    return s1 > s0;
}

template <int D>
void CgGrid<D>::deposit(const std::vector<std::pair<int, double>>* shares, int channel, const double* values, int count,
                        double scale) {
    const int na = spec_.nAxes;
    const std::size_t nc = ncells_;
    double* base = sum_.data() + static_cast<std::size_t>(channel) * nc;
    auto add = [&](std::size_t cell, double s) {
        s *= scale;
        for (int v = 0; v < count; ++v) base[static_cast<std::size_t>(v) * nc + cell] += s * values[v];
    };
    // Cell index: grid axis 0 fastest (VTK image order).
    if (na == 1) {
        for (const auto& [c0, s0] : shares[0]) add(static_cast<std::size_t>(c0), s0);
    } else if (na == 2) {
        const std::size_t n0 = static_cast<std::size_t>(spec_.cells[0]);
        for (const auto& [c1, s1] : shares[1])
            for (const auto& [c0, s0] : shares[0]) add(static_cast<std::size_t>(c1) * n0 + c0, s0 * s1);
    } else {
        const std::size_t n0 = static_cast<std::size_t>(spec_.cells[0]), n1 = static_cast<std::size_t>(spec_.cells[1]);
        for (const auto& [c2, s2] : shares[2])
            for (const auto& [c1, s1] : shares[1]) {
                const double s12 = s1 * s2;
                for (const auto& [c0, s0] : shares[0])
                    add((static_cast<std::size_t>(c2) * n1 + c1) * n0 + c0, s0 * s12);
            }
    }
}

template <int D>
template <class Add>
void CgGrid<D>::forImages(const Vec<D>& x, const Vec<D>& lo, const Vec<D>& hi, Add add) const {
    // Up to three images per axis (the region lies in the box, a position at most a skin outside it): the shifts
    // -L, 0, +L of each axis with a period that reach into [region lo, region hi), combined over the axes.
    std::array<std::array<double, 3>, D> shifts;
    std::array<int, D> count;
    for (int k = 0; k < D; ++k) {
        const double len = spec_.period[k];
        count[k] = 0;
        if (len == 0) {
            shifts[k][count[k]++] = 0;
            continue;
        }
        double r = 0;
        for (int a = 0; a < spec_.nAxes; ++a)
            if (spec_.axis[a] == k) r = k_[a].support();
        for (double s : {0.0, -len, len})
            if (x[k] + s + hi[k] + r >= spec_.lo[k] && x[k] + s + lo[k] - r < spec_.hi[k]) shifts[k][count[k]++] = s;
    }
    for (int k = 0; k < D; ++k)
        if (count[k] == 0) return;  // no image reaches the region
    std::array<int, D> q{};
    for (;;) {
        Vec<D> xs = x;
        for (int k = 0; k < D; ++k) xs[k] += shifts[k][q[k]];
        add(xs);
        int k = 0;
        while (k < D && ++q[k] >= count[k]) q[k++] = 0;
        if (k == D) return;
    }
}

template <int D>
void CgGrid<D>::addParticle(const Vec<D>& x, double mass, double volume, bool tdm, const Vec<D>& v) {
    double values[3 + D + D * D];
    values[kCgMass] = mass;
    values[kCgVolume] = volume;
    values[kCgTdmVolume] = tdm ? volume : 0.0;
    for (int a = 0; a < D; ++a) {
        values[L::kMomentum + a] = mass * v[a];
        for (int b = 0; b < D; ++b) values[L::kMvv + a * D + b] = mass * v[a] * v[b];
    }
    forImages(x, Vec<D>::zero(), Vec<D>::zero(), [&](const Vec<D>& xs) { addParticleImage(xs, values); });
}

template <int D>
void CgGrid<D>::addParticleImage(const Vec<D>& x, const double* values) {
    if (!inTransverse(x)) return;
    for (int a = 0; a < spec_.nAxes; ++a) pointShares(a, x[spec_.axis[a]], sh_[a]);
    deposit(sh_, 0, values, 3 + D + D * D, 1.0);
}

template <int D>
void CgGrid<D>::addSegment(const Vec<D>& x, const Vec<D>& b, const Vec<D>& f, int channel) {
    Vec<D> lo, hi;  // the segment x -> x - b relative to x
    for (int k = 0; k < D; ++k) lo[k] = std::min(0.0, -b[k]), hi[k] = std::max(0.0, -b[k]);
    forImages(x, lo, hi, [&](const Vec<D>& xs) { addSegmentImage(xs, b, f, channel); });
}

template <int D>
void CgGrid<D>::addSegmentImage(const Vec<D>& x, const Vec<D>& b, const Vec<D>& f, int channel) {
    double s0, s1;
    if (!transverseClip(x, b, s0, s1)) return;
    double t[D * D];
    for (int a = 0; a < D; ++a)
        for (int c = 0; c < D; ++c) t[a * D + c] = f[a] * b[c];
    const double part = s1 - s0;
    const Vec<D> xa = x - b * s0;
    const Vec<D> bs = b * part;
    if (spec_.nAxes == 1) {
        const int k = spec_.axis[0];
        segmentShares(0, xa[k], bs[k], sh_[0]);
        deposit(sh_, channel, t, D * D, part);
        return;
    }
    double nodes[6], weights[6];
    const int nn = std::clamp(spec_.branchNodes, 1, 6);
    gaussLegendre01(nn, nodes, weights);
    for (int g = 0; g < nn; ++g) {
        const Vec<D> xg = xa - bs * nodes[g];
        for (int a = 0; a < spec_.nAxes; ++a) pointShares(a, xg[spec_.axis[a]], sh_[a]);
        deposit(sh_, channel, t, D * D, part * weights[g]);
    }
}

template <int D>
CgFields<D> CgGrid<D>::fields(double window) const {
    CgFields<D> out;
    const std::size_t n = ncells_;
    out.cells = n;
    out.density.assign(n, 0.0);
    out.volumeFraction.assign(n, 0.0);
    out.velocity.assign(n * D, 0.0);
    out.kineticStress.assign(n * D * D, 0.0);
    out.temperature.assign(n, 0.0);
    out.contactStress.assign(n * D * D, 0.0);
    out.collisionalStress.assign(n * D * D, 0.0);
    out.stress.assign(n * D * D, 0.0);
    out.modeFraction.assign(n, 0.0);
    const double ns = samples_ > 0 ? static_cast<double>(samples_) : 1.0;
    const double perSample = 1.0 / (ns * cellVolume_);
    const double perWindow = window > 0 ? 1.0 / (window * cellVolume_) : 0.0;
    auto at = [&](int channel, std::size_t c) { return sum_[static_cast<std::size_t>(channel) * n + c]; };
    for (std::size_t c = 0; c < n; ++c) {
        const double m = at(kCgMass, c) * perSample;
        const double vol = at(kCgVolume, c) * perSample;
        out.density[c] = m;
        out.volumeFraction[c] = vol;
        out.modeFraction[c] = vol > 0 ? at(kCgTdmVolume, c) * perSample / vol : 0.0;
        double p[D];
        for (int a = 0; a < D; ++a) {
            p[a] = at(L::kMomentum + a, c) * perSample;
            out.velocity[c * D + a] = m > 0 ? p[a] / m : 0.0;
        }
        double trace = 0;
        for (int a = 0; a < D; ++a)
            for (int b = 0; b < D; ++b) {
                const std::size_t e = c * D * D + static_cast<std::size_t>(a * D + b);
                // sigma_k = <sum m v v phi> - <p> <p> / <rho>: the fluctuations about the window's mean velocity.
                const double kin = at(L::kMvv + a * D + b, c) * perSample - (m > 0 ? p[a] * p[b] / m : 0.0);
                const double con = at(L::kContact + a * D + b, c) * perSample;
                const double col = at(L::kCollision + a * D + b, c) * perWindow;
                out.kineticStress[e] = kin;
                out.contactStress[e] = con;
                out.collisionalStress[e] = col;
                out.stress[e] = kin + con + col;
                if (a == b) trace += kin;
            }
        out.temperature[c] = m > 0 ? trace / (D * m) : 0.0;
    }
    return out;
}

template <int D>
void CgGrid<D>::clear() {
    std::fill(sum_.begin(), sum_.end(), 0.0);
    samples_ = 0;
}

template class CgGrid<2>;
template class CgGrid<3>;

}  // namespace haet
