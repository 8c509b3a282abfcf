#include "run/flow.hpp"

#include <fmt/format.h>

#include <ostream>

namespace haet {

namespace {
void describeSize(const std::string& who, const SizeDistribution& s, int dim, std::ostream& out) {
    const SizeSummary m = summarize(s, dim);
    out << fmt::format("sizes      {}: {}\n", who, describeSizes(s));
    out << fmt::format(
        "           diameter mean {:.4g} m by number, {:.4g} m by mass; d50 {:.4g} m by number, {:.4g} m by mass\n",
        m.meanByNumber, m.meanByMass, m.d50ByNumber, m.d50ByMass);
}
}  // namespace

void describeFlows(const Scenario& sc, std::ostream& out) {
    for (std::size_t k = 0; k < sc.inserts.size(); ++k)
        if (sc.inserts[k].arrangement != Arrangement::File)
            describeSize("insert[" + std::to_string(k + 1) + "]", sc.inserts[k].size, sc.dimension, out);
    for (const InletDef& in : sc.inlets) describeSize("inlet " + in.name, in.particles.size, sc.dimension, out);
}

}  // namespace haet
