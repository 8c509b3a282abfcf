#pragma once
// The loader's parts for size distributions, inlets and outlets (docs/scenario.md, "Size distributions", "Inlets",
// "Outlets"); scenario/loader.cpp calls them. Errors are ScenarioError with file:line: key, as everywhere.
#include "scenario/definition.hpp"
#include "scenario/table_reader.hpp"

namespace haet::loader {

/// `radius` (a number, or [min, max]: uniform) or a `distribution` table of an [[insert]] or [[inlet]]: sets
/// in.size, in.radiusMin and in.radiusMax.
void readSizes(const TableReader& r, int dim, InsertDef& in);

/// `cylinder = { center, radius, z }` of a 3D inlet: sets in.cylinder and the bounding box in.regionLo/Hi.
void readCylinder(const TableReader& r, int dim, const DomainDef& domain, InsertDef& in);

/// `surface = { center, normal, size | length | radius, axis }` of a surface inlet (as LIGGGHTS insert/stream):
/// the slab one batch fills downstream of the face, v.n x interval thick (in.interval set before, or its default
/// here), as in.slab; in.regionLo/Hi its bounding box. The velocity (read before) must cross the face.
void readSurface(const TableReader& r, int dim, const DomainDef& domain, InletDef& in);

/// The timing of an [[inlet]] (`rate` or `mass_rate`, `start`, `end`, `interval`) and its name; the region, sizes,
/// shape and velocities are read before (in.particles), since `interval`'s default depends on them.
void readInletFlow(const TableReader& r, int dim, const Scenario& s, InletDef& in);

/// An [[outlet]]: `name`, `region = { lo, hi }` or `plane = { point, normal }`, `interval`.
OutletDef readOutlet(const TableReader& r, int dim, double duration);

/// Names: unique among the inlets and the outlets (they name series.csv's columns); unnamed ones get theirs.
void nameFlows(Scenario& s);

}  // namespace haet::loader
