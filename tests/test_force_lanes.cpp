// The force loop's contact law on four touching pairs at once in lanes (core/lanes.hpp) against the same loop
// evaluating them one by one: the same forces, torques, springs and statistics to the last bit, for every normal
// law, with one and two threads, in 2D and 3D. The scene is a hot frictional gas of two materials between walls
// (examples/confined_gas*.toml with a second material), stepped a while first so that contacts carry springs and
// some slide.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "physics_util.hpp"
#include "scenario/loader.hpp"
#include "scenario_text.hpp"
#include "tdm/engine.hpp"
#include "tdm/forces.hpp"
#include "world/build.hpp"

namespace haet {
namespace {

using testing::replaced;
using testing::sameBits;

/// confined_gasXd.toml with 500 fewer particles, and 500 of a second material (other friction and restitution, other
/// sizes). dense: the first 2 500 on a square (cubic) lattice of touching disks (spheres), spacing one diameter, under
/// the hot start, so that most of them touch a neighbour: blocks with many touching pairs (the 2D law takes eight at a
/// time when a block has them).
Scenario twoMaterialGas(const char* name, bool dense = false) {
    const std::filesystem::path file = std::filesystem::path(HAET_SOURCE_DIR) / "examples" / name;
    std::ifstream in(file);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = replaced(ss.str(), "[contact]", R"([materials.rubber]
density = 1200
restitution = 0.6
friction = 0.9

[contact])");
    if (dense)
        text = replaced(text, "arrangement = \"random\"\ncount = 3000\nradius = [0.0009, 0.0011]",
                        "arrangement = \"lattice\"\ncount = 2500\nradius = 0.001\nspacing = 0.002");
    else
        text = replaced(text, "count = 3000", "count = 2500");
    text += R"(
[[insert]]
arrangement = "random"
count = 500
radius = [0.0008, 0.0012]
material = "rubber"
temperature = 0.1
)";
    return parseScenario(text, file);
}

/// oneLaw: every material pair gets the first pair's coefficients, so the lanes take the table's first entry for
/// every contact (uniformForceLaw) while the one-by-one loop still looks each pair's entry up.
template <int D, class Normal>
void expectLanesMatchOneByOne(const Scenario& sc, int threads, bool oneLaw = false, std::size_t minContacts = 40) {
    World<D> w = buildWorld<D>(sc);
    ASSERT_EQ(w.contact.nMaterials, 2);
    TdmEngine<D> eng(w, tdmSettings<D>(sc, w));
    for (int k = 0; k < 300; ++k) eng.step();
    ContactSetup cs = w.contact;
    // The Hertz laws get coefficients of their own (the scene's are linear), different per material pair.
    for (std::size_t m = 0; m < cs.table.size(); ++m) {
        cs.table[m].hertzK = 2e8 * (1.0 + 0.5 * double(m));
        cs.table[m].dissipationTime = 1e-6 * (1.0 + double(m));
        cs.table[m].tsujiAlpha = 0.2 + 0.1 * double(m);
    }
    if (oneLaw)
        for (PairCoeffs& c : cs.table) c = cs.table[0];
    cs.wallTable = cs.table;  // the walls' contacts with the same Hertz coefficients
    ASSERT_EQ(uniformForceLaw(cs.table.data(), cs.table.size()), oneLaw);
    const int before = omp_get_max_threads();
    omp_set_num_threads(threads);
    auto run = [&](auto lanes, Particles<D>& p, PairList<D>& pl, std::vector<Vec<D>>& wh) {
        p = w.particles;
        pl = eng.pairs();
        wh.assign(p.tdmCount() * w.walls.size(), Vec<D>::zero());
        // Walls carry springs too: a first evaluation makes them, the second is compared.
        ForceScratch<D> s;
        auto none = [](std::size_t, const Vec<D>&, const Ang<D>&) {};
        computeForces<D, Normal, SpringTangential, decltype(lanes)::value>(
            p, pl, w.walls, wh, cs, w.domain, w.time, 1e-6, w.particles.v.data(), w.particles.w.data(), s, none);
        return computeForces<D, Normal, SpringTangential, decltype(lanes)::value>(
            p, pl, w.walls, wh, cs, w.domain, w.time, 1e-6, w.particles.v.data(), w.particles.w.data(), s, none);
    };
    Particles<D> pa, pb;
    PairList<D> la, lb;
    std::vector<Vec<D>> wa, wb;
    const ForceStats a = run(std::true_type{}, pa, la, wa);
    const ForceStats b = run(std::false_type{}, pb, lb, wb);
    omp_set_num_threads(before);
    EXPECT_GT(a.contacts, minContacts) << "few contacts: the test would prove little";
    EXPECT_EQ(a.contacts, b.contacts);
    EXPECT_EQ(std::memcmp(&a.virial, &b.virial, sizeof(double)), 0) << a.virial << " " << b.virial;
    EXPECT_EQ(std::memcmp(&a.maxOverlapRatio, &b.maxOverlapRatio, sizeof(double)), 0);
    EXPECT_EQ(a.worstParticle, b.worstParticle);
    EXPECT_EQ(a.nonFinite, b.nonFinite);
    EXPECT_TRUE(sameBits(pa.f, pb.f));
    EXPECT_TRUE(sameBits(pa.torque, pb.torque));
    EXPECT_TRUE(sameBits(la.history, lb.history));
    EXPECT_TRUE(sameBits(wa, wb));
    // The touching pairs carry springs (their law ran, not only the contact test).
    std::size_t springs = 0;
    for (const Vec<D>& h : la.history) springs += norm2(h) > 0;
    EXPECT_GT(springs, minContacts);
}

TEST(ForceLanes, LinearSameBitsAsOneByOne3D) {
    const Scenario sc = twoMaterialGas("confined_gas3d.toml");
    expectLanesMatchOneByOne<3, LinearNormal>(sc, 1);
    expectLanesMatchOneByOne<3, LinearNormal>(sc, 2);
}

TEST(ForceLanes, LinearSameBitsAsOneByOne2D) {
    const Scenario sc = twoMaterialGas("confined_gas2d.toml");
    expectLanesMatchOneByOne<2, LinearNormal>(sc, 1);
    expectLanesMatchOneByOne<2, LinearNormal>(sc, 2);
}

TEST(ForceLanes, DensePackingSameBitsAsOneByOne2D) {
    const Scenario sc = twoMaterialGas("confined_gas2d.toml", true);
    expectLanesMatchOneByOne<2, LinearNormal>(sc, 1, false, 1500);
    expectLanesMatchOneByOne<2, HertzViscoNormal>(sc, 2, false, 1500);
}

TEST(ForceLanes, DensePackingSameBitsAsOneByOne3D) {
    const Scenario sc = twoMaterialGas("confined_gas3d.toml", true);
    expectLanesMatchOneByOne<3, LinearNormal>(sc, 1, false, 1000);
    expectLanesMatchOneByOne<3, HertzTsujiNormal>(sc, 2, false, 1000);
}

TEST(ForceLanes, HertzSameBitsAsOneByOne) {
    const Scenario s3 = twoMaterialGas("confined_gas3d.toml");
    expectLanesMatchOneByOne<3, HertzViscoNormal>(s3, 1);
    expectLanesMatchOneByOne<3, HertzTsujiNormal>(s3, 2);
    const Scenario s2 = twoMaterialGas("confined_gas2d.toml");
    expectLanesMatchOneByOne<2, HertzViscoNormal>(s2, 2);
    expectLanesMatchOneByOne<2, HertzTsujiNormal>(s2, 1);
}

TEST(ForceLanes, OneLawForAllPairsSameBitsAsOneByOne) {
    expectLanesMatchOneByOne<3, LinearNormal>(twoMaterialGas("confined_gas3d.toml"), 1, true);
    expectLanesMatchOneByOne<2, LinearNormal>(twoMaterialGas("confined_gas2d.toml"), 2, true);
}

// A non-finite velocity reaches the forces of the particle and its partners in the same evaluation, an infinite
// position the particle's own test: the pass reports the first particle concerned, in both ways of evaluating.
TEST(ForceLanes, NonFiniteStateIsReported) {
    const Scenario sc = twoMaterialGas("confined_gas3d.toml");
    World<3> w = buildWorld<3>(sc);
    TdmEngine<3> eng(w, tdmSettings<3>(sc, w));
    for (int k = 0; k < 100; ++k) eng.step();
    const PairList<3>& pairs = eng.pairs();
    std::size_t touching = ForceStats::kNone;  // owner of the first pair with a spring
    for (std::size_t i = 0; i + 1 < pairs.first.size() && touching == ForceStats::kNone; ++i)
        for (std::uint32_t k = pairs.first[i]; k < pairs.first[i + 1]; ++k)
            if (norm2(pairs.history[k]) > 0) touching = i;
    ASSERT_NE(touching, ForceStats::kNone);
    const std::size_t last = w.particles.tdmCount() - 1;
    for (int kind = 0; kind < 2; ++kind) {
        auto run = [&](auto lanes) {
            Particles<3> p = w.particles;
            if (kind == 0)
                p.v[touching][1] = std::numeric_limits<double>::quiet_NaN();
            else
                p.x[last][2] = std::numeric_limits<double>::infinity();
            PairList<3> pl = pairs;
            std::vector<Vec<3>> wh(p.tdmCount() * w.walls.size(), Vec<3>::zero());
            ForceScratch<3> s;
            auto none = [](std::size_t, const Vec<3>&, const Ang<3>&) {};
            return computeForces<3, LinearNormal, SpringTangential, decltype(lanes)::value>(
                p, pl, w.walls, wh, w.contact, w.domain, w.time, 1e-6, p.v.data(), p.w.data(), s, none);
        };
        const ForceStats a = run(std::true_type{}), b = run(std::false_type{});
        EXPECT_EQ(a.nonFinite, b.nonFinite);
        if (kind == 0)
            EXPECT_LE(a.nonFinite, touching);
        else
            EXPECT_EQ(a.nonFinite, last);
    }
}

TEST(ForceLanes, UniformForceLawComparesTheForceCoefficientsOnly) {
    PairCoeffs a;
    a.knConst = 2e5;
    a.gtPerMeff = 25;
    a.mu = 0.5;
    std::vector<PairCoeffs> t(4, a);
    EXPECT_TRUE(uniformForceLaw(t.data(), t.size()));
    t[3].restitution = 0.3;  // the collision operator's view, not the force law
    t[3].beta0 = 0.2;
    EXPECT_TRUE(uniformForceLaw(t.data(), t.size()));
    t[2].mu = 0.6;
    EXPECT_FALSE(uniformForceLaw(t.data(), t.size()));
    t[2].mu = 0.5;
    t[1].knConst = std::nextafter(2e5, 1e6);  // the next double: not the same bits
    EXPECT_FALSE(uniformForceLaw(t.data(), t.size()));
    EXPECT_TRUE(uniformForceLaw(t.data(), 1));
}

}  // namespace
}  // namespace haet
