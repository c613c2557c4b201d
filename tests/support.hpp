#pragma once
// Shared helpers for the tests: scenes in memory, runs of a variant, and the list of variants.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <utility>
#include <string>
#include <vector>

#include "demmat/checker.hpp"
#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/problem.hpp"
#include "demmat/registry.hpp"
#include "demmat/scenes.hpp"
#include "demmat/state_file.hpp"

namespace demmat::test {

inline std::vector<std::string> variant_names() { return registry().names(); }

// The length of a long equivalence run (thousands of contact-rich steps). The sanitizer build
// (DEMMAT_SANITIZE) runs a fifth of it, and no fewer than 50 steps: it hunts memory errors and
// undefined behaviour, which the first few hundred steps of every path already exercise (the settled
// beds are contact-rich from the start and the loose one within a few hundred steps, which its test
// checks; the list is rebuilt every ten to twenty steps on the compression stage; contacts are made and
// broken), while the normal build checks the full trajectories bit for bit. This keeps CI within its time.
#ifdef DEMMAT_SANITIZED
inline constexpr std::int64_t kLongRunDivisor = 5;
#else
inline constexpr std::int64_t kLongRunDivisor = 1;
#endif
inline std::int64_t long_run(std::int64_t steps) { return std::max(steps / kLongRunDivisor, std::min<std::int64_t>(steps, 50)); }

// Runs `steps` steps of a variant and returns it with its driver.
struct VariantRun {
    std::unique_ptr<Variant> variant;
    std::unique_ptr<Driver> driver;
    VariantRun(const std::string& name, const Setup& setup) : VariantRun(registry().find(name).create(), setup) {}
    VariantRun(std::unique_ptr<Variant> v, const Setup& setup) : variant(std::move(v)), driver(std::make_unique<Driver>(*variant, setup)) {}
    Snapshot snapshot() const
    {
        Snapshot s;
        variant->snapshot(s);
        return s;
    }
};

// The state a run has reached, as `demmat run --save` writes it (with Δt and the scene's fingerprint).
inline State saved_state(const VariantRun& run, const Problem& p)
{
    State st;
    run.variant->save(st);
    st.dt = p.scene().dt;
    st.fingerprint = p.state().fingerprint;
    return st;
}

// The dense bed of 2000 particles after 12000 steps (0.12 s) of settling from its loose grid: it has
// collapsed into a contact-rich bed (about 3.5 contacts per particle, rising to 4.4 over the next
// 5000 steps). Computed once with the arrays variant and cached beside the tests (each ctest is its
// own process); any valid state serves, so a cache from older code is harmless.
inline const std::int64_t kSettleSteps = 12000;
inline State settling_bed_state(const Scene& bed)
{
    return settled_state(bed, kSettleSteps, "equivalence_bed_2000_12000.state", registry().find("arrays").create);
}

// The settling bed as a scene that starts from the cached state; with `wall_speed` > 0, the paper's
// compression stage (the x_max wall moving inwards), re-anchored at the state's step. `edit`, if given,
// changes the scene before the problem is made (a contact law, a search method).
inline Problem bed_case(double wall_speed, const std::function<void(Scene&)>& edit = {})
{
    const Scene bed = dense_bed_scene(2000);
    State st = settling_bed_state(bed);
    Scene s = wall_speed > 0 ? compression_scene(bed, "(cached state)", wall_speed) : bed;
    if (edit) edit(s);
    st.walls = continue_walls(s, st);
    return Problem(s, st);
}

// Turns a variant name into a valid test-name suffix.
inline std::string param_name(const std::string& s)
{
    std::string out;
    for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    return out;
}

} // namespace demmat::test
