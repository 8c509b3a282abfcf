// The measurements of a run (docs/physics.md L; docs/scenario.md "Fields", "Regions"): the contact network's
// records against the contact law bit for bit, and a run that records them against one that does not; a static
// bed's coarse-grained stress against the weight above each height and its series stress against the virial
// theorem; an elastic hard-sphere gas's collisional stress against the collision virial; bad [[fields]] keys.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "cli_util.hpp"
#include "csv_util.hpp"
#include "physics_util.hpp"
#include "run/runner.hpp"
#include "tdm/engine.hpp"
#include "world/build.hpp"
#include "world_util.hpp"

namespace haet {
namespace {

namespace fs = std::filesystem;

/// Two spheres meeting obliquely with spin, then a sphere sliding on a plane under gravity: the recorded forces
/// are the ones the pass added to the particles, bit for bit.
TEST(ContactNetwork, RecordsAreTheLawsForcesBitForBit) {
    const Scenario sc = testing::linearScenario(3, 0.7, 1e-4, 0.5, TangentialLaw::Spring);
    const double a = 0.001, rho = 2500;
    for (bool wall : {false, true}) {
        World<3> w;
        w.domain = testing::openBox<3>(0.05);
        if (wall) {
            w.domain.gravity = Vec<3>{{0, 0, -9.81}};
            w.particles.add(Vec<3>{{0, 0, a * 0.999}}, Vec<3>{{0.05, 0.02, -0.01}}, Ang<3>{{0.0, 3.0, 1.0}}, a, rho, 0,
                            0);
            Wall<3> floor = Wall<3>::plane(Vec<3>::zero(), Vec<3>{{0, 0, 1}}, Vec<3>::zero(), 0);
            floor.id = 0;
            w.walls.push_back(floor);
        } else {
            w.particles.add(Vec<3>{{0, 0, 0}}, Vec<3>{{0.05, 0.01, 0}}, Ang<3>{{0, 0, 5}}, a, rho, 0, 0);
            w.particles.add(Vec<3>{{1.97 * a, 0.3 * a, 0.1 * a}}, Vec<3>{{-0.05, 0, 0.01}}, Ang<3>{{1, 0, 0}}, a, rho,
                            0, 1);
        }
        w.contact = buildContactSetup<3>(sc, testing::statsOf(w.particles, 1));
        TdmSettings s;
        s.dt = w.contact.contactTime / 50;
        s.skin = a;
        s.sortEvery = 0;
        TdmEngine<3> eng(w, s);
        for (int k = 0; k < 3; ++k) eng.step();  // a spring that has grown
        ContactSink<3> sink;
        eng.recordContactsAt(&sink, eng.timeAfter(1));
        eng.step();
        ASSERT_EQ(eng.contactsRecordedAt(), w.time);
        ASSERT_EQ(sink.size(), 1u) << (wall ? "wall" : "pair");
        const ContactRecord<3>& r = sink[0];
        const Particles<3>& p = w.particles;
        EXPECT_GT(norm(r.ft), 1e-3 * norm(r.fn)) << "the test wants a tangential force";
        if (wall) {
            EXPECT_EQ(r.j, ContactRecord<3>::kWall);
            EXPECT_EQ(r.wall, 0);
            Vec<3> f = w.domain.gravity * p.mass[0];  // the pass's order: gravity, then the wall's law
            f += r.fn;
            f += r.ft;
            for (int k = 0; k < 3; ++k) EXPECT_EQ(p.f[0][k], f[k]) << k;
            EXPECT_NEAR(r.overlap, a - p.x[0][2], 1e-15);
            EXPECT_EQ(r.point[2], 0.0);
        } else {
            const Vec<3> f = r.fn + r.ft;  // the law's f = n fn, then f += ft
            for (int k = 0; k < 3; ++k) {
                EXPECT_EQ(p.f[r.i][k], f[k]) << k;
                EXPECT_EQ(p.f[r.j][k], -f[k]) << k;
            }
            EXPECT_NEAR(r.overlap, 2 * a - norm(p.x[0] - p.x[1]), 1e-15);
            EXPECT_NEAR(norm(r.normal), 1.0, 1e-15);
            EXPECT_NEAR(dot(r.fn, r.ft), 0.0, 1e-12 * norm2(r.fn));
        }
        EXPECT_EQ(r.idI, p.id[r.i]);
    }
}

/// A run that records its contacts at every step (single-threaded recording passes) ends in the same state, bit for
/// bit, as one that never does, with the threads of the machine.
TEST(ContactNetwork, RecordingChangesNothing) {
    const Scenario sc = testing::exampleScenario("bed3d_fields.toml");
    World<3> a = buildWorld<3>(sc), b = buildWorld<3>(sc);
    std::string note;
    TdmEngine<3> ea(a, tdmSettings<3>(sc, a, &note)), eb(b, tdmSettings<3>(sc, b, &note));
    // The bed landed on its floor: the steps below have many contacts.
    ea.advanceTo(0.12);
    eb.advanceTo(0.12);
    ContactSink<3> sink;
    std::size_t recorded = 0;
    for (int k = 0; k < 300; ++k) {
        eb.recordContactsAt(&sink, eb.timeAfter(1));
        eb.advanceTo(eb.timeAfter(1));
        recorded += sink.size();
    }
    ea.advanceTo(eb.timeAfter(0));
    EXPECT_GT(recorded, 300u * 700u);  // more than one contact a grain
    ASSERT_EQ(a.particles.size(), b.particles.size());
    for (std::size_t i = 0; i < a.particles.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(a.particles.x[i][k], b.particles.x[i][k]) << i;
            ASSERT_EQ(a.particles.v[i][k], b.particles.v[i][k]) << i;
        }
}

/// The contacts of the state at construction (the outputs at the start time): the constructor's pass again, so the
/// records are the forces in the store bit for bit, and the run goes on as one that never recorded.
TEST(ContactNetwork, StartContactsAreTheFirstPassBitForBit) {
    const Scenario sc = testing::linearScenario(3, 0.7, 1e-4, 0.5, TangentialLaw::Spring);
    const double a = 0.001, rho = 2500;
    auto world = [&] {
        World<3> w;
        w.domain = testing::openBox<3>(0.05);
        w.domain.gravity = Vec<3>{{0, 0, -9.81}};
        w.particles.add(Vec<3>{{0, 0, a * 0.999}}, Vec<3>{{0.05, 0.02, -0.01}}, Ang<3>{{0.0, 3.0, 1.0}}, a, rho, 0, 0);
        w.particles.add(Vec<3>{{1.9 * a, 0.3 * a, 0.998 * a}}, Vec<3>{{-0.05, 0, 0.01}}, Ang<3>{{1, 0, 0}}, a, rho, 0,
                        1);
        Wall<3> floor = Wall<3>::plane(Vec<3>::zero(), Vec<3>{{0, 0, 1}}, Vec<3>::zero(), 0);
        floor.id = 0;
        w.walls.push_back(floor);
        w.contact = buildContactSetup<3>(sc, testing::statsOf(w.particles, 1));
        return w;
    };
    World<3> wa = world(), wb = world();
    TdmSettings s;
    s.dt = wa.contact.contactTime / 50;
    s.skin = a;
    s.sortEvery = 0;
    TdmEngine<3> ea(wa, s), eb(wb, s);
    ContactSink<3> sink;
    ASSERT_TRUE(eb.recordStartContacts(&sink));
    EXPECT_EQ(eb.contactsRecordedAt(), wb.time);
    ASSERT_EQ(sink.size(), 3u);  // the pair and each sphere on the floor
    const Particles<3>& p = wb.particles;
    for (std::size_t i = 0; i < 2; ++i) {
        Vec<3> f = Vec<3>::zero();
        for (const ContactRecord<3>& r : sink) {
            if (r.i == i) f += r.fn + r.ft;
            if (r.j == i) f -= r.fn + r.ft;
        }
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(p.f[i][k], f[k] + p.mass[i] * wb.domain.gravity[k], 1e-12) << i;
        for (int k = 0; k < 3; ++k) EXPECT_EQ(p.f[i][k], wa.particles.f[i][k]) << i;
    }
    for (int k = 0; k < 20; ++k) {
        ea.step();
        eb.step();
    }
    EXPECT_FALSE(eb.recordStartContacts(&sink));  // not after a step
    for (std::size_t i = 0; i < 2; ++i)
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(wa.particles.x[i][k], wb.particles.x[i][k]);
            EXPECT_EQ(wa.particles.w[i][k], wb.particles.w[i][k]);
        }
}

/// Polygons (and disks among them) have their contact network too, through the polygon kernel's one-pair path:
/// every particle's force is gravity plus its records' forces, the records' normal and tangential parts are
/// orthogonal, and a run that records at every step ends as one that does not, bit for bit.
TEST(ContactNetwork, PolygonRecordsSumToTheForces) {
    struct Case {
        const char* name;
        std::vector<std::string> overrides;
    };
    // The pile; the box with disks among its hexagons.
    const std::vector<Case> cases = {{"pile2d_polygons.toml", {}},
                                     {"box2d_polygons.toml",
                                      {"contact.duration=5e-4",
                                       "insert[2]={ arrangement = \"random\", count = 300, radius = [0.0015, 0.002], "
                                       "material = \"grain\", region = { lo = [0.0, 0.075], hi = [0.1, 0.15] } }"}}};
    for (const Case& c : cases) {
        const char* name = c.name;
        const Scenario sc = testing::exampleScenario(name, c.overrides);
        World<2> a = buildWorld<2>(sc), b = buildWorld<2>(sc);
        std::string note;
        TdmEngine<2> ea(a, tdmSettings<2>(sc, a, &note)), eb(b, tdmSettings<2>(sc, b, &note));
        ea.advanceTo(0.15);
        eb.advanceTo(0.15);
        ContactSink<2> sink;
        std::size_t walls = 0, pairs = 0;
        for (int k = 0; k < 50; ++k) {
            eb.recordContactsAt(&sink, eb.timeAfter(1));
            eb.advanceTo(eb.timeAfter(1));
        }
        ea.advanceTo(eb.timeAfter(0));
        const Particles<2>& p = b.particles;
        std::vector<Vec<2>> f(p.size(), Vec<2>::zero());
        double scale = 0;
        for (const ContactRecord<2>& r : sink) {
            const Vec<2> fr = r.fn + r.ft;
            f[r.i] += fr;
            if (r.j == ContactRecord<2>::kWall) {
                ++walls;
                EXPECT_GE(r.wall, 0);
            } else {
                ++pairs;
                f[r.j] -= fr;
            }
            EXPECT_NEAR(norm(r.normal), 1.0, 1e-12);
            EXPECT_NEAR(dot(r.fn, r.ft), 0.0, 1e-9 * norm2(fr) + 1e-300);
            EXPECT_GE(dot(r.fn, r.normal), 0.0);
            EXPECT_GT(r.overlap, 0.0);
            scale = std::max(scale, norm(fr));
        }
        EXPECT_GT(pairs, p.size() / 2) << name;
        EXPECT_GT(walls, 10u) << name;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.flags[i] & kFrozen) continue;
            for (int k = 0; k < 2; ++k)
                EXPECT_NEAR(p.f[i][k], f[i][k] + p.mass[i] * b.domain.gravity[k], 1e-9 * scale) << name << " " << i;
        }
        for (std::size_t i = 0; i < p.size(); ++i)
            for (int k = 0; k < 2; ++k) {
                ASSERT_EQ(a.particles.x[i][k], b.particles.x[i][k]) << name << " " << i;
                ASSERT_EQ(a.particles.v[i][k], b.particles.v[i][k]) << name << " " << i;
            }
    }
}

