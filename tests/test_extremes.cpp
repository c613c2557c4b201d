// Scenes at the extremes (docs/stability.md), for every registered variant: steel-stiff grains, a
// 50 m/s impact on a wall, a size ratio of 1:10 with hundreds of small grains in one cell, zero damping
// over 10⁵ steps, overdamped contacts, grains that leave the domain; and the detection that stops a run
// that goes wrong, with one-line messages.
#include <cmath>

#include <gtest/gtest.h>

#include "demmat/stability.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

Material steel()
{
    Material m;
    m.density = 7800.0;
    m.young = 2e11;
    m.poisson = 0.3;
    m.shear = 0.0;  // E/(2(1+ν))
    m.gamma_n = m.gamma_t = m.mu = 0.0;
    return m;
}

double estar(double young, double poisson) { return young / (2.0 * (1.0 - poisson * poisson)); }

// A sphere of radius r moving at `speed` towards the floor z = 0, `gap` above it, no gravity.
Scene wall_impact(const Material& m, double speed, double r, double gap, double dt)
{
    Scene s = drop_scene(gap, r);
    s.name = "wall_impact";
    s.material = m;
    s.gravity = {0, 0, 0};
    s.particles[0].velocity = {0, 0, -speed};
    s.dt = dt;
    return s;
}

// The driver's error for a run of `steps` steps, or "" if it completed.
std::string run_error(VariantRun& run, std::int64_t steps, std::int64_t* step = nullptr, std::int64_t* particle = nullptr)
{
    try {
        run.driver->run(steps);
    } catch (const InstabilityError& e) {
        if (step) *step = e.step();
        if (particle) *particle = e.particle();
        return e.what();
    }
    return "";
}

bool contains(const std::string& s, const std::string& what) { return s.find(what) != std::string::npos; }

} // namespace

class Extremes : public ::testing::TestWithParam<std::string> {};

// ---- steel-stiff grains ----------------------------------------------------------------------------------

TEST_P(Extremes, SteelHeadOnMatchesHertz)
{
    const double v = 1.0, r = 0.004;
    Scene s = head_on_scene(v, r);
    s.material = steel();
    const double m = sphere_mass(r, 7800.0), es = estar(2e11, 0.3);
    const double tc = hertz_contact_time(m / 2, r / 2, es, v), hmax = hertz_max_overlap(m / 2, r / 2, es, v);
    s.dt = tc / 100.0;  // 2.5e-7 s, 0.06 of the Rayleigh time
    s.particles[0].position.x = -(r + hmax / 2);  // h_max apart: the contact starts after 0.35 t_c
    s.particles[1].position.x = r + hmax / 2;
    Case c(s);
    EXPECT_EQ(check_time_step(c.scene, c.state), "");
    VariantRun run(GetParam(), c.setup);
    double worst = 0.0;
    for (int k = 0; k < 400; ++k) {
        run.driver->step();
        const Snapshot sn = run.snapshot();
        const Vec3d d = sn.position[1] - sn.position[0];
        worst = std::max(worst, 2 * r - std::sqrt(dot(d, d)));
    }
    const Snapshot sn = run.snapshot();
    EXPECT_NEAR(worst / hmax, 1.0, 2e-3) << "h_max " << worst << " against " << hmax;
    EXPECT_NEAR((sn.velocity[1].x - sn.velocity[0].x) / v, 1.0, 1e-3);
}

TEST(ExtremesCheck, SteelAtThePapersTimeStepIsRefused)
{
    Scene s = head_on_scene(1.0, 0.004);
    s.material = steel();
    s.dt = 1e-5;  // the paper's Δt: 2.3 Rayleigh times of a 4 mm steel grain
    Case c(s);
    try {
        check_time_step(c.scene, c.state);
        ADD_FAILURE() << "a steel scene at the paper's time step was accepted";
    } catch (const Error& e) {
        EXPECT_TRUE(contains(e.what(), "exceeds the Rayleigh time")) << e.what();
        EXPECT_TRUE(contains(e.what(), "use dt <=")) << e.what();
    }
}

// ---- a 50 m/s impact ---------------------------------------------------------------------------------------

TEST_P(Extremes, FiftyMetresPerSecondOnSteelIsResolved)
{
    const double v = 50.0, r = 0.004;
    const double m = sphere_mass(r, 7800.0), es = estar(2e11, 0.3);
    const double tc = hertz_contact_time(m, r, es, v), hmax = hertz_max_overlap(m, r, es, v);
    Case c(wall_impact(steel(), v, r, hmax, tc / 50.0));
    EXPECT_EQ(check_time_step(c.scene, c.state), "");
    VariantRun run(GetParam(), c.setup);
    double worst = 0.0;
    for (int k = 0; k < 200; ++k) {
        run.driver->step();
        worst = std::max(worst, r - run.snapshot().position[0].z);
    }
    EXPECT_NEAR(worst / hmax, 1.0, 5e-3);
    EXPECT_NEAR(run.snapshot().velocity[0].z / v, 1.0, 2e-3);  // undamped: rebounds at 50 m/s
}

