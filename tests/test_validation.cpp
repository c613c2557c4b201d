// The rigid wall and the Chung & Ooi (2011) tests (docs/validation.md): key quantities of each test against
// closed forms and rigid-body limits computed here, at a stated Δt and tolerance, so that a change of a
// kernel that breaks a benchmark fails CI. The full sweeps against the independent Python integration are
// scripts/run_validation.sh's; ChungOoiIntegratorsLong holds the integrator comparison (label long).
#include <gtest/gtest.h>

#include <cmath>

#include "demmat/chung_ooi.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/error.hpp"
#include "demmat/registry.hpp"
#include "demmat/scene_toml.hpp"
#include "demmat/scenes.hpp"
#include "demmat/stability.hpp"
#include "support.hpp"

using namespace demmat;

namespace {

ImpactResult run(const ChungOoiCase& c, const std::string& variant = "arrays")
{
    Problem p(chung_ooi_scene(c));
    auto v = registry().find(variant).create();
    return run_impact(*v, p, false);
}

double slip_compliance_wall(double m, double r) { return 1.0 / m + r * r / (0.4 * m * r * r); }  // 1/m + R²/I = 7/(2m)

} // namespace

// ---- the rigid wall ---------------------------------------------------------------------------------------

TEST(RigidWall, AddsNothingToEstarOrGstar)
{
    Scene s = drop_scene();
    s.wall_material = Material{};
    s.wall_material->rigid = true;
    const Material& m = s.material;
    EXPECT_DOUBLE_EQ(s.contact_params().estar_pw(), m.young / (1.0 - m.poisson * m.poisson));
    EXPECT_DOUBLE_EQ(s.contact_params().estar_pp(), m.young / (2.0 * (1.0 - m.poisson * m.poisson)));
    s.contact_model.damping = NormalDamping::restitution;
    s.contact_model.restitution = 0.5;
    s.contact_model.tangential = TangentialModel::mindlin;
    const MemoryParams<double> q = memory_params(s);
    EXPECT_DOUBLE_EQ(q.shear8_pw, 8.0 / (2.0 * (2.0 - m.poisson) * (1.0 + m.poisson) / m.young));
    EXPECT_DOUBLE_EQ(q.shear8_pw, 2.0 * q.shear8_pp);  // a wall of the particles' material would give shear8_pp
}

TEST(RigidWall, RoundTripsAndChangesOnlyItsOwnFingerprint)
{
    Scene plain = drop_scene();
    Scene rigid = plain;
    rigid.wall_material = Material{};
    rigid.wall_material->rigid = true;
    const Scene back = parse_scene(scene_to_toml(rigid), "round trip");
    ASSERT_TRUE(back.wall_material.has_value());
    EXPECT_TRUE(back.wall_material->rigid);
    EXPECT_EQ(back.fingerprint(1), rigid.fingerprint(1));
    EXPECT_NE(rigid.fingerprint(1), plain.fingerprint(1));
    EXPECT_EQ(parse_scene(scene_to_toml(plain), "plain").fingerprint(1), plain.fingerprint(1));
    // A wall of the particles' own material, written out, is not rigid and keeps the plain fingerprint.
    Scene same = plain;
    same.wall_material = plain.material;
    EXPECT_EQ(same.fingerprint(1), plain.fingerprint(1));
    EXPECT_FALSE(parse_scene(scene_to_toml(same), "same").wall_material->rigid);
}

TEST(ChungOoi, ScenesRoundTripThroughTheirFile)
{
    for (const ChungOoiTest& t : chung_ooi_tests())
        for (const std::string& law : t.laws) {
            const ChungOoiCase c{t.number, "", t.values.back(), law, 200.0, {}};
            const Scene s = chung_ooi_scene(c);
            const Scene back = parse_scene(scene_to_toml(s), s.name);
            EXPECT_EQ(back.fingerprint(s.particles.size()), s.fingerprint(s.particles.size())) << s.name;
            EXPECT_EQ(back.walls.empty(), !t.wall()) << s.name;
        }
    EXPECT_THROW(chung_ooi_test(9), Error);
    EXPECT_THROW(chung_ooi_scene({3, "", 1.5, "restitution", 200.0, {}}), Error);
}

