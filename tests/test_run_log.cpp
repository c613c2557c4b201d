// The run log (run_log.hpp) against analytic values: free fall, energy conservation over an undamped
// bounce, a sphere at rest on the floor (wall force m·g, the Hertz elastic energy at the rest overlap of
// physics.md §8); the log file itself; and the walls of the VTK output (plane_in_box, VtkSeries).
#include <cmath>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "demmat/output.hpp"
#include "demmat/run_log.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

// The drop scene (a sphere of radius r above the floor, z_min) without damping or friction.
Scene undamped_drop(double gap, double r)
{
    Scene s = drop_scene(gap, r);
    s.material.gamma_n = 0.0;
    s.material.gamma_t = 0.0;
    s.material.mu = 0.0;
    return s;
}

std::vector<std::string> read_lines(const std::filesystem::path& file)
{
    std::ifstream in(file);
    std::vector<std::string> out;
    for (std::string line; std::getline(in, line);) out.push_back(line);
    return out;
}

std::vector<std::string> fields(const std::string& line)
{
    std::vector<std::string> out;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) out.push_back(f);
    return out;
}

} // namespace

TEST(RunLog, FreeFallIsExactAndTheUndampedBounceConservesTotalEnergy)
{
    const double gap = 0.001, r = 0.004;
    Problem c(undamped_drop(gap, r));
    VariantRun run("arrays", c.setup());
    const double m = c.setup().mass[0], g = c.scene().gravity.z, z0 = c.state().trans.x[0].z;
    const LogRow first = measure_log_row(run.snapshot(), c.setup());
    ASSERT_EQ(first.wall_force.size(), 1u);
    EXPECT_DOUBLE_EQ(first.gravitational, -m * g * z0);
    EXPECT_EQ(first.kinetic_translational, 0.0);
    const double e0 = first.total(), scale = m * std::abs(g) * gap;  // the energy the fall trades
    double worst_fall = 0.0, worst = 0.0, elastic_max = 0.0;
    std::int64_t free_rows = 0, contact_rows = 0, after_rows = 0;
    bool touched = false;
    for (std::int64_t k = 1; k <= 4000; ++k) {
        run.driver->step();
        const LogRow row = measure_log_row(run.snapshot(), c.setup());
        EXPECT_EQ(row.total(), row.kinetic_translational + row.kinetic_rotational + row.gravitational + row.elastic);
        worst = std::max(worst, std::abs(row.total() - e0) / scale);
        elastic_max = std::max(elastic_max, row.elastic);
        if (row.contacts_wall > 0) {
            touched = true;
            ++contact_rows;
        } else if (!touched) {
            // Before the contact: v = g·t and z = z0 + g·t²/2, which the Gear scheme integrates exactly.
            const double t = row.time, v = g * t, z = z0 + 0.5 * g * t * t;
            EXPECT_EQ(row.elastic, 0.0);
            EXPECT_EQ(row.kinetic_rotational, 0.0);
            worst_fall = std::max(worst_fall, std::abs(row.kinetic_translational - 0.5 * m * v * v) / scale);
            worst_fall = std::max(worst_fall, std::abs(row.gravitational - (-m * g * z)) / scale);
            ++free_rows;
        } else {
            ++after_rows;
        }
        EXPECT_EQ(row.wall_force[0].x, 0.0);
        EXPECT_EQ(row.wall_force[0].y, 0.0);
    }
    // The run covered the fall, a whole contact and the rise after it.
    ASSERT_GT(free_rows, 1000);
    ASSERT_GT(contact_rows, 100);
    ASSERT_GT(after_rows, 100);
    // At the deepest point the fall's energy is stored in the contact: without the elastic term the
    // total would dip by about `scale`.
    EXPECT_GT(elastic_max, 0.9 * scale);
    EXPECT_LT(worst_fall, 1e-11);
    EXPECT_LT(worst, 1e-5) << "total energy drifts by " << worst << " of m·g·gap over the bounce";
}

TEST(RunLog, ASphereAtRestPushesTheFloorWithItsWeightAndStoresTheHertzEnergy)
{
    const double r = 0.004;
    Problem c(drop_scene(0.001, r));
    VariantRun run("arrays", c.setup());
    run.driver->run(120000);  // 1.2 s: the bounce decays as exp(-γn·t/2), to 1e-15 of its amplitude
    const LogRow row = measure_log_row(run.snapshot(), c.setup());
    const double m = c.setup().mass[0];
    const Vec3d g = c.scene().gravity;
    const double es = c.setup().contact.hertz_pw * 3.0 / 4.0;
    const double h = std::pow(3.0 * m * std::sqrt(dot(g, g)) / (4.0 * es * std::sqrt(r)), 2.0 / 3.0);  // physics.md §8
    EXPECT_EQ(row.contacts_wall, 1);
    EXPECT_EQ(row.contacts_particle, 0);
    ASSERT_EQ(row.wall_force.size(), 1u);
    EXPECT_NEAR(row.wall_force[0].z / (m * g.z), 1.0, 1e-6) << "force on the floor " << row.wall_force[0].z;
    EXPECT_EQ(row.wall_force[0].x, 0.0);
    EXPECT_EQ(row.wall_force[0].y, 0.0);
    EXPECT_NEAR(row.elastic / (8.0 / 15.0 * es * std::sqrt(r) * std::pow(h, 2.5)), 1.0, 1e-5);
    EXPECT_NEAR(row.largest_overlap_ratio / (h / r), 1.0, 1e-5);
    EXPECT_LT(row.kinetic_translational, 1e-15 * m);
}

