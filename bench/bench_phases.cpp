// Google Benchmark over the registry × N: one benchmark per variant and size on the dense bed after
// a short settling, each iteration one step, with per-phase seconds per step, µs per particle-step
// and contacts per particle as counters. Phases are timed by the suite's driver, not by PauseTiming.
#include <map>
#include <memory>

#include <benchmark/benchmark.h>

#include "demmat/driver.hpp"
#include "demmat/output.hpp"
#include "demmat/registry.hpp"
#include "demmat/scenes.hpp"

using namespace demmat;

namespace {

// The bed of N particles after `settle` steps of the arrays variant: a contact-rich state shared by
// every variant (built once per N).
struct Bed {
    Scene scene;
    State state;
    Setup setup;
};

const Bed& bed(std::int64_t n)
{
    static std::map<std::int64_t, std::unique_ptr<Bed>> cache;
    auto& b = cache[n];
    if (!b) {
        b = std::make_unique<Bed>();
        b->scene = dense_bed_scene(n);
        const State grid = initial_state(b->scene);
        const Setup s0 = Setup::make(b->scene, grid);
        auto v = registry().find("arrays").create();
        Driver d(*v, s0);
        d.run(8000);
        v->save(b->state);
        b->state.dt = b->scene.dt;
        b->state.fingerprint = grid.fingerprint;
        b->setup = Setup::make(b->scene, b->state);
    }
    return *b;
}

void run_variant(benchmark::State& st, const std::string& name, std::int64_t n)
{
    const Bed& b = bed(n);
    auto variant = registry().find(name).create();
    Driver driver(*variant, b.setup);
    for (int k = 0; k < 5; ++k) driver.step();  // warm caches and lists
    const PhaseTimes before = driver.times();
    for (auto _ : st) driver.step();
    const PhaseTimes& t = driver.times();
    const double steps = double(st.iterations());
    st.counters["predict_s"] = (t.predict - before.predict) / steps;
    st.counters["search_s"] = (t.search - before.search) / steps;
    st.counters["forces_s"] = (t.forces - before.forces) / steps;
    st.counters["correct_s"] = (t.correct - before.correct) / steps;
    st.counters["search_plus_forces_s"] = (t.search - before.search + t.forces - before.forces) / steps;
    st.counters["us_per_particle_step"] = (t.total() - before.total()) / steps / double(n) * 1e6;
    const ContactCounts c = variant->counts();
    st.counters["contacts_per_particle"] = (2.0 * double(c.particle_particle) + double(c.particle_wall)) / double(n);
    st.counters["particles"] = double(n);
}

} // namespace

int main(int argc, char** argv)
{
    benchmark::Initialize(&argc, argv);
    // Sizes outermost, variants inner: with --benchmark_repetitions the variants of one size run
    // one after another, so drift of a shared machine hits them alike.
    for (std::int64_t n : {1000, 8000, 27000})
        for (const auto& v : registry().all())
            benchmark::RegisterBenchmark(("step/" + v.name + "/" + std::to_string(n)).c_str(),
                                         [name = v.name, n](benchmark::State& st) { run_variant(st, name, n); })
                ->Unit(benchmark::kMillisecond)
                ->MinTime(0.5);
    const auto p = provenance_json();
    for (const char* k : {"commit", "compiler", "flags", "cpu"}) benchmark::AddCustomContext(k, p[k].dump());
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
