#include "demmat/problem.hpp"

#include <cmath>

#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/scene_toml.hpp"
#include "demmat/state_file.hpp"

namespace demmat {

Problem::Problem(Scene scene) : scene_(std::move(scene)), state_(initial_state(scene_)), setup_(Setup::make(scene_, state_)) {}

Problem::Problem(Scene scene, State state)
    : scene_(std::move(scene)), state_(std::move(state)), setup_(Setup::make(scene_, state_))
{
}

std::unique_ptr<Problem> Problem::load(const std::filesystem::path& scene_file)
{
    return std::make_unique<Problem>(load_scene(scene_file));
}

std::int64_t steps_to_reach(double time, double dt) { return std::int64_t(std::ceil(time / dt - 1e-9)); }

State settled_state(const Scene& bed, std::int64_t steps, const std::filesystem::path& cache,
                    const std::function<std::unique_ptr<Variant>()>& make_variant,
                    const std::function<void(std::int64_t, std::int64_t)>& progress)
{
    try {
        State st = load_state(cache);
        if (st.fingerprint == bed.fingerprint(st.size()) && st.step == steps) return st;
    } catch (const Error&) {
        // missing, stale or damaged: settle again
    }
    const Problem start(bed);
    auto v = make_variant();
    Driver d(*v, start.setup());
    d.run(steps, progress ? [&](std::int64_t k) { progress(k, steps); } : std::function<void(std::int64_t)>{});
    State st;
    v->save(st);
    st.dt = bed.dt;
    st.fingerprint = start.state().fingerprint;
    if (cache.has_parent_path()) std::filesystem::create_directories(cache.parent_path());
    save_state(st, cache);
    return st;
}

} // namespace demmat
