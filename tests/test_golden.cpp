// Frozen reference data (tests/golden/*.golden), in the manner of LAMMPS's force-style YAML files. The
// equivalence tests compare every variant with arrays, so a wrong edit to the shared contact law or
// integrator changes every variant alike and they stay green; these files do not change with the code.
//
//   demmat_golden --case tests/golden/FILE.golden   one case: every registered bitwise variant, bit for bit
//   demmat_golden --write tests/golden/             regenerate the outputs of every file (or of named files)
//
// A file is blocks, each opened by a line "@ NAME ...", after comment lines (#) kept as they are:
//   trajectory case (inputs, written by hand)   @ scene (TOML, docs/scene-format.md), @ steps K1 K2 ...,
//                                               @ settle S (optional: how the start below was made)
//   its start (input, frozen once written)      @ start: per particle radius, x, v, ω (12 hexfloats)
//   its outputs (written by --write)            @ initial acceleration / angular_acceleration (t = 0,
//                                               the reference forces), @ step K position / velocity /
//                                               angular_velocity / force / torque
//   law table (inputs by hand)                  @ law: "params hertz_pp hertz_pw gamma_n gamma_t mu", then
//                                               "pair xi xj vi vj wi wj ri rj mi mj" and
//                                               "wall xi vi wi ri mi point normal vw" lines (decimal)
//   its outputs                                 @ law results: touch, f_i, t_i, t_j, overlap per line
// Outputs are hexfloats, so the bits are exact. --write keeps the inputs and a start block it finds
// (delete the block to make a new start: S steps of arrays with the walls held still, from the scene).
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "demmat/io.hpp"
#include "demmat/model.hpp"
#include "demmat/scene_toml.hpp"
#include "demmat/state_file.hpp"

#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

// ---- the file -------------------------------------------------------------------------------------

struct Block {
    std::string name;                // the header after "@ "
    std::vector<std::string> lines;  // its lines, up to the next header
};

struct GoldenFile {
    std::filesystem::path path;
    std::vector<std::string> preamble;  // comment lines before the first block
    std::vector<Block> blocks;

    const Block* find(const std::string& name) const
    {
        for (const Block& b : blocks)
            if (b.name == name) return &b;
        return nullptr;
    }
    const Block& need(const std::string& name) const
    {
        const Block* b = find(name);
        if (!b) throw Error(fmt::format("{}: no '@ {}' block (regenerate: demmat_golden --write {})", path.string(), name, path.string()));
        return *b;
    }
    // The header's words after `word` on the block whose name starts with it ("steps 1 200").
    std::vector<std::string> header_args(const std::string& word) const
    {
        for (const Block& b : blocks) {
            std::istringstream in(b.name);
            std::string w;
            in >> w;
            if (w != word) continue;
            std::vector<std::string> out;
            while (in >> w) out.push_back(w);
            return out;
        }
        return {};
    }
};

GoldenFile read_golden(const std::filesystem::path& path)
{
    std::ifstream in(path);
    if (!in) throw Error(fmt::format("{}: cannot open golden file", path.string()));
    GoldenFile g;
    g.path = path;
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("@ ", 0) == 0) g.blocks.push_back({line.substr(2), {}});
        else if (g.blocks.empty()) g.preamble.push_back(line);
        else g.blocks.back().lines.push_back(line);
    }
    return g;
}

std::string hex(double v) { return fmt::format("{:a}", v); }

std::vector<double> numbers(const std::string& line, const std::string& where)
{
    std::vector<double> out;
    std::istringstream in(line);
    std::string w;
    while (in >> w) {
        char* end = nullptr;
        const double v = std::strtod(w.c_str(), &end);  // reads decimals and hexfloats alike
        if (end == w.c_str() || *end != '\0') throw Error(fmt::format("{}: '{}' is not a number", where, w));
        out.push_back(v);
    }
    return out;
}

std::vector<Vec3d> vectors(const GoldenFile& g, const std::string& name, std::size_t n)
{
    const Block& b = g.need(name);
    if (b.lines.size() != n) throw Error(fmt::format("{}: '@ {}' has {} lines for {} particles", g.path.string(), name, b.lines.size(), n));
    std::vector<Vec3d> out;
    for (const std::string& l : b.lines) {
        const auto v = numbers(l, g.path.string());
        if (v.size() != 3) throw Error(fmt::format("{}: '@ {}': a line of {} numbers, 3 expected", g.path.string(), name, v.size()));
        out.push_back({v[0], v[1], v[2]});
    }
    return out;
}

