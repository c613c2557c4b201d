// Exchange with LAMMPS and LIGGGHTS (docs/peers.md): the data-file and dump round trips are exact, and,
// where Debian's lammps is installed, two-body contacts run by LAMMPS from the exported files agree with
// the suite (skipped elsewhere).
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "demmat/io.hpp"
#include "demmat/peer_io.hpp"
#include "support.hpp"

namespace demmat {
namespace {

namespace fs = std::filesystem;

fs::path scratch_dir(const std::string& name)
{
    const fs::path d = fs::temp_directory_path() / fmt::format("demmat_test_peers_{}_{}", name, ::getpid());
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

void expect_same_bits(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, const char* what)
{
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_TRUE(std::memcmp(&a[i], &b[i], sizeof(Vec3d)) == 0) << what << " of particle " << i << " differs";
        if (std::memcmp(&a[i], &b[i], sizeof(Vec3d)) != 0) return;
    }
}

// A loose bed with random spins as well, so every column of the files carries information.
State spinning_bed(const Scene& scene)
{
    State s = initial_state(scene);
    std::mt19937_64 g(5);
    std::uniform_real_distribution<double> u(-30.0, 30.0);
    for (Vec3d& w : s.rot.v) w = {u(g), u(g), u(g)};
    return s;
}

TEST(PeerIo, DataFileRoundTripIsBitExact)
{
    const Scene scene = dense_bed_scene(300, 7);
    const State s = spinning_bed(scene);
    const fs::path dir = scratch_dir("data");
    const PeerExport e = export_peers(scene, s, {});
    write_atomically(dir / "scene.data", e.data);
    const State back = import_peer_state(dir / "scene.data", scene);
    ASSERT_EQ(back.size(), s.size());
    EXPECT_TRUE(std::memcmp(back.radius.data(), s.radius.data(), s.size() * sizeof(double)) == 0);
    expect_same_bits(back.trans.x, s.trans.x, "position");
    expect_same_bits(back.trans.v, s.trans.v, "velocity");
    expect_same_bits(back.rot.v, s.rot.v, "angular velocity");
    // The t = 0 accelerations come from the same reference code as for the scene itself.
    const State fresh = initial_state(scene);
    expect_same_bits(back.trans.a, fresh.trans.a, "acceleration");
    EXPECT_EQ(back.fingerprint, s.fingerprint);
    fs::remove_all(dir);
}

TEST(PeerIo, DumpRoundTripTakesTheLastFrameExactly)
{
    const Scene scene = dense_bed_scene(125, 3);
    const State s = spinning_bed(scene);
    std::vector<Vec3d> moved = s.trans.x;
    for (Vec3d& x : moved) x.z -= 1e-3;
    const fs::path dir = scratch_dir("dump");
    write_atomically(dir / "run.dump", lammps_dump_frame(0, scene, s.radius, s.trans.x, s.trans.v, s.rot.v) +
                                           lammps_dump_frame(100, scene, s.radius, moved, s.trans.v, s.rot.v));
    const State back = import_peer_state(dir / "run.dump", scene);
    expect_same_bits(back.trans.x, moved, "position");
    expect_same_bits(back.rot.v, s.rot.v, "angular velocity");
    fs::remove_all(dir);
}

TEST(PeerIo, PerturbationIsSmallReproducibleAndSeeded)
{
    const Scene scene = dense_bed_scene(200, 1);
    const State s = initial_state(scene);
    State a = s, b = s, c = s;
    perturb_velocities(a, 1e-6, 4);
    perturb_velocities(b, 1e-6, 4);
    perturb_velocities(c, 1e-6, 5);
    expect_same_bits(a.trans.v, b.trans.v, "perturbed velocity");
    double largest = 0.0;
    bool differs = false;
    for (std::size_t i = 0; i < s.size(); ++i) {
        for (int k = 0; k < 3; ++k) largest = std::max(largest, std::abs(component(a.trans.v[i], k) - component(s.trans.v[i], k)));
        differs = differs || !(a.trans.v[i] == c.trans.v[i]);
    }
    EXPECT_LE(largest, 1e-6 * (1 + 1e-9));
    EXPECT_GT(largest, 0.5e-6);
    EXPECT_TRUE(differs) << "another seed must give another perturbation";
}

TEST(PeerIo, DamagedFilesAreRefusedWithTheirName)
{
    const Scene scene = dense_bed_scene(27, 1);
    const State s = initial_state(scene);
    const fs::path dir = scratch_dir("bad");
    std::string data = export_peers(scene, s, {}).data;
    write_atomically(dir / "cut.data", data.substr(0, data.size() / 2));
    try {
        import_peer_state(dir / "cut.data", scene);
        ADD_FAILURE() << "a truncated data file was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cut.data"), std::string::npos) << e.what();
    }
    const std::string other = std::string(data).replace(data.find(" 1000 "), 6, " 2000 ");  // another density
    write_atomically(dir / "density.data", other);
    EXPECT_THROW(import_peer_state(dir / "density.data", scene), Error);
    fs::remove_all(dir);
}

