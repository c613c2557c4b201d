// The fast variant against arrays at given thread counts and list skins: bit-identical at every step on
// the dense settling bed (2000 particles, 5000 steps) and on the compression stage (where the list is
// rebuilt dozens of times, or every step with no skin), at 1, 2 and 3 threads; and fast_unordered,
// which drops the canonical order, within a bound that only a change of summation order explains
// (measured: the spread of fast_unordered itself over thread counts).
#include <array>
#include <cmath>
#include <cstring>
#include <iostream>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <fmt/format.h>

#include <gtest/gtest.h>

#include "demmat/state_file.hpp"
#include "demmat/threads.hpp"
#include "fast.hpp"
#include "fast_support.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

// fast_unordered's options, on the threads asked for and on the prefetching and streaming paths however small the scene.
FastOptions threaded_unordered()
{
    FastOptions o;
    o.canonical = false;
    o.min_parallel = 0;
    o.prefetch_from = 0;
    o.stream_records_from = 0;
    return o;
}

// Largest |a − b| over particles and components, relative to the largest |a|.
double relative_gap(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b)
{
    double gap = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            gap = std::max(gap, std::abs(component(a[i], c) - component(b[i], c)));
            scale = std::max(scale, std::abs(component(a[i], c)));
        }
    return gap / scale;
}

} // namespace

TEST(Fast, DenseBedIsBitIdenticalToArraysAtOneAndTwoThreads)
{
    Problem c = bed_case(0.0);
    ASSERT_GE(c.state().size(), 2000u);
    const auto r = lockstep(c.setup(), long_run(5000), {{FastOptions{}, 1}, {FastOptions{}, 2}});
    EXPECT_EQ(r.difference, "");
    EXPECT_GT(r.contacts, 3000);  // contact-rich: > 3 contacts per particle
}

TEST(Fast, CompressionStageIsBitIdenticalToArraysWhileTheListIsRebuilt)
{
    // Grains still falling and the wall moving in: with a skin of 0.1·R_max (0.5 mm) the list is
    // rebuilt, and the particles re-sorted, every ten to twenty steps.
    Problem c = bed_case(0.5);
    FastOptions thin;
    thin.skin = 0.1;
    const auto r = lockstep(c.setup(), long_run(3000), {{thin, 1}, {thin, 2}});
    EXPECT_EQ(r.difference, "");
    ASSERT_EQ(r.rebuilds.size(), 2u);
    EXPECT_GE(r.rebuilds[0], 20) << "the displacement check never asked for a rebuild";
    EXPECT_EQ(r.rebuilds[0], r.rebuilds[1]) << "the rebuild decision depends on the thread count";
}

TEST(Fast, AnySkinAndThreadCountGiveTheSameTrajectory)
{
    // No skin (a rebuild every step), a wide skin (rare rebuilds, 3x the candidates), and an odd thread
    // count that splits the particles unevenly.
    Problem c = bed_case(0.5);
    const std::int64_t steps = 600;
    FastOptions none;
    none.skin = 0.0;
    FastOptions wide;
    wide.skin = 1.0;
    const auto r = lockstep(c.setup(), steps, {{none, 3}, {wide, 2}, {wide, 1}});
    EXPECT_EQ(r.difference, "");
    ASSERT_EQ(r.rebuilds.size(), 3u);
    EXPECT_EQ(r.rebuilds[0], steps + 1) << "no skin: every step must rebuild";
    EXPECT_LT(r.rebuilds[1], steps / 20);
}

TEST(Fast, MoreWallsThanTheNearWallBitsGiveTheSameTrajectory)
{
    // fast marks the walls a grain may touch a bit per wall up to 8 walls and tests each wall again
    // beyond. Four walls that touch nothing (the side walls moved 5 cm out) put in front of the box's
    // six make ten, with the floor (z_min, the most contacts) at index 8, past the bits.
    Problem c = bed_case(0.5);
    Scene s = c.scene();
    State st = c.state();
    std::vector<Wall> far;
    for (const Wall& w : st.walls) {
        if (w.name == "z_min" || w.name == "z_max") continue;
        Wall out = w;
        out.name = w.name + "_far";
        out.point = w.point - 0.05 * w.normal;
        far.push_back(out);
    }
    ASSERT_EQ(far.size(), 4u);
    st.walls.insert(st.walls.begin(), far.begin(), far.end());
    s.walls.insert(s.walls.begin(), far.begin(), far.end());
    ASSERT_EQ(st.walls[8].name, "z_min");
    Problem many(s, st);
    const auto r = lockstep(many.setup(), 300, {{FastOptions{}, 1}, {FastOptions{}, 2}});
    EXPECT_EQ(r.difference, "");
}

