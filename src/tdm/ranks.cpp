// The time-driven engine across ranks (docs/parallel.md): slabs cut by particle count, ghosts within the range of
// a slab, migration at the pair-list rebuilds with the contacts' springs keyed by particle id, and the agreement of
// the ranks on every decision that must be the same everywhere (rebuild, stop, failure).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "tdm/halo.hpp"

namespace haet {

int Slabs::rankOf(double s) const {
    return static_cast<int>(std::upper_bound(cut.begin(), cut.end(), s) - cut.begin());
}

double Slabs::gap(double s, int r) const {
    constexpr double inf = std::numeric_limits<double>::infinity();
    const double a = r == 0 ? (periodic ? lo : -inf) : cut[r - 1];
    const double b = r == ranks() - 1 ? (periodic ? hi : inf) : cut[r];
    auto to = [&](double y) { return y < a ? a - y : (y > b ? y - b : 0.0); };
    if (!periodic) return to(s);
    const double L = hi - lo;
    return std::min({to(s), to(s - L), to(s + L)});
}

Slabs placeSlabs(std::vector<double> coords, int ranks, int axis, bool periodic, double lo, double hi) {
    Slabs s;
    s.axis = axis;
    s.periodic = periodic;
    s.lo = lo;
    s.hi = hi;
    std::sort(coords.begin(), coords.end());
    const std::size_t n = coords.size();
    for (int r = 1; r < ranks; ++r) {
        const std::size_t k = n * static_cast<std::size_t>(r) / static_cast<std::size_t>(ranks);
        double c;
        if (n == 0)
            c = lo + (hi - lo) * r / ranks;
        else if (k == 0)
            c = coords[0];
        else
            c = 0.5 * (coords[k - 1] + coords[std::min(k, n - 1)]);
        s.cut.push_back(s.cut.empty() ? c : std::max(c, s.cut.back()));
    }
    return s;
}

template <int D>
Particles<D> gatherParticles(Ranks& ranks, const Particles<D>& p, std::size_t owned) {
    std::vector<std::vector<char>> send(static_cast<std::size_t>(ranks.size()));
    Particles<D> all;
    if (!p.hasTdmState()) all.dropTdmState();
    std::vector<ParticleRecord<D>> recs;
    if (ranks.rank() != 0) {
        ByteSink out{send[0]};
        for (std::size_t i = 0; i < owned; ++i) out.put(recordOf(p, i));
    } else {
        for (std::size_t i = 0; i < owned; ++i) recs.push_back(recordOf(p, i));
    }
    const auto got = ranks.exchange(send);
    if (ranks.rank() != 0) return all;
    for (const std::vector<char>& bytes : got) {
        ByteSource in{bytes};
        while (!in.done()) recs.push_back(in.get<ParticleRecord<D>>());
    }
    std::sort(recs.begin(), recs.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
    for (const auto& r : recs) appendRecord(all, r);
    return all;
}

template Particles<2> gatherParticles(Ranks&, const Particles<2>&, std::size_t);
template Particles<3> gatherParticles(Ranks&, const Particles<3>&, std::size_t);

namespace {

/// A contact's tangential spring as the pair list of one rank holds it, by the particles' ids: the spring of the
/// pair taken from `a` to `b`; the other way round it is the negative (the relative displacement of the contact
/// points, docs/physics.md B.4).
template <int D>
struct IdSpring {
    std::uint64_t a, b;
    Vec<D> xi;
};

struct PairKey {
    std::uint64_t lo, hi;
    bool operator==(const PairKey&) const = default;
};
struct PairKeyHash {
    std::size_t operator()(const PairKey& k) const {
        return std::hash<std::uint64_t>()(k.lo * 0x9E3779B97F4A7C15ull ^ k.hi);
    }
};

}  // namespace

template <int D>
const Slabs* TdmEngine<D>::slabs() const {
    return halo_ ? &halo_->slabs : nullptr;
}

template <int D>
std::uint64_t TdmEngine<D>::migrated() const {
    return halo_ ? halo_->migrated : 0;
}

template <int D>
std::uint64_t TdmEngine<D>::rebalances() const {
    return halo_ ? halo_->rebalances : 0;
}

template <int D>
void TdmEngine<D>::scatterToSlabs() {
    Particles<D>& p = w_.particles;
    if (verlet_ == nullptr)
        throw std::invalid_argument(
            "tdm.integrator: runs across ranks take \"verlet\" only (Gear's history does not "
            "migrate yet)");
    if (shapes_ || p.hasPolygons()) throw std::invalid_argument("polygons do not run across ranks yet");
    if (!w_.surfaces.empty()) throw std::invalid_argument("walls other than planes do not run across ranks yet");
    if (p.tdmCount() != p.size()) throw std::invalid_argument("a hybrid run does not run across ranks yet");
    halo_ = std::make_unique<Halo>();
    Halo& h = *halo_;
    h.ranks = s_.ranks;
    // Every rank built the same World from the scenario: each places the same cuts and keeps its own particles.
    // The slabs run across the longest periodic axis (a flow along it keeps the slabs' counts; no free surface
    // crosses them), else across the axis the particles spread farthest along.
    const Domain<D>& dom = w_.domain;
    int axis = -1;
    for (int k = 0; k < D; ++k)
        if (dom.periodic[k] && (axis < 0 || dom.hi[k] - dom.lo[k] > dom.hi[axis] - dom.lo[axis])) axis = k;
    if (axis < 0) {
        double best = -1;
        for (int k = 0; k < D; ++k) {
            double a = std::numeric_limits<double>::infinity(), b = -a;
            for (std::size_t i = 0; i < p.size(); ++i) {
                a = std::min(a, p.x[i][k]);
                b = std::max(b, p.x[i][k]);
            }
            if (b - a > best) {
                best = b - a;
                axis = k;
            }
        }
    }
    wrapPositions(p, dom);
    std::vector<double> coords(p.size());
    double rmax = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        coords[i] = p.x[i][axis];
        rmax = std::max(rmax, p.radius[i]);
    }
    h.slabs = placeSlabs(coords, h.ranks->size(), axis, dom.periodic[axis], dom.lo[axis], dom.hi[axis]);
    // The pair list of the owned particles pairs them with any particle within their two radii plus the skin;
    // until the next rebuild none moves more than skin/2, so every contact an owned particle can make is with a
    // particle within the largest diameter plus the skin of the slab at the rebuild.
    h.range = 2 * rmax + s_.skin;
    std::vector<std::uint32_t> keep;
    for (std::size_t i = 0; i < p.size(); ++i)
        if (h.slabs.rankOf(p.x[i][axis]) == h.ranks->rank()) keep.push_back(static_cast<std::uint32_t>(i));
    keepParticles(p, keep);
    nOwned_ = p.size();
}

template <int D>
void TdmEngine<D>::agree(bool& moved, bool& stop) {
    Ranks& ranks = *halo_->ranks;
    const bool failed = !failure_.empty();
    const std::uint32_t bits = ranks.orBits((moved ? 1u : 0u) | (stop ? 2u : 0u) | (failed ? 4u : 0u));
    moved = bits & 1u;
    stop = bits & 2u;
    if (!(bits & 4u)) return;
    // A health check failed on some rank since the last agreement: every rank stops with the message of the lowest
    // rank that failed.
    std::string failure = failure_;
    std::vector<std::vector<char>> send(static_cast<std::size_t>(ranks.size()));
    for (int r = 0; r < ranks.size(); ++r)
        if (r != ranks.rank()) send[r].assign(failure.begin(), failure.end());
    const auto got = ranks.exchange(send);
    for (int r = 0; r < ranks.size(); ++r) {
        if (r == ranks.rank() && failed) break;
        if (r != ranks.rank() && !got[r].empty()) {
            failure.assign(got[r].begin(), got[r].end());
            break;
        }
    }
    failure_.clear();
    throw SimulationError(failure);
}

template <int D>
void TdmEngine<D>::rebuildAcrossRanks(bool sort) {
    Particles<D>& p = w_.particles;
    Halo& h = *halo_;
    Ranks& ranks = *h.ranks;
    const int me = ranks.rank(), nr = ranks.size();
    const std::size_t nw = w_.walls.size();
    const int axis = h.slabs.axis;
    const bool moving = motion_.v.size() == p.size();  // not yet at the constructor's first build
    wrapPositions(p, w_.domain);

    // The contacts' springs by id. Every listed pair has an owned particle first (ghost-ghost pairs are not listed).
    std::vector<IdSpring<D>> springs;
    std::vector<std::uint32_t> springOwner, springPartner;
    if (!pairs_.history.empty())
        for (std::size_t i = 0; i + 1 < pairs_.first.size(); ++i)
            for (std::uint32_t k = pairs_.first[i]; k < pairs_.first[i + 1]; ++k) {
                if (norm2(pairs_.history[k]) == 0) continue;
                const std::uint32_t j = pairs_.partner[k];
                springs.push_back({p.id[i], p.id[j], pairs_.history[k]});
                springOwner.push_back(static_cast<std::uint32_t>(i));
                springPartner.push_back(j);
            }
    // The ghosts go; they come back anew below.
    keepParticles(p, [&] {
        std::vector<std::uint32_t> k(nOwned_);
        for (std::size_t i = 0; i < nOwned_; ++i) k[i] = static_cast<std::uint32_t>(i);
        return k;
    }());
    if (moving) {
        motion_.v.resize(nOwned_);
        motion_.w.resize(nOwned_);
    }
    wallHistory_.resize(nOwned_ * nw);

    // The cuts again when the slabs' counts drift apart by more than 10 %: every rank sorts every coordinate (rare;
    // a flow along a periodic axis keeps the counts).
    {
        std::vector<double> counts(static_cast<std::size_t>(nr), 0.0);
        counts[me] = static_cast<double>(nOwned_);
        ranks.sum(counts);
        double total = 0, most = 0;
        for (double c : counts) {
            total += c;
            most = std::max(most, c);
        }
        if (most > 1.1 * total / nr + 1) {
            std::vector<std::vector<char>> send(static_cast<std::size_t>(nr));
            for (int r = 0; r < nr; ++r) {
                if (r == me) continue;
                ByteSink out{send[r]};
                for (std::size_t i = 0; i < nOwned_; ++i) out.put(p.x[i][axis]);
            }
            const auto got = ranks.exchange(send);
            std::vector<double> coords;
            for (int r = 0; r < nr; ++r) {
                if (r == me) {
                    for (std::size_t i = 0; i < nOwned_; ++i) coords.push_back(p.x[i][axis]);
                    continue;
                }
                ByteSource in{got[r]};
                while (!in.done()) coords.push_back(in.get<double>());
            }
            h.slabs = placeSlabs(std::move(coords), nr, axis, h.slabs.periodic, h.slabs.lo, h.slabs.hi);
            ++h.rebalances;
        }
    }

    // Migration: a particle whose centre left the slab goes to the rank of the slab it is in, with the step's mean
    // velocities, its planes' springs and the springs of its pairs.
    std::vector<int> dest(nOwned_);
    std::vector<std::vector<char>> send(static_cast<std::size_t>(nr));
    std::vector<std::uint32_t> keep;
    std::vector<std::uint32_t> count(static_cast<std::size_t>(nr), 0);
    for (std::size_t i = 0; i < nOwned_; ++i) {
        dest[i] = h.slabs.rankOf(p.x[i][axis]);
        if (dest[i] == me)
            keep.push_back(static_cast<std::uint32_t>(i));
        else
            ++count[dest[i]];
    }
    for (int r = 0; r < nr; ++r) {
        if (r == me) continue;
        ByteSink out{send[r]};
        out.put(count[r]);
    }
    for (std::size_t i = 0; i < nOwned_; ++i) {
        if (dest[i] == me) continue;
        ByteSink out{send[dest[i]]};
        out.put(recordOf(p, i));
        out.put(moving ? motion_.v[i] : p.v[i]);
        out.put(moving ? motion_.w[i] : p.w[i]);
        for (std::size_t q = 0; q < nw; ++q) out.put(wallHistory_[i * nw + q]);
        ++h.migrated;
    }
    for (std::size_t s = 0; s < springs.size(); ++s) {
        const std::uint32_t i = springOwner[s], j = springPartner[s];
        if (i >= nOwned_) continue;  // not listed (the pairs of two ghosts); a ghost's owner keeps its springs
        const int ri = dest[i], rj = j < nOwned_ ? dest[j] : me;
        if (ri != me) {
            ByteSink out{send[ri]};
            out.put(springs[s]);
        }
        if (rj != me && rj != ri) {
            ByteSink out{send[rj]};
            out.put(springs[s]);
        }
    }
    const auto got = ranks.exchange(send);
    {
        std::vector<Vec<D>> mv, wh;
        std::vector<Ang<D>> mw;
        for (std::uint32_t i : keep) {
            if (moving) {
                mv.push_back(motion_.v[i]);
                mw.push_back(motion_.w[i]);
            }
            for (std::size_t q = 0; q < nw; ++q) wh.push_back(wallHistory_[i * nw + q]);
        }
        keepParticles(p, keep);
        for (int r = 0; r < nr; ++r) {
            if (r == me) continue;
            ByteSource in{got[r]};
            const auto n = in.get<std::uint32_t>();
            for (std::uint32_t k = 0; k < n; ++k) {
                appendRecord(p, in.get<ParticleRecord<D>>());
                const Vec<D> v = in.get<Vec<D>>();
                const Ang<D> w = in.get<Ang<D>>();
                if (moving) {
                    mv.push_back(v);
                    mw.push_back(w);
                }
                for (std::size_t q = 0; q < nw; ++q) wh.push_back(in.get<Vec<D>>());
            }
            while (!in.done()) springs.push_back(in.get<IdSpring<D>>());
        }
        motion_.v.swap(mv);
        motion_.w.swap(mw);
        wallHistory_.swap(wh);
        if (!moving) {
            motion_.v.clear();
            motion_.w.clear();
        }
        nOwned_ = p.size();
    }

    if (sort) {
        double rmax = 0;
        for (std::size_t i = 0; i < nOwned_; ++i) rmax = std::max(rmax, p.radius[i]);
        const auto order = spatialOrder(p, w_.domain, 2 * rmax + s_.skin);
        p.permute(order);
        if (moving) {
            auto mv = motion_.v;
            auto mw = motion_.w;
            for (std::size_t k = 0; k < nOwned_; ++k) {
                motion_.v[k] = mv[order[k]];
                motion_.w[k] = mw[order[k]];
            }
        }
        if (nw > 0) {
            std::vector<Vec<D>> wh(wallHistory_.size());
            for (std::size_t k = 0; k < nOwned_; ++k)
                for (std::size_t q = 0; q < nw; ++q) wh[k * nw + q] = wallHistory_[order[k] * nw + q];
            wallHistory_.swap(wh);
        }
        lastSort_ = steps_;
    }

    // The ghosts: every owned particle within the range of another rank's slab, its copy kept there.
    h.send.assign(static_cast<std::size_t>(nr), {});
    std::vector<std::vector<char>> ghosts(static_cast<std::size_t>(nr));
    for (int r = 0; r < nr; ++r) {
        if (r == me) continue;
        ByteSink out{ghosts[r]};
        for (std::size_t i = 0; i < nOwned_; ++i) {
            if (h.slabs.gap(p.x[i][axis], r) >= h.range) continue;
            h.send[r].push_back(static_cast<std::uint32_t>(i));
            out.put(recordOf(p, i));
            out.put(moving ? motion_.v[i] : p.v[i]);
            out.put(moving ? motion_.w[i] : p.w[i]);
        }
    }
    const auto copies = ranks.exchange(ghosts);
    h.ghostFirst.assign(static_cast<std::size_t>(nr) + 1, nOwned_);
    for (int r = 0; r < nr; ++r) {
        h.ghostFirst[r] = p.size();
        if (r == me) continue;
        ByteSource in{copies[r]};
        while (!in.done()) {
            ParticleRecord<D> rec = in.get<ParticleRecord<D>>();
            rec.flags |= kGhost;
            appendRecord(p, rec);
            const Vec<D> v = in.get<Vec<D>>();
            const Ang<D> w = in.get<Ang<D>>();
            if (moving) {
                motion_.v.push_back(v);
                motion_.w.push_back(w);
            }
        }
    }
    h.ghostFirst[nr] = p.size();
    wallHistory_.resize(p.size() * nw, Vec<D>::zero());
    if (s_.planeLoads) planeForce_.assign(p.size() * nw, Vec<D>::zero());

    // The new list, and the springs of its pairs by id: this rank's own first, then those that came with migrants
    // (the same pair's spring on two ranks differs by rounding at most; this rank keeps its own).
    PairList<D> none, fresh;
    buildPairList(p, w_.domain, NeighborSettings{s_.skin, true}, none, fresh);
    pairs_ = std::move(fresh);
    if (!springs.empty()) {
        std::unordered_map<PairKey, Vec<D>, PairKeyHash> byIds;
        byIds.reserve(springs.size());
        for (const IdSpring<D>& s : springs) {
            const bool up = s.a < s.b;
            byIds.try_emplace(PairKey{up ? s.a : s.b, up ? s.b : s.a}, up ? s.xi : s.xi * -1.0);
        }
        for (std::size_t i = 0; i + 1 < pairs_.first.size(); ++i)
            for (std::uint32_t k = pairs_.first[i]; k < pairs_.first[i + 1]; ++k) {
                const std::uint64_t a = p.id[i], b = p.id[pairs_.partner[k]];
                const bool up = a < b;
                const auto it = byIds.find(PairKey{up ? a : b, up ? b : a});
                if (it != byIds.end()) pairs_.history[k] = up ? it->second : it->second * -1.0;
            }
    }
    xAtBuild_.assign(p.x.begin(), p.x.end());
    ++rebuilds_;
}

template <int D>
void TdmEngine<D>::refreshGhosts() {
    Particles<D>& p = w_.particles;
    Halo& h = *halo_;
    Ranks& ranks = *h.ranks;
    const int me = ranks.rank(), nr = ranks.size();
    // What the force pass reads of a ghost that changes over a step: the predicted state and the step's mean
    // velocities (the springs' increments), as its owner computed them.
    std::vector<std::vector<char>> send(static_cast<std::size_t>(nr));
    for (int r = 0; r < nr; ++r) {
        if (r == me) continue;
        ByteSink out{send[r]};
        for (const std::uint32_t i : h.send[r]) {
            out.put(p.x[i]);
            out.put(p.v[i]);
            out.put(p.w[i]);
            out.put(motion_.v[i]);
            out.put(motion_.w[i]);
        }
    }
    // The ghosts of each rank are as many as at the rebuild: the sizes are known, and only neighbours talk.
    constexpr std::size_t kBytes = 3 * sizeof(Vec<D>) + 2 * sizeof(Ang<D>);
    std::vector<std::size_t> bytes(static_cast<std::size_t>(nr), 0);
    for (int r = 0; r < nr; ++r)
        if (r != me) bytes[r] = (h.ghostFirst[r + 1] - h.ghostFirst[r]) * kBytes;
    const auto got = ranks.exchangeKnown(send, bytes);
    for (int r = 0; r < nr; ++r) {
        if (r == me) continue;
        ByteSource in{got[r]};
        for (std::size_t g = h.ghostFirst[r]; g < h.ghostFirst[r + 1]; ++g) {
            p.x[g] = in.get<Vec<D>>();
            p.v[g] = in.get<Vec<D>>();
            p.w[g] = in.get<Ang<D>>();
            motion_.v[g] = in.get<Vec<D>>();
            motion_.w[g] = in.get<Ang<D>>();
        }
    }
}

template <int D>
double TdmEngine<D>::contactShare() const {
    if (!halo_) return static_cast<double>(stats_.contacts);
    // The pass's own test of a listed pair (disk_kernel.hpp: touching when the centres are closer than the radii
    // sum) and of a plane (wall_kernel.hpp), at the state of the last pass.
    const Particles<D>& p = w_.particles;
    double n = 0;
    for (std::size_t i = 0; i < nOwned_; ++i) {
        for (std::uint32_t k = pairs_.first[i]; k < pairs_.first[i + 1]; ++k) {
            const std::uint32_t j = pairs_.partner[k];
            const Vec<D> d = p.x[i] - p.x[j] + pairs_.shiftVec[pairs_.shift[k]];
            const double rs = p.radius[i] + p.radius[j];
            if (norm2(d) < rs * rs) n += j < nOwned_ ? 1.0 : 0.5;
        }
        if (p.frozen(i)) continue;
        for (const Wall<D>& wall : w_.walls) n += wall.distanceNow(p.x[i]) < p.radius[i];
    }
    return n;
}

template <int D>
double TdmEngine<D>::contactEnergyShare() const {
    const ForceContext<D> ctx = context(motion_.v.data(), motion_.w.data());
    auto share = [&](const auto& kernel) {
        const auto& walls = kernel.walls();
        double e = 0;
        for (std::size_t i = 0; i < nOwned_; ++i) {
            for (std::uint32_t k = pairs_.first[i]; k < pairs_.first[i + 1]; ++k)
                e += (pairs_.partner[k] < nOwned_ ? 1.0 : 0.5) * kernel.energy(i, k);
            for (std::size_t w = 0; w < ctx.nWalls; ++w) e += walls.energy(i, w);
        }
        return e;
    };
    if (w_.contact.normal == NormalLaw::Linear) return share(DiskKernel<D, LinearNormal, NoTangential, false>(ctx));
    return share(DiskKernel<D, HertzViscoNormal, NoTangential, false>(ctx));
}

#define HAET_RANKS_MEMBERS(D)                                \
    template const Slabs* TdmEngine<D>::slabs() const;       \
    template std::uint64_t TdmEngine<D>::migrated() const;   \
    template std::uint64_t TdmEngine<D>::rebalances() const; \
    template void TdmEngine<D>::scatterToSlabs();            \
    template void TdmEngine<D>::agree(bool&, bool&);         \
    template void TdmEngine<D>::rebuildAcrossRanks(bool);    \
    template void TdmEngine<D>::refreshGhosts();             \
    template double TdmEngine<D>::contactShare() const;      \
    template double TdmEngine<D>::contactEnergyShare() const;
HAET_RANKS_MEMBERS(2)
HAET_RANKS_MEMBERS(3)
#undef HAET_RANKS_MEMBERS

}  // namespace haet
