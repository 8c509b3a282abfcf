#pragma once
// The one particle store shared by every engine: structure-of-arrays, ordered for the force loop.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/polygon_shape.hpp"
#include "core/vec.hpp"

namespace haet {

/// Per-particle flag bits.
enum ParticleFlag : std::uint8_t {
    kFrozen = 1u << 0,  ///< not integrated: position and velocity stay as given (a rough base, a fixture)
    /// A copy of another rank's particle (a run across MPI ranks, tdm/ranks.hpp): its forces are that rank's to
    /// compute, and its state is overwritten from there every step.
    kGhost = 1u << 1,
};
/// Two particles that share one of these bits are never paired: two frozen ones never move apart or together, and
/// the pair of two ghosts is computed by a rank that owns one of them.
inline constexpr std::uint8_t kUnpaired = kFrozen | kGhost;

/// Shape factor q of the moment of inertia I = q m a^2 (docs/physics.md B.4): solid disk 1/2, solid sphere 2/5.
template <int D>
inline constexpr double kInertiaFactor = (D == 2) ? 0.5 : 0.4;

/// Shape index of a particle that is a disk or sphere (Particles::shape).
inline constexpr std::uint32_t kNoShape = 0xffffffffu;

/// Shapes of the polygon particles (2D): vertex lists in the body frame, one entry per polygon particle.
/// Rotating the body frame by Particles::angle and moving it to Particles::x gives the polygon in the world.
struct ShapeTable {
    std::vector<std::uint32_t> first{0};  ///< CSR: shape s owns vertices [first[s], first[s+1])
    std::vector<Vec<2>> vertices;         ///< centroid at the origin, counter-clockwise [m]
    std::vector<double> inertiaPerMass;   ///< moment of inertia about the centroid / mass [m^2]
    std::vector<double> area;             ///< [m^2]

    std::size_t size() const { return area.size(); }
    int count(std::uint32_t s) const { return int(first[s + 1] - first[s]); }
    const Vec<2>* of(std::uint32_t s) const { return vertices.data() + first[s]; }
};

template <int D>
struct Particles {
    // hot: read or written every step
    std::vector<Vec<D>> x;                ///< centre position [m]
    std::vector<Vec<D>> v;                ///< velocity [m/s]
    std::vector<Ang<D>> w;                ///< angular velocity [rad/s]
    std::vector<Vec<D>> f;                ///< total force [N] (empty without hasTdmState())
    std::vector<Ang<D>> torque;           ///< total torque [N m] (empty without hasTdmState())
    std::vector<double> radius;           ///< [m]
    std::vector<double> invMass;          ///< 1/m [1/kg]; 0 for a frozen particle
    std::vector<double> invInertia;       ///< 1/I [1/(kg m^2)]; 0 for a frozen particle
    std::vector<std::uint16_t> material;  ///< index into the material table
    std::vector<std::uint8_t> flags;      ///< ParticleFlag bits
    // cold
    std::vector<double> mass;       ///< [kg] (kept for frozen particles too, for contact effective mass)
    std::vector<std::uint64_t> id;  ///< stable user-visible id (survives reordering)
    /// Periodic box crossings per axis, as LAMMPS's image flags: the unwrapped position is Domain::unwrap(x, image).
    std::vector<std::array<std::int32_t, D>> image;
    // polygons (2D only). Empty while the store holds no polygon, so disk and sphere runs carry nothing extra:
    // a disk or a sphere looks the same however it has turned, so only a polygon's orientation is kept.
    std::vector<std::uint32_t> shape;  ///< index into `shapes`, kNoShape for a disk
    std::vector<Ang<D>> angle;         ///< orientation [rad], integrated from w (a disk's too, once polygons exist)
    ShapeTable shapes;                 ///< never permuted: particles point into it

    /// Particles [0, tdmCount()) are integrated by the time-driven engine. In a hybrid run the rest belong to the
    /// event-driven engine (docs/physics.md A); in a pure run one engine owns them all (the default: every particle).
    std::size_t nTdm = static_cast<std::size_t>(-1);

    std::size_t size() const { return id.size(); }
    /// Whether f and torque are kept. Only the time-driven engine reads them (the hybrid too, for its
    /// time-driven particles); a pure event-driven run applies impulses, not forces, so it drops them
    /// (dropTdmState): 48 of the 187 bytes per sphere.
    bool hasTdmState() const { return tdmState_; }
    /// Frees f and torque; particles added later get none either. For a pure event-driven run.
    void dropTdmState() {
        tdmState_ = false;
        std::vector<Vec<D>>().swap(f);
        std::vector<Ang<D>>().swap(torque);
    }
    std::size_t tdmCount() const { return nTdm < size() ? nTdm : size(); }

    /// Whether x, v and radius are in the store. A pure event-driven run keeps them only in its engine between
    /// synchronisations (EdmSettings::holdState), where they sit together in one record per particle, and releases
    /// them here: 56 bytes per sphere that would otherwise be held twice. While they are released nothing may read
    /// them, and particles are neither added, swapped nor permuted.
    bool hasMotion() const { return motion_; }
    void releaseMotion() {
        motion_ = false;
        std::vector<Vec<D>>().swap(x);
        std::vector<Vec<D>>().swap(v);
        std::vector<double>().swap(radius);
    }
    /// Gives x, v and radius their size back (the values are the holder's to write).
    void restoreMotion() {
        motion_ = true;
        x.resize(size());
        v.resize(size());
        radius.resize(size());
    }

