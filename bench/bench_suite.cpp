// The suite's Google Benchmark program: every family of measurement behind the figures (docs/benchmarks.md).
//
//   phases/...    registry × N × state (loose grid, settled bed, compression stage) [× threads]:
//                 per-phase seconds per step, µs per particle-step, contacts and candidates per particle,
//                 cost per contact and per candidate pair, memory per particle (Figure 7, scaling)
//   figure4/...   the paper's literal scene (2 m box) against N for cells of 2·Rmax, 4·Rmax and all pairs
//   cellsize/...  the settled bed against the cell edge (2 … 6·Rmax) at several N
//   stream/...    STREAM-like copy, scale, add and triad over arrays far larger than the caches: the
//                 memory bandwidth that bounds the integrator phases ("where the time goes")
//
// Each benchmark's label is a JSON object (family, variant, state, particles, cell size, threads) that
// analysis/ reads as data; nothing is parsed out of names. Phases are timed by the suite's driver, the
// clock owner, not by PauseTiming. Run with --benchmark_enable_random_interleaving=true and
// --benchmark_repetitions=R so that machine drift hits every variant alike (scripts/run_figures.sh).
//
// Own options (before Google Benchmark's): --sweep=short|full, --states-dir=DIR (settled beds are cached
// there, default "states"), --families=phases,figure4,cellsize,stream.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "benchmark_common.hpp"
#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/output.hpp"
#include "demmat/problem.hpp"
#include "demmat/registry.hpp"
#include "demmat/text.hpp"
#include "demmat/scenes.hpp"
#include "demmat/state.hpp"
#include "demmat/threads.hpp"

using namespace demmat;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

struct Options {
    bool full = false;
    fs::path states_dir = "states";
    std::set<std::string> families = {"phases", "figure4", "cellsize", "stream"};
};
Options opt;
std::set<std::int64_t> beds_to_settle;  // settled before the first benchmark runs, with progress

// The settled bed: the dense bed of N grains after this much simulated time under gravity (as the main
// job settles its bed with `demmat run --time 0.4 --save`).
constexpr double settle_time = 0.4;

// ---- prepared states (built once per process, settled beds cached on disk) ------------------------

enum class Start { loose, settled, compression };
const char* start_name(Start s) { return s == Start::loose ? "loose" : s == Start::settled ? "settled" : "compression"; }

// The variant that settles beds: the fastest bit-identical one built in, at all threads (any variant
// gives the same state bit for bit; the tests check that).
std::string settling_variant()
{
    for (const char* v : {"fast", "arrays"})
        for (const auto& info : registry().all())
            if (info.name == v) return v;
    return registry().all().front().name;
}

// Named apart from the main job's states/dense_bed_N_settled.state: that one belongs to a scene file the
// user may edit, this one to dense_bed_scene(N) as built in code.
fs::path settled_file(std::int64_t n) { return opt.states_dir / fmt::format("bench_dense_bed_{}_settled.state", n); }

// Loads the cached settled bed of N grains, or settles it (and caches it) when missing or stale.
void ensure_settled(std::int64_t n)
{
    const Scene bed = dense_bed_scene(n);
    const std::int64_t steps = steps_to_reach(settle_time, bed.dt);
    const std::string name = settling_variant();
    set_threads(max_threads());
    const auto start = std::chrono::steady_clock::now();
    auto last = start;
    settled_state(bed, steps, settled_file(n), registry().find(name).create, [&](std::int64_t k, std::int64_t total) {
        if (k == 1)
            std::cerr << fmt::format("demmat_bench: settling the dense bed of {} grains ({} steps of {}, {} thread(s); cached in {})\n",
                                     n, total, name, max_threads(), settled_file(n).string());
        const auto now = std::chrono::steady_clock::now();
        if (now - last > std::chrono::seconds(15)) {
            last = now;
            const double el = std::chrono::duration<double>(now - start).count();
            std::cerr << fmt::format("demmat_bench:   step {}/{}, about {:.0f} s left\n", k, total, el / double(k) * double(total - k));
        }
    });
}

