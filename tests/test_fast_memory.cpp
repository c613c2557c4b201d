// The fast variant under the contact laws of physics.md §9 against arrays: bit-identical at every step,
// and in the saved state (every live contact's stretches, in canonical order), at 1, 2 and 3 threads,
// with no skin (the list rebuilt and the particles re-sorted every step, so each step carries every
// stretch to new slots by pair) and with wide ones, on phases run by teams of changing sizes, and across
// save-and-continue (in both directions between fast and arrays). The stretches must matter for these
// to fail: the beds are contact-rich, the laws' stretches grow over hundreds of steps, and a control
// shows that a continuation without them differs. A small slice runs in the default suite; the full
// matrix (every law, the settling bed and the compression stage, 2000 grains, cells of 2 and 4·R_max
// and all pairs) is FastMemoryLong.
#include <cstdlib>
#include <filesystem>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "demmat/contact_model.hpp"
#include "demmat/features.hpp"
#include "demmat/state_file.hpp"
#include "fast_support.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

struct Law {
    const char* name;
    ContactModel model;
    bool memory;  // carries stretches
};

// The laws under test: each spring alone and together (also with the trapezoidal update), and both
// restitution-set dampings.
std::vector<Law> laws()
{
    ContactModel linear;
    linear.tangential = TangentialModel::linear_history;
    linear.kt = 50.0;
    linear.tangential_damping_ratio = 0.5;
    ContactModel mindlin;
    mindlin.tangential = TangentialModel::mindlin;
    mindlin.tangential_damping_ratio = 0.5;
    ContactModel rolling = mindlin;
    rolling.rolling = RollingModel::sds;
    rolling.kr = 50.0;
    rolling.rolling_damping = 0.05;
    rolling.rolling_friction = 0.2;
    ContactModel trapezoidal = rolling;  // the trapezoidal stretch update (physics.md §9) on both springs
    trapezoidal.stretch_update = StretchUpdate::trapezoidal;
    ContactModel tsuji;
    tsuji.damping = NormalDamping::tsuji;
    tsuji.restitution = 0.6;
    ContactModel restitution = linear;
    restitution.damping = NormalDamping::restitution;
    restitution.restitution = 0.3;
    return {{"linear_history", linear, true},
            {"mindlin", mindlin, true},
            {"mindlin_sds", rolling, true},
            {"mindlin_sds_trapezoidal", trapezoidal, true},
            {"tsuji", tsuji, false},
            {"restitution_linear_history", restitution, true}};
}

const Law& law_named(const std::string& name)
{
    static const std::vector<Law> all = laws();
    for (const Law& l : all)
        if (name == l.name) return l;
    throw Error("no law " + name);
}

// A polydisperse bed of 500 in its closed box, settled by fast under the paper's law (12000 steps,
// cached); with `wall_speed` > 0 the compression stage. The law is then switched on: every contact of
// the settled bed starts its stretches from zero at the first step.
std::unique_ptr<Problem> small_bed(const ContactModel& law, double wall_speed)
{
    const Scene bed = dense_bed_scene(500);
    State st = settled_state(bed, 12000, "fast_bed_500_12000.state", [] { return make_fast_variant(FastOptions{}); });
    Scene s = wall_speed > 0 ? compression_scene(bed, "(cached state)", wall_speed) : bed;
    s.contact_model = law;
    st.walls = continue_walls(s, st);
    return std::make_unique<Problem>(s, st);
}

// The 2000-grain bed of the other equivalence tests (support.hpp), under a law.
std::unique_ptr<Problem> large_bed(const ContactModel& law, double wall_speed, SearchMethod method, double cell)
{
    const Problem base = bed_case(wall_speed);
    Scene s = base.scene();
    s.contact_model = law;
    s.search.method = method;
    s.search.cell_size = cell;
    return std::make_unique<Problem>(s, base.state());
}

FastOptions skin(double s)
{
    FastOptions o;
    o.skin = s;
    return o;
}

// The runs of every lockstep: no skin on 3 threads (a rebuild and re-sort every step), a skin of R_max
// on 2, the default on 1.
const std::vector<FastRun> kRuns = {{skin(0.0), 3}, {skin(1.0), 2}, {skin(0.3), 1}};

