// The contact laws of physics.md §9 in every variant that implements them: bit-identical to arrays at
// every step, on the dense bed settling and on the compression stage, whatever the search (cells of 2
// and 4·R_max, every pair), and across save-and-continue, where the saved stretches themselves must be
// arrays' bit for bit. Parameterised over the registry × law, so a variant joins the moment its
// supports(law) says yes; the others are skipped with a message.
//
// The bed starts from the cached settled state of the paper's law, which holds no stretches: a valid
// start (every stretch begins at zero, §9), and within a few steps thousands of persisting contacts carry
// one. The save-and-continue case asserts that they do (nonzero stretches in the saved state), so a
// variant that dropped or misplaced its memory would differ from arrays at once.
//
// MemoryEquivalence and MemoryEquivalenceStages run a representative slice in the normal suite (a few
// hundred steps); MemoryEquivalenceLong (ctest label `long`) runs the full product for longer.
#include <cmath>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "demmat/contact_model.hpp"
#include "demmat/state_file.hpp"

#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

// The laws under test, with parameters that make their springs matter on the paper's soft material
// (E = 0.3 MPa: k_n of a few hundred N/m at the bed's overlaps).
ContactModel law_named(const std::string& name)
{
    ContactModel m;
    if (name == "tsuji") {  // restitution damping, the paper's viscous tangential force: no memory
        m.damping = NormalDamping::tsuji;
        m.restitution = 0.6;
    } else if (name == "linear_history") {
        m.tangential = TangentialModel::linear_history;
        m.kt = 100.0;
        m.tangential_damping_ratio = 0.5;
    } else {  // mindlin, mindlin_sds, mindlin_sds_trapezoidal: k_t from the material's E and ν
        m.tangential = TangentialModel::mindlin;
        m.tangential_damping_ratio = 0.5;
        if (name.starts_with("mindlin_sds")) {
            m.rolling = RollingModel::sds;
            m.kr = 50.0;
            m.rolling_damping = 0.05;
            m.rolling_friction = 0.2;
        }
    }
    // The trapezoidal stretch update (§9) on every spring there is: its onset rule and the ζ each store keeps.
    if (name.ends_with("_trapezoidal")) m.stretch_update = StretchUpdate::trapezoidal;
    return m;
}
const std::vector<std::string> kLaws = {"linear_history", "mindlin", "mindlin_sds", "mindlin_sds_trapezoidal", "tsuji"};

struct SearchSetting {
    SearchMethod method;
    double cell;  // in R_max
    std::string name() const { return method == SearchMethod::all_pairs ? "all pairs" : fmt::format("cells of {}·R_max", cell); }
};
const SearchSetting kCells2{SearchMethod::cells, 2.0}, kCells4{SearchMethod::cells, 4.0}, kAllPairs{SearchMethod::all_pairs, 2.0};

// The dense bed settling (wall_speed 0) or the compression stage, under `law`, with the given search.
Problem law_case(double wall_speed, const ContactModel& law, const SearchSetting& search)
{
    return bed_case(wall_speed, [&](Scene& s) {
        s.contact_model = law;
        s.search.method = search.method;
        s.search.cell_size = search.cell;
    });
}

std::string first_difference_with_arrays(const std::string& variant, const Setup& setup, std::int64_t steps)
{
    const CompareReport r = compare_variants({"arrays", variant}, setup, steps);
    return r.difference ? r.difference->describe() : "";
}

// The stretches of two saved states, bit for bit, keys and order included; "" when they agree.
std::string stretch_difference(const State& a, const State& b)
{
    if (a.stretches.size() != b.stretches.size()) return fmt::format("{} contacts against {}", a.stretches.size(), b.stretches.size());
    for (std::size_t k = 0; k < a.stretches.size(); ++k) {
        const ContactStretch &x = a.stretches[k], &y = b.stretches[k];
        if (x.i != y.i || x.partner != y.partner || x.wall != y.wall)
            return fmt::format("contact {}: ({}, {}{}) against ({}, {}{})", k, x.i, x.wall ? "wall " : "", x.partner, y.i,
                               y.wall ? "wall " : "", y.partner);
        if (!(x.tangential == y.tangential) || !(x.rolling == y.rolling))
            return fmt::format("contact {} ({}, {}{}): the stretches differ", k, x.i, x.wall ? "wall " : "", x.partner);
    }
    return "";
}

std::size_t count_nonzero(const State& s, bool rolling)
{
    std::size_t n = 0;
    for (const ContactStretch& c : s.stretches) n += rolling ? !(c.rolling == Vec3d{}) : !(c.tangential == Vec3d{});
    return n;
}

using Param = std::tuple<std::string, std::string>;  // variant, law

class MemoryEquivalenceBase : public ::testing::TestWithParam<Param> {
protected:
    // Why this variant is not compared here, or "": the reference itself, not bitwise, or not implementing the law.
    std::string skip_reason() const
    {
        const auto& [variant, law] = GetParam();
        if (variant == "arrays") return "the reference itself";
        if (!registry().find(variant).bitwise) return "drops the canonical order on purpose (its physics is tested elsewhere)";
        if (!registry().find(variant).create()->supports(law_named(law)))
            return fmt::format("{} does not implement the law ({})", variant, law_named(law).describe());
        return "";
    }
    const std::string& variant() const { return std::get<0>(GetParam()); }
    ContactModel law() const { return law_named(std::get<1>(GetParam())); }

    // Every step of `steps` against arrays on the bed or the compression stage with one search.
    void expect_identical(double wall_speed, const SearchSetting& search, std::int64_t steps)
    {
        Problem c = law_case(wall_speed, law(), search);
        EXPECT_EQ(first_difference_with_arrays(variant(), c.setup(), steps), "")
            << (wall_speed > 0 ? "compression stage, " : "settling bed, ") << search.name();
    }