TEST(Fast, UnorderedDiffersFromArraysOnlyByTheSummationOrder)
{
    // One step from the settled bed: the contact set is the same, only each particle's sum is taken in
    // another order. A sum of k terms reordered moves by at most about k·ε·Σ|terms| (ε = 1.1e-16, k ≤ 16
    // here); 1e-11 of the largest force leaves a margin of 10³ over that, and is far below any
    // physical difference: one contact missed or added changes a force by that contact's own size.
    Problem c = bed_case(0.5);
    set_threads(2);
    VariantRun ref("arrays", c.setup()), unordered(make_fast_variant(threaded_unordered()), c.setup());
    ref.driver->step();
    unordered.driver->step();
    const Snapshot a = ref.snapshot(), b = unordered.snapshot();
    EXPECT_EQ(ref.variant->counts().particle_particle, unordered.variant->counts().particle_particle);
    EXPECT_EQ(ref.variant->counts().particle_wall, unordered.variant->counts().particle_wall);
    EXPECT_LT(relative_gap(a.force, b.force), 1e-11);
    EXPECT_LT(relative_gap(a.torque, b.torque), 1e-11);
    const auto d = first_difference(a, b);
    ASSERT_TRUE(d) << "plain accumulation happened to give the canonical bits everywhere";
    std::cout << "fast_unordered against arrays, first difference: " << d->describe() << "\n";

    // Over the next steps the bed amplifies those last bits. How far a difference of summation order
    // alone carries the bed over this horizon is measured, not assumed: fast_unordered on 1 and 3
    // threads sums in other orders again (the loads of other threads), so the largest gap between
    // those two runs at any step is what order alone gives here. The gap to arrays is a difference of the
    // same kind and must stay within a margin of that (10x: such gaps scatter within a few times each
    // other while they grow alike); a contact dropped or computed twice is no rounding, it changes a
    // force by the contact's own size and leaves that bound within a few steps. (A one-ulp nudge of
    // the start is no yardstick: larger than these differences, it moves contacts' first steps, whose
    // damping force jumps, and grows orders of magnitude faster.)
    const std::int64_t steps = 999;
    std::vector<std::unique_ptr<VariantRun>> others;
    for (int threads : {1, 3}) {
        set_threads(threads);
        others.push_back(std::make_unique<VariantRun>(make_fast_variant(threaded_unordered()), c.setup()));
        others.back()->driver->step();
    }
    auto largest_gap = [](const Snapshot& x, const Snapshot& y) {
        double worst = 0.0;
        for (std::size_t i = 0; i < x.position.size(); ++i) {
            const Vec3d g = x.position[i] - y.position[i];
            worst = std::max(worst, std::sqrt(dot(g, g)));
        }
        return worst;
    };
    double order = 0.0, worst = 0.0;
    for (std::int64_t k = 0; k < steps; ++k) {
        ref.driver->step();
        set_threads(2);
        unordered.driver->step();
        set_threads(1);
        others[0]->driver->step();
        set_threads(3);
        others[1]->driver->step();
        const Snapshot u = unordered.snapshot(), u1 = others[0]->snapshot(), u3 = others[1]->snapshot();
        // The yardstick from the two runs not under test, so that a fault of the 2-thread run alone
        // cannot widen it.
        order = std::max(order, largest_gap(u1, u3));
        worst = std::max(worst, largest_gap(ref.snapshot(), u));
    }
    std::cout << "over " << steps + 1 << " steps: order alone (fast_unordered on 1 and 3 threads) " << order
              << " m; fast_unordered against arrays " << worst << " m\n";
    EXPECT_GT(order, 0.0) << "the two orders gave the same bits: no yardstick";
    EXPECT_LT(worst, 10.0 * order);
    set_threads(0);
}

