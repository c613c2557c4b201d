// The mpi variant against arrays, run under mpirun at several process counts (tests/CMakeLists.txt):
// every rank drives the mpi variant; rank 0 also runs arrays from the same state and compares the two
// snapshots bit for bit after init and after every step. Every rank takes the same path through each
// test (the collective calls must match), so the tests use EXPECT, never ASSERT, and only rank 0 holds
// the data they check. Suites named *Long are the long runs (ctest label long).
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <mpi.h>

#include "leak_check.hpp"
#include "lockstep.hpp"
#include "mpi_variant.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::mpi;
using namespace demmat::test;

namespace {

const Comm& world()
{
    static const Comm c(MPI_COMM_WORLD);
    return c;
}

struct Lockstep {
    std::string difference;            // rank 0: the first difference from arrays, "" if none
    std::int64_t steps = 0;            // steps compared
    std::vector<RankReport> reports;   // rank 0: every rank's share after the run
    ContactCounts counts;
    Snapshot last;                     // rank 0: the mpi variant's last snapshot
    Bricks bricks;
    std::size_t particles = 0;
    double halo = 0.0;
};

// `steps` steps of the mpi variant and (rank 0) arrays, compared after init and after every step; stops
// at the first difference (lockstep.hpp).
Lockstep run_lockstep(const std::function<std::unique_ptr<Problem>()>& load, std::int64_t steps, const MpiOptions& options = {})
{
    Lockstep out;
    auto problem = share_problem(world(), load);
    auto mpi = make_mpi_variant(MPI_COMM_WORLD, options);
    const LockstepResult r = compare_lockstep(*problem, *mpi, registry().find("arrays").create, "arrays", steps, &out.last);
    if (r.difference) out.difference = r.difference->describe();
    out.steps = r.steps;
    out.reports = mpi->rank_reports();
    out.counts = mpi->counts();
    out.bricks = mpi->bricks();
    out.particles = problem->size();
    out.halo = mpi->halo();
    return out;
}

std::unique_ptr<Problem> bed(double wall_speed)
{
    const Scene scene = dense_bed_scene(2000);
    State st = settling_bed_state(scene);
    Scene s = wall_speed > 0 ? compression_scene(scene, "(cached state)", wall_speed) : scene;
    st.walls = continue_walls(s, st);
    return std::make_unique<Problem>(s, st);
}

// A loose gas of fast grains (3 to 6 m/s, no gravity) in a box of 0.24 × 0.12 × 0.12 m: a grain
// crosses a brick of 3 cm (8 along x) in about 700 steps, so grains cross the faces again and again;
// polydisperse, walls, friction, damping.
std::unique_ptr<Problem> gas()
{
    Scene s = paper_scene(1000, 7);
    s.name = "loose_gas";
    s.gravity = {0.0, 0.0, 0.0};
    s.domain = {{0.0, 0.0, 0.0}, {0.24, 0.12, 0.12}};
    s.walls = box_walls(s.domain);
    s.grid->speed_min = 3.0;
    s.grid->speed_max = 6.0;
    return std::make_unique<Problem>(s);
}

// The laws of physics.md §9 on the settled bed (its contacts start without stretches): every memory
// (mindlin, sds, tsuji), a constant spring with restitution damping, and restitution damping alone.
ContactModel memory_law(int which)
{
    ContactModel m;
    if (which == 0) {
        m = contact_model_from_options({"damping=tsuji", "restitution=0.5", "tangential=mindlin", "tangential_damping_ratio=0.5",
                                        "rolling=sds", "kr=50", "rolling_damping=0.05", "rolling_friction=0.1"});
    } else if (which == 1) {
        m = contact_model_from_options({"damping=restitution", "restitution=0.3", "tangential=linear_history", "kt=50",
                                        "tangential_damping_ratio=0.5"});
    } else {
        m = contact_model_from_options({"damping=restitution", "restitution=0.7"});
    }
    return m;
}

std::unique_ptr<Problem> bed_with_law(double wall_speed, int which)
{
    const Scene scene = dense_bed_scene(2000);
    State st = settling_bed_state(scene);
    Scene s = wall_speed > 0 ? compression_scene(scene, "(cached state)", wall_speed) : scene;
    s.contact_model = memory_law(which);
    st.walls = continue_walls(s, st);
    return std::make_unique<Problem>(s, st);
}

// Eight grains spread along x, in empty space (no walls, no gravity), moving and spinning, each with
// the nonzero scaled derivatives of a grain that has just left a contact: in free flight these decay
// into the subnormal numbers unless the rule for negligible derivatives (physics.md §3) clears them
// (tests/test_negligible_derivatives.cpp shows the decay for one grain in every registered variant).
std::unique_ptr<Problem> free_flight()
{
    Scene s = drop_scene(0.05, 0.004);
    s.name = "free_flight";
    s.walls.clear();
    s.gravity = {0.0, 0.0, 0.0};
    s.domain = {{0.0, 0.0, 0.0}, {0.24, 0.12, 0.12}};
    s.particles.clear();
    for (int i = 0; i < 8; ++i) s.particles.push_back({0.004, {0.015 + 0.03 * i, 0.06, 0.06}, {0.3, -0.2, 0.1}, {5.0, -3.0, 2.0}});
    State st = Problem(s).state();
    for (std::size_t i = 0; i < st.size(); ++i) {
        const double f = 1.0 + 0.1 * double(i);
        st.trans.b3[i] = f * Vec3d{1.1e-9, -2.3e-9, 3.7e-10};
        st.trans.b4[i] = f * Vec3d{-3.1e-10, 5.3e-11, 1.9e-10};
        st.trans.b5[i] = f * Vec3d{7.3e-11, -1.7e-11, 2.9e-11};
        st.rot.b3[i] = f * Vec3d{2.3e-7, 1.3e-7, -4.1e-8};
        st.rot.b4[i] = f * Vec3d{-6.7e-8, 2.1e-8, 1.1e-8};
        st.rot.b5[i] = f * Vec3d{1.3e-8, -3.3e-9, 4.7e-9};
    }
    return std::make_unique<Problem>(s, st);
}

void expect_identical(const Lockstep& r, std::int64_t steps)
{
    if (!world().root()) return;
    EXPECT_EQ(r.difference, "") << "at " << world().size() << " processes";
    EXPECT_EQ(r.steps, steps);
}

} // namespace