// ---- tests 1 and 2: Hertz's closed forms, every variant that runs the paper's law ------------------------
// Δt = t_c/200 (gear5): contact time from the interpolated crossings, peak overlap and force from a parabola
// through the three largest samples, all within 1e-5 of Hertz (measured: about 1e-6).

TEST(ChungOoi, Test1And2MatchHertzInEveryVariant)
{
    for (int k : {1, 2})
        for (const std::string& mat : {chung_ooi_test(k).materials[0].name, chung_ooi_test(k).materials[1].name})
            for (const std::string& name : registry().names()) {
                const ChungOoiCase c{k, mat, 0.0, "paper", 200.0, {}};
                const ChungOoiSetup su = chung_ooi_setup(c);
                const ImpactResult r = run(c, name);
                ASSERT_TRUE(r.separated) << name;
                const double tc = hertz_exact_contact_time(su.mstar, su.rstar, su.estar, su.normal_speed);
                EXPECT_NEAR(r.contact_time / tc, 1.0, 1e-5) << name << " test " << k << " " << mat;
                EXPECT_NEAR(r.peak_overlap / hertz_max_overlap(su.mstar, su.rstar, su.estar, su.normal_speed), 1.0, 1e-5) << name;
                EXPECT_NEAR(r.peak_force / hertz_peak_force(su.mstar, su.rstar, su.estar, su.normal_speed), 1.0, 1e-5) << name;
                EXPECT_NEAR(r.normal_restitution, 1.0, 1e-5) << name;
            }
}

// ---- test 3: the named restitution ------------------------------------------------------------------------
// Δt = t_c/200: the §9 restitution damping within 2e-3 of e (measured ≤ 6e-4), the paper's viscous damping
// solved for e within 5e-3 (measured ≤ 2.5e-3: a stiffer damping term for Gear's predictor).

TEST(ChungOoi, Test3ReboundsAtTheNamedRestitution)
{
    for (double e : {0.3, 0.6, 0.9}) {
        EXPECT_NEAR(run({3, "alumina", e, "restitution", 200.0, {}}).normal_restitution, e, 2e-3) << e;
        EXPECT_NEAR(run({3, "cast_iron", e, "paper", 200.0, {}}).normal_restitution, e, 5e-3) << e;
    }
}

// ---- tests 4, 6, 7: oblique impact theory -----------------------------------------------------------------
// Gross slip (Maw, Barber & Fawcett 1976): J_t = μ·J_n with J_n = m·(1 + e)·v_n, so v_t' = v_t − μ(1 + e)v_n and
// ω' = (5/2)·μ(1 + e)·v_n/R. At 60° on alumina every law is within 1% of it at Δt = t_c/200 (measured ≤ 0.2%:
// the lever arm R − h/2 and the finite contact).

TEST(ChungOoi, Test4GrossSlipMatchesRigidBodyTheory)
{
    const ChungOoiTest& t = chung_ooi_test(4);
    for (const std::string& law : t.laws) {
        const ChungOoiCase c{4, "alumina", 60.0, law, 200.0, {}};
        const ChungOoiSetup su = chung_ooi_setup(c);
        const ImpactResult r = run(c);
        ASSERT_TRUE(r.separated) << law;
        const double jn = (1.0 + t.restitution) * su.normal_speed;  // per unit mass
        EXPECT_NEAR(r.v1.x / (su.tangential_slip - t.mu * jn), 1.0, 1e-2) << law;
        EXPECT_NEAR(r.w1.y / (2.5 * t.mu * jn / t.radius), 1.0, 1e-2) << law;
        EXPECT_NEAR(r.normal_restitution, t.restitution, 2e-3) << law;
    }
}