fs::path runExample(const std::string& name, const std::vector<std::string>& overrides = {}) {
    const Scenario sc = testing::exampleScenario(name, overrides);
    RunOptions o;
    o.outDir = fs::temp_directory_path() / ("haet_fields_" + std::to_string(::getpid()) + "_" + name);
    o.quiet = true;
    std::ostringstream log;
    EXPECT_EQ(runScenario(sc, o, log), RunStatus::Completed) << log.str();
    return o.outDir;
}

/// examples/bed3d_fields.toml settled: at every height of the bulk the coarse-grained vertical stress is the weight
/// of the grains above per area (docs/physics.md L.3), within 1 %; the bed's mean stress in series.csv is
/// sum m g z / V (the virial theorem, L.5), within 1 %; the lower region carries more than the mean.
TEST(FieldsRun, StaticBedStressIsTheWeightAbove) {
    const fs::path out = runExample("bed3d_fields.toml");
    const testing::CsvTable series = testing::readCsv(out / "series.csv");
    ASSERT_GT(series.rows.size(), 10u);
    const std::size_t last = series.rows.size() - 1;
    EXPECT_LT(series.at(last, "kinetic_energy"), 1e-9) << "not at rest";
    const double g = 9.81, area = 0.008 * 0.008, volume = area * 0.03;
    const testing::CsvTable state = testing::readCsv(out / "final.csv");
    double mgz = 0;
    for (std::size_t i = 0; i < state.rows.size(); ++i) {
        const double r = state.at(i, "radius");
        mgz += 2500 * 4.0 / 3.0 * std::numbers::pi * r * r * r * g * state.at(i, "z");
    }
    EXPECT_NEAR(series.at(last, "stress_zz"), mgz / volume, 0.01 * mgz / volume);
    EXPECT_GT(series.at(last, "lower_stress_zz"), 2 * series.at(last, "stress_zz"));
    EXPECT_NEAR(series.at(last, "stress_xz"), 0.0, 0.01 * series.at(last, "stress_zz"));

    const testing::CsvTable f = testing::readCsv(out / "fields_z.csv");
    const std::vector<double> time = f.column("time"), z = f.column("z"), rho = f.column("density"),
                              szz = f.column("contact_stress_zz");
    std::vector<std::size_t> cells;
    for (std::size_t r = 0; r < f.rows.size(); ++r)
        if (time[r] == time.back()) cells.push_back(r);
    ASSERT_EQ(cells.size(), 120u);
    const double h = z[cells[1]] - z[cells[0]];
    double above = 0, top = 0;
    std::vector<double> weight(cells.size());
    for (std::size_t q = cells.size(); q-- > 0;) {
        weight[q] = above + 0.5 * rho[cells[q]] * h * g;  // the cell's own weight: half of it above its centre
        above += rho[cells[q]] * h * g;
    }
    for (std::size_t q = 0; q < cells.size(); ++q)
        if (rho[cells[q]] > 500) top = z[cells[q]];
    int checked = 0;
    for (std::size_t q = 0; q < cells.size(); ++q) {
        const double zc = z[cells[q]];
        if (zc < 0.0015 || zc > top - 0.002) continue;  // the bulk: 3 widths above the floor, 2 d below the top
        EXPECT_NEAR(szz[cells[q]], weight[q], 0.01 * weight[q]) << "z = " << zc;
        ++checked;
    }
    EXPECT_GT(checked, 20);
    fs::remove_all(out);
}

