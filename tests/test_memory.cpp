// The contact laws of physics.md §9 (contact_memory.hpp) in the arrays variant: restitution and Tsuji
// damping against an independent integration of the same head-on law, the tangential spring against
// the analytic limits of an oblique impact, a sphere on a slope against (5/7)·g·sinθ and the rolling
// resistance's holding condition, and the bookkeeping: stretches keyed by ids (any search gives the
// same bits), carried through a saved state, refused by the variants that do not implement them.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "demmat/contact_memory.hpp"
#include "demmat/features.hpp"
#include "demmat/scene_toml.hpp"
#include "demmat/state_file.hpp"

#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

// ---- an independent reference: the head-on law in SI units, integrated with RK4 --------------------
// m*·ḧ = −max(0, K·h^(3/2) + η_n(h)·ḣ), K = (4/3)·E*·sqrt(R*), η_n = α·sqrt(m*·(4/3)·E*·sqrt(R*·h))
// (physics.md §9), from h = 0 at ḣ = v until h < 0 again. Written here from the formulas, in SI units
// and with pow, not through the suite's code; the step is 1/20000 of the Hertz contact time (§8).
double reference_rebound(double alpha, double estar, double rstar, double mstar, double v)
{
    const double K = 4.0 / 3.0 * estar * std::sqrt(rstar);
    const double tc = 2.87 * std::pow(mstar * mstar / (rstar * estar * estar * v), 0.2);
    const double dt = tc / 20000.0;
    auto acc = [&](double h, double hd) {
        const double hp = std::max(h, 0.0);
        const double eta = alpha * std::sqrt(mstar * 4.0 / 3.0 * estar * std::sqrt(rstar * hp));
        const double f = K * std::pow(hp, 1.5) + eta * hd;
        return f > 0.0 ? -f / mstar : 0.0;
    };
    double h = 0.0, hd = v;
    for (int k = 0; k < 10000000; ++k) {
        const double a1 = acc(h, hd);
        const double a2 = acc(h + 0.5 * dt * hd, hd + 0.5 * dt * a1);
        const double a3 = acc(h + 0.5 * dt * (hd + 0.5 * dt * a1), hd + 0.5 * dt * a2);
        const double a4 = acc(h + dt * (hd + 0.5 * dt * a2), hd + dt * a3);
        h += dt * (hd + dt / 6.0 * (a1 + a2 + a3));
        hd += dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
        if (h < 0.0 && hd < 0.0) return -hd / v;
    }
    return 0.0;
}

ContactModel damping_law(NormalDamping d, double e)
{
    ContactModel m;
    m.damping = d;
    m.restitution = e;
    return m;
}

// Runs a two-particle head-on scene (no gravity) with the arrays variant until the pair has separated
// and returns the ratio of relative speeds after and before.
double measured_rebound(const ContactModel& law, double speed)
{
    Scene s = head_on_scene(speed);
    s.contact_model = law;
    s.particles[0].position.x = -(0.004 + 1e-6);  // start just apart: the contact begins within a step or two
    s.particles[1].position.x = 0.004 + 1e-6;
    Problem c(s);
    VariantRun run("arrays", c.setup());
    bool touched = false;
    for (int k = 0; k < 2000000; ++k) {
        run.driver->step();
        const Snapshot snap = run.snapshot();
        const double gap = snap.position[1].x - snap.position[0].x - 0.008;
        if (gap < 0.0) touched = true;
        if (touched && gap > 0.0) return (snap.velocity[1].x - snap.velocity[0].x) / speed;
    }
    ADD_FAILURE() << "the pair never separated";
    return 0.0;
}

