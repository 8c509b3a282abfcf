#include "scenario/distribution.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace haet {
namespace {

/// The standard normal distribution between za and zb, renormalised: the probability of (za, z]. A range in the
/// upper tail is computed from the upper tail's probabilities Q(z) = erfc(z / sqrt 2) / 2, which keep their
/// precision there, as Phi(z) = 1 - Q(z) would not.
double truncatedNormalCdf(double z, double za, double zb) {
    z = std::clamp(z, za, zb);
    const double s = 1 / std::sqrt(2.0);
    if (za >= 0) {
        const double qa = std::erfc(za * s), qb = std::erfc(zb * s);
        return qa > qb ? (qa - std::erfc(z * s)) / (qa - qb) : 0.0;
    }
    const double pa = std::erfc(-za * s), pb = std::erfc(-zb * s);
    return pb > pa ? (std::erfc(-z * s) - pa) / (pb - pa) : 0.0;
}

/// The x in [a, b] where the increasing function f reaches u, by bisection to the last bit (a draw of an insert or
/// an inlet, never in a time step, so its cost does not matter and there is no approximation to trust).
template <class F>
double invert(F&& f, double u, double a, double b) {
    for (int it = 0; it < 200; ++it) {
        const double m = 0.5 * (a + b);
        if (m <= a || m >= b) break;
        (f(m) < u ? a : b) = m;
    }
    return 0.5 * (a + b);
}

/// The variable whose normal distribution defines the kind: r (normal) or ln r (log-normal), standardised.
double standardised(const SizeDistribution& s, double r) {
    if (s.kind == SizeKind::LogNormal) return std::log(r / s.location) / s.sigma;
    return (r - s.location) / s.sigma;
}

}  // namespace

SizeDistribution uniformSizes(double min, double max) {
    SizeDistribution s;
    s.kind = SizeKind::Uniform;
    s.min = min;
    s.max = max;
    return s;
}

SizeDistribution discreteSizes(std::vector<double> radii, const std::vector<double>& fractions, bool byMass,
                               int dimension) {
    if (radii.empty() || radii.size() != fractions.size())
        throw std::invalid_argument("discreteSizes: one fraction per radius");
    std::vector<std::size_t> order(radii.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return radii[a] < radii[b]; });
    SizeDistribution s;
    s.kind = SizeKind::Discrete;
    std::vector<double> given;
    for (const std::size_t k : order) {
        s.radii.push_back(radii[k]);
        given.push_back(fractions[k]);
    }
    // Number and mass fractions of size k differ by the mass of one particle, m_k ~ r_k^D.
    std::vector<double> other(given.size());
    double sum = 0;
    for (std::size_t k = 0; k < given.size(); ++k) {
        const double m = std::pow(s.radii[k], dimension);
        other[k] = byMass ? given[k] / m : given[k] * m;
        sum += other[k];
    }
    for (double& f : other) f /= sum;
    double total = 0;
    for (const double f : given) total += f;
    for (double& f : given) f /= total;  // sums to 1 within the loader's tolerance already
    s.numberFraction = byMass ? other : given;
    s.massFraction = byMass ? given : other;
    s.min = s.radii.front();
    s.max = s.radii.back();
    return s;
}

SizeDistribution normalSizes(double mean, double sigma, double min, double max) {
    SizeDistribution s;
    s.kind = SizeKind::Normal;
    s.location = mean;
    s.sigma = sigma;
    s.min = min;
    s.max = max;
    return s;
}

SizeDistribution logNormalSizes(double median, double sigma, double min, double max) {
    SizeDistribution s = normalSizes(median, sigma, min, max);
    s.kind = SizeKind::LogNormal;
    return s;
}

double SizeDistribution::cdf(double r) const {
    if (r < min) return 0;
    if (r >= max) return 1;
    switch (kind) {
        case SizeKind::Uniform:
            return (r - min) / (max - min);
        case SizeKind::Discrete: {
            double c = 0;
            for (std::size_t k = 0; k < radii.size() && radii[k] <= r; ++k) c += numberFraction[k];
            return std::min(c, 1.0);
        }
        case SizeKind::Normal:
        case SizeKind::LogNormal:
            return truncatedNormalCdf(standardised(*this, r), standardised(*this, min), standardised(*this, max));
    }
    return 0;
}

