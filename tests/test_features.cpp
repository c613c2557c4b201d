// Model features (model.hpp, features.hpp): a run models what its scene needs and never less, picks
// the smallest instantiated model, and a specialised run is bit-identical, at every step, to the general
// one on a scene where the features it skips are inert.
#include <cstring>
#include <filesystem>
#include <map>

#include <gtest/gtest.h>

#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/scene_toml.hpp"
#include "demmat/state_file.hpp"

#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

ModelFeatures features(bool rot, bool fric, bool damp, bool walls, bool moving, bool poly)
{
    return {rot, fric, damp, walls, moving, poly};
}

// All 64 combinations of the six flags.
std::vector<ModelFeatures> every_combination()
{
    std::vector<ModelFeatures> out;
    for (int b = 0; b < 64; ++b)
        out.push_back(features(b & 1, b & 2, b & 4, b & 8, b & 16, b & 32));
    return out;
}

// The variants that specialise (their model() is not always the full one).
const std::vector<std::string> kSpecialising = {"arrays", "eigen_soa", "linked_list"};

bool registered(const std::string& name)
{
    for (const auto& n : variant_names())
        if (n == name) return true;
    return false;
}

bool same_bits(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b)
{
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3d)) == 0;
}

// Runs `name` twice on one scene and state, with the model it picks and with one widened by `widen`
// (a more general kernel), compares the snapshots after every step and the full saved states (both
// Gear states, orientations included) at the end. Returns "" or the first difference. Also returns
// the largest particle–particle and particle–wall contact counts seen, so a test can insist that the
// skipped feature had contacts to act on.
struct Outcome {
    std::string difference;
    ModelFeatures specialised, general;
    std::int64_t max_pp = 0, max_pw = 0;
};

Outcome specialised_vs_general(const std::string& name, const Problem& c, ModelFeatures widen, std::int64_t steps,
                               double general_gamma_n = -1.0)
{
    Setup general = c.setup();
    general.widen = widen;
    if (general_gamma_n >= 0.0) general.contact.gamma_n = general_gamma_n;  // only for the control test
    VariantRun a(name, c.setup()), b(name, general);
    Outcome o;
    o.specialised = a.variant->model();
    o.general = b.variant->model();
    for (std::int64_t k = 1; k <= steps && o.difference.empty(); ++k) {
        a.driver->step();
        b.driver->step();
        if (const auto d = first_difference(a.snapshot(), b.snapshot())) o.difference = d->describe();
        o.max_pp = std::max(o.max_pp, a.variant->counts().particle_particle);
        o.max_pw = std::max(o.max_pw, a.variant->counts().particle_wall);
    }
    if (!o.difference.empty()) return o;
    State sa, sb;
    a.variant->save(sa);
    b.variant->save(sb);
    const std::vector<Vec3d>* qa[12] = {&sa.trans.x, &sa.trans.v, &sa.trans.a, &sa.trans.b3, &sa.trans.b4, &sa.trans.b5,
                                        &sa.rot.x,   &sa.rot.v,   &sa.rot.a,   &sa.rot.b3,   &sa.rot.b4,   &sa.rot.b5};
    const std::vector<Vec3d>* qb[12] = {&sb.trans.x, &sb.trans.v, &sb.trans.a, &sb.trans.b3, &sb.trans.b4, &sb.trans.b5,
                                        &sb.rot.x,   &sb.rot.v,   &sb.rot.a,   &sb.rot.b3,   &sb.rot.b4,   &sb.rot.b5};
    for (int q = 0; q < 12; ++q)
        if (!same_bits(*qa[q], *qb[q])) o.difference = "saved state differs in Gear quantity " + std::to_string(q);
    return o;
}

// A small dense bed: 343 grains in a closed box, polydisperse, with friction and damping, from its
// loose lattice (contacts within a few dozen steps, walls touched from the start).
Scene small_bed() { return dense_bed_scene(343); }

