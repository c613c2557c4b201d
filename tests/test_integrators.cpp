// The integrators of integrators.hpp: each converges at its theoretical order (harmonic oscillator,
// undamped and damped, so the velocity-dependent choice of Verlet is tested too), float stays within
// float-sized error of double on a Hertz impact, the arrays variant runs every choice through the Driver,
// and a variant that integrates with gear5 in double only refuses another choice.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "demmat/error.hpp"
#include "demmat/integrators.hpp"
#include "demmat/scene_toml.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

// x'' = -ω² x - c·x', x(0) = 1, v(0) = 0, integrated by scheme S on one value of type V.
template <class S, class V = double>
V oscillate(double dt, double tend, double w, double c)
{
    const auto k = S::template Coefficients<V>::make(dt);
    auto accel = [&](V x, V v) { return V(-w * w) * x - V(c) * v; };
    V x = 1, v = 0, a = accel(1, 0), b3 = 0, b4 = 0, b5 = 0;
    const auto n = std::int64_t(std::llround(tend / dt));
    for (std::int64_t s = 0; s < n; ++s) {
        S::predict(x, v, a, b3, b4, b5, k);
        S::correct(x, v, a, b3, b4, b5, accel(x, v), k);
    }
    return x;
}

double exact(double t, double w, double c)
{
    const double wd = std::sqrt(w * w - c * c / 4.0);  // underdamped
    return std::exp(-c * t / 2.0) * (std::cos(wd * t) + c / (2.0 * wd) * std::sin(wd * t));
}

// Observed global order in position, averaged over three halvings of Δt from dt0 (errors stay well
// above rounding), within [order - 0.2, order + 0.4]. tend = 2.3 avoids whole periods, where phase
// errors cancel (Verlet looks fourth order at t = 2).
template <class S>
void expect_order(double c, double dt0, double order)
{
    const double w = 2.0 * 3.14159265358979323846, tend = 2.3;
    auto err = [&](double dt) { return std::abs(oscillate<S>(dt, tend, w, c) - exact(tend, w, c)); };
    const double observed = std::log2(err(dt0) / err(dt0 / 8.0)) / 3.0;
    EXPECT_GT(observed, order - 0.2) << name(S::id) << " damping " << c;
    EXPECT_LT(observed, order + 0.4) << name(S::id) << " damping " << c;
}

} // namespace

TEST(Integrators, EachConvergesAtItsOrderOnTheHarmonicOscillator)
{
    // Forces that depend on position only: Gear 6-value and 4-value 4 (on this linear problem), Verlet 2,
    // symplectic Euler 1.
    expect_order<Gear5Scheme>(0.0, 1e-2, 4.0);
    expect_order<Gear3Scheme>(0.0, 1e-2, 4.0);
    expect_order<VerletScheme>(0.0, 1e-2, 2.0);
    expect_order<SymplecticEulerScheme>(0.0, 1e-2, 1.0);
}

TEST(Integrators, VelocityDependentForcesLimitTheOrder)
{
    // Damping 2 1/s on ω = 2π. One corrector pass with forces at the predicted velocity: both Gear
    // schemes fall to order 2 (docs/accuracy.md); Verlet, with forces at the Euler-predicted v(t+Δt),
    // stays second order (at the half-step velocity it would fall to 1); symplectic Euler stays 1.
    expect_order<Gear5Scheme>(2.0, 6.25e-4, 2.0);
    expect_order<Gear3Scheme>(2.0, 6.25e-4, 2.0);
    expect_order<VerletScheme>(2.0, 6.25e-4, 2.0);
    expect_order<SymplecticEulerScheme>(2.0, 6.25e-4, 1.0);
}

TEST(Integrators, NamesRoundTripAndTheDefaultIsThePapers)
{
    for (Integrator s : all_integrators) EXPECT_EQ(parse_integrator(name(s)), s);
    for (Precision p : all_precisions) EXPECT_EQ(parse_precision(name(p)), p);
    EXPECT_FALSE(parse_integrator("rk4"));
    EXPECT_TRUE(IntegratorChoice{}.is_default());
    EXPECT_EQ(Scene{}.integrator.scheme, Integrator::gear5);
    EXPECT_EQ(Scene{}.integrator.precision, Precision::float64);
}