TEST(Fast, UnorderedIsDeterministicForAFixedThreadCount)
{
    // Not promised across thread counts, but a fixed partition sums in a fixed order: two runs agree.
    Problem c = bed_case(0.5);
    set_threads(2);
    VariantRun one(make_fast_variant(threaded_unordered()), c.setup()), two(make_fast_variant(threaded_unordered()), c.setup());
    for (int k = 0; k < 300; ++k) {
        one.driver->step();
        two.driver->step();
        const auto d = first_difference(one.snapshot(), two.snapshot());
        ASSERT_FALSE(d) << "step " << k + 1 << ": " << d->describe();
    }
    set_threads(0);
}

TEST(Fast, PhasesOnTeamsOfDifferentSizesGiveTheSameTrajectory)
{
    // The wall candidates are listed per thread by predict() (or a rebuild), the force pass reads them:
    // with OpenMP's dynamic teams (omp_set_dynamic, OMP_DYNAMIC=true) the two may run on teams of
    // different sizes, which must change no bit. Every phase here on its own cycle of 1, 2 and 3 threads,
    // through the compression stage (rebuilds, wall contacts), against arrays at every step.
    Problem c = bed_case(0.5);
    FastOptions o;
    o.min_parallel = 0;
    o.prefetch_from = 0;
    o.stream_records_from = 0;
    auto fast = make_fast_variant(o);
    fast->init(c.setup());
    VariantRun ref("arrays", c.setup());
    Snapshot a, b;
    std::string difference;
    step_with_teams(*fast, c.state().step, 400, {{{3, 1, 2}, {1, 3}, {2, 3, 1, 1}}}, [&](std::int64_t k) {
        ref.driver->step();
        ref.variant->snapshot(a);
        fast->snapshot(b);
        if (difference.empty())
            if (const auto d = first_difference(a, b)) difference = fmt::format("step {}: {}", k, d->describe());
    });
    EXPECT_EQ(difference, "");
    EXPECT_GT(ref.variant->counts().particle_wall, 0);
    EXPECT_GT(fast->rebuilds(), 5);
}

TEST(Fast, UnorderedForcesDoNotDependOnTheTeamsOfTheOtherPhases)
{
    // fast_unordered's bits depend on the force pass's team, not on those of predict() and the rebuild.
    Problem c = bed_case(0.5);
    auto fixed = make_fast_variant(threaded_unordered()), varied = make_fast_variant(threaded_unordered());
    fixed->init(c.setup());
    varied->init(c.setup());
    step_with_teams(*fixed, c.state().step, 300, {{{2}, {2}, {2}}}, [](std::int64_t) {});
    step_with_teams(*varied, c.state().step, 300, {{{3, 1}, {1, 3, 2}, {2}}}, [](std::int64_t) {});
    Snapshot a, b;
    fixed->snapshot(a);
    varied->snapshot(b);
    const auto d = first_difference(a, b);
    EXPECT_FALSE(d) << d->describe();
}

#ifdef _OPENMP
TEST(Fast, DynamicTeamsGiveTheSameTrajectory)
{
    // OpenMP's own dynamic teams (their sizes follow the machine's load): bit-identical to arrays.
    Problem c = bed_case(0.5);
    omp_set_dynamic(1);
    const auto r = lockstep(c.setup(), 300, {{FastOptions{}, 3}, {FastOptions{}, 2}});
    omp_set_dynamic(0);
    EXPECT_EQ(r.difference, "");
}
#endif

TEST(Fast, ReportsTheThreadsItRunsOn)
{
    // Below min_parallel one thread whatever is asked; above, the force pass's team.
    Problem c = bed_case(0.5);
    ASSERT_LT(c.state().size(), FastOptions{}.min_parallel);
    set_threads(2);
    VariantRun small(make_fast_variant(FastOptions{}), c.setup());
    FastOptions threaded;
    threaded.min_parallel = 0;
    VariantRun big(make_fast_variant(threaded), c.setup());
    small.driver->step();
    big.driver->step();
    EXPECT_EQ(small.variant->threads_used(), 1);
#ifdef _OPENMP
    EXPECT_EQ(big.variant->threads_used(), 2);
#endif
    set_threads(0);
    EXPECT_EQ(VariantRun("arrays", c.setup()).variant->threads_used(), 1);
}

// ---- the models fast specialises to (fast_models.hpp) ------------------------------------------------

namespace {

// A monodisperse bed of 500 settled by fast itself (bit-identical to arrays), for the feature levels.
State settled_mono_bed(const Scene& bed)
{
    return settled_state(bed, 12000, "fast_mono_bed_500_12000.state", [] { return make_fast_variant(FastOptions{}); });
}

} // namespace