TEST(Memory, RestitutionSolveMatchesAnIndependentIntegration)
{
    // α from contact_memory.cpp's dimensionless bisection, checked in SI units on another particle pair.
    for (double e : {0.1, 0.3, 0.5, 0.7, 0.9, 0.95}) {
        const double alpha = restitution_alpha(e);
        EXPECT_NEAR(reference_rebound(alpha, 1e7, 0.003, 2e-4, 0.7), e, 2e-6 * 1.0) << "e = " << e << ", α = " << alpha;
        EXPECT_NEAR(dimensionless_rebound(alpha), e, 1e-9);
    }
    EXPECT_EQ(restitution_alpha(1.0), 0.0);
}

TEST(Memory, RestitutionHeadOnReboundsAtTheNamedCoefficient)
{
    // physics.md §9: the rebound of the restitution law is the named e at any speed, within 0.5 % (the
    // time integration's error; Δt = 10⁻⁵ s is ≥ 1/300 of the contact time up to 2 m/s).
    for (double e : {0.1, 0.3, 0.6, 0.9, 0.95})
        for (double v : {0.01, 0.1, 1.0, 2.0}) {
            const double got = measured_rebound(damping_law(NormalDamping::restitution, e), v);
            if (std::getenv("DEMMAT_MEMORY_VERBOSE")) std::printf("restitution e=%g v=%g got %.6f\n", e, v, got);
            EXPECT_NEAR(got, e, 0.005 * e) << "e = " << e << " at " << v << " m/s";
        }
}

TEST(Memory, TsujiReboundIsSpeedIndependentAndNearTheFit)
{
    // The same head-on pair under Tsuji's α(e): the rebound of the independent RK4 (paper material,
    // m* and R* of two 4 mm grains) at each speed, and the spec's approximate values 0.50 / 0.72 / 0.93.
    const Material mat = head_on_scene().material;
    const double estar = mat.young / (2.0 * (1.0 - mat.poisson * mat.poisson));
    const double m = sphere_mass(0.004, mat.density);
    const double spec[3] = {0.50, 0.72, 0.93};
    int k = 0;
    for (double e : {0.3, 0.6, 0.9}) {
        const double expect = reference_rebound(tsuji_alpha(e), estar, 0.002, m / 2.0, 1.0);
        if (std::getenv("DEMMAT_MEMORY_VERBOSE")) std::printf("tsuji e=%g rebound %.6f measured(1 m/s) %.6f\n", e, expect, measured_rebound(damping_law(NormalDamping::tsuji, e), 1.0));
        EXPECT_NEAR(expect, spec[k++], 0.015) << "the fit at e = " << e;
        for (double v : {0.05, 0.5, 2.0}) {
            EXPECT_NEAR(reference_rebound(tsuji_alpha(e), estar, 0.002, m / 2.0, v), expect, 1e-5) << "speed-independent, e = " << e;
            EXPECT_NEAR(measured_rebound(damping_law(NormalDamping::tsuji, e), v), expect, 0.005 * expect) << "e = " << e << " at " << v;
        }
    }
}

// ---- oblique impact of a sphere on a wall ---------------------------------------------------------

struct Impact {
    Vec3d v_before, v_after, w_after;
    double mass = 0.0, radius = 0.0, contact_time = 0.0;
};

// A sphere (R = 4 mm, stiff: E = 10⁸ Pa, so h/R stays below 2 %) hits the floor z = 0 at (vt, 0, −vn),
// no gravity, no spin, under linear_history with the given k_t and μ and no damping at all.
Impact oblique_impact(double vt, double vn, double kt, double mu)
{
    Scene s = drop_scene(1e-6);
    s.gravity = {};
    s.dt = 1e-6;
    s.material.young = 1e8;
    s.material.gamma_n = 0.0;
    s.material.gamma_t = 0.0;
    s.material.mu = mu;
    s.particles[0].velocity = {vt, 0.0, -vn};
    s.contact_model.tangential = TangentialModel::linear_history;
    s.contact_model.kt = kt;
    s.contact_model.tangential_damping_ratio = 0.0;
    Problem c(s);
    VariantRun run("arrays", c.setup());
    Impact out;
    out.v_before = s.particles[0].velocity;
    out.mass = c.setup().mass[0];
    out.radius = 0.004;
    std::int64_t first = -1;
    for (int k = 0; k < 100000; ++k) {
        run.driver->step();
        const Snapshot snap = run.snapshot();
        const bool touching = snap.position[0].z < 0.004;
        if (touching && first < 0) first = run.driver->current_step();
        if (first >= 0 && !touching) {
            out.v_after = snap.velocity[0];
            out.w_after = snap.angular_velocity[0];
            out.contact_time = double(run.driver->current_step() - first) * s.dt;
            return out;
        }
    }
    ADD_FAILURE() << "the sphere never left the wall";
    return out;
}