void expect_lockstep(const Problem& p, const Law& law, std::int64_t steps, std::size_t min_stretched)
{
    const LockstepResult r = lockstep(p.setup(), steps, kRuns);
    EXPECT_EQ(r.difference, "") << law.name;
    EXPECT_EQ(r.saved_difference, "") << law.name;
    ASSERT_EQ(r.rebuilds.size(), kRuns.size());
    EXPECT_EQ(r.rebuilds[0], steps + 1) << "no skin: every step must rebuild";
    if (law.memory) {
        EXPECT_GT(r.stretched, min_stretched) << law.name << ": too few live stretches for the test to mean much";
    }
}

std::filesystem::path save_to(const State& st, const std::string& name)
{
    const std::filesystem::path file = name;
    save_state(st, file);
    return file;
}

// A scene that continues from `file` (the same scene otherwise, so the same fingerprint).
std::unique_ptr<Problem> continued(const Scene& s, const std::filesystem::path& file)
{
    Scene c = s;
    c.grid.reset();
    c.state_file = file;
    return std::make_unique<Problem>(c);
}

} // namespace

TEST(FastMemory, OffersEveryLawInTheCanonicalOrderOnly)
{
    for (const Law& law : laws()) {
        EXPECT_TRUE(registry().find("fast").create()->supports(law.model)) << law.name;
        EXPECT_FALSE(registry().find("fast_unordered").create()->supports(law.model)) << law.name;
    }
    const auto p = small_bed(law_named("mindlin_sds").model, 0.0);
    VariantRun run("fast", p->setup());
    const ModelFeatures m = run.variant->model();
    EXPECT_TRUE(m.history && m.rolling && !m.restitution_damping) << m.name();
    EXPECT_TRUE(m.covers(features_of(p->scene(), p->state())));
}

TEST(FastMemory, EveryLawIsBitIdenticalToArraysAtOneTwoAndThreeThreadsOnTheCompressionStage)
{
    // The wall moving in: grains re-sorted (every step without a skin), wall contacts made and broken.
    for (const Law& law : laws()) {
        const auto p = small_bed(law.model, 0.5);
        expect_lockstep(*p, law, 300, 300);
    }
}

TEST(FastMemory, PhasesOnTeamsOfChangingSizesGiveArraysBits)
{
    // The wall candidates (and their stretches) listed by predict() and the rebuild on other teams than
    // the force pass that reads them, as OpenMP's dynamic teams may do.
    const auto p = small_bed(law_named("mindlin_sds").model, 0.5);
    FastOptions o = skin(0.1);
    o.min_parallel = 0;
    o.prefetch_from = 0;
    o.stream_records_from = 0;
    auto fast = make_fast_variant(o);
    fast->init(p->setup());
    VariantRun ref("arrays", p->setup());
    Snapshot a, b;
    std::string difference;
    step_with_teams(*fast, p->state().step, 300, {{{3, 1, 2}, {1, 3}, {2, 3, 1, 1}}}, [&](std::int64_t k) {
        ref.driver->step();
        ref.variant->snapshot(a);
        fast->snapshot(b);
        if (difference.empty())
            if (const auto d = first_difference(a, b)) difference = fmt::format("step {}: {}", k, d->describe());
    });
    EXPECT_EQ(difference, "");
    State sa, sb;
    ref.variant->save(sa);
    fast->save(sb);
    EXPECT_EQ(state_difference(sa, sb), "");
    EXPECT_GT(fast->rebuilds(), 5);
    EXPECT_GT(ref.variant->counts().particle_wall, 0);
}

#ifdef _OPENMP
TEST(FastMemory, DynamicTeamsGiveArraysBits)
{
    const auto p = small_bed(law_named("mindlin").model, 0.5);
    omp_set_dynamic(1);
    const LockstepResult r = lockstep(p->setup(), 200, {{skin(0.0), 3}, {skin(0.3), 2}});
    omp_set_dynamic(0);
    EXPECT_EQ(r.difference, "");
    EXPECT_EQ(r.saved_difference, "");
}
#endif

