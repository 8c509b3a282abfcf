// The coarse-graining of measure/ (docs/physics.md L): the kernels, and the grids' conservation: the density
// integrates to the mass in the region, the momentum density to its momentum, the contact stress to sum f (x) b,
// to round-off; the analytic branch integral against a many-point quadrature of the point shares.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "measure/cg_kernel.hpp"
#include "measure/field_grid.hpp"

namespace haet {
namespace {

TEST(CgKernel, CdfIsTheIntegralOfTheKernelAndIntegralOfCdf) {
    for (CgKernelKind kind : {CgKernelKind::Gaussian, CgKernelKind::Lucy}) {
        const CgKernel1d k(kind, 0.7, 3.0);
        const double r = k.support();
        EXPECT_EQ(k.cdf(-r), 0.0);
        EXPECT_EQ(k.cdf(r), 1.0);
        EXPECT_NEAR(k.cdf(0), 0.5, 1e-15);
        EXPECT_NEAR(k.cdfIntegral(r), r, 1e-14);
        EXPECT_EQ(k.cdfIntegral(-r), 0.0);
        double prev = 0;
        for (int q = -100; q <= 100; ++q) {
            const double x = r * q / 100.0, hstep = 1e-6;
            const double c = k.cdf(x);
            EXPECT_GE(c, prev);  // monotone
            prev = c;
            // I' = C (central difference)
            EXPECT_NEAR((k.cdfIntegral(x + hstep) - k.cdfIntegral(x - hstep)) / (2 * hstep), c, 1e-8) << x;
            // symmetric kernel: C(-x) = 1 - C(x)
            EXPECT_NEAR(k.cdf(-x), 1 - c, 1e-15);
        }
    }
    // The Gaussian's second moment is close to w^2 with the cut-off at 3 w (truncation removes 2.7 %).
    const CgKernel1d g(CgKernelKind::Gaussian, 1.0, 3.0);
    double m2 = 0;
    const int n = 20000;
    for (int q = 0; q < n; ++q) {
        const double a = -3 + 6.0 * q / n, b = -3 + 6.0 * (q + 1) / n, x = 0.5 * (a + b);
        m2 += x * x * (g.cdf(b) - g.cdf(a));
    }
    EXPECT_NEAR(m2, 0.9733, 2e-3);
    // Lucy: variance 2 w^2 / 21.
    const CgKernel1d l(CgKernelKind::Lucy, 1.0, 0.0);
    double l2 = 0;
    for (int q = 0; q < n; ++q) {
        const double a = -1 + 2.0 * q / n, b = -1 + 2.0 * (q + 1) / n, x = 0.5 * (a + b);
        l2 += x * x * (l.cdf(b) - l.cdf(a));
    }
    EXPECT_NEAR(l2, 2.0 / 21.0, 1e-6);
}

template <int D>
CgGridSpec<D> boxSpec(int nAxes, CgKernelKind kind, double width, bool periodic) {
    CgGridSpec<D> s;
    s.nAxes = nAxes;
    for (int a = 0; a < 3; ++a) s.axis[a] = (D - 1 + a) % D;  // z (2D: y) first
    s.cells = {13, 7, 5};
    for (int k = 0; k < D; ++k) {
        s.lo[k] = -1.0 + 0.25 * k;
        s.hi[k] = 2.0 + 0.5 * k;
        s.wraps[k] = periodic;
    }
    s.kernel = kind;
    s.width = width;
    s.cutoff = 3;
    return s;
}

template <int D>
void checkConservation(int nAxes, CgKernelKind kind, bool periodic) {
    const CgGridSpec<D> spec = boxSpec<D>(nAxes, kind, 0.15, periodic);
    CgGrid<D> g(spec);
    std::mt19937_64 rng(7 + nAxes);
    std::uniform_real_distribution<double> u(0, 1), vel(-2, 2);
    const double margin = periodic ? 0.0 : g.spec().width * 3 + 1e-9;
    double mass = 0;
    Vec<D> mom = Vec<D>::zero();
    double ft[D * D] = {};
    for (int i = 0; i < 300; ++i) {
        Vec<D> x, v, b, f;
        for (int k = 0; k < D; ++k) {
            const double lo = spec.lo[k] + margin + 0.1, hi = spec.hi[k] - margin - 0.1;
            x[k] = lo + (hi - lo) * u(rng);
            v[k] = vel(rng);
            b[k] = 0.05 * vel(rng);
            f[k] = vel(rng);
        }
        const double m = 0.5 + u(rng);
        g.addParticle(x, m, 0.1, i % 2 == 0, v);
        g.addContact(x, b, f);
        mass += m;
        mom += v * m;
        for (int a = 0; a < D; ++a)
            for (int c = 0; c < D; ++c) ft[a * D + c] += f[a] * b[c];
    }
    g.endSample();
    const CgFields<D> fl = g.fields(0);
    double m = 0;
    Vec<D> p = Vec<D>::zero();
    double cs[D * D] = {};
    for (std::size_t c = 0; c < fl.cells; ++c) {
        m += fl.density[c] * g.cellVolume();
        for (int a = 0; a < D; ++a) p[a] += fl.density[c] * fl.velocity[c * D + a] * g.cellVolume();
        for (int e = 0; e < D * D; ++e) cs[e] += fl.contactStress[c * D * D + e] * g.cellVolume();
    }
    EXPECT_NEAR(m, mass, 1e-12 * mass);
    for (int a = 0; a < D; ++a) EXPECT_NEAR(p[a], mom[a], 1e-12 * mass * 2);
    for (int e = 0; e < D * D; ++e) EXPECT_NEAR(cs[e], ft[e], 1e-12 * 300);
}

TEST(CgGrid, DensityMomentumAndContactStressIntegrateToTheirSums) {
    for (CgKernelKind kind : {CgKernelKind::Gaussian, CgKernelKind::Lucy})
        for (bool periodic : {false, true}) {
            for (int na = 1; na <= 2; ++na) checkConservation<2>(na, kind, periodic);
            for (int na = 1; na <= 3; ++na) checkConservation<3>(na, kind, periodic);
        }
}

// The analytic average of the point shares along a branch (1-axis grids) against the average of 20 000 points
// along it: the simple twin.
TEST(CgGrid, BranchIntegralEqualsQuadratureOfPointShares) {
    for (CgKernelKind kind : {CgKernelKind::Gaussian, CgKernelKind::Lucy}) {
        const CgGridSpec<3> spec = boxSpec<3>(1, kind, 0.2, false);
        CgGrid<3> exact(spec), quad(spec);
        const Vec<3> x{{0.5, 0.6, 0.3}}, b{{0.1, -0.2, 0.45}}, f{{1.0, 0.5, -2.0}};
        exact.addContact(x, b, f);
        const int n = 20000;
        for (int q = 0; q < n; ++q) {
            // Midpoint rule: point q of n along the branch, as a contact with a tiny branch whose stress is f (x) b /
            // n.
            const Vec<3> xq = x - b * ((q + 0.5) / n);
            quad.addContact(xq, b * 1e-12, f * (1e12 / n));
        }
        for (std::size_t c = 0; c < exact.cellCount(); ++c)
            for (int e = 0; e < 9; ++e) {
                const std::size_t at = (CgLayout<3>::kContact + e) * exact.cellCount() + c;
                EXPECT_NEAR(exact.sums()[at], quad.sums()[at], 1e-6) << c << " " << e;
            }
    }
}

// A zero width is the box: a region's averages (the series' stress of regions).
TEST(CgGrid, ZeroWidthCountsWholeParticlesAndClipsBranches) {
    CgGridSpec<3> s;
    s.nAxes = 1;
    s.axis = {2, 0, 1};
    s.cells = {1, 1, 1};
    s.lo = Vec<3>{{0, 0, 0}};
    s.hi = Vec<3>{{1, 1, 1}};
    s.width = 0;
    CgGrid<3> g(s);
    g.addParticle(Vec<3>{{0.5, 0.5, 0.5}}, 2.0, 0.1, true, Vec<3>{{1, 0, 0}});
    g.addParticle(Vec<3>{{0.5, 1.5, 0.5}}, 5.0, 0.1, true, Vec<3>{{1, 0, 0}});  // outside
    // A branch half inside along z (the grid axis) and a quarter inside along x (transverse).
    g.addContact(Vec<3>{{0.5, 0.5, 0.9}}, Vec<3>{{0, 0, -0.2}}, Vec<3>{{0, 0, -1}});
    g.addContact(Vec<3>{{0.9, 0.5, 0.5}}, Vec<3>{{-0.4, 0, 0}}, Vec<3>{{-1, 0, 0}});
    g.endSample();
    const CgFields<3> f = g.fields(0);
    EXPECT_DOUBLE_EQ(f.density[0], 2.0);
    EXPECT_NEAR(f.contactStress[8], 0.2 * 0.5, 1e-15);
    EXPECT_NEAR(f.contactStress[0], 0.4 * 0.25, 1e-15);
}

// A region over part of a periodic axis sees the periodic images: its cells equal those of a grid over the whole
// periodic box (which wraps) where the two overlap, for particles and branches that cross the box's face.
TEST(CgGrid, PartOfAPeriodicAxisSeesTheImages) {
    for (CgKernelKind kind : {CgKernelKind::Gaussian, CgKernelKind::Lucy}) {
        CgGridSpec<3> whole;
        whole.nAxes = 1;
        whole.axis = {0, 1, 2};
        whole.cells = {40, 1, 1};
        whole.lo = Vec<3>{{0, 0, 0}};
        whole.hi = Vec<3>{{10, 1, 1}};
        whole.wraps = {true, false, false};
        whole.kernel = kind;
        whole.width = 0.6;
        CgGridSpec<3> part = whole;  // [8, 10) and, by images, nothing more: cells 32..39 of the whole
        part.cells = {8, 1, 1};
        part.lo[0] = 8;
        part.wraps = {false, false, false};
        part.period = {10, 0, 0};
        CgGridSpec<3> low = part;  // [0, 3): cells 0..11 of the whole
        low.cells = {12, 1, 1};
        low.lo[0] = 0;
        low.hi[0] = 3;
        CgGrid<3> gw(whole), gp(part), gl(low);
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<double> u(0, 1), vel(-1, 1);
        for (int i = 0; i < 200; ++i) {
            // Near the face x = 0 = 10 (some a little outside, as between pair-list rebuilds).
            const double x0 = u(rng) < 0.5 ? -0.2 + 1.6 * u(rng) : 8.6 + 1.6 * u(rng);
            const Vec<3> x{{x0, u(rng), u(rng)}}, v{{vel(rng), vel(rng), vel(rng)}};
            const Vec<3> b{{0.9 * vel(rng), 0.1 * vel(rng), 0.1 * vel(rng)}}, f{{vel(rng), vel(rng), vel(rng)}};
            for (CgGrid<3>* g : {&gw, &gp, &gl}) {
                g->addParticle(x, 1.0, 0.5, true, v);
                g->addContact(x, b, f);
            }
        }
        const std::vector<double>&w = gw.sums(), &p = gp.sums(), &l = gl.sums();
        for (int ch = 0; ch < CgLayout<3>::kChannels; ++ch) {
            for (int c = 0; c < 8; ++c)
                EXPECT_NEAR(p[ch * 8 + c], w[ch * 40 + 32 + c], 1e-12) << "channel " << ch << " cell " << c;
            for (int c = 0; c < 12; ++c)
                EXPECT_NEAR(l[ch * 12 + c], w[ch * 40 + c], 1e-12) << "channel " << ch << " cell " << c;
        }
    }
    // Across the axis: a box region [0, 5) of a periodic x of length 10, profiles over z. A particle at x = -0.1
    // (the image 9.9 is outside) is outside; one at 10.2 is inside as 0.2; a branch from 9.8 to 10.3 lies 0.3 of
    // 0.5 inside.
    CgGridSpec<3> s;
    s.nAxes = 1;
    s.axis = {2, 0, 1};
    s.cells = {1, 1, 1};
    s.lo = Vec<3>{{0, 0, 0}};
    s.hi = Vec<3>{{5, 1, 1}};
    s.period = {10, 0, 0};
    s.width = 0;
    CgGrid<3> g(s);
    g.addParticle(Vec<3>{{-0.1, 0.5, 0.5}}, 2.0, 0.1, true, Vec<3>::zero());
    g.addParticle(Vec<3>{{10.2, 0.5, 0.5}}, 3.0, 0.1, true, Vec<3>::zero());
    g.addContact(Vec<3>{{9.8, 0.5, 0.5}}, Vec<3>{{-0.5, 0, 0}}, Vec<3>{{-1, 0, 0}});
    g.endSample();
    const CgFields<3> f = g.fields(0);
    EXPECT_DOUBLE_EQ(f.density[0] * 5, 3.0);
    EXPECT_NEAR(f.contactStress[0] * 5, 0.5 * 0.6, 1e-15);
}

}  // namespace
}  // namespace haet
