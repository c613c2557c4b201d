// demmat_validation: the Chung & Ooi (2011) benchmark tests 1–8 (docs/validation.md). Every test's scenes
// come from chung_ooi_scene, the generator behind `demmat scene chung-ooi`; each run goes through Problem
// and the Driver with every registered variant that supports the run's law and integrator (those named by
// --variants; others are listed as skipped), and is measured by run_impact. Writes, into --out:
//   test<K>.csv         one row per run: the inputs, the derived constants and the measures
//   test<K>_curves.csv  tests 1 and 2: overlap and normal force at every step of the main runs (gear5)
//   validation.json     provenance, settings, which variants ran and which were skipped, the files
// analysis/plot_validation.py turns them into the error table and the figures. Run by scripts/run_validation.sh.
#include <cmath>
#include <iostream>
#include <set>
#include <sstream>
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

struct Options {
    std::string out_dir = "results/validation";
    std::vector<std::string> variants{"arrays", "fast"};
    std::set<int> tests{1, 2, 3, 4, 5, 6, 7, 8};
    double per_tc = 200.0;  // Δt = t_c / per_tc for every run but the integrator study
    bool quick = false;     // every third value of each sweep (a smoke test of the whole pipeline)
    StretchUpdate stretch_update = StretchUpdate::first_order;  // the history laws' (physics.md §9)
};

// The integrator study of the brief: tests 1 and 4 with gear5, gear3 and verlet at t_c/50 and t_c/200.
const std::vector<Integrator> kStudied{Integrator::gear5, Integrator::gear3, Integrator::verlet};
const std::vector<double> kStudiedPerTc{50.0, 200.0};

std::vector<std::string> split(const std::string& s)
{
    std::vector<std::string> out;
    std::stringstream in(s);
    for (std::string x; std::getline(in, x, ',');)
        if (!x.empty()) out.push_back(x);
    return out;
}

const char* kHeader =
    "test,material,law,variant,integrator,per_tc,dt,value,normal_speed,tangential_slip,radius1,radius2,density,young,poisson,"
    "mu,restitution,mstar,rstar,estar,hertz_contact_time,hertz_peak_overlap,gamma_n,gamma_t,alpha,kt,shear8,separated,steps,"
    "contact_time,peak_overlap,peak_force,normal_restitution,v1x,v1z,w1y,v2x,v2z,w2y\n";

std::string row(const ChungOoiCase& c, const Problem& p, const std::string& variant, const ImpactResult& r)
{
    const ChungOoiTest& t = chung_ooi_test(c.test);
    const ChungOoiMaterial& m = chung_ooi_material(t, c.material);
    const ChungOoiSetup su = chung_ooi_setup(c);
    const Scene& s = p.scene();
    const MemoryParams<double>& q = p.setup().memory;
    const double e = t.sweep == ChungOoiSweep::restitution ? c.value : t.restitution;
    auto g = [](double x) { return fmt::format("{:.17g}", x); };
    std::string o = fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},", t.number, m.name, c.law, variant,
                                name(c.integrator.scheme), g(c.per_tc), g(s.dt), g(c.value), g(su.normal_speed), g(su.tangential_slip),
                                g(t.radius), g(t.radius2), g(m.density), g(m.young), g(m.poisson), g(t.mu), g(e), g(su.mstar),
                                g(su.rstar), g(su.estar), g(su.contact_time), g(su.peak_overlap));
    o += fmt::format("{},{},{},{},{},{},{},", g(s.material.gamma_n), g(s.material.gamma_t), g(q.alpha), g(s.contact_model.kt),
                     g(t.wall() ? q.shear8_pw : q.shear8_pp), r.separated ? 1 : 0, r.steps);
    o += fmt::format("{},{},{},{},{},{},{},{},{},{}\n", g(r.contact_time), g(r.peak_overlap), g(r.peak_force), g(r.normal_restitution),
                     g(r.v1.x), g(r.v1.z), g(r.w1.y), g(r.v2.x), g(r.v2.z), g(r.w2.y));
    return o;
}

struct Outputs {
    std::string rows = kHeader;
    std::string curves = "test,material,law,variant,integrator,per_tc,t,overlap,normal_force\n";
    std::int64_t runs = 0;
};