TEST(PeerIo, LammpsWallModulusGivesTheSuitesEffectiveModulus)
{
    // fix wall/gran turns its argument E into E/(2(1-ν)) (measured, docs/peers.md).
    const double estar = 123456.0, nu = 0.3;
    EXPECT_DOUBLE_EQ(lammps_wall_modulus_argument(estar, nu) / (2.0 * (1.0 - nu)), estar);
    const Scene scene = drop_scene();
    const PeerExport e = export_peers(scene, initial_state(scene), {});
    EXPECT_NE(e.lammps.find("wall/gran granular hertz/material 230769.23076923"), std::string::npos) << e.lammps;
}

#ifdef DEMMAT_LAMMPS_EXECUTABLE
// Runs the exported scene in LAMMPS (Debian's binary unless `lmp` names another, with `options` on its
// command line) for `steps` steps and returns its final particles.
State run_lammps(const Scene& scene, const State& s, std::int64_t steps, const std::string& name,
                 const std::string& lmp = DEMMAT_LAMMPS_EXECUTABLE, const std::string& options = "")
{
    const fs::path dir = scratch_dir(name);
    PeerOptions o;
    o.data_name = name + ".data";
    const PeerExport e = export_peers(scene, s, o);
    write_atomically(dir / o.data_name, e.data);
    write_atomically(dir / (name + ".lammps"), e.lammps);
    write_atomically(dir / "in.test", fmt::format("include {}.lammps\nthermo 0\nrun {}\nwrite_dump all custom final.dump id radius x y z vx vy vz "
                                                  "omegax omegay omegaz modify sort id format float %.17g\n", name, steps));
    const std::string cmd = fmt::format("cd '{}' && OMP_NUM_THREADS=1 '{}' {} -in in.test -log none -nocite > lammps.out 2>&1", dir.string(),
                                        lmp, options);
    EXPECT_EQ(std::system(cmd.c_str()), 0) << "LAMMPS failed; see " << (dir / "lammps.out");
    State out = import_peer_state(dir / "final.dump", scene);
    fs::remove_all(dir);
    return out;
}

Snapshot run_suite(const Scene& scene, std::int64_t steps)
{
    const Problem p(scene);
    test::VariantRun run("arrays", p.setup());
    run.driver->run(steps);
    return run.snapshot();
}

TEST(PeerLammps, SphereComesToRestOnAWallAtTheSuitesOverlap)
{
    // The wall's modulus is where fix wall/gran differs from the pair style; a wrong conversion changes
    // the rest overlap by 19 % (E/(2(1-ν)) against E/(2(1-ν²)) at ν = 0.3).
    const Scene scene = drop_scene(0.0005);
    const std::int64_t steps = 60000;  // 0.6 s: the bounce has died away (γn = 60 1/s)
    const State lammps = run_lammps(scene, initial_state(scene), steps, "drop");
    const Snapshot suite = run_suite(scene, steps);
    const double r = scene.particles[0].radius;
    const double m = sphere_mass(r, scene.material.density);
    const double estar = scene.contact_params().estar_pw();
    const double h_rest = std::cbrt(std::pow(3.0 * m * 10.0 / (4.0 * estar * std::sqrt(r)), 2.0));  // physics.md §8
    const double h_lammps = r - lammps.trans.x[0].z, h_suite = r - suite.position[0].z;
    EXPECT_NEAR(h_suite, h_rest, 1e-3 * h_rest);
    EXPECT_NEAR(h_lammps, h_rest, 1e-3 * h_rest);
    EXPECT_NEAR(h_lammps, h_suite, 1e-3 * h_rest);
}