TEST(RunLog, PairContactsCountAndTheirReactionsBalanceTheWeightOnTheFloor)
{
    // Two spheres stacked on the floor at rest: one pair contact, one wall contact, and the floor carries
    // both weights; the pair's overlap ratio is the larger one (the lower sphere carries one weight).
    const double r = 0.004;
    Scene s = drop_scene(0.0001, r);
    s.particles.push_back({r, {0.0, 0.0, 3.0 * r + 0.0003}, {}, {}});
    Problem c(s);
    VariantRun run("arrays", c.setup());
    run.driver->run(300000);
    const LogRow row = measure_log_row(run.snapshot(), c.setup());
    const double m = c.setup().mass[0];
    EXPECT_EQ(row.contacts_particle, 1);
    EXPECT_EQ(row.contacts_wall, 1);
    EXPECT_NEAR(row.wall_force[0].z / (2.0 * m * s.gravity.z), 1.0, 1e-6);
    // The pair holds one weight with R* = r/2 and E*_pp; the wall holds two with R* = r and E*_pw.
    const double epp = c.setup().contact.hertz_pp * 0.75;
    const double h_pair = std::pow(3.0 * m * 10.0 / (4.0 * epp * std::sqrt(r / 2)), 2.0 / 3.0);
    const double h_wall = std::pow(3.0 * 2.0 * m * 10.0 / (4.0 * c.setup().contact.estar_pw() * std::sqrt(r)), 2.0 / 3.0);
    EXPECT_NEAR(row.largest_overlap_ratio, std::max(h_pair, h_wall) / r, 1e-5 * std::max(h_pair, h_wall) / r);
}

TEST(RunLog, ABlownUpStateGivesNaNNotACrash)
{
    // 125 grains: the contact set is a cell list, which cannot place a non-finite position.
    Problem c(dense_bed_scene(125));
    VariantRun run("arrays", c.setup());
    Snapshot s = run.snapshot();
    s.position[7].z = std::nan("");
    const LogRow row = measure_log_row(s, c.setup());
    EXPECT_TRUE(std::isnan(row.elastic));
    EXPECT_TRUE(std::isnan(row.total()));
    EXPECT_TRUE(std::isnan(row.largest_overlap_ratio));
    ASSERT_EQ(row.wall_force.size(), 6u);
    EXPECT_TRUE(std::isnan(row.wall_force[5].z));
    EXPECT_TRUE(log_line(row).find("nan") != std::string::npos);
}

TEST(RunLog, TheFileHasAHeaderAndARowPerLoggedStep)
{
    Problem c(undamped_drop(0.001, 0.004));
    VariantRun run("arrays", c.setup());
    const std::filesystem::path file = "run_log_test.csv";
    const std::int64_t steps = 250, every = 100;
    std::vector<LogRow> expected;
    {
        RunLog log(file, c.setup(), every);
        Snapshot s = run.snapshot();
        log.write(s);
        expected.push_back(measure_log_row(s, c.setup()));
        run.driver->run(steps, [&](std::int64_t k) {
            if (!log.due(k, steps)) return;
            run.variant->snapshot(s);
            log.write(s);
            expected.push_back(measure_log_row(s, c.setup()));
        });
        // Each row is in the file as soon as it is written, before the log is closed.
        EXPECT_EQ(read_lines(file).size(), 5u);
    }
    const auto lines = read_lines(file);
    ASSERT_EQ(lines.size(), 5u);  // header, steps 0, 100, 200 and the last, 250
    EXPECT_EQ(lines[0], log_header(1));
    const auto names = fields(lines[0]);
    ASSERT_EQ(names.size(), 13u);
    EXPECT_EQ(names[6], "total");
    EXPECT_EQ(names[12], "wall0_fz");
    const std::int64_t steps_seen[] = {0, 100, 200, 250};
    for (std::size_t i = 1; i < lines.size(); ++i) {
        const auto f = fields(lines[i]);
        ASSERT_EQ(f.size(), names.size());
        EXPECT_EQ(std::stoll(f[0]), steps_seen[i - 1]);
        // %.17g: the values read back exactly.
        EXPECT_EQ(std::stod(f[4]), expected[i - 1].gravitational);
        EXPECT_EQ(std::stod(f[6]), expected[i - 1].total());
    }
    EXPECT_THROW(RunLog(file, c.setup(), 0), Error);
    std::filesystem::remove(file);
}