TEST(Integrators, SceneKeyParsesAndIsWrittenBack)
{
    Scene s = head_on_scene();
    EXPECT_EQ(scene_to_toml(s).find("[integrator]"), std::string::npos);  // default: not written
    s.integrator = {Integrator::verlet, Precision::float32};
    const Scene back = parse_scene(scene_to_toml(s), "roundtrip");
    EXPECT_EQ(back.integrator, s.integrator);
    std::string bad = scene_to_toml(s);
    bad.replace(bad.find("\"verlet\""), 8, "\"rk4\"");
    try {
        parse_scene(bad, "bad");
        ADD_FAILURE() << "an unknown integrator was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("unknown integrator 'rk4'"), std::string::npos) << e.what();
    }
}

namespace {

struct Impact {
    double max_overlap = 0, restitution = 0;
};

// The head-on Hertz impact (physics.md §8) run by the arrays variant with a choice.
Impact head_on(IntegratorChoice choice, double dt)
{
    Scene s = head_on_scene(1.0);
    s.dt = dt;
    s.integrator = choice;
    Problem c(s);
    VariantRun run("arrays", c.setup());
    Impact out;
    const auto steps = std::int64_t(std::ceil(4e-3 / dt));
    for (std::int64_t k = 0; k < steps; ++k) {
        run.driver->step();
        const Snapshot snap = run.snapshot();
        const double d = snap.position[1].x - snap.position[0].x;
        out.max_overlap = std::max(out.max_overlap, 0.008 - d);
        out.restitution = (snap.velocity[1].x - snap.velocity[0].x) / 1.0;
    }
    return out;
}

} // namespace

TEST(Integrators, ArraysRunsEveryChoiceOnAHertzImpact)
{
    // Undamped head-on impact at 1 m/s (t_c ≈ 2.3 ms): every scheme at Δt = 2 µs (t_c/1150) matches the
    // analytic maximum overlap to 1e-3 (the per-step sampling of the maximum alone costs ~1e-5) and
    // rebounds elastically to 1e-3; float stays within 2e-4 of double (float's 6e-8 grown over
    // 2000 steps of a stiff contact; measured 1e-6 … 3e-5).
    Scene s = head_on_scene(1.0);
    Problem c(s);
    const double mstar = c.setup().mass[0] / 2.0, rstar = 0.002, estar = c.setup().contact.estar_pp();
    const double hmax = std::pow(15.0 * mstar / (16.0 * estar * std::sqrt(rstar)), 0.4);
    for (Integrator scheme : all_integrators) {
        const Impact d = head_on({scheme, Precision::float64}, 2e-6);
        const Impact f = head_on({scheme, Precision::float32}, 2e-6);
        EXPECT_NEAR(d.max_overlap / hmax, 1.0, 1e-3) << name(scheme);
        EXPECT_NEAR(d.restitution, 1.0, 1e-3) << name(scheme);
        EXPECT_NEAR(f.max_overlap / d.max_overlap, 1.0, 2e-4) << name(scheme);
        EXPECT_NEAR(f.restitution, d.restitution, 2e-4) << name(scheme);
        EXPECT_NE(f.max_overlap, d.max_overlap) << name(scheme) << ": the float run must really run in float";
    }
}

TEST(Integrators, ChoicesReallyDiffer)
{
    // At a coarse step the schemes give different answers: the choice reaches the kernels.
    const double g5 = head_on({Integrator::gear5, Precision::float64}, 4e-5).max_overlap;
    for (Integrator scheme : {Integrator::gear3, Integrator::verlet, Integrator::symplectic_euler})
        EXPECT_NE(head_on({scheme, Precision::float64}, 4e-5).max_overlap, g5) << name(scheme);
}

TEST(Integrators, AVariantWithoutTheChoiceRefusesIt)
{
    Scene s = head_on_scene(1.0);
    s.integrator = {Integrator::verlet, Precision::float64};
    Problem c(s);
    for (const std::string& v : variant_names()) {
        auto variant = registry().find(v).create();
        if (variant->supports(s.integrator)) continue;
        try {
            Driver d(*variant, c.setup());
            ADD_FAILURE() << v << " accepted an integrator it does not support";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("gear5 in double only, not verlet in double"), std::string::npos) << e.what();
        }
    }
    EXPECT_TRUE(registry().find("arrays").create()->supports(s.integrator));
}