// At 20° the contact sticks. The history-free law can only stop the slip: the contact point leaves with no
// slip (within 1% of the incident slip). A tangential spring stores the stick and gives it back: the contact
// point leaves slipping backwards (Maw, Barber & Fawcett's reversal), which the paper's law cannot show.
TEST(ChungOoi, Test4StickingReversesTheSlipOnlyWithASpring)
{
    const ChungOoiCase paper{4, "alumina", 20.0, "paper", 200.0, {}};
    const ChungOoiSetup su = chung_ooi_setup(paper);
    const double r = chung_ooi_test(4).radius;
    const ImpactResult p = run(paper);
    EXPECT_NEAR((p.v1.x - r * p.w1.y) / su.tangential_slip, 0.0, 1e-2);
    EXPECT_NEAR(p.v1.x / su.tangential_slip, 5.0 / 7.0, 1e-2);  // the rigid no-slip outcome
    for (const char* law : {"linear_history", "mindlin"}) {
        const ImpactResult h = run({4, "alumina", 20.0, law, 200.0, {}});
        EXPECT_LT((h.v1.x - r * h.w1.y) / su.tangential_slip, -0.2) << law;  // measured: about −0.32
    }
}

// Test 6 at the largest spin slides throughout: v_t' = −μ(1 + e)v_n·sign, ω' = ω − (5/2)μ(1 + e)v_n/R.
TEST(ChungOoi, Test6SpinningSphereSlidesAsTheoryPredicts)
{
    const ChungOoiTest& t = chung_ooi_test(6);
    for (const std::string& law : t.laws) {
        const ChungOoiCase c{6, "al_alloy", t.values.back(), law, 200.0, {}};
        const ChungOoiSetup su = chung_ooi_setup(c);
        const ImpactResult r = run(c);
        const double jt = t.mu * (1.0 + t.restitution) * su.normal_speed;  // per unit mass; the slip −Rω is negative
        ASSERT_LT(jt * slip_compliance_wall(1.0, t.radius), su.tangential_slip);
        EXPECT_NEAR(r.v1.x / jt, 1.0, 1e-2) << law;
        EXPECT_NEAR((t.values.back() - r.w1.y) / (2.5 * jt / t.radius), 1.0, 1e-2) << law;
    }
}

// Test 7 as Kratos sets it (spins equal and opposite about one axis): the contact points move together, so
// no law may produce a tangential force: the spins and the tangential velocities stay as they were.
TEST(ChungOoi, Test7OppositeSpinsMakeNoTangentialForce)
{
    const ChungOoiTest& t = chung_ooi_test(7);
    for (const std::string& law : t.laws) {
        const ImpactResult r = run({7, "copper", t.values[8], law, 200.0, {}});
        EXPECT_NEAR(r.w1.y / t.values[8], 1.0, 1e-9) << law;
        EXPECT_NEAR(r.w2.y / t.values[8], -1.0, 1e-9) << law;
        EXPECT_NEAR(r.v1.z, 0.0, 1e-12) << law;
    }
}

// ---- the integrators on tests 1 and 4 (label long: scripts/run_validation.sh shows the full comparison) ---

TEST(ChungOoiIntegratorsLong, ContactTimeErrorFallsWithTheStep)
{
    for (Integrator scheme : {Integrator::gear5, Integrator::gear3, Integrator::verlet}) {
        double previous = 1.0;
        for (double per_tc : {50.0, 200.0}) {
            ChungOoiCase c{1, "glass", 0.0, "paper", per_tc, {scheme, Precision::float64}};
            const ChungOoiSetup su = chung_ooi_setup(c);
            const double err = std::abs(run(c).contact_time / su.contact_time - 1.0);
            EXPECT_LT(err, 5e-4) << name(scheme) << " t_c/" << per_tc;  // measured: verlet 2e-4 at t_c/50
            EXPECT_LT(err, previous) << name(scheme);
            previous = err;
        }
    }
}
