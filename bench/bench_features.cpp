// What each model feature costs per step (docs/design.md, "Model features").
//
// One monodisperse dense bed, settled once with every feature on (cached in --states-dir), then six
// scenes made from it, each needing one feature more than the one before:
//
//   0 normal        Hertz normal force only: μ = 0, γ_n = 0, no walls, no spin
//   1 +damping      γ_n = 60 1/s
//   2 +friction     μ = 0.6 (γ_t = 60 1/s), with rotation and the settled bed's spins
//   3 +walls        the closed box, fixed
//   4 +moving walls x_max moving in at 0.5 m/s (the compression stage)
//   5 +polydisperse level 4 with R*, m* computed per contact: on this monodisperse bed the feature is
//                   inert, so the trajectory is level 4's bit for bit and the difference is its work alone
//
// Every level runs twice per variant: the specialised model the variant picks for the scene, and the
// full model (Setup::widen), which on that scene gives the same trajectory bit for bit (tested in
// tests/test_features.cpp) — the difference is what specialisation saves. Each benchmark run starts from
// the settled state, takes 20 untimed steps, then exactly --steps timed steps (Iterations), so every
// repetition of every benchmark covers the same stretch of trajectory. Phases are timed by the suite's
// driver. Run with --benchmark_enable_random_interleaving=true --benchmark_repetitions=R
// (scripts/run_features.sh) so machine drift hits every configuration alike.
//
// Every variant runs on one core (a threaded one, fast, on one thread: the table compares codes, not
// machines).
//
// Own options (before Google Benchmark's): --n=N (2000), --steps=K (300), --states-dir=DIR (states),
// --variants=a,b (arrays,eigen_soa,fast).
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "benchmark_common.hpp"
#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/output.hpp"
#include "demmat/problem.hpp"
#include "demmat/registry.hpp"
#include "demmat/text.hpp"
#include "demmat/threads.hpp"
#include "demmat/scenes.hpp"
#include "demmat/state.hpp"

using namespace demmat;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

struct Options {
    std::int64_t n = 2000;
    std::int64_t steps = 300;
    fs::path states_dir = "states";
    std::vector<std::string> variants = {"arrays", "eigen_soa", "fast"};
};
Options opt;

const double kSettleTime = 0.3;  // s: the bed has collapsed and is nearly at rest (about 6 contacts per grain)
const std::int64_t kWarmup = 20;

// The monodisperse dense bed: the dense-bed family with R_min = R_max.
Scene mono_bed(std::int64_t n)
{
    Scene s = dense_bed_scene(n);
    s.name = fmt::format("dense_bed_mono_{}", n);
    s.grid->radius_min = s.grid->radius_max;
    return s;
}

State settled_bed(const Scene& bed)
{
    const fs::path file = opt.states_dir / fmt::format("{}_settled.state", bed.name);
    const std::int64_t steps = steps_to_reach(kSettleTime, bed.dt);
    return settled_state(bed, steps, file, registry().find("arrays").create, [&](std::int64_t k, std::int64_t total) {
        if (k == 1)
            std::cerr << fmt::format("bench_features: settling {} for {} s ({} steps; cached in {})\n", bed.name, kSettleTime, total,
                                     file.string());
    });
}

struct Level {
    int index;
    std::string name;
    std::unique_ptr<Problem> problem;
    ModelFeatures widen;  // level 5 only: the inert polydisperse kernel
};

// The six scenes, each with its own copy of the settled state (walls and spins as the level needs).
std::vector<std::unique_ptr<Level>> make_levels(const Scene& bed, const State& settled)
{
    std::vector<std::unique_ptr<Level>> out;
    auto add = [&](const std::string& name, auto&& change, bool spin, ModelFeatures widen = {}) {
        auto l = std::make_unique<Level>();
        l->index = int(out.size());
        l->name = name;
        Scene scene = bed;
        scene.name = bed.name + "_" + name;
        change(scene);
        State state = settled;
        if (!spin)
            for (std::vector<Vec3d>* q : {&state.rot.x, &state.rot.v, &state.rot.a, &state.rot.b3, &state.rot.b4, &state.rot.b5})
                std::fill(q->begin(), q->end(), Vec3d{});
        state.walls = continue_walls(scene, state);
        l->problem = std::make_unique<Problem>(std::move(scene), std::move(state));
        l->widen = widen;
        out.push_back(std::move(l));
    };
    auto normal = [](Scene& s) {
        s.material.mu = 0.0;
        s.material.gamma_n = 0.0;
        s.walls.clear();
    };
    auto damping = [&](Scene& s) {
        normal(s);
        s.material.gamma_n = bed.material.gamma_n;
    };
    auto friction = [&](Scene& s) {
        damping(s);
        s.material.mu = bed.material.mu;
    };
    auto walls = [&](Scene& s) {
        friction(s);
        s.walls = bed.walls;
    };
    auto moving = [&](Scene& s) {
        walls(s);
        for (Wall& w : s.walls)
            if (w.name == "x_max") w.velocity = {-0.5, 0.0, 0.0};
    };
    add("normal", normal, false);
    add("damping", damping, false);
    add("friction", friction, true);
    add("walls", walls, true);
    add("moving_walls", moving, true);
    ModelFeatures poly;
    poly.polydisperse = true;
    add("polydisperse", moving, true, poly);
    return out;
}