TEST(ExtremesCheck, FiftyMetresPerSecondWithATooLongStepIsRefused)
{
    // The paper's material at 50 m/s: Δt = 5e-4 s is within the Rayleigh time (1.3e-3 s) but the grain
    // travels 25 mm, six radii, in one step; the Hertz contact time at 50 m/s (1.2e-3 s) refuses it.
    Scene s = drop_scene(0.001, 0.004);
    s.particles[0].velocity = {0, 0, -50.0};
    s.dt = 5e-4;
    Case c(s);
    try {
        check_time_step(c.scene, c.state);
        ADD_FAILURE() << "a step that crosses the wall was accepted";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_TRUE(contains(m, "of the Hertz contact time")) << m;
        EXPECT_TRUE(contains(m, "impact speed 51.9 m/s")) << m;
        EXPECT_TRUE(contains(m, "stability limit")) << m;
        EXPECT_TRUE(contains(m, "use dt <=")) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos);
    }
}

TEST_P(Extremes, AGrainThatCrossesAWallInOneStepIsCaught)
{
    // Told to go on (--allow-unstable: no check_time_step), a steel grain at 50 m/s with Δt = 2.4e-4 s
    // starts 1 mm above the floor and is 11 mm behind it after the predictor: the first check stops it.
    Scene s = wall_impact(steel(), 50.0, 0.004, 0.001, 2.4e-4);
    s.checks.interval = 1;
    Case c(s);
    EXPECT_THROW(check_time_step(c.scene, c.state), Error);
    VariantRun run(GetParam(), c.setup);
    std::int64_t step = -1, particle = -1;
    const std::string m = run_error(run, 100, &step, &particle);
    EXPECT_EQ(step, 1) << m;
    EXPECT_EQ(particle, 0) << m;
    EXPECT_TRUE(contains(m, "step 1: particle 0 ")) << m;
    EXPECT_TRUE(contains(m, "Hertz contact time")) << m;  // the hint names the stable Δt
}

// ---- size ratio 1:10, many grains in one cell ----------------------------------------------------------------

namespace {

// A grain of R = 5 mm just above the floor of a closed box and 294 grains of r = 0.5 mm in a block above
// it, falling at 0.5 m/s: cells of 2·R_max = 10 mm hold up to hundreds of small grains each.
Scene mixture()
{
    Scene s = drop_scene();
    s.name = "mixture_1_10";
    s.domain = {{0, 0, 0}, {0.03, 0.03, 0.04}};
    s.walls = box_walls(s.domain);
    s.capacity.contacts_per_particle = 128;  // the big grain (id 0) meets dozens of small ones
    s.particles = {{0.005, {0.015, 0.015, 0.0051}, {}, {}}};
    for (int k = 0; k < 6; ++k)
        for (int j = 0; j < 7; ++j)
            for (int i = 0; i < 7; ++i)
                s.particles.push_back({0.0005, {0.0117 + 0.0011 * i, 0.0117 + 0.0011 * j, 0.0115 + 0.0011 * k}, {0, 0, -0.5}, {}});
    return s;
}

} // namespace

TEST_P(Extremes, SizeRatioTenWithHundredsOfGrainsInACell)
{
    Case c(mixture());
    EXPECT_EQ(c.setup.cell_size, 0.01);  // cells sized from the largest grain
    EXPECT_EQ(check_time_step(c.scene, c.state), "");
    if (GetParam() != "arrays" && registry().find(GetParam()).bitwise) {
        const CompareReport r = compare_variants({"arrays", GetParam()}, c.setup, 500);
        EXPECT_FALSE(r.difference) << r.difference->describe();
        return;  // arrays itself runs the checks below
    }
    VariantRun run(GetParam(), c.setup);
    EXPECT_EQ(run_error(run, 500), "");
    EXPECT_GT(run.variant->counts().particle_particle, 40);  // the block has landed on the big grain
}

TEST(ExtremesCheck, SizeRatioTenSearchEqualsEveryPair)
{
    std::vector<Snapshot> out;
    for (SearchMethod m : {SearchMethod::cells, SearchMethod::all_pairs}) {
        Scene s = mixture();
        s.search.method = m;
        Case c(s);
        VariantRun run("arrays", c.setup);
        run.driver->run(500);
        out.push_back(run.snapshot());
    }
    const auto d = first_difference(out[0], out[1]);
    EXPECT_FALSE(d) << d->describe();
}

