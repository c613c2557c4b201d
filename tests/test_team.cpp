// fast's teams (lane_engine/team.hpp, in_team): a region asked for in parallel runs on a team only where OpenMP
// may give more than one thread; otherwise its body runs once on this thread, outside any parallel
// region (no team of one, whose barriers are system calls each step), and its directives still do
// their work: a worksharing loop covers its range exactly once, a single runs once, thread_count() is 1.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <vector>

#include "demmat/lane_engine/team.hpp"

using namespace demmat::fast;

namespace {

#ifdef _OPENMP
// Restores the thread limit a test changed.
struct ThreadLimit {
    int saved = omp_get_max_threads();
    explicit ThreadLimit(int n) { omp_set_num_threads(n); }
    ~ThreadLimit() { omp_set_num_threads(saved); }
};
#endif

struct Seen {
    std::atomic<int> bodies{0}, singles{0}, in_parallel{0};  // bodies run inside a parallel region
    std::vector<std::atomic<int>> visits;
    int team = 0;
    explicit Seen(std::size_t n) : visits(n) {}
};

// A body like fast's: its own share by thread_range, a single, a barrier, a worksharing loop.
void run(bool parallel, Seen& seen)
{
    in_team(parallel, [&] {
        ++seen.bodies;
#ifdef _OPENMP
        if (omp_get_level() > 0) ++seen.in_parallel;  // inside a region, a team of one included
#endif
#pragma omp single
        {
            ++seen.singles;
            seen.team = thread_count();
        }
#pragma omp barrier
#pragma omp for schedule(static)
        for (std::size_t s = 0; s < seen.visits.size(); ++s) ++seen.visits[s];
    });
}

void expect_each_visited_once(const Seen& seen)
{
    for (std::size_t s = 0; s < seen.visits.size(); ++s) ASSERT_EQ(seen.visits[s].load(), 1) << "index " << s;
}

} // namespace

TEST(Team, NotParallelRunsTheBodyOnceOutsideAnyRegion)
{
    Seen seen(1000);
    run(false, seen);
    EXPECT_EQ(seen.bodies.load(), 1);
    EXPECT_EQ(seen.in_parallel.load(), 0);
    EXPECT_EQ(seen.singles.load(), 1);
    EXPECT_EQ(seen.team, 1);
    expect_each_visited_once(seen);
}

TEST(Team, ALimitOfOneThreadMakesNoTeamOfOne)
{
#ifndef _OPENMP
    GTEST_SKIP() << "built without OpenMP";
#else
    ThreadLimit one(1);
    Seen seen(1000);
    run(true, seen);
    EXPECT_EQ(seen.bodies.load(), 1);
    EXPECT_EQ(seen.in_parallel.load(), 0) << "a team of one was made";
    EXPECT_EQ(seen.singles.load(), 1);
    expect_each_visited_once(seen);
#endif
}

TEST(Team, SeveralThreadsRunTheBodyOnATeam)
{
#ifndef _OPENMP
    GTEST_SKIP() << "built without OpenMP";
#else
    ThreadLimit three(3);
    Seen seen(1000);
    run(true, seen);
    // The runtime may give fewer threads than asked (dynamic teams), never none.
    EXPECT_GE(seen.bodies.load(), 1);
    EXPECT_EQ(seen.in_parallel.load(), seen.bodies.load()) << "the body ran outside the team";
    EXPECT_EQ(seen.team, seen.bodies.load());
    EXPECT_EQ(seen.singles.load(), 1);
    expect_each_visited_once(seen);
#endif
}

// PerThread: each thread's value on cache lines of its own (two threads' vector headers on one line
// made each resize by one take the line from the other), and its memory account counts what the values
// hold on the heap.
TEST(Team, PerThreadValuesShareNoCacheLine)
{
    PerThread<std::vector<int>> per;
    per.resize(4);
    for (std::size_t t = 0; t < per.size(); ++t) {
        const auto at = reinterpret_cast<std::uintptr_t>(&per[t]);
        EXPECT_EQ(at % 64, 0u) << "thread " << t << "'s value does not start a cache line";
        if (t > 0) {
            EXPECT_GE(at - reinterpret_cast<std::uintptr_t>(&per[t - 1]), 64u) << "threads " << t - 1 << " and " << t;
        }
    }
    const std::size_t empty = per.bytes();
    per[2].reserve(1000);
    EXPECT_EQ(per.bytes(), empty + per[2].capacity() * sizeof(int));
}