// One case with every asked variant that supports it; `skipped` collects "variant: why".
void run_case(const ChungOoiCase& c, const Options& opt, Outputs& out, std::set<std::string>& skipped, std::set<std::string>& ran)
{
    Problem problem(chung_ooi_scene(c));
    // Force against time for tests 1 and 2, from the main runs (gear5 at --per-tc): the figures' curves.
    const bool curve = (c.test == 1 || c.test == 2) && c.integrator.is_default() && c.per_tc == opt.per_tc;
    for (const std::string& vname : opt.variants) {
        bool registered = false;
        for (const auto& v : registry().all()) registered = registered || v.name == vname;
        if (!registered) {
            skipped.insert(fmt::format("{}: not registered in this build", vname));
            continue;
        }
        auto variant = registry().find(vname).create();
        if (!variant->supports(problem.scene().contact_model) || !variant->supports(problem.scene().integrator)) {
            skipped.insert(fmt::format("{}: does not support {} with {}", vname, problem.scene().contact_model.is_paper() ? "the paper's law" : c.law,
                                       name(c.integrator.scheme)));
            continue;
        }
        const ImpactResult r = run_impact(*variant, problem, curve);
        ran.insert(vname);
        ++out.runs;
        out.rows += row(c, problem, vname, r);
        if (curve)
            for (const ImpactSample& s : r.curve)
                out.curves += fmt::format("{},{},{},{},{},{},{:.17g},{:.17g},{:.17g}\n", c.test, c.material, c.law, vname,
                                          name(c.integrator.scheme), c.per_tc, s.t, s.overlap, s.normal_force);
    }
}

int usage()
{
    std::cerr << "usage: demmat_validation [--out DIR] [--variants a,b] [--tests 1,2,...] [--per-tc N] [--quick]\n"
                 "       [--stretch-update first_order|trapezoidal]\n"
                 "  the Chung & Ooi tests 1–8 with every law that applies (docs/validation.md); default variants arrays,fast\n";
    return 2;
}

} // namespace

int main(int argc, char** argv)
{
    try {
        Options opt;
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            auto next = [&]() -> std::string {
                if (i + 1 >= argc) throw Error(fmt::format("option {} needs a value", a));
                return argv[++i];
            };
            if (a == "--out") opt.out_dir = next();
            else if (a == "--variants") opt.variants = split(next());
            else if (a == "--tests") {
                opt.tests.clear();
                for (const std::string& t : split(next())) opt.tests.insert(chung_ooi_test(std::stoi(t)).number);
            } else if (a == "--per-tc") opt.per_tc = std::stod(next());
            else if (a == "--quick") opt.quick = true;
            else if (a == "--stretch-update") {
                const std::string u = next();
                if (u == name(StretchUpdate::trapezoidal)) opt.stretch_update = StretchUpdate::trapezoidal;
                else if (u != name(StretchUpdate::first_order)) throw Error(fmt::format("--stretch-update '{}': expected first_order or trapezoidal", u));
            }
            else if (a == "--help" || a == "-h") return usage();
            else throw Error(fmt::format("unknown option '{}' (see --help)", a));
        }
        if (opt.variants.empty()) throw Error("--variants names no variant");
        if (!(opt.per_tc >= 1.0)) throw Error("--per-tc must be >= 1");

        json files = json::array();
        std::set<std::string> skipped, ran;
        for (int k : opt.tests) {
            const ChungOoiTest& t = chung_ooi_test(k);
            Outputs out;
            for (const ChungOoiMaterial& m : t.materials)
                for (std::size_t iv = 0; iv < t.values.size(); ++iv) {
                    if (opt.quick && iv % 3 != 0) continue;
                    for (const std::string& law : t.laws) {
                        ChungOoiCase c{k, m.name, t.values[iv], law, opt.per_tc, {}, opt.stretch_update};
                        run_case(c, opt, out, skipped, ran);
                        if (k != 1 && k != 4) continue;
                        for (Integrator scheme : kStudied)  // the integrator study (gear5 at per_tc is the run above)
                            for (double per_tc : kStudiedPerTc) {
                                if (scheme == Integrator::gear5 && per_tc == opt.per_tc) continue;
                                ChungOoiCase ci = c;
                                ci.per_tc = per_tc;
                                ci.integrator.scheme = scheme;
                                run_case(ci, opt, out, skipped, ran);
                            }
                    }
                }
            const std::string stem = fmt::format("{}/test{}", opt.out_dir, k);
            write_atomically(stem + ".csv", out.rows);
            files.push_back(fmt::format("test{}.csv", k));
            if (k == 1 || k == 2) {
                write_atomically(stem + "_curves.csv", out.curves);
                files.push_back(fmt::format("test{}_curves.csv", k));
            }
            std::cerr << fmt::format("test {}: {} runs\n", k, out.runs);
        }
        const json meta = {{"provenance", provenance_json()},
                           {"chung_ooi", {{"paper", "Chung & Ooi, Granular Matter 13 (2011) 643-656"}, {"tests", std::vector<int>(opt.tests.begin(), opt.tests.end())}}},
                           {"settings", {{"per_tc", opt.per_tc}, {"quick", opt.quick}, {"stretch_update", name(opt.stretch_update)}, {"variants_asked", opt.variants},
                                         {"integrator_study", {{"tests", {1, 4}}, {"schemes", {"gear5", "gear3", "verlet"}}, {"per_tc", kStudiedPerTc}}}}},
                           {"variants_ran", std::vector<std::string>(ran.begin(), ran.end())},
                           {"skipped", std::vector<std::string>(skipped.begin(), skipped.end())},
                           {"files", files}};
        write_atomically(opt.out_dir + "/validation.json", meta.dump(1) + "\n");
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "demmat_validation: error: " << e.what() << "\n";
        return 2;
    }
}
