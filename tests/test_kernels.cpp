// The shared kernels on problems with known answers: the Gear scheme (free fall, harmonic oscillator)
// and the contact law (hand-computed values).
#include <cmath>

#include <gtest/gtest.h>

#include "demmat/contact_law.hpp"
#include "demmat/gear.hpp"
#include "support.hpp"

using namespace demmat;

namespace {

// One degree of freedom x'' = f(x, v) integrated by the shared kernels.
template <class F>
double integrate(double x0, double v0, double dt, std::int64_t steps, F accel)
{
    const auto k = GearCoefficients<double>::make(dt);
    double x = x0, v = v0, a = accel(x0, v0), b3 = 0, b4 = 0, b5 = 0;
    for (std::int64_t s = 0; s < steps; ++s) {
        gear_predict(x, v, a, b3, b4, b5, k);
        const double da = accel(x, v) - a;
        gear_correct(x, v, a, b3, b4, b5, da, k);
    }
    return x;
}

} // namespace

TEST(Gear, FreeFallIsExactUpToRounding)
{
    // A constant acceleration has b3 = b4 = b5 = 0 forever: the predictor is the exact Taylor polynomial.
    const double g = -10.0, dt = 1e-3;
    const std::int64_t n = 1000;
    const double x = integrate(2.0, 3.0, dt, n, [&](double, double) { return g; });
    const double t = double(n) * dt;
    EXPECT_NEAR(x, 2.0 + 3.0 * t + 0.5 * g * t * t, 1e-12);
}

TEST(Gear, HarmonicOscillatorConvergesAtTheExpectedOrder)
{
    // x'' = -ω² x, x(0) = 1, v(0) = 0; position error at t = 2 against cos(ωt) as Δt halves. The
    // 6-value Gear scheme converges at global order 4 in position on this problem (with c0 = 3/16 it
    // approaches 4 from above: 4.4, 4.2, 4.1 for ω·Δt from 0.03 to 0.004; with 3/20 from below). The
    // test asserts the observed order over three halvings, well clear of rounding (errors >= 1e-12).
    const double w = 2.0 * 3.14159265358979323846, tend = 2.0;
    auto err = [&](double dt) {
        const auto n = std::int64_t(std::llround(tend / dt));
        const double x = integrate(1.0, 0.0, dt, n, [&](double x, double) { return -w * w * x; });
        return std::abs(x - std::cos(w * tend));
    };
    double prev = err(5e-3);
    for (double dt : {2.5e-3, 1.25e-3, 6.25e-4}) {
        const double e = err(dt);
        const double order = std::log2(prev / e);
        EXPECT_GT(order, 3.9) << "dt " << dt;
        EXPECT_LT(order, 4.6) << "dt " << dt;
        prev = e;
    }
    EXPECT_LT(prev, 2e-12);
}

TEST(ContactLaw, HandComputedNormalDampedAndCoulombFriction)
{
    ContactParams<double> p{1.0, 1.0, 0.1, 0.2, 0.5};
    // Unit spheres of unit mass 1.9 apart along x: h = 0.1, n = x, R* = 0.5, m* = 0.5.
    ContactForce<double> c;
    ASSERT_TRUE(particle_contact<FullModel>(Vec3d{0, 0, 0}, Vec3d{1.9, 0, 0}, Vec3d{1, 0.5, 0}, Vec3d{0, 0, 0}, Vec3d{}, Vec3d{},
                                            1.0, 1.0, 1.0, 1.0, p, c));
    const double fe = std::sqrt(0.5) * 0.1 * std::sqrt(0.1);  // (4/3)E* = 1
    const double fn = fe + 0.1 * 0.5 * 1.0;                    // + γn·m*·u_n, u_n = 1
    const double ft = std::min(0.5 * fn, 0.2 * 0.5 * 0.5);     // Coulomb limit 0.036 < viscous 0.05
    EXPECT_NEAR(c.overlap, 0.1, 1e-15);
    EXPECT_NEAR(c.f_i.x, -fn, 1e-15);
    EXPECT_NEAR(c.f_i.y, -ft, 1e-15);
    EXPECT_EQ(c.f_i.z, 0.0);
    EXPECT_NEAR(ft, 0.5 * fn, 1e-15);  // this configuration is in the Coulomb regime
    // Lever arms ±0.95 n; both torques are (0, 0, -0.95·ft).
    EXPECT_NEAR(c.t_i.z, -0.95 * ft, 1e-15);
    EXPECT_NEAR(c.t_j.z, -0.95 * ft, 1e-15);
    EXPECT_EQ(c.t_i.x, 0.0);
    EXPECT_EQ(c.t_i.y, 0.0);
}