TEST(Memory, ObliqueImpactSlidesWithImpulseRatioMu)
{
    // Tangential speed 6× the normal one and μ = 0.2: the contact slides throughout (Maw, Barber and
    // Fawcett's gross-sliding regime), F_t = μ·F_n at every step, so the tangential impulse m·Δv_x is
    // μ times the normal impulse m·Δv_z, and the spin gained is 5/2 of Δv_x/R (torque R·F_t, I = 2/5 m R²).
    const Impact i = oblique_impact(3.0, 0.5, 2e4, 0.2);
    const double jn = i.v_after.z - i.v_before.z, jt = i.v_before.x - i.v_after.x;
    if (std::getenv("DEMMAT_MEMORY_VERBOSE")) std::printf("sliding jt/jn %.6f w*R %.6f 2.5jt %.6f\n", jt / jn, i.w_after.y * i.radius, 2.5 * jt);
    EXPECT_GT(jn, 0.9);  // about 2·v_n (no damping)
    EXPECT_NEAR(jt / jn, 0.2, 0.2 * 0.01);
    EXPECT_NEAR(i.w_after.y * i.radius, 2.5 * jt, 0.03 * 2.5 * jt);
}

TEST(Memory, ObliqueImpactSticksAndReversesTheTangentialContactVelocity)
{
    // Small tangential speed and μ = 5: the contact sticks, and its tangential point velocity u_t = v_x − ω_y·R
    // swings as an oscillator of stiffness k_t and mass m_t = m/(1 + m·R²/I) = (2/7)·m, starting at ξ = 0:
    // u_t(t) = u_0·cos(ω_t·t), ω_t = sqrt(k_t/m_t). Over the Hertz contact time t_c (measured) the rebound is
    // u_0·cos(ω_t·t_c); k_t is chosen so that ω_t·t_c ≈ 0.8π: the tangential contact velocity reverses.
    const double m = sphere_mass(0.004, 1000.0);
    const Impact probe = oblique_impact(0.05, 0.5, 1.0, 5.0);  // t_c of the normal impact (the tangential part hardly changes it)
    const double w_target = 0.8 * 3.14159265358979 / probe.contact_time;
    const double kt = w_target * w_target * (2.0 / 7.0) * m;
    const Impact i = oblique_impact(0.05, 0.5, kt, 5.0);
    const double u0 = 0.05, u1 = i.v_after.x - i.w_after.y * i.radius;
    const double expect = u0 * std::cos(std::sqrt(kt / ((2.0 / 7.0) * m)) * i.contact_time);
    if (std::getenv("DEMMAT_MEMORY_VERBOSE")) std::printf("stick u1 %.6f expect %.6f tc %g\n", u1, expect, i.contact_time);
    EXPECT_LT(u1, 0.0) << "the tangential contact velocity reverses";
    EXPECT_NEAR(u1, expect, 0.05 * std::abs(expect)) << "u_t after / before " << u1 / u0;
}

// ---- a sphere on a slope ------------------------------------------------------------------------