/// examples/gas3d_fields.toml (elastic hard spheres, event-driven): in every window the coarse-grained collisional
/// pressure, averaged over the box, is the collision-virial pressure of series.csv (docs/physics.md L.4, E.2), and
/// the whole stress's is the pressure, within 1 %; the series stress's trace over 3 is the pressure.
TEST(FieldsRun, ElasticGasCollisionalPressureIsTheVirial) {
    const fs::path out = runExample("gas3d_fields.toml");
    const testing::CsvTable s = testing::readCsv(out / "series.csv");
    const testing::CsvTable f = testing::readCsv(out / "fields_z.csv");
    const double volume = std::pow(0.0184, 3);
    int windows = 0;
    for (std::size_t r = 0; r < s.rows.size(); ++r) {
        const double t = s.at(r, "time"), pressure = s.at(r, "pressure");
        const double trace = (s.at(r, "stress_xx") + s.at(r, "stress_yy") + s.at(r, "stress_zz")) / 3;
        EXPECT_NEAR(trace, pressure, 1e-9 * pressure) << t;
        if (t == 0) continue;  // no window yet
        const double virial = pressure - 2 * s.at(r, "kinetic_energy") / (3 * volume);
        double col = 0, all = 0;
        int n = 0;
        for (std::size_t c = 0; c < f.rows.size(); ++c) {
            if (std::abs(f.at(c, "time") - t) > 1e-9 * t) continue;
            col += (f.at(c, "collisional_stress_xx") + f.at(c, "collisional_stress_yy") +
                    f.at(c, "collisional_stress_zz")) /
                   3;
            all += (f.at(c, "stress_xx") + f.at(c, "stress_yy") + f.at(c, "stress_zz")) / 3;
            ++n;
        }
        ASSERT_EQ(n, 20) << t;
        EXPECT_GT(virial, 0.3 * pressure);
        EXPECT_NEAR(col / n, virial, 0.01 * virial) << t;
        EXPECT_NEAR(all / n, pressure, 0.01 * pressure) << t;
        ++windows;
    }
    EXPECT_EQ(windows, 5);
    fs::remove_all(out);
}

