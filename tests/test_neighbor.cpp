// The cell-grid pair list against its reference twin, all-pairs (2D and 3D, periodic and walled, polydisperse).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <tuple>

#include "neighbor/pair_list.hpp"

namespace haet {
namespace {

template <int D>
Particles<D> randomParticles(std::size_t n, const Domain<D>& dom, double rmin, double rmax, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    Particles<D> p;
    for (std::size_t i = 0; i < n; ++i) {
        Vec<D> x;
        for (int k = 0; k < D; ++k) x[k] = dom.lo[k] + u(rng) * (dom.hi[k] - dom.lo[k]);
        p.add(x, Vec<D>::zero(), Ang<D>::zero(), rmin + (rmax - rmin) * u(rng), 1000, 0, i, u(rng) < 0.1 ? kFrozen : 0);
    }
    return p;
}

template <int D>
std::set<std::tuple<std::uint32_t, std::uint32_t, int>> pairSet(const PairList<D>& l) {
    std::set<std::tuple<std::uint32_t, std::uint32_t, int>> s;
    for (std::size_t i = 0; i + 1 < l.first.size(); ++i)
        for (std::uint32_t k = l.first[i]; k < l.first[i + 1]; ++k) s.emplace(i, l.partner[k], l.shift[k]);
    return s;
}

template <int D>
void compareWithAllPairs(std::array<bool, D> periodic, double boxLen, unsigned seed) {
    Domain<D> dom;
    dom.lo = Vec<D>::zero();
    dom.hi = Vec<D>::filled(boxLen);
    dom.periodic = periodic;
    auto p = randomParticles<D>(D == 2 ? 1500 : 2000, dom, 0.01, 0.05, seed);
    NeighborSettings s{0.02, true};
    PairList<D> fast, ref;
    buildPairList(p, dom, s, PairList<D>{}, fast);
    buildAllPairs(p, dom, s, ref);
    ASSERT_GT(ref.size(), 100u);
    EXPECT_EQ(pairSet(fast), pairSet(ref));
}

TEST(Neighbor, CellListMatchesAllPairs3D) {
    compareWithAllPairs<3>({true, true, true}, 1.0, 1);
    compareWithAllPairs<3>({false, false, false}, 1.0, 2);
    compareWithAllPairs<3>({true, true, false}, 1.0, 3);
    compareWithAllPairs<3>({true, false, true}, 0.25, 4);  // fewer than 3 cells on an axis
}

TEST(Neighbor, CellListMatchesAllPairs2D) {
    compareWithAllPairs<2>({true, true}, 2.0, 5);
    compareWithAllPairs<2>({false, false}, 2.0, 6);
    compareWithAllPairs<2>({true, false}, 0.3, 7);
}

TEST(Neighbor, HistorySurvivesRebuildAndPermutation) {
    Domain<3> dom;
    dom.lo = Vec<3>::zero();
    dom.hi = Vec<3>::filled(1.0);
    dom.periodic = {true, true, true};
    auto p = randomParticles<3>(500, dom, 0.03, 0.05, 9);
    NeighborSettings s{0.02, false};
    PairList<3> a;
    buildPairList(p, dom, s, PairList<3>{}, a);
    // tag every pair with a history value that encodes its ids
    for (std::size_t i = 0; i < p.size(); ++i)
        for (std::uint32_t k = a.first[i]; k < a.first[i + 1]; ++k)
            a.history[k] = Vec<3>{{double(p.id[i]), double(p.id[a.partner[k]]), 1.0}};
    // reverse the particle order: every pair flips, so xi must change sign
    std::vector<std::uint32_t> order(p.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<std::uint32_t>(order.size() - 1 - k);
    p.permute(order);
    permutePairList(a, order);
    PairList<3> b;
    buildPairList(p, dom, s, a, b);
    std::size_t checked = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
        for (std::uint32_t k = b.first[i]; k < b.first[i + 1]; ++k) {
            const Vec<3>& h = b.history[k];
            // stored as (id_i, id_j, 1) for the old orientation: now i and j swapped, so negated
            EXPECT_EQ(h[0], -double(p.id[b.partner[k]]));
            EXPECT_EQ(h[1], -double(p.id[i]));
            EXPECT_EQ(h[2], -1.0);
            ++checked;
        }
    EXPECT_GT(checked, 100u);
}

/// The incremental update of a hybrid mode change against a full build: particles leave (the last TDM particle
/// takes a leaver's place) and new ones join at the end; the pairs must be those of a fresh build, each row sorted
/// by partner, and the history of kept pairs must follow its particles. Without leavers the kept particles keep
/// their numbers (the update's fast path).
template <int D>
void remapMatchesBuild(std::array<bool, D> periodic, unsigned seed, std::size_t joining, bool leave = true) {
    Domain<D> dom;
    dom.lo = Vec<D>::zero();
    dom.hi = Vec<D>::filled(1.0);
    dom.periodic = periodic;
    auto all = randomParticles<D>(D == 2 ? 1200 : 1500, dom, 0.01, 0.04, seed);
    const std::size_t n0 = all.size() - 100;  // the last 100 are outside the list at first; `joining` of them join
    all.nTdm = n0;
    NeighborSettings s{0.02, true};
    PairList<D> list;
    buildPairList(all, dom, s, PairList<D>{}, list);
    for (std::size_t i = 0; i < n0; ++i)
        for (std::uint32_t k = list.first[i]; k < list.first[i + 1]; ++k)
            list.history[k] = Vec<D>::filled(double(all.id[i]) * 10000 + double(all.id[list.partner[k]]));
    // 60 leave (every 17th), `joining` join (a few: tested against all; many: with a grid).
    std::vector<std::uint32_t> from(n0);
    for (std::size_t k = 0; k < n0; ++k) from[k] = static_cast<std::uint32_t>(k);
    std::size_t nT = n0;
    for (std::size_t d = 17 * 59; leave; d -= 17) {
        all.swapEntries(d, nT - 1);
        from[d] = from[nT - 1];
        from.pop_back();
        --nT;
        if (d == 0) break;
    }
    // the leavers now sit at [nT, n0); bring `joining` outsiders in front of them
    for (std::size_t k = 0; k < joining; ++k) {
        all.swapEntries(n0 + k, nT);
        from.push_back(0xFFFFFFFFu);
        ++nT;
    }
    all.nTdm = nT;
    remapPairList(all, dom, s, from, list);
    PairList<D> ref;
    buildPairList(all, dom, s, PairList<D>{}, ref);
    EXPECT_EQ(pairSet(list), pairSet(ref));
    for (std::size_t i = 0; i < nT; ++i)
        EXPECT_TRUE(std::is_sorted(list.partner.begin() + list.first[i], list.partner.begin() + list.first[i + 1]));
    std::size_t kept = 0;
    for (std::size_t i = 0; i < nT; ++i)
        for (std::uint32_t k = list.first[i]; k < list.first[i + 1]; ++k) {
            const double h = list.history[k][0];
            if (h == 0) continue;  // a pair with a new particle
            const double a = double(all.id[i]) * 10000 + double(all.id[list.partner[k]]);
            const double b = double(all.id[list.partner[k]]) * 10000 + double(all.id[i]);
            EXPECT_TRUE(h == a || h == -b) << "pair " << all.id[i] << "-" << all.id[list.partner[k]];
            ++kept;
        }
    EXPECT_GT(kept, 100u);
}

TEST(Neighbor, RemapAfterModeChangeMatchesBuild3D) {
    remapMatchesBuild<3>({true, true, true}, 21, 100);
    remapMatchesBuild<3>({false, true, false}, 22, 100);
    remapMatchesBuild<3>({true, true, true}, 25, 5);
    remapMatchesBuild<3>({true, false, true}, 27, 100, false);
    remapMatchesBuild<3>({false, false, false}, 28, 4, false);
}

TEST(Neighbor, RemapAfterModeChangeMatchesBuild2D) {
    remapMatchesBuild<2>({true, true}, 23, 100);
    remapMatchesBuild<2>({false, false}, 24, 100);
    remapMatchesBuild<2>({false, true}, 26, 3);
    remapMatchesBuild<2>({true, true}, 29, 100, false);
    remapMatchesBuild<2>({false, false}, 30, 2, false);
}

/// A kept particle that drifted away from a newcomer since the last build may drift back by skin/2 before the next
/// one, while the newcomer drifts skin/2 towards it: the newcomer must be paired with it within skin + its drift.
/// Pair list valid: every touching pair is listed while each particle stays within skin/2 of its reference.
TEST(Neighbor, RemapCountsTheKeptParticlesDrift) {
    Domain<2> dom;
    dom.lo = Vec<2>::zero();
    dom.hi = Vec<2>::filled(1.0);
    const double r = 0.01, skin = 0.004;
    Particles<2> p;
    p.add(Vec<2>{0.5, 0.5}, Vec<2>::zero(), Ang<2>::zero(), r, 1000, 0, 0, 0);  // kept
    p.add(Vec<2>{0.9, 0.9}, Vec<2>::zero(), Ang<2>::zero(), r, 1000, 0, 1, 0);  // joins later
    p.nTdm = 1;
    const NeighborSettings s{skin, true};
    PairList<2> list;
    buildPairList(p, dom, s, PairList<2>{}, list);
    const Vec<2> ref0 = p.x[0];
    p.x[0][0] -= 0.49 * skin;                               // drifts away, within skin/2
    p.x[1] = Vec<2>{p.x[0][0] + 2 * r + 1.01 * skin, 0.5};  // joins just beyond the plain reach
    p.nTdm = 2;
    const std::vector<Vec<2>> ref{ref0, p.x[1]};
    PairList<2> plain = list, drifting = list;
    remapPairList(p, dom, s, {0, 0xFFFFFFFFu}, plain);
    remapPairList(p, dom, s, {0, 0xFFFFFFFFu}, drifting, ref.data());
    // Both move skin/2 - epsilon towards each other from their references: they touch.
    p.x[0][0] = ref0[0] + 0.49 * skin;
    p.x[1][0] -= 0.49 * skin;
    ASSERT_LT(norm(p.x[0] - p.x[1]), 2 * r);
    EXPECT_EQ(drifting.size(), 1u);
    EXPECT_EQ(plain.size(), 0u) << "without the drift the newcomer is left out (the case the reference is for)";
}

}  // namespace
}  // namespace haet