// A sphere resting (just above) the floor under gravity tilted by θ about y; returns the velocity along
// the slope at t1 and t2.
std::pair<double, double> slope_run(double theta, const ContactModel& law, double t1, double t2, double* displacement = nullptr)
{
    Scene s = drop_scene(1e-7);
    s.gravity = {10.0 * std::sin(theta), 0.0, -10.0 * std::cos(theta)};
    s.material.mu = 0.6;
    s.contact_model = law;
    Problem c(s);
    VariantRun run("arrays", c.setup());
    run.driver->run(std::int64_t(std::llround(t1 / s.dt)));
    const Snapshot a = run.snapshot();
    run.driver->run(std::int64_t(std::llround((t2 - t1) / s.dt)));
    const Snapshot b = run.snapshot();
    if (displacement) *displacement = b.position[0].x - a.position[0].x;
    return {a.velocity[0].x, b.velocity[0].x};
}

ContactModel slope_law(double mu_r)
{
    ContactModel m;
    m.damping = NormalDamping::restitution;
    m.restitution = 0.3;
    m.tangential = TangentialModel::linear_history;
    m.kt = 50.0;
    m.tangential_damping_ratio = 0.5;
    if (mu_r > 0.0) {
        m.rolling = RollingModel::sds;
        m.kr = 50.0;
        m.rolling_damping = 0.05;
        m.rolling_friction = mu_r;
    }
    return m;
}

TEST(Memory, SphereRollsDownASlopeAtFiveSevenths)
{
    // Rolling without slipping (μ = 0.6 > (2/7)·tanθ): a = (5/7)·g·sinθ, measured as Δv/Δt over 0.1 s
    // after the landing has settled.
    const double theta = 20.0 * 3.14159265358979 / 180.0;
    const auto [v1, v2] = slope_run(theta, slope_law(0.0), 0.05, 0.15);
    const double expect = 5.0 / 7.0 * 10.0 * std::sin(theta);
    if (std::getenv("DEMMAT_MEMORY_VERBOSE")) std::printf("slope a %.6f expect %.6f\n", (v2 - v1) / 0.1, expect);
    EXPECT_NEAR((v2 - v1) / 0.1, expect, 0.01 * expect);
}

TEST(Memory, RollingResistanceHoldsTheSphereOnceMuRExceedsTanTheta)
{
    // With sds the rolling torque is capped at R·μ_r·F_n, and holding the sphere needs R·m·g·sinθ of it:
    // μ_r > tanθ = 0.176 holds it (μ_r = 0.3), μ_r below does not (μ_r = 0.1 rolls on, slower than 5/7).
    const double theta = 10.0 * 3.14159265358979 / 180.0;
    double moved = 0.0;
    const auto [h1, h2] = slope_run(theta, slope_law(0.3), 0.1, 0.2, &moved);
    if (std::getenv("DEMMAT_MEMORY_VERBOSE")) std::printf("held v %.3g moved %.3g\n", h2, moved);
    EXPECT_LT(std::abs(h2), 1e-4);
    EXPECT_LT(std::abs(moved), 1e-6);
    // Below it the capped torque R·μ_r·m·g·cosθ acts throughout: m·a = m·g·sinθ − F_t and (I/R²)·a = F_t − μ_r·m·g·cosθ
    // give a = (5/7)·g·(sinθ − μ_r·cosθ).
    const auto [r1, r2] = slope_run(theta, slope_law(0.1), 0.1, 0.2, &moved);
    const double expect = 5.0 / 7.0 * 10.0 * (std::sin(theta) - 0.1 * std::cos(theta));
    if (std::getenv("DEMMAT_MEMORY_VERBOSE")) std::printf("capped roll a %.6f expect %.6f\n", (r2 - r1) / 0.1, expect);
    EXPECT_NEAR((r2 - r1) / 0.1, expect, 0.02 * expect);
}

// ---- bookkeeping ------------------------------------------------------------------------------------

