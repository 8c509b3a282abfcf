#include "run/flow.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>

namespace haet {

namespace {

constexpr double kNoTime = std::numeric_limits<double>::infinity();

/// Draws of positions per due particle and batch before it waits for the next batch (LIGGGHTS's insertion
/// commands try a fixed number of times too): a crowded region costs a bounded amount per batch.
constexpr std::uint64_t kTriesPerParticle = 200;

template <int D>
Vec<D> toVec(const Vec3d& a) {
    Vec<D> v;
    for (int k = 0; k < D; ++k) v[k] = a[std::size_t(k)];
    return v;
}

void describeSize(const std::string& who, const SizeDistribution& s, int dim, std::ostream& out) {
    const SizeSummary m = summarize(s, dim);
    out << fmt::format("sizes      {}: {}\n", who, describeSizes(s));
    out << fmt::format(
        "           diameter mean {:.4g} m by number, {:.4g} m by mass; d50 {:.4g} m by number, {:.4g} m by mass\n",
        m.meanByNumber, m.meanByMass, m.d50ByNumber, m.d50ByMass);
}

}  // namespace

template <int D>
Flow<D>::Flow(const Scenario& sc, const World<D>& world, double dt) : sc_(sc), dt_(dt) {
    const Particles<D>& p = world.particles;
    initial_ = p.size();
    for (std::size_t i = 0; i < p.size(); ++i) nextId_ = std::max(nextId_, p.id[i] + 1);
    time_ = world.time;
    for (std::size_t k = 0; k < sc.inlets.size(); ++k) {
        const InletDef& d = sc.inlets[k];
        inlets_.push_back(Inlet{
            &d, Rng(sc.seed, static_cast<std::uint64_t>(RngStream::InletFirst) + k), d.start, {}, {}, 0, 0, 0, {}});
    }
    for (const OutletDef& d : sc.outlets) {
        lazyInterval_ = std::min(lazyInterval_, d.interval);
        outlets_.push_back(Outlet{&d, {}, 0, {}});
    }
    nextLazy_ = outlets_.empty() ? kNoTime : world.time + lazyInterval_;
}

template <int D>
double Flow<D>::nextTime() const {
    double t = nextLazy_;
    if (!outlets_.empty() && dt_ > 0) t = std::min(t, time_ + dt_);
    for (const Inlet& in : inlets_) t = std::min(t, in.next);
    return t;
}

template <int D>
bool Flow<D>::inside(const OutletDef& o, const Vec<D>& x) const {
    if (o.kind == OutletKind::HalfSpace) {
        double s = 0;
        for (int k = 0; k < D; ++k) s += (x[k] - o.point[std::size_t(k)]) * o.normal[std::size_t(k)];
        return s >= 0;
    }
    for (int k = 0; k < D; ++k)
        if (x[k] < o.lo[std::size_t(k)] || x[k] > o.hi[std::size_t(k)]) return false;
    return true;
}

template <int D>
void Flow<D>::act(World<D>& world, FlowHost<D>& host, double tol) {
    Particles<D>& p = world.particles;
    const double t = world.time;
    time_ = t;
    bool synced = false;
    auto sync = [&] {
        if (!synced) host.synchronise();
        synced = true;
    };
    if (!outlets_.empty()) {
        // Time-driven particles after every step, event-driven ones at the outlets' interval.
        const bool lazy = nextLazy_ <= t + tol;
        if (lazy) {
            sync();
            while (nextLazy_ <= t + tol) nextLazy_ += lazyInterval_;
        }
        const std::size_t n = p.size(), end = lazy ? n : std::min(n, dt_ > 0 ? host.eager() : 0);
        std::vector<std::uint32_t> which;
        for (std::size_t i = 0; i < end; ++i) {
            if (p.frozen(i)) continue;  // a fixture never leaves
            for (Outlet& o : outlets_) {
                if (!inside(*o.def, p.x[i])) continue;
                if (!o.def->remove) {  // a counter: once per particle, and the particle goes on to the next outlets
                    if (o.seen.insert(p.id[i]).second) {
                        ++o.out.particles;
                        o.out.mass += p.mass[i];
                    }
                    continue;
                }
                which.push_back(static_cast<std::uint32_t>(i));
                ++o.out.particles;
                o.out.mass += p.mass[i];
                break;
            }
        }
        // A removed particle never comes back: the counters forget it, so that what they hold is bounded by the
        // particles in the run, not by every particle that ever passed (a long fed run's memory stays flat).
        if (!which.empty())
            for (Outlet& o : outlets_)
                if (!o.def->remove)
                    for (const std::uint32_t i : which) o.seen.erase(p.id[i]);
        if (!which.empty()) host.remove(which);
    }
    const std::size_t first = p.size();
    for (Inlet& in : inlets_) {
        if (in.next > t + tol) continue;
        sync();
        batch(world, in);
    }
    if (p.size() > first) host.added(first);
}

template <int D>
void Flow<D>::batch(World<D>& world, Inlet& in) {
    const InletDef& def = *in.def;
    const InsertDef& d = def.particles;
    const double t = world.time;
    const double elapsed = std::min(t, def.end) - def.start;
    // What fell due by now: floor(rate x elapsed) particles, or particles while the mass drawn stays within half a
    // particle of mass_rate x elapsed. Each particle is drawn (size, shape) before it is due, and waits drawn.
    for (;;) {
        if (!in.drawn) {
            NewParticle<D> q;
            q.radius = d.size.sample(in.rng);
            finishParticle(sc_, d, q, in.rng);
            in.drawn = q;
        }
        const bool due = def.rate > 0 ? double(in.drawnCount) < std::floor(def.rate * elapsed * (1 + 1e-12))
                                      : in.drawnMass + 0.5 * in.drawn->mass() <= def.massRate * elapsed;
        if (!due) break;
        in.drawnMass += in.drawn->mass();
        ++in.drawnCount;
        in.pending.push_back(std::move(*in.drawn));
        in.drawn.reset();
    }
    if (!in.pending.empty()) {
        RandomPlacer<D> placer(sc_, d, world.particles, in.pending.size());
        std::vector<NewParticle<D>> left;
        for (NewParticle<D>& q : in.pending) {
            if (!placer.place(q, in.rng, kTriesPerParticle)) {
                left.push_back(std::move(q));  // the shortfall: tried again at the next batch
                continue;
            }
            thermalVelocity(d, q, in.rng);
            addToStore(world.particles, q, nextId_++);
            ++in.in.particles;
            in.in.mass += q.mass();
        }
        in.pending.swap(left);
    }
    // Batches at start + j interval, one at `end` itself, and after it only while a shortfall waits.
    ++in.batches;
    const double next = def.start + double(in.batches) * def.interval;
    if (t < def.end)
        in.next = std::min(next, def.end);
    else
        in.next = in.pending.empty() ? kNoTime : t + def.interval;
}

template <int D>
std::vector<std::string> Flow<D>::columns() const {
    std::vector<std::string> c;
    for (const Inlet& in : inlets_)
        for (const char* what : {"_particles", "_mass", "_shortfall"}) c.push_back(in.def->name + what);
    for (const Outlet& o : outlets_)
        for (const char* what : {"_particles", "_mass", "_rate"}) c.push_back(o.def->name + what);
    return c;
}

template <int D>
std::vector<std::optional<double>> Flow<D>::row(double time) {
    std::vector<std::optional<double>> r;
    for (const Inlet& in : inlets_) {
        r.push_back(double(in.in.particles));
        r.push_back(in.in.mass);
        r.push_back(double(in.pending.size()));
    }
    const bool first = !(time > rowTime_);  // the first row (NaN before) has no interval: no rate
    for (Outlet& o : outlets_) {
        r.push_back(double(o.out.particles));
        r.push_back(o.out.mass);
        r.push_back(first ? std::nullopt : std::optional<double>((o.out.mass - o.massAtRow) / (time - rowTime_)));
        o.massAtRow = o.out.mass;
    }
    rowTime_ = time;
    return r;
}

template <int D>
void Flow<D>::describe(JsonObject& j) const {
    if (empty()) return;
    JsonObject f;
    f.add("initial_particles", initial_);
    std::uint64_t added = 0, removed = 0;
    JsonObject inlets, outlets;
    for (const Inlet& in : inlets_) {
        JsonObject o;
        o.add("particles", in.in.particles);
        o.add("mass", in.in.mass);
        o.add("shortfall", static_cast<std::uint64_t>(in.pending.size()));
        inlets.add(in.def->name, o);
        added += in.in.particles;
    }
    for (const Outlet& out : outlets_) {
        JsonObject o;
        o.add("particles", out.out.particles);
        o.add("mass", out.out.mass);
        if (!out.def->remove) o.add("counter", true);
        outlets.add(out.def->name, o);
        if (out.def->remove) removed += out.out.particles;
    }
    f.add("inserted", added);
    f.add("removed", removed);
    f.add("inlets", inlets);
    f.add("outlets", outlets);
    j.add("flows", f);
}

template <int D>
void dropParticles(Particles<D>& p, const std::vector<std::uint32_t>& which) {
    for (auto it = which.rbegin(); it != which.rend(); ++it) {
        p.swapEntries(*it, p.size() - 1);
        p.popBack();
    }
}

template <int D>
void removeTimeDriven(World<D>& w, TdmEngine<D>& eng, const std::vector<std::uint32_t>& which) {
    Particles<D>& p = w.particles;
    std::vector<std::uint32_t> from(p.size());
    for (std::size_t k = 0; k < from.size(); ++k) from[k] = static_cast<std::uint32_t>(k);
    // Highest index first: the last particle, which takes a removed one's place, is never one still to remove.
    for (auto it = which.rbegin(); it != which.rend(); ++it) {
        const std::size_t last = p.size() - 1;
        p.swapEntries(*it, last);
        from[*it] = from[last];
        from.pop_back();
        p.popBack();
    }
    eng.remap(from);
}

template <int D>
void addTimeDriven(World<D>& w, TdmEngine<D>& eng, std::size_t first) {
    std::vector<std::uint32_t> from(w.particles.size(), TdmEngine<D>::kFresh);
    for (std::size_t k = 0; k < first; ++k) from[k] = static_cast<std::uint32_t>(k);
    eng.remap(from);
}

template void dropParticles<2>(Particles<2>&, const std::vector<std::uint32_t>&);
template void dropParticles<3>(Particles<3>&, const std::vector<std::uint32_t>&);
template void removeTimeDriven<2>(World<2>&, TdmEngine<2>&, const std::vector<std::uint32_t>&);
template void removeTimeDriven<3>(World<3>&, TdmEngine<3>&, const std::vector<std::uint32_t>&);
template void addTimeDriven<2>(World<2>&, TdmEngine<2>&, std::size_t);
template void addTimeDriven<3>(World<3>&, TdmEngine<3>&, std::size_t);

double inletRadiusBound(const Scenario& sc) {
    double r = 0;
    for (const InletDef& in : sc.inlets) r = std::max(r, in.particles.radiusMax);
    return r;
}

void describeFlows(const Scenario& sc, std::ostream& out) {
    for (std::size_t k = 0; k < sc.inserts.size(); ++k)
        if (sc.inserts[k].arrangement != Arrangement::File)
            describeSize("insert[" + std::to_string(k + 1) + "]", sc.inserts[k].size, sc.dimension, out);
    for (const InletDef& in : sc.inlets) {
        const InsertDef& p = in.particles;
        const char* where = p.slab ? (p.slabRound ? "through a disc"
                                                  : (sc.dimension == 2 ? "through a segment" : "through a rectangle"))
                                   : (p.cylinder ? "in a cylinder" : "in a box");
        out << fmt::format(
            "inlet      {}: {} {} from {:.4g} s to {:.4g} s, a batch every {:.4g} s (docs/physics.md K.3)\n", in.name,
            in.rate > 0 ? fmt::format("{:.4g} particles/s", in.rate) : fmt::format("{:.4g} kg/s", in.massRate), where,
            in.start, in.end, in.interval);
        describeSize("inlet " + in.name, in.particles.size, sc.dimension, out);
    }
    for (const OutletDef& o : sc.outlets)
        out << fmt::format(
            "outlet     {}: {}{}; time-driven particles checked every step, event-driven ones every {:.4g} s\n", o.name,
            o.kind == OutletKind::Box ? "box" : "half-space beyond a plane",
            o.remove ? "" : ", a counter (particles stay)", o.interval);
}

namespace {

template <int D>
void putNew(ByteWriter& out, const NewParticle<D>& q) {
    out.put(q.x);
    out.put(q.v);
    out.put(q.w);
    out.put(q.radius);
    out.put(q.density);
    out.put(q.material);
    out.put(q.flags);
    out.put(q.image);
    out.putVector(q.body);
    out.put(q.orientation);
}

template <int D>
NewParticle<D> getNew(ByteReader& in) {
    NewParticle<D> q;
    q.x = in.get<Vec<D>>();
    q.v = in.get<Vec<D>>();
    q.w = in.get<Ang<D>>();
    q.radius = in.get<double>();
    q.density = in.get<double>();
    q.material = in.get<std::uint16_t>();
    q.flags = in.get<std::uint8_t>();
    q.image = in.get<std::array<std::int32_t, D>>();
    in.getVector(q.body);
    q.orientation = in.get<double>();
    return q;
}

}  // namespace

template <int D>
void Flow<D>::saveState(ByteWriter& out) const {
    out.put<double>(time_);
    out.put<double>(rowTime_);
    out.put<std::uint64_t>(nextId_);
    out.put<std::uint64_t>(initial_);
    out.put<double>(nextLazy_);
    out.put<std::uint64_t>(inlets_.size());
    for (const Inlet& in : inlets_) {
        out.put(in.rng.position());
        out.put<double>(in.next);
        out.put<std::uint64_t>(in.pending.size());
        for (const NewParticle<D>& q : in.pending) putNew(out, q);
        out.put<std::uint8_t>(in.drawn.has_value());
        if (in.drawn) putNew(out, *in.drawn);
        out.put<std::uint64_t>(in.batches);
        out.put<std::uint64_t>(in.drawnCount);
        out.put<double>(in.drawnMass);
        out.put<std::uint64_t>(in.in.particles);
        out.put<double>(in.in.mass);
    }
    out.put<std::uint64_t>(outlets_.size());
    for (const Outlet& o : outlets_) {
        out.put<std::uint64_t>(o.out.particles);
        out.put<double>(o.out.mass);
        out.put<double>(o.massAtRow);
        // A counter's ids, sorted: the same state gives the same bytes.
        std::vector<std::uint64_t> seen(o.seen.begin(), o.seen.end());
        std::sort(seen.begin(), seen.end());
        out.putVector(seen);
    }
}

template <int D>
void Flow<D>::loadState(ByteReader& in) {
    time_ = in.get<double>();
    rowTime_ = in.get<double>();
    nextId_ = in.get<std::uint64_t>();
    initial_ = in.get<std::uint64_t>();
    nextLazy_ = in.get<double>();
    if (in.get<std::uint64_t>() != inlets_.size()) in.fail("another number of inlets than the scenario's");
    for (Inlet& k : inlets_) {
        if (!k.rng.setPosition(in.get<Rng::Position>())) in.fail("an inlet's random stream is in no possible place");
        k.next = in.get<double>();
        const auto pending = in.get<std::uint64_t>();
        if (pending > in.rest().size() / sizeof(Vec<D>)) in.fail("more pending particles than the bytes left hold");
        k.pending.clear();
        for (std::uint64_t q = 0; q < pending; ++q) k.pending.push_back(getNew<D>(in));
        k.drawn.reset();
        if (in.get<std::uint8_t>()) k.drawn = getNew<D>(in);
        k.batches = in.get<std::uint64_t>();
        k.drawnCount = in.get<std::uint64_t>();
        k.drawnMass = in.get<double>();
        k.in.particles = in.get<std::uint64_t>();
        k.in.mass = in.get<double>();
    }
    if (in.get<std::uint64_t>() != outlets_.size()) in.fail("another number of outlets than the scenario's");
    for (Outlet& o : outlets_) {
        o.out.particles = in.get<std::uint64_t>();
        o.out.mass = in.get<double>();
        o.massAtRow = in.get<double>();
        std::vector<std::uint64_t> seen;
        in.getVector(seen);
        o.seen = std::unordered_set<std::uint64_t>(seen.begin(), seen.end());
    }
    in.expectEnd();
}

template class Flow<2>;
template class Flow<3>;

}  // namespace haet
