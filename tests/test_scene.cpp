// Scenes: the generator is deterministic, scene files round-trip, and bad scenes are refused with a
// one-line message naming the problem.
#include <gtest/gtest.h>

#include "demmat/error.hpp"
#include "demmat/stability.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

TEST(Generator, SameSeedSameStateOtherSeedOtherState)
{
    const State a = initial_state(dense_bed_scene(500, 5));
    const State b = initial_state(dense_bed_scene(500, 5));
    const State c = initial_state(dense_bed_scene(500, 6));
    EXPECT_EQ(a.radius, b.radius);
    EXPECT_TRUE(a.trans.v[123] == b.trans.v[123]);
    EXPECT_NE(a.radius, c.radius);
    for (double r : a.radius) {
        EXPECT_GE(r, 0.003);
        EXPECT_LE(r, 0.005);
    }
    for (const Vec3d& v : a.trans.v) EXPECT_LE(std::sqrt(dot(v, v)), 1.0 + 1e-15);
}

TEST(Generator, DenseBedsGrowWiderNotDeeperBeyondTheLayerCap)
{
    // Up to 12³ grains a cube of sites; beyond, 12 layers and a wider square base (scenes.cpp says why).
    auto layers = [](const Scene& s) { return s.grid->cells[2]; };
    const Scene cube = dense_bed_scene(1000), bed2000 = dense_bed_scene(2000), wide = dense_bed_scene(64000);
    EXPECT_EQ(cube.grid->cells[0], 10);
    EXPECT_EQ(layers(cube), 10);
    EXPECT_EQ(bed2000.grid->cells[0], 13);  // the main benchmark's bed (scenes/dense_bed_2000.toml)
    EXPECT_EQ(layers(bed2000), 12);
    EXPECT_EQ(layers(wide), 12);
    EXPECT_GE(wide.grid->cells[0] * wide.grid->cells[1] * layers(wide), 64000);
    EXPECT_LT(wide.grid->cells[0] * wide.grid->cells[1] * (layers(wide) - 1), 64000);  // no empty layer
    EXPECT_DOUBLE_EQ(wide.domain.max.z, double(layers(wide)) * wide.grid->spacing);
    EXPECT_EQ(layers(dense_bed_scene(64000, 1, 20)), 20);
    EXPECT_THROW(dense_bed_scene(100, 1, 0), Error);
}

TEST(Generator, InitialAccelerationIsGravityWhenNothingTouches)
{
    const State s = initial_state(paper_scene());
    EXPECT_EQ(s.size(), 1000u);
    for (std::size_t i = 0; i < s.size(); ++i) {
        EXPECT_EQ(s.trans.a[i].z, -10.0);
        EXPECT_EQ(s.trans.b3[i].z, 0.0);
    }
}

TEST(SceneFile, RoundTripsThroughToml)
{
    for (const Scene& s : {paper_scene(), dense_bed_scene(1234, 9), head_on_scene(2.0), drop_scene(0.002)}) {
        const Scene r = parse_scene(scene_to_toml(s), "roundtrip");
        EXPECT_EQ(r.name, s.name);
        EXPECT_EQ(r.dt, s.dt);
        EXPECT_EQ(r.walls.size(), s.walls.size());
        EXPECT_EQ(r.fingerprint(10), s.fingerprint(10));
        const State a = initial_state(s), b = initial_state(r);
        EXPECT_EQ(a.radius, b.radius);
        EXPECT_EQ(a.trans.x.size(), b.trans.x.size());
        for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a.trans.x[i] == b.trans.x[i]);
    }
}

namespace {
std::string error_of(const std::string& toml)
{
    try {
        const Scene s = parse_scene(toml, "bad.toml");
        initial_state(s);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}
const char* kGood = R"(
[time]
dt = 1e-5
[domain]
min = [0, 0, 0]
max = [0.1, 0.1, 0.1]
[[wall]]
face = "z_min"
[particles]
source = "list"
[[particles.particle]]
radius = 0.004
position = [0.05, 0.05, 0.05]
)";
} // namespace