TEST_P(Extremes, SmallGrainRestsOnABigOneAtTheAnalyticOverlaps)
{
    // r = 0.4 mm on R = 4 mm on the floor, strongly damped (γ_n = 2000 1/s) so that it is at rest in 0.1 s.
    const double R = 0.004, r = 0.0004;
    Scene s = drop_scene();
    s.name = "stack_1_10";
    s.material.gamma_n = 2000.0;
    s.particles = {{R, {0, 0, R + 1e-5}, {}, {}}, {r, {0, 0, 2 * R + r + 2e-5}, {}, {}}};
    Case c(s);
    VariantRun run(GetParam(), c.setup);
    EXPECT_EQ(run_error(run, 10000), "");
    const Snapshot sn = run.snapshot();
    const double mb = c.setup.mass[0], ms = c.setup.mass[1], es = c.setup.contact.estar_pp();
    const double hw = std::pow(3.0 * (mb + ms) * 10.0 / (4.0 * es * std::sqrt(R)), 2.0 / 3.0);
    const double hp = std::pow(3.0 * ms * 10.0 / (4.0 * es * std::sqrt(R * r / (R + r))), 2.0 / 3.0);
    EXPECT_NEAR((R - sn.position[0].z) / hw, 1.0, 1e-5);
    EXPECT_NEAR((R + r - (sn.position[1].z - sn.position[0].z)) / hp, 1.0, 1e-5);
}

// ---- zero damping: energy over 10⁵ steps ------------------------------------------------------------------

namespace {

// Eight grains in a closed box under gravity, no damping, no friction: they bounce for ever.
Scene elastic_box()
{
    Scene s = dense_bed_scene(8, 3);
    s.name = "elastic_box";
    s.material.gamma_n = s.material.gamma_t = s.material.mu = 0.0;
    s.grid->speed_max = 0.3;  // with the fall, impacts stay below 1 m/s: overlaps below 0.4·R
    return s;
}

double total_energy(const Snapshot& sn, const Case& c)
{
    double e = kinetic_energy(sn, c.setup) +
               elastic_energy(sn.position, c.state.radius, c.state.walls, sn.step, c.scene.dt, c.setup.contact);
    for (std::size_t i = 0; i < sn.position.size(); ++i) e -= c.setup.mass[i] * dot(c.scene.gravity, sn.position[i]);
    return e;
}

} // namespace

TEST_P(Extremes, ZeroDampingEnergyDriftIsBoundedOver1e5Steps)
{
    Case c(elastic_box());
    VariantRun run(GetParam(), c.setup);
    Snapshot sn = run.snapshot();
    sn.position = c.state.trans.x;  // before the first step the snapshot's forces are zero; positions are the state's
    sn.velocity = c.state.trans.v;
    const double e0 = total_energy(sn, c);
    double scale = kinetic_energy(sn, c.setup);  // + what gravity can trade across the box's height
    for (double m : c.setup.mass) scale += m * 10.0 * (c.scene.domain.max.z - c.scene.domain.min.z);
    double worst = 0.0;
    std::int64_t contacts = 0;
    for (int block = 0; block < 100; ++block) {
        ASSERT_EQ(run_error(run, 1000), "");
        contacts += run.variant->counts().particle_particle + run.variant->counts().particle_wall;
        worst = std::max(worst, std::abs(total_energy(run.snapshot(), c) - e0));
    }
    EXPECT_GT(contacts, 10);  // the grains do collide
    // Gear at Δt ≈ t_c/200: the energy error of a contact is tiny and does not accumulate.
    EXPECT_LT(worst / scale, 1e-4) << "energy drift " << worst << " J of " << scale << " J";
}

// ---- overdamped contacts ----------------------------------------------------------------------------------

