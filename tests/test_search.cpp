// The contact search against brute force: on random polydisperse packings (overlaps allowed), one
// step with every variant and search setting must give forces bit-identical to the reference, which
// takes every pair (O(N²)) and sums in the canonical order; the contact counts must match too.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "demmat/reference.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

struct Packing {
    const char* name;
    double rmin, rmax;
    SearchMethod method;
    double cell;     // in units of R_max
    bool moving_wall;
};

// A random packing in a box, dense enough that most particles overlap some others; at rest with zero
// Gear derivatives, so the predictor leaves positions unchanged and forces are those of these positions.
Problem packing(const Packing& p, std::int64_t n, std::uint64_t seed)
{
    Scene s;
    s.name = p.name;
    s.dt = 1e-6;
    s.gravity = {0, 0, 0};
    const double mean_vol = 4.18879 * (p.rmin + p.rmax) * (p.rmin + p.rmax) * (p.rmin + p.rmax) / 8.0;
    const double side = std::cbrt(double(n) * mean_vol / 0.55);
    s.domain = {{0, 0, 0}, {side, side, side}};
    s.walls = box_walls(s.domain);
    if (p.moving_wall) s.walls[1].velocity = {-0.3, 0.0, 0.0};
    s.search.method = p.method;
    s.search.cell_size = p.cell;
    s.capacity.contacts_per_particle = 64;
    State st;
    st.resize(std::size_t(n));
    std::uint64_t x = seed;
    auto uni = [&] {
        x += 0x9e3779b97f4a7c15ull;
        std::uint64_t z = x;
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
    };
    for (std::int64_t i = 0; i < n; ++i) {
        st.radius[i] = p.rmin + (p.rmax - p.rmin) * uni();
        st.trans.x[i] = {side * uni(), side * uni(), side * uni()};
        st.rot.v[i] = {uni() - 0.5, uni() - 0.5, uni() - 0.5};  // spin: exercises torques and ω × d
    }
    st.walls = s.walls;
    st.dt = s.dt;
    return Problem(s, st);
}

double max_abs(const std::vector<Vec3d>& a)
{
    double m = 0.0;
    for (const Vec3d& v : a) m = std::max({m, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    return m;
}

double max_gap(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b)
{
    double m = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) m = std::max({m, std::abs(a[i].x - b[i].x), std::abs(a[i].y - b[i].y), std::abs(a[i].z - b[i].z)});
    return m;
}

} // namespace

class Search : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

const Packing kPackings[] = {
    {"mono_cells2", 1.0, 1.0, SearchMethod::cells, 2.0, false},
    {"poly3_cells2", 0.5, 1.5, SearchMethod::cells, 2.0, false},
    {"poly3_cells4", 0.5, 1.5, SearchMethod::cells, 4.0, false},
    {"poly10_cells2", 0.1, 1.0, SearchMethod::cells, 2.0, false},
    {"poly3_allpairs", 0.5, 1.5, SearchMethod::all_pairs, 2.0, false},
    {"poly3_cells2_moving_wall", 0.5, 1.5, SearchMethod::cells, 2.0, true},
};

