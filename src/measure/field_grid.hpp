#pragma once
// Coarse-grained fields on a grid (docs/physics.md L): density, volume fraction, momentum, the kinetic stress, the
// contact stress and the collisional stress, as cell averages over a grid of 1, 2 or 3 of the box's axes, after
// Weinhart, Thornton, Luding & Bokhove (Granular Matter 14, 289, 2012) and Goldhirsch (Granular Matter 12, 239,
// 2010). The kernel is a product of one-dimensional kernels, one per grid axis (measure/cg_kernel.hpp); the axes
// not in the grid are averaged over the region (a 1-axis grid over a periodic chute gives profiles).
//
// The grid accumulates sums over samples (particles and contacts at one time each, impulses of collisions over a
// time window); `fields` turns the sums into the fields. Everything is in the order it is given, so the result does
// not depend on threads, and the sums are plain arrays that a checkpoint saves as they are.
#include <array>
#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "measure/cg_kernel.hpp"

namespace haet {

/// A field grid's geometry and kernel, in runtime form (the scenario's [[fields]] block, world/build.cpp).
template <int D>
struct CgGridSpec {
    int nAxes = 1;                      ///< grid axes, 1..D
    std::array<int, 3> axis{2, 0, 1};   ///< the box axis of each grid axis
    std::array<int, 3> cells{1, 1, 1};  ///< cells along each grid axis
    Vec<D> lo, hi;                      ///< the region [m]
    std::array<bool, 3> wraps{};        ///< per box axis: periodic and the region spans the box (the kernel wraps)
    /// Per box axis: the box's length when the axis is periodic and the region covers only part of it (then a
    /// particle's and a branch's periodic images count where they reach into the region); 0 otherwise [m].
    std::array<double, 3> period{};
    CgKernelKind kernel = CgKernelKind::Gaussian;
    double width = 0;   ///< [m] (cg_kernel.hpp)
    double cutoff = 3;  ///< Gaussian cut-off in widths
    /// Gauss-Legendre nodes along a branch vector on grids of 2 or 3 axes (1-axis grids integrate it exactly).
    int branchNodes = 3;
};

/// The channels a grid sums, each a block of `cells` values: scalars, then vectors, then D x D tensors (row-major).
enum CgChannel : int {
    kCgMass = 0,   ///< sum m [kg]
    kCgVolume,     ///< sum of particle volumes (2D: areas) [m^D]
    kCgTdmVolume,  ///< the same over the time-driven particles (the hybrid's mode fraction)
    kCgMomentum,   ///< D components: sum m v [kg m/s]
    kCgScalarEnd = kCgMomentum,
};

template <int D>
struct CgLayout {
    static constexpr int kMomentum = kCgMomentum;
    static constexpr int kMvv = kMomentum + D;           ///< D*D: sum m v v [J]
    static constexpr int kContact = kMvv + D * D;        ///< D*D: sum f (x) b, force times branch [J]
    static constexpr int kCollision = kContact + D * D;  ///< D*D: sum dp (x) b over collisions [J s]
    static constexpr int kChannels = kCollision + D * D;
    static constexpr int kSampled = kCollision;  ///< channels that are per sample (collisions are per window)
};

/// The fields of one output of a grid, per cell (row-major D x D tensors; compressive stress positive).
template <int D>
struct CgFields {
    std::size_t cells = 0;
    std::vector<double> density;            ///< [kg/m^D]
    std::vector<double> volumeFraction;     ///< [-]
    std::vector<double> velocity;           ///< D per cell: momentum over density [m/s]
    std::vector<double> kineticStress;      ///< D*D per cell [Pa] (2D: N/m)
    std::vector<double> temperature;        ///< trace of the kinetic stress / (D density) [m^2/s^2]
    std::vector<double> contactStress;      ///< D*D per cell [Pa]
    std::vector<double> collisionalStress;  ///< D*D per cell [Pa]
    std::vector<double> stress;             ///< D*D: kinetic + contact + collisional [Pa]
    std::vector<double> modeFraction;       ///< the time-driven share of the volume [-]
};

template <int D>
class CgGrid {
public:
    using L = CgLayout<D>;
    explicit CgGrid(const CgGridSpec<D>& spec);

