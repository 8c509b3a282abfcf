#pragma once
// Definition structs: everything a user sets in a scenario file, with defaults and units.
// The loader (scenario/loader.cpp) fills these from TOML and validates them; nothing below the loader
// parses strings. Vectors are stored with three components; a 2D scenario uses the first two.
#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "contact/model.hpp"
#include "core/vec.hpp"
#include "measure/cg_kernel.hpp"
#include "scenario/distribution.hpp"

namespace haet {

using Vec3d = std::array<double, 3>;

/// The first D components of a definition's vector (definitions keep three; a 2D scenario uses two).
template <int D>
Vec<D> toVec(const Vec3d& a) {
    Vec<D> v;
    for (int k = 0; k < D; ++k) v[k] = a[static_cast<std::size_t>(k)];
    return v;
}

enum class Method { Tdm, Edm, Haet };
enum class Arrangement { Lattice, Random, File };
enum class FileFormat { Csv, LammpsData };
enum class ShapeKind { Disk, Polygon };
enum class PolygonKind { Regular, Rectangle, Random };

/// Where a value came from, for error messages: file and 1-based line (0 when unknown).
struct SourcePos {
    std::string file;
    int line = 0;
};

/// A scenario that cannot be run. Carries "file:line: key: what is wrong"; the CLI exits with code 2.
class ScenarioError : public std::runtime_error {
public:
    ScenarioError(const SourcePos& pos, const std::string& key, const std::string& what)
        : std::runtime_error(format(pos, key, what)), pos_(pos), key_(key), message_(what) {}
    const SourcePos& pos() const { return pos_; }
    const std::string& key() const { return key_; }
    const std::string& message() const { return message_; }  ///< what is wrong, without the place and key

private:
    static std::string format(const SourcePos& p, const std::string& key, const std::string& what) {
        std::string s = p.file;
        if (p.line > 0) s += ":" + std::to_string(p.line);
        s += ": ";
        if (!key.empty()) s += key + ": ";
        return s + what;
    }
    SourcePos pos_;
    std::string key_;
    std::string message_;
};

struct DomainDef {
    Vec3d lo{0, 0, 0};                                  ///< lower corner [m]
    Vec3d hi{1, 1, 1};                                  ///< upper corner [m]
    std::array<bool, 3> periodic{false, false, false};  ///< periodic per axis
    Vec3d gravity{0, 0, 0};                             ///< [m/s^2]
    SourcePos pos;                                      ///< the [domain] table
};

/// A [materials.NAME] table: the properties the contact laws read (contact/model.hpp) and where they were set.
struct MaterialDef : MaterialProps {
    std::string name;
    SourcePos pos;
};

/// The [contact] section: the laws and their parameters (contact/model.hpp) and where they were set.
struct ContactDef : ContactModelDef {
    SourcePos pos;
};

struct TdmDef {
    IntegratorKind integrator = IntegratorKind::Verlet;
    bool integratorGiven = false;  ///< false: the default applies (verlet; gear5 in scenes with polygons)
    std::optional<double> dt;      ///< time step [s]; unset = "auto": t_c / steps_per_contact
    double stepsPerContact = 50;   ///< auto rule: dt = t_c / steps_per_contact [-]
    std::optional<double> skin;    ///< Verlet-list skin [m]; default 0.1 x smallest diameter... see docs
    double maxOverlap = 0.5;       ///< blow-up: stop when overlap / smaller radius exceeds this [-]
    int sortEvery = 1000;          ///< spatial re-sort of particles every N steps (0 = never)
    SourcePos pos;
    SourcePos dtPos;  ///< where dt was given (the table's line when it was not)
};

enum class EdmTangential { Walton, Constant };

/// Event-driven engine (method = "edm", and the dilute zones of "haet").
struct EdmDef {
    /// Tangential restitution: Walton's rule with (e, mu, beta0) of the materials, or beta = beta0 always.
    EdmTangential tangential = EdmTangential::Walton;
    bool tcModel = true;             ///< inelastic-collapse protection (TC model, docs/physics.md D.7)
    std::optional<double> tcTime;    ///< TC time [s]; default: the soft contact duration t_c
    std::optional<double> cellSize;  ///< event grid cell edge [m]; default: the largest diameter
    SourcePos pos;
    SourcePos cellPos;  ///< where cell_size was given
};

/// The hybrid (method = "haet"), docs/physics.md A: TDM where the local volume fraction is high, EDM where low.
struct HaetDef {
    std::optional<double> zoneSize;  ///< zone cell edge [m]; default 4 x the largest diameter
    std::optional<double> phiOn;     ///< a zone turns dense above this volume (area) fraction [-]
    std::optional<double> phiOff;    ///< and dilute again below this one [-]; phi_off < phi_on
    int relabelEvery = 50;           ///< zone re-labelling and mode-change period [TDM steps]
    int buffer = 1;                  ///< zones around a dense zone whose particles are TDM too [cells]
    int diluteSteps = 20;            ///< a TDM particle returns to EDM after its zone is dilute this long [steps]
    std::optional<double> dtMin;     ///< modified EDM: minimum time between collisions [s]; default t_c
    SourcePos pos;
};

/// The shape of a [[walls]] block (docs/scenario.md, "[[walls]]").
enum class WallType { Plane, Segment, Polyline, Circle, Arc, Mesh, Cylinder, Cone, Disc, Rectangle };

struct WallDef {
    WallType type = WallType::Plane;
    std::string name;         ///< optional: a named wall's load is in series.csv
    Vec3d point{0, 0, 0};     ///< plane: a point on it [m]
    Vec3d normal{0, 0, 1};    ///< plane: unit normal pointing into the domain; disc, rectangle: their normal
    Vec3d velocity{0, 0, 0};  ///< translation velocity [m/s]
    int material = 0;         ///< index into Scenario::materials
    // Oscillation about the translation: displacement A (sin(2 pi f t + phase) - sin(phase)).
    Vec3d amplitude{0, 0, 0};  ///< [m]
    double frequency = 0;      ///< [Hz]; 0 = none
    double phase = 0;          ///< [rad]
    // Rotation about an axis through `rotationCentre` (2D: about z).
    Vec3d rotationCentre{0, 0, 0};  ///< [m]
    Vec3d rotationAxis{0, 0, 1};    ///< unit vector (3D)
    double omega = 0;               ///< angular speed [rad/s]; 0 = none
    // Shapes (body frame = world frame at t = 0).
    std::vector<Vec3d> points;      ///< segment, polyline: the vertices [m]
    bool closed = false;            ///< polyline: joins the last point to the first
    Vec3d centre{0, 0, 0};          ///< circle, arc, disc, rectangle: the centre; cylinder, cone: the base centre [m]
    Vec3d axis{0, 0, 1};            ///< cylinder, cone: unit axis from the base
    double radius = 0;              ///< circle, arc, disc; cylinder; cone: at the base [m]
    double radiusTop = 0;           ///< cone: at the top [m]
    double length = 0;              ///< cylinder, cone: along the axis [m]
    double angle0 = 0, angle1 = 0;  ///< arc: from, to, counter-clockwise [rad]
    bool capBase = false, capTop = false;         ///< cylinder, cone: discs closing the ends
    Vec3d edge1{0, 0, 0}, edge2{0, 0, 0};         ///< rectangle: its two edge vectors [m]
    std::vector<std::array<Vec3d, 3>> triangles;  ///< mesh: the triangles, transformed as the file asks [m]
    std::string file;                             ///< mesh: the STL file it came from (resolved path)
    SourcePos pos;