    /// Appends one particle of given density [kg/m^D-volume]; mass from radius and density.
    std::size_t add(const Vec<D>& pos, const Vec<D>& vel, const Ang<D>& spin, double r, double density,
                    std::uint16_t mat, std::uint64_t pid, std::uint8_t flag = 0) {
        const double m = density * volumeOf(r);
        x.push_back(pos);
        v.push_back(vel);
        w.push_back(spin);
        if (tdmState_) {
            f.push_back(Vec<D>::zero());
            torque.push_back(Ang<D>::zero());
        }
        radius.push_back(r);
        mass.push_back(m);
        const bool frozen = flag & kFrozen;
        invMass.push_back(frozen ? 0.0 : 1.0 / m);
        invInertia.push_back(frozen ? 0.0 : 1.0 / (kInertiaFactor<D> * m * r * r));
        material.push_back(mat);
        flags.push_back(flag);
        id.push_back(pid);
        image.push_back({});
        if (!shape.empty()) {
            shape.push_back(kNoShape);
            angle.push_back(Ang<D>::zero());
        }
        return x.size() - 1;
    }

    /// Appends one convex polygon (2D only) with its centroid at `pos`, turned by `orientation` [rad]. `body`:
    /// the vertices in the body frame [m], convex, in either order, about any origin (they are re-centred on
    /// their centroid and put counter-clockwise). The radius becomes the circumradius about the centroid (the
    /// bounding circle the neighbour grid uses), mass and moment of inertia follow from the vertices.
    std::size_t addPolygon(const Vec<D>& pos, const Vec<D>& vel, const Ang<D>& spin, double orientation,
                           std::vector<Vec<2>> body, double density, std::uint16_t mat, std::uint64_t pid,
                           std::uint8_t flag = 0) {
        static_assert(D == 2, "polygons exist only in 2D");
        const polygon::BodyFrame frame = polygon::toBodyFrame(body);
        const double area = frame.area;
        const std::size_t i = add(pos, vel, spin, frame.circumradius, density, mat, pid, flag);
        // The first polygon gives the disks before it kNoShape entries and orientations.
        shape.resize(x.size(), kNoShape);
        angle.resize(x.size(), Ang<D>::zero());
        const double m = density * area;
        const double ipm = frame.inertiaPerMass;
        mass[i] = m;
        invMass[i] = (flag & kFrozen) ? 0.0 : 1.0 / m;
        invInertia[i] = (flag & kFrozen) ? 0.0 : 1.0 / (ipm * m);
        angle[i][0] = orientation;
        shape[i] = static_cast<std::uint32_t>(shapes.size());
        shapes.vertices.insert(shapes.vertices.end(), body.begin(), body.end());
        shapes.first.push_back(static_cast<std::uint32_t>(shapes.vertices.size()));
        shapes.inertiaPerMass.push_back(ipm);
        shapes.area.push_back(area);
        return i;
    }

    bool hasPolygons() const { return !shape.empty(); }
    bool isPolygon(std::size_t i) const { return !shape.empty() && shape[i] != kNoShape; }

    /// Volume of a sphere (3D) or area of a disk (2D) of radius r.
    static double volumeOf(double r) {
        constexpr double pi = 3.14159265358979323846;
        return (D == 2) ? pi * r * r : (4.0 / 3.0) * pi * r * r * r;
    }

    double inertia(std::size_t i) const {
        if (isPolygon(i)) return shapes.inertiaPerMass[shape[i]] * mass[i];
        return kInertiaFactor<D> * mass[i] * radius[i] * radius[i];
    }
    bool frozen(std::size_t i) const { return flags[i] & kFrozen; }

    /// Exchanges particles i and j (all fields).
    void swapEntries(std::size_t i, std::size_t j) {
        if (i == j) return;
        forEachArray([&](auto& arr) { std::swap(arr[i], arr[j]); });
    }

    /// Drops the last particle (all fields; a polygon's shape stays in `shapes`, unreferenced). Particles leave a
    /// run this way (an outlet): whoever removes one first exchanges it with the last (swapEntries).
    void popBack() {
        forEachArray([](auto& arr) { arr.pop_back(); });
    }

    /// Applies a permutation: new index k holds old particle order[k]. Used for spatial sorting. A shorter order
    /// permutes the first order.size() particles only.
    void permute(const std::vector<std::uint32_t>& order) {
        forEachArray([&](auto& arr) {
            auto tmp = arr;
            for (std::size_t k = 0; k < order.size(); ++k) tmp[k] = arr[order[k]];
            arr.swap(tmp);
        });
    }

private:
    /// Calls op on every per-particle array the store holds now (forces and torques only while the time-driven
    /// state is kept, shapes and orientations only once it holds a polygon): the one list of the fields that
    /// follow a particle when it changes place.
    template <class Op>
    void forEachArray(Op&& op) {
        op(x);
        op(v);
        op(w);
        op(radius);
        op(invMass);
        op(invInertia);
        op(material);
        op(flags);
        op(mass);
        op(id);
        op(image);
        if (tdmState_) {
            op(f);
            op(torque);
        }
        if (!shape.empty()) {
            op(shape);
            op(angle);
        }
    }

    bool tdmState_ = true;
    bool motion_ = true;
};

}  // namespace haet

namespace haet {
/// Below this many particles a loop runs on one thread: fork/join would cost more than it saves.
inline constexpr std::size_t kParallelMin = 2048;
}  // namespace haet
