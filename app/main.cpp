// demmat: the suite's command-line program. Every error is one line on stderr and a non-zero exit;
// every output file is written whole or not at all.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <limits>
#include <map>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "demmat/checker.hpp"
#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/io.hpp"
#include "demmat/output.hpp"
#include "demmat/problem.hpp"
#include "demmat/provenance.hpp"
#include "demmat/registry.hpp"
#include "demmat/run_log.hpp"
#include "demmat/text.hpp"
#include "demmat/chung_ooi.hpp"
#include "demmat/scenes.hpp"
#include "demmat/stability.hpp"
#include "demmat/threads.hpp"
#include "cli_ranges.hpp"
#include "peer_commands.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace demmat;

namespace {

// The files a scene reads (itself and its state file): an output must not overwrite one.
std::vector<NamedPath> scene_inputs(const Scene& s)
{
    std::vector<NamedPath> in{{s.source, "scene file"}};
    if (!s.state_file.empty()) in.emplace_back(s.state_file, "state file");
    return in;
}

// The problem of a scene file, validated. `prepare` runs on the scene before its state is made and Δt
// is checked: a command's overrides of the scene and the checks of its output paths, which must fail
// before any long work.
std::unique_ptr<Problem> load(const std::string& file, bool allow_unstable, const std::function<void(Scene&)>& prepare = {})
{
    Scene scene = load_scene(file);
    if (prepare) prepare(scene);
    auto l = std::make_unique<Problem>(std::move(scene));
    if (const std::string w = check_continued_walls(l->scene(), l->state()); !w.empty()) std::cerr << "demmat: warning: " << w << "\n";
    if (!allow_unstable) {
        const std::string warning = check_time_step(l->scene(), l->state());
        if (!warning.empty()) std::cerr << "demmat: warning: " << warning << "\n";
    } else {
        check_magnitudes(l->scene(), l->state());  // what no run survives, --allow-unstable or not
    }
    return l;
}

// --steps (>= 1, checked by the option) or, when --time is given (> 0), the steps that reach it.
std::int64_t steps_for(const Scene& scene, std::int64_t steps, double time)
{
    // 2^53 steps: beyond that a step count is not exact in a double (and the conversion could overflow).
    if (!(time >= 0.0) || !(time / scene.dt <= double(kMaxSteps)))
        throw Error(fmt::format("--time {:g} s is more than a run of Δt = {:g} s can reach in {} steps", time, scene.dt, kMaxSteps));
    if (steps < 1) throw Error(fmt::format("--steps {} is not a step count >= 1", steps));
    if (time > 0.0) return std::max<std::int64_t>(1, steps_to_reach(time, scene.dt));
    return steps;
}

std::vector<std::string> variant_list(const std::string& spec, bool allow_twice = false)
{
    if (spec == "all") return registry().names();
    std::vector<std::string> out;
    for (const std::string& name : split_list(spec)) {
        if (!allow_twice && std::find(out.begin(), out.end(), name) != out.end()) throw Error(fmt::format("variant '{}' is named twice", name));
        out.push_back(registry().find(name).name);
    }
    if (out.empty()) throw Error("no variant named in --variants");
    return out;
}

json phase_json(const PhaseTimes& t)
{
    return {{"predict", t.predict}, {"search", t.search}, {"forces", t.forces}, {"correct", t.correct},
            {"search_plus_forces", t.search + t.forces}, {"total", t.total()}};
}

json scene_json(const Problem& l)
{
    const Scene& s = l.scene();
    return {{"name", s.name},
            {"file", s.source.string()},
            {"particles", l.state().size()},
            {"dt", s.dt},
            {"start_step", l.state().step},
            {"search", s.search.method == SearchMethod::cells ? "cells" : "all_pairs"},
            {"cell_size_rmax", s.search.method == SearchMethod::cells ? s.search.cell_size : 0.0},
            {"cell_size_m", l.setup().cell_size},
            {"integrator", name(s.integrator.scheme)},
            {"precision", name(s.integrator.precision)}};
}

// ---- demmat run ------------------------------------------------------------------------------------
struct RunArgs {
    std::string scene, variant = "arrays", json_file, save_file, vtk_dir, log_file;
    std::string integrator, precision;  // override the scene's [integrator] when given
    std::int64_t steps = 1000, vtk_every = 0, log_every = kDefaultLogEvery;
    double time = 0.0;
    bool quiet = false, allow_unstable = false;
};

// Every output of `demmat run`, checked before the run: none is a directory or an input, each can be
// written, and no two are the same file.
// '-' as --json or --log: standard output (the run's report then goes to standard error).
bool to_stdout(const std::string& file) { return file == "-"; }
// An output given as a file (not absent, not standard output).
bool to_file(const std::string& file) { return !file.empty() && !to_stdout(file); }

void check_run_outputs(const RunArgs& a, const Scene& s)
{
    if (to_stdout(a.json_file) && to_stdout(a.log_file))
        throw Error("--json - and --log - both ask for standard output; give one of them a file name");
    if (to_stdout(a.save_file)) throw Error("--save -: a state file is binary, not written to standard output; give a file name");
    const auto inputs = scene_inputs(s);
    if (to_file(a.json_file)) check_output_path(a.json_file, "--json", inputs);
    if (to_file(a.save_file)) check_output_path(a.save_file, "--save", inputs);
    if (to_file(a.json_file) && to_file(a.save_file) && same_file(a.json_file, a.save_file))
        throw Error(fmt::format("--json and --save name the same file {}", a.json_file));
    if (!a.vtk_dir.empty()) {
        check_output_folder(a.vtk_dir, "--vtk");
        const fs::path pvd = fs::path(a.vtk_dir) / (safe_file_stem(s.name) + ".pvd");
        check_output_path(pvd, "--vtk", inputs);
        for (const std::string* f : {&a.json_file, &a.save_file, &a.log_file})
            if (to_file(*f) && same_file(*f, pvd)) throw Error(fmt::format("{} is also the VTK series of --vtk", *f));
    }
    if (!a.log_file.empty()) {
        for (const std::string* f : {&a.json_file, &a.save_file})
            if (to_file(*f) && to_file(a.log_file) && same_file(*f, a.log_file))
                throw Error(fmt::format("--log and another output name the same file {}", *f));
        // The log evaluates energies and wall forces with the paper's law (it has no access to the
        // variant's stretches): under a law of physics.md §9 its columns would be wrong, so it refuses.
        if (!s.contact_model.is_paper())
            throw Error("--log computes energies and wall forces with the paper's contact law only; this scene's [contact] law is "
                        "not supported by the run log yet");
    }
}

int cmd_run(const RunArgs& a)
{
    if (!a.log_file.empty()) {
        check_log_every(a.log_every);
        check_log_path(a.log_file, {a.scene});
    }
    const VariantInfo& info = registry().find(a.variant);
    auto l = load(a.scene, a.allow_unstable, [&](Scene& s) {
        override_integrator(s, a.integrator, a.precision);
        check_run_outputs(a, s);
    });
    const std::int64_t steps = steps_for(l->scene(), a.steps, a.time);
    // Files named after the scene's name, made safe: a name such as "../../x" stays inside the folder.
    const std::string vtk_stem = safe_file_stem(l->scene().name);
    if (!a.vtk_dir.empty()) {  // every snapshot name of the run, now that its first step is known
        auto others = scene_inputs(l->scene());
        for (const auto& [f, what] : {std::pair{a.json_file, "the --json file"}, {a.save_file, "the --save file"}, {a.log_file, "the --log file"}})
            if (to_file(f)) others.emplace_back(f, what);
        check_vtk_names(a.vtk_dir, vtk_stem, l->state().step, l->state().step + steps, others);
    }
    auto variant = info.create();
    Driver driver(*variant, l->setup());
    std::ostream& report = to_stdout(a.json_file) || to_stdout(a.log_file) ? std::cerr : std::cout;

    std::unique_ptr<VtkSeries> vtk;
    Snapshot snap;
    std::unique_ptr<RunLog> log;
    if (!a.log_file.empty()) {
        check_log_path(a.log_file, {a.scene, l->scene().state_file});
        log = std::make_unique<RunLog>(a.log_file, l->setup(), a.log_every);
        variant->snapshot(snap);
        log->write(snap);
    }
    auto write_vtk = [&] {
        variant->snapshot(snap);
        vtk->write(snap, l->state().radius, driver.time());
    };
    if (!a.vtk_dir.empty()) {
        vtk = std::make_unique<VtkSeries>(a.vtk_dir, vtk_stem, l->scene().domain, l->state().walls, l->scene().dt);
        write_vtk();
    }
    if (!a.quiet)
        std::cerr << fmt::format("demmat: {} on '{}': {} particles, {} walls, {} steps of {:g} s from step {}\n", info.name,
                                 l->scene().name, l->state().size(), l->state().walls.size(), steps, l->scene().dt, l->state().step);

    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    auto last = start;
    const bool tty = isatty(STDERR_FILENO);
    auto after_step = [&](std::int64_t k) {
        if (vtk && ((a.vtk_every > 0 && k % a.vtk_every == 0) || k == steps)) write_vtk();  // every E, and the last
        if (log && log->due(k, steps)) {
            variant->snapshot(snap);
            log->write(snap);
        }
        if (!a.quiet && (k & 63) == 0) {
            const auto now = clock::now();
            if (now - last > std::chrono::seconds(tty ? 1 : 10)) {
                last = now;
                const double el = std::chrono::duration<double>(now - start).count();
                std::cerr << fmt::format("{}step {}/{} ({:.0f}%), t = {:.4g} s, {:.0f} s elapsed, about {:.0f} s left{}",
                                         tty ? "\r" : "", k, steps, 100.0 * double(k) / double(steps), driver.time(), el,
                                         el / double(k) * double(steps - k), tty ? "   " : "\n");
            }
        }
    };
    try {
        driver.run(steps, after_step);
    } catch (const InstabilityError& e) {
        if (!vtk) throw;
        // The series ends with the state at the failing step, so that ParaView shows the blow-up; --json
        // and --save are not written.
        write_vtk();
        throw InstabilityError(fmt::format("{}; the VTK series {} ends with the state at step {}", e.what(),
                                           (fs::path(a.vtk_dir) / (vtk_stem + ".pvd")).string(), driver.current_step()),
                               e.step(), e.particle());
    }
    const double wall = std::chrono::duration<double>(clock::now() - start).count();
    if (!a.quiet && tty) std::cerr << "\r" << std::string(78, ' ') << "\r";

    variant->snapshot(snap);
    const ContactCounts c = variant->counts();
    const double n = double(l->state().size());
    const double ke = kinetic_energy(snap, l->setup());
    const PhaseTimes t = driver.times().per_step(steps);
    report << fmt::format("variant {}  scene {}  particles {}  steps {}  t = {:.6g} s\n", info.name, l->scene().name,
                             l->state().size(), steps, driver.time());
    report << fmt::format("integrator {}\n", l->scene().integrator.describe());
    if (!l->scene().contact_model.is_paper())
        report << "contact law " << describe_law(l->scene().contact_model, l->setup().memory) << "\n";
    // The model instantiation the variant picked in init() (docs/design.md, "Model features").
    report << fmt::format("model {}  (the scene needs {})\n", variant->model().name(),
                             features_of(l->scene(), l->state()).name());
    report << fmt::format("steps per second {:.1f}  ({:.4f} us per particle-step)\n", 1.0 / t.total(),
                             t.total() / n * 1e6);
    report << fmt::format("per step: predict {:.3e} s  search {:.3e} s  forces {:.3e} s  correct {:.3e} s  total {:.3e} s\n",
                             t.predict, t.search, t.forces, t.correct, t.total());
    report << fmt::format("contacts per particle {:.3f} (particle-particle {}, particle-wall {})  kinetic energy {:.6e} J\n",
                             c.per_particle(l->size()), c.particle_particle, c.particle_wall, ke);
    // Sampled: measured at the health checks only (every checks.interval steps and the last), not every step.
    if (l->scene().checks.interval > 0)
        report << fmt::format("largest overlap at the health checks (sampled every {} steps and at the last) {:.3g} of the "
                                 "smaller radius (bound {})\n",
                                 l->scene().checks.interval, driver.largest_overlap_ratio(), l->scene().checks.max_overlap_ratio);
    report << fmt::format("PERFORMANCE variant={} particles={} steps={} us_per_particle_step={:.5f} seconds={:.4f}\n",
                             info.name, l->state().size(), steps, t.total() / n * 1e6, wall);

    if (!a.save_file.empty()) {
        State out;
        variant->save(out);
        out.dt = l->scene().dt;
        out.fingerprint = l->state().fingerprint;
        save_state(out, a.save_file);
    }
    if (!a.json_file.empty()) {
        json j = {{"provenance", provenance_json()},
                  {"scene", scene_json(*l)},
                  {"variant", info.name},
                  {"model", {{"picked", variant->model().name()}, {"scene_needs", features_of(l->scene(), l->state()).name()}}},
                  {"steps", steps},
                  {"threads", variant->threads_used()},
                  {"end_time", driver.time()},
                  {"wall_seconds", wall},
                  {"steps_per_second", 1.0 / t.total()},
                  {"us_per_particle_step", t.total() / n * 1e6},
                  {"seconds_per_step", phase_json(t)},
                  {"contacts", {{"particle_particle", c.particle_particle}, {"particle_wall", c.particle_wall},
                                {"per_particle", c.per_particle(l->size())}}},
                  {"kinetic_energy", ke},
                  {"largest_overlap_ratio", driver.largest_overlap_ratio()},  // sampled at the health checks
                  {"largest_overlap_sampled_every_steps", l->scene().checks.interval},  // 0: no checks, no sample
                  {"memory_bytes", variant->memory_bytes()}};
        if (to_stdout(a.json_file)) std::cout << j.dump(2) << "\n" << std::flush;
        else write_atomically(a.json_file, j.dump(2) + "\n");
    }
    return 0;
}

// ---- demmat compare ----------------------------------------------------------------------------------
int cmd_compare(const std::string& scene, const std::string& variants, std::int64_t steps, double time, bool allow_unstable)
{
    // A variant may be named twice: two instances must agree too (run-to-run determinism). The names are
    // checked before the scene's state is made.
    auto names = variant_list(variants, true);
    auto l = load(scene, allow_unstable);
    if (variants == "all") {  // every variant that promises bit identity (fast_unordered drops it on purpose)
        std::vector<std::string> left_out;
        for (const std::string& n : names)
            if (!registry().find(n).bitwise) left_out.push_back(n);
        std::erase_if(names, [](const std::string& n) { return !registry().find(n).bitwise; });
        if (!left_out.empty())
            std::cout << fmt::format("left out: {} (not bit-identical by design: {} not keep the canonical order of force "
                                     "summation; name {} in --variants to see how far {} drifts)\n",
                                     fmt::join(left_out, ", "), left_out.size() == 1 ? "it does" : "they do",
                                     left_out.size() == 1 ? "it" : "them", left_out.size() == 1 ? "it" : "they");
    }
    if (variants == "all" && names.size() == 1) names.push_back(names.front());
    if (names.size() < 2) throw Error("compare needs at least two variants (a variant may be named twice)");
    const std::int64_t k = steps_for(l->scene(), steps, time);
    const CompareReport r = compare_variants(names, l->setup(), k);
    if (r.difference) {
        std::cout << "differ: " << r.difference->describe() << "\n";
        return 1;
    }
    std::cout << fmt::format("identical: {} over {} steps of '{}' ({} particles)\n", fmt::join(names, ", "), r.steps,
                             l->scene().name, l->state().size());
    return 0;
}

// ---- demmat bench --------------------------------------------------------------------------------------
struct BenchArgs {
    std::string scene, variants = "all", json_file, threads = "0";
    std::int64_t steps = 200, repetitions = 5, warmup = 20;
    bool allow_unstable = false;
};

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    const std::size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// `--threads 1,2`: the thread counts to time; 0 stands for OpenMP's default (OMP_NUM_THREADS, else all cores).
std::vector<int> thread_counts(const std::string& spec)
{
    const int fallback = max_threads();
    std::vector<int> out;
    if (spec.empty() || spec.front() == ',' || spec.back() == ',' || spec.find(",,") != std::string::npos)
        throw Error(fmt::format("--threads '{}': an empty item in the list (thread counts separated by single commas)", spec));
    for (const std::string& item : split_list(spec)) {
        std::size_t used = 0;
        int t = -1;
        try {
            t = std::stoi(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != item.size() || t < 0) throw Error(fmt::format("--threads: '{}' is not a thread count (0 to {})", item, max_thread_count()));
        if (t > max_thread_count())
            throw Error(fmt::format("--threads: {} is out of range (0 to {}: {})", item, max_thread_count(), thread_limit_reason()));
        if (t == 0) t = fallback;
        if (t > 1 && !openmp_enabled()) throw Error(fmt::format("--threads: {} threads asked, but this build has no OpenMP", t));
        if (std::find(out.begin(), out.end(), t) != out.end()) throw Error(fmt::format("--threads: {} thread(s) named twice", t));
        out.push_back(t);
    }
    if (out.empty()) throw Error("no thread count in --threads");
    return out;
}

// One timed configuration: a variant at a thread count (a variant that is not threaded runs once, at 1).
struct BenchConfig {
    std::string variant;
    int threads;
    std::string label() const { return fmt::format("{}@{}", variant, threads); }
};

int cmd_bench(const BenchArgs& a)
{
    const auto names = variant_list(a.variants);  // the cheap checks before the scene's state is made
    const std::vector<int> counts_asked = thread_counts(a.threads);
    auto l = load(a.scene, a.allow_unstable, [&](const Scene& s) {
        if (!a.json_file.empty()) check_output_path(a.json_file, "--json", scene_inputs(s));
    });
    std::vector<BenchConfig> configs;
    for (const auto& name : names) {
        if (!registry().find(name).threaded) configs.push_back({name, 1});
        else
            for (const int t : counts_asked) configs.push_back({name, t});
    }
    const char* phases[] = {"predict", "search", "forces", "correct"};
    // samples[config][phase] = seconds per step, one per repetition
    std::map<std::string, std::map<std::string, std::vector<double>>> samples;
    std::map<std::string, ContactCounts> counts;
    std::map<std::string, std::size_t> memory;
    std::map<std::string, std::string> model;  // the model instantiation each variant picked
    std::map<std::string, int> used;           // the threads it really ran on (fast runs small beds on one)
    json reps = json::array();
    for (std::int64_t r = 0; r < a.repetitions; ++r) {
        // Interleaved, variants and thread counts alike, with the order rotated each repetition, so that
        // drift of a shared machine hits all alike (a speed-up is then a ratio of samples taken side by side).
        for (std::size_t q = 0; q < configs.size(); ++q) {
            const BenchConfig& cfg = configs[(q + std::size_t(r)) % configs.size()];
            const std::string key = cfg.label();
            set_threads(cfg.threads);
            auto variant = registry().find(cfg.variant).create();
            Driver driver(*variant, l->setup());
            const PhaseTimes t = measure_steps(driver, a.warmup, a.steps);
            const double v[4] = {t.predict, t.search, t.forces, t.correct};
            used[key] = variant->threads_used();
            for (int p = 0; p < 4; ++p) {
                samples[key][phases[p]].push_back(v[p]);
                reps.push_back({{"variant", cfg.variant},
                                {"threads", used[key]},
                                {"threads_asked", cfg.threads},
                                {"repetition", r},
                                {"phase", phases[p]},
                                {"seconds_per_step", v[p]}});
            }
            counts[key] = variant->counts();
            memory[key] = variant->memory_bytes();
            model[key] = variant->model().name();
        }
        std::cerr << fmt::format("demmat bench: repetition {}/{} done\n", r + 1, a.repetitions);
    }
    json summary = json::array();
    const double n = double(l->state().size());
    std::size_t width = 7;  // the longest variant name, so that the columns line up
    for (const auto& cfg : configs) width = std::max(width, cfg.variant.size());
    std::cout << fmt::format("{:<{}} {:>7} {:>12} {:>12} {:>12} {:>12} {:>12} {:>10}\n", "variant", width, "threads", "predict", "search",
                             "forces", "correct", "total", "us/p-step");
    for (const auto& cfg : configs) {
        const std::string key = cfg.label();
        json ph;
        std::vector<double> totals(std::size_t(a.repetitions), 0.0);
        for (const char* p : phases) {
            const auto& s = samples[key][p];
            ph[p] = {{"median", median(s)}, {"min", *std::min_element(s.begin(), s.end())}, {"max", *std::max_element(s.begin(), s.end())}};
            for (std::size_t r = 0; r < s.size(); ++r) totals[r] += s[r];
        }
        const double tot_med = median(totals);
        ph["total"] = {{"median", tot_med}, {"min", *std::min_element(totals.begin(), totals.end())},
                       {"max", *std::max_element(totals.begin(), totals.end())}};
        const ContactCounts& c = counts[key];
        summary.push_back({{"variant", cfg.variant},
                           {"threads", used[key]},
                           {"threads_asked", cfg.threads},
                           {"seconds_per_step", ph},
                           {"us_per_particle_step", tot_med / n * 1e6},
                           {"contacts_per_particle", c.per_particle(l->size())},
                           {"memory_bytes", memory[key]},
                           {"model", model[key]}});
        std::cout << fmt::format("{:<{}} {:>7} {:>12.4e} {:>12.4e} {:>12.4e} {:>12.4e} {:>12.4e} {:>10.4f}\n", cfg.variant, width, used[key],
                                 ph["predict"]["median"].get<double>(), ph["search"]["median"].get<double>(),
                                 ph["forces"]["median"].get<double>(), ph["correct"]["median"].get<double>(), tot_med,
                                 tot_med / n * 1e6);
    }
    std::cout << "(seconds per step, medians over " << a.repetitions << " interleaved repetitions of " << a.steps
              << " steps; the variants that are not threaded run on 1 thread)\n";
    if (!a.json_file.empty()) {
        json j = {{"provenance", provenance_json()},
                  {"scene", scene_json(*l)},
                  {"steps", a.steps},
                  {"warmup_steps", a.warmup},
                  {"repetitions", a.repetitions},
                  {"thread_counts", counts_asked},
                  {"summary", summary},
                  {"samples", reps}};
        write_atomically(a.json_file, j.dump(2) + "\n");
    }
    return 0;
}

// ---- demmat scene ----------------------------------------------------------------------------------------
// chung-ooi's case before the options: test 0 says --test was not given.
ChungOoiCase no_test()
{
    ChungOoiCase c;
    c.test = 0;
    return c;
}

struct SceneArgs {
    std::string kind, out, from, state;
    std::int64_t count = 0;  // 0: the kind's default
    std::uint64_t seed = 1;
    std::int64_t max_layers = dense_bed_max_layers;
    double speed = 0.0, gap = 0.001;  // speed 0: the kind's default
    std::vector<std::string> contact;  // --contact KEY=VALUE: the [contact] table (physics.md §9)
    ChungOoiCase chung_ooi = no_test();  // chung-ooi (test 0: --test not given): --test, --material, --value, --law, --per-tc
    bool chung_ooi_value = false;      // --value given (else the test's first)
    std::vector<std::string> given;    // the options given, by their long names
};

// The options each kind of scene reads (besides --out): any other option given is refused, never ignored.
void check_scene_options(const SceneArgs& a)
{
    static const std::map<std::string, std::vector<std::string>> takes = {
        {"paper", {"--n", "--seed", "--contact"}},
        {"dense-bed", {"--n", "--seed", "--max-layers", "--contact"}},
        {"head-on", {"--speed", "--contact"}},
        {"drop", {"--gap", "--contact"}},
        {"chung-ooi", {"--test", "--material", "--value", "--law", "--per-tc"}},
        {"compression", {"--from", "--state", "--speed", "--contact"}},
        {"settled", {"--from", "--state", "--contact"}}};
    const auto it = takes.find(a.kind);
    if (it == takes.end()) return;  // an unknown kind is named by cmd_scene
    for (const std::string& opt : a.given)
        if (opt != "--out" && std::find(it->second.begin(), it->second.end(), opt) == it->second.end())
            throw Error(fmt::format("scene {} does not use {} (it takes {} and --out)", a.kind, opt, fmt::join(it->second, ", ")));
    if (a.kind == "chung-ooi" && a.chung_ooi_value && a.chung_ooi.test >= 1 && a.chung_ooi.test <= 8 &&
        chung_ooi_test(a.chung_ooi.test).sweep == ChungOoiSweep::none)
        throw Error(fmt::format("scene chung-ooi --test {} sweeps nothing: --value has no meaning for it", a.chung_ooi.test));
}

// Checking a scene makes its grains (the state and the t = 0 force pass, about this many bytes each):
// a count this machine cannot hold is refused at once rather than by the out-of-memory killer.
constexpr double kBytesPerGrainToCheck = 384.0;
void check_memory_for(std::int64_t grains)
{
    const double need = double(grains) * kBytesPerGrainToCheck;
    const double have = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGE_SIZE));
    if (have > 0.0 && need > have)
        throw Error(fmt::format("--n {}: checking the scene makes its grains, about {:.0f} GB at {:.0f} bytes a grain, more than this "
                                "machine's {:.0f} GB of memory", grains, need / 1e9, kBytesPerGrainToCheck, have / 1e9));
}