TEST(PeerLammps, DampedHeadOnCollisionReboundsAsInTheSuite)
{
    // Damping γn·m*·u_n (mass_velocity) with the clip at the end of the contact (limit_damping): the
    // rebound speed depends on both. Gear against velocity Verlet with ~60 steps per contact differ by
    // far less than 1 %; a damping form off by a factor (2γn, or γn·a·m*) changes it by several percent (about 3.5 % for 2γn).
    Scene scene = head_on_scene(1.0);
    scene.material.gamma_n = 60.0;
    const std::int64_t steps = 2000;
    const State lammps = run_lammps(scene, initial_state(scene), steps, "head_on");
    const Snapshot suite = run_suite(scene, steps);
    const double v_suite = suite.velocity[1].x - suite.velocity[0].x;
    const double v_lammps = lammps.trans.v[1].x - lammps.trans.v[0].x;
    EXPECT_GT(v_suite, 0.0) << "the spheres must have separated";
    EXPECT_LT(v_suite, 0.99) << "the damping must have taken energy";
    EXPECT_NEAR(v_lammps, v_suite, 1e-2 * v_suite) << "restitution: suite " << v_suite << ", LAMMPS " << v_lammps;
}

// ---- the laws with memory (physics.md §9) against LAMMPS's pair_style granular and fix wall/gran ------
// LAMMPS differs from the suite only where physics.md §9 lists it: velocity Verlet against Gear, full
// radii against the lever arms R − h/2. The last matters in proportion to h/R, more so under mindlin
// (k_t grows with the contact radius): with E = 10⁷ Pa (h/R up to 3 %) a sticking wall impact's rebound
// spin differs by about 7 %, with E = 10⁹ Pa (h/R below 0.5 %) by under 2 %, hence the stiff wall case.
// Each case is chosen so that the stretch decides the outcome (the contact sticks: its tangential impulse
// stays far below μ times the normal one), so a wrong stiffness, damping ratio, cap or wall k_t moves the
// rebound by more than the tolerance (3·10⁻³ of the impact speed); checked by mutation: k_t ×1.5, x_γt ×2,
// k_r ×2, γ_r ×2, μ_r ×0.5 and the wall's mindlin NULL each fail a case.

ContactModel history_law(TangentialModel t, bool rolling)
{
    ContactModel m;
    m.damping = NormalDamping::restitution;
    m.restitution = 0.7;
    m.tangential = t;
    m.kt = 2000.0;
    m.tangential_damping_ratio = 0.5;
    if (rolling) {
        m.rolling = RollingModel::sds;
        m.kr = 500.0;
        m.rolling_damping = 0.5;
        m.rolling_friction = 0.2;
    }
    return m;
}

// A sphere at (vt, 0, −vn) with spin onto the floor, no gravity.
Scene oblique_wall_scene(const ContactModel& law, double vt, double vn, double spin)
{
    Scene scene = drop_scene(1e-6);
    scene.gravity = {};
    scene.dt = 2e-7;
    scene.material.young = 1e9;
    scene.material.mu = 0.3;
    scene.contact_model = law;
    scene.particles[0].velocity = {vt, 0.0, -vn};
    scene.particles[0].angular_velocity = {0.0, spin, 0.0};
    return scene;
}
constexpr std::int64_t kWallImpactSteps = 3000;  // the contact lasts about 800 steps

// The wall impact run by the suite and by LAMMPS for kWallImpactSteps.
std::pair<Snapshot, State> oblique_wall_impact(const ContactModel& law, double vt, double vn, double spin, const std::string& name)
{
    const Scene scene = oblique_wall_scene(law, vt, vn, spin);
    const State lammps = run_lammps(scene, initial_state(scene), kWallImpactSteps, name);
    return {run_suite(scene, kWallImpactSteps), lammps};
}

// Two spheres meeting off-centre with opposite spins, the linear history and sds rolling laws.
Scene oblique_pair_scene()
{
    Scene scene = head_on_scene(0.5);
    scene.dt = 2e-6;
    scene.material.young = 1e7;
    scene.material.mu = 0.3;
    scene.contact_model = history_law(TangentialModel::linear_history, true);
    scene.particles[0].position = {-(0.004 + 1e-6), -0.001, 0.0};
    scene.particles[1].position = {0.004 + 1e-6, 0.001, 0.0};
    scene.particles[0].angular_velocity = {0.0, 0.0, 20.0};
    scene.particles[1].angular_velocity = {0.0, 0.0, -20.0};
    return scene;
}

