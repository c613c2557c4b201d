// demmat_accuracy: the speed–accuracy study of docs/accuracy.md. Every integrator × precision of the
// arrays variant over a sweep of Δt, on (a) two-body impacts against analytic or converged answers and
// (b) a settling dense bed against a reference run at a much smaller Δt in double. Writes one JSON file
// (provenance, settings, references, every row) and one CSV (one row per run and measure) for
// analysis/plot_accuracy.py. Run through scripts/run_accuracy.sh.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iostream>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/io.hpp"
#include "demmat/output.hpp"
#include "demmat/problem.hpp"
#include "demmat/reference.hpp"
#include "demmat/registry.hpp"
#include "demmat/scenes.hpp"
#include "demmat/stability.hpp"
#include "demmat/state_file.hpp"

using namespace demmat;
using json = nlohmann::json;

namespace {

constexpr double pi = 3.14159265358979323846;

struct Options {
    std::string out_dir = "results/accuracy";
    bool long_run = false;
    std::int64_t bed_n = 216;
    double bed_time = 0.2;
    int bed_ref_factor = 8;  // Δt_ref = smallest swept Δt / this
    int repetitions = 1;     // timed repetitions of each many-body run (median)
};

// One row of results: a run (case, integrator, precision, Δt) and one of its error measures.
struct Row {
    std::string kind, scene, integrator, precision, measure, status = "ok";
    double dt = 0, dt_over_tc = 0, seconds = 0, seconds_per_step = 0, value = 0, reference = 0, error = 0;
    std::int64_t steps = 0;
};

json row_json(const Row& r)
{
    return {{"kind", r.kind}, {"scene", r.scene}, {"integrator", r.integrator}, {"precision", r.precision},
            {"dt", r.dt}, {"dt_over_tc", r.dt_over_tc}, {"steps", r.steps}, {"status", r.status},
            {"cpu_seconds", r.seconds}, {"seconds_per_step", r.seconds_per_step}, {"measure", r.measure},
            {"value", r.value}, {"reference", r.reference}, {"error", r.error}};
}

// ---- observing a two-body impact ----------------------------------------------------------------------

// The state of a small system at one instant, in double.
struct Frame {
    double t = 0;
    std::vector<Vec3d> x, v, w;
};

// What a two-body impact is judged on (docs/accuracy.md): contact time, maximum overlap, normal
// coefficient of restitution, and for the oblique impact the rebound angle and the final spin.
struct ImpactMeasures {
    double contact_time = 0, max_overlap = 0, restitution = 0, rebound_angle = 0, spin = 0;
    bool separated = false;
};

// The overlap h, its rate and its second derivative along the normal for one frame (pair or wall).
struct NormalMotion {
    double h, hd, hdd;
};

class Impact {
public:
    Impact(Scene scene, bool wall) : problem_(std::make_unique<Problem>(std::move(scene))), wall_(wall) {}
    const Scene& scene() const { return problem_->scene(); }
    const State& state() const { return problem_->state(); }
    const Setup& setup() const { return problem_->setup(); }
    // The same impact run with another time step and integrator.
    void retime(double dt, const IntegratorChoice& integrator)
    {
        Scene s = scene();
        s.dt = dt;
        s.integrator = integrator;
        problem_ = std::make_unique<Problem>(std::move(s), state());
    }

    // Normal motion from positions, velocities and the forces of the shared law (reference_forces).
    NormalMotion normal(const Frame& f) const
    {
        std::vector<Vec3d> force, torque;
        reference_forces(f.x, f.v, f.w, state().radius, setup().mass, state().walls, 0, scene().dt, setup().contact, force, torque);
        if (wall_) {  // floor z = 0, normal +z; gravity is off in these scenes
            const double h = state().radius[0] - f.x[0].z;
            return {h, -f.v[0].z, -(force[0].z / setup().mass[0] + scene().gravity.z)};
        }
        const Vec3d d = f.x[1] - f.x[0];
        const double dist = std::sqrt(dot(d, d));
        const Vec3d n = d / dist;
        const Vec3d vr = f.v[1] - f.v[0];
        const Vec3d ar = force[1] / setup().mass[1] - force[0] / setup().mass[0];
        const double vn = dot(vr, n);
        const Vec3d vp = vr - vn * n;
        return {state().radius[0] + state().radius[1] - dist, -vn, -(dot(ar, n) + dot(vp, vp) / dist)};
    }

