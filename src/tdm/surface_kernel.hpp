#pragma once
// The wall kernel of disks and spheres against walls of any shape (geometry/surface.hpp): the particle's
// candidates from the broad phase, their contacts (docs/physics.md H.2: local minima of the distance, each wall's
// merged), each matched to the particle's contact with that wall in the last pass (its spring carries over,
// H.3), then the particles' contact law as for a plane (wallContactLaw, tdm/wall_law.hpp), with the wall's
// surface velocity at the contact point. The pair pass (tdm/pair_pass.hpp) runs it once the particle's pair and
// plane sums are complete.
#include <algorithm>
#include <cstdint>

#include "contact/laws.hpp"
#include "contact/setup.hpp"
#include "core/particles.hpp"
#include "tdm/contact_record.hpp"
#include "tdm/pair_pass.hpp"
#include "tdm/surface_state.hpp"
#include "tdm/wall_law.hpp"

namespace haet {

/// N values of T, not initialised: the kernel's scratch per particle (zeroing it would cost more than its use).
template <class T, int N>
struct Scratch {
    union {
        T v[N];
    };
    Scratch() {}
    T& operator[](int k) { return v[k]; }
};

template <int D, class Normal, class Tangential>
class SurfaceKernel {
public:
    /// Contacts of one particle found in one pass, before merging: at most this many are kept.
    static constexpr int kMaxHits = 32;

    explicit SurfaceKernel(const ForceContext<D>& ctx)
        : s_(ctx.surfaces),
          slotOf_(ctx.surfaces ? ctx.surfaces->slotOf.data() : nullptr),
          x_(ctx.p.x.data()),
          v_(ctx.p.v.data()),
          w_(ctx.p.w.data()),
          sv_(ctx.sv),
          sw_(ctx.sw),
          radius_(ctx.p.radius.data()),
          mass_(ctx.p.mass.data()),
          material_(ctx.p.material.data()),
          table_(ctx.cs.wallTable.data()),
          nMaterials_(ctx.cs.nMaterials),
          dt_(ctx.dt),
          clip_(!ctx.cs.attraction) {}

    /// Adds particle i's contacts with walls of any shape to its force f and torque tq, and their overlap / radius to
    /// worst; returns how many touch.
    /// With sink (the contact network's pass) also each contact as the law computed it.
    /// Most particles of a scene have no wall element near them: their test is inlined into the pass, and only the
    /// others pay for the call.
    [[gnu::always_inline]] std::uint32_t add(std::size_t i, Vec<D>& f, Ang<D>& tq, double& worst,
                                             ContactSink<D>* sink = nullptr) const {
        const std::uint32_t base = slotOf_[i];
        if (base == SurfaceState<D>::kNoSlots) return 0;
        return addNear(i, base, f, tq, worst, sink);
    }