    const CgGridSpec<D>& spec() const { return spec_; }
    std::size_t cellCount() const { return ncells_; }
    double cellVolume() const { return cellVolume_; }  ///< [m^D]
    /// The centre of cell c along grid axis a [m].
    double cellCentre(int a, int c) const { return spec_.lo[spec_.axis[a]] + (c + 0.5) * h_[a]; }

    /// One particle at x: its mass, volume, whether time-driven, velocity.
    void addParticle(const Vec<D>& x, double mass, double volume, bool tdm, const Vec<D>& v);
    /// One contact: force f on the particle at x, branch b (the force is spread along x -> x - b).
    void addContact(const Vec<D>& x, const Vec<D>& b, const Vec<D>& f) { addSegment(x, b, f, L::kContact); }
    /// One collision's impulse dp on the particle at x, branch b.
    void addCollision(const Vec<D>& x, const Vec<D>& b, const Vec<D>& dp) { addSegment(x, b, dp, L::kCollision); }
    /// One sample taken (the averages divide the sampled channels by the samples' count).
    void endSample() { ++samples_; }

    std::uint64_t samples() const { return samples_; }
    /// The sums, channel by channel ([channel * cells + cell]).
    const std::vector<double>& sums() const { return sum_; }
    std::vector<double>& sums() { return sum_; }
    void setSamples(std::uint64_t n) { samples_ = n; }

    /// The fields from the sums: the sampled channels averaged over the samples, the collisions' impulses over
    /// `window` [s] (0: no collisional stress).
    CgFields<D> fields(double window) const;
    /// The sums cleared for the next window.
    void clear();

private:
    /// The shares of a point at coordinate p (box axis of grid axis a): cells and shares, wrapped on a periodic
    /// axis, cut to the grid otherwise.
    void pointShares(int a, double p, std::vector<std::pair<int, double>>& out) const;
    /// The same averaged over a segment from p to p - db.
    void segmentShares(int a, double p, double db, std::vector<std::pair<int, double>>& out) const;
    /// Whether x lies in the region along the box axes not in the grid.
    bool inTransverse(const Vec<D>& x) const;
    /// The part [s0, s1] of the segment x -> x - b inside the region along the axes not in the grid.
    bool transverseClip(const Vec<D>& x, const Vec<D>& b, double& s0, double& s1) const;
    void addSegment(const Vec<D>& x, const Vec<D>& b, const Vec<D>& f, int channel);
    void addParticleImage(const Vec<D>& x, const double* values);
    void addSegmentImage(const Vec<D>& x, const Vec<D>& b, const Vec<D>& f, int channel);
    /// Calls add(image of x) for each periodic image (spec.period) of the extent [x + lo, x + hi] that reaches
    /// into the region (along grid axes widened by the kernel's support); x itself when no axis has a period.
    template <class Add>
    void forImages(const Vec<D>& x, const Vec<D>& lo, const Vec<D>& hi, Add add) const;
    /// Adds value * (outer product of the shares) to `count` channels starting at `channel`.
    void deposit(const std::vector<std::pair<int, double>>* shares, int channel, const double* values, int count,
                 double scale);

    CgGridSpec<D> spec_;
    std::vector<CgKernel1d> k_;
    std::array<double, 3> h_{};
    std::array<bool, D> inGrid_{};
    std::size_t ncells_ = 0;
    double cellVolume_ = 0;
    std::vector<double> sum_;
    std::uint64_t samples_ = 0;
    std::vector<std::pair<int, double>> sh_[3];
};

/// Gauss-Legendre nodes and weights on [0, 1] for n = 1..6 (weights sum to one).
void gaussLegendre01(int n, double* nodes, double* weights);

extern template class CgGrid<2>;
extern template class CgGrid<3>;

}  // namespace haet