    // Measures from a sampled trajectory (every step). Contact start and end come from the free flights
    // before and after (exact straight lines), the maximum overlap from the quintic Hermite interpolant
    // of (h, ḣ, ḧ) on the step where ḣ changes sign (interpolation error O(Δt⁶), below every scheme's).
    ImpactMeasures measure(const std::vector<Frame>& frames) const
    {
        ImpactMeasures m;
        const NormalMotion first = normal(frames.front()), last = normal(frames.back());
        if (!(last.h < 0.0 && last.hd < 0.0)) return m;
        m.separated = true;
        const double t_start = frames.front().t + (-first.h) / first.hd;
        const double t_end = frames.back().t - last.h / last.hd;
        m.contact_time = t_end - t_start;
        m.restitution = -last.hd / first.hd;
        double best = -1e300;
        NormalMotion prev = first;
        for (std::size_t k = 1; k < frames.size(); ++k) {
            const NormalMotion cur = normal(frames[k]);
            best = std::max(best, cur.h);
            if (prev.hd > 0.0 && cur.hd <= 0.0 && prev.h > -1e-3) {
                const double dt = frames[k].t - frames[k - 1].t;
                const double c0 = prev.h, c1 = dt * prev.hd, c2 = dt * dt * prev.hdd / 2.0;
                const double A = cur.h - c0 - c1 - c2, B = dt * cur.hd - c1 - 2.0 * c2, C = dt * dt * cur.hdd - 2.0 * c2;
                const double c3 = 10.0 * A - 4.0 * B + C / 2.0, c4 = -15.0 * A + 7.0 * B - C, c5 = 6.0 * A - 3.0 * B + C / 2.0;
                auto p = [&](double s) { return c0 + s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * c5)))); };
                auto dp = [&](double s) { return c1 + s * (2.0 * c2 + s * (3.0 * c3 + s * (4.0 * c4 + s * 5.0 * c5))); };
                double lo = 0.0, hi = 1.0;
                for (int it = 0; it < 80; ++it) {
                    const double mid = 0.5 * (lo + hi);
                    (dp(mid) > 0.0 ? lo : hi) = mid;
                }
                best = std::max(best, p(0.5 * (lo + hi)));
            }
            prev = cur;
        }
        m.max_overlap = best;
        if (wall_) {
            const Frame& f = frames.back();
            m.rebound_angle = std::atan2(f.v[0].x, f.v[0].z);  // from the normal, radians
            m.spin = f.w[0].y;
        }
        return m;
    }

    // The converged answer: classical RK4 on the same forces (reference_forces, the shared law) with
    // `substeps` steps per Δt_obs; a different integrator from every scheme studied.
    std::vector<Frame> rk4(double dt, double t_end) const
    {
        const std::size_t n = state().size();
        Frame f{0.0, state().trans.x, state().trans.v, state().rot.v};
        std::vector<Frame> out{f};
        auto deriv = [&](const Frame& s, std::vector<Vec3d>& a, std::vector<Vec3d>& al) {
            std::vector<Vec3d> force, torque;
            reference_forces(s.x, s.v, s.w, state().radius, setup().mass, state().walls, 0, scene().dt, setup().contact, force, torque);
            a.resize(n);
            al.resize(n);
            for (std::size_t i = 0; i < n; ++i) {
                a[i] = force[i] / setup().mass[i] + scene().gravity;
                al[i] = torque[i] / setup().inertia[i];
            }
        };
        const auto steps = std::int64_t(std::ceil(t_end / dt));
        std::vector<Vec3d> a1, l1, a2, l2, a3, l3, a4, l4;
        for (std::int64_t k = 0; k < steps; ++k) {
            auto shifted = [&](const Frame& s, double h, const std::vector<Vec3d>& a, const std::vector<Vec3d>& al,
                               const std::vector<Vec3d>& vv) {
                Frame r = s;
                for (std::size_t i = 0; i < n; ++i) {
                    r.x[i] = s.x[i] + h * vv[i];
                    r.v[i] = s.v[i] + h * a[i];
                    r.w[i] = s.w[i] + h * al[i];
                }
                return r;
            };
            deriv(f, a1, l1);
            const Frame f2 = shifted(f, dt / 2, a1, l1, f.v);
            deriv(f2, a2, l2);
            const Frame f3 = shifted(f, dt / 2, a2, l2, f2.v);
            deriv(f3, a3, l3);
            const Frame f4 = shifted(f, dt, a3, l3, f3.v);
            deriv(f4, a4, l4);
            for (std::size_t i = 0; i < n; ++i) {
                f.x[i] = f.x[i] + (dt / 6) * (f.v[i] + 2.0 * f2.v[i] + 2.0 * f3.v[i] + f4.v[i]);
                f.v[i] = f.v[i] + (dt / 6) * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
                f.w[i] = f.w[i] + (dt / 6) * (l1[i] + 2.0 * l2[i] + 2.0 * l3[i] + l4[i]);
            }
            f.t = double(k + 1) * dt;
            out.push_back(f);
        }
        return out;
    }