void expect_close(const Vec3d& suite, const Vec3d& lammps, double scale, const char* what)
{
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(component(lammps, c), component(suite, c), 3e-3 * scale) << what << " component " << c;
}

TEST(PeerLammps, ObliqueWallImpactWithMindlinAsInTheSuite)
{
    // The contact sticks: the rebound spin and tangential speed depend on the wall's 8·G* (given to LAMMPS
    // as a number, physics.md §9).
    const auto [suite, lammps] = oblique_wall_impact(history_law(TangentialModel::mindlin, false), 0.1, 0.5, 0.0, "wall_mindlin");
    ASSERT_GT(suite.position[0].z, 0.004) << "the sphere must have left the wall";
    const double jt = 0.1 - suite.velocity[0].x, jn = suite.velocity[0].z + 0.5;
    EXPECT_LT(jt, 0.5 * 0.3 * jn) << "the contact must stick for part of the impact, not slide throughout";
    expect_close(suite.velocity[0], lammps.trans.v[0], 0.5, "velocity");
    expect_close(0.004 * suite.angular_velocity[0], 0.004 * lammps.rot.v[0], 0.5, "spin·R");
}

TEST(PeerLammps, ObliquePairImpactWithLinearHistoryAndRollingAsInTheSuite)
{
    // Two spheres meeting off-centre with opposite spins: the tangential spring and the rolling spring
    // both act; the final velocities and spins of both depend on k_t, x_γt, k_r, γ_r and μ_r.
    const Scene scene = oblique_pair_scene();
    const std::int64_t steps = 3000;
    const State lammps = run_lammps(scene, initial_state(scene), steps, "pair_history");
    const Snapshot suite = run_suite(scene, steps);
    ASSERT_GT(suite.position[1].x - suite.position[0].x, 0.008) << "the spheres must have separated";
    for (int i = 0; i < 2; ++i) {
        expect_close(suite.velocity[i], lammps.trans.v[i], 0.5, "velocity");
        expect_close(0.004 * suite.angular_velocity[i], 0.004 * lammps.rot.v[i], 0.5, "spin·R");
    }
}

#ifdef DEMMAT_LAMMPS_NATIVE
// The LAMMPS that run_peers.sh times (scripts/build_lammps.sh: -O3 -march=native, GRANULAR, OPENMP) runs
// the exported laws as Debian's binary does, on one thread and through its OPENMP styles on two: the pair
// impact (normal, tangential history and rolling terms) and the mindlin wall impact. -O3 -march=native lets
// GCC fuse multiply-adds, so the last bits may differ (two bodies, no chaos: far below the tolerance); a
// missing package or a style of another law would stop the run or move the rebound by percents.
TEST(PeerLammps, TheBuildForTheCpuRunsTheLawsAsDebiansBinary)
{
    const Scene pair = oblique_pair_scene();
    const Scene wall = oblique_wall_scene(history_law(TangentialModel::mindlin, false), 0.1, 0.5, 0.0);
    for (const auto& [scene, steps, name] : {std::tuple{pair, std::int64_t{3000}, "native_pair"},
                                             std::tuple{wall, kWallImpactSteps, "native_wall"}}) {
        const State debian = run_lammps(scene, initial_state(scene), steps, name);
        for (const char* options : {"", "-sf omp -pk omp 2"}) {
            const State native = run_lammps(scene, initial_state(scene), steps, name, DEMMAT_LAMMPS_NATIVE, options);
            ASSERT_EQ(native.size(), debian.size());
            for (std::size_t i = 0; i < debian.size(); ++i)
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(component(native.trans.v[i], c), component(debian.trans.v[i], c), 1e-9) << name << " " << options;
                    EXPECT_NEAR(0.004 * component(native.rot.v[i], c), 0.004 * component(debian.rot.v[i], c), 1e-9) << name << " " << options;
                }
        }
    }
}
#endif
#else
TEST(PeerLammps, SkippedWithoutLammps) { GTEST_SKIP() << "lmp not found at configure time (scripts/install_deps.sh --optional)"; }
#endif

} // namespace
} // namespace demmat
