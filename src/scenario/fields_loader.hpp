#pragma once
// The loader's parts for the measurements: [[fields]] blocks (coarse-grained fields) and [[regions]] (named boxes
// whose stress goes to series.csv); docs/scenario.md, "Fields" and "Regions". scenario/loader.cpp calls them.
#include "scenario/definition.hpp"
#include "scenario/table_reader.hpp"

namespace haet::loader {

/// One [[fields]] block (the method, the domain and the duration read before).
FieldsDef readFields(const TableReader& r, int dim, const Scenario& s);

/// One [[regions]] block.
RegionDef readRegion(const TableReader& r, int dim, const DomainDef& domain);

/// Names unique among the [[fields]] blocks and among the [[regions]] (they name files and columns).
void checkMeasureNames(const Scenario& s);

}  // namespace haet::loader