Block vector_block(const std::string& name, const std::vector<Vec3d>& v)
{
    Block b{name, {}};
    for (const Vec3d& x : v) b.lines.push_back(fmt::format("{} {} {}", hex(x.x), hex(x.y), hex(x.z)));
    return b;
}

// ---- a trajectory case ------------------------------------------------------------------------------

constexpr const char* kSnapshotFields[] = {"position", "velocity", "angular_velocity", "force", "torque"};

std::vector<Vec3d> Snapshot::*snapshot_field(int k)
{
    constexpr std::vector<Vec3d> Snapshot::*fields[] = {&Snapshot::position, &Snapshot::velocity, &Snapshot::angular_velocity,
                                                        &Snapshot::force, &Snapshot::torque};
    return fields[k];
}

Scene golden_scene(const GoldenFile& g)
{
    std::string toml;
    for (const std::string& l : g.need("scene").lines) toml += l + "\n";
    return parse_scene(toml, g.path.string());
}

std::vector<std::int64_t> golden_steps(const GoldenFile& g)
{
    std::vector<std::int64_t> out;
    for (const std::string& w : g.header_args("steps")) out.push_back(std::stoll(w));
    if (out.empty() || !std::is_sorted(out.begin(), out.end()) || out.front() < 1)
        throw Error(fmt::format("{}: '@ steps K1 K2 ...' must list step counts >= 1 in ascending order", g.path.string()));
    return out;
}

// The state the case starts from: the scene's, with radii, positions, velocities and spins from the
// start block, and the t = 0 accelerations of the shared code (b3 = b4 = b5 = 0).
State golden_start(const Scene& scene, const Block& start, const std::string& where)
{
    State s = initial_state(scene);
    if (start.lines.size() != s.size())
        throw Error(fmt::format("{}: '@ start' has {} lines, the scene {} particles", where, start.lines.size(), s.size()));
    for (std::size_t i = 0; i < s.size(); ++i) {
        const auto v = numbers(start.lines[i], where);
        if (v.size() != 10) throw Error(fmt::format("{}: '@ start' line {}: 10 numbers expected (radius, x, v, w)", where, i + 1));
        s.radius[i] = v[0];
        s.trans.x[i] = {v[1], v[2], v[3]};
        s.trans.v[i] = {v[4], v[5], v[6]};
        s.rot.v[i] = {v[7], v[8], v[9]};
    }
    initial_accelerations(scene, s);
    return s;
}

// A start for a new file: the scene's own state after `settle` steps of arrays with every wall held
// still (so the moving walls start from the scene's positions), contacts and all.
Block make_start(const Scene& scene, std::int64_t settle)
{
    Scene still = scene;
    for (Wall& w : still.walls) w.velocity = {};
    Problem c(still);
    VariantRun run("arrays", c.setup());
    run.driver->run(settle);
    const Snapshot s = run.snapshot();
    Block b{"start", {}};
    for (std::size_t i = 0; i < c.state().size(); ++i) {
        const Vec3d &x = s.position[i], &v = s.velocity[i], &w = s.angular_velocity[i];
        b.lines.push_back(fmt::format("{} {} {} {} {} {} {} {} {} {}", hex(c.state().radius[i]), hex(x.x), hex(x.y), hex(x.z), hex(v.x),
                                      hex(v.y), hex(v.z), hex(w.x), hex(w.y), hex(w.z)));
    }
    return b;
}

// Runs `variant` from the case's start and returns its snapshot after each of `steps`.
std::vector<Snapshot> run_case(const std::string& variant, const Setup& setup, const std::vector<std::int64_t>& steps)
{
    VariantRun run(variant, setup);
    std::vector<Snapshot> out;
    for (std::int64_t k : steps) {
        run.driver->run(k - run.driver->current_step());
        out.push_back(run.snapshot());
        out.back().step = k;
    }
    return out;
}

Snapshot expected_snapshot(const GoldenFile& g, std::int64_t step, std::size_t n)
{
    Snapshot s;
    s.step = step;
    for (int k = 0; k < 5; ++k) s.*snapshot_field(k) = vectors(g, fmt::format("step {} {}", step, kSnapshotFields[k]), n);
    return s;
}

// ---- the law table ----------------------------------------------------------------------------------

struct LawRow {
    bool touch = false;
    ContactForce<double> out;
};

Vec3d vec_at(const std::vector<double>& v, std::size_t k) { return {v[k], v[k + 1], v[k + 2]}; }