const Problem& prepared(Start start, std::int64_t n)
{
    static std::map<std::pair<int, std::int64_t>, std::unique_ptr<Problem>> cache;
    auto& p = cache[{int(start), n}];
    if (p) return *p;
    const Scene bed = dense_bed_scene(n);
    switch (start) {
    case Start::loose:
        p = std::make_unique<Problem>(bed);
        break;
    case Start::settled: {
        ensure_settled(n);
        Scene s = bed;
        s.grid.reset();
        s.state_file = settled_file(n);
        p = std::make_unique<Problem>(std::move(s));
        break;
    }
    case Start::compression:
        ensure_settled(n);
        p = std::make_unique<Problem>(compression_scene(bed, settled_file(n)));
        break;
    }
    return *p;
}

// The paper's literal scene (2 m box, N grains on a grid, random speeds) with a given search.
const Problem& paper_case(std::int64_t n, double cell_rmax)
{
    static std::map<std::pair<std::int64_t, double>, std::unique_ptr<Problem>> cache;
    auto& p = cache[{n, cell_rmax}];
    if (p) return *p;
    Scene s = paper_scene(n);
    s.search.method = cell_rmax > 0.0 ? SearchMethod::cells : SearchMethod::all_pairs;
    if (cell_rmax > 0.0) s.search.cell_size = cell_rmax;
    p = std::make_unique<Problem>(std::move(s));
    return *p;
}

// ---- timing a variant ------------------------------------------------------------------------------

// Times steps of `variant` from `setup`: one benchmark iteration is one step, its phases timed by the
// driver. Counters are per step (seconds) or per particle.
void time_steps(benchmark::State& st, const std::string& name, const Setup& setup, int threads)
{
    set_threads(threads);
    auto variant = registry().find(name).create();
    Driver driver(*variant, setup);
    for (int k = 0; k < 3; ++k) driver.step();  // first touches, first list builds
    const PhaseTimes before = driver.times();
    std::int64_t pp = 0, pw = 0, cand = 0;
    for (auto _ : st) {
        driver.step();
        const ContactCounts c = variant->counts();
        pp += c.particle_particle;
        pw += c.particle_wall;
        cand += c.candidates;
    }
    const std::int64_t steps = st.iterations();
    const double n = double(setup.state->size());
    const PhaseTimes t = (driver.times() - before).per_step(steps);
    const double predict = t.predict, search = t.search, forces = t.forces, correct = t.correct, total = t.total();
    const double contacts = double(pp + pw) / double(steps), candidates = double(cand) / double(steps);
    st.counters["predict_s"] = predict;
    st.counters["search_s"] = search;
    st.counters["forces_s"] = forces;
    st.counters["correct_s"] = correct;
    st.counters["search_plus_forces_s"] = search + forces;
    st.counters["total_s"] = total;
    st.counters["us_per_particle_step"] = total / n * 1e6;
    st.counters["contacts_per_particle"] = ContactCounts{pp, pw, 0}.per_particle(setup.state->size()) / double(steps);
    st.counters["candidates_per_particle"] = candidates / n;
    st.counters["forces_ns_per_contact"] = contacts > 0 ? forces / contacts * 1e9 : 0.0;
    st.counters["forces_ns_per_candidate"] = candidates > 0 ? forces / candidates * 1e9 : 0.0;
    st.counters["search_ns_per_candidate"] = candidates > 0 ? search / candidates * 1e9 : 0.0;
    st.counters["memory_bytes_per_particle"] = double(variant->memory_bytes()) / n;
    st.counters["steps"] = double(steps);
    set_threads(max_threads());
}

std::string label(json j) { return j.dump(); }

// ---- families ----------------------------------------------------------------------------------------

// Thread counts to time a variant at: 1, and all cores too for variants that use threads.
std::vector<int> thread_counts(const VariantInfo& v)
{
    std::vector<int> t{1};
    if (v.threaded && max_threads() > 1) t.push_back(max_threads());
    return t;
}