TEST(Fast, EachLevelOfTheFeatureChainMatchesTheFullModelWhereItsFeaturesAreInert)
{
    // The levels of the cost-per-feature table (bench/bench_features.cpp), each a scene that needs one
    // feature more than the one before: fast runs the level's model (model() names it) and is
    // bit-identical at every step, and in the saved Gear state, to the full model (Setup::widen) on the
    // same scene, where the features the level skips compute zeros.
    Scene bed = dense_bed_scene(500);
    bed.grid->radius_min = bed.grid->radius_max;
    const State settled = settled_mono_bed(bed);
    struct Level {
        const char* model;
        double mu, gamma_n;
        bool spin, walls, moving;
    };
    const Level levels[] = {{"normal", 0.0, 0.0, false, false, false},
                            {"damping", 0.0, 60.0, false, false, false},
                            {"rotation+friction+damping", 0.6, 60.0, true, false, false},
                            {"rotation+friction+damping+walls", 0.6, 60.0, true, true, false},
                            {"rotation+friction+damping+walls+moving_walls", 0.6, 60.0, true, true, true}};
    for (const Level& l : levels) {
        Scene s = bed;
        s.material.mu = l.mu;
        s.material.gamma_n = l.gamma_n;
        if (!l.walls) s.walls.clear();
        if (l.moving)
            for (Wall& w : s.walls)
                if (w.name == "x_max") w.velocity = {-0.5, 0.0, 0.0};
        State st = settled;
        if (!l.spin)
            for (std::vector<Vec3d>* q : {&st.rot.x, &st.rot.v, &st.rot.a, &st.rot.b3, &st.rot.b4, &st.rot.b5})
                std::fill(q->begin(), q->end(), Vec3d{});
        st.walls = continue_walls(s, st);
        Problem c(s, st);
        demmat::Setup full = c.setup();
        full.widen = ModelFeatures::full();
        VariantRun a(make_fast_variant(FastOptions{}), c.setup()), b(make_fast_variant(FastOptions{}), full);
        // Without kAllModels the chain's ends only (model.hpp): every level above the first runs the last.
        EXPECT_EQ(a.variant->model().name(), kAllModels || &l == levels ? l.model : std::end(levels)[-1].model);
        EXPECT_EQ(b.variant->model(), ModelFeatures::full());
        std::string difference;
        std::int64_t contacts = 0, walls = 0;
        for (int k = 1; k <= 400 && difference.empty(); ++k) {
            a.driver->step();
            b.driver->step();
            if (const auto d = first_difference(a.snapshot(), b.snapshot())) difference = fmt::format("step {}: {}", k, d->describe());
            contacts = std::max(contacts, a.variant->counts().particle_particle);
            walls = std::max(walls, a.variant->counts().particle_wall);
        }
        EXPECT_EQ(difference, "") << l.model;
        State sa, sb;
        a.variant->save(sa);
        b.variant->save(sb);
        EXPECT_EQ(state_difference(sa, sb), "") << l.model;
        EXPECT_GT(contacts, 500) << l.model;  // contact-rich, so a skipped feature had work to skip
        if (l.walls) {
            EXPECT_GT(walls, 50) << l.model;
        }
    }
}

TEST(Fast, TheFeatureChainComparisonSeesADampingTermThatIsNotInert)
{
    // Control: the comparison above, with the full run given γ_n = 60 where the scene says 0, differs.
    Scene bed = dense_bed_scene(500);
    bed.grid->radius_min = bed.grid->radius_max;
    State st = settled_mono_bed(bed);
    Scene s = bed;
    s.material.mu = 0.0;
    s.material.gamma_n = 0.0;
    s.walls.clear();
    for (std::vector<Vec3d>* q : {&st.rot.x, &st.rot.v, &st.rot.a, &st.rot.b3, &st.rot.b4, &st.rot.b5}) std::fill(q->begin(), q->end(), Vec3d{});
    st.walls.clear();
    Problem c(s, st);
    demmat::Setup full = c.setup();
    full.widen = ModelFeatures::full();
    full.contact.gamma_n = 60.0;
    VariantRun a(make_fast_variant(FastOptions{}), c.setup()), b(make_fast_variant(FastOptions{}), full);
    for (int k = 0; k < 20; ++k) {
        a.driver->step();
        b.driver->step();
    }
    EXPECT_TRUE(first_difference(a.snapshot(), b.snapshot()));
}