// The scalar law of the general model on every row of the '@ law' block.
std::vector<LawRow> evaluate_law(const GoldenFile& g)
{
    const std::string where = g.path.string();
    ContactParams<double> p;
    bool have_params = false;
    std::vector<LawRow> rows;
    for (const std::string& l : g.need("law").lines) {
        std::istringstream in(l);
        std::string kind;
        if (!(in >> kind) || kind[0] == '#') continue;
        std::string rest;
        std::getline(in, rest);
        const auto v = numbers(rest, where);
        if (kind == "params" && v.size() == 5) {
            p = {v[0], v[1], v[2], v[3], v[4]};
            have_params = true;
        } else if (kind == "pair" && v.size() == 22 && have_params) {
            LawRow r;
            r.touch = particle_contact<FullModel>(vec_at(v, 0), vec_at(v, 3), vec_at(v, 6), vec_at(v, 9), vec_at(v, 12), vec_at(v, 15),
                                                  v[18], v[19], v[20], v[21], p, r.out);
            rows.push_back(r);
        } else if (kind == "wall" && v.size() == 20 && have_params) {
            LawRow r;
            r.touch = wall_contact<FullModel>(vec_at(v, 0), vec_at(v, 3), vec_at(v, 6), v[9], v[10], vec_at(v, 11), vec_at(v, 14),
                                              vec_at(v, 17), p, r.out);
            rows.push_back(r);
        } else {
            throw Error(fmt::format("{}: '@ law' line '{}': expected params (5 numbers, first), pair (22) or wall (20)", where, l));
        }
    }
    return rows;
}

std::vector<double> law_values(const LawRow& r)
{
    const ContactForce<double>& o = r.out;
    return {r.touch ? 1.0 : 0.0, o.f_i.x, o.f_i.y, o.f_i.z, o.t_i.x, o.t_i.y, o.t_i.z, o.t_j.x, o.t_j.y, o.t_j.z, o.overlap};
}

// ---- writing ------------------------------------------------------------------------------------------

void write_golden(const std::filesystem::path& path)
{
    GoldenFile g = read_golden(path);
    std::vector<Block> out;
    for (const Block& b : g.blocks)  // the inputs, as written
        if (b.name == "scene" || b.name == "law" || b.name.rfind("steps", 0) == 0 || b.name.rfind("settle", 0) == 0 || b.name == "start")
            out.push_back(b);
    if (g.find("law")) {
        Block r{"law results", {}};
        for (const LawRow& row : evaluate_law(g)) {
            std::string line;
            for (double v : law_values(row)) line += (line.empty() ? "" : " ") + hex(v);
            r.lines.push_back(line);
        }
        out.push_back(r);
    } else {
        const Scene scene = golden_scene(g);
        if (!g.find("start")) {
            const auto settle = g.header_args("settle");
            out.push_back(make_start(scene, settle.empty() ? 0 : std::stoll(settle.front())));
        }
        g.blocks = out;
        const State start = golden_start(scene, g.need("start"), path.string());
        out.push_back(vector_block("initial acceleration", start.trans.a));
        out.push_back(vector_block("initial angular_acceleration", start.rot.a));
        const Setup setup = Setup::make(scene, start);
        const auto steps = golden_steps(g);
        const auto snaps = run_case("arrays", setup, steps);
        for (std::size_t s = 0; s < steps.size(); ++s)
            for (int k = 0; k < 5; ++k)
                out.push_back(vector_block(fmt::format("step {} {}", steps[s], kSnapshotFields[k]), snaps[s].*snapshot_field(k)));
    }
    std::string text;
    for (const std::string& l : g.preamble) text += l + "\n";
    for (const Block& b : out) {
        text += "@ " + b.name + "\n";
        for (const std::string& l : b.lines) text += l + "\n";
    }
    write_atomically(path, text);
}

// ---- the tests ------------------------------------------------------------------------------------------

const GoldenFile* g_case = nullptr;  // --case FILE

bool is_law(const GoldenFile& g) { return g.find("law") != nullptr; }

class Golden : public ::testing::TestWithParam<std::string> {};