// A small polydisperse bed under a law with every memory: contacts made, kept and broken.
Scene memory_bed(const std::string& integrator = "gear5", const std::string& precision = "double")
{
    Scene s = dense_bed_scene(120, 3);
    s.contact_model = slope_law(0.2);
    s.contact_model.tangential = TangentialModel::mindlin;
    s.contact_model.kt = 0.0;
    s.integrator = {*parse_integrator(integrator), *parse_precision(precision)};
    return s;
}

TEST(Memory, StretchesSurviveAnySearch)
{
    // Keyed by partner id, the stretches do not depend on how the candidates were found: cells of 2 and
    // 4·R_max and every pair give the same bits, step after step.
    Scene base = memory_bed();
    std::vector<Snapshot> runs;
    for (auto [method, size] : {std::pair{SearchMethod::cells, 2.0}, {SearchMethod::cells, 4.0}, {SearchMethod::all_pairs, 2.0}}) {
        Scene s = base;
        s.search.method = method;
        s.search.cell_size = size;
        Problem c(s);
        VariantRun run("arrays", c.setup());
        run.driver->run(3000);
        runs.push_back(run.snapshot());
        EXPECT_GT(run.variant->counts().particle_particle, 20);
    }
    for (std::size_t k = 1; k < runs.size(); ++k) EXPECT_FALSE(first_difference(runs[0], runs[k])) << k;
}

TEST(Memory, SaveAndContinueIsBitIdenticalForEveryIntegrator)
{
    // In float too: a float run saves the radii it was given, not their float roundings, so a continued run
    // derives the same masses (before that fix, float save-and-continue differed for every law).
    for (const char* integrator : {"gear5", "gear3", "verlet", "symplectic_euler"})
        for (const char* precision : {"double", "float"}) {
            const Scene s = memory_bed(integrator, precision);
            Problem c(s);
            VariantRun straight("arrays", c.setup());
            straight.driver->run(2000);
            VariantRun first("arrays", c.setup());
            first.driver->run(1000);
            const State saved = saved_state(first, c);
            EXPECT_GT(saved.stretches.size(), 50u) << integrator;
            const std::filesystem::path file = fmt::format("memory_{}_{}.state", integrator, precision);
            save_state(saved, file);
            Scene cont = s;
            cont.grid.reset();
            cont.state_file = file;
            Problem c2(cont);
            EXPECT_EQ(c2.state().stretches.size(), saved.stretches.size());
            VariantRun second("arrays", c2.setup());
            second.driver->run(1000);
            EXPECT_FALSE(first_difference(straight.snapshot(), second.snapshot())) << integrator << " in " << precision;
            std::filesystem::remove(file);
        }
}

TEST(Memory, StateFileVersions)
{
    // A state without stretches is written as version 1, as before §9 existed (the paper's law, or a law
    // with no live contact), and a version-2 file round-trips every stretch.
    auto version = [](const std::filesystem::path& f) {
        std::ifstream in(f, std::ios::binary);
        char b[12];
        in.read(b, 12);
        std::uint32_t v;
        std::memcpy(&v, b + 8, 4);
        return v;
    };
    Problem paper(head_on_scene());
    save_state(paper.state(), "memory_v1.state");
    EXPECT_EQ(version("memory_v1.state"), 1u);
    EXPECT_TRUE(load_state("memory_v1.state").stretches.empty());
    Problem c(memory_bed());
    VariantRun run("arrays", c.setup());
    run.driver->run(500);
    State st;
    run.variant->save(st);
    st.dt = c.scene().dt;
    save_state(st, "memory_v2.state");
    EXPECT_EQ(version("memory_v2.state"), 2u);
    const State back = load_state("memory_v2.state");
    ASSERT_EQ(back.stretches.size(), st.stretches.size());
    ASSERT_FALSE(st.stretches.empty());
    for (std::size_t k = 0; k < st.stretches.size(); ++k) {
        EXPECT_EQ(back.stretches[k].i, st.stretches[k].i);
        EXPECT_EQ(back.stretches[k].partner, st.stretches[k].partner);
        EXPECT_EQ(back.stretches[k].wall, st.stretches[k].wall);
        EXPECT_TRUE(back.stretches[k].tangential == st.stretches[k].tangential);
        EXPECT_TRUE(back.stretches[k].rolling == st.stretches[k].rolling);
    }
    // Damage to a contact's key is named, not read as a stretch of another contact: the first contact's
    // partner (after the Gear values, at the end of the file less the checksum and C·72 bytes) set past N.
    std::ifstream in("memory_v2.state", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t first = bytes.size() - 8 - 72 * st.stretches.size();
    const std::int64_t bad = 1000000;
    std::memcpy(bytes.data() + first + 8, &bad, 8);
    try {
        parse_state(bytes, "damaged");
        ADD_FAILURE() << "a contact naming particle 1000000 was read";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("corrupt (contact 0 names particle"), std::string::npos) << e.what();
    }
    std::filesystem::remove("memory_v1.state");
    std::filesystem::remove("memory_v2.state");
}