private:
    std::unique_ptr<Problem> problem_;  // replaced whole by retime(): its setup points into it
    bool wall_;
};

// Runs the arrays variant with a choice, every step observed; the phase times of the run (the
// observation is outside them).
struct Observed {
    std::vector<Frame> frames;
    double seconds = 0;
    std::int64_t steps = 0;
    std::string status = "ok";
};

Observed run_observed(const Setup& setup, std::int64_t steps, std::int64_t every)
{
    Observed o;
    auto variant = registry().find("arrays").create();
    Snapshot snap;
    auto grab = [&](double t) {
        variant->snapshot(snap);
        o.frames.push_back({t, snap.position, snap.velocity, snap.angular_velocity});
    };
    try {
        Driver driver(*variant, setup);
        grab(0.0);
        driver.run(steps, [&](std::int64_t k) {
            if (k % every == 0) grab(driver.time());
        });
        o.seconds = driver.times().total();
        o.steps = steps;
    } catch (const InstabilityError& e) {
        o.status = "unstable";
    }
    return o;
}

// ---- two-body cases -------------------------------------------------------------------------------------

struct TwoBodyCase {
    std::string name;
    Impact impact;
    bool oblique = false;
};

double hertz_tc(double mstar, double rstar, double estar, double v)
{
    // Exact Hertz contact time: 2·(h_max/v)·∫₀¹(1 − x^{5/2})^{−1/2} dx, the integral (2/5)·B(2/5, 1/2).
    const double hmax = hertz_max_overlap(mstar, rstar, estar, v);
    const double integral = 0.4 * std::tgamma(0.4) * std::tgamma(0.5) / std::tgamma(0.9);
    return 2.0 * hmax / v * integral;
}

std::vector<TwoBodyCase> two_body_cases()
{
    std::vector<TwoBodyCase> out;
    {
        Scene s = head_on_scene(1.0);  // Hertz without damping or friction: the analytic answers
        s.name = "head_on_elastic";
        out.push_back({s.name, Impact(s, false)});
    }
    {
        Scene s = head_on_scene(1.0);
        s.name = "head_on_damped";
        s.material.gamma_n = 60.0;  // the paper's γ_n
        out.push_back({s.name, Impact(s, false)});
    }
    {
        // A sphere hitting a floor obliquely (v_t/v_n = 3, no gravity), μ = 0.3 and γ_t large, so the
        // regularised Coulomb law slides throughout: the gross-sliding regime.
        Scene s = drop_scene(0.0005);
        s.name = "oblique_sliding";
        s.gravity = {0.0, 0.0, 0.0};
        s.material.gamma_n = 60.0;
        s.material.gamma_t = 1e4;
        s.material.mu = 0.3;
        s.particles[0].velocity = {3.0, 0.0, -1.0};
        out.push_back({s.name, Impact(s, true), true});
    }
    return out;
}

