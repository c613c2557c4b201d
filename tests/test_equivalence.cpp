// Bitwise equivalence, the suite's backbone: every search method gives the same trajectory, and every
// variant gives the trajectory of the arrays variant, step by step, on a dense settling bed and on the
// compression stage.
#include <filesystem>

#include <gtest/gtest.h>

#include "demmat/error.hpp"

#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

std::string compare(const std::vector<std::string>& names, const Setup& setup, std::int64_t steps)
{
    const CompareReport r = compare_variants(names, setup, steps);
    return r.difference ? r.difference->describe() : "";
}

} // namespace

class Equivalence : public ::testing::TestWithParam<std::string> {};

TEST_P(Equivalence, SearchMethodsGiveBitIdenticalTrajectories)
{
    // Without the canonical order the sums follow the storage order, which the cell size changes.
    if (!registry().find(GetParam()).bitwise) GTEST_SKIP() << "drops the canonical order on purpose (its physics is tested elsewhere)";
    // Cells of 2·R_max, 4·R_max and every pair: one trajectory, over thousands of contact-rich steps.
    const std::int64_t steps = long_run(3000);
    std::vector<Snapshot> finals;
    for (auto [method, cell] : {std::pair{SearchMethod::cells, 2.0}, {SearchMethod::cells, 4.0}, {SearchMethod::all_pairs, 2.0}}) {
        Scene s = dense_bed_scene(1000);
        s.search.method = method;
        s.search.cell_size = cell;
        Problem c(s);
        VariantRun run(GetParam(), c.setup());
        run.driver->run(steps);
        EXPECT_GT(run.variant->counts().particle_particle, 200);
        finals.push_back(run.snapshot());
    }
    for (std::size_t k = 1; k < finals.size(); ++k) {
        const auto d = first_difference(finals[0], finals[k]);
        EXPECT_FALSE(d) << "search setting " << k << ": " << d->describe();
    }
}

TEST_P(Equivalence, DenseBedIsBitIdenticalToArraysAtEveryStep)
{
    if (GetParam() == "arrays") GTEST_SKIP() << "the reference itself";
    if (!registry().find(GetParam()).bitwise) GTEST_SKIP() << "drops the canonical order on purpose (its physics is tested elsewhere)";
    Problem c = bed_case(0.0);
    EXPECT_EQ(compare({"arrays", GetParam()}, c.setup(), long_run(5000)), "");
}

TEST_P(Equivalence, CompressionStageIsBitIdenticalToArraysAtEveryStep)
{
    if (GetParam() == "arrays") GTEST_SKIP() << "the reference itself";
    if (!registry().find(GetParam()).bitwise) GTEST_SKIP() << "drops the canonical order on purpose (its physics is tested elsewhere)";
    Problem c = bed_case(0.5);
    EXPECT_EQ(compare({"arrays", GetParam()}, c.setup(), long_run(3000)), "");
}

TEST_P(Equivalence, PaperSceneIsBitIdenticalToArrays)
{
    if (GetParam() == "arrays") GTEST_SKIP() << "the reference itself";
    if (!registry().find(GetParam()).bitwise) GTEST_SKIP() << "drops the canonical order on purpose (its physics is tested elsewhere)";
    Problem c(paper_scene());
    EXPECT_EQ(compare({"arrays", GetParam()}, c.setup(), 300), "");
}

INSTANTIATE_TEST_SUITE_P(AllVariants, Equivalence, ::testing::ValuesIn(variant_names()),
                         [](const auto& info) { return param_name(info.param); });

TEST(Checker, ReportsTheFirstDifferenceWithUlps)
{
    Snapshot a;
    a.resize(3);
    Snapshot b = a;
    b.step = a.step = 7;
    b.velocity[1].y = std::nextafter(0.0, 1.0);
    b.force[2].z = 1.0;
    const auto d = first_difference(a, b);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->particle, 1);
    EXPECT_EQ(d->quantity, "velocity.y");
    EXPECT_EQ(d->ulps, 1u);
    EXPECT_EQ(ulp_distance(1.0, std::nextafter(std::nextafter(1.0, 2.0), 2.0)), 2u);
    EXPECT_EQ(ulp_distance(-1.0, std::nextafter(-1.0, 0.0)), 1u);
    EXPECT_EQ(ulp_distance(0.0, -0.0), 1u);  // different bits: the suite promises bit identity
    EXPECT_EQ(ulp_distance(2.5, 2.5), 0u);
}

TEST(Checker, DetectsADivergingVariant)
{
    // Two runs of the same variant from states one ulp apart must be reported as different.
    Problem c(dense_bed_scene(300));
    State other = c.state();
    other.trans.x[17].x = std::nextafter(other.trans.x[17].x, 1.0);
    Problem d(c.scene(), other);
    VariantRun a("arrays", c.setup()), b("arrays", d.setup());
    a.driver->run(10);
    b.driver->run(10);
    const auto diff = first_difference(a.snapshot(), b.snapshot());
    ASSERT_TRUE(diff);
    EXPECT_EQ(diff->particle, 17);
}