void register_phases()
{
    // Short: what the main command can afford; full: up to 10⁵ settled, 10⁶ on the loose grid.
    const std::vector<std::int64_t> sizes = opt.full ? std::vector<std::int64_t>{1000, 8000, 27000, 100000, 1000000}
                                                     : std::vector<std::int64_t>{1000, 8000};
    for (std::int64_t n : sizes)
        for (Start s : {Start::loose, Start::settled, Start::compression}) {
            // 10⁶ grains: loose grid only (settling a million grains takes hours on 2 cores).
            if (n > 100000 && s != Start::loose) continue;
            if (s != Start::loose) beds_to_settle.insert(n);
            for (const auto& v : registry().all()) {
                // The O(N²)-memory or slow reference styles stop where they would take minutes per step.
                if (n > 100000 && !v.threaded && v.name != "arrays") continue;
                for (int t : thread_counts(v)) {
                    const std::string nm = fmt::format("phases/{}/{}/{}/threads:{}", start_name(s), v.name, n, t);
                    const json lab = {{"family", "phases"}, {"variant", v.name}, {"state", start_name(s)}, {"particles", n},
                                      {"threads", t}, {"bitwise", v.bitwise}};
                    benchmark::RegisterBenchmark(nm.c_str(), [name = v.name, s, n, t, lab](benchmark::State& st) {
                        st.SetLabel(label(lab));
                        time_steps(st, name, prepared(s, n).setup(), t);
                    })->Unit(benchmark::kMillisecond)->MinTime(n >= 100000 ? 2.0 : 0.5)->UseRealTime();
                }
            }
        }
}

void register_figure4()
{
    const std::vector<std::int64_t> sizes = opt.full
        ? std::vector<std::int64_t>{100, 200, 500, 1000, 2000, 5000, 10000, 20000, 50000}
        : std::vector<std::int64_t>{100, 200, 500, 1000, 2000, 5000};
    for (std::int64_t n : sizes)
        for (double cell : {2.0, 4.0, 0.0}) {
            if (cell == 0.0 && n > 20000) continue;  // all pairs: O(N²), seconds per step beyond this
            const char* search = cell == 2.0 ? "cells_2rmax" : cell == 4.0 ? "cells_4rmax" : "all_pairs";
            const std::string nm = fmt::format("figure4/{}/{}", search, n);
            const json lab = {{"family", "figure4"}, {"variant", "arrays"}, {"state", "paper"}, {"particles", n},
                              {"search", search}, {"cell_size_rmax", cell}, {"threads", 1}};
            benchmark::RegisterBenchmark(nm.c_str(), [n, cell, lab](benchmark::State& st) {
                st.SetLabel(label(lab));
                time_steps(st, "arrays", paper_case(n, cell).setup(), 1);
            })->Unit(benchmark::kMillisecond)->MinTime(0.3)->UseRealTime();
        }
}

void register_cellsize()
{
    const std::vector<std::int64_t> sizes = opt.full ? std::vector<std::int64_t>{1000, 8000, 27000} : std::vector<std::int64_t>{8000};
    std::vector<std::string> variants{"arrays"};
    for (const auto& v : registry().all())
        if (v.name == "fast") variants.push_back("fast");
    for (std::int64_t n : sizes) beds_to_settle.insert(n);
    for (std::int64_t n : sizes)
        for (double cell : {2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0})
            for (const auto& name : variants) {
                const std::string nm = fmt::format("cellsize/{}/{}/{:.1f}", name, n, cell);
                const json lab = {{"family", "cellsize"}, {"variant", name}, {"state", "settled"}, {"particles", n},
                                  {"cell_size_rmax", cell}, {"threads", 1}};
                benchmark::RegisterBenchmark(nm.c_str(), [name, n, cell, lab](benchmark::State& st) {
                    st.SetLabel(label(lab));
                    static std::map<std::pair<std::int64_t, double>, std::unique_ptr<Problem>> cache;
                    auto& p = cache[{n, cell}];
                    if (!p) {
                        const Problem& bed = prepared(Start::settled, n);
                        Scene s = bed.scene();
                        s.search.method = SearchMethod::cells;
                        s.search.cell_size = cell;
                        p = std::make_unique<Problem>(std::move(s), bed.state());
                    }
                    time_steps(st, name, p->setup(), 1);
                })->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
            }
}

