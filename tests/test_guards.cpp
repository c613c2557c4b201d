// Runs that go wrong stop with a clear message: an unstable time step is caught by the driver's health
// checks with the step and the particle, and an overflowing capacity names the capacity and the value
// that would fit.
#include <gtest/gtest.h>

#include "demmat/error.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

class Guards : public ::testing::TestWithParam<std::string> {};

TEST_P(Guards, UnstableTimeStepStopsWithStepAndParticle)
{
    Scene s = dense_bed_scene(500);
    s.dt = 6e-4;  // 0.6 of the Rayleigh time: the Gear scheme blows up within 100 steps
    Problem c(s);
    VariantRun run(GetParam(), c.setup());
    try {
        run.driver->run(5000);
        ADD_FAILURE() << "an unstable run went on to the end";
    } catch (const InstabilityError& e) {
        EXPECT_GT(e.step(), 0);
        EXPECT_LE(e.step(), 5000);
        EXPECT_GE(e.particle(), 0);
        EXPECT_LT(e.particle(), 500);
        const std::string m = e.what();
        EXPECT_NE(m.find("step " + std::to_string(e.step())), std::string::npos) << m;
        EXPECT_NE(m.find("Rayleigh time"), std::string::npos) << m;
    }
}

TEST_P(Guards, StableRunPassesTheHealthChecks)
{
    Problem c(dense_bed_scene(500));
    VariantRun run(GetParam(), c.setup());
    EXPECT_NO_THROW(run.driver->run(2000));
}

INSTANTIATE_TEST_SUITE_P(AllVariants, Guards, ::testing::ValuesIn(variant_names()),
                         [](const auto& info) { return param_name(info.param); });

TEST(Capacity, ArraysOverflowNamesTheCapacityAndTheValueThatFits)
{
    // Particle 0 overlaps particles 1, 2 and 3: three partners j > 0 where the capacity holds one.
    Scene s = head_on_scene();
    s.capacity.contacts_per_particle = 1;
    State st;
    st.resize(4);
    st.dt = s.dt;
    const Vec3d at[4] = {{0, 0, 0}, {0.007, 0, 0}, {0, 0.007, 0}, {0, 0, 0.007}};
    for (int i = 0; i < 4; ++i) {
        st.radius[i] = 0.004;
        st.trans.x[i] = at[i];
    }
    Problem c(s, st);
    VariantRun run("arrays", c.setup());
    try {
        run.driver->step();
        ADD_FAILURE() << "capacity 1 did not overflow";
    } catch (const CapacityError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("capacity.contacts_per_particle = 1 exceeded: particle 0"), std::string::npos) << m;
        EXPECT_NE(m.find("particle 0 has 3 candidate partners; set it to at least 3"), std::string::npos) << m;
    }
}