void two_body_study(const Options& opt, std::vector<Row>& rows, json& refs)
{
    std::vector<int> per_tc;  // Δt = t_c / n
    if (opt.long_run)
        for (double n = 6; n <= 8200; n *= std::sqrt(2.0)) per_tc.push_back(int(std::lround(n)));
    else
        for (int n = 8; n <= 2048; n *= 2) per_tc.push_back(n);

    for (TwoBodyCase& c : two_body_cases()) {
        const State& st = c.impact.state();
        const Setup& su = c.impact.setup();
        const double r = st.radius[0];
        const bool wall = c.oblique;
        const double mstar = wall ? su.mass[0] : su.mass[0] * su.mass[1] / (su.mass[0] + su.mass[1]);
        const double rstar = wall ? r : r / 2.0;
        const double estar = wall ? su.contact.estar_pw() : su.contact.estar_pp();
        const double vn = wall ? -st.trans.v[0].z : st.trans.v[0].x - st.trans.v[1].x;
        const double tc = hertz_tc(mstar, rstar, estar, vn);
        const double gap = -c.impact.normal({0.0, st.trans.x, st.trans.v, st.rot.v}).h;
        const double t_end = gap / vn + 2.0 * tc;

        // The converged reference: RK4 at t_c/40000, checked against RK4 at twice that step.
        const auto fine = c.impact.rk4(tc / 40000.0, t_end);
        const auto half = c.impact.rk4(tc / 20000.0, t_end);
        const ImpactMeasures ref = c.impact.measure(fine), ref2 = c.impact.measure(half);
        json jr = {{"tc_hertz_s", tc}, {"rk4_dt_over_tc", 1.0 / 40000.0},
                   {"contact_time", ref.contact_time}, {"max_overlap", ref.max_overlap}, {"restitution", ref.restitution},
                   {"rk4_self_check_max_rel_difference",
                    std::max({std::abs(ref.contact_time / ref2.contact_time - 1), std::abs(ref.max_overlap / ref2.max_overlap - 1),
                              std::abs(ref.restitution / ref2.restitution - 1)})}};
        ImpactMeasures target = ref;
        if (c.name == "head_on_elastic") {
            // Analytic Hertz (physics.md §8): these are the targets; the RK4 values are kept to show it agrees.
            target.max_overlap = hertz_max_overlap(mstar, rstar, estar, vn);
            target.contact_time = tc;
            target.restitution = 1.0;
            jr["analytic"] = {{"contact_time", target.contact_time}, {"max_overlap", target.max_overlap}, {"restitution", 1.0}};
        }
        if (c.oblique) {
            const double mu = c.impact.scene().material.mu, e = ref.restitution, vt = st.trans.v[0].x;
            // Gross sliding throughout (rigid-body impulse): J_t = μ·J_n, J_n = m·(1 + e)·v_n.
            const double vt_out = vt - mu * (1 + e) * vn, spin = 2.5 * mu * (1 + e) * vn / r;
            jr["rebound_angle"] = ref.rebound_angle;
            jr["spin"] = ref.spin;
            jr["gross_sliding"] = {{"rebound_angle", std::atan2(vt_out, e * vn)}, {"spin", spin},
                                   {"note", "rigid-body formula with lever arm R; the law's lever arm R - h/2 and its "
                                            "regularisation make the converged answer differ by about h_max/(2R)"}};
        }
        refs[c.name] = jr;
        std::cerr << fmt::format("two-body {}: t_c = {:.4g} s, reference contact time {:.6g} s, max overlap {:.6g} m, e = {:.6f}\n",
                                 c.name, tc, ref.contact_time, ref.max_overlap, ref.restitution);

        for (Integrator scheme : all_integrators)
            for (Precision prec : all_precisions) {
                for (int n : per_tc) {
                    const double dt = tc / double(n);
                    c.impact.retime(dt, {scheme, prec});
                    const auto steps = std::int64_t(std::ceil(t_end / dt));
                    const Observed o = run_observed(c.impact.setup(), steps, 1);
                    Row base;
                    base.kind = "two_body";
                    base.scene = c.name;
                    base.integrator = name(scheme);
                    base.precision = name(prec);
                    base.dt = dt;
                    base.dt_over_tc = 1.0 / double(n);
                    base.steps = steps;
                    base.seconds = o.seconds;
                    base.seconds_per_step = o.seconds / double(std::max<std::int64_t>(1, steps));
                    ImpactMeasures m;
                    if (o.status == "ok") m = c.impact.measure(o.frames);
                    if (o.status == "ok" && !m.separated) base.status = "no_separation";
                    else base.status = o.status;
                    std::vector<std::tuple<std::string, double, double>> ms = {
                        {"contact_time", m.contact_time, target.contact_time},
                        {"max_overlap", m.max_overlap, target.max_overlap},
                        {"restitution", m.restitution, target.restitution}};
                    if (c.oblique) {
                        ms.emplace_back("rebound_angle", m.rebound_angle, ref.rebound_angle);
                        ms.emplace_back("spin", m.spin, ref.spin);
                    }
                    for (const auto& [key, value, reference] : ms) {
                        Row r = base;
                        r.measure = key;
                        r.value = value;
                        r.reference = reference;
                        r.error = base.status == "ok" ? std::abs(value - reference) / std::abs(reference) : NAN;
                        rows.push_back(r);
                    }
                }
            }
    }
}