    // `first` steps of the settling bed, saved by the variant (its stretches must be arrays' bit for bit
    // and, under a law with memory, many and nonzero), written to a file and continued as the compression
    // stage (walls re-keyed by name) for `second` steps: every step against arrays continued from the same
    // file, and the last against arrays run through both stages without stopping.
    void expect_save_and_continue(const SearchSetting& search, std::int64_t first, std::int64_t second)
    {
        Problem settle = law_case(0.0, law(), search);
        VariantRun run(variant(), settle.setup());
        run.driver->run(first);
        VariantRun reference("arrays", settle.setup());
        reference.driver->run(first);
        State saved = saved_state(run, settle);
        EXPECT_EQ(stretch_difference(saved_state(reference, settle), saved), "") << "saved stretches against arrays'";
        const ContactModel m = law();
        if (m.tangential != TangentialModel::viscous) {
            EXPECT_GT(count_nonzero(saved, false), 1000u) << "tangential stretches";
        }
        if (m.rolling != RollingModel::none) {
            EXPECT_GT(count_nonzero(saved, true), 1000u) << "rolling stretches";
        }
        if (m.tangential == TangentialModel::viscous && m.rolling == RollingModel::none) {
            EXPECT_TRUE(saved.stretches.empty()) << "a law without memory saves no stretches";
        }

        const std::filesystem::path file = fmt::format("memory_equivalence_{}_{}.state", param_name(variant()), std::get<1>(GetParam()));
        Scene cont = compression_scene(settle.scene(), file, 0.5);
        saved.fingerprint = cont.fingerprint(saved.size());
        save_state(saved, file);
        Problem c2(cont);
        ASSERT_EQ(c2.state().stretches.size(), saved.stretches.size());
        EXPECT_EQ(first_difference_with_arrays(variant(), c2.setup(), second), "") << "continued, " << search.name();

        VariantRun continued(variant(), c2.setup());
        continued.driver->run(second);
        // arrays without stopping: the same two stages, the second from arrays' own state in memory
        State straight_state = saved_state(reference, settle);
        straight_state.walls = continue_walls(cont, straight_state);
        Problem straight(cont, straight_state);
        VariantRun straight_run("arrays", straight.setup());
        straight_run.driver->run(second);
        const auto d = first_difference(straight_run.snapshot(), continued.snapshot());
        EXPECT_FALSE(d) << "continued from the file against arrays without a file: " << d->describe();
        std::filesystem::remove(file);
    }
};

std::string name_of(const ::testing::TestParamInfo<Param>& info)
{
    return param_name(std::get<0>(info.param)) + "_" + std::get<1>(info.param);
}

} // namespace

// ---- the slice in the normal suite: the settling bed under each law, the compression stage and
// save-and-continue under two (every memory there is, and none), the three searches spread over them ----

class MemoryEquivalence : public MemoryEquivalenceBase {};

TEST_P(MemoryEquivalence, SettlingBedIsBitIdenticalToArrays)
{
    if (const std::string why = skip_reason(); !why.empty()) GTEST_SKIP() << why;
    expect_identical(0.0, kCells2, long_run(150));
}

INSTANTIATE_TEST_SUITE_P(RegistryTimesLaws, MemoryEquivalence,
                         ::testing::Combine(::testing::ValuesIn(variant_names()), ::testing::ValuesIn(kLaws)), name_of);

class MemoryEquivalenceStages : public MemoryEquivalenceBase {};

TEST_P(MemoryEquivalenceStages, CompressionStageIsBitIdenticalToArrays)
{
    if (const std::string why = skip_reason(); !why.empty()) GTEST_SKIP() << why;
    expect_identical(0.5, std::get<1>(GetParam()) == "tsuji" ? kAllPairs : kCells4, long_run(150));
}

TEST_P(MemoryEquivalenceStages, SaveAndContinueIsBitIdenticalToArrays)
{
    if (const std::string why = skip_reason(); !why.empty()) GTEST_SKIP() << why;
    expect_save_and_continue(kCells4, long_run(80), long_run(80));
}

INSTANTIATE_TEST_SUITE_P(RegistryTimesLaws, MemoryEquivalenceStages,
                         ::testing::Combine(::testing::ValuesIn(variant_names()), ::testing::Values("mindlin_sds", "mindlin_sds_trapezoidal", "tsuji")), name_of);

// ---- the full product (ctest label long): both stages × three searches, and save-and-continue under each ----

class MemoryEquivalenceLong : public MemoryEquivalenceBase {};

TEST_P(MemoryEquivalenceLong, BothStagesEverySearchAreBitIdenticalToArrays)
{
    if (const std::string why = skip_reason(); !why.empty()) GTEST_SKIP() << why;
    for (const SearchSetting& search : {kCells2, kCells4, kAllPairs}) {
        expect_identical(0.0, search, long_run(2000));
        expect_identical(0.5, search, long_run(2000));
    }
}

TEST_P(MemoryEquivalenceLong, SaveAndContinueEverySearchIsBitIdenticalToArrays)
{
    if (const std::string why = skip_reason(); !why.empty()) GTEST_SKIP() << why;
    for (const SearchSetting& search : {kCells2, kCells4, kAllPairs}) expect_save_and_continue(search, long_run(1000), long_run(1000));
}

INSTANTIATE_TEST_SUITE_P(RegistryTimesLaws, MemoryEquivalenceLong,
                         ::testing::Combine(::testing::ValuesIn(variant_names()), ::testing::ValuesIn(kLaws)), name_of);
