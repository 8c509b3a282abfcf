#pragma once
// Small worlds built directly in code for unit tests (no scenario file).
#include "contact/setup.hpp"
#include "scenario/definition.hpp"
#include "world/build.hpp"
#include "world/world.hpp"

namespace haet::testing {

/// A scenario skeleton with one material and the linear law from (e, t_c).
inline Scenario linearScenario(int dim, double e, double tc, double mu = 0.0,
                               TangentialLaw tang = TangentialLaw::None) {
    Scenario sc;
    sc.dimension = dim;
    sc.duration = 1;
    MaterialDef m;
    m.name = "m";
    m.density = 1000;
    m.restitution = e;
    m.friction = mu;
    sc.materials.push_back(m);
    sc.contact.normal = NormalLaw::Linear;
    sc.contact.duration = tc;
    sc.contact.tangential = tang;
    return sc;
}

template <int D>
std::vector<MaterialStats> statsOf(const Particles<D>& p, int nMaterials) {
    return materialStats(p, nMaterials);
}

template <int D>
Domain<D> openBox(double half) {
    Domain<D> d;
    d.lo = Vec<D>::filled(-half);
    d.hi = Vec<D>::filled(half);
    return d;
}

}  // namespace haet::testing
