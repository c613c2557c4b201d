// The cuda variant (docs/cuda.md). Its kernels run here on the host backend, blocks and threads in a
// shuffled order: bit-identical to arrays at every step on a small settled bed and on its compression
// stage (a moving wall), for two shuffles and two block sizes, under the paper's law and under a §9 law
// with memory (the saved stretches bit for bit too). On a machine with a GPU the same checks run the
// device; elsewhere they skip, saying why. Also: the host backend's launch, and the registry's
// unavailable variants (how `cuda` shows without a GPU).
#include <algorithm>
#include <set>

#include <fmt/format.h>

#include <gtest/gtest.h>

#include "cuda_host.hpp"
#include "demmat/error.hpp"
#include "host_backend.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

// 400 grains settled for 15000 steps from the dense bed's loose grid (arrays), so the runs start with
// contacts; with wall_speed > 0 the compression stage of that bed (the x_max wall moving inwards); under
// `law` (the settled state holds no stretches: every contact's starts at zero).
Problem small_bed(double wall_speed, const ContactModel& law = {})
{
    static const Scene bed = dense_bed_scene(400);
    static const State settled = [] {
        Problem c(bed);
        VariantRun run("arrays", c.setup());
        run.driver->run(15000);
        return saved_state(run, c);
    }();
    State st = settled;
    Scene s = wall_speed > 0 ? compression_scene(bed, "(settled in memory)", wall_speed) : bed;
    s.contact_model = law;
    st.walls = continue_walls(s, st);
    return Problem(s, st);
}

// Mindlin's tangential spring with sds rolling resistance, as tests/test_memory_equivalence.cpp runs it.
ContactModel mindlin_sds()
{
    ContactModel m;
    m.tangential = TangentialModel::mindlin;
    m.tangential_damping_ratio = 0.5;
    m.rolling = RollingModel::sds;
    m.kr = 50.0;
    m.rolling_damping = 0.05;
    m.rolling_friction = 0.2;
    return m;
}

// "" when two states hold the same contacts with the same stretches, bit for bit and in the same order.
std::string stretch_difference(const State& a, const State& b)
{
    if (a.stretches.size() != b.stretches.size()) return fmt::format("{} stretches against {}", b.stretches.size(), a.stretches.size());
    for (std::size_t k = 0; k < a.stretches.size(); ++k) {
        const ContactStretch &x = a.stretches[k], &y = b.stretches[k];
        if (x.i != y.i || x.partner != y.partner || x.wall != y.wall || !(x.tangential == y.tangential) || !(x.rolling == y.rolling))
            return fmt::format("stretch {} ({}, {}{}) differs", k, x.i, x.wall ? "wall " : "", x.partner);
    }
    return "";
}

struct Lockstep {
    std::string difference;  // "" when every run matched arrays at every step, and in the saved state
    ContactCounts counts;    // arrays' at the end
    State saved;             // arrays' saved state at the end
};

// arrays and the given variants in lockstep, compared bit for bit after every step (snapshot and
// contact counts) and in the saved state at the end.
Lockstep lockstep(const Setup& setup, std::int64_t steps, std::vector<std::unique_ptr<Variant>> runs)
{
    auto ref = registry().find("arrays").create();
    Driver ref_driver(*ref, setup);
    std::vector<std::unique_ptr<Driver>> drivers;
    for (auto& v : runs) drivers.push_back(std::make_unique<Driver>(*v, setup));
    Lockstep out;
    Snapshot a, b;
    for (std::int64_t k = 0; k <= steps && out.difference.empty(); ++k) {
        if (k > 0) {
            ref_driver.step();
            for (auto& d : drivers) d->step();
        }
        ref->snapshot(a);
        const ContactCounts ca = ref->counts();
        for (std::size_t v = 0; v < runs.size() && out.difference.empty(); ++v) {
            runs[v]->snapshot(b);
            if (const auto d = first_difference(a, b)) out.difference = fmt::format("run {}: {}", v, d->describe());
            const ContactCounts cb = runs[v]->counts();
            if (cb.particle_particle != ca.particle_particle || cb.particle_wall != ca.particle_wall || cb.candidates != ca.candidates)
                out.difference = fmt::format("run {} step {}: counts {}/{}/{} against arrays' {}/{}/{}", v, k, cb.particle_particle,
                                             cb.particle_wall, cb.candidates, ca.particle_particle, ca.particle_wall, ca.candidates);
        }
    }
    State sa, sb;
    ref->save(sa);
    for (std::size_t v = 0; v < runs.size() && out.difference.empty(); ++v) {
        runs[v]->save(sb);
        if (!(sa.trans.x == sb.trans.x && sa.trans.b5 == sb.trans.b5 && sa.rot.v == sb.rot.v && sa.rot.b5 == sb.rot.b5 &&
              sa.radius == sb.radius && sa.step == sb.step && sa.walls.size() == sb.walls.size()))
            out.difference = fmt::format("run {}: the saved state differs", v);
        else if (const std::string d = stretch_difference(sa, sb); !d.empty())
            out.difference = fmt::format("run {}: the saved stretches differ: {}", v, d);
    }
    out.counts = ref->counts();
    out.saved = sa;
    return out;
}