TEST(ContactLaw, ViscousTangentialRegimeAndSpinContribution)
{
    ContactParams<double> p{1.0, 1.0, 0.0, 0.2, 10.0};
    ContactForce<double> c;
    // i spins about z at 1 rad/s: ω × d_i = (0, 0, 1) × (0.95, 0, 0) = (0, 0.95, 0) at the contact.
    ASSERT_TRUE(particle_contact<FullModel>(Vec3d{0, 0, 0}, Vec3d{1.9, 0, 0}, Vec3d{}, Vec3d{}, Vec3d{0, 0, 1}, Vec3d{}, 1.0, 1.0,
                                            1.0, 1.0, p, c));
    EXPECT_NEAR(c.f_i.y, -0.2 * 0.5 * 0.95, 1e-15);  // viscous: γt·m*·|u_t| < μ·Fn
}

TEST(ContactLaw, NoAttractionAndNoContactWhenApart)
{
    ContactParams<double> p{1.0, 1.0, 100.0, 0.2, 0.5};
    ContactForce<double> c;
    // Separating fast: the damping term exceeds the elastic one, F_n is clipped to zero.
    ASSERT_TRUE(particle_contact<FullModel>(Vec3d{0, 0, 0}, Vec3d{1.99, 0, 0}, Vec3d{-1, 0.3, 0}, Vec3d{}, Vec3d{}, Vec3d{}, 1.0, 1.0,
                                            1.0, 1.0, p, c));
    EXPECT_EQ(c.f_i.x, 0.0);
    EXPECT_EQ(c.f_i.y, 0.0);
    EXPECT_FALSE(particle_contact<FullModel>(Vec3d{0, 0, 0}, Vec3d{2.0, 0, 0}, Vec3d{}, Vec3d{}, Vec3d{}, Vec3d{}, 1.0, 1.0, 1.0,
                                             1.0, p, c));
    EXPECT_TRUE(may_touch(Vec3d{0, 0, 0}, Vec3d{1.9999999, 0, 0}, 1.0, 1.0));
}

TEST(ContactLaw, WallUsesParticleRadiusAndMassAndWallVelocity)
{
    ContactParams<double> p{0.0, 2.0, 0.5, 0.0, 0.0};
    ContactForce<double> c;
    // Particle of radius 1, mass 2, centre 0.9 above a floor moving up at 1 m/s: h = 0.1, u_n = +1.
    ASSERT_TRUE(wall_contact<FullModel>(Vec3d{0, 0, 0.9}, Vec3d{}, Vec3d{}, 1.0, 2.0, Vec3d{0, 0, 0}, Vec3d{0, 0, 1},
                                        Vec3d{0, 0, 1}, p, c));
    const double fn = 2.0 * std::sqrt(1.0) * 0.1 * std::sqrt(0.1) + 0.5 * 2.0 * 1.0;
    EXPECT_NEAR(c.f_i.z, fn, 1e-15);  // pushes the particle up, into the domain
}

TEST(Material, EffectiveModulusAndRayleighTime)
{
    Scene s = paper_scene();
    const auto c = s.contact_params();
    const double estar = 0.3e6 / (2.0 * (1.0 - 0.09));
    EXPECT_NEAR(c.hertz_pp, 4.0 / 3.0 * estar, 1e-9);
    EXPECT_NEAR(c.hertz_pw, c.hertz_pp, 1e-9);  // choice: walls have the particles' material
    // T_R = π R sqrt(ρ/G) / (0.1631 ν + 0.8766) for R = 3 mm.
    EXPECT_NEAR(rayleigh_time(s.material, 0.003), 3.14159265358979 * 0.003 * std::sqrt(1000.0 / 0.11e6) / (0.1631 * 0.3 + 0.8766),
                1e-15);
}
