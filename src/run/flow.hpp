#pragma once
// Particles that come and go during a run (docs/physics.md H): inlets that insert particles in batches at a rate,
// outlets that remove the particles whose centre enters their region, and their books (series.csv, run.json).
#include <iosfwd>

#include "scenario/definition.hpp"

namespace haet {

/// `haet check`: the size distribution of every insert and inlet (mean and d50 by number and by mass).
void describeFlows(const Scenario& sc, std::ostream& out);

}  // namespace haet