double SizeDistribution::sample(Rng& rng) const {
    switch (kind) {
        case SizeKind::Uniform:
            return rng.uniform(min, max);
        case SizeKind::Discrete: {
            const double u = rng.uniform();
            double c = 0;
            for (std::size_t k = 0; k + 1 < radii.size(); ++k) {
                c += numberFraction[k];
                if (u < c) return radii[k];
            }
            return radii.back();
        }
        case SizeKind::Normal:
        case SizeKind::LogNormal: {
            const double u = rng.uniform();
            const double za = standardised(*this, min), zb = standardised(*this, max);
            auto f = [&](double z) { return truncatedNormalCdf(z, za, zb); };
            const double z = invert(f, u, za, zb);
            const double r = kind == SizeKind::Normal ? location + sigma * z : location * std::exp(sigma * z);
            return std::clamp(r, min, max);
        }
    }
    return min;
}

SizeSummary summarize(const SizeDistribution& s, int dimension) {
    SizeSummary out;
    // Points r_k with weights w_k by number: the table itself, or Simpson's rule over [min, max] on the density
    // (the cdf's differences over fine intervals, exact for the uniform and a close quadrature for the others).
    std::vector<double> r, w;
    if (s.kind == SizeKind::Discrete) {
        r = s.radii;
        w = s.numberFraction;
    } else if (!(s.max > s.min)) {
        r = {s.min};
        w = {1.0};
    } else {
        const int n = 20000;
        const double h = (s.max - s.min) / n;
        for (int k = 0; k < n; ++k) {
            r.push_back(s.min + (k + 0.5) * h);
            w.push_back(s.cdf(s.min + (k + 1) * h) - s.cdf(s.min + k * h));
        }
    }
    double wn = 0, wm = 0, mn = 0, mm = 0;
    for (std::size_t k = 0; k < r.size(); ++k) {
        const double m = w[k] * std::pow(r[k], dimension);
        wn += w[k];
        wm += m;
        mn += w[k] * r[k];
        mm += m * r[k];
    }
    out.meanByNumber = 2 * mn / wn;
    out.meanByMass = 2 * mm / wm;
    // d50: the size below which half the particles (half the mass) lie; within a bin, where the cumulative
    // crosses one half (a discrete table: the first size that reaches it).
    auto median = [&](bool byMass) {
        const double total = byMass ? wm : wn;
        double c = 0;
        for (std::size_t k = 0; k < r.size(); ++k) {
            const double dk = byMass ? w[k] * std::pow(r[k], dimension) : w[k];
            if (c + dk >= 0.5 * total) {
                if (s.kind == SizeKind::Discrete || r.size() == 1) return 2 * r[k];
                const double h = (s.max - s.min) / double(r.size());
                return 2 * (r[k] - 0.5 * h + h * (0.5 * total - c) / dk);
            }
            c += dk;
        }
        return 2 * r.back();
    };
    out.d50ByNumber = median(false);
    out.d50ByMass = median(true);
    return out;
}

std::string describeSizes(const SizeDistribution& s) {
    std::ostringstream os;
    os.precision(4);
    switch (s.kind) {
        case SizeKind::Uniform:
            if (s.max > s.min)
                os << "uniform radius in [" << s.min << ", " << s.max << "] m";
            else
                os << "one radius " << s.min << " m";
            break;
        case SizeKind::Discrete:
            os << "discrete: " << s.radii.size() << " radii in [" << s.min << ", " << s.max << "] m";
            break;
        case SizeKind::Normal:
            os << "normal radius, mean " << s.location << " m, sigma " << s.sigma << " m, truncated to [" << s.min
               << ", " << s.max << "] m";
            break;
        case SizeKind::LogNormal:
            os << "log-normal radius, median " << s.location << " m, sigma(ln r) " << s.sigma << ", truncated to ["
               << s.min << ", " << s.max << "] m";
            break;
    }
    return os.str();
}

}  // namespace haet