    bool isPlane() const { return type == WallType::Plane; }
    bool rotates() const { return omega != 0; }
};

struct InsertDef {
    Arrangement arrangement = Arrangement::Random;
    std::size_t count = 0;                ///< number of particles (lattice: at most this many)
    double radiusMin = 0, radiusMax = 0;  ///< radius range [m]: the bounds of `size`; equal for monodisperse
    SizeDistribution size;                ///< radius distribution (docs/scenario.md, "Size distributions")
    int material = 0;
    Vec3d regionLo{0, 0, 0}, regionHi{0, 0, 0};  ///< box the centres+radii must fit in [m]
    /// Inlets in 3D: a vertical cylinder (axis along z) instead of the box, which is then its bounding box.
    bool cylinder = false;
    std::array<double, 2> cylinderCentre{0, 0};  ///< axis position (x, y) [m]
    double cylinderRadius = 0;                   ///< [m]
    /// Surface inlets: the slab a batch fills, downstream of the face, instead of the box (then its bounding box):
    /// centre, orthonormal axes (the last one the face's normal), half-extents along them; `slabRound`: a disc
    /// face, radius slabHalf[0] about the last axis.
    bool slab = false;
    Vec3d slabCentre{0, 0, 0};        ///< [m]
    std::array<Vec3d, 3> slabAxes{};  ///< unit vectors
    Vec3d slabHalf{0, 0, 0};          ///< [m]
    bool slabRound = false;
    std::optional<double> spacing;  ///< lattice spacing [m]; default 2 * radius_max
    Vec3d velocity{0, 0, 0};        ///< mean velocity [m/s]
    double temperature = 0;         ///< velocity variance per component [m^2/s^2] (Maxwellian)
    bool frozen = false;
    std::string file;  ///< arrangement = File: path (resolved against the scenario dir)
    FileFormat format = FileFormat::Csv;
    std::vector<int> frozenTypes;  ///< LAMMPS data files: atom types (1-based) whose particles are frozen
    // Polygons (2D, docs/physics.md G). `radius` is then the circumradius about the centroid (the bounding circle).
    ShapeKind shape = ShapeKind::Disk;
    PolygonKind polygon = PolygonKind::Regular;
    int sidesMin = 0, sidesMax = 0;     ///< vertices per polygon, uniform in [min, max] (regular: min = max)
    double aspect = 1;                  ///< rectangle: side ratio (x over y) [-]; random: largest stretch [-]
    std::optional<double> orientation;  ///< [rad]; unset = uniform random in [0, 2 pi)
    SourcePos pos;
};

// ---- Flows: particles that come and go during the run (docs/scenario.md, "Inlets" and "Outlets") ----------------

enum class OutletKind { Box, HalfSpace };

/// An [[outlet]]: particles whose centre enters the region are removed (docs/physics.md K).
struct OutletDef {
    std::string name;  ///< column prefix in series.csv; empty: "outlet1", "outlet2", ... by file order
    OutletKind kind = OutletKind::Box;
    Vec3d lo{0, 0, 0}, hi{0, 0, 0};  ///< box [m]
    Vec3d point{0, 0, 0};            ///< half-space: a point on its plane [m]
    Vec3d normal{0, 0, 1};           ///< half-space: unit normal pointing into the removed side
    double interval = 0;             ///< [s] between checks of event-driven particles; 0: duration / 1000
    /// false: a counter (LIGGGHTS massflow/mesh without delete_atoms): each particle is counted the first time its
    /// centre is found inside, and stays in the run.
    bool remove = true;
    SourcePos pos;
};

/// An [[inlet]]: particles appear in a region at a rate, in batches (docs/physics.md K).
struct InletDef {
    std::string name;  ///< column prefix in series.csv; empty: "inlet1", "inlet2", ... by file order
    /// What is inserted and where: arrangement random, count unused; region (box or cylinder), size distribution,
    /// material, velocity, temperature, shape.
    InsertDef particles;
    double rate = 0;      ///< [particles/s]; 0 when massRate is given
    double massRate = 0;  ///< [kg/s] (2D: kg/(m s), per unit depth as every 2D mass); 0 when rate is given
    double start = 0;     ///< first batch [s]
    double end = 0;       ///< no particle is due after this time [s]
    double interval = 0;  ///< [s] between batches
    SourcePos pos;
};

/// The snapshot fields a picture may be coloured by (`[output] color_by`); a vector field also by its magnitude
/// (the name alone) or one component (NAME_x, NAME_y, NAME_z). "mode" exists in hybrid runs only.
inline constexpr std::array<const char*, 7> kPictureFields = {
    "velocity", "angular_velocity", "force", "radius", "material", "id", "mode"};
inline constexpr std::array<const char*, 3> kPictureVectorFields = {"velocity", "angular_velocity", "force"};

// ---- Measurements (docs/scenario.md, "Fields", "Regions"; docs/physics.md L) ------------------------------------

/// The fields a [[fields]] block may write (`fields = [...]`), in this order.
inline constexpr std::array<const char*, 9> kCgFieldNames = {
    "density",        "volume_fraction",    "velocity", "kinetic_stress", "temperature",
    "contact_stress", "collisional_stress", "stress",   "mode_fraction"};

/// A [[fields]] block: coarse-grained fields on a grid of 1 to 3 axes over a box, averaged over a time window.
struct FieldsDef {
    std::string name;                   ///< names its files: fields_NAME.pvd, fields_NAME_K.vti, fields_NAME.csv
    int nAxes = 1;                      ///< grid axes
    std::array<int, 3> axes{2, 0, 1};   ///< box axis of each grid axis (0 x, 1 y, 2 z)
    std::array<int, 3> cells{1, 1, 1};  ///< cells along each grid axis
    Vec3d lo{0, 0, 0}, hi{0, 0, 0};     ///< region [m] (default: the domain)
    CgKernelKind kernel = CgKernelKind::Gaussian;
    double width = 0;           ///< [m]: the Gaussian's standard deviation, Lucy's support radius
    double cutoff = 3;          ///< Gaussian cut-off [widths]
    double window = 0;          ///< [s]: samples in [t - window, t] averaged at each output time t; 0: one sample
    double sampleInterval = 0;  ///< [s] between samples in a window; 0: window / 10
    double period = 0;          ///< [s] between outputs; 0: the snapshot period
    int branchNodes = 3;        ///< Gauss-Legendre nodes along a branch (grids of 2 or 3 axes)
    std::uint32_t fields = 0;   ///< bit k: kCgFieldNames[k] written
    SourcePos pos;
};

/// A [[regions]] block: a named box whose stress tensor goes to series.csv (NAME_stress_xx, ...).
struct RegionDef {
    std::string name;
    Vec3d lo{0, 0, 0}, hi{0, 0, 0};  ///< [m]
    SourcePos pos;
};

struct OutputDef {
    std::string directory = "out";  ///< run directory (--out overrides)
    double seriesPeriod = 0;        ///< [s] between rows of series.csv; 0 = 1/100 of duration
    double snapshotPeriod = 0;      ///< [s] between snapshots; 0 = 1/20 of duration; < 0 = none
    /// final.png: the field it is coloured by ("" = "mode" in a hybrid run, else "velocity"), the colour bar's
    /// limits (none = the data's), the direction a 3D picture looks along, and the width of the view [px].
    std::string colorBy;
    std::optional<std::array<double, 2>> colorRange;
    Vec3d view{0, 1, 0};
    int pictureWidth = 900;
    double checkpointPeriod = 0;  ///< [s] between checkpoints; 0 = none but the one at the end (and at a stop)
    bool contacts = false;        ///< the contact network at every snapshot (contacts.pvd, contacts_K.csv)
    bool stress = true;           ///< the stress tensor of the domain and the regions in series.csv
    SourcePos pos;
};

/// Bounds on what a run writes (docs/scenario.md, [output]): a period that asks for more is an error.
inline constexpr double kMaxSeriesRows = 1e7;
inline constexpr double kMaxSnapshots = 1e5;

struct Scenario {
    std::string path;  ///< scenario file
    std::string name;
    int dimension = 3;
    Method method = Method::Tdm;
    double duration = 0;  ///< simulated time [s]
    std::uint64_t seed = 1;
    DomainDef domain;
    std::vector<MaterialDef> materials;
    ContactDef contact;
    TdmDef tdm;
    EdmDef edm;
    HaetDef haet;
    std::vector<WallDef> walls;
    std::vector<InsertDef> inserts;
    std::vector<OutletDef> outlets;
    std::vector<InletDef> inlets;
    std::vector<FieldsDef> fields;
    std::vector<RegionDef> regions;
    OutputDef output;
    std::string hash;  ///< hash of the file contents (hex)
    /// Every key a resume may not change (docs/scenario.md, "Resuming"), one "key = value" line each, after the
    /// overrides, in key order: what a checkpoint records of its scenario, and stateHash its hash (hex).
    std::string stateKeys;
    std::string stateHash;
    std::vector<std::string> overrides;  ///< command-line overrides applied to the file, "KEY=VALUE" (loader.hpp)
};

}  // namespace haet