TEST_P(Search, FindsExactlyTheBruteForceContactSet)
{
    const auto& [variant, k] = GetParam();
    const Packing& p = kPackings[k];
    for (std::uint64_t seed : {1u, 2u, 3u}) {
        Problem c = packing(p, 1200, seed);
        VariantRun run(variant, c.setup());
        run.driver->step();
        const Snapshot s = run.snapshot();
        // The reference at the predicted positions and velocities, which are the initial ones because
        // every derivative is zero; the moving wall is at its step-1 position.
        std::vector<Vec3d> f, t;
        reference_forces(c.state().trans.x, c.state().trans.v, c.state().rot.v, c.state().radius, c.setup().mass, c.state().walls, 1, c.scene().dt,
                         c.setup().contact, f, t);
        const auto pairs = contact_pairs(c.state().trans.x, c.state().radius, true);
        ASSERT_GT(pairs.size(), c.state().size());  // dense: more contacts than particles
        EXPECT_EQ(run.variant->counts().particle_particle, std::int64_t(pairs.size())) << p.name << " seed " << seed;
        Snapshot ref = s;
        ref.force = f;
        ref.torque = t;
        if (!registry().find(variant).bitwise) {
            // A variant that drops the canonical order sums the same contacts in another order. A
            // reordered sum of k terms moves by about k·ε·Σ|terms| (k ≤ 64 here); 1e-10 of the largest
            // force is far above that and far below a missed or extra contact (its own size).
            EXPECT_LT(max_gap(ref.force, s.force), 1e-10 * max_abs(ref.force)) << p.name << " seed " << seed;
            EXPECT_LT(max_gap(ref.torque, s.torque), 1e-10 * max_abs(ref.torque)) << p.name << " seed " << seed;
            continue;
        }
        const auto d = first_difference(ref, s);
        EXPECT_FALSE(d) << p.name << " seed " << seed << ": " << d->describe();
    }
}

INSTANTIATE_TEST_SUITE_P(AllVariants, Search,
                         ::testing::Combine(::testing::ValuesIn(variant_names()), ::testing::Range(0, int(std::size(kPackings)))),
                         [](const auto& info) {
                             return param_name(std::get<0>(info.param)) + "_" + kPackings[std::get<1>(info.param)].name;
                         });

// The reference's own cell list (the health checks' and the counts' contact set at any N) against its
// brute force: polydisperse clouds spanning negative and positive cells, pairs placed at exactly the
// sum of their radii (h = 0 is no contact) and a hair inside it, a particle far out (its cell clamped),
// a NaN position and a NaN radius (they touch nothing).
TEST(ReferenceContactPairs, CellListFindsExactlyTheBruteForcePairs)
{
    for (std::uint64_t seed : {1u, 2u, 3u}) {
        std::mt19937_64 rng(seed);
        std::uniform_real_distribution<double> pos(-0.05, 0.05), rad(0.002, 0.008), unit(0.0, 1.0);
        std::vector<Vec3d> x;
        std::vector<double> r;
        for (int k = 0; k < 1500; ++k) {
            x.push_back({pos(rng), pos(rng), pos(rng)});
            r.push_back(rad(rng));
        }
        for (int k = 0; k < 40; ++k) {  // touching exactly, and a hair inside, across cell edges
            const Vec3d a{pos(rng), pos(rng), pos(rng)};
            const double ra = rad(rng), rb = rad(rng);
            const Vec3d v{unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5};
            const Vec3d dir = v / std::sqrt(dot(v, v));
            const double d = (k % 2 == 0) ? ra + rb : (ra + rb) * (1.0 - 1e-12);
            x.push_back(a);
            r.push_back(ra);
            x.push_back(a + d * dir);
            r.push_back(rb);
        }
        x.push_back({1e300, -1e300, 0.0});
        r.push_back(0.005);
        x.push_back({1e300, -1e300, 0.001});  // touches the one before, both clamped into one cell
        r.push_back(0.005);
        x.push_back({std::nan(""), 0.0, 0.0});
        r.push_back(0.005);
        // A NaN radius first, beside a grain: it touches nothing, and the cells' size comes from the others.
        x.insert(x.begin(), x[5] + Vec3d{0.001, 0.0, 0.0});
        r.insert(r.begin(), std::nan(""));
        const auto brute = contact_pairs(x, r, true);
        const auto cells = contact_pairs(x, r, false);
        ASSERT_GT(brute.size(), x.size());
        EXPECT_EQ(cells, brute) << "seed " << seed;
    }
    // Radii of zero: no pair has h > 0.
    const std::vector<Vec3d> x(100, Vec3d{0.01, 0.02, 0.03});
    EXPECT_TRUE(contact_pairs(x, std::vector<double>(100, 0.0), false).empty());
}