TEST(Memory, OtherVariantsRefuseALawTheyDoNotImplement)
{
    // A variant that says it implements a law runs it (and is compared with arrays step by step in
    // test_memory_equivalence.cpp); one that does not refuses it with a one-line error naming itself and
    // the law. The ports keep the paper's law.
    const Scene s = memory_bed();
    Problem c(s);
    for (const std::string& name : variant_names()) {
        auto v = registry().find(name).create();
        if (name == "arrays" || name == "fast" || name == "cuda_host" || name == "cuda") {  // fast's own tests: test_fast_memory.cpp
            EXPECT_TRUE(v->supports(s.contact_model)) << name;
        }
        if (name == "f90" || name == "pascal") {
            EXPECT_FALSE(v->supports(s.contact_model)) << name;
        }
        if (v->supports(s.contact_model)) {
            Driver d(*v, c.setup());
            EXPECT_TRUE(v->model().history && v->model().rolling) << name << " runs " << v->model().name();
            continue;
        }
        try {
            Driver d(*v, c.setup());
            ADD_FAILURE() << name << " ran a §9 law";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("variant '" + name + "'"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("tangential mindlin"), std::string::npos) << e.what();
        }
    }
}

TEST(Memory, ThePickedModelHasTheLawsFlags)
{
    Problem c(memory_bed());
    VariantRun run("arrays", c.setup());
    const ModelFeatures m = run.variant->model();
    EXPECT_TRUE(m.restitution_damping && m.history && m.rolling) << m.name();
    EXPECT_TRUE(m.covers(features_of(c.scene(), c.state())));
    // The paper's law picks the instantiation it always did (no law flags).
    Problem p(dense_bed_scene(120, 3));
    VariantRun paper("arrays", p.setup());
    EXPECT_FALSE(paper.variant->model().beyond_paper());
}

TEST(Memory, SceneTableRoundTrips)
{
    Scene s = memory_bed();
    const Scene back = parse_scene(scene_to_toml(s), "round trip");
    EXPECT_EQ(back.contact_model.describe(), s.contact_model.describe());
    EXPECT_EQ(back.fingerprint(10), s.fingerprint(10));
    // The paper's law writes no table, and its fingerprint is the one it always had.
    Scene p = dense_bed_scene(120, 3);
    EXPECT_EQ(scene_to_toml(p).find("[contact]"), std::string::npos);
    EXPECT_NE(p.fingerprint(10), s.fingerprint(10));
    EXPECT_EQ(contact_model_from_options({"tangential=linear_history", "kt=100", "tangential_damping_ratio=0.5"}).describe(),
              "damping viscous, tangential linear_history (kt = 100 N/m, tangential_damping_ratio = 0.5), rolling none");
}

// ---- lanes -----------------------------------------------------------------------------------------