TEST(MpiEquivalence, DenseBedIsBitIdenticalToArraysAtEveryStep)
{
    const Lockstep r = run_lockstep([] { return bed(0.0); }, long_run(200));
    expect_identical(r, long_run(200));
    if (world().root()) {
        EXPECT_GT(r.counts.particle_particle, 2500);  // a contact-rich bed (about 3 contacts per grain)
    }  // a contact-rich bed (about 3.5 per grain)
}

TEST(MpiEquivalence, CompressionStageIsBitIdenticalToArraysAtEveryStep)
{
    const Lockstep r = run_lockstep([] { return bed(0.5); }, long_run(200));
    expect_identical(r, long_run(200));
}

TEST(MpiEquivalence, LooseGasCrossingTheBricksIsBitIdentical)
{
    const std::int64_t steps = 800;  // a thousand grains: cheap in the sanitizer build too, and the crossings need the steps
    const Lockstep r = run_lockstep(gas, steps);
    expect_identical(r, steps);
    if (world().root() && world().size() > 1) {
        std::int64_t migrants = 0;
        for (const RankReport& q : r.reports) migrants += q.migrants;
        EXPECT_GT(migrants, 40 * (world().size() - 1)) << "the gas should cross the bricks' faces";
    }
}

// The gas on a grid that cuts as many axes as the process count allows (2: along z; 3: along y; 4: 2x2
// in x and y; 8: 2x2x2), so that grains migrate across edges and corners, through a neighbour, and
// ghosts reach the bricks across an edge or a corner through the staged exchange.
TEST(MpiEquivalence, LooseGasOnBricksInEveryDirectionIsBitIdentical)
{
    const int ranks = world().size();
    MpiOptions grid;
    grid.grid = ranks == 2 ? std::array<int, 3>{1, 1, 2} : ranks == 3 ? std::array<int, 3>{1, 3, 1} : ranks == 4 ? std::array<int, 3>{2, 2, 1}
              : ranks == 8 ? std::array<int, 3>{2, 2, 2} : std::array<int, 3>{ranks, 1, 1};
    const std::int64_t steps = 800;
    const Lockstep r = run_lockstep(gas, steps, grid);
    expect_identical(r, steps);
    if (!world().root()) return;
    EXPECT_EQ(r.bricks.dims, grid.grid);
    if (ranks >= 4) {
        std::int64_t migrants = 0, ghosts = 0;
        for (const RankReport& q : r.reports) {
            migrants += q.migrants;
            ghosts += q.ghosts;
        }
        EXPECT_GT(migrants, 40 * (ranks - 1)) << "the gas should cross the bricks' faces";
        EXPECT_GT(ghosts, 0);
    }
}

TEST(MpiEquivalence, EvenCutsGiveTheSameBits)
{
    MpiOptions even;
    even.balance = Balance::even;
    const Lockstep r = run_lockstep([] { return bed(0.5); }, 100, even);
    expect_identical(r, 100);
}

// The rule for negligible derivatives on bricks along x (a grain or two each): bit-identical to arrays
// at every step, and every a, b3, b4, b5 of every grain is exactly +0 after 150 steps of free flight.
TEST(MpiEquivalence, FreeFlightDerivativesEndAtPositiveZero)
{
    MpiOptions along_x;
    along_x.grid = {world().size(), 1, 1};
    const std::int64_t steps = 150;
    const Lockstep r = run_lockstep(free_flight, steps, along_x);
    expect_identical(r, steps);
    auto problem = share_problem(world(), free_flight);
    auto mpi = make_mpi_variant(MPI_COMM_WORLD, along_x);
    Driver driver(*mpi, problem->setup());
    driver.run(steps);
    State st;
    mpi->save(st);  // collective: gathered on rank 0
    if (!world().root()) return;
    ASSERT_EQ(st.size(), 8u);
    for (const GearState* g : {&st.trans, &st.rot})
        for (const std::vector<Vec3d>* q : {&g->a, &g->b3, &g->b4, &g->b5})
            for (std::size_t i = 0; i < st.size(); ++i)
                for (int c = 0; c < 3; ++c) {
                    const double u = component((*q)[i], c);
                    EXPECT_TRUE(u == 0.0 && !std::signbit(u)) << "grain " << i << " component " << c << ": " << u;
                }
}

