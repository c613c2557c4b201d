// Every fixed capacity, overflowed on purpose, in every registered variant. A variant either stops with a
// CapacityError whose message names the capacity and the value that would fit, or (a variant whose store
// grows: oop, the linked lists, ...) goes on and computes exactly what a variant with room to spare
// computes. A silently truncated contact list, the failure this guards against, gives neither.
// The particle capacity (32-bit indices) is checked by the scene reader: bad_input/grid_count_over_capacity.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

// Variants known to keep fixed (N, capacity) tables: these must throw, not grow.
const std::set<std::string> fixed_tables = {"arrays", "eigen_soa", "f90", "pascal"};

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// Particle 0 overlaps particles 1, 2 and 3: three partners j > 0.
Problem crowded(SearchMethod method, int pair_capacity, int wall_capacity, bool in_corner)
{
    Scene s = head_on_scene();
    s.search.method = method;
    s.capacity.contacts_per_particle = pair_capacity;
    s.capacity.wall_contacts_per_particle = wall_capacity;
    State st;
    st.resize(4);
    st.dt = s.dt;
    const double r = 0.004;
    // In the corner, particle 0 overlaps the x_min, y_min and z_min walls: three walls.
    const Vec3d o = in_corner ? s.domain.min + Vec3d{0.9 * r, 0.9 * r, 0.9 * r} : Vec3d{};
    if (in_corner) s.walls = box_walls(s.domain);
    const Vec3d at[4] = {o, o + Vec3d{0.007, 0, 0}, o + Vec3d{0, 0.007, 0}, o + Vec3d{0, 0, 0.007}};
    for (int i = 0; i < 4; ++i) {
        st.radius[i] = r;
        st.trans.x[i] = at[i];
    }
    st.walls = s.walls;
    st.fingerprint = s.fingerprint(4);
    return Problem(s, st);
}

// One step of `variant` on the crowded case; either a CapacityError (returned) or the same snapshot and
// contact counts as arrays with ample capacities.
std::string step_or_match(const std::string& variant, SearchMethod method, int pair_cap, int wall_cap, bool corner)
{
    Problem tight = crowded(method, pair_cap, wall_cap, corner);
    VariantRun run(variant, tight.setup());
    try {
        run.driver->step();
    } catch (const CapacityError& e) {
        return e.what();
    }
    EXPECT_FALSE(fixed_tables.count(variant)) << variant << " keeps fixed tables but did not stop on overflow";
    Problem ample = crowded(method, 64, 6, corner);
    VariantRun ref("arrays", ample.setup());
    ref.driver->step();
    const auto d = first_difference(ref.snapshot(), run.snapshot());
    EXPECT_FALSE(d) << variant << " went on past the capacity but computed something else: " << d->describe();
    EXPECT_EQ(run.variant->counts().particle_particle, ref.variant->counts().particle_particle);
    EXPECT_EQ(run.variant->counts().particle_wall, ref.variant->counts().particle_wall);
    return "";
}

} // namespace

class Capacities : public ::testing::TestWithParam<std::tuple<std::string, SearchMethod>> {};

TEST_P(Capacities, ContactsPerParticle)
{
    const auto [variant, method] = GetParam();
    // The store holds one partner per particle; particle 0 has three.
    const std::string m = step_or_match(variant, method, 1, 6, false);
    if (m.empty()) return;  // a growing store, checked exact above
    EXPECT_TRUE(contains(m, "capacity.contacts_per_particle = 1 exceeded")) << m;
    EXPECT_TRUE(contains(m, "particle 0 has 3 candidate partners")) << m;
    EXPECT_TRUE(contains(m, "set it to at least 3")) << m;
}

TEST_P(Capacities, ContactsPerParticleExactlyFull)
{
    // Three partners in room for three: no overflow, and the result matches a roomy run.
    const auto [variant, method] = GetParam();
    Problem tight = crowded(method, 3, 6, false);
    Problem ample = crowded(method, 64, 6, false);
    VariantRun run(variant, tight.setup()), ref("arrays", ample.setup());
    ASSERT_NO_THROW(run.driver->step());
    ref.driver->step();
    const auto d = first_difference(ref.snapshot(), run.snapshot());
    EXPECT_FALSE(d) << d->describe();
}

TEST_P(Capacities, WallContactsPerParticle)
{
    const auto [variant, method] = GetParam();
    // The store holds one wall per particle; particle 0 touches three of the six.
    const std::string m = step_or_match(variant, method, 64, 1, true);
    if (m.empty()) return;
    EXPECT_TRUE(contains(m, "capacity.wall_contacts_per_particle = 1 exceeded")) << m;
    EXPECT_TRUE(contains(m, "particle 0 touches more walls")) << m;
    EXPECT_TRUE(contains(m, "set it to 6")) << m;  // the number of walls always fits
}

INSTANTIATE_TEST_SUITE_P(AllVariants, Capacities,
                         ::testing::Combine(::testing::ValuesIn(variant_names()),
                                            ::testing::Values(SearchMethod::cells, SearchMethod::all_pairs)),
                         [](const auto& info) {
                             return param_name(std::get<0>(info.param)) +
                                    (std::get<1>(info.param) == SearchMethod::cells ? "_cells" : "_all_pairs");
                         });

TEST(Capacity, PascalInstanceSlots)
{
    // The Pascal port keeps its state in a global table of instance slots (the paper's global arrays).
    const auto names = variant_names();
    if (std::find(names.begin(), names.end(), "pascal") == names.end()) GTEST_SKIP() << "pascal not built here";
    std::vector<std::unique_ptr<Variant>> live;
    try {
        for (int k = 0; k < 1000; ++k) live.push_back(registry().find("pascal").create());
        FAIL() << "1000 live Pascal instances and no error";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_TRUE(contains(m, fmt::format("at most {} live instances", live.size()))) << m;
        EXPECT_GE(live.size(), 2u);  // save-and-continue and self-comparison need two
    }
    live.clear();  // slots are freed: one can be created again
    EXPECT_NO_THROW(registry().find("pascal").create());
}
