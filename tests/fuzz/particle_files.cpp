// Fuzz target: the particle-file readers of [[insert]] arrangement = "file" (scenario/insert.hpp) from memory,
// through the stream entry points the file readers use, and the checks a file's particles then pass
// (checkFileParticles: centres in the domain, radii, a LAMMPS box against periodic axes, overlaps of hard
// particles). The first byte picks the reader: 0 a 2D particle CSV, 1 a 3D one, 2 a polygon CSV, 3 a LAMMPS data
// file (3D), with hard particles in a periodic box for the odd ones. Bad input must be a ScenarioError naming the
// file and a line; anything else escaping, a crash or a sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "scenario/checks.hpp"
#include "scenario/insert.hpp"

namespace {

/// A scenario with one file insert: box [0, 1]^D, two materials; hard particles in a box periodic in x when `hard`.
haet::Scenario scenarioFor(int dimension, bool hard) {
    haet::Scenario s;
    s.dimension = dimension;
    s.method = hard ? haet::Method::Edm : haet::Method::Tdm;
    s.domain.lo = {0, 0, 0};
    s.domain.hi = {1, 1, dimension == 3 ? 1.0 : 0.0};
    s.domain.periodic = {hard, false, false};
    for (const char* name : {"sand", "glass"}) {
        haet::MaterialDef m;
        m.name = name;
        m.density = 2500;
        m.restitution = 0.8;
        s.materials.push_back(m);
    }
    haet::InsertDef in;
    in.arrangement = haet::Arrangement::File;
    in.file = "fuzz.data";
    s.inserts.push_back(in);
    return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const int reader = data[0] % 4;
    const bool hard = data[0] / 4 % 2 == 1;
    std::istringstream in(std::string(reinterpret_cast<const char*>(data) + 1, size - 1), std::ios::binary);
    const std::string name = "fuzz.data", key = "insert[1].file";
    try {
        if (reader == 2) {
            const haet::Scenario s = scenarioFor(2, false);
            const std::vector<haet::FilePolygon> p = haet::readPolygonCsv(in, name, s.materials, key);
            if (p.empty()) __builtin_trap();  // the reader promises polygons or an error
            for (const haet::FilePolygon& q : p)
                if (q.vertices.size() < 3 || q.line < 1) __builtin_trap();
            return 0;
        }
        const int dimension = reader == 0 ? 2 : 3;
        const haet::Scenario s = scenarioFor(dimension, hard);
        const haet::ParticleFile f = reader == 3 ? haet::readLammpsData(in, name, key)
                                                 : haet::readParticleCsv(in, name, dimension, s.materials, key);
        if (f.particles.empty()) __builtin_trap();
        if (dimension == 2)
            haet::checkFileParticles<2>(s, 0, f);
        else
            haet::checkFileParticles<3>(s, 0, f);
    } catch (const haet::ScenarioError& e) {
        if (e.pos().file != name || e.key() != key) __builtin_trap();  // every error names the file and the key
    }
    return 0;
}
