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

namespace haet {

using Vec3d = std::array<double, 3>;

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
        : std::runtime_error(format(pos, key, what)), pos_(pos), key_(key) {}
    const SourcePos& pos() const { return pos_; }
    const std::string& key() const { return key_; }

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

struct WallDef {
    Vec3d point{0, 0, 0};     ///< a point on the plane [m]
    Vec3d normal{0, 0, 1};    ///< unit normal pointing into the domain (normalised by the loader)
    Vec3d velocity{0, 0, 0};  ///< translation velocity of the plane [m/s]
    int material = 0;         ///< index into Scenario::materials
    SourcePos pos;
};

struct InsertDef {
    Arrangement arrangement = Arrangement::Random;
    std::size_t count = 0;                ///< number of particles (lattice: at most this many)
    double radiusMin = 0, radiusMax = 0;  ///< radius range [m], uniform; equal for monodisperse
    int material = 0;
    Vec3d regionLo{0, 0, 0}, regionHi{0, 0, 0};  ///< box the centres+radii must fit in [m]
    std::optional<double> spacing;               ///< lattice spacing [m]; default 2 * radius_max
    Vec3d velocity{0, 0, 0};                     ///< mean velocity [m/s]
    double temperature = 0;                      ///< velocity variance per component [m^2/s^2] (Maxwellian)
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

struct OutputDef {
    std::string directory = "out";  ///< run directory (--out overrides)
    double seriesPeriod = 0;        ///< [s] between rows of series.csv; 0 = 1/100 of duration
    double snapshotPeriod = 0;      ///< [s] between snapshots; 0 = 1/20 of duration; < 0 = none
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
    OutputDef output;
    std::string hash;                    ///< hash of the file contents (hex)
    std::vector<std::string> overrides;  ///< command-line overrides applied to the file, "KEY=VALUE" (loader.hpp)
};

}  // namespace haet