TEST(SceneFile, BadScenesGiveOneLineErrors)
{
    EXPECT_EQ(error_of(kGood), "");
    auto with = [](const std::string& from, const std::string& to) {
        std::string s = kGood;
        s.replace(s.find(from), from.size(), to);
        return s;
    };
    const std::pair<std::string, std::string> cases[] = {
        {with("radius = 0.004", "radius = -0.004"), "must be > 0"},
        {with("dt = 1e-5", "dt = 0"), "'time.dt' must be > 0"},
        {with("dt = 1e-5", "dtt = 1e-5"), "missing key 'dt'"},
        {with("[time]", "[time]\nextra = 1"), "unknown key 'extra'"},
        {with("source = \"list\"", "source = \"cloud\""), "must be grid, list or state"},
        {with("position = [0.05, 0.05, 0.05]", "position = [0.05, 0.05, 0.002]"), "overlaps wall 'z_min'"},
        {with("position = [0.05, 0.05, 0.05]", "position = [0.05, 0.05, 0.5]"), "outside the domain"},
        {with("position = [0.05, 0.05, 0.05]", "position = [0.05, 0.05]"), "array of 3 numbers"},
        {with("dt = 1e-5", "dt = \"fast\""), "must be a number"},
        {with("dt = 1e-5", "dt = 1e-5\ngravity = [0, 0, nan]"), "must be finite"},
        {with("max = [0.1, 0.1, 0.1]", "max = [0.1, 0.1"), "TOML syntax error"},
        {with("face = \"z_min\"", "face = \"floor\""), "'wall[0].face': unknown box face 'floor'"},
        {std::string(kGood) + "[search]\nmethod = \"octree\"\n", "unknown search method 'octree'"},
        {std::string(kGood) + "[[particles.particle]]\nradius = 0.004\nposition = [0.053, 0.05, 0.05]\n", "particles 0 and 1 overlap"},
    };
    for (const auto& [toml, expect] : cases) {
        const std::string e = error_of(toml);
        EXPECT_NE(e.find(expect), std::string::npos) << "expected '" << expect << "', got '" << e << "'";
        EXPECT_EQ(e.find('\n'), std::string::npos) << "not one line: " << e;
    }
}

TEST(SceneFile, AWallNormalOfHugeOrTinyComponentsIsNormalised)
{
    // n·n of (1e300, 1e300, 0) overflows and of (1e-320, 0, 0) underflows: the normal must still be a unit
    // vector (it was (0, 0, 0), and the scene was refused as a particle overlapping the wall).
    const std::pair<std::string, Vec3d> cases[] = {{"[1e300, 1e300, 0]", {std::sqrt(0.5), std::sqrt(0.5), 0.0}},
                                                    {"[1e-320, 0, 0]", {1.0, 0.0, 0.0}},
                                                    {"[0, -3e-200, 4e-200]", {0.0, -0.6, 0.8}}};
    for (const auto& [normal, unit] : cases) {
        const std::string text = "[time]\ndt = 1e-5\n[domain]\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n[[wall]]\npoint = [0, 0, 0]\nnormal = " +
                                 normal + "\n[particles]\nsource = \"state\"\nfile = \"x.state\"\n";
        const Vec3d n = parse_scene(text, "normal").walls.at(0).normal;
        EXPECT_NEAR(n.x, unit.x, 1e-15) << normal;
        EXPECT_NEAR(n.y, unit.y, 1e-15) << normal;
        EXPECT_NEAR(n.z, unit.z, 1e-15) << normal;
    }
}

TEST(SceneFile, TimeStepAboveTheRayleighTimeIsRefused)
{
    // The drop scene's Hertz contact time at its largest impact speed is 2.33e-3 s; the Rayleigh time of
    // a 4 mm grain of the paper's material is 1.3e-3 s (docs/stability.md).
    Scene s = drop_scene();
    s.dt = 1.6e-4;  // 0.07 t_c: above the 0.05 t_c warning, below gear5's limit 0.09 t_c and 0.2 T_R
    const std::string warning = check_time_step(s, initial_state(s));
    EXPECT_NE(warning.find("contact time"), std::string::npos) << warning;
    s.dt = 1e-3;  // 0.43 t_c: refused by the Hertz check
    EXPECT_THROW(check_time_step(s, initial_state(s)), Error);
    s.dt = 2e-3;  // above the Rayleigh time
    EXPECT_THROW(check_time_step(s, initial_state(s)), Error);
}
