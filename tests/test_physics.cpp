// Every registered variant against analytic results: a head-on Hertz collision (physics.md §8), energy
// conservation without damping, a sphere settling on a wall, free fall, and momentum conservation.
#include <cmath>

#include <gtest/gtest.h>

#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

class Physics : public ::testing::TestWithParam<std::string> {};

namespace {
double estar_pp(const Scene& s) { return s.contact_params().estar_pp(); }
} // namespace

TEST_P(Physics, HeadOnHertzMatchesAnalyticOverlapAndContactTime)
{
    const double v = 1.0, r = 0.004;
    Case c(head_on_scene(v, r));
    VariantRun run(GetParam(), c.setup);
    const double m = c.setup.mass[0], mstar = m / 2, rstar = r / 2, es = estar_pp(c.scene);
    const double hmax_exact = std::pow(15.0 * mstar * v * v / (16.0 * es * std::sqrt(rstar)), 0.4);
    const double tc_exact = 2.87 * std::pow(mstar * mstar / (rstar * es * es * v), 0.2);
    double hmax = 0.0;
    std::int64_t first = -1, last = -1;
    for (std::int64_t k = 1; k <= 2000; ++k) {
        run.driver->step();
        const Snapshot s = run.snapshot();
        const Vec3d d = s.position[1] - s.position[0];
        const double h = 2 * r - std::sqrt(dot(d, d));
        if (h > 0) {
            if (first < 0) first = k;
            last = k;
            hmax = std::max(hmax, h);
        }
    }
    ASSERT_GT(first, 0);
    const double tc = double(last - first + 1) * c.scene.dt;
    EXPECT_NEAR(hmax / hmax_exact, 1.0, 2e-3) << "h_max " << hmax << " against " << hmax_exact;
    // 2.87 is the rounded constant of the analytic contact time (2.868); the step resolves t_c to 1/200.
    EXPECT_NEAR(tc / tc_exact, 1.0, 1e-2) << "t_c " << tc << " against " << tc_exact;
    // Without damping the restitution is 1: the pair separates at its approach speed.
    const Snapshot s = run.snapshot();
    EXPECT_NEAR((s.velocity[1].x - s.velocity[0].x) / v, 1.0, 2e-3);
}

TEST_P(Physics, EnergyIsConservedWithoutDampingOrFriction)
{
    const double v = 1.0, r = 0.004;
    Case c(head_on_scene(v, r));
    VariantRun run(GetParam(), c.setup);
    const double es = estar_pp(c.scene), rstar = r / 2;
    const double e0 = kinetic_energy(run.snapshot(), c.setup);
    double worst = 0.0;
    for (std::int64_t k = 1; k <= 1500; ++k) {
        run.driver->step();
        const Snapshot s = run.snapshot();
        const Vec3d d = s.position[1] - s.position[0];
        const double h = std::max(0.0, 2 * r - std::sqrt(dot(d, d)));
        const double e = kinetic_energy(s, c.setup) + 8.0 / 15.0 * es * std::sqrt(rstar) * std::pow(h, 2.5);
        worst = std::max(worst, std::abs(e - e0) / e0);
    }
    EXPECT_LT(worst, 1e-4);
}

TEST_P(Physics, SphereSettlesOnAWallAtTheAnalyticOverlap)
{
    const double r = 0.004;
    Case c(drop_scene(0.001, r));
    VariantRun run(GetParam(), c.setup);
    run.driver->run(120000);  // 1.2 s: the bounce decays as exp(-γn·t/2), to 1e-15 of its amplitude
    const Snapshot s = run.snapshot();
    const double m = c.setup.mass[0];
    const double es = c.scene.contact_params().estar_pw();
    const double h_exact = std::pow(3.0 * m * 10.0 / (4.0 * es * std::sqrt(r)), 2.0 / 3.0);
    EXPECT_NEAR((r - s.position[0].z) / h_exact, 1.0, 1e-6);
    EXPECT_LT(std::abs(s.velocity[0].z), 1e-9);
}

TEST_P(Physics, FreeFallFollowsTheParabola)
{
    Scene sc = drop_scene(0.05, 0.004);
    sc.walls.clear();
    Case c(sc);
    VariantRun run(GetParam(), c.setup);
    run.driver->run(1000);
    const double t = 1000 * c.scene.dt;
    EXPECT_NEAR(run.snapshot().position[0].z, 0.054 - 5.0 * t * t, 1e-14);
}

TEST_P(Physics, ParticleContactsConserveMomentum)
{
    // A loose cloud with random velocities, no gravity, no walls: every contact force acts on both
    // particles with opposite signs, so total momentum changes only by rounding.
    Scene sc = dense_bed_scene(343, 7);
    sc.gravity = {0, 0, 0};
    sc.walls.clear();
    sc.grid->spacing = 2.02 * sc.grid->radius_max;  // close enough for many collisions
    Case c(sc);
    VariantRun run(GetParam(), c.setup);
    auto momentum = [&](const Snapshot& s) {
        Vec3d p{};
        for (std::size_t i = 0; i < s.velocity.size(); ++i) p += c.setup.mass[i] * s.velocity[i];
        return p;
    };
    double scale = 0.0;
    for (std::size_t i = 0; i < c.state.size(); ++i) scale += c.setup.mass[i] * std::sqrt(dot(c.state.trans.v[i], c.state.trans.v[i]));
    const Vec3d p0 = momentum(run.snapshot());
    run.driver->run(3000);
    EXPECT_GT(run.variant->counts().particle_particle, 0);
    const Vec3d p1 = momentum(run.snapshot());
    EXPECT_LT(std::abs(p1.x - p0.x) / scale, 1e-12);
    EXPECT_LT(std::abs(p1.y - p0.y) / scale, 1e-12);
    EXPECT_LT(std::abs(p1.z - p0.z) / scale, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(AllVariants, Physics, ::testing::ValuesIn(variant_names()),
                         [](const auto& info) { return param_name(info.param); });