// ---- many-body: the settling dense bed -------------------------------------------------------------------

struct BedSamples {
    std::vector<double> t, ke, floor_force, com_height;
    std::vector<std::vector<Vec3d>> x;  // positions at every sample
    double seconds = 0;
    std::int64_t steps = 0;
    std::string status = "ok";
};

BedSamples run_bed(const Scene& scene, const State& state, double sample_dt, int samples, int repetitions)
{
    BedSamples out;
    const Setup setup = Setup::make(scene, state);
    const auto every = std::int64_t(std::llround(sample_dt / scene.dt));
    const std::int64_t steps = every * samples;
    const Wall* floor = nullptr;
    for (const Wall& w : state.walls)
        if (w.name == "z_min") floor = &w;
    std::vector<double> times;
    for (int rep = 0; rep < repetitions; ++rep) {
        BedSamples s;
        auto variant = registry().find("arrays").create();
        Snapshot snap;
        auto grab = [&](double t) {
            variant->snapshot(snap);
            s.t.push_back(t);
            s.ke.push_back(kinetic_energy(snap, setup));
            double fz = 0.0, z = 0.0;
            for (std::size_t i = 0; i < snap.position.size(); ++i) {
                z += snap.position[i].z;
                if (floor && snap.position[i].z < state.radius[i]) {  // the floor's force on grain i alone
                    std::vector<Vec3d> f, tq;
                    reference_forces({snap.position[i]}, {snap.velocity[i]}, {snap.angular_velocity[i]}, {state.radius[i]},
                                     {setup.mass[i]}, {*floor}, 0, scene.dt, setup.contact, f, tq);
                    fz += f[0].z;
                }
            }
            s.floor_force.push_back(fz);
            s.com_height.push_back(z / double(snap.position.size()));
            s.x.push_back(snap.position);
        };
        try {
            Driver driver(*variant, setup);
            grab(0.0);
            driver.run(steps, [&](std::int64_t k) {
                if (k % every == 0) grab(driver.time());
            });
            s.seconds = driver.times().total();
            s.steps = steps;
        } catch (const InstabilityError&) {
            s.status = "unstable";
        }
        times.push_back(s.seconds);
        if (rep == 0) out = std::move(s);
    }
    std::sort(times.begin(), times.end());
    out.seconds = times[times.size() / 2];
    return out;
}

double rel_l2(const std::vector<double>& a, const std::vector<double>& b)
{
    double num = 0, den = 0;
    for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
        num += (a[k] - b[k]) * (a[k] - b[k]);
        den += b[k] * b[k];
    }
    return std::sqrt(num / den);
}

