// Long checks of walls of any shape (docs/physics.md H): the torque a slowly turning drum takes balances its bed's
// weight times the bed's offset from the axis; a bed packs alike in an analytic cylinder and in a mesh of it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../physics_util.hpp"
#include "../world_util.hpp"
#include "geometry/surface.hpp"
#include "scenario/loader.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"

namespace haet {
namespace {

constexpr double kPi = 3.141592653589793;

TEST(WallsValidate, DrumTorqueBalancesTheBedsWeightOffset) {
    // 2D drum of radius R turning at 1 rad/s, half a thousand disks: in the steady rolling regime the bed's angular
    // momentum about the axis is constant on average, so the drum's torque is -M g x_com (gravity -y, axis z).
    const double tc = 2e-4, R = 0.04, omega = 1.0, g = 9.81;
    Scenario sc = testing::linearScenario(2, 0.5, tc, 0.5, TangentialLaw::Spring);
    World<2> w;
    w.domain = testing::openBox<2>(0.05);
    w.domain.gravity = Vec<2>{{0, -g}};
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> u(0.0012, 0.0015);
    std::uint64_t id = 0;
    for (double y = -R + 0.002; y < -0.005; y += 0.0031)
        for (double x = -R; x < R; x += 0.0031)
            if (std::hypot(x, y) < R - 0.002)
                w.particles.add(Vec<2>{{x, y}}, Vec<2>::zero(), Ang<2>::zero(), u(rng), 2.5, 0, id++);
    SurfaceWall<2> drum;
    drum.kind = SurfaceKind::Arc;
    drum.radius = R;
    drum.angle1 = 2 * kPi;
    drum.motion.omega = omega;
    w.surfaces.push_back(drum);
    w.contact = buildContactSetup<2>(sc, testing::statsOf(w.particles, 1));
    TdmSettings s;
    s.dt = tc / 50;
    s.skin = 0.0003;
    TdmEngine<2> eng(w, s);
    eng.advanceTo(1.0);  // the bed is lifted to its angle of repose and rolls
    double torque = 0, weightOffset = 0;
    int n = 0;
    while (w.time < 3.0) {
        eng.advanceTo(w.time + 0.001);
        torque += eng.surfaceLoad(0).torque[0];
        double mx = 0;
        for (std::size_t i = 0; i < w.particles.size(); ++i) mx += w.particles.mass[i] * w.particles.x[i][0];
        weightOffset += -g * mx;
        ++n;
    }
    torque /= n;
    weightOffset /= n;
    EXPECT_GT(std::abs(weightOffset), 0) << "the bed must lean";
    EXPECT_NEAR(torque, weightOffset, 0.02 * std::abs(weightOffset)) << id << " disks";
}

/// The packing fraction of spheres poured into a cylinder (analytic or a mesh of it) and settled, measured in a slab
/// away from the floor and the free surface.
double cylinderPacking(bool mesh, std::uint64_t seed) {
    const std::string text =
        R"(
name = "pack"
dimension = 3
duration = 0.2
seed = )" +
        std::to_string(seed) + R"(
[domain]
lo = [-0.021, -0.021, 0.0]
hi = [0.021, 0.021, 0.06]
gravity = [0.0, 0.0, -9.81]
[materials.glass]
density = 2500
restitution = 0.3
friction = 0.3
[contact]
normal = "linear"
duration = 2e-4
tangential = "spring"
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "glass"
[[walls]]
)" +
        (mesh ? std::string("type = \"mesh\"\nfile = \"meshes/cylinder.stl\"\n")
              : std::string("type = \"cylinder\"\nbase = [0.0, 0.0, 0.0]\naxis = [0.0, 0.0, 1.0]\nlength = 0.06\n"
                            "radius = 0.02\n")) +
        R"(material = "glass"
[[insert]]
arrangement = "random"
count = 1500
radius = 0.0012
material = "glass"
region = { lo = [-0.0135, -0.0135, 0.002], hi = [0.0135, 0.0135, 0.058] }
)";
    const Scenario sc = parseScenario(text, std::string(HAET_SOURCE_DIR) + "/examples/pack.toml");
    World<3> w = buildWorld<3>(sc);
    TdmEngine<3> eng(w, tdmSettings<3>(sc, w));
    eng.advanceTo(sc.duration);
    // Volume of spheres in the slab 0.0035 < z < 0.0095 (their parts inside it; the bed is some 14 mm deep), over the
    // slab's volume in the cylinder (the mesh's inscribed polygon is within 0.2 % of the circle's area).
    const double z0 = 0.0035, z1 = 0.0095;
    double vol = 0;
    for (std::size_t i = 0; i < w.particles.size(); ++i) {
        const double a = w.particles.radius[i], z = w.particles.x[i][2];
        auto capBelow = [&](double h) {  // volume of the sphere below height h
            const double d = std::clamp(h - (z - a), 0.0, 2 * a);
            return kPi * d * d * (3 * a - d) / 3;
        };
        vol += capBelow(z1) - capBelow(z0);
    }
    return vol / (kPi * 0.02 * 0.02 * (z1 - z0));
}

TEST(WallsValidate, CylinderAndItsMeshPackAlike) {
    std::vector<double> analytic, mesh;
    for (std::uint64_t seed : {1, 2, 3}) {
        analytic.push_back(cylinderPacking(false, seed));
        mesh.push_back(cylinderPacking(true, seed));
    }
    auto mean = [](const std::vector<double>& v) { return testing::sampleStats(v).mean; };
    auto sd = [](const std::vector<double>& v) { return testing::sampleStats(v).sd; };
    const double spread = std::sqrt(sd(analytic) * sd(analytic) + sd(mesh) * sd(mesh)) / std::sqrt(3.0);
    EXPECT_GT(mean(analytic), 0.5);
    EXPECT_LT(mean(analytic), 0.66);
    EXPECT_NEAR(mean(mesh), mean(analytic), std::max(3 * spread, 0.01))
        << "analytic " << mean(analytic) << " +- " << sd(analytic) << ", mesh " << mean(mesh) << " +- " << sd(mesh);
}

}  // namespace
}  // namespace haet