// The small bed (monodisperse or not) after 20000 steps (0.2 s) of settling with every feature on: a
// contact-rich state (about 4 contacts per grain, a quarter of them with walls) for the tests below to
// start from, made once per process. The tests change the scene's physics; `spin` false clears the
// rotational Gear state, so that a frictionless scene needs no rotation.
Problem settled_bed(Scene scene, bool monodisperse, bool spin)
{
    static std::map<bool, State> cache;
    if (!cache.count(monodisperse)) {
        Scene base = small_bed();
        if (monodisperse) base.grid->radius_min = base.grid->radius_max;
        Problem c(base);
        VariantRun run("arrays", c.setup());
        run.driver->run(20000);
        State st;
        run.variant->save(st);
        cache[monodisperse] = st;
    }
    State st = cache[monodisperse];
    if (!spin)
        for (std::vector<Vec3d>* q : {&st.rot.x, &st.rot.v, &st.rot.a, &st.rot.b3, &st.rot.b4, &st.rot.b5})
            std::fill(q->begin(), q->end(), Vec3d{});
    st.walls = continue_walls(scene, st);
    return Problem(std::move(scene), std::move(st));
}

std::filesystem::path source_dir() { return DEMMAT_SOURCE_DIR; }

} // namespace

// ---- the choice of a model ---------------------------------------------------------------------------

TEST(ModelChoice, PicksTheSmallestInstantiatedModelThatCoversTheNeed)
{
    for (const ModelFeatures& need : every_combination()) {
        const ModelFeatures got = with_model(need, []<class M>() { return ModelFeatures::of<M>(); });
        EXPECT_TRUE(got.covers(need)) << need.name() << " got " << got.name();
        // Nothing is added but what the instantiated set forces: rotation and friction together,
        // walls with moving walls; without kAllModels, every feature but polydispersity together.
        const bool spin = need.rotation || need.friction;
        const bool any = spin || need.damping || need.walls || need.moving_walls;
        const ModelFeatures expected = kAllModels ? features(spin, spin, need.damping, need.walls || need.moving_walls, need.moving_walls, need.polydisperse)
                                                  : features(any, any, any, any, any, need.polydisperse);
        EXPECT_EQ(got, expected) << need.name();
    }
    EXPECT_EQ(with_model(ModelFeatures{}, []<class M>() { return ModelFeatures::of<M>(); }).name(), "normal");
    EXPECT_EQ(with_model(ModelFeatures::full(), []<class M>() { return ModelFeatures::of<M>(); }), ModelFeatures::of<FullModel>());
}

TEST(ModelChoice, CoversAndNames)
{
    EXPECT_TRUE(ModelFeatures::full().covers(features(true, true, true, true, true, true)));
    EXPECT_FALSE(features(true, true, true, true, false, true).covers(features(false, false, false, true, true, false)));
    EXPECT_FALSE(ModelFeatures{}.covers(features(false, false, false, false, false, true)));
    EXPECT_EQ(features(true, true, false, true, false, false).name(), "rotation+friction+walls");
    EXPECT_EQ((features(true, false, false, false, false, false) | features(false, false, true, false, false, false)).name(),
              "rotation+damping");
}

TEST(ModelChoice, FeaturesOfASceneFollowItsPhysics)
{
    Scene s = small_bed();
    State st = initial_state(s);
    EXPECT_EQ(features_of(s, st).name(), "rotation+friction+damping+walls+polydisperse");
    s.material.mu = 0.0;  // no friction: no tangential force, and no spin to carry (the grains start without)
    EXPECT_EQ(features_of(s, initial_state(s)).name(), "damping+walls+polydisperse");
    s.material.mu = 0.6;
    s.material.gamma_t = 0.0;  // min(μ·F_n, 0) = 0: no friction either
    EXPECT_EQ(features_of(s, initial_state(s)).name(), "damping+walls+polydisperse");
    s.material.gamma_n = 0.0;
    s.grid->radius_min = s.grid->radius_max;
    s.walls.clear();
    State bare = initial_state(s);
    EXPECT_EQ(features_of(s, bare).name(), "normal");
    bare.rot.v[5].z = 1.0;  // a grain given a spin: rotation (and, in the instantiated set, friction) runs
    EXPECT_TRUE(features_of(s, bare).rotation);
    bare.rot.v[5].z = -0.0;  // a signed zero counts: it could change a zero's sign somewhere
    EXPECT_TRUE(features_of(s, bare).rotation);
    s.walls = box_walls(s.domain);
    s.walls[1].velocity = {-0.5, 0.0, 0.0};
    EXPECT_EQ(features_of(s, initial_state(s)).name(), "walls+moving_walls");
}