// STREAM's four kernels (McCalpin) over arrays of 2²⁴ doubles (128 MiB each, far beyond any cache).
// Bytes counted as STREAM counts them: what the kernel reads and writes, without write-allocate.
void register_stream()
{
    static std::vector<double> a, b, c;
    constexpr std::size_t len = std::size_t(1) << 24;
    struct Kernel {
        const char* name;
        int arrays;  // arrays touched per element
    };
    for (Kernel k : {Kernel{"copy", 2}, Kernel{"scale", 2}, Kernel{"add", 3}, Kernel{"triad", 3}})
        for (int t : max_threads() > 1 ? std::vector<int>{1, max_threads()} : std::vector<int>{1}) {
            const std::string nm = fmt::format("stream/{}/threads:{}", k.name, t);
            const json lab = {{"family", "stream"}, {"kernel", k.name}, {"threads", t}, {"bytes_per_element", 8 * k.arrays}};
            benchmark::RegisterBenchmark(nm.c_str(), [k, t, lab](benchmark::State& st) {
                st.SetLabel(label(lab));
                if (a.empty()) {
                    a.assign(len, 1.0);
                    b.assign(len, 2.0);
                    c.assign(len, 0.0);
                }
                set_threads(t);
                double* __restrict pa = a.data();
                double* __restrict pb = b.data();
                double* __restrict pc = c.data();
                const double s = 3.0;
                const auto n = std::int64_t(len);
                for (auto _ : st) {
                    if (std::strcmp(k.name, "copy") == 0) {
#pragma omp parallel for schedule(static)
                        for (std::int64_t i = 0; i < n; ++i) pc[i] = pa[i];
                    } else if (std::strcmp(k.name, "scale") == 0) {
#pragma omp parallel for schedule(static)
                        for (std::int64_t i = 0; i < n; ++i) pb[i] = s * pc[i];
                    } else if (std::strcmp(k.name, "add") == 0) {
#pragma omp parallel for schedule(static)
                        for (std::int64_t i = 0; i < n; ++i) pc[i] = pa[i] + pb[i];
                    } else {
#pragma omp parallel for schedule(static)
                        for (std::int64_t i = 0; i < n; ++i) pa[i] = pb[i] + s * pc[i];
                    }
                    benchmark::ClobberMemory();
                }
                st.SetBytesProcessed(std::int64_t(st.iterations()) * n * 8 * k.arrays);
                st.counters["bandwidth_GBps"] = benchmark::Counter(double(n) * 8.0 * k.arrays * double(st.iterations()) / 1e9,
                                                                   benchmark::Counter::kIsRate);
                set_threads(max_threads());
            })->Unit(benchmark::kMillisecond)->MinTime(0.5)->UseRealTime();
        }
}

// One of the suite's own options (take_own_options); false for any other argument.
bool own_option(std::string_view key, const char* v)
{
    if (key == "--sweep") {
        if (std::strcmp(v, "full") != 0 && std::strcmp(v, "short") != 0)
            throw Error(fmt::format("--sweep must be 'short' or 'full', not '{}'", v));
        opt.full = std::strcmp(v, "full") == 0;
    } else if (key == "--states-dir") {
        opt.states_dir = v;
    } else if (key == "--families") {
        opt.families.clear();
        for (const std::string& family : split_list(v)) {
            if (family != "phases" && family != "figure4" && family != "cellsize" && family != "stream")
                throw Error(fmt::format("unknown family '{}' in --families (known: phases, figure4, cellsize, stream)", family));
            opt.families.insert(family);
        }
        if (opt.families.empty()) throw Error("--families names no family (known: phases, figure4, cellsize, stream)");
    } else {
        return false;
    }
    return true;
}

} // namespace

int main(int argc, char** argv)
{
    if (!take_own_options(argc, argv, "demmat_bench", own_option)) return 2;
    bool filtered = false;
    for (int i = 1; i < argc; ++i) filtered = filtered || std::strncmp(argv[i], "--benchmark_filter=", 19) == 0;
    const std::string json_out = benchmark_json_out(argc, argv);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
    if (opt.families.count("stream")) register_stream();
    if (opt.families.count("figure4")) register_figure4();
    if (opt.families.count("cellsize")) register_cellsize();
    if (opt.families.count("phases")) register_phases();
    benchmark::AddCustomContext("demmat_sweep", opt.full ? "full" : "short");
    benchmark::AddCustomContext("demmat_settle_time_s", fmt::format("{}", settle_time));
    try {
        // Settle up front (with progress) unless a filter is given: then only what a selected benchmark
        // needs is settled, when it first runs (outside the timed loop).
        if (!filtered)
            for (std::int64_t n : beds_to_settle) ensure_settled(n);
        benchmark::RunSpecifiedBenchmarks();
        benchmark::Shutdown();
        add_provenance(json_out);
    } catch (const Error& e) {
        std::cerr << "demmat_bench: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
