#pragma once
// A problem: a scene, its initial state and the Setup derived from them, built in one place and owned
// together. The Setup points into the scene and the state, so a Problem is neither copied nor moved;
// hold it by value where it is made or by unique_ptr.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>

#include "demmat/scene.hpp"
#include "demmat/state.hpp"
#include "demmat/variant.hpp"

namespace demmat {

class Problem {
public:
    explicit Problem(Scene scene);      // the state the scene describes (grid, list or state file)
    Problem(Scene scene, State state);  // a state made elsewhere (a settled bed, a test's geometry)
    Problem(const Problem&) = delete;
    Problem& operator=(const Problem&) = delete;

    // A scene file, read and validated, with its initial state.
    static std::unique_ptr<Problem> load(const std::filesystem::path& scene_file);

    const Scene& scene() const { return scene_; }
    const State& state() const { return state_; }
    const Setup& setup() const { return setup_; }
    std::size_t size() const { return state_.size(); }
    // Features to model beyond what the scene needs (Setup::widen): tests of bit identity, feature costs.
    void widen(const ModelFeatures& extra) { setup_.widen = extra; }

private:
    Scene scene_;
    State state_;
    Setup setup_;
};

// The steps a run takes to reach `time` with steps of `dt`: integer steps, never accumulated time (the
// 1e-9 forgives a quotient such as 0.4 / 1e-5 rounding to just above an integer).
std::int64_t steps_to_reach(double time, double dt);

// The one way to settle a bed: `steps` steps of a variant (made by `make_variant`, e.g. a registry
// entry's `create`) from the scene's initial state, saved to `cache` and read back on the next call
// while the cache matches the scene (fingerprint) and the step count; any bit-identical variant gives
// the same state bit for bit. `progress(k, steps)`, if given, is called after each step.
State settled_state(const Scene& bed, std::int64_t steps, const std::filesystem::path& cache,
                    const std::function<std::unique_ptr<Variant>()>& make_variant,
                    const std::function<void(std::int64_t, std::int64_t)>& progress = {});

} // namespace demmat