TEST(ModelChoice, EveryCommittedSceneGetsTheExpectedModel)
{
    const std::map<std::string, std::string> expected = {
        {"paper.toml", "rotation+friction+damping+walls+polydisperse"},
        {"dense_bed_2000.toml", "rotation+friction+damping+walls+polydisperse"},
        {"dense_bed_2000_compression.toml", "rotation+friction+damping+walls+moving_walls+polydisperse"},
        {"drop.toml", "rotation+friction+damping+walls"},  // one grain: monodisperse
        {"head_on.toml", "normal"},                        // μ = γ = 0, no walls, two equal grains
    };
    std::size_t seen = 0;
    for (const auto& entry : std::filesystem::directory_iterator(source_dir() / "scenes")) {
        if (entry.path().extension() != ".toml") continue;
        const std::string file = entry.path().filename().string();
        ASSERT_TRUE(expected.count(file)) << "scenes/" << file << " has no expected model in this test";
        const Scene s = load_scene(entry.path());
        State st;
        if (s.state_file.empty() || std::filesystem::exists(s.state_file)) {
            st = initial_state(s);
        } else {
            // The settled state is made by scripts/run_main.sh, not committed: the bed's own initial
            // state has the same radii, spins-to-be (friction) and wall names.
            ASSERT_EQ(file, "dense_bed_2000_compression.toml");
            st = initial_state(load_scene(source_dir() / "scenes" / "dense_bed_2000.toml"));
            st.walls = continue_walls(s, st);
        }
        const ModelFeatures need = features_of(s, st);
        EXPECT_EQ(need.name(), expected.at(file)) << file;
        const demmat::Setup setup = demmat::Setup::make(s, st);
        for (const auto& name : variant_names()) {
            auto v = registry().find(name).create();
            v->init(setup);
            EXPECT_TRUE(v->model().covers(need)) << name << " on " << file << " runs " << v->model().name();
            if (std::find(kSpecialising.begin(), kSpecialising.end(), name) != kSpecialising.end()) {
                EXPECT_EQ(v->model(), with_model(need, []<class M>() { return ModelFeatures::of<M>(); })) << name << " on " << file;
            }
        }
        ++seen;
    }
    EXPECT_EQ(seen, expected.size());
}

// A scene that needs a feature never gets a model without it: every variant, every combination of
// needs that a scene can have.
TEST(ModelChoice, NoVariantEverModelsLessThanItsSceneNeeds)
{
    for (int b = 0; b < 32; ++b) {
        Scene s = small_bed();
        if (!(b & 1)) s.material.mu = 0.0;
        if (!(b & 2)) s.material.gamma_n = 0.0;
        if (!(b & 4)) s.walls.clear();
        if ((b & 12) == 12) s.walls[1].velocity = {-0.5, 0.0, 0.0};
        if ((b & 12) == 8) continue;  // moving walls without walls: not a scene
        if (!(b & 16)) s.grid->radius_min = s.grid->radius_max;
        Problem c(s);
        const ModelFeatures need = features_of(c.scene(), c.state());
        for (const auto& name : variant_names()) {
            VariantRun run(name, c.setup());
            EXPECT_TRUE(run.variant->model().covers(need)) << name << " needs " << need.name() << ", runs " << run.variant->model().name();
        }
    }
}

// ---- a specialised run is bit-identical to the general one where the skipped feature is inert --------

class Specialised : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override
    {
        if (!registered(GetParam())) GTEST_SKIP() << GetParam() << " is not built here";
    }
};

// The comparisons of one skipped feature need the models between the chain's ends (model.hpp).
#define SKIP_WITHOUT_EVERY_MODEL()                                                                                   \
    if (!kAllModels) GTEST_SKIP() << "this build instantiates the ends of the model chain only (DEMMAT_ALL_MODELS=OFF, " \
                                     "the sanitizer build); the normal build runs this comparison"

TEST_P(Specialised, FrictionlessRunWithoutRotationMatchesTheRotatingKernelWithMuZero)
{
    SKIP_WITHOUT_EVERY_MODEL();
    Scene s = small_bed();
    s.material.mu = 0.0;  // γ_t stays 60: the friction kernel computes u_t and min(0, γ_t·m*·|u_t|) = 0
    const Problem c = settled_bed(s, false, false);
    const Outcome o = specialised_vs_general(GetParam(), c, features(true, true, false, false, false, false), 1500);
    EXPECT_FALSE(o.specialised.rotation || o.specialised.friction) << o.specialised.name();
    EXPECT_TRUE(o.general.rotation && o.general.friction) << o.general.name();
    EXPECT_EQ(o.difference, "");
    EXPECT_GT(o.max_pp, 400);
    EXPECT_GT(o.max_pw, 80);
}