// Writes a scene only if `demmat run` would accept it: the options are checked by their validators (--n
// >= 1, --speed > 0, --gap >= 0, finite), and the scene itself by making its initial state (particles in
// the domain, apart, clear of the walls; a state file of this scene) and checking Δt as run does.
int cmd_scene(const SceneArgs& a)
{
    check_scene_options(a);
    if (!a.out.empty() && !to_stdout(a.out)) {
        std::vector<NamedPath> inputs;
        if (!a.from.empty()) inputs.emplace_back(a.from, "scene file");
        if (!a.state.empty()) inputs.emplace_back(a.state, "state file");
        check_output_path(a.out, "--out", inputs);
    }
    if ((a.kind == "paper" || a.kind == "dense-bed") && a.count > 0) check_memory_for(a.count);
    Scene s;
    if (a.kind == "paper") s = paper_scene(a.count > 0 ? a.count : 1000, a.seed);
    else if (a.kind == "dense-bed") s = dense_bed_scene(a.count > 0 ? a.count : 2000, a.seed, a.max_layers);
    else if (a.kind == "head-on") s = head_on_scene(a.speed > 0.0 ? a.speed : 1.0);
    else if (a.kind == "drop") s = drop_scene(a.gap);
    else if (a.kind == "chung-ooi") {
        if (a.chung_ooi.test == 0) throw Error("scene chung-ooi needs --test K (1 to 8, Chung & Ooi 2011; docs/validation.md)");
        if (!a.contact.empty()) throw Error("scene chung-ooi: the law is chosen with --law (paper, restitution, linear_history, mindlin), not --contact");
        ChungOoiCase c = a.chung_ooi;
        if (!a.chung_ooi_value) c.value = chung_ooi_test(c.test).values.front();
        s = chung_ooi_scene(c);
    }
    else if (a.kind == "compression" || a.kind == "settled") {
        if (a.from.empty() || a.state.empty()) throw Error(fmt::format("scene {} needs --from SCENE and --state STATE", a.kind));
        const Scene from = load_scene(a.from);
        // The state must hold the grains of the scene it continues (the fingerprint binds its materials,
        // Δt and gravity to its own count, so a state of 2000 grains would pass for a scene of 1).
        const std::size_t from_count = from.grid ? std::size_t(from.grid->count)
                                     : from.state_file.empty() ? from.particles.size() : load_state(from.state_file).size();
        const std::size_t state_count = load_state(a.state).size();
        if (from_count != state_count)
            throw Error(fmt::format("--state {} holds {} particles, but --from {} makes {}: the state was not saved from this scene",
                                    a.state, state_count, a.from, from_count));
        s = a.kind == "compression" ? compression_scene(from, a.state, a.speed > 0.0 ? a.speed : 0.5) : settled_scene(from, a.state);
    } else {
        throw Error(fmt::format("unknown scene kind '{}' (expected paper, dense-bed, settled, compression, head-on, drop or chung-ooi)", a.kind));
    }
    if (!a.contact.empty()) s.contact_model = contact_model_from_options(a.contact);
    {
        const State state = initial_state(s);
        check_time_step(s, state);  // throws above the stability limit; its warnings are run's to give
        // A continued scene names its walls where the state has them, so that the file says what a run does.
        if (!s.state_file.empty())
            for (std::size_t w = 0; w < s.walls.size(); ++w) {
                s.walls[w].point = state.walls[w].point_at(state.step, s.dt);
                s.walls[w].normal = state.walls[w].normal;
            }
    }
    if ((a.kind == "compression" || a.kind == "settled") && !a.out.empty() && !to_stdout(a.out)) {  // the state path relative to the new scene file, so the pair can move together
        std::error_code ec;
        const fs::path rel = fs::relative(fs::absolute(a.state), fs::absolute(fs::path(a.out)).parent_path(), ec);
        if (!ec && !rel.empty()) s.state_file = rel;
    }
    const std::string text = scene_to_toml(s);
    if (a.out.empty() || to_stdout(a.out)) std::cout << text;
    else write_atomically(a.out, text);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"demmat: the DEMMAT discrete element benchmark suite (variants of one DEM processor for spheres)"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Help for every subcommand");
    app.set_version_flag("--version", [] {
        const Provenance& p = build_provenance();
        return fmt::format("demmat {}\ncommit {}{}\ncompiler {}\nflags {}\nbuild type {}\ncpu {}", DEMMAT_VERSION, p.commit,
                           p.dirty ? " (dirty)" : "", p.compiler, p.flags, p.build_type, cpu_model());
    });

    auto* list = app.add_subcommand("list", "List the registered variants, one per line, name first");
    PeerCommands peers(app);  // export-lammps, import-lammps, dump (docs/peers.md)

    SceneArgs sa;
    auto* scene = app.add_subcommand("scene", "Write a standard scene as an editable TOML file (to stdout without --out)");
    scene->add_option("kind", sa.kind, "paper | dense-bed | settled | compression | head-on | drop | chung-ooi")->required();
    scene->add_option("--out,-o", sa.out, "Output file (default, or -: standard output)")->check(path_given());
    constexpr std::int64_t int_max = 2147483647, int64_max = std::numeric_limits<std::int64_t>::max();
    scene->add_option("--n", sa.count, "Number of particles (paper: 1000, dense-bed: 2000; at most what this machine's memory holds, "
                                       "about 384 bytes a grain)")
        ->check(integer_in(1, int_max, "32-bit particle indices"));
    scene->add_option("--seed", sa.seed, "Seed of the particle generator")->check(integer_in(0, int64_max));
    scene->add_option("--max-layers", sa.max_layers, "dense-bed: at most this many lattice layers; more grains make the bed wider")
        ->check(integer_in(1, int_max));
    scene->add_option("--speed", sa.speed, "head-on: relative speed (m/s); compression: wall speed (m/s)")->check(number_from(0.0, true));
    scene->add_option("--gap", sa.gap, "drop: initial gap between the sphere and the wall (m)")->check(number_from(0.0, false));
    scene->add_option("--from", sa.from, "settled, compression: the scene that was settled")->check(path_given());
    scene->add_option("--state", sa.state, "settled, compression: the settled state file")->check(path_given());
    scene->add_option("--test", sa.chung_ooi.test, "chung-ooi: the test, 1 to 8 (docs/validation.md)")->check(integer_in(1, 8));
    scene->add_option("--material", sa.chung_ooi.material, "chung-ooi: the test's material (default its first)");
    scene->add_option("--value", sa.chung_ooi.value, "chung-ooi: the swept value (e, angle in degrees, tangential speed or spin; default the first)")
        ->each([&sa](const std::string&) { sa.chung_ooi_value = true; });
    scene->add_option("--law", sa.chung_ooi.law, "chung-ooi: paper | restitution | linear_history | mindlin");
    scene->add_option("--per-tc", sa.chung_ooi.per_tc, "chung-ooi: Δt = t_c / this (default 200)")->check(number_from(1.0, false));
    scene->add_option("--contact", sa.contact, "KEY=VALUE of the [contact] table, repeatable (e.g. tangential=mindlin); docs/scene-format.md");

    RunArgs ra;
    auto* run = app.add_subcommand("run", "Run a scene with one variant and report per-phase times");
    run->add_option("scene", ra.scene, "Scene file (TOML)")->required();
    run->add_option("--variant,-v", ra.variant, "Variant name (see demmat list)");
    auto* steps_opt = run->add_option("--steps,-n", ra.steps, "Number of steps")->check(integer_in(1, kMaxSteps));
    run->add_option("--time,-t", ra.time, "Simulated time (s), instead of --steps")->excludes(steps_opt)->check(number_from(0.0, true));
    run->add_option("--json", ra.json_file, "Write the summary as JSON with provenance (-: to standard output, the report to standard error)")->check(path_given());
    run->add_option("--save", ra.save_file, "Save the final state (continue with particles.source = \"state\")")->check(path_given());
    run->add_option("--vtk", ra.vtk_dir, "Write VTK snapshots (particles and walls) and a .pvd series (ParaView) into this folder, "
                                          "named after the scene (characters other than letters, digits, '-', '_', '.' become '_'); "
                                          "on a blow-up the series ends with the failing step")->check(path_given());
    run->add_option("--vtk-every", ra.vtk_every, "Steps between VTK snapshots (0: first and last only)")->check(integer_in(0, kMaxSteps));
    auto* log_opt = run->add_option("--log", ra.log_file, "Write a CSV time series (energies, contacts, overlap, wall forces; -: to standard output)")
                        ->check(path_given());
    run->add_option("--log-every", ra.log_every, fmt::format("Steps between rows of --log (default {})", kDefaultLogEvery))->needs(log_opt);
    run->add_flag("--quiet,-q", ra.quiet, "No progress on stderr");
    run->add_flag("--allow-unstable", ra.allow_unstable, "Run even with a time step above the Rayleigh time, without warning");
    run->add_option("--integrator", ra.integrator, "gear5 | gear3 | verlet | symplectic_euler (overrides the scene's [integrator])");
    run->add_option("--precision", ra.precision, "double | float (overrides the scene's [integrator])");
    // Threads of the OpenMP variants (fast, fast_unordered); 0 = OpenMP's default (OMP_NUM_THREADS, else all cores).
    int threads = 0;
    const char* threads_help = "Threads for the threaded variants (fast, fast_unordered); 0: OpenMP's default";
    const CLI::Validator thread_range = integer_in(0, max_thread_count(), thread_limit_reason());
    run->add_option("--threads", threads, threads_help)->check(thread_range);

    std::string cmp_scene, cmp_variants = "all";
    std::int64_t cmp_steps = 100;
    double cmp_time = 0.0;
    bool cmp_allow = false;
    auto* compare = app.add_subcommand("compare", "Run variants side by side and check that every step is bit-identical");
    compare->add_option("scene", cmp_scene, "Scene file (TOML)")->required();
    compare->add_option("--variants", cmp_variants, "Comma-separated variant names, or all");
    auto* cmp_steps_opt = compare->add_option("--steps,-n", cmp_steps, "Number of steps")->check(integer_in(1, kMaxSteps));
    compare->add_option("--time,-t", cmp_time, "Simulated time (s), instead of --steps")->excludes(cmp_steps_opt)->check(number_from(0.0, true));
    compare->add_flag("--allow-unstable", cmp_allow, "Run even with a time step above the Rayleigh time, without warning");
    compare->add_option("--threads", threads, threads_help)->check(thread_range);

    BenchArgs ba;
    auto* bench = app.add_subcommand("bench", "Time variants per phase: interleaved repetitions, medians and spread");
    bench->add_option("scene", ba.scene, "Scene file (TOML)")->required();
    bench->add_option("--variants", ba.variants, "Comma-separated variant names, or all");
    bench->add_option("--steps,-n", ba.steps, "Timed steps per repetition")->check(integer_in(1, kMaxSteps));
    bench->add_option("--repetitions,-r", ba.repetitions, "Repetitions")->check(integer_in(1, int_max));
    bench->add_option("--warmup", ba.warmup, "Untimed steps before each repetition")->check(integer_in(0, kMaxSteps));
    bench->add_option("--json", ba.json_file, "Write the samples and medians as JSON with provenance")->check(path_given());
    bench->add_flag("--allow-unstable", ba.allow_unstable, "Run even with a time step above the Rayleigh time, without warning");
    bench->add_option("--threads", ba.threads,
                      "Comma-separated thread counts for the threaded variants, timed interleaved (e.g. 1,2); 0: OpenMP's default");

    remove_partial_files_on_signal();
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) names.push_back(sub->get_name());
    if (argc > 1 && argv[1][0] != '-' && std::find(names.begin(), names.end(), argv[1]) == names.end()) {  // CLI11: "A subcommand is required"
        std::cerr << fmt::format("demmat: error: unknown subcommand '{}' (expected {}; see demmat --help)\n", argv[1], fmt::join(names, ", "));
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "demmat: error: " << e.what() << " (see demmat --help)\n";
        return 2;
    }
    set_threads(threads);
    for (const CLI::Option* opt : scene->get_options())
        if (opt->count() > 0 && opt->nonpositional()) sa.given.push_back(opt->get_name());

    try {
        if (*list) {
            std::size_t width = 0;
            for (const auto& v : registry().all()) width = std::max(width, v.name.size());
            for (const auto& u : registry().unavailable()) width = std::max(width, u.first.size());
            for (const auto& v : registry().all()) std::cout << fmt::format("{:<{}}  {}\n", v.name, width, v.summary);
            for (const auto& [name, why] : registry().unavailable()) std::cout << fmt::format("{:<{}}  unavailable: {}\n", name, width, why);
            return 0;
        }
        if (*scene) return cmd_scene(sa);
        if (*run) return cmd_run(ra);
        if (*compare) return cmd_compare(cmp_scene, cmp_variants, cmp_steps, cmp_time, cmp_allow);
        if (*bench) return cmd_bench(ba);
        if (const int rc = peers.dispatch(); rc >= 0) return rc;
    } catch (const InstabilityError& e) {
        std::cerr << "demmat: run stopped: " << e.what() << "\n";
        return 3;
    } catch (const Error& e) {
        std::cerr << "demmat: error: " << e.what() << "\n";
        return 2;
    } catch (const std::bad_alloc&) {
        std::cerr << "demmat: error: out of memory (the scene needs more than this machine can allocate)\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "demmat: internal error: " << e.what() << "\n";
        return 70;
    }
    return 0;
}