TEST_P(Golden, VariantReproducesTheFrozenTrajectory)
{
    if (is_law(*g_case)) GTEST_SKIP() << "a law table";
    if (!registry().find(GetParam()).bitwise) GTEST_SKIP() << "drops the canonical order on purpose (not bit-identical by design)";
    const Scene scene = golden_scene(*g_case);
    if (!registry().find(GetParam()).create()->supports(scene.contact_model))
        GTEST_SKIP() << "does not implement the case's contact law (" << scene.contact_model.describe() << ")";
    const State start = golden_start(scene, g_case->need("start"), g_case->path.string());
    const demmat::Setup setup = demmat::Setup::make(scene, start);
    const auto steps = golden_steps(*g_case);
    const auto got = run_case(GetParam(), setup, steps);
    for (std::size_t s = 0; s < steps.size(); ++s) {
        auto d = first_difference(expected_snapshot(*g_case, steps[s], start.size()), got[s]);
        if (d) {
            d->variant_a = "file";
            d->variant_b = GetParam();
        }
        EXPECT_FALSE(d) << g_case->path.string() << ": " << d->describe();
    }
    // A case worth freezing has contacts: the law was exercised.
    VariantRun probe(GetParam(), setup);
    probe.driver->step();
    EXPECT_GT(probe.variant->counts().particle_particle + probe.variant->counts().particle_wall, 0);
}

TEST(GoldenStart, InitialAccelerationsMatchTheFile)
{
    if (is_law(*g_case)) GTEST_SKIP() << "a law table";
    const Scene scene = golden_scene(*g_case);
    const State start = golden_start(scene, g_case->need("start"), g_case->path.string());
    Snapshot expect, got;
    expect.position = vectors(*g_case, "initial acceleration", start.size());
    expect.velocity = vectors(*g_case, "initial angular_acceleration", start.size());
    got.position = start.trans.a;
    got.velocity = start.rot.a;
    for (Snapshot* s : {&expect, &got}) {
        s->angular_velocity = s->force = s->torque = std::vector<Vec3d>(start.size());
    }
    auto d = first_difference(expect, got);  // "position" is a, "velocity" α
    if (d) {
        d->variant_a = "file";
        d->variant_b = "initial_accelerations";
    }
    EXPECT_FALSE(d) << g_case->path.string() << ": (position = a, velocity = α at t = 0) " << d->describe();
}

TEST(GoldenLaw, ScalarLawReproducesTheTable)
{
    if (!is_law(*g_case)) GTEST_SKIP() << "a trajectory case";
    const auto rows = evaluate_law(*g_case);
    const Block& results = g_case->need("law results");
    ASSERT_EQ(rows.size(), results.lines.size()) << "rows of '@ law' and '@ law results'";
    const char* names[] = {"touch", "f_i.x", "f_i.y", "f_i.z", "t_i.x", "t_i.y", "t_i.z", "t_j.x", "t_j.y", "t_j.z", "overlap"};
    for (std::size_t r = 0; r < rows.size(); ++r) {
        const auto expect = numbers(results.lines[r], g_case->path.string());
        const auto got = law_values(rows[r]);
        ASSERT_EQ(expect.size(), got.size());
        for (std::size_t k = 0; k < got.size(); ++k)
            EXPECT_EQ(ulp_distance(expect[k], got[k]), 0u)
                << "row " << r + 1 << " " << names[k] << ": file " << hex(expect[k]) << ", law " << hex(got[k]);
    }
}

INSTANTIATE_TEST_SUITE_P(Variants, Golden, ::testing::ValuesIn(variant_names()),
                         [](const ::testing::TestParamInfo<std::string>& i) { return param_name(i.param); });

int usage()
{
    std::cerr << "usage: demmat_golden --case FILE.golden [gtest options] | demmat_golden --write DIR_OR_FILE...\n";
    return 2;
}

} // namespace

int main(int argc, char** argv)
{
    ::testing::InitGoogleTest(&argc, argv);
    try {
        if (argc >= 3 && std::string(argv[1]) == "--write") {
            for (int a = 2; a < argc; ++a) {
                std::vector<std::filesystem::path> files;
                if (std::filesystem::is_directory(argv[a])) {
                    for (const auto& e : std::filesystem::directory_iterator(argv[a]))
                        if (e.path().extension() == ".golden") files.push_back(e.path());
                    std::sort(files.begin(), files.end());
                } else {
                    files.push_back(argv[a]);
                }
                for (const auto& f : files) {
                    write_golden(f);
                    std::cout << "wrote " << f.string() << "\n";
                }
            }
            return 0;
        }
        if (argc != 3 || std::string(argv[1]) != "--case") return usage();
        static const GoldenFile file = read_golden(argv[2]);
        g_case = &file;
    } catch (const Error& e) {
        std::cerr << "demmat_golden: " << e.what() << "\n";
        return 2;
    }
    return RUN_ALL_TESTS();
}
