// The event-driven engine: fast engine against the brute-force reference (same event sequence), conservation,
// periodic wrapping, moving walls, frozen particles, the TC model and the collapse guard.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "tdm/engine.hpp"
#include "test_edm_util.hpp"

namespace haet {
namespace {

using testing::edmContact;
using testing::GasSpec;
using testing::kineticEnergyEdm;
using testing::makeGas;

struct LoggedCollision {
    double time;
    std::uint32_t a, b;  // a < b for pairs; b = wall index for walls
    bool wall;
};

template <int D>
std::vector<LoggedCollision> runLogged(World<D> w, const EdmSettings& s, double tEnd, EdmStats* stats = nullptr) {
    std::vector<LoggedCollision> log;
    EdmEngine<D> eng(w, s);
    eng.setObserver([&](const EdmCollision<D>& c) {
        if (c.wall)
            log.push_back({c.time, c.i, c.partner, true});
        else
            log.push_back({c.time, std::min(c.i, c.partner), std::max(c.i, c.partner), false});
    });
    eng.advanceTo(tEnd);
    if (stats) *stats = eng.stats();
    return log;
}

/// Time of the minCollisions-th collision of the fast engine (a run stopped by its observer).
template <int D>
double timeForCollisions(World<D> w, const EdmSettings& s, std::size_t minCollisions) {
    struct Stop {
        double t;
    };
    EdmEngine<D> eng(w, s);
    std::size_t count = 0;
    eng.setObserver([&](const EdmCollision<D>& c) {
        if (++count == minCollisions) throw Stop{c.time};
    });
    try {
        eng.advanceTo(1e6);
    } catch (const Stop& stop) {
        return stop.t;
    }
    return 1e6;
}

/// The fast engine and the reference twin process the same collisions in the same order at the same times; the
/// fast engine with cell crossings and with neighbour shells of two thicknesses. All run with one advanceTo: the
/// synchronisation at its end changes the stored states' last bits, after which events pending from before would
/// differ from fresh predictions in the last bits.
/// Returns the number of neighbour-list enlargements in the shell runs.
template <int D>
std::uint64_t compareWithReference(const World<D>& w, EdmSettings s, std::size_t minCollisions) {
    s.reference = false;
    s.shell = 0;
    const double tEnd = std::nextafter(timeForCollisions(w, s, minCollisions), kNever);
    s.reference = true;
    const auto ref = runLogged(w, s, tEnd);
    EXPECT_GE(ref.size(), minCollisions);
    s.reference = false;
    std::uint64_t growths = 0;
    const double cellSize = s.cellSize;  // for the cell crossings; shells take their own default
    for (const double shell : {0.0, 0.2, 0.7}) {
        SCOPED_TRACE(shell == 0 ? std::string("cell crossings") : "neighbour shells " + std::to_string(shell));
        s.shell = shell;
        s.cellSize = shell > 0 ? 0 : cellSize;
        EdmStats st;
        const auto fast = runLogged(w, s, tEnd, &st);
        growths += st.listGrowths;
        EXPECT_EQ(st.shellExits > 0, shell > 0);
        std::size_t exact = 0;
        for (std::size_t k = 0; k < std::min(ref.size(), fast.size()); ++k) {
            const bool same = fast[k].wall == ref[k].wall && fast[k].a == ref[k].a && fast[k].b == ref[k].b &&
                              std::abs(fast[k].time - ref[k].time) <= 1e-9 * std::abs(ref[k].time);
            if (!same) {
                ADD_FAILURE() << "collision " << k << " differs: fast (" << fast[k].a << ", " << fast[k].b << ", wall "
                              << fast[k].wall << ", t " << fast[k].time << "), reference (" << ref[k].a << ", "
                              << ref[k].b << ", wall " << ref[k].wall << ", t " << ref[k].time << ")";
                return growths;
            }
            exact += fast[k].time == ref[k].time;
        }
        EXPECT_EQ(fast.size(), ref.size());
        EXPECT_EQ(exact, ref.size()) << "times bit-identical";
    }
    return growths;
}

TEST(EdmEngine, MatchesReference2DPeriodicRoughElastic) {
    GasSpec g;
    g.n = 50;
    g.phi = 0.35;
    g.polydisperse = true;
    g.spin = 1;
    g.seed = 3;
    // Elastic and perfectly rough (a dissipative gas slows down too much for a long comparison)
    EdmSettings s;
    s.tcModel = false;
    s.tangential = EdmSettings::Tangential::Constant;
    compareWithReference<2>(makeGas<2>(g, edmContact(1.0, 0.0, 1.0)), s, 10000);
}

TEST(EdmEngine, MatchesReference3DPeriodicRoughElastic) {
    GasSpec g;
    g.n = 50;
    g.phi = 0.2;
    g.polydisperse = true;
    g.spin = 1;
    g.seed = 4;
    EdmSettings s;
    s.tcModel = false;
    s.tangential = EdmSettings::Tangential::Constant;
    compareWithReference<3>(makeGas<3>(g, edmContact(1.0, 0.0, 1.0)), s, 10000);
}

// Seven or more cells per periodic axis: a crossing scans only the new neighbour cells and recomputes the time of the
// event it keeps (with the partner's minimum image); with fewer cells it scans them all.
TEST(EdmEngine, MatchesReference3DPeriodicPartialScans) {
    GasSpec g;
    g.n = 110;
    g.phi = 0.15;
    g.spin = 1;
    g.seed = 6;
    EdmSettings s;
    s.tcModel = false;
    s.tangential = EdmSettings::Tangential::Constant;
    s.cellSize = 2 * g.radius;  // one diameter (the default for this dilute gas without gravity is coarser)
    World<3> w = makeGas<3>(g, edmContact(1.0, 0.0, 1.0));
    {
        World<3> probe = w;
        const EdmEngine<3> eng(probe, s);
        for (int k = 0; k < 3; ++k) ASSERT_GE(eng.cellDims()[k], 7);
    }
    compareWithReference<3>(w, s, 4000);
}

// A dilute gas without gravity gets cells coarser than a diameter by default (2.5 per particle), with partial scans.
TEST(EdmEngine, MatchesReference3DPeriodicCoarseCells) {
    GasSpec g;
    g.n = 250;
    g.phi = 0.08;
    g.seed = 7;
    EdmSettings s;
    s.tcModel = false;
    World<3> w = makeGas<3>(g, edmContact(1.0));
    {
        World<3> probe = w;
        const EdmEngine<3> eng(probe, s);
        ASSERT_GT(eng.cellSize(), 1.2 * 2 * g.radius);
        for (int k = 0; k < 3; ++k) ASSERT_GE(eng.cellDims()[k], 7);
    }
    compareWithReference<3>(w, s, 4000);
}

TEST(EdmEngine, MatchesReference2DWalledGravity) {
    GasSpec g;
    g.n = 50;
    g.phi = 0.25;
    g.polydisperse = true;
    g.periodic = false;
    g.gravity = 1.0;
    g.speed = 2;
    g.seed = 5;
    EdmSettings s;
    s.tcTime = 1e-3;
    compareWithReference<2>(makeGas<2>(g, edmContact(0.8, 0.4, 0.6)), s, 10000);
}

TEST(EdmEngine, MatchesReference3DMixedGravityFrozen) {
    GasSpec g;
    g.n = 50;
    g.phi = 0.2;
    g.polydisperse = true;
    g.periodic = true;
    g.gravity = 1.0;
    g.speed = 2;
    g.seed = 6;
    World<3> w = makeGas<3>(g, edmContact(0.9, 0.3, 0.5));
    // periodic in x, y; a floor and a ceiling along z; the lowest layer of particles frozen as obstacles
    w.domain.periodic[2] = false;
    const double L = w.domain.hi[2];
    w.walls.push_back(Wall<3>::plane(Vec<3>::zero(), Vec<3>{{0, 0, 1}}, Vec<3>::zero(), 0));
    w.walls.push_back(Wall<3>::plane(Vec<3>::filled(L), Vec<3>{{0, 0, -1}}, Vec<3>::zero(), 0));
    for (int i = 0; i < 9; ++i) {
        w.particles.flags[i] |= kFrozen;
        w.particles.invMass[i] = 0;
        w.particles.invInertia[i] = 0;
        w.particles.v[i] = Vec<3>::zero();
    }
    EdmSettings s;
    s.tcTime = 1e-3;
    compareWithReference<3>(w, s, 10000);
}

// A gas falling onto a floor packs densely: the neighbour lists outgrow the rows made at the start and are
// rebuilt longer in the middle of the run, and the events stay those of the reference.
TEST(EdmEngine, MatchesReferenceWhileListsGrow) {
    GasSpec g;
    g.n = 64;
    g.phi = 0.1;
    g.periodic = false;
    g.gravity = 20.0;
    g.speed = 0.5;
    g.seed = 8;
    EdmSettings s;
    s.tcTime = 1e-3;
    EXPECT_GT(compareWithReference<3>(makeGas<3>(g, edmContact(0.7, 0.3, 0.4)), s, 10000), 0u);
}

// ---- conservation ----

template <int D>
void elasticGasEnergy(bool rough, std::uint64_t minCollisions) {
    GasSpec g;
    g.n = D == 3 ? 1000 : 900;
    g.phi = D == 3 ? 0.25 : 0.5;
    g.polydisperse = true;
    g.spin = rough ? 1 : 0;
    EdmSettings s;
    s.tangential = EdmSettings::Tangential::Constant;
    World<D> w = makeGas<D>(g, edmContact(1.0, 0.0, rough ? 1.0 : -1.0));
    EdmEngine<D> eng(w, s);
    const double e0 = kineticEnergyEdm(w.particles);
    double t = 0;
    while (eng.collisions() < minCollisions) {
        t += 1.0;
        eng.advanceTo(t);
        EXPECT_NEAR(kineticEnergyEdm(w.particles), e0, 1e-12 * e0) << "t = " << t;
    }
    ::testing::Test::RecordProperty("relative_energy_error", std::to_string(kineticEnergyEdm(w.particles) / e0 - 1));
    EXPECT_LT(testing::maxOverlapRatio(w), 1e-9);
}

TEST(EdmEngine, ElasticSmoothGasConservesEnergy3D) { elasticGasEnergy<3>(false, 100000); }
TEST(EdmEngine, ElasticRoughGasConservesEnergy2D) { elasticGasEnergy<2>(true, 100000); }

// A smooth pair (Walton's rule with mu = 0, whatever beta0; or a constant beta0 = -1) gets no tangential impulse: the
// spins stay exactly as they were (the engine neither reads nor writes them), translation conserves energy.
template <int D>
void smoothCollisionsKeepSpins(EdmSettings::Tangential rule, double beta0) {
    GasSpec g;
    g.n = D == 3 ? 300 : 400;
    g.phi = D == 3 ? 0.2 : 0.25;
    g.polydisperse = true;
    g.spin = 3;
    World<D> w = makeGas<D>(g, edmContact(1.0, 0.0, beta0));
    const std::vector<Ang<D>> w0 = w.particles.w;
    EdmSettings s;
    s.tangential = rule;
    EdmEngine<D> eng(w, s);
    const double e0 = kineticEnergyEdm(w.particles);
    for (double t = 1; eng.collisions() < 20000; t += 1) eng.advanceTo(t);
    ASSERT_EQ(w.particles.w.size(), w0.size());
    EXPECT_EQ(std::memcmp(w.particles.w.data(), w0.data(), w0.size() * sizeof(Ang<D>)), 0);
    EXPECT_NEAR(kineticEnergyEdm(w.particles), e0, 1e-12 * e0);
}

TEST(EdmEngine, SmoothCollisionsKeepSpinsWalton3D) {
    smoothCollisionsKeepSpins<3>(EdmSettings::Tangential::Walton, 0.4);
}
TEST(EdmEngine, SmoothCollisionsKeepSpinsConstant2D) {
    smoothCollisionsKeepSpins<2>(EdmSettings::Tangential::Constant, -1.0);
}

TEST(EdmEngine, MomentumConservedInPeriodicGas) {
    GasSpec g;
    g.n = 300;
    g.phi = 0.2;
    g.polydisperse = true;
    g.spin = 1;
    World<3> w = makeGas<3>(g, edmContact(0.7, 0.5, 0.3));
    EdmSettings s;
    s.tcModel = false;
    double scale = 0;  // of the initial state: the gas cools
    for (std::size_t i = 0; i < w.particles.size(); ++i) scale += w.particles.mass[i] * norm(w.particles.v[i]);
    EdmEngine<3> eng(w, s);
    for (double t = 1; eng.collisions() < 20000; t *= 1.5) eng.advanceTo(t);
    Vec<3> pm = Vec<3>::zero();
    for (std::size_t i = 0; i < w.particles.size(); ++i) pm += w.particles.v[i] * w.particles.mass[i];
    EXPECT_LT(norm(pm), 1e-12 * scale);
}

// ---- geometry: periodic images, moving walls, frozen particles ----

TEST(EdmEngine, PeriodicWrapRecordsImages) {
    World<2> w;
    w.contact = edmContact(1.0);
    w.domain.lo = Vec<2>::zero();
    w.domain.hi = Vec<2>{{10, 10}};
    w.domain.periodic = {true, true};
    w.particles.add(Vec<2>{{1, 1}}, Vec<2>{{3.3, -1.7}}, Ang<2>{{0.5}}, 0.5, 1.0, 0, 0);
    EdmEngine<2> eng(w, EdmSettings{});
    for (int k = 1; k <= 20; ++k) {
        eng.advanceTo(k * 1.0);
        const Vec<2> unwrapped = w.domain.unwrap(w.particles.x[0], w.particles.image[0]);
        EXPECT_NEAR(unwrapped[0], 1 + 3.3 * k, 1e-12);
        EXPECT_NEAR(unwrapped[1], 1 - 1.7 * k, 1e-12);
        EXPECT_GE(w.particles.x[0][0], 0);
        EXPECT_LT(w.particles.x[0][0], 10);
        EXPECT_EQ(w.particles.w[0][0], 0.5);  // free rotation: the spin stays
    }
    EXPECT_GT(eng.stats().cellCrossings, 50u);
    EXPECT_EQ(eng.collisions(), 0u);
}

// The wraps since the last synchronisation have 10 bits per axis in 3D: a particle that crosses a periodic face more
// than 510 times between synchronisations moves whole box lengths from its stored position into Particles::image.
TEST(EdmEngine, ManyWrapsBetweenSynchronisations) {
    World<3> w;
    w.contact = edmContact(1.0);
    w.domain.lo = Vec<3>::zero();
    w.domain.hi = Vec<3>{{2, 2, 2}};
    w.domain.periodic = {true, true, true};
    w.particles.add(Vec<3>{{0.5, 0.5, 0.5}}, Vec<3>{{3.1, -2.3, 0.7}}, Ang<3>::zero(), 0.25, 1.0, 0, 0);
    EdmEngine<3> eng(w, EdmSettings{});
    const double t = 800;  // 1240 wraps along x, 920 along y
    eng.advanceEvents(t);
    eng.synchronise(t);
    const Vec<3> unwrapped = w.domain.unwrap(w.particles.x[0], w.particles.image[0]);
    EXPECT_NEAR(unwrapped[0], 0.5 + 3.1 * t, 1e-9);
    EXPECT_NEAR(unwrapped[1], 0.5 - 2.3 * t, 1e-9);
    EXPECT_NEAR(unwrapped[2], 0.5 + 0.7 * t, 1e-9);
    for (int k = 0; k < 3; ++k) {
        EXPECT_GE(w.particles.x[0][k], 0);
        EXPECT_LT(w.particles.x[0][k], 2);
    }
    EXPECT_EQ(eng.positionAt(0, t), w.particles.x[0]);
    EXPECT_GT(eng.stats().cellCrossings, 2000u);
}

TEST(EdmEngine, PeriodicImagesCollide) {
    // two particles that meet only through the periodic boundary
    World<3> w;
    w.contact = edmContact(1.0);
    w.domain.lo = Vec<3>::zero();
    w.domain.hi = Vec<3>::filled(4);
    w.domain.periodic = {true, true, true};
    w.particles.add(Vec<3>{{0.6, 2, 2}}, Vec<3>{{-1, 0, 0}}, Ang<3>::zero(), 0.5, 1.0, 0, 0);
    w.particles.add(Vec<3>{{3.4, 2, 2}}, Vec<3>{{1, 0, 0}}, Ang<3>::zero(), 0.5, 1.0, 0, 1);
    EdmSettings s;
    EdmEngine<3> eng(w, s);
    eng.advanceTo(0.25);
    // gap through the boundary: 0.6 + (4 - 3.4) - 1 = 0.2, closing at 2 m/s -> contact at t = 0.1, then reversed
    EXPECT_EQ(eng.collisions(), 1u);
    EXPECT_NEAR(w.particles.v[0][0], 1, 1e-14);
    EXPECT_NEAR(w.particles.v[1][0], -1, 1e-14);
    EXPECT_NEAR(w.particles.x[0][0], 0.6 - 0.1 + 0.15, 1e-12);
    // virial r_ij . dp_i = sigma m_eff (1+e) |g_n| = 1 * 0.5 m * 2 * 2 (docs/physics.md E.2)
    const double m = w.particles.mass[0];
    EXPECT_NEAR(eng.takeCollisionVirial(), 2 * m, 1e-12 * m);
    EXPECT_EQ(eng.takeCollisionVirial(), 0.0);
}

TEST(EdmEngine, MovingWallPushesParticle) {
    World<3> w;
    w.contact = edmContact(1.0);
    w.domain.lo = Vec<3>::filled(-5);
    w.domain.hi = Vec<3>::filled(5);
    // piston at x = 1 moving with -1 m/s, normal -x; particle at rest at x = 0.5, radius 0.1: contact at t = 0.4
    w.walls.push_back(Wall<3>::plane(Vec<3>{{1, 0, 0}}, Vec<3>{{-1, 0, 0}}, Vec<3>{{-1, 0, 0}}, 0));
    w.particles.add(Vec<3>::zero() + Vec<3>{{0.5, 0, 0}}, Vec<3>::zero(), Ang<3>::zero(), 0.1, 1.0, 0, 0);
    EdmEngine<3> eng(w, EdmSettings{});
    eng.advanceTo(1.0);
    EXPECT_EQ(eng.collisions(), 1u);
    EXPECT_NEAR(w.particles.v[0][0], -2, 1e-14);  // elastic reflection off a wall moving at -1
    EXPECT_NEAR(w.particles.x[0][0], 0.5 - 2 * 0.6, 1e-12);
}

TEST(EdmEngine, FrozenParticlesNeverMove) {
    GasSpec g;
    g.n = 125;
    g.phi = 0.3;
    g.periodic = false;
    g.gravity = 2;
    World<3> w = makeGas<3>(g, edmContact(0.7, 0.5, 0.5));
    std::vector<Vec<3>> x0;
    for (int i = 0; i < 25; ++i) {  // the lowest lattice layer
        w.particles.flags[i] |= kFrozen;
        w.particles.invMass[i] = 0;
        w.particles.invInertia[i] = 0;
        x0.push_back(w.particles.x[i]);
    }
    EdmSettings s;
    s.tcTime = 1e-3;
    EdmEngine<3> eng(w, s);
    eng.advanceTo(3.0);
    for (int i = 0; i < 25; ++i) EXPECT_TRUE(w.particles.x[i] == x0[i]);
    EXPECT_LT(testing::maxOverlapRatio(w), 1e-9);
    EXPECT_LT(testing::maxWallPenetration(w), 1e-9);
    EXPECT_GT(eng.collisions(), 1000u);
}

// ---- inelastic collapse: the TC model and the guard ----

World<3> bouncingBall(double e) {
    World<3> w;
    w.contact = edmContact(e, 0.5, 0.5);
    w.domain.lo = Vec<3>::filled(-1);
    w.domain.hi = Vec<3>::filled(1);
    w.domain.gravity = Vec<3>{{0, 0, -9.81}};
    w.walls.push_back(Wall<3>::plane(Vec<3>{{0, 0, -1}}, Vec<3>{{0, 0, 1}}, Vec<3>::zero(), 0));
    w.particles.add(Vec<3>{{0, 0, 0}}, Vec<3>{{0.3, 0, 0}}, Ang<3>::zero(), 0.05, 1000, 0, 0);
    return w;
}

TEST(EdmEngine, CollapseWithoutTcModelIsReported) {
    World<3> w = bouncingBall(0.5);
    EdmSettings s;
    s.tcModel = false;
    s.maxEventRate = 1e5;
    EdmEngine<3> eng(w, s);
    EXPECT_THROW(eng.advanceTo(10.0), SimulationError);
}

TEST(EdmEngine, CollapseUnderDefaultBoundIsReported) {
    World<3> w = bouncingBall(0.5);
    EdmSettings s;
    s.tcModel = false;  // no TC time: the default bound 10^4 u / d_min catches the micro-bouncing
    EdmEngine<3> eng(w, s);
    EXPECT_THROW(eng.advanceTo(10.0), SimulationError);
}

TEST(EdmEngine, TcModelLetsBallSettle) {
    World<3> w = bouncingBall(0.5);
    EdmSettings s;
    s.tcTime = 1e-4;
    EdmEngine<3> eng(w, s);
    eng.advanceTo(10.0);
    // resting: hops of height g (2 tc)^2 / 8 above the floor, sliding stopped by friction
    const double h = w.particles.x[0][2] + 1 - 0.05;
    EXPECT_GE(h, -1e-12);
    EXPECT_LT(h, 9.81 * 4e-8 / 2);
    EXPECT_LT(std::abs(w.particles.v[0][2]), 9.81 * 2e-4);
    // rolling without sliding: g_t = v_x - a w_y -> 0 through the sticking collisions (beta0 = 0.5)
    EXPECT_LT(std::abs(w.particles.v[0][0] - 0.05 * w.particles.w[0][1]), 1e-6);
    EXPECT_NEAR(w.particles.v[0][0], 0.3 * 5 / 7, 0.02);
    EXPECT_GT(eng.stats().restHops, 1000u);
    EXPECT_LT(eng.events(), 10.0 / 1e-4 * 2);  // about one hop per 2 tc
}

// A pure event-driven run drops forces and torques from the store (Particles::dropTdmState): nothing in
// the run reads them, so positions, velocities and spins come out bit-identical, and the store is smaller.
TEST(EdmEngine, SameRunWithoutTdmState) {
    GasSpec g;
    g.n = 200;
    g.phi = 0.3;
    g.spin = 1;
    g.seed = 9;
    World<3> full = makeGas<3>(g, edmContact(0.9, 0.5, 0.4));
    World<3> lean = full;
    lean.particles.dropTdmState();
    EXPECT_FALSE(lean.particles.hasTdmState());
    EXPECT_TRUE(lean.particles.f.empty() && lean.particles.torque.empty() && lean.particles.angle.empty());
    EdmEngine<3> a(full, EdmSettings{}), b(lean, EdmSettings{});
    a.advanceTo(5.0);
    b.advanceTo(5.0);
    EXPECT_GT(a.collisions(), 1000u);
    EXPECT_EQ(a.collisions(), b.collisions());
    for (std::size_t i = 0; i < full.particles.size(); ++i) {
        EXPECT_EQ(full.particles.x[i], lean.particles.x[i]);
        EXPECT_EQ(full.particles.v[i], lean.particles.v[i]);
        EXPECT_EQ(full.particles.w[i], lean.particles.w[i]);
    }
    lean.particles.add(Vec<3>::zero(), Vec<3>::zero(), Ang<3>::zero(), 0.5, 1.0, 0, 999);
    EXPECT_TRUE(lean.particles.f.empty());
    lean.particles.swapEntries(0, lean.particles.size() - 1);
    EXPECT_THROW({ TdmEngine<3> t(lean, TdmSettings{}); }, std::invalid_argument);
}

// With holdState the engine is the only holder of positions, velocities and radii between synchronisations: the
// World's arrays are empty while events run and come back at synchronise, with the same run bit for bit (several
// windows of advanceEvents, frozen particles with a velocity of their own, periodic wraps into Particles::image).
TEST(EdmEngine, SameRunHoldingState) {
    GasSpec g;
    g.n = 216;
    g.phi = 0.3;
    g.spin = 1;
    g.seed = 11;
    g.gravity = 1;
    World<3> shared = makeGas<3>(g, edmContact(0.9, 0.5, 0.4));
    for (int i = 0; i < 6; ++i) {
        shared.particles.flags[i] |= kFrozen;
        shared.particles.invMass[i] = 0;
        shared.particles.invInertia[i] = 0;
        shared.particles.v[i] = Vec<3>{{0.1 * i, 0, 0}};
    }
    shared.particles.dropTdmState();
    World<3> held = shared;
    EdmSettings s;
    EdmEngine<3> a(shared, s);
    s.holdState = true;
    EdmEngine<3> b(held, s);
    for (int window = 1; window <= 4; ++window) {
        const double t = 0.5 * window;
        a.advanceEvents(t);
        b.advanceEvents(t);
        EXPECT_FALSE(held.particles.hasMotion());
        EXPECT_TRUE(held.particles.x.empty() && held.particles.v.empty() && held.particles.radius.empty());
        EXPECT_EQ(held.particles.size(), shared.particles.size());
        if (window % 2 == 0) continue;  // two windows without a synchronisation
        a.synchronise(t);
        b.synchronise(t);
        ASSERT_TRUE(held.particles.hasMotion());
        for (std::size_t i = 0; i < shared.particles.size(); ++i) {
            EXPECT_EQ(shared.particles.x[i], held.particles.x[i]);
            EXPECT_EQ(shared.particles.v[i], held.particles.v[i]);
            EXPECT_EQ(shared.particles.w[i], held.particles.w[i]);
            EXPECT_EQ(shared.particles.image[i], held.particles.image[i]);
            EXPECT_EQ(shared.particles.radius[i], held.particles.radius[i]);
        }
    }
    EXPECT_GT(a.collisions(), 1000u);
    EXPECT_EQ(a.collisions(), b.collisions());
    EXPECT_THROW(b.reset(), std::logic_error);  // the World's arrays are with the engine
    b.synchronise(held.time);
    b.reset();
    s.firstParticle = 1;
    EXPECT_THROW({ EdmEngine<3> c(shared, s); }, std::invalid_argument);
}

// Default cell edge: one diameter, or in a dilute 3D gas without gravity the edge of 2.5 cells per particle.
TEST(EdmEngine, DefaultCellsOfDiluteGas) {
    GasSpec g;
    g.n = 1000;
    g.phi = 0.1;
    g.seed = 3;
    World<3> w = makeGas<3>(g, edmContact(1.0));
    const double perParticle = (4.0 / 3.0) * M_PI * std::pow(g.radius, 3) / g.phi;
    {
        World<3> probe = w;
        const EdmEngine<3> eng(probe, EdmSettings{});
        EXPECT_NEAR(eng.cellSize(), std::cbrt(perParticle / 2.5), 0.15 * eng.cellSize());  // whole cells per axis
        EXPECT_GT(eng.cellSize(), 1.1 * 2 * g.radius);
        EXPECT_LE(eng.cellCount(), 2.5 * g.n);
    }
    g.phi = 0.3;  // denser: cells of one diameter
    {
        World<3> dense = makeGas<3>(g, edmContact(1.0));
        const EdmEngine<3> eng(dense, EdmSettings{});
        EXPECT_NEAR(eng.cellSize(), 2 * g.radius, 0.15 * g.radius);
    }
    w.domain.gravity[2] = -1;  // gravity: cells of one diameter, whatever the mean density
    const EdmEngine<3> eng(w, EdmSettings{});
    EXPECT_NEAR(eng.cellSize(), 2 * g.radius, 0.15 * g.radius);
}

// A particle joining the engine (from the time-driven side of a hybrid run) is checked as the constructor checks
// every particle: its material must be in the contact table.
TEST(EdmEngine, JoiningParticleNeedsAMaterialOfTheTable) {
    World<3> w = bouncingBall(0.5);
    w.particles.add(Vec<3>{{0.5, 0.5, 0.8}}, Vec<3>::zero(), Ang<3>::zero(), 0.05, 1000, 0, 1);
    EdmSettings s;
    s.firstParticle = 1;  // particle 0 belongs to another engine
    EdmEngine<3> eng(w, s);
    EXPECT_FALSE(eng.owns(0));
    w.particles.material[0] = static_cast<std::uint16_t>(w.contact.nMaterials);
    EXPECT_THROW(eng.add(0, 0.0), std::invalid_argument);
    EXPECT_FALSE(eng.owns(0));
    w.particles.material[0] = 0;
    eng.add(0, 0.0);
    EXPECT_TRUE(eng.owns(0));
}

TEST(EdmEngine, RejectsBadSettings) {
    World<3> w = bouncingBall(0.5);
    EdmSettings s;
    s.cellSize = 0.05;  // below the diameter 0.1
    EXPECT_THROW({ EdmEngine<3> e(w, s); }, std::invalid_argument);
    World<3> empty;
    EXPECT_THROW({ EdmEngine<3> e(empty, EdmSettings{}); }, std::invalid_argument);  // no contact table
    s = EdmSettings{};
    s.shell = -0.1;
    EXPECT_THROW({ EdmEngine<3> e(w, s); }, std::invalid_argument);
    s.shell = 0.2;
    s.cellSize = 0.11;  // below the diameter 0.1 plus the shell 0.02
    EXPECT_THROW({ EdmEngine<3> e(w, s); }, std::invalid_argument);
    s.cellSize = 0;
    EdmEngine<3> withShells(w, s);
    struct Silent final : EdmObserver<3> {
        void restart(const CellGrid<3>&) override {}
        void joined(std::uint32_t, std::uint32_t, double) override {}
        void left(std::uint32_t, std::uint32_t, double) override {}
        void crossed(std::uint32_t, std::uint32_t, std::uint32_t, double) override {}
        void tcCollision(std::uint32_t) override {}
    } observer;
    EXPECT_THROW({ EdmEngine<3> e(w, s, &observer); }, std::logic_error);  // an observer follows cell crossings
}

}  // namespace
}  // namespace haet
