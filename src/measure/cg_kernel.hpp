#pragma once
// The coarse-graining functions of the field grids (docs/physics.md L.1): one-dimensional kernels whose products
// over the grid's axes are the coarse-graining function phi(r) of Weinhart, Thornton, Luding & Bokhove (Granular
// Matter 14, 289, 2012) and Goldhirsch (Granular Matter 12, 239, 2010).
//
// A grid holds cell averages of the fields, not point values: cell q of an axis gets the share of a particle's
// kernel that falls inside it, C(e_{q+1} - p) - C(e_q - p), with C the kernel's cumulative distribution. The
// shares of all cells sum to one whatever the cell size (the differences telescope), so the density integrates to
// the mass in the region to round-off, and a cell size finer than the width changes nothing but resolution.
// Along a branch vector (a contact's force spread from one centre to the other) the share is averaged over the
// segment analytically: the integral of C is I, a closed form for both kernels, so
//   int_0^1 C(e - a - s (b - a)) ds = (I(e - a) - I(e - b)) / (b - a).
#include <cmath>
#include <numbers>

namespace haet {

enum class CgKernelKind {
    Gaussian,  ///< exp(-x^2 / (2 w^2)) cut off at |x| = c w, normalised over the cut-off support
    Lucy,      ///< (1 + 3 s)(1 - s)^3 with s = |x| / w, compact on |x| < w (Lucy 1977; Weinhart et al. 2012)
};

/// One axis's kernel: its cumulative distribution C(x) and the integral of that, I(x) = int_{-inf}^x C.
class CgKernel1d {
public:
    /// kind, width w [m] (the Gaussian's standard deviation; Lucy's support radius) and the Gaussian's cut-off c
    /// in widths (support |x| < c w; ignored for Lucy).
    /// A width of zero is the box: a point counts whole in the cell it lies in (a region's averages, measure/).
    CgKernel1d(CgKernelKind kind, double width, double cutoff) : kind_(kind), w_(width), c_(cutoff) {
        if (w_ <= 0) {
            r_ = 0;
        } else if (kind_ == CgKernelKind::Gaussian) {
            r_ = c_ * w_;
            tail_ = phi(-c_);
            z_ = 1.0 - 2.0 * tail_;
        } else {
            r_ = w_;
        }
    }

    double support() const { return r_; }  ///< half-width of the support [m]

    /// The share of the kernel below x: 0 for x <= -support, 1 for x >= support.
    double cdf(double x) const {
        if (x <= -r_) return 0.0;
        if (x >= r_) return 1.0;  // the box (r_ = 0) ends here
        if (kind_ == CgKernelKind::Gaussian) return (phi(x / w_) - tail_) / z_;
        const double s = x / w_, t = std::abs(s);
        const double f = 1.25 * t * (1.0 + t * t * (-2.0 + t * (2.0 - 0.6 * t)));
        return s < 0 ? 0.5 - f : 0.5 + f;
    }

    /// int_{-inf}^x cdf: 0 below the support, x above it (the kernel has mean zero) [m].
    double cdfIntegral(double x) const {
        if (x <= -r_) return 0.0;
        if (x >= r_) return x;
        if (kind_ == CgKernelKind::Gaussian) {
            // int_{-R}^x (Phi(t/w) - Phi(-c)) dt / Z with int Phi(u) du = u Phi(u) + phi(u) (the normal density).
            const double u = x / w_;
            const double g = u * phi(u) + density(u), g0 = -c_ * tail_ + density(-c_);
            return (w_ * (g - g0) - (x + r_) * tail_) / z_;
        }
        // Lucy: w (1/8 + s/2 + H(|s|)), H(t) = int_0^t F, F the cdf's odd part.
        const double s = x / w_, t = std::abs(s), t2 = t * t;
        const double h = 1.25 * t2 * (0.5 + t2 * (-0.5 + t * (0.4 - 0.1 * t)));
        return w_ * (0.125 + 0.5 * s + h);
    }

private:
    static double phi(double u) { return 0.5 * std::erfc(-u * std::numbers::sqrt2 * 0.5); }
    static double density(double u) {
        return std::exp(-0.5 * u * u) * (0.5 * std::numbers::inv_sqrtpi * std::numbers::sqrt2);
    }

    CgKernelKind kind_;
    double w_, c_;
    double r_ = 0, tail_ = 0, z_ = 1;
};

}  // namespace haet