std::vector<std::unique_ptr<Variant>> two_shuffles()
{
    std::vector<std::unique_ptr<Variant>> v;
    v.push_back(make_cuda_host_variant(1, 128));
    v.push_back(make_cuda_host_variant(20261202, 32));
    return v;
}

// Why the device variant cannot run here, or "" when it can.
std::string device_missing()
{
    for (const auto& v : registry().all())
        if (v.name == "cuda") return "";
    for (const auto& [name, why] : registry().unavailable())
        if (name == "cuda") return why;
    return "the cuda variant is not built (no nvcc when this build was configured)";
}

std::vector<std::unique_ptr<Variant>> device_run()
{
    std::vector<std::unique_ptr<Variant>> v;
    v.push_back(registry().find("cuda").create());
    return v;
}

} // namespace

TEST(CudaHost, LaunchRunsEveryThreadOnceInShuffledBlockOrder)
{
    auto order = [](std::uint64_t seed) {
        gpu::HostBackend be({seed, 8});
        std::vector<unsigned> seen;
        // 100 items in 13 blocks of 8: the body sees every (block, thread), in the backend's order.
        be.launch(100, [&](unsigned block, unsigned thread, unsigned dim) { seen.push_back(block * dim + thread); });
        return seen;
    };
    const auto a = order(1), b = order(2);
    ASSERT_EQ(a.size(), 104u);
    EXPECT_EQ(std::set<unsigned>(a.begin(), a.end()).size(), 104u);
    EXPECT_FALSE(std::is_sorted(a.begin(), a.end()));
    EXPECT_NE(a, b);
    EXPECT_EQ(std::set<unsigned>(b.begin(), b.end()), std::set<unsigned>(a.begin(), a.end()));
}

TEST(CudaHost, SettledBedIsBitIdenticalToArraysAtEveryStepForTwoShuffles)
{
    Problem c = small_bed(0.0);
    const Lockstep r = lockstep(c.setup(), 300, two_shuffles());
    EXPECT_EQ(r.difference, "");
    EXPECT_GT(r.counts.particle_particle, 400);  // a contact-rich bed, not a cloud
    EXPECT_GT(r.counts.particle_wall, 20);
}

TEST(CudaHost, CompressionStageIsBitIdenticalToArraysAtEveryStepForTwoShuffles)
{
    Problem c = small_bed(0.5);
    ASSERT_TRUE(c.scene().walls.size() > 0);
    const Lockstep r = lockstep(c.setup(), 300, two_shuffles());
    EXPECT_EQ(r.difference, "");
    EXPECT_GT(r.counts.particle_particle, 400);
}

TEST(CudaHost, LawWithMemoryIsBitIdenticalToArraysAtEveryStepForTwoShuffles)
{
    // Each pair's stretches are kept in both of its particles' rows and advanced by both threads; the
    // rows follow the particles through the re-sort of every search. Settling and compressed, the saved
    // stretches arrays' bit for bit, and many of them nonzero (the memory was exercised).
    for (double wall_speed : {0.0, 0.5}) {
        Problem c = small_bed(wall_speed, mindlin_sds());
        const Lockstep r = lockstep(c.setup(), 300, two_shuffles());
        EXPECT_EQ(r.difference, "") << "wall speed " << wall_speed;
        std::size_t pairs = 0, walls = 0;
        for (const ContactStretch& k : r.saved.stretches)
            if (!(k.tangential == Vec3d{}) && !(k.rolling == Vec3d{})) ++(k.wall ? walls : pairs);
        EXPECT_GT(pairs, 300u);
        EXPECT_GT(walls, 20u);
    }
}