TEST(RunLog, ThePathIsCheckedBeforeTheRun)
{
    namespace fs = std::filesystem;
    const fs::path dir = "run_log_path_test";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path scene = dir / "scene.toml";
    std::ofstream(scene) << "name = \"x\"\n";
    EXPECT_THROW(check_log_path(dir, {scene}), Error);                       // a folder
    EXPECT_THROW(check_log_path(dir / "missing" / "log.csv", {scene}), Error);  // no such folder
    EXPECT_THROW(check_log_path(scene, {scene}), Error);                     // the input itself
    EXPECT_THROW(check_log_path(dir / "." / "scene.toml", {scene}), Error);  // ... by another name
    EXPECT_NO_THROW(check_log_path(dir / "log.csv", {scene}));
    EXPECT_THROW(check_log_every(0), Error);
    EXPECT_NO_THROW(check_log_every(1));
    fs::remove_all(dir);
}

TEST(VtkWalls, APlaneCutsTheBoxInAConvexPolygonFacingItsNormal)
{
    const Box box{{0.0, 0.0, 0.0}, {0.1, 0.1, 0.1}};
    auto check = [&](const Vec3d& p, Vec3d n, std::size_t corners) {
        n = n / std::sqrt(dot(n, n));
        const auto poly = plane_in_box(p, n, box);
        ASSERT_EQ(poly.size(), corners);
        for (std::size_t k = 0; k < poly.size(); ++k) {
            const Vec3d& a = poly[k];
            EXPECT_NEAR(dot(a - p, n), 0.0, 1e-15);  // on the plane
            for (int c = 0; c < 3; ++c) {            // in the box
                EXPECT_GE(component(a, c), component(box.min, c) - 1e-15);
                EXPECT_LE(component(a, c), component(box.max, c) + 1e-15);
            }
            // Convex and counter-clockwise about n: every turn goes the same way, along n.
            const Vec3d b = poly[(k + 1) % poly.size()], d = poly[(k + 2) % poly.size()];
            EXPECT_GT(dot(cross(b - a, d - b), n), 0.0);
        }
    };
    check(box.min, {0, 0, 1}, 4);                 // the floor: the face itself
    check(box.max, {-1, 0, 0}, 4);                // x_max, normal inwards
    check({0.05, 0.0, 0.05}, {0, 0.1, 1}, 4);     // a ramp (scene-format.md)
    check({0.05, 0.05, 0.05}, {1, 1, 1}, 6);      // through the centre, diagonal: a hexagon
    check({0.0, 0.0, 0.0}, {1, 1, 1}, 0);         // touches a corner only
    check({0.0, 0.0, 0.01}, {1, 2, 3}, 3);        // cuts a corner off: a triangle
    check({0.0, 0.0, -1.0}, {0, 0, 1}, 0);        // misses the box
}

TEST(VtkWalls, AMovingWallIsWrittenWhereItStandsAndListedAsPartOne)
{
    namespace fs = std::filesystem;
    const fs::path dir = "vtk_walls_test";
    fs::remove_all(dir);
    const Box box{{0.0, 0.0, 0.0}, {0.1, 0.1, 0.1}};
    std::vector<Wall> walls = box_walls(box);
    const double dt = 1e-5;
    walls[1].velocity = {-0.5, 0.0, 0.0};  // x_max moving inwards
    ASSERT_EQ(walls[1].name, "x_max");
    VtkSeries vtk(dir, "t", box, walls, dt);
    Snapshot s;
    s.resize(1);
    s.step = 4000;
    vtk.write(s, {0.001}, double(s.step) * dt);
    std::ifstream in(dir / "t_walls_000004000.vtp");
    ASSERT_TRUE(in) << "no walls file";
    std::stringstream text;
    text << in.rdbuf();
    const std::string xml = text.str();
    EXPECT_NE(xml.find("NumberOfPoints=\"24\" NumberOfPolys=\"6\""), std::string::npos);
    // x_max's four corners at x = 0.1 − 0.5·4000·Δt = 0.08 (its point_at), the second quad in the file.
    const double x = walls[1].point_at(s.step, dt).x;
    // The text of the position array (std::regex is avoided: GCC 12's <regex> warns under the sanitizers).
    const auto array = xml.find("Name=\"position\"");
    ASSERT_NE(array, std::string::npos);
    const auto open = xml.find('>', array);
    ASSERT_NE(open, std::string::npos);
    std::stringstream pts(xml.substr(open + 1, xml.find('<', open) - open - 1));
    std::vector<Vec3d> p;
    for (Vec3d v; pts >> v.x >> v.y >> v.z;) p.push_back(v);
    ASSERT_EQ(p.size(), 24u);
    for (int k = 4; k < 8; ++k) EXPECT_DOUBLE_EQ(p[std::size_t(k)].x, x);
    EXPECT_NEAR(x, 0.08, 1e-12);
    std::ifstream pvd(dir / "t.pvd");
    std::stringstream series;
    series << pvd.rdbuf();
    EXPECT_NE(series.str().find("part=\"0\" file=\"t_000004000.vtp\""), std::string::npos);
    EXPECT_NE(series.str().find("part=\"1\" file=\"t_walls_000004000.vtp\""), std::string::npos);
    fs::remove_all(dir);
}