double mean_position_error(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b)
{
    double s = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const Vec3d d = a[i] - b[i];
        s += std::sqrt(dot(d, d));
    }
    return s / double(a.size());
}

// The many-body measures of a run against the reference (docs/accuracy.md).
std::vector<std::pair<std::string, double>> bed_errors(const BedSamples& s, const BedSamples& ref, double r_mean)
{
    const std::size_t q = ref.t.size() - 1;
    return {{"ke_history", rel_l2(s.ke, ref.ke)},
            {"floor_force_history", rel_l2(s.floor_force, ref.floor_force)},
            {"final_height", std::abs(s.com_height.back() - ref.com_height.back()) / ref.com_height.back()},
            {"position_error_quarter", mean_position_error(s.x[q / 4], ref.x[q / 4]) / r_mean},
            {"position_error_half", mean_position_error(s.x[q / 2], ref.x[q / 2]) / r_mean},
            {"position_error_end", mean_position_error(s.x[q], ref.x[q]) / r_mean}};
}

void many_body_study(const Options& opt, std::vector<Row>& rows, json& refs)
{
    Scene scene = dense_bed_scene(opt.bed_n);
    const State state = initial_state(scene);
    const int samples = 50;
    const double sample_dt = opt.bed_time / samples;
    std::vector<double> dts;
    for (double dt = 1.25e-5; dt <= 2.01e-4; dt *= 2) dts.push_back(dt);
    if (opt.long_run) dts.insert(dts.begin(), 6.25e-6);
    const double dt_ref = dts.front() / opt.bed_ref_factor;
    double r_mean = 0;
    for (double r : state.radius) r_mean += r;
    r_mean /= double(state.size());
    const double rmin = *std::min_element(state.radius.begin(), state.radius.end());
    const double t_rayleigh = rayleigh_time(scene.material, rmin);

    std::cerr << fmt::format("many-body: dense bed of {} grains, {} s simulated, reference at Δt = {:g} s\n", opt.bed_n,
                             opt.bed_time, dt_ref);
    scene.dt = dt_ref;
    const BedSamples ref = run_bed(scene, state, sample_dt, samples, 1);
    // The chaos floor: the same reference with one grain moved by 1 nm at t = 0. Differences of this
    // size come from the bed's sensitivity alone; no integrator can be judged below them.
    State nudged = state;
    nudged.trans.x[0].x += 1e-9;
    const BedSamples twin = run_bed(scene, nudged, sample_dt, samples, 1);
    json floor = json::object();
    for (const auto& [key, value] : bed_errors(twin, ref, r_mean)) floor[key] = value;
    refs["dense_bed"] = {{"particles", opt.bed_n}, {"simulated_s", opt.bed_time}, {"dt_ref", dt_ref}, {"samples", samples},
                         {"rayleigh_time_s", t_rayleigh}, {"chaos_floor", floor},
                         {"reference_final_com_height", ref.com_height.back()}, {"reference_seconds", ref.seconds},
                         {"t", ref.t}, {"ke", ref.ke}, {"floor_force", ref.floor_force}, {"com_height", ref.com_height}};

    for (Integrator scheme : all_integrators)
        for (Precision prec : all_precisions)
            for (double dt : dts) {
                scene.dt = dt;
                scene.integrator = {scheme, prec};
                const BedSamples s = run_bed(scene, state, sample_dt, samples, opt.repetitions);
                std::cerr << fmt::format("  {:>16} {:<6} Δt = {:<8g} {} {:.3f} s\n", name(scheme), name(prec), dt, s.status, s.seconds);
                Row base;
                base.kind = "many_body";
                base.scene = scene.name;
                base.integrator = name(scheme);
                base.precision = name(prec);
                base.dt = dt;
                base.dt_over_tc = dt / t_rayleigh;  // for the bed: Δt in units of the Rayleigh time
                base.steps = s.steps;
                base.status = s.status;
                base.seconds = s.seconds;
                base.seconds_per_step = s.seconds / double(std::max<std::int64_t>(1, s.steps));
                if (s.status != "ok") {
                    for (const char* key : {"ke_history", "floor_force_history", "final_height"}) {
                        Row r = base;
                        r.measure = key;
                        r.error = NAN;
                        rows.push_back(r);
                    }
                    continue;
                }
                for (const auto& [key, value] : bed_errors(s, ref, r_mean)) {
                    Row r = base;
                    r.measure = key;
                    r.value = value;
                    r.error = value;
                    r.reference = floor[key].get<double>();  // the chaos floor of this measure
                    rows.push_back(r);
                }
            }
}

