#pragma once
// A time-driven run cut into subdomains, one per MPI rank (docs/parallel.md). The engine sees the other ranks only
// through `Ranks`, collectives over bytes: run/ranks_mpi.cpp binds them to MPI, so that nothing below run/ includes
// mpi.h and the library builds without MPI. The subdomains are slabs along one axis (`Slabs`), cut where each holds
// about as many particles; a rank owns the particles whose centres lie in its slab and keeps ghost copies of the
// other ranks' particles within the interaction range plus the skin of its slab.
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "core/particles.hpp"

namespace haet {

/// The ranks of a run, as the engine and the run loop call them. Every call is collective: all ranks make it, in
/// the same order.
class Ranks {
public:
    virtual ~Ranks() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    /// The bitwise or of every rank's bits.
    virtual std::uint32_t orBits(std::uint32_t mine) = 0;
    bool any(bool mine) { return orBits(mine ? 1u : 0u) != 0; }
    /// Element by element over the ranks, added in rank order: the same bits on every rank, whatever the transport.
    virtual void sum(std::vector<double>& v) = 0;
    virtual void max(std::vector<double>& v) = 0;
    /// send[r] goes to rank r (send[rank()] is not sent); returns what each rank sent here, by rank.
    virtual std::vector<std::vector<char>> exchange(const std::vector<std::vector<char>>& send) = 0;
    /// The same when every rank knows how many bytes each other rank sends it (recvBytes[r]): only the ranks that
    /// send or receive something talk, point to point, with no collective first (the ghosts' state every step).
    virtual std::vector<std::vector<char>> exchangeKnown(const std::vector<std::vector<char>>& send,
                                                         const std::vector<std::size_t>& recvBytes) = 0;
};

/// The cut of the box into one slab per rank along one axis. Rank r owns [cut[r-1], cut[r]), the first slab reaching
/// down to -infinity and the last up to +infinity (on a periodic axis, where positions are wrapped into the box at
/// every rebuild, the box faces).
struct Slabs {
    int axis = 0;
    bool periodic = false;
    double lo = 0, hi = 0;    ///< the box along the axis [m]
    std::vector<double> cut;  ///< the ranks - 1 interior cuts, ascending [m]

    int ranks() const { return static_cast<int>(cut.size()) + 1; }
    int rankOf(double s) const;
    /// The distance along the axis from s to rank r's slab [m] (0 inside), the nearer way round on a periodic axis.
    double gap(double s, int r) const;
};

/// Slabs with the cuts between the coordinates (every rank's particles along the axis) at the quantiles k / ranks:
/// the cut between the k-th and the next particle in order is their midpoint.
Slabs placeSlabs(std::vector<double> coords, int ranks, int axis, bool periodic, double lo, double hi);

/// Appends plain values to bytes, and reads them back in the same order.
struct ByteSink {
    std::vector<char>& out;
    template <class T>
    void put(const T& v) {
        const std::size_t n = out.size();
        out.resize(n + sizeof(T));
        std::memcpy(out.data() + n, &v, sizeof(T));
    }
};
struct ByteSource {
    const std::vector<char>& in;
    std::size_t at = 0;
    template <class T>
    T get() {
        T v;
        std::memcpy(&v, in.data() + at, sizeof(T));
        at += sizeof(T);
        return v;
    }
    bool done() const { return at >= in.size(); }
};

/// Every field of one particle of the store (a disk or a sphere: runs with polygons stay on one rank).
template <int D>
struct ParticleRecord {
    Vec<D> x, v, f;
    Ang<D> w, torque;
    double radius, invMass, invInertia, mass;
    std::uint64_t id;
    std::array<std::int32_t, D> image;
    std::uint16_t material;
    std::uint8_t flags;
};

template <int D>
ParticleRecord<D> recordOf(const Particles<D>& p, std::size_t i) {
    ParticleRecord<D> r{};
    r.x = p.x[i];
    r.v = p.v[i];
    r.w = p.w[i];
    if (p.hasTdmState()) {
        r.f = p.f[i];
        r.torque = p.torque[i];
    }
    r.radius = p.radius[i];
    r.invMass = p.invMass[i];
    r.invInertia = p.invInertia[i];
    r.mass = p.mass[i];
    r.id = p.id[i];
    r.image = p.image[i];
    r.material = p.material[i];
    r.flags = p.flags[i];
    return r;
}

/// Appends r to the store, every field as it was.
template <int D>
void appendRecord(Particles<D>& p, const ParticleRecord<D>& r) {
    p.x.push_back(r.x);
    p.v.push_back(r.v);
    p.w.push_back(r.w);
    if (p.hasTdmState()) {
        p.f.push_back(r.f);
        p.torque.push_back(r.torque);
    }
    p.radius.push_back(r.radius);
    p.invMass.push_back(r.invMass);
    p.invInertia.push_back(r.invInertia);
    p.mass.push_back(r.mass);
    p.id.push_back(r.id);
    p.image.push_back(r.image);
    p.material.push_back(r.material);
    p.flags.push_back(r.flags);
}

/// Keeps particles keep[0], keep[1], ... (ascending or not) as particles 0, 1, ... and drops the others.
template <int D>
void keepParticles(Particles<D>& p, const std::vector<std::uint32_t>& keep) {
    p.permute(keep);
    while (p.size() > keep.size()) p.popBack();
}

/// Every rank's particles [0, owned) on rank 0, in order of id (other ranks: an empty store). Collective.
template <int D>
Particles<D> gatherParticles(Ranks& ranks, const Particles<D>& p, std::size_t owned);

}  // namespace haet