template <class T>
bool same_bits(T a, T b) { return std::memcmp(&a, &b, sizeof(T)) == 0; }

// Packs of W pairs and wall contacts against the scalar §9 law, bit for bit, stretches included: random
// geometry near contact, random velocities and spins, random stretches (some zero, some with a normal
// part, some long enough to slide). Lanes out of contact keep their stretches and add zeros.
template <class M, class T, int W>
void check_memory_lanes(bool mindlin, bool trapezoidal = false)
{
    using V = Pack<T, W>;
    const ContactParams<T> p{T(4e5), T(6e5), T(60), T(60), T(0.4)};
    MemoryParams<double> qd;
    qd.alpha = 0.4;
    qd.kt = 80.0;
    qd.shear8_pp = 3e5;
    qd.shear8_pw = 5e5;
    qd.ratio_t = 0.5;
    qd.kr = 60.0;
    qd.gamma_r = 0.01;
    qd.mu_r = 0.2;
    qd.dt = 1e-5;
    qd.mindlin = mindlin;
    qd.trapezoidal = trapezoidal;
    const MemoryParams<T> q = qd.as<T>();
    std::uint64_t seed = 12345;
    auto uniform = [&seed](double lo, double hi) {
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        return T(lo + (hi - lo) * double(seed >> 11) * 0x1.0p-53);
    };
    auto vec = [&](double a) { return Vec3<T>{uniform(-a, a), uniform(-a, a), uniform(-a, a)}; };
    int touching = 0, sliding = 0;
    for (int batch = 0; batch < 200; ++batch) {
        Vec3<T> xi[W], xj[W], vi[W], vj[W], wi[W], wj[W];
        T ri[W], rj[W], mi[W], mj[W];
        Stretch<T> st[W];
        for (int l = 0; l < W; ++l) {
            ri[l] = uniform(0.003, 0.005);
            rj[l] = uniform(0.003, 0.005);
            mi[l] = T(1000.0 * 4.18879 * double(ri[l]) * double(ri[l]) * double(ri[l]));
            mj[l] = T(1000.0 * 4.18879 * double(rj[l]) * double(rj[l]) * double(rj[l]));
            const Vec3<T> dir = vec(1.0);
            const T len = lane_sqrt(dot(dir, dir));
            xi[l] = vec(0.01);
            xj[l] = xi[l] + ((ri[l] + rj[l]) * uniform(0.97, 1.01) / len) * dir;
            vi[l] = vec(0.5);
            vj[l] = vec(0.5);
            wi[l] = vec(50.0);
            wj[l] = vec(50.0);
            const double scale = (batch % 4 == 0) ? 0.0 : (batch % 4 == 1 ? 1e-6 : 1e-3);  // none, sticking, sliding
            st[l] = {vec(scale), vec(scale)};
        }
        auto pack = [&](auto get) {
            V v{};
            for (int l = 0; l < W; ++l) v[l] = get(l);
            return v;
        };
        auto pack3 = [&](const Vec3<T>* a) {
            return Vec3<V>{pack([&](int l) { return a[l].x; }), pack([&](int l) { return a[l].y; }), pack([&](int l) { return a[l].z; })};
        };
        auto pack_stretch = [&] {
            Vec3<T> t[W], r[W];
            for (int l = 0; l < W; ++l) {
                t[l] = st[l].t;
                r[l] = st[l].r;
            }
            return Stretch<V>{pack3(t), pack3(r)};
        };
        // pairs
        Stretch<V> sl = pack_stretch();
        ContactForce<V> lanes;
        const auto touch = particle_contact_memory_lanes<M>(pack3(xi), pack3(xj), pack3(vi), pack3(vj), pack3(wi), pack3(wj),
                                                            pack([&](int l) { return ri[l]; }), pack([&](int l) { return rj[l]; }),
                                                            pack([&](int l) { return mi[l]; }), pack([&](int l) { return mj[l]; }), p, q,
                                                            sl, true, lanes);
        // walls: the same particles i against a plane through xj with normal from xj towards xi
        Vec3<T> wp[W], wn[W], wv[W];
        for (int l = 0; l < W; ++l) {
            const Vec3<T> d = xi[l] - xj[l];
            wn[l] = d / lane_sqrt(dot(d, d));
            wp[l] = xi[l] - (ri[l] * uniform(0.97, 1.01)) * wn[l];
            wv[l] = vec(0.2);
        }
        Stretch<V> sw = pack_stretch();
        ContactForce<V> wlanes;
        const auto wtouch = wall_contact_memory_lanes<M>(pack3(xi), pack3(vi), pack3(wi), pack([&](int l) { return ri[l]; }),
                                                         pack([&](int l) { return mi[l]; }), pack3(wp), pack3(wn), pack3(wv), p, q, sw,
                                                         true, wlanes);
        for (int l = 0; l < W; ++l) {
            for (int kind = 0; kind < 2; ++kind) {
                Stretch<T> one = st[l];
                ContactForce<T> f;
                const bool hit = kind == 0 ? particle_contact_memory<M>(xi[l], xj[l], vi[l], vj[l], wi[l], wj[l], ri[l], rj[l], mi[l], mj[l],
                                                                        p, q, one, true, f)
                                           : wall_contact_memory<M>(xi[l], vi[l], wi[l], ri[l], mi[l], wp[l], wn[l], wv[l], p, q, one,
                                                                    true, f);
                ASSERT_EQ(hit, (kind == 0 ? touch[l] : wtouch[l]) != 0);
                if (!hit) f = ContactForce<T>{};
                touching += hit;
                const ContactForce<V>& g = kind == 0 ? lanes : wlanes;
                const Stretch<V>& gs = kind == 0 ? sl : sw;
                const Vec3<T>* want[5] = {&f.f_i, &f.t_i, &f.t_j, &one.t, &one.r};
                const Vec3<V>* got[5] = {&g.f_i, &g.t_i, &g.t_j, &gs.t, &gs.r};
                for (int k = 0; k < 5; ++k) {
                    if (kind == 1 && k == 2) continue;  // a wall contact has no t_j
                    for (int c = 0; c < 3; ++c)
                        ASSERT_TRUE(same_bits(component(*want[k], c), component(*got[k], c)[l]))
                            << (kind == 0 ? "pair" : "wall") << " lane " << l << " batch " << batch << " quantity " << k << " c " << c;
                }
                if (hit && kind == 0) {  // sliding: the tangential part of f_i has the length μ·F_n
                    const Vec3<T> d = xj[l] - xi[l];
                    const Vec3<T> n = d / lane_sqrt(dot(d, d));
                    const T fn = -dot(f.f_i, n);
                    const Vec3<T> ft = f.f_i + fn * n;
                    const T ft_abs = lane_sqrt(dot(ft, ft));
                    sliding += fn > T(0) && std::abs(double(ft_abs) - 0.4 * double(fn)) < 1e-4 * double(fn);
                }
            }
        }
    }
    EXPECT_GT(touching, 200 * W / 2);
    EXPECT_GT(sliding, 0);
}

TEST(Memory, EveryLaneOfAPackHasTheScalarLawsBits)
{
    using Law = Model<true, true, true, true, true, true, true, true, true>;
    check_memory_lanes<Law, double, native_lanes<double>>(false);
    check_memory_lanes<Law, double, native_lanes<double>>(true);
    check_memory_lanes<Law, float, native_lanes<float>>(true);
    check_memory_lanes<Law, double, native_lanes<double>>(true, true);  // the trapezoidal update (fresh stores: batch % 4 == 0)
    check_memory_lanes<Law, float, native_lanes<float>>(false, true);
    check_memory_lanes<Model<true, true, true, true, true, true, false, true, false>, double, native_lanes<double>>(false);
}

} // namespace
