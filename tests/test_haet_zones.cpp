// Zone labelling of the hybrid (docs/physics.md A.2): volume fractions, smoothing, hysteresis, buffer, sticky zones.
#include <gtest/gtest.h>

#include <cmath>

#include "haet/zones.hpp"

namespace haet {
namespace {

constexpr double kPi = 3.14159265358979323846;

Domain<2> box2(double L, bool periodic) {
    Domain<2> d;
    d.lo = Vec<2>::zero();
    d.hi = Vec<2>::filled(L);
    d.periodic = {periodic, periodic};
    return d;
}

/// Fills the square [x0, x0 + w) x [y0, y0 + w) with disks of radius r on a square lattice of spacing 2r.
void fillBlock(Particles<2>& p, double x0, double y0, double w, double r) {
    for (double x = x0 + r; x < x0 + w; x += 2 * r)
        for (double y = y0 + r; y < y0 + w; y += 2 * r)
            p.add(Vec<2>{{x, y}}, Vec<2>::zero(), Ang<2>::zero(), r, 1.0, 0, p.size());
}

TEST(HaetZones, FractionOfAFullZoneIsTheLatticePacking) {
    Particles<2> p;
    fillBlock(p, 0.0, 0.0, 1.0, 0.05);  // square lattice: area fraction pi/4
    ZoneGrid<2> g(box2(4.0, false), {1.0, 0.45, 0.40, 1});
    g.relabel(p, {});
    EXPECT_NEAR(g.fraction(g.zoneOf(Vec<2>{{0.5, 0.5}})), kPi / 4, 1e-12);
    EXPECT_EQ(g.fraction(g.zoneOf(Vec<2>{{2.5, 2.5}})), 0.0);
}

TEST(HaetZones, DenseBlockWithBufferAndDiluteFarAway) {
    Particles<2> p;
    fillBlock(p, 4.0, 4.0, 2.0, 0.05);  // 2 x 2 zones fully packed in a 10 x 10 box of unit zones
    ZoneGrid<2> g(box2(10.0, false), {1.0, 0.45, 0.40, 1});
    g.relabel(p, {});
    // Centre of the block: smoothed over 3x3 zones of which 4 are full: 4/9 pi/4 = 0.349 < 0.45 -> not dense
    // on the raw block corners; the smoothed fraction of every block zone is the same, so nothing is dense.
    EXPECT_FALSE(g.dense(g.zoneOf(Vec<2>{{4.5, 4.5}})));
    // A larger block: its interior zones are dense, the buffer ring is time-driven, far zones are dilute.
    Particles<2> q;
    fillBlock(q, 3.0, 3.0, 4.0, 0.05);
    g.relabel(q, {});
    EXPECT_TRUE(g.dense(g.zoneOf(Vec<2>{{4.5, 4.5}})));
    EXPECT_TRUE(g.timeDriven(g.zoneOf(Vec<2>{{2.5, 4.5}})));   // outside the block, next to a dense zone
    EXPECT_FALSE(g.timeDriven(g.zoneOf(Vec<2>{{0.5, 0.5}})));  // far away
}

TEST(HaetZones, HysteresisKeepsADenseZoneUntilBelowPhiOff) {
    // One zone per box side of 3 (periodic, so smoothing averages 9 copies of the same zone: smoothed = raw).
    ZoneGrid<2> g(box2(3.0, true), {3.0, 0.45, 0.40, 0});
    auto withFraction = [&](double phi) {
        Particles<2> p;
        const double r = std::sqrt(phi * 9.0 / kPi);  // one disk of area phi * zone area
        p.add(Vec<2>{{1.5, 1.5}}, Vec<2>::zero(), Ang<2>::zero(), r, 1.0, 0, 0);
        return p;
    };
    g.relabel(withFraction(0.42), {});
    EXPECT_FALSE(g.dense(0));  // below phi_on
    g.relabel(withFraction(0.46), {});
    EXPECT_TRUE(g.dense(0));  // above phi_on
    g.relabel(withFraction(0.42), {});
    EXPECT_TRUE(g.dense(0));  // between: stays dense
    g.relabel(withFraction(0.39), {});
    EXPECT_FALSE(g.dense(0));  // below phi_off
    g.relabel(withFraction(0.0), {1});
    EXPECT_TRUE(g.dense(0));  // sticky
}

TEST(HaetZones, PeriodicBufferWraps3D) {
    Domain<3> d;
    d.lo = Vec<3>::zero();
    d.hi = Vec<3>::filled(5.0);
    d.periodic = {true, true, true};
    ZoneGrid<3> g(d, {1.0, 0.3, 0.25, 1});
    Particles<3> p;
    // a dense cube of 3x3x3 zones centred on zone (0,0,0), wrapping across the periodic faces
    for (double x = -1.0 + 0.05; x < 2.0; x += 0.1)
        for (double y = -1.0 + 0.05; y < 2.0; y += 0.1)
            for (double z = -1.0 + 0.05; z < 2.0; z += 0.1) {
                Vec<3> c{{x < 0 ? x + 5 : x, y < 0 ? y + 5 : y, z < 0 ? z + 5 : z}};
                p.add(c, Vec<3>::zero(), Ang<3>::zero(), 0.05, 1.0, 0, p.size());
            }
    g.relabel(p, {});
    // Lattice fraction pi/6 = 0.52. Smoothed: the centre zone 0.52, its face neighbours 2/3 of it (0.35, dense),
    // edge neighbours 4/9 of it (0.23, dilute).
    EXPECT_TRUE(g.dense(g.zoneOf(Vec<3>{{0.5, 0.5, 0.5}})));
    EXPECT_TRUE(g.dense(g.zoneOf(Vec<3>{{4.5, 0.5, 0.5}})));  // face neighbour across the periodic face
    EXPECT_FALSE(g.dense(g.zoneOf(Vec<3>{{1.5, 1.5, 0.5}})));
    EXPECT_TRUE(g.timeDriven(g.zoneOf(Vec<3>{{1.5, 1.5, 0.5}})));   // buffer
    EXPECT_TRUE(g.timeDriven(g.zoneOf(Vec<3>{{3.5, 4.5, 0.5}})));   // buffer of the wrapped face neighbour
    EXPECT_FALSE(g.timeDriven(g.zoneOf(Vec<3>{{2.5, 2.5, 0.5}})));  // beyond the buffer
}

/// The axis-by-axis smoothing and buffer against their definition zone by zone (every zone within the radius on
/// each axis, each once), on grids of 1 to 5 zones per axis, periodic and open, buffers 0 to 2.
template <int D>
void smoothingAndBufferMatchDefinition(std::uint32_t seed) {
    std::uint32_t state = seed;
    auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return state >> 8;
    };
    for (int trial = 0; trial < 40; ++trial) {
        Domain<D> d;
        d.lo = Vec<D>::zero();
        std::array<int, D> n;
        for (int k = 0; k < D; ++k) {
            n[k] = 1 + static_cast<int>(next() % 5);
            d.hi[k] = n[k];
            d.periodic[k] = next() % 2 == 0;
        }
        const int buffer = static_cast<int>(next() % 3);
        ZoneGrid<D> g(d, {1.0, 0.3, 0.25, buffer});
        std::vector<double> vol(static_cast<std::size_t>(g.count()));
        for (double& v : vol) v = next() % 3 == 0 ? 0.0 : (next() % 1000) / 1000.0;
        g.relabel(vol, {});
        auto coords = [&](int z) {
            std::array<int, D> c;
            for (int k = 0; k < D; ++k) c[k] = (z / g.stride(k)) % n[k];
            return c;
        };
        // zones within `radius` of z on every axis, each once
        auto around = [&](int z, int radius) {
            std::vector<int> out;
            const std::array<int, D> c = coords(z);
            for (int q = 0; q < g.count(); ++q) {
                const std::array<int, D> e = coords(q);
                bool in = true;
                for (int k = 0; k < D; ++k) {
                    int dist = std::abs(e[k] - c[k]);
                    if (d.periodic[k]) dist = std::min(dist, n[k] - dist);
                    in = in && dist <= radius;
                }
                if (in) out.push_back(q);
            }
            return out;
        };
        for (int z = 0; z < g.count(); ++z) {
            double sum = 0;
            const std::vector<int> nb = around(z, 1);
            for (const int q : nb) sum += vol[q];
            EXPECT_NEAR(g.smoothed(z), sum / static_cast<double>(nb.size()), 1e-14) << "trial " << trial;
            bool any = false;
            for (const int q : around(z, buffer)) any = any || g.dense(q);
            EXPECT_EQ(g.timeDriven(z), any) << "trial " << trial << " zone " << z;
        }
    }
}

TEST(HaetZones, SmoothingAndBufferMatchTheirDefinition2D) { smoothingAndBufferMatchDefinition<2>(7); }
TEST(HaetZones, SmoothingAndBufferMatchTheirDefinition3D) { smoothingAndBufferMatchDefinition<3>(8); }

}  // namespace
}  // namespace haet
