#pragma once
// The fast variant's test helpers (test_fast.cpp, test_fast_memory.cpp): runs of fast at given thread
// counts and options in lockstep with arrays, phases on teams of changing sizes, saved states compared.
#include <array>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "demmat/threads.hpp"
#include "fast.hpp"
#include "support.hpp"

namespace demmat::test {

// "" when the two states hold the same Gear values, radii and stretches bit for bit, else what differs.
inline std::string state_difference(const State& a, const State& b)
{
    auto same = [](const auto& x, const auto& y) { return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0; };
    const GearState* ga[2] = {&a.trans, &a.rot};
    const GearState* gb[2] = {&b.trans, &b.rot};
    for (int g = 0; g < 2; ++g)
        for (auto q : {&GearState::x, &GearState::v, &GearState::a, &GearState::b3, &GearState::b4, &GearState::b5})
            if (!same(ga[g]->*q, gb[g]->*q)) return fmt::format("{} Gear values differ", g == 0 ? "translational" : "rotational");
    if (!same(a.radius, b.radius)) return "radii differ";
    if (a.stretches.size() != b.stretches.size()) return fmt::format("{} stretches against {}", a.stretches.size(), b.stretches.size());
    for (std::size_t k = 0; k < a.stretches.size(); ++k) {
        const ContactStretch &x = a.stretches[k], &y = b.stretches[k];
        if (x.i != y.i || x.partner != y.partner || x.wall != y.wall || std::memcmp(&x.tangential, &y.tangential, sizeof(Vec3d)) != 0 ||
            std::memcmp(&x.rolling, &y.rolling, sizeof(Vec3d)) != 0)
            return fmt::format("stretch {} differs (particle {}, {} {})", k, x.i, x.wall ? "wall" : "partner", x.partner);
    }
    return "";
}

struct FastRun {
    FastOptions options;
    int threads;
};

struct LockstepResult {
    std::string difference;                // "" when every step of every run was bit-identical to arrays
    std::vector<std::int64_t> rebuilds;    // per fast run
    std::int64_t contacts = 0;             // arrays' particle–particle contacts at the end
    std::string saved_difference;          // "" when every fast run's saved state is arrays' bit for bit
    std::size_t stretched = 0;             // arrays' saved contacts with a stretch not zero (a §9 law)
};

// arrays and the given fast runs in lockstep, each fast run stepping at its own thread count, compared
// bit for bit after every step.
inline LockstepResult lockstep(const Setup& setup, std::int64_t steps, const std::vector<FastRun>& runs)
{
    auto ref = registry().find("arrays").create();
    Driver ref_driver(*ref, setup);
    std::vector<std::unique_ptr<FastVariant>> fast;
    std::vector<std::unique_ptr<Driver>> drivers;
    for (const FastRun& r : runs) {
        set_threads(r.threads);
        FastOptions o = r.options;
        o.min_parallel = 0;   // the threads asked for, however small the scene
        o.prefetch_from = 0;  // and the kernel's prefetching path,
        o.stream_records_from = 0;  // and predict()'s streamed records
        fast.push_back(make_fast_variant(o));
        drivers.push_back(std::make_unique<Driver>(*fast.back(), setup));
    }
    LockstepResult out;
    Snapshot a, b;
    for (std::int64_t k = 0; k <= steps && out.difference.empty(); ++k) {
        if (k > 0) {
            ref_driver.step();
            for (std::size_t v = 0; v < runs.size(); ++v) {
                set_threads(runs[v].threads);
                drivers[v]->step();
            }
        }
        ref->snapshot(a);
        for (std::size_t v = 0; v < runs.size() && out.difference.empty(); ++v) {
            fast[v]->snapshot(b);
            if (const auto d = first_difference(a, b))
                out.difference = fmt::format("threads {}, skin {}: {}", runs[v].threads, runs[v].options.skin, d->describe());
        }
    }
    for (const auto& f : fast) out.rebuilds.push_back(f->rebuilds());
    out.contacts = ref->counts().particle_particle;
    State sa, sb;
    ref->save(sa);
    for (const ContactStretch& c : sa.stretches)
        if (!(c.tangential == Vec3d{}) || !(c.rolling == Vec3d{})) ++out.stretched;
    for (std::size_t v = 0; v < runs.size() && out.difference.empty() && out.saved_difference.empty(); ++v) {
        fast[v]->save(sb);
        if (std::string d = state_difference(sa, sb); !d.empty())
            out.saved_difference = fmt::format("threads {}, skin {}: saved state: {}", runs[v].threads, runs[v].options.skin, d);
    }
    set_threads(0);
    return out;
}

// Steps `variant` (initialised) `steps` times, each phase on the team `teams[phase][step % size]` (0:
// predict, 1: search, 2: forces), as OpenMP's dynamic teams may choose; `after` after each step.
template <class After>
inline void step_with_teams(Variant& variant, std::int64_t first_step, std::int64_t steps, const std::array<std::vector<int>, 3>& teams,
                     After&& after)
{
    auto team = [&](int phase, std::int64_t k) { return teams[std::size_t(phase)][std::size_t(k) % teams[std::size_t(phase)].size()]; };
    for (std::int64_t k = 1; k <= steps; ++k) {
        set_threads(team(0, k));
        variant.predict(first_step + k);
        set_threads(team(1, k));
        variant.search();
        set_threads(team(2, k));
        variant.forces();
        variant.correct();
        after(k);
    }
    set_threads(0);
}

} // namespace demmat::test
