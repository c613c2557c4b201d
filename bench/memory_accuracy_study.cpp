// demmat_memory_accuracy: work against precision of the contact laws of physics.md §9 (docs/accuracy.md,
// "Laws with memory"). Chung & Ooi test 4 (a sphere onto the rigid plane, 5°–85°) and test 8 (a spinning
// sphere onto a larger one at rest), from chung_ooi_scene, under each law × integrator × stretch update ×
// Δt = t_c/n, on the arrays variant (the only one that runs every integrator). Each run's error is against
// a reference run converged in Δt (gear5, trapezoidal update, t_c/8000; shown converged against t_c/4000),
// each cost the CPU time of the runs. Writes, into --out:
//   memory_accuracy.csv   one row per test × law × integrator × update × Δt: the worst error over the sweep
//                         per quantity, the CPU seconds and steps of the sweep
//   memory_accuracy.json  provenance, settings, the references' own step error
// analysis/plot_memory_accuracy.py draws the figures and the recommendation table. Run by
// scripts/run_accuracy.sh --memory.
#include <algorithm>
#include <cmath>
#include <ctime>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "demmat/chung_ooi.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/error.hpp"
#include "demmat/io.hpp"
#include "demmat/output.hpp"
#include "demmat/problem.hpp"
#include "demmat/registry.hpp"

using namespace demmat;
using json = nlohmann::json;

namespace {

// The laws: the Chung & Ooi scenes' (docs/validation.md) and two more built on mindlin's scene.
const std::vector<std::string> kLaws = {"paper", "linear_history", "mindlin", "mindlin_sds", "mindlin_tsuji"};
const std::vector<Integrator> kSchemes = {Integrator::gear5, Integrator::gear3, Integrator::verlet, Integrator::symplectic_euler};
constexpr double kRefPerTc = 8000.0, kCheckPerTc = 4000.0;

struct Options {
    std::string out_dir = "results/accuracy/memory";
    std::vector<double> per_tc{20, 50, 100, 200, 500, 1000, 2000};
    bool quick = false;  // every fourth point of each sweep, Δt down to t_c/200
};

// The scene of one run: the Chung & Ooi case, and for mindlin_sds / mindlin_tsuji the law changed on it.
// choice: sds's k_r is linear_history's k_t (Mindlin's at Hertz's peak), γ_r = 0, μ_r = μ/10; tsuji's e is
// the test's (its fit rebounds near, not at, e: physics.md §9).
Scene law_scene(int test, double value, const std::string& law, Integrator scheme, StretchUpdate update, double per_tc)
{
    ChungOoiCase c{test, "", value, law == "paper" || law == "linear_history" ? law : "mindlin", per_tc, {scheme, Precision::float64},
                   update};
    Scene s = chung_ooi_scene(c);
    if (law == "mindlin_sds") {
        const ChungOoiSetup su = chung_ooi_setup(c);
        const MemoryParams<double> q = memory_params(s);
        s.contact_model.rolling = RollingModel::sds;
        s.contact_model.kr = (chung_ooi_test(test).wall() ? q.shear8_pw : q.shear8_pp) * std::sqrt(su.rstar * su.peak_overlap);
        s.contact_model.rolling_friction = 0.1 * s.material.mu;
    }
    if (law == "mindlin_tsuji") s.contact_model.damping = NormalDamping::tsuji;
    return s;
}

struct Outcome {
    double vt = 0, spin = 0, restitution = 0, cpu = 0;
    std::int64_t steps = 0;
    bool ok = true;  // separated, and no health check stopped the run
};

Outcome run(const Scene& scene, bool wall)
{
    Problem problem(scene);
    auto variant = registry().find("arrays").create();
    const std::clock_t t0 = std::clock();
    try {
        const ImpactResult r = run_impact(*variant, problem, false);
        const double cpu = double(std::clock() - t0) / CLOCKS_PER_SEC;
        return {wall ? r.v1.x : r.v1.z, r.w1.y, r.normal_restitution, cpu, r.steps, r.separated};
    } catch (const Error&) {  // a step too long for the scheme: the Driver's health check stops it
        return {0, 0, 0, double(std::clock() - t0) / CLOCKS_PER_SEC, 0, false};
    }
}

const char* kQuantities[] = {"tangential_velocity", "spin", "normal_restitution"};
double get(const Outcome& o, int q) { return q == 0 ? o.vt : (q == 1 ? o.spin : o.restitution); }

int usage()
{
    std::cerr << "usage: demmat_memory_accuracy [--out DIR] [--quick]\n"
                 "  work against precision of the §9 laws on Chung & Ooi tests 4 and 8 (docs/accuracy.md)\n";
    return 2;
}

} // namespace

