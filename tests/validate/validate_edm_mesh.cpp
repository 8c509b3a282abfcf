// The long version of the event-driven engine's comparison with its reference twin with static mesh walls
// (tests/test_edm_mesh.cpp; docs/edm.md, "Mesh walls"): boxes of mesh walls with random elements inside under gravity,
// tens of thousands of collisions, bit for bit, with cell crossings and with neighbour shells.
#include <gtest/gtest.h>

#include "../edm_mesh_util.hpp"

namespace haet {
namespace {

TEST(EdmMeshValidate, MatchesReference2DLongRun) {
    testing::MeshGas m;
    m.n = 36;
    m.inner = 8;
    m.e = 0.97;
    m.seed = 21;
    EdmSettings s;
    s.tcTime = 1e-3;
    testing::compareWithReference<2>(testing::meshGas<2>(m), s, 60000);
}

TEST(EdmMeshValidate, MatchesReference3DLongRun) {
    testing::MeshGas m;
    m.n = 27;
    m.inner = 8;
    m.e = 0.9;
    m.seed = 22;
    EdmSettings s;
    s.tcTime = 1e-3;
    testing::compareWithReference<3>(testing::meshGas<3>(m), s, 40000);
}

TEST(EdmMeshValidate, MatchesReferenceElasticRough3DLongRun) {
    testing::MeshGas m;
    m.n = 27;
    m.inner = 10;
    m.e = 1;
    m.mu = 0;
    m.beta0 = 1;
    m.seed = 23;
    EdmSettings s;
    s.tcModel = false;
    s.tangential = EdmSettings::Tangential::Constant;
    testing::compareWithReference<3>(testing::meshGas<3>(m), s, 20000);
}

}  // namespace
}  // namespace haet