TEST_P(Extremes, OverdampedContactGainsNoEnergyAndDoesNotStick)
{
    // γ_n·h_max/v = 20: restitution about 0; Δt = 2e-6 s keeps γ_n·Δt = 0.05.
    const double v = 1.0, r = 0.004;
    Scene s = head_on_scene(v, r);
    s.material.gamma_n = 25600.0;
    s.dt = 2e-6;
    s.checks.interval = 1;
    Case c(s);
    VariantRun run(GetParam(), c.setup);
    const double es = c.setup.contact.estar_pp();
    double last = INFINITY, hmax = 0.0, prev_h = -1.0;
    bool past_max = false;
    for (int k = 0; k < 5000; ++k) {
        ASSERT_EQ(run_error(run, 1), "");
        const Snapshot sn = run.snapshot();
        const Vec3d d = sn.position[1] - sn.position[0];
        const double h = 2 * r - std::sqrt(dot(d, d));
        const double e = kinetic_energy(sn, c.setup) + (h > 0 ? 0.4 * es * 4.0 / 3.0 * std::sqrt(r / 2) * h * h * std::sqrt(h) : 0.0);
        ASSERT_LE(e, last * (1 + 1e-12)) << "energy grew at step " << k + 1;
        last = e;
        ASSERT_LE(sn.force[0].x, 0.0) << "attraction at step " << k + 1;  // the force on 0 points away from 1
        if (h > 0 && prev_h > 0 && h < prev_h) past_max = true;
        if (past_max) {
            ASSERT_LE(h, prev_h) << "the pair approached again at step " << k + 1;
        }
        hmax = std::max(hmax, h);
        prev_h = h;
    }
    EXPECT_TRUE(past_max);
    const Snapshot sn = run.snapshot();
    const double e = (sn.velocity[1].x - sn.velocity[0].x) / v;
    EXPECT_GE(e, 0.0);
    EXPECT_LT(e, 0.05);
    EXPECT_LT(hmax, hertz_max_overlap(c.setup.mass[0] / 2, r / 2, es, v));  // damping shortens the approach
}

// ---- grains that leave the domain ---------------------------------------------------------------------------

TEST_P(Extremes, AGrainLeavingThroughAnOpenSideFliesOn)
{
    // The domain is open where it has no wall (docs/stability.md): a grain thrown out of it is in free
    // flight, exact, and no check mistakes the fall for a blow-up: after 2.5 s it is 300 domain heights
    // below and falls at 25 m/s, beyond ten times the fall across the domain (19.6 m/s). Δt = 1e-4 s:
    // the Gear scheme integrates free fall exactly at any Δt.
    Scene s = drop_scene(0.05, 0.004);
    s.walls.clear();
    s.particles[0].velocity = {1.0, 0.0, 0.0};
    s.dt = 1e-4;
    Case c(s);
    VariantRun run(GetParam(), c.setup);
    ASSERT_EQ(run_error(run, 25000), "");
    const double t = 25000 * c.scene.dt;
    const Snapshot sn = run.snapshot();
    EXPECT_NEAR(sn.position[0].x, t, 1e-9);
    EXPECT_NEAR(sn.position[0].z, 0.054 - 5.0 * t * t, 1e-8);
    EXPECT_NEAR(sn.velocity[0].z, -10.0 * t, 1e-9);
}

TEST_P(Extremes, AClosedBoxKeepsItsGrains)
{
    // The same grain in the box closed by walls bounces off x_max and the floor and stays inside.
    Scene s = drop_scene(0.05, 0.004);
    s.walls = box_walls(s.domain);
    s.particles[0].velocity = {1.0, 0.0, 0.0};
    Case c(s);
    VariantRun run(GetParam(), c.setup);
    ASSERT_EQ(run_error(run, 35000), "");
    const Snapshot sn = run.snapshot();
    for (int a = 0; a < 3; ++a) {
        EXPECT_GT(component(sn.position[0], a), component(s.domain.min, a));
        EXPECT_LT(component(sn.position[0], a), component(s.domain.max, a));
    }
}

// ---- detection -------------------------------------------------------------------------------------------------

TEST_P(Extremes, EnergyGrowthIsDetected)
{
    // Undamped head-on at Δt = 0.22 t_c: the Gear scheme gains energy in the contact (docs/stability.md)
    // while no grain is yet fast, deep or behind a wall: the energy check stops it.
    const double v = 1.0, r = 0.004;
    Scene s = head_on_scene(v, r);
    const double m = sphere_mass(r, 1000.0);
    s.dt = 0.22 * hertz_contact_time(m / 2, r / 2, s.contact_params().estar_pp(), v);
    s.checks.interval = 1;
    Case c(s);
    VariantRun run(GetParam(), c.setup);
    std::int64_t step = -1, particle = -1;
    const std::string msg = run_error(run, 100, &step, &particle);
    EXPECT_TRUE(contains(msg, "exceeds the start energy plus the work of gravity")) << msg;
    EXPECT_TRUE(contains(msg, "energy growth")) << msg;
    EXPECT_TRUE(contains(msg, "step " + std::to_string(step) + ": ")) << msg;
    EXPECT_GE(particle, 0);
    EXPECT_EQ(msg.find('\n'), std::string::npos);
}

TEST(ExtremesCheck, StandardScenesPassTheTimeStepChecks)
{
    for (const Scene& s : {paper_scene(), dense_bed_scene(2000), head_on_scene(), drop_scene()}) {
        Case c(s);
        EXPECT_EQ(check_time_step(c.scene, c.state), "") << s.name;
    }
}

INSTANTIATE_TEST_SUITE_P(AllVariants, Extremes, ::testing::ValuesIn(variant_names()),
                         [](const auto& info) { return param_name(info.param); });