TEST(FastMemory, SaveAndContinueIsBitIdenticalAndTheStretchesMatter)
{
    // fast straight for 2K steps against fast for K, saved, and continued for K from the file (on
    // other threads and skin); arrays continued from fast's file and fast from arrays' give the same
    // bits, so the saved stretches are the same contacts in the same order. Control: the continuation
    // from the file with its stretches removed differs, so the stretches carried something.
    const Law& law = law_named("mindlin_sds");
    const auto p = small_bed(law.model, 0.0);
    const std::int64_t k = 300;
    set_threads(2);
    FastOptions threaded;
    threaded.min_parallel = 0;
    VariantRun straight(make_fast_variant(threaded), p->setup());
    straight.driver->run(2 * k);
    VariantRun first(make_fast_variant(threaded), p->setup()), first_arrays("arrays", p->setup());
    first.driver->run(k);
    first_arrays.driver->run(k);
    State saved = saved_state(first, *p);
    saved.fingerprint = p->scene().fingerprint(p->size());  // the scene with its law (the bed was settled without)
    EXPECT_EQ(state_difference(saved, saved_state(first_arrays, *p)), "");
    ASSERT_TRUE(first_difference(first.snapshot(), first_arrays.snapshot()) == std::nullopt);
    EXPECT_GT(saved.stretches.size(), 500u);
    const auto from_fast = continued(p->scene(), save_to(saved, "fast_memory_continue.state"));
    ASSERT_EQ(from_fast->state().stretches.size(), saved.stretches.size());
    set_threads(3);
    FastOptions other = threaded;
    other.skin = 0.0;
    VariantRun second(make_fast_variant(other), from_fast->setup()), second_arrays("arrays", from_fast->setup());
    second.driver->run(k);
    second_arrays.driver->run(k);
    EXPECT_FALSE(first_difference(straight.snapshot(), second.snapshot()));
    EXPECT_FALSE(first_difference(straight.snapshot(), second_arrays.snapshot()));
    // Saved right after init, before any step: the state it started from, stretches included.
    VariantRun fresh(make_fast_variant(threaded), from_fast->setup());
    EXPECT_EQ(state_difference(saved_state(fresh, *from_fast), saved), "");

    State forgotten = saved;
    forgotten.stretches.clear();
    const auto without = continued(p->scene(), save_to(forgotten, "fast_memory_forgotten.state"));
    VariantRun control(make_fast_variant(threaded), without->setup());
    control.driver->run(k);
    EXPECT_TRUE(first_difference(straight.snapshot(), control.snapshot())) << "the stretches changed nothing";
    set_threads(0);
    std::filesystem::remove("fast_memory_continue.state");
    std::filesystem::remove("fast_memory_forgotten.state");
}

// ---- the full matrix (ctest label long) ----------------------------------------------------------------

struct MatrixCase {
    std::string law;
    double wall_speed;  // 0: the settling bed; 0.5: the compression stage
    SearchMethod method;
    double cell;  // in units of R_max
};

class FastMemoryLong : public ::testing::TestWithParam<MatrixCase> {};

TEST_P(FastMemoryLong, BitIdenticalToArraysAtEveryStep)
{
    const MatrixCase& c = GetParam();
    const Law& law = law_named(c.law);
    const auto p = large_bed(law.model, c.wall_speed, c.method, c.cell);
    expect_lockstep(*p, law, long_run(2000), 2000);
}

std::vector<MatrixCase> matrix()
{
    std::vector<MatrixCase> out;
    for (const Law& law : laws())
        for (double speed : {0.0, 0.5}) {
            out.push_back({law.name, speed, SearchMethod::cells, 2.0});
            if (law.memory && speed > 0.0) {  // the search's cells and all pairs: the arrays side's candidates
                out.push_back({law.name, speed, SearchMethod::cells, 4.0});
                out.push_back({law.name, speed, SearchMethod::all_pairs, 2.0});
            }
        }
    return out;
}

INSTANTIATE_TEST_SUITE_P(Laws, FastMemoryLong, ::testing::ValuesIn(matrix()), [](const auto& info) {
    const MatrixCase& c = info.param;
    return param_name(fmt::format("{}_{}_{}{}", c.law, c.wall_speed > 0 ? "compression" : "settling",
                                  c.method == SearchMethod::all_pairs ? "all_pairs" : "cells", c.method == SearchMethod::all_pairs ? 0 : int(c.cell)));
});