std::vector<std::unique_ptr<Level>> levels;

void run_level(benchmark::State& st, const std::string& variant, const Level& level, bool full)
{
    Problem& p = *level.problem;
    p.widen(full ? ModelFeatures::full() : level.widen);
    set_threads(1);
    auto v = registry().find(variant).create();
    Driver driver(*v, p.setup());
    for (std::int64_t k = 0; k < kWarmup; ++k) driver.step();
    const PhaseTimes before = driver.times();
    double contacts = 0.0;
    for (auto _ : st) {
        driver.step();
        contacts += v->counts().per_particle(p.size());
    }
    const std::int64_t steps = st.iterations();
    const PhaseTimes t = (driver.times() - before).per_step(steps);
    st.counters["predict_s"] = t.predict;
    st.counters["search_s"] = t.search;
    st.counters["forces_s"] = t.forces;
    st.counters["correct_s"] = t.correct;
    st.counters["total_s"] = t.total();
    st.counters["us_per_particle_step"] = t.total() / double(p.size()) * 1e6;
    st.counters["contacts_per_particle"] = contacts / double(steps);  // mean over the timed steps
    const json label = {{"family", "features"},
                        {"variant", variant},
                        {"level", level.index},
                        {"level_name", level.name},
                        {"kernel", full ? "full" : "specialised"},
                        {"model", v->model().name()},
                        {"scene_needs", features_of(p.scene(), p.state()).name()},
                        {"particles", p.size()},
                        {"steps", st.iterations()}};
    st.SetLabel(label.dump());
}

// One of the program's own options (take_own_options); false for any other argument.
bool own_option(std::string_view key, const char* v)
{
    auto count = [&](const char* v) {
        char* end = nullptr;
        const long long x = std::strtoll(v, &end, 10);
        if (end == v || *end != '\0' || x <= 0) throw Error(fmt::format("{} needs a positive integer, not '{}'", key, v));
        return std::int64_t(x);
    };
    if (key == "--n") {
        opt.n = count(v);
    } else if (key == "--steps") {
        opt.steps = count(v);
    } else if (key == "--states-dir") {
        opt.states_dir = v;
    } else if (key == "--variants") {
        opt.variants.clear();
        for (const std::string& name : split_list(v)) opt.variants.push_back(registry().find(name).name);  // throws naming the known variants
        if (opt.variants.empty()) throw Error("--variants names no variant");
    } else {
        return false;
    }
    return true;
}

} // namespace

int main(int argc, char** argv)
{
    if (!take_own_options(argc, argv, "bench_features", own_option)) return 2;
    const std::string json_out = benchmark_json_out(argc, argv);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
    try {
        const Scene bed = mono_bed(opt.n);
        const State settled = settled_bed(bed);
        levels = make_levels(bed, settled);
    } catch (const Error& e) {
        std::cerr << "bench_features: " << e.what() << "\n";
        return 1;
    }
    for (const auto& variant : opt.variants)
        for (const auto& level : levels)
            for (bool full : {false, true})
                benchmark::RegisterBenchmark(
                    fmt::format("features/{}/{}_{}/{}/{}", variant, level->index, level->name, full ? "full" : "specialised", opt.n)
                        .c_str(),
                    [variant, l = level.get(), full](benchmark::State& st) { run_level(st, variant, *l, full); })
                    ->Unit(benchmark::kMillisecond)
                    ->Iterations(opt.steps);
    benchmark::AddCustomContext("demmat_settle_time_s", fmt::format("{}", kSettleTime));
    benchmark::AddCustomContext("demmat_warmup_steps", fmt::format("{}", kWarmup));
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    try {
        add_provenance(json_out);
    } catch (const Error& e) {
        std::cerr << "bench_features: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