class FieldsInput : public testing::cli::Cli {};

/// A bad key of a [[fields]] or [[regions]] block stops `haet check` with exit code 2 and file:line: key.
TEST_F(FieldsInput, BadKeysNameFileLineAndKey) {
    const std::string base = testing::sceneText("bed3d_fields.toml");
    struct Case {
        std::string from, to, line, key, what;  // line: how the blamed line starts
    };
    const std::vector<Case> cases = {
        {"axes = \"z\"", "axes = \"w\"", "axes = \"w\"", "fields[1].axes", "distinct letters"},
        {"cells = 120 ", "cells = 0 ", "cells = 0", "fields[1].cells", "must be >= 1"},
        {"width = 0.0005 ", "width = -1 ", "width = -1", "fields[1].width", "must be > 0"},
        {"kernel = \"gaussian\"", "kernel = \"box\"", "kernel = \"box\"", "fields[1].kernel", "must be one of"},
        {"window = 0.01 ", "windw = 0.01 ", "windw", "fields[1].windw", "unknown key"},
        {"period = 0.05\n", "period = 0.05\nfields = [\"pressure\"]\n", "fields = [", "fields[1].fields",
         "unknown field"},
        {"period = 0.05\n", "period = 0.05\nfields = [\"collisional_stress\"]\n", "fields = [", "fields[1].fields",
         "event-driven"},
        {"name = \"lower\"", "name = \"lo wer\"", "name = \"lo wer\"", "regions[1].name", "only letters"},
        {"hi = [0.008, 0.008, 0.003]", "hi = [0.008, 0.008, 0.5]",
         "region = { lo = [0.0, 0.0, 0.0], hi = [0.008, 0.008, 0.5]", "regions[1].region", "inside the domain"},
    };
    for (const Case& c : cases) {
        const std::string text = testing::replaced(base, c.from, c.to);
        ASSERT_NE(text, base) << c.from;
        const fs::path file = dir_ / "bad.toml";
        std::ofstream(file) << text;
        const Result r = haet("check '" + file.string() + "'");
        EXPECT_EQ(r.code, 2) << c.key << ": " << r.err;
        const std::string where =
            file.string() + ":" + std::to_string(testing::cli::lineOf(text, c.line)) + ": " + c.key + ": ";
        EXPECT_NE(r.err.find(where), std::string::npos) << where << " in " << r.err;
        EXPECT_NE(r.err.find(c.what), std::string::npos) << c.key << ": " << r.err;
    }
}

}  // namespace
}  // namespace haet
