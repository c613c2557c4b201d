// demmat_stability: the stability study of docs/stability.md. For every integrator × precision the
// variant runs (integrators.hpp), the largest stable Δt, found by a ladder and a bisection, in units of
// the Hertz contact time t_c and of the Rayleigh time, for a head-on pair, a sphere hitting a wall under
// gravity and a small dense bed, across restitution (0.2 … 1.0, through γ_n) and stiffness (E from 10⁵
// to 2·10¹¹ Pa). Writes one JSON file with provenance for analysis/plot_stability.py. Run through
// scripts/run_stability.sh.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/io.hpp"
#include "demmat/problem.hpp"
#include "demmat/output.hpp"
#include "demmat/registry.hpp"
#include "demmat/scenes.hpp"
#include "demmat/stability.hpp"
#include "demmat/state_file.hpp"

using namespace demmat;
using json = nlohmann::json;

namespace {

struct Options {
    std::string out_dir = "results/stability";
    std::string variant = "arrays";
    bool long_run = false;
    std::vector<double> young{1e5, 1e8, 2e11};
    std::vector<double> restitution{0.2, 0.4, 0.6, 0.8, 1.0};
};

// ---- restitution → γ_n -----------------------------------------------------------------------------------
// The normal contact of physics.md §2 in units of h_max (undamped maximum overlap) and τ = h_max/v:
// h'' = −max(0, 1.25·h^{3/2} + g·h'), h(0) = 0, h'(0) = 1, with g = γ_n·τ (the clip is the no-attraction
// choice). The restitution −h'(end) depends on g alone, so one g per target serves every E, R and v.
double restitution_of(double g)
{
    // RK4 at the step 2e-4; the contact lasts about 3 time units.
    return head_on_rebound([g](double x, double xd) { return x > 0.0 ? -std::max(0.0, 1.25 * x * std::sqrt(x) + g * xd) : 0.0; },
                           2e-4);
}

// g = γ_n·τ giving restitution e (bisection; e(g) decreases monotonically).
double damping_for(double e)
{
    if (e >= 1.0) return 0.0;
    double lo = 0.0, hi = 1.0;
    while (restitution_of(hi) > e) hi *= 2.0;
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (restitution_of(mid) > e ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// ---- the cases ---------------------------------------------------------------------------------------------
enum class Kind { head_on, wall, bed };
const char* kind_name(Kind k) { return k == Kind::head_on ? "head_on" : k == Kind::wall ? "wall" : "dense_bed"; }

constexpr double kSpeed = 1.0;    // m/s: impact speed of the two-body cases and the unit of t_c
// The bed's grains start at up to 0.5 m/s and gain about 1 m/s falling: at E = 10⁵ Pa a 2 m/s impact
// would overlap more than the driver's 0.5·R bound physically, not numerically.
constexpr double kBedSpeed = 0.5;
constexpr double kRadius = 0.004; // m
constexpr double kDensity = 1000.0;

// The material of a case: E, ν = 0.3, ρ = 1000 kg/m³, G from E and ν (for the Rayleigh time), γ_n from
// the target restitution at the case's reference contact.
Material material(double young)
{
    Material m;
    m.density = kDensity;
    m.young = young;
    m.poisson = 0.3;
    m.shear = 0.0;
    m.gamma_n = m.gamma_t = m.mu = 0.0;
    return m;
}

struct CaseSpec {
    Kind kind;
    double young, target_e;
    Scene scene;      // at Δt = 1 (set per run)
    double tc = 0;    // Hertz contact time at kSpeed of the reference contact (the unit of Δt)
    double tc_check = 0;  // the shortest contact time that `demmat run` checks against (stability.hpp)
    double rayleigh = 0;  // of the smallest grain
    double t_end = 0;     // simulated time of one run
    double e_ref = 0;     // restitution of the converged run (two-body)
};

double estar_of(const Material& m) { return m.young / (2.0 * (1.0 - m.poisson * m.poisson)); }

CaseSpec make_case(Kind kind, double young, double target_e)
{
    CaseSpec c{kind, young, target_e, {}};
    const Material mat = material(young);
    const double g = damping_for(target_e);
    Scene& s = c.scene;
    if (kind == Kind::bed) {
        // 125 grains, radii in [0.95, 1]·R on a lattice 2.02·R_max apart in a closed box, speeds up to
        // kBedSpeed, gravity: they collide within a few contact times and pile up on the floor.
        s = dense_bed_scene(125, 7);
        s.name = "stability_bed";
        s.grid->radius_min = 0.95 * kRadius;
        s.grid->radius_max = kRadius;
        s.grid->spacing = 2.02 * kRadius;
        s.grid->speed_min = 0.0;
        s.grid->speed_max = kBedSpeed;
        s.domain.max = {5 * s.grid->spacing, 5 * s.grid->spacing, 5 * s.grid->spacing};
        s.walls = box_walls(s.domain);
        s.checks.interval = 5;
    } else {
        s = kind == Kind::head_on ? head_on_scene(kSpeed, kRadius) : drop_scene(0.001, kRadius);
        s.name = kind == Kind::head_on ? "stability_head_on" : "stability_wall";
        s.checks.interval = 1;
    }
    s.material = mat;
    const double rmin = kind == Kind::bed ? 0.95 * kRadius : kRadius;
    const double m = sphere_mass(rmin, kDensity);
    const bool wall = kind == Kind::wall;
    const double mstar = wall ? m : m / 2, rstar = wall ? rmin : rmin / 2, es = estar_of(mat);
    c.tc = hertz_contact_time(mstar, rstar, es, kSpeed);
    const double hmax = hertz_max_overlap(mstar, rstar, es, kSpeed);
    s.material.gamma_n = g / (hmax / kSpeed);
    if (kind == Kind::bed) {
        s.material.gamma_t = s.material.gamma_n;  // the paper's γ_t = γ_n, with friction
        s.material.mu = 0.5;
    }
    // Two-body: start h_max apart (the contact begins after 0.35 t_c), run 3 t_c beyond it.
    if (kind == Kind::head_on) {
        s.particles[0].position = {-(kRadius + hmax / 2), 0, 0};
        s.particles[1].position = {kRadius + hmax / 2, 0, 0};
        c.t_end = hmax / kSpeed + 3.0 * c.tc;
    } else if (kind == Kind::wall) {
        s.particles[0].position = {0, 0, kRadius + hmax};
        s.particles[0].velocity = {0, 0, -kSpeed};
        c.t_end = hmax / kSpeed + 3.0 * c.tc;
    } else {
        const double gap = s.grid->spacing - 2.0 * s.grid->radius_min;
        c.t_end = std::max(30.0 * c.tc, 2.0 * gap / kBedSpeed);
    }
    s.dt = c.tc / 100.0;
    const State st = initial_state(s);
    c.tc_check = shortest_contact_time(s, st, impact_speed_bound(s, st)).tc;
    c.rayleigh = rayleigh_time(mat, rmin);
    return c;
}

// ---- one run -------------------------------------------------------------------------------------------------
struct Outcome {
    bool stable = false;  // no detection, contact ended, restitution sane
    bool survived = false;  // no detection and the contact ended (the restitution not judged)
    std::string reason;   // why not, or "ok"
    double restitution = 0;
    std::int64_t steps = 0;
};

Outcome run_case(const CaseSpec& c, IntegratorChoice choice, double dt, const std::string& variant_name)
{
    Outcome o;
    Scene s = c.scene;
    s.dt = dt;
    s.integrator = choice;
    try {
        const State st = initial_state(s);
        const Setup setup = Setup::make(s, st);
        auto variant = registry().find(variant_name).create();
        Driver driver(*variant, setup);
        o.steps = steps_to_reach(c.t_end, dt);
        driver.run(o.steps);
        Snapshot snap;
        variant->snapshot(snap);
        if (c.kind == Kind::bed) {
            o.stable = o.survived = true;
            o.reason = "ok";
            return o;
        }
        double h, vout;
        if (c.kind == Kind::head_on) {
            const Vec3d d = snap.position[1] - snap.position[0];
            h = 2.0 * kRadius - std::sqrt(dot(d, d));
            vout = snap.velocity[1].x - snap.velocity[0].x;
        } else {
            h = kRadius - snap.position[0].z;
            vout = snap.velocity[0].z;
        }
        o.restitution = vout / kSpeed;
        o.survived = h <= 0.0;
        if (h > 0.0) {
            o.reason = "still in contact at the end (stuck)";
        } else if (!(std::abs(o.restitution - c.e_ref) <= 0.1)) {
            o.reason = fmt::format("restitution {:.3f} is more than 0.1 from the converged {:.3f}", o.restitution, c.e_ref);
        } else {
            o.stable = true;
            o.reason = "ok";
        }
    } catch (const InstabilityError& e) {
        const std::string m = e.what();
        o.reason = "detected: " + m.substr(0, m.find(" ("));
    } catch (const Error& e) {
        o.reason = std::string("stopped: ") + e.what();
    }
    return o;
}

// ---- the search -----------------------------------------------------------------------------------------------
// Ladder Δt/t_c = 0.02·1.25^k upward until the first failure (at most 8), then bisection (in log Δt) between
// the last stable rung and the first failure down to 1.5 %. The limit is the largest Δt found stable below
// which every tried Δt was stable.
struct Limit {
    double ratio = 0;          // Δt/t_c, largest stable
    double fail_ratio = 0;     // smallest failing Δt/t_c found (0: none up to the ladder's top)
    std::string fail_reason;
    double restitution_at_limit = 0;
    int runs = 0;
};

// sane: the restitution criterion counts (the headline limit); otherwise only detection and separation.
Limit find_limit(const CaseSpec& c, IntegratorChoice choice, const std::string& variant, bool sane)
{
    Limit L;
    double lo = 0.0, hi = 0.0;
    Outcome at_lo;
    auto ok = [sane](const Outcome& o) { return sane ? o.stable : o.survived; };
    for (double r = 0.02; r <= 8.0; r *= 1.25) {
        const Outcome o = run_case(c, choice, r * c.tc, variant);
        ++L.runs;
        if (!ok(o)) {
            hi = r;
            L.fail_reason = o.reason;
            break;
        }
        lo = r;
        at_lo = o;
    }
    if (hi > 0.0 && lo > 0.0) {
        while (hi / lo > 1.015) {
            const double mid = std::sqrt(lo * hi);
            const Outcome o = run_case(c, choice, mid * c.tc, variant);
            ++L.runs;
            if (ok(o)) {
                lo = mid;
                at_lo = o;
            } else {
                hi = mid;
                L.fail_reason = o.reason;
            }
        }
    }
    L.ratio = lo;
    L.fail_ratio = hi;
    L.restitution_at_limit = at_lo.restitution;
    return L;
}

int run(const Options& opt)
{
    const VariantInfo& info = registry().find(opt.variant);
    json rows = json::array();
    std::vector<IntegratorChoice> choices;
    {
        auto probe = info.create();
        for (Integrator i : all_integrators)
            for (Precision p : all_precisions)
                if (probe->supports({i, p})) choices.push_back({i, p});
    }
    json gammas = json::array();
    for (double e : opt.restitution) gammas.push_back({{"restitution", e}, {"gamma_n_times_tau", damping_for(e)}});
    const auto start = std::chrono::steady_clock::now();
    for (Kind kind : {Kind::head_on, Kind::wall, Kind::bed})
        for (double young : opt.young)
            for (double e : opt.restitution) {
                CaseSpec c = make_case(kind, young, e);
                if (kind != Kind::bed) {  // the converged restitution: gear5 in double at t_c/1000
                    c.e_ref = 1e9;
                    const Outcome ref = run_case(c, {}, c.tc / 1000.0, opt.variant);
                    if (ref.reason.rfind("restitution", 0) != 0 && ref.reason != "ok")
                        throw Error(fmt::format("reference run of {} failed: {}", kind_name(kind), ref.reason));
                    c.e_ref = ref.restitution;
                }
                for (const IntegratorChoice& ch : choices) {
                    const Limit L = find_limit(c, ch, opt.variant, true);
                    const Limit D = kind == Kind::bed ? L : find_limit(c, ch, opt.variant, false);
                    const double dt = L.ratio * c.tc;
                    rows.push_back({{"scene", kind_name(kind)}, {"young", young}, {"target_restitution", e},
                                    {"gamma_n", c.scene.material.gamma_n}, {"converged_restitution", c.e_ref},
                                    {"integrator", name(ch.scheme)}, {"precision", name(ch.precision)},
                                    {"tc", c.tc}, {"tc_check", c.tc_check}, {"rayleigh_time", c.rayleigh},
                                    {"dt_limit", dt}, {"dt_over_tc", L.ratio}, {"dt_over_tc_check", dt / c.tc_check},
                                    {"dt_over_rayleigh", dt / c.rayleigh}, {"first_fail_dt_over_tc", L.fail_ratio},
                                    {"fail_reason", L.fail_reason}, {"restitution_at_limit", L.restitution_at_limit},
                                    {"detected_only_dt_over_tc", D.ratio}, {"detected_only_fail_reason", D.fail_reason},
                                    {"runs", L.runs + (kind == Kind::bed ? 0 : D.runs)}});
                    std::cerr << fmt::format("{:<9} E={:<7.0e} e={:.1f} {:<16} {:<6}: dt/tc = {:.4f}  dt/T_R = {:.4f}  ({})\n",
                                             kind_name(kind), young, e, name(ch.scheme), name(ch.precision), L.ratio,
                                             dt / c.rayleigh, L.fail_reason.empty() ? "no failure up to 8 t_c" : L.fail_reason);
                }
            }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    json j = {{"provenance", provenance_json()},
              {"variant", opt.variant},
              {"mode", opt.long_run ? "long" : "default"},
              {"seconds", secs},
              {"settings",
               {{"impact_speed", kSpeed}, {"radius", kRadius}, {"density", kDensity}, {"poisson", 0.3},
                {"ladder", "dt/tc = 0.02 * 1.25^k up to 8, then bisection to 1.5 %"},
                {"bed_speed", kBedSpeed},
                {"stable_means", "the run completes with the driver's health checks (every step; every 5 in the bed), "
                                 "no capacity overflow, and for two-body cases the contact has ended and the "
                                 "restitution is within 0.1 of the converged run (gear5, double, dt = tc/1000)"},
                {"detected_only_means", "the same without the restitution criterion"},
                {"damping", gammas}}},
              {"rows", rows}};
    const std::string file = fmt::format("{}/stability_{}.json", opt.out_dir, opt.long_run ? "long" : "default");
    std::filesystem::create_directories(opt.out_dir);
    write_atomically(file, j.dump(1) + "\n");
    std::cerr << fmt::format("demmat_stability: {} limits in {:.0f} s, written to {}\n", rows.size(), secs, file);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    Options opt;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--long") {
            opt.long_run = true;
            opt.young = {1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 2e11};
            opt.restitution = {0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0};
        } else if (a == "--out" && i + 1 < argc) {
            opt.out_dir = argv[++i];
        } else if (a == "--variant" && i + 1 < argc) {
            opt.variant = argv[++i];
        } else if (a == "--help" || a == "-h") {
            std::cout << "demmat_stability [--long] [--out DIR] [--variant NAME]\n"
                         "  the largest stable time step per integrator x precision, scene, restitution and stiffness;\n"
                         "  writes DIR/stability_default.json (or stability_long.json); see docs/stability.md\n";
            return 0;
        } else {
            std::cerr << "demmat_stability: error: unknown argument '" << a << "' (see --help)\n";
            return 2;
        }
    }
    try {
        return run(opt);
    } catch (const Error& e) {
        std::cerr << "demmat_stability: error: " << e.what() << "\n";
        return 2;
    }
}