int main(int argc, char** argv)
{
    try {
        Options opt;
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            if (a == "--out" && i + 1 < argc) opt.out_dir = argv[++i];
            else if (a == "--quick") opt.quick = true;
            else if (a == "--help" || a == "-h") return usage();
            else throw Error(fmt::format("unknown option '{}' (see --help)", a));
        }
        if (opt.quick) opt.per_tc = {20, 50, 200};
        std::string csv = "test,law,integrator,update,per_tc,runs,steps,cpu_seconds,error_tangential_velocity,error_spin,"
                          "error_normal_restitution,error,reference_step_error\n";
        json checks = json::array();
        for (int test : {4, 8}) {
            const ChungOoiTest& t = chung_ooi_test(test);
            std::vector<double> values;
            for (std::size_t k = 0; k < t.values.size(); k += opt.quick ? 4 : 1) values.push_back(t.values[k]);
            for (const std::string& law : kLaws) {
                // The reference at every point, its scale per quantity (the largest |value| over the sweep) and
                // its own step error (against t_c/4000, over the scale).
                std::vector<Outcome> ref, check;
                for (double v : values) {
                    ref.push_back(run(law_scene(test, v, law, Integrator::gear5, StretchUpdate::trapezoidal, kRefPerTc), t.wall()));
                    check.push_back(run(law_scene(test, v, law, Integrator::gear5, StretchUpdate::trapezoidal, kCheckPerTc), t.wall()));
                }
                double scale[3] = {0, 0, 0}, ref_error = 0;
                for (int q = 0; q < 3; ++q)
                    for (const Outcome& o : ref) scale[q] = std::max(scale[q], std::abs(get(o, q)));
                for (std::size_t k = 0; k < ref.size(); ++k) {
                    if (!ref[k].ok || !check[k].ok) throw Error(fmt::format("test {} {}: a reference run did not separate", test, law));
                    for (int q = 0; q < 3; ++q) ref_error = std::max(ref_error, std::abs(get(check[k], q) - get(ref[k], q)) / scale[q]);
                }
                checks.push_back({{"test", test}, {"law", law}, {"reference_step_error", ref_error}});
                std::cerr << fmt::format("test {} {}: reference step error {:.1e}\n", test, law, ref_error);
                const std::vector<StretchUpdate> updates = law == "paper" ? std::vector<StretchUpdate>{StretchUpdate::first_order}
                                                                          : std::vector<StretchUpdate>{StretchUpdate::first_order,
                                                                                                       StretchUpdate::trapezoidal};
                for (Integrator scheme : kSchemes)
                    for (StretchUpdate update : updates)
                        for (double n : opt.per_tc) {
                            double err[3] = {0, 0, 0}, cpu = 0;
                            std::int64_t steps = 0;
                            for (std::size_t k = 0; k < values.size(); ++k) {
                                const Outcome o = run(law_scene(test, values[k], law, scheme, update, n), t.wall());
                                cpu += o.cpu;
                                steps += o.steps;
                                for (int q = 0; q < 3; ++q)
                                    err[q] = o.ok ? std::max(err[q], std::abs(get(o, q) - get(ref[k], q)) / scale[q]) : INFINITY;
                            }
                            csv += fmt::format("{},{},{},{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.3g}\n", test, law, name(scheme),
                                               law == "paper" ? "none" : name(update), n, values.size(), steps, cpu, err[0], err[1], err[2],
                                               std::max({err[0], err[1], err[2]}), ref_error);
                        }
            }
        }
        write_atomically(opt.out_dir + "/memory_accuracy.csv", csv);
        const json meta = {{"provenance", provenance_json()},
                           {"settings", {{"variant", "arrays"}, {"per_tc", opt.per_tc}, {"quick", opt.quick}, {"laws", kLaws},
                                         {"reference", {{"integrator", "gear5"}, {"update", "trapezoidal"}, {"per_tc", kRefPerTc},
                                                        {"checked_against_per_tc", kCheckPerTc}}},
                                         {"quantities", kQuantities}, {"cost", "CPU seconds (std::clock) of the sweep's runs"}}},
                           {"references", checks}};
        write_atomically(opt.out_dir + "/memory_accuracy.json", meta.dump(1) + "\n");
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "demmat_memory_accuracy: error: " << e.what() << "\n";
        return 2;
    }
}
