// fast's neighbour list (lane_engine/neighbour_list.hpp on lane_engine/cell_order.hpp): after a rebuild's cell sort and
// permutation, the slots hold every pair closer than R_i + R_j + skin (may_touch with each radius grown
// by skin/2) exactly once, stored with the particle that comes first in storage, the lower id its owner
// (the law's i), and no other pair: checked against all N(N-1)/2 pairs of a polydisperse cloud, on the
// grid of cell starts (a compact box) and on the comparison-sorted cells of a box made huge by one
// particle far away, from one thread and from a team.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "demmat/problem.hpp"
#include "demmat/scenes.hpp"
#include "demmat/lane_engine/cell_order.hpp"
#include "demmat/lane_engine/neighbour_list.hpp"
#include "demmat/lane_engine/particles.hpp"
#include "demmat/state_file.hpp"

using namespace demmat;
using namespace demmat::fast;

namespace {

using Pairs = std::set<std::pair<Index, Index>>;  // by id, lower first

// A dense bed's grains (its radii) at random places in a box that gives each a few partners within
// reach; `far`: the last one moved 10 km away along x.
State cloud(const Scene& bed, bool far)
{
    State st = initial_state(bed);
    std::mt19937_64 rng(7);
    // A cube of edge 1.5 R_max per grain: a few partners each within R_i + R_j + skin.
    const double edge = 1.5 * *std::max_element(st.radius.begin(), st.radius.end()) * std::cbrt(double(st.size()));
    std::uniform_real_distribution<double> at(0.0, edge);
    for (Vec3d& x : st.trans.x) x = {at(rng), at(rng), at(rng)};
    if (far) st.trans.x.back().x = 1e4;
    return st;
}

// The list's pairs, each checked to be stored with its storage-earlier particle under the lower id.
Pairs listed(const NeighbourList& list, const Particles& p)
{
    Pairs out;
    for (std::size_t s = 0; s < p.n; ++s)
        for (Index k = list.start[s]; k < list.start[s + 1]; ++k) {
            const Index i = list.owner[std::size_t(k)], j = list.partner[std::size_t(k)];
            const std::size_t other = std::size_t(i) == s ? std::size_t(j) : std::size_t(i);
            EXPECT_TRUE(std::size_t(i) == s || std::size_t(j) == s) << "slot " << k << " stored at " << s;
            EXPECT_GT(other, s) << "slot " << k << " stored with the later particle";
            EXPECT_LT(p.id[std::size_t(i)], p.id[std::size_t(j)]) << "slot " << k << ": the owner has the higher id";
            EXPECT_TRUE(out.insert({p.id[std::size_t(i)], p.id[std::size_t(j)]}).second) << "pair listed twice at slot " << k;
        }
    return out;
}

// Every pair within reach, from all pairs.
Pairs brute_force(const Particles& p, double skin)
{
    Pairs out;
    for (std::size_t s = 0; s < p.n; ++s)
        for (std::size_t q = s + 1; q < p.n; ++q)
            if (may_touch(p.get(p.x, s), p.get(p.x, q), p.r[s] + 0.5 * skin, p.r[q] + 0.5 * skin))
                out.insert(std::minmax(p.id[s], p.id[q]));
    return out;
}

void check(bool far, bool parallel)
{
    const Scene bed = dense_bed_scene(600);
    const Problem problem(bed, cloud(bed, far));
    const Setup& setup = problem.setup();
    Particles p;
    p.init(setup);
    const double skin = 0.3 * setup.radius_max;
    CellOrder cells;
    cells.sort(p.x, p.id, p.n, 2.0 * setup.radius_max + skin);
    p.permute([&](std::size_t s) { return std::size_t(cells.key(s).from); }, [&](std::size_t s) { return cells.key(s).id; }, parallel);
    NeighbourList list;
    list.build(p, cells, skin, true, parallel);
    const Pairs want = brute_force(p, skin), got = listed(list, p);
    ASSERT_GT(want.size(), 2 * p.n) << "the cloud should give each grain a few partners";
    EXPECT_EQ(got.size(), want.size());
    EXPECT_TRUE(got == want) << "the list is not the set of pairs within R_i + R_j + skin";
}

// Restores the thread limit a test changed.
struct ThreadLimit {
    int saved = omp_get_max_threads();
    explicit ThreadLimit(int n) { omp_set_num_threads(n); }
    ~ThreadLimit() { omp_set_num_threads(saved); }
};

} // namespace

TEST(NeighbourList, CompactBoxListsExactlyThePairsWithinReach)
{
    check(false, false);
    ThreadLimit three(3);
    check(false, true);
}

TEST(NeighbourList, HugeSparseBoxListsExactlyThePairsWithinReach)
{
    check(true, false);
    ThreadLimit three(3);
    check(true, true);
}