// No replicated data: the ranks own every particle exactly once, each about N/R (the cuts balance the
// count), and each holds as ghosts only its neighbours' particles near the shared faces.
TEST(MpiEquivalence, EachRankHoldsItsShareAndItsHaloOnly)
{
    const Lockstep r = run_lockstep([] { return bed(0.0); }, 50);
    if (!world().root()) return;
    const int ranks = world().size();
    std::int64_t owned = 0;
    for (const RankReport& q : r.reports) {
        owned += q.owned;
        EXPECT_LE(double(q.owned_max), 1.25 * double(r.particles) / ranks + 10) << "rank " << q.rank;
        EXPECT_GE(double(q.owned), 0.75 * double(r.particles) / ranks - 10) << "rank " << q.rank;
        // The ghosts are the other bricks' particles within the halo of this one (across a face, an edge
        // or a corner), counted here from the last positions, with slack for one step's motion.
        std::int64_t near = 0, close = 0;
        for (const Vec3d& x : r.last.position) {
            if (r.bricks.owner(x) == q.rank) continue;
            double d = 0.0;  // how far outside the brick, along the axis where it is farthest
            for (int a = 0; a < 3; ++a)
                d = std::max({d, r.bricks.low(q.rank, a) - component(x, a), component(x, a) - r.bricks.high(q.rank, a)});
            near += d < 1.5 * r.halo;
            close += d < 0.5 * r.halo;
        }
        EXPECT_LE(q.ghosts, near) << "rank " << q.rank;
        EXPECT_GE(q.ghosts, close) << "rank " << q.rank;
        if (ranks == 1) {
            EXPECT_EQ(q.ghosts, 0);
        }
        // A message to each face neighbour per step (the ghosts refreshed), and one more at a rebuild
        // (migrants, then the new ghosts).
        int neighbours = 0;
        for (int a = 0; a < 3; ++a) neighbours += (r.bricks.neighbour(q.rank, a, -1) >= 0) + (r.bricks.neighbour(q.rank, a, 1) >= 0);
        EXPECT_EQ(q.traffic.messages, neighbours * (q.steps + q.rebuilds)) << "rank " << q.rank;
        EXPECT_LT(q.rebuilds, q.steps) << "the list is kept over several steps";
    }
    EXPECT_EQ(owned, std::int64_t(r.particles));
}

// The stretches: both ranks of a pair across a face hold it and update it from the same inputs, and a
// migrant takes its contacts' stretches along (the compression pushes grains across the faces).
TEST(MpiEquivalence, ContactMemoryIsBitIdenticalToArrays)
{
    const Lockstep r = run_lockstep([] { return bed_with_law(2.0, 0); }, long_run(200));
    expect_identical(r, long_run(200));
}

TEST(MpiEquivalenceLong, EveryContactLawIsBitIdenticalToArrays)
{
    for (int which = 0; which < 3; ++which) {
        const Lockstep r = run_lockstep([which] { return bed_with_law(2.0, which); }, long_run(2000));
        expect_identical(r, long_run(2000));
        if (world().root() && world().size() > 1) {
            std::int64_t migrants = 0;
            for (const RankReport& q : r.reports) migrants += q.migrants;
            EXPECT_GT(migrants, 0) << "the compression should push grains across the faces";
        }
    }
}

TEST(MpiEquivalenceLong, DenseBedIsBitIdenticalToArraysAtEveryStep)
{
    const Lockstep r = run_lockstep([] { return bed(0.0); }, long_run(5000));
    expect_identical(r, long_run(5000));
}

TEST(MpiEquivalenceLong, CompressionStageIsBitIdenticalToArraysAtEveryStep)
{
    const Lockstep r = run_lockstep([] { return bed(0.5); }, long_run(3000));
    expect_identical(r, long_run(3000));
}

TEST(MpiEquivalenceLong, LooseGasCrossingTheBricksIsBitIdentical)
{
    const Lockstep r = run_lockstep(gas, long_run(8000));
    expect_identical(r, long_run(8000));
}

// gtest under MPI: every rank runs every test; only rank 0 prints, and the program fails on every rank
// when a test failed on any.
int main(int argc, char** argv)
{
    MPI_Init(&argc, &argv);
    ::testing::InitGoogleTest(&argc, argv);
    if (world().rank() != 0) {
        auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
        delete listeners.Release(listeners.default_result_printer());
    }
    int failed = RUN_ALL_TESTS() != 0;
    int any = 0;
    MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    check_leaks_before_finalize();
    MPI_Finalize();
    return any;
}