std::string csv(const std::vector<Row>& rows)
{
    std::string o = "kind,scene,integrator,precision,dt,dt_over_tc,steps,status,cpu_seconds,seconds_per_step,measure,value,reference,error\n";
    for (const Row& r : rows)
        o += fmt::format("{},{},{},{},{:.17g},{:.17g},{},{},{:.6g},{:.6g},{},{:.17g},{:.17g},{:.6g}\n", r.kind, r.scene, r.integrator,
                         r.precision, r.dt, r.dt_over_tc, r.steps, r.status, r.seconds, r.seconds_per_step, r.measure, r.value,
                         r.reference, r.error);
    return o;
}

int usage()
{
    std::cerr << "usage: demmat_accuracy [--long] [--out DIR] [--n N] [--time T] [--repetitions R]\n"
                 "  default: two-body sweep t_c/8 … t_c/2048 (×2), a bed of 216 grains for 0.2 s\n"
                 "  --long:  two-body sweep t_c/6 … t_c/8192 (×√2), a bed of 1000 grains for 0.4 s, 3 timed repetitions\n";
    return 2;
}

} // namespace

int main(int argc, char** argv)
{
    try {
        Options opt;
        bool n_given = false, t_given = false, r_given = false;
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            auto next = [&]() -> std::string {
                if (i + 1 >= argc) throw Error(fmt::format("option {} needs a value", a));
                return argv[++i];
            };
            if (a == "--long") opt.long_run = true;
            else if (a == "--out") opt.out_dir = next();
            else if (a == "--n") { opt.bed_n = std::stoll(next()); n_given = true; }
            else if (a == "--time") { opt.bed_time = std::stod(next()); t_given = true; }
            else if (a == "--repetitions") { opt.repetitions = std::stoi(next()); r_given = true; }
            else if (a == "--help" || a == "-h") return usage();
            else throw Error(fmt::format("unknown option '{}' (see --help)", a));
        }
        if (opt.long_run) {
            if (!n_given) opt.bed_n = 1000;
            if (!t_given) opt.bed_time = 0.4;
            if (!r_given) opt.repetitions = 3;
            opt.bed_ref_factor = 16;
        }
        if (opt.bed_n < 8 || !(opt.bed_time > 0) || opt.repetitions < 1) throw Error("--n must be >= 8, --time > 0, --repetitions >= 1");

        std::vector<Row> rows;
        json refs = json::object();
        two_body_study(opt, rows, refs);
        many_body_study(opt, rows, refs);

        json jrows = json::array();
        for (const Row& r : rows) jrows.push_back(row_json(r));
        const json out = {{"provenance", provenance_json()},
                          {"settings", {{"long", opt.long_run}, {"bed_particles", opt.bed_n}, {"bed_time_s", opt.bed_time},
                                        {"bed_ref_factor", opt.bed_ref_factor}, {"repetitions", opt.repetitions},
                                        {"variant", "arrays"}, {"time_measure", "sum of the driver's phase times (steady_clock)"}}},
                          {"references", refs},
                          {"rows", jrows}};
        const std::string stem = opt.out_dir + "/accuracy";
        write_atomically(stem + ".json", out.dump(1) + "\n");
        write_atomically(stem + ".csv", csv(rows));
        std::cerr << fmt::format("wrote {}.json and {}.csv ({} rows)\n", stem, stem, rows.size());
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "demmat_accuracy: error: " << e.what() << "\n";
        return 2;
    }
}