    /// The elastic energy of particle i's contacts with walls of any shape at the last force pass [J].
    double energy(std::size_t i) const {
        const SurfaceState<D>& s = *s_;
        const std::uint32_t base = s.slotOf[i];
        if (base == SurfaceState<D>::kNoSlots) return 0;
        double e = 0;
        for (int q = 0; q < s.count[i]; ++q) {
            const SurfaceContact<D>& c = s.slots[base + q];
            e += Normal::energy(table_[material_[i] * nMaterials_ + (*s.walls)[c.wall].material], c.overlap, mass_[i],
                                radius_[i]);
        }
        return e;
    }

private:
    /// add() of particle i, whose contacts take the slots from base on.
    [[gnu::noinline]] std::uint32_t addNear(std::size_t i, std::uint32_t base, Vec<D>& f, Ang<D>& tq, double& worst,
                                            ContactSink<D>* sink) const {
        SurfaceState<D>& s = *s_;
        const std::vector<SurfaceWall<D>>& walls = *s.walls;
        const double ri = radius_[i];
        const Vec<D> xi = x_[i];
        Scratch<SurfaceHit<D>, kMaxHits> hits;
        std::uint32_t hitWall[kMaxHits];
        int nh = 0;
        const std::uint32_t k1 = s.candidates.first[i + 1];
        // Beyond this squared distance from its box an element cannot touch (the boxes are widened for rounding,
        // surface_state.hpp, and so is this bound).
        const double beyond2 = ri * ri * (1 + 1e-9);
        for (std::uint32_t k = s.candidates.first[i]; k < k1;) {
            // One wall's candidates at a time: its contacts are merged among themselves.
            const std::uint32_t w = s.candidates.wall[k];
            const Vec<D> xb = s.poses[w].toBody(xi);
            const int start = nh;
            auto emit = [&](const SurfaceHit<D>& h) {
                if (nh < kMaxHits) hits[nh++] = h;
            };
            if (walls[w].kind == SurfaceKind::Mesh) {
                // On a fine mesh a particle has many candidates and touches one or two: the distance to an
                // element's box, a few instructions, rules out most before their closest points are found.
                const ElementBox<D>* box = s.boxes.data() + s.boxFirst[w];
                for (; k < k1 && s.candidates.wall[k] == w; ++k) {
                    const std::uint32_t e = s.candidates.element[k];
                    if (boxDistance2(box[e], xb) > beyond2) continue;
                    walls[w].contacts(e, xb, ri, emit);
                }
            } else {
                for (; k < k1 && s.candidates.wall[k] == w; ++k)
                    walls[w].contacts(s.candidates.element[k], xb, ri, emit);
            }
            nh = start + mergeHits(hits.v + start, nh - start);
            for (int q = start; q < nh; ++q) hitWall[q] = w;
        }
        if (nh > kSurfaceSlots) {  // the deepest, in their order otherwise
            int order[kMaxHits];
            for (int q = 0; q < nh; ++q) order[q] = q;
            std::stable_sort(order, order + nh, [&](int a, int b) { return hits[a].distance < hits[b].distance; });
            std::sort(order, order + kSurfaceSlots);
            for (int q = 0; q < kSurfaceSlots; ++q) {
                hits[q] = hits[order[q]];
                hitWall[q] = hitWall[order[q]];
            }
            nh = kSurfaceSlots;
        }

        SurfaceContact<D>* slot = s.slots.data() + base;
        const int old = s.count[i];
        Scratch<SurfaceContact<D>, kSurfaceSlots> now;
        bool taken[kSurfaceSlots] = {};
        for (int q = 0; q < nh; ++q) {
            const std::uint32_t w = hitWall[q];
            const Pose<D>& pose = s.poses[w];
            SurfaceContact<D>& c = now[q];
            c.wall = w;
            c.normal = pose.directionToWorld(hits[q].normal);
            c.point = pose.toWorld(hits[q].point);
            c.overlap = ri - hits[q].distance;
            // The same contact as in the last pass: the wall's contact with the nearest normal.
            int match = -1;
            double best = 0.5;
            for (int o = 0; o < old; ++o) {
                if (taken[o] || slot[o].wall != w) continue;
                const double d = dot(slot[o].normal, c.normal);
                if (d > best) {
                    best = d;
                    match = o;
                }
            }
            if (match >= 0) {
                taken[match] = true;
                c.spring = slot[match].spring;
            } else {
                c.spring = Vec<D>::zero();
            }
        }
        for (int q = 0; q < nh; ++q) {
            SurfaceContact<D>& c = now[q];
            const SurfaceWall<D>& wall = walls[c.wall];
            ContactRecord<D> rec;
            c.force = wallContactLaw<D, Normal, Tangential>(
                table_[material_[i] * nMaterials_ + wall.material], c.overlap, c.normal,
                s.poses[c.wall].surfaceVelocity(c.point), v_[i], w_[i], sv_[i], sw_[i], ri, mass_[i], clip_, c.spring,
                dt_, f, tq, sink ? &rec.fn : nullptr, sink ? &rec.ft : nullptr);
            if (sink) [[unlikely]] {
                placeWallRecord(rec, i, wall.id, xi, c.point, c.normal, c.overlap);
                sink->push_back(rec);
            }
            worst = std::max(worst, c.overlap / ri);
            slot[q] = c;
        }
        s.count[i] = static_cast<std::uint8_t>(nh);
        return static_cast<std::uint32_t>(nh);
    }

    SurfaceState<D>* s_;
    const std::uint32_t* slotOf_;  ///< SurfaceState::slotOf (its size is fixed during a pass)
    const Vec<D>* x_;
    const Vec<D>* v_;
    const Ang<D>* w_;
    const Vec<D>* sv_;
    const Ang<D>* sw_;
    const double* radius_;
    const double* mass_;
    const std::uint16_t* material_;
    const PairCoeffs* table_;  ///< ContactSetup::wallTable: particle material x wall material
    int nMaterials_;
    double dt_;
    bool clip_;
};

}  // namespace haet