TEST_P(Specialised, UndampedRunMatchesTheDampingKernelWithGammaZero)
{
    SKIP_WITHOUT_EVERY_MODEL();
    Scene s = small_bed();
    s.material.gamma_n = 0.0;
    const Problem c = settled_bed(s, false, true);
    const Outcome o = specialised_vs_general(GetParam(), c, features(false, false, true, false, false, false), 1500);
    EXPECT_FALSE(o.specialised.damping);
    EXPECT_TRUE(o.general.damping);
    EXPECT_EQ(o.difference, "");
    EXPECT_GT(o.max_pp, 400);
}

TEST_P(Specialised, MonodisperseRunMatchesThePolydisperseKernel)
{
    const Problem c = settled_bed(small_bed(), true, true);
    const Outcome o = specialised_vs_general(GetParam(), c, features(false, false, false, false, false, true), 1500);
    EXPECT_FALSE(o.specialised.polydisperse);
    EXPECT_TRUE(o.general.polydisperse);
    EXPECT_EQ(o.difference, "");
    EXPECT_GT(o.max_pp, 400);
    EXPECT_GT(o.max_pw, 80);
}

TEST_P(Specialised, RunWithoutWallsMatchesTheWallKernel)
{
    SKIP_WITHOUT_EVERY_MODEL();
    Scene s = small_bed();
    s.walls.clear();  // the bed falls freely, its contacts kept
    const Problem c = settled_bed(s, false, true);
    const Outcome o = specialised_vs_general(GetParam(), c, features(false, false, false, true, true, false), 1500);
    EXPECT_FALSE(o.specialised.walls);
    EXPECT_TRUE(o.general.walls && o.general.moving_walls);
    EXPECT_EQ(o.difference, "");
    EXPECT_GT(o.max_pp, 400);
}

TEST_P(Specialised, FixedWallsMatchTheMovingWallKernelAtZeroVelocity)
{
    SKIP_WITHOUT_EVERY_MODEL();
    const Problem c = settled_bed(small_bed(), false, true);
    const Outcome o = specialised_vs_general(GetParam(), c, features(false, false, false, false, true, false), 1500);
    EXPECT_FALSE(o.specialised.moving_walls);
    EXPECT_TRUE(o.general.moving_walls);
    EXPECT_EQ(o.difference, "");
    EXPECT_GT(o.max_pw, 80);
}

TEST_P(Specialised, TheComparisonSeesADampingTermThatIsNotInert)
{
    // Control: the same comparison, with the general run given γ_n = 60 where the scene says 0, must
    // report a difference, so the tests above could fail.
    Scene s = small_bed();
    s.material.gamma_n = 0.0;
    const Problem c = settled_bed(s, false, true);
    const Outcome o = specialised_vs_general(GetParam(), c, features(false, false, true, false, false, false), 50, 60.0);
    EXPECT_NE(o.difference, "");
}

TEST_P(Specialised, NormalOnlyRunMatchesTheFullKernel)
{
    // Every feature inert at once: the smallest model against the paper's full one.
    Scene s = small_bed();
    s.material.mu = 0.0;
    s.material.gamma_n = 0.0;
    s.walls.clear();
    const Problem c = settled_bed(s, true, false);
    const Outcome o = specialised_vs_general(GetParam(), c, ModelFeatures::full(), 1500);
    EXPECT_EQ(o.specialised.name(), "normal");
    EXPECT_EQ(o.general, ModelFeatures::full());
    EXPECT_EQ(o.difference, "");
    EXPECT_GT(o.max_pp, 400);
}

TEST_P(Specialised, ASceneWithEveryFeatureRunsTheFullModel)
{
    Scene s = small_bed();
    s.walls[1].velocity = {-0.5, 0.0, 0.0};
    Problem c(s);
    VariantRun run(GetParam(), c.setup());
    EXPECT_EQ(run.variant->model(), ModelFeatures::full());
}

INSTANTIATE_TEST_SUITE_P(SpecialisingVariants, Specialised, ::testing::ValuesIn(kSpecialising),
                         [](const auto& info) { return param_name(info.param); });