TEST(CudaHost, ContinuesFromASavedStateWithStretchesAsArraysDoes)
{
    // Saved by cuda_host mid-run (state format v2: its stretches), then continued by cuda_host and by arrays
    // from that state: both continuations the same at every step.
    Problem c = small_bed(0.0, mindlin_sds());
    auto v = make_cuda_host_variant(3, 64);
    Driver d(*v, c.setup());
    d.run(150);
    State mid;
    v->save(mid);
    ASSERT_GT(mid.stretches.size(), 300u);
    const Problem cont(c.scene(), mid);
    EXPECT_EQ(lockstep(cont.setup(), 150, two_shuffles()).difference, "");
}

TEST(CudaHost, AllPairsAndWideCellsGiveTheSameTrajectory)
{
    // The device search (hashed cells, or every pair with no cells) cannot change the contact set.
    for (auto [method, cell] : {std::pair{SearchMethod::all_pairs, 2.0}, {SearchMethod::cells, 4.0}}) {
        const Problem bed = small_bed(0.0);
        Scene s = bed.scene();
        s.search.method = method;
        s.search.cell_size = cell;
        const Problem c(std::move(s), bed.state());
        std::vector<std::unique_ptr<Variant>> v;
        v.push_back(make_cuda_host_variant(7, 64));
        EXPECT_EQ(lockstep(c.setup(), 100, std::move(v)).difference, "") << "cell " << cell;
    }
}

TEST(CudaHost, CapacityOverflowStopsTheRunNamingTheCapacity)
{
    const Problem bed = small_bed(0.0);
    Scene s = bed.scene();
    s.capacity.contacts_per_particle = 2;
    const Problem c(std::move(s), bed.state());
    auto v = make_cuda_host_variant(1);
    Driver d(*v, c.setup());
    try {
        d.step();
        FAIL() << "no capacity error";
    } catch (const CapacityError& e) {
        EXPECT_NE(std::string(e.what()).find("capacity.contacts_per_particle = 2 exceeded"), std::string::npos) << e.what();
    }
}

TEST(Registry, AnUnavailableVariantIsListedApartWithItsReason)
{
    Registry r;
    r.add({"here", "runs", [] { return registry().find("arrays").create(); }});
    VariantInfo gone{"gone", "needs a device", [] { return registry().find("arrays").create(); }};
    gone.unavailable = [] { return std::string("no device found"); };
    r.add(gone);
    VariantInfo fine{"fine", "checks and runs", [] { return registry().find("arrays").create(); }};
    fine.unavailable = [] { return std::string(); };
    r.add(fine);
    EXPECT_EQ(r.names(), (std::vector<std::string>{"here", "fine"}));
    ASSERT_EQ(r.unavailable().size(), 1u);
    EXPECT_EQ(r.unavailable()[0].first, "gone");
    try {
        r.find("gone");
        FAIL() << "found an unavailable variant";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "variant 'gone' cannot run here: no device found");
    }
}

TEST(CudaDevice, SettledBedIsBitIdenticalToArraysAtEveryStep)
{
    if (const std::string why = device_missing(); !why.empty()) GTEST_SKIP() << "cuda: " << why;
    Problem c = small_bed(0.0);
    EXPECT_EQ(lockstep(c.setup(), 300, device_run()).difference, "");
}

TEST(CudaDevice, CompressionStageIsBitIdenticalToArraysAtEveryStep)
{
    if (const std::string why = device_missing(); !why.empty()) GTEST_SKIP() << "cuda: " << why;
    Problem c = small_bed(0.5);
    EXPECT_EQ(lockstep(c.setup(), 300, device_run()).difference, "");
}

TEST(CudaDevice, LawWithMemoryIsBitIdenticalToArraysAtEveryStep)
{
    if (const std::string why = device_missing(); !why.empty()) GTEST_SKIP() << "cuda: " << why;
    for (double wall_speed : {0.0, 0.5}) {
        Problem c = small_bed(wall_speed, mindlin_sds());
        EXPECT_EQ(lockstep(c.setup(), 300, device_run()).difference, "") << "wall speed " << wall_speed;
    }
}
