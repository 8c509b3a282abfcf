// Checkpoints of the engines themselves, for what no scenario reaches: the event-driven engine with neighbour
// shells (edm/shells.hpp; the scenario has no key for them), and a time-driven engine made with another skin than the
// saved one (as a resumed run's is, when the skin follows from particles an outlet has removed since). A run to T and
// the same run saved at T/2 (the World and the engine, as a checkpoint holds them), taken up by an engine made on a
// World loaded from those bytes, and run on to T: the same bits in every particle and the same counts of events.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "edm/engine.hpp"
#include "io/checkpoint.hpp"
#include "tdm/engine.hpp"
#include "test_edm_util.hpp"
#include "world/state.hpp"
#include "world_util.hpp"

namespace haet::testing {
namespace {

template <int D>
bool sameBits(const std::vector<Vec<D>>& a, const std::vector<Vec<D>>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec<D>)) == 0;
}

/// The gas run to T in one engine, and in two: saved at T/2, loaded into an engine made on a World built from the
/// same definition and the saved particles, run on to T.
template <int D>
void expectShellsResume(const GasSpec& g, double shell, double T) {
    SCOPED_TRACE(std::to_string(D) + "D, shell " + std::to_string(shell) + (g.periodic ? ", periodic" : ", walls"));
    const ContactSetup cs = edmContact(0.9, 0.3, 0.2, 1, 1e-3);
    EdmSettings s;
    s.shell = shell;
    World<D> whole = makeGas<D>(g, cs), first = whole;
    EdmEngine<D> one(whole, s);
    one.advanceEvents(T);
    one.synchronise(T);

    EdmEngine<D> before(first, s);
    before.advanceEvents(T / 2);  // stopped between calls: each particle at its own clock, as a checkpoint has it
    ByteWriter world, engine;
    saveWorld(world, first);
    before.saveState(engine);

    World<D> resumed = makeGas<D>(g, cs);
    ByteReader w1(world.bytes(), "WRLD");
    loadWorld(w1, resumed);
    EdmEngine<D> after(resumed, s);
    ByteReader w2(world.bytes(), "WRLD"), e(engine.bytes(), "ENGN");
    loadWorld(w2, resumed);  // as saved: making the engine wrapped it into the box
    after.loadState(e);
    after.advanceEvents(T);
    after.synchronise(T);

    EXPECT_GT(one.stats().shellExits, 100u);
    EXPECT_GT(one.stats().pairCollisions, 100u);
    EXPECT_EQ(after.events(), one.events());
    EXPECT_EQ(after.stats().shellExits, one.stats().shellExits);
    EXPECT_EQ(after.stats().listGrowths, one.stats().listGrowths);
    EXPECT_EQ(after.collisions(), one.collisions());
    EXPECT_TRUE(sameBits<D>(resumed.particles.x, whole.particles.x)) << "positions";
    EXPECT_TRUE(sameBits<D>(resumed.particles.v, whole.particles.v)) << "velocities";
    EXPECT_EQ(resumed.particles.image, whole.particles.image);
}

TEST(RestartEngines, EdmWithNeighbourShellsResumesBitForBit) {
    GasSpec g;
    g.n = 400;
    g.phi = 0.2;
    g.polydisperse = true;
    expectShellsResume<3>(g, 0.2, 6.0);
    expectShellsResume<2>(g, 0.7, 6.0);
    g.periodic = false;
    g.gravity = 1;
    expectShellsResume<3>(g, 0.2, 6.0);
}

// A checkpoint of an engine with shells is refused by one without, and the reverse: the lists are not guessed.
TEST(RestartEngines, ShellsAndCellCrossingsDoNotMix) {
    GasSpec g;
    g.n = 64;
    const ContactSetup cs = edmContact(0.9);
    EdmSettings with, without;
    with.shell = 0.2;
    World<3> a = makeGas<3>(g, cs), b = a;
    EdmEngine<3> ea(a, with), eb(b, without);
    ea.advanceEvents(1.0);
    ByteWriter saved;
    ea.saveState(saved);
    ByteReader in(saved.bytes(), "ENGN");
    EXPECT_THROW(eb.loadState(in), CheckpointError);
}

// 64 spheres fall onto a plane and settle; the engine that takes up the saved state was made with a thinner skin.
TEST(RestartEngines, TdmGoesOnWithTheSavedSkin) {
    World<3> base;
    base.domain = openBox<3>(0.05);
    base.domain.gravity = {0, 0, -9.81};
    for (int i = 0; i < 64; ++i) {
        const Vec<3> x{-0.015 + 0.01 * (i % 4), -0.015 + 0.01 * (i / 4 % 4), -0.043 + 0.01 * (i / 16)};
        base.particles.add(x, Vec<3>::zero(), Ang<3>::zero(), 0.0042 + 0.0001 * (i % 5), 2500, 0, i);
    }
    base.walls.push_back(Wall<3>::plane({0, 0, -0.05}, {0, 0, 1}, Vec<3>::zero(), 0));
    const Scenario sc = linearScenario(3, 0.5, 1e-3, 0.4, TangentialLaw::Spring);
    base.contact = buildContactSetup<3>(sc, statsOf(base.particles, 1));
    TdmSettings thick;
    thick.dt = 2e-5;
    thick.skin = 8e-4;
    TdmSettings thin = thick;
    thin.skin = 2e-4;
    const double T = 0.1;

    World<3> whole = base, first = base, resumed = base;
    TdmEngine<3> one(whole, thick);
    one.advanceTo(T);
    TdmEngine<3> before(first, thick);
    before.advanceTo(T / 2);
    ByteWriter world, engine;
    saveWorld(world, first);
    before.saveState(engine);
    ByteReader w1(world.bytes(), "WRLD");
    loadWorld(w1, resumed);
    TdmEngine<3> after(resumed, thin);
    ByteReader w2(world.bytes(), "WRLD"), e(engine.bytes(), "ENGN");
    loadWorld(w2, resumed);
    after.loadState(e);
    EXPECT_EQ(after.settings().skin, thick.skin);
    after.advanceTo(T);

    EXPECT_GE(one.forceStats().contacts, 48u);  // settled columns on the plane
    EXPECT_GT(one.rebuilds(), 3u);
    EXPECT_EQ(after.rebuilds(), one.rebuilds());
    EXPECT_TRUE(sameBits<3>(resumed.particles.x, whole.particles.x)) << "positions";
    EXPECT_TRUE(sameBits<3>(resumed.particles.v, whole.particles.v)) << "velocities";
}

}  // namespace
}  // namespace haet::testing
