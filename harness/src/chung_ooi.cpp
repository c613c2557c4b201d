// The Chung & Ooi (2011) tests as scenes, and the measurement of a two-body impact (chung_ooi.hpp). The
// sources of every number below are listed in docs/validation.md; those no port confirms are marked there.
#include "demmat/chung_ooi.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "demmat/contact_memory.hpp"
#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/stability.hpp"

namespace demmat {

namespace {

constexpr double pi = 3.14159265358979323846;

// tan(5°), …, tan(85°) times `scale`: the seventeen points of tests 4–8 in the ports (Kratos: 90°/(17+1)·k).
std::vector<double> seventeen(double scale, bool angle)
{
    std::vector<double> v;
    for (int k = 1; k <= 17; ++k) v.push_back(angle ? 5.0 * k : scale * std::tan(5.0 * k * pi / 180.0));
    return v;
}

std::vector<ChungOoiTest> make_tests()
{
    const ChungOoiMaterial glass{"glass", 4.8e10, 0.20, 2800}, limestone{"limestone", 2.0e10, 0.25, 2500};
    const ChungOoiMaterial al_alloy_t2{"al_alloy", 7.0e10, 0.30, 2699}, mg_alloy{"mg_alloy", 4.0e10, 0.35, 1800};
    const ChungOoiMaterial alumina{"alumina", 3.8e11, 0.23, 4000}, cast_iron{"cast_iron", 1.0e11, 0.25, 7000};
    const ChungOoiMaterial al_alloy{"al_alloy", 7.0e10, 0.33, 2700}, nylon{"nylon", 2.5e9, 0.40, 1000};
    const ChungOoiMaterial steel{"steel", 2.08e11, 0.30, 7850}, polyethylene{"polyethylene", 1.0e9, 0.40, 1400};
    const ChungOoiMaterial copper{"copper", 1.2e11, 0.35, 8900};
    const std::vector<std::string> history{"paper", "linear_history", "mindlin"};
    std::vector<double> es;
    for (int k = 1; k <= 10; ++k) es.push_back(0.1 * k);
    return {
        {1, "elastic normal impact of two identical spheres", ChungOoiSweep::none, {glass, limestone}, 0.010, 0.010, 10.0, 0.0, 1.0, {0.0}, history},
        {2, "elastic normal impact of a sphere on a rigid plane", ChungOoiSweep::none, {al_alloy_t2, mg_alloy}, 0.10, 0.0, 0.2, 0.0, 1.0, {0.0}, history},
        {3, "normal impact on a rigid plane, restitution varied", ChungOoiSweep::restitution, {alumina, cast_iron}, 0.0025, 0.0, 3.9, 0.0, 1.0, es,
         {"paper", "restitution"}},
        {4, "oblique impact on a rigid plane at constant speed, incident angle varied", ChungOoiSweep::angle, {alumina, al_alloy}, 0.0025, 0.0, 3.9,
         0.092, 0.98, seventeen(0.0, true), history},
        {5, "oblique impact on a rigid plane at constant normal speed, tangential speed varied", ChungOoiSweep::tangential_speed,
         {steel, polyethylene}, 1e-5, 0.0, 5.0, 0.3, 1.0, seventeen(5.0, false), history},
        {6, "sphere on a rigid plane at normal speed 0.2 m/s, initial spin varied", ChungOoiSweep::spin, {al_alloy, nylon}, 0.10, 0.0, 0.2, 0.4, 0.5,
         seventeen(0.2 / 0.10, false), history},
        {7, "two identical spheres, spins varied", ChungOoiSweep::spin, {al_alloy, copper}, 0.10, 0.10, 0.2, 0.4, 0.5, seventeen(0.2 / 0.10, false),
         history},
        {8, "two spheres of different size, the small one's spin varied", ChungOoiSweep::spin, {al_alloy, nylon}, 0.10, 0.50, 0.2, 0.4, 0.5,
         seventeen(0.2 / 0.10, false), history},
    };
}

// The paper's viscous damping γ_n (F_nd = γ_n·m*·u_n) that rebounds a head-on impact at v with exactly e.
// In the units h₀ = (m*·v²/K)^(2/5), t₀ = h₀/v the clipped law is h'' = −max(0, h^(3/2) + g·h'), g = γ_n·t₀
// (the derivation of restitution_alpha, with a constant coefficient): g is solved once by bisection on
// the shared RK4 rebound (head_on_rebound), which falls monotonically with g.
double viscous_gamma_for(double e, double mstar, double rstar, double estar, double v)
{
    if (e >= 1.0) return 0.0;
    auto rebound = [](double g) {
        return head_on_rebound(
            [g](double h, double hd) {
                const double hp = std::max(h, 0.0);
                const double f = hp * std::sqrt(hp) + g * hd;
                return f > 0.0 ? -f : 0.0;
            },
            1e-4);
    };
    const double g = damping_for_rebound(rebound, e);
    const double K = 4.0 / 3.0 * estar * std::sqrt(rstar);
    const double h0 = std::pow(mstar * v * v / K, 0.4);
    return g / (h0 / v);
}

double check_value(const ChungOoiTest& t, double value)
{
    if (t.sweep == ChungOoiSweep::none) return 0.0;
    if (!std::isfinite(value)) throw Error(fmt::format("chung-ooi test {}: the value must be finite", t.number));
    if (t.sweep == ChungOoiSweep::restitution && !(value > 0.0 && value <= 1.0))
        throw Error(fmt::format("chung-ooi test 3: the restitution must lie in (0, 1] (got {})", value));
    if (t.sweep == ChungOoiSweep::angle && !(value >= 0.0 && value < 90.0))
        throw Error(fmt::format("chung-ooi test 4: the incident angle must lie in [0, 90) degrees (got {})", value));
    if (t.sweep == ChungOoiSweep::tangential_speed && !(value >= 0.0))
        throw Error(fmt::format("chung-ooi test 5: the tangential speed must be >= 0 m/s (got {})", value));
    return value;
}

} // namespace

const std::vector<ChungOoiTest>& chung_ooi_tests()
{
    static const std::vector<ChungOoiTest> tests = make_tests();
    return tests;
}

const ChungOoiTest& chung_ooi_test(int number)
{
    for (const ChungOoiTest& t : chung_ooi_tests())
        if (t.number == number) return t;
    throw Error(fmt::format("unknown Chung & Ooi test {} (expected 1 to 8)", number));
}

const ChungOoiMaterial& chung_ooi_material(const ChungOoiTest& test, const std::string& name)
{
    if (name.empty()) return test.materials.front();
    std::string known;
    for (const ChungOoiMaterial& m : test.materials) {
        if (m.name == name) return m;
        known += (known.empty() ? "" : " or ") + m.name;
    }
    throw Error(fmt::format("chung-ooi test {} has no material '{}' (expected {})", test.number, name, known));
}

const char* name(ChungOoiSweep s)
{
    switch (s) {
    case ChungOoiSweep::none: return "none";
    case ChungOoiSweep::restitution: return "restitution";
    case ChungOoiSweep::angle: return "incident_angle_deg";
    case ChungOoiSweep::tangential_speed: return "tangential_speed";
    case ChungOoiSweep::spin: return "initial_spin";
    }
    return "?";
}

double hertz_peak_force(double mstar, double rstar, double estar, double v)
{
    const double h = hertz_max_overlap(mstar, rstar, estar, v);
    return 4.0 / 3.0 * estar * std::sqrt(rstar) * h * std::sqrt(h);
}

double hertz_exact_contact_time(double mstar, double rstar, double estar, double v)
{
    const double integral = 0.4 * std::tgamma(0.4) * std::tgamma(0.5) / std::tgamma(0.9);  // (2/5)·B(2/5, 1/2)
    return 2.0 * hertz_max_overlap(mstar, rstar, estar, v) / v * integral;
}

ChungOoiSetup chung_ooi_setup(const ChungOoiCase& c)
{
    const ChungOoiTest& t = chung_ooi_test(c.test);
    const ChungOoiMaterial& mat = chung_ooi_material(t, c.material);
    const double value = check_value(t, c.value);
    const double m1 = sphere_mass(t.radius, mat.density);
    const double one = (1.0 - mat.poisson * mat.poisson) / mat.young;  // a sphere's share of 1/E*
    ChungOoiSetup s{};
    if (t.wall()) {
        s.mstar = m1;
        s.rstar = t.radius;
        s.estar = 1.0 / one;  // the rigid plane adds nothing
    } else {
        const double m2 = sphere_mass(t.radius2, mat.density);
        s.mstar = m1 * m2 / (m1 + m2);
        s.rstar = t.radius * t.radius2 / (t.radius + t.radius2);
        s.estar = 1.0 / (2.0 * one);
    }
    s.normal_speed = t.speed;
    if (t.number == 1 || t.number == 7) s.normal_speed = 2.0 * t.speed;
    if (t.number == 4) s.normal_speed = t.speed * std::cos(value * pi / 180.0);
    if (t.number == 4) s.tangential_slip = t.speed * std::sin(value * pi / 180.0);
    if (t.number == 5) s.tangential_slip = value;
    if (t.number == 6 || t.number == 8) s.tangential_slip = t.radius * value;
    s.contact_time = hertz_exact_contact_time(s.mstar, s.rstar, s.estar, s.normal_speed);
    s.peak_overlap = hertz_max_overlap(s.mstar, s.rstar, s.estar, s.normal_speed);
    return s;
}

Scene chung_ooi_scene(const ChungOoiCase& c)
{
    const ChungOoiTest& t = chung_ooi_test(c.test);
    const ChungOoiMaterial& mat = chung_ooi_material(t, c.material);
    const ChungOoiSetup su = chung_ooi_setup(c);
    const double value = check_value(t, c.value);
    if (!(c.per_tc >= 1.0 && std::isfinite(c.per_tc))) throw Error(fmt::format("chung-ooi: Δt = t_c/{} needs a finite divisor >= 1", c.per_tc));
    const double e = t.sweep == ChungOoiSweep::restitution ? value : t.restitution;

    Scene s;
    s.name = fmt::format("chung_ooi_{}_{}_{}", t.number, mat.name, c.law);
    if (t.sweep != ChungOoiSweep::none) s.name += fmt::format("_{}", value);
    s.material = Material{mat.density, mat.young, mat.poisson, 0.0, 0.0, 0.0, t.mu};
    s.gravity = {0.0, 0.0, 0.0};
    s.dt = su.contact_time / c.per_tc;
    s.integrator = c.integrator;
    s.search.method = SearchMethod::all_pairs;

    const double r1 = t.radius, gap = su.normal_speed * su.contact_time / 20.0;  // contact begins after t_c/20
    if (t.wall()) {
        s.wall_material = Material{};
        s.wall_material->rigid = true;
        Wall w;
        w.name = "plane";
        w.normal = {0.0, 0.0, 1.0};
        s.walls.push_back(w);
        const double L = 20.0 * r1;
        s.domain = {{-L, -L, -r1}, {L, L, L}};
        Vec3d v{su.tangential_slip, 0.0, -su.normal_speed}, w0{};
        if (t.number == 6) {  // the spin alone slips: contact point velocity v − R·ω_y x̂
            v.x = 0.0;
            w0.y = value;
        }
        s.particles.push_back({r1, {0.0, 0.0, r1 + gap}, v, w0});
    } else {
        const double r2 = t.radius2, L = 4.0 * (r1 + r2);
        s.domain = {{-L, -L, -L}, {L, L, L}};
        const double v2 = t.number == 8 ? 0.0 : -t.speed;  // test 8: the large sphere waits at rest
        Vec3d w1{}, w2{};
        if (t.number == 7) {  // equal and opposite spins about y (Kratos's Benchmark7)
            w1.y = value;
            w2.y = -value;
        }
        if (t.number == 8) w1.y = value;
        s.particles.push_back({r1, {-(r1 + gap / 2.0), 0.0, 0.0}, {t.speed, 0.0, 0.0}, w1});
        s.particles.push_back({r2, {r2 + gap / 2.0, 0.0, 0.0}, {v2, 0.0, 0.0}, w2});
    }

    if (c.law == "paper") {
        s.material.gamma_n = viscous_gamma_for(e, su.mstar, su.rstar, su.estar, su.normal_speed);
        // choice (docs/validation.md): the viscous regularisation relaxes a slip within 2/(7γ_t) ≈ t_c/35,
        // so the history-free law is Coulomb's wherever the slip would not stop within the contact.
        if (t.mu > 0.0) s.material.gamma_t = 10.0 / su.contact_time;
    } else if (c.law == "restitution" || c.law == "linear_history" || c.law == "mindlin") {
        s.contact_model.damping = NormalDamping::restitution;
        s.contact_model.restitution = e;
        if (c.law != "restitution") {
            s.contact_model.tangential = TangentialModel::mindlin;  // x_γt = 0: an undamped spring, as the theory's
            if (c.law == "linear_history") {
                // choice: k_t = Mindlin's 8·G*·a at Hertz's peak overlap, so the two springs differ only in
                // how their stiffness follows the overlap.
                const MemoryParams<double> q = memory_params(s);
                s.contact_model.tangential = TangentialModel::linear_history;
                s.contact_model.kt = (t.wall() ? q.shear8_pw : q.shear8_pp) * std::sqrt(su.rstar * su.peak_overlap);
            }
            s.contact_model.stretch_update = c.stretch_update;
        }
    } else {
        throw Error(fmt::format("chung-ooi: unknown law '{}' (expected paper, restitution, linear_history or mindlin)", c.law));
    }
    return s;
}

namespace {
// Overlap, its rate and the normal force on the first body for one sample.
struct Normal {
    double h, hd, fn;
};
Normal normal_of(const std::vector<Vec3d>& x, const std::vector<Vec3d>& v, const std::vector<Vec3d>* f, const State& st)
{
    if (!st.walls.empty()) {
        const Wall& w = st.walls[0];
        return {st.radius[0] - dot(x[0] - w.point, w.normal), -dot(v[0], w.normal), f ? dot((*f)[0], w.normal) : 0.0};
    }
    const Vec3d d = x[1] - x[0];
    const double dist = std::sqrt(dot(d, d));
    const Vec3d n = d / dist;
    return {st.radius[0] + st.radius[1] - dist, -dot(v[1] - v[0], n), f ? -dot((*f)[0], n) : 0.0};
}
// The vertex of the parabola through three equally spaced samples (the middle one the largest).
double vertex(double y0, double y1, double y2)
{
    const double c = y2 - 2.0 * y1 + y0;
    return c < 0.0 ? y1 - (y2 - y0) * (y2 - y0) / (8.0 * c) : y1;
}
} // namespace

ImpactResult run_impact(Variant& variant, const Problem& problem, bool keep_curve, double max_contact_times)
{
    const State& st = problem.state();
    const Scene& sc = problem.scene();
    const Normal n0 = normal_of(st.trans.x, st.trans.v, nullptr, st);
    if (!(n0.h < 0.0 && n0.hd > 0.0)) throw Error("run_impact: the bodies must start apart and approaching");
    const double mstar = st.walls.empty() ? problem.setup().mass[0] * problem.setup().mass[1] / (problem.setup().mass[0] + problem.setup().mass[1])
                                          : problem.setup().mass[0];
    const double rstar = st.walls.empty() ? st.radius[0] * st.radius[1] / (st.radius[0] + st.radius[1]) : st.radius[0];
    const double estar = st.walls.empty() ? problem.setup().contact.estar_pp() : problem.setup().contact.estar_pw();
    const double tc = hertz_exact_contact_time(mstar, rstar, estar, n0.hd);
    const auto max_steps = std::int64_t(std::ceil((-n0.h / n0.hd + max_contact_times * tc) / sc.dt));

    Driver driver(variant, problem.setup());
    Snapshot snap;
    std::vector<ImpactSample> all{{0.0, n0.h, 0.0}};
    ImpactResult r;
    bool touched = false;
    int apart = 0;
    Normal last = n0;
    const int interval = sc.checks.interval;
    for (std::int64_t k = 1; k <= max_steps && apart < 3; ++k) {
        driver.step();
        if (interval > 0 && driver.steps_taken() % interval == 0) driver.check_health();
        variant.snapshot(snap);
        last = normal_of(snap.position, snap.velocity, &snap.force, st);
        all.push_back({driver.time(), last.h, last.fn});
        if (last.h > 0.0) {
            touched = true;
            apart = 0;
        } else if (touched) {
            ++apart;
        }
        r.steps = k;
    }
    r.separated = touched && apart >= 3 && last.hd < 0.0;
    r.v1 = snap.velocity[0];
    r.w1 = snap.angular_velocity[0];
    if (snap.velocity.size() > 1) {
        r.v2 = snap.velocity[1];
        r.w2 = snap.angular_velocity[1];
    }
    if (r.separated) {
        const double t_start = -n0.h / n0.hd;                // the straight approach from t = 0
        const double t_end = all.back().t - last.h / last.hd;  // the straight flight back to the last sample
        r.contact_time = t_end - t_start;
        r.normal_restitution = -last.hd / n0.hd;
    }
    std::size_t ih = 0, ifn = 0;
    for (std::size_t k = 0; k < all.size(); ++k) {
        if (all[k].overlap > all[ih].overlap) ih = k;
        if (all[k].normal_force > all[ifn].normal_force) ifn = k;
    }
    auto peak = [&](std::size_t k, double ImpactSample::*field) {
        if (k == 0 || k + 1 >= all.size()) return all[k].*field;
        return vertex(all[k - 1].*field, all[k].*field, all[k + 1].*field);
    };
    r.peak_overlap = peak(ih, &ImpactSample::overlap);
    r.peak_force = peak(ifn, &ImpactSample::normal_force);
    if (keep_curve) r.curve = std::move(all);
    return r;
}

} // namespace demmat
