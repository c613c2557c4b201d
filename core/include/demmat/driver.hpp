#pragma once
// The driver owns the clock: it calls a variant's phases in the paper's order and times each one.
// Health checks (NaN, runaway speed, excessive overlap, a particle through a wall, energy growth beyond
// what gravity supplies; docs/stability.md) run between steps, outside the timed phases.
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "demmat/variant.hpp"

namespace demmat {

struct PhaseTimes {  // seconds, summed over the steps taken
    double predict = 0.0, search = 0.0, forces = 0.0, correct = 0.0;
    double total() const { return predict + search + forces + correct; }
    PhaseTimes operator-(const PhaseTimes& o) const
    {
        return {predict - o.predict, search - o.search, forces - o.forces, correct - o.correct};
    }
    PhaseTimes per_step(std::int64_t steps) const
    {
        const double k = steps > 0 ? 1.0 / double(steps) : 0.0;
        return {predict * k, search * k, forces * k, correct * k};
    }
};

class Driver {
public:
    // Initialises the variant from the setup (not timed).
    Driver(Variant& variant, const Setup& setup);

    void step();                     // one timed step
    // `steps` timed steps, with health checks at the scene's interval; after_step(k), k = 1 … steps, runs
    // after each step, outside the timed phases (snapshots, progress).
    void run(std::int64_t steps, const std::function<void(std::int64_t)>& after_step = {});
    void check_health();             // throws InstabilityError naming the step and particle

    std::int64_t current_step() const { return step_; }
    double time() const { return double(step_) * setup_.gear.dt; }
    const PhaseTimes& times() const { return times_; }
    std::int64_t steps_taken() const { return steps_taken_; }
    // The largest overlap seen by the health checks so far, over the smaller radius (particle pairs)
    // or the radius (walls): how close the run came to the scene's max_overlap_ratio.
    double largest_overlap_ratio() const { return largest_overlap_ratio_; }
    Variant& variant() { return variant_; }
    const Setup& setup() const { return setup_; }

private:
    void timed_step();
    std::string stability_hint() const;

    Variant& variant_;
    const Setup& setup_;
    std::int64_t step_;
    std::int64_t steps_taken_ = 0;
    PhaseTimes times_;
    Snapshot scratch_;
    double speed_bound_;
    double largest_overlap_ratio_ = 0.0;
    // Energy-growth check (docs/stability.md): start positions and energy, the tolerance's floor; off
    // when a wall moves (its work is not tracked).
    std::vector<Vec3d> x0_;
    double energy0_ = 0.0, energy_floor_ = 0.0;
    bool energy_check_ = false;
};

// The one measurement of a variant's phases: `warmup` steps left out of the result (first touches, first
// list builds), then `steps` steps run as run() runs them (health checks included) whose phase times,
// per step, are returned; after_step as in run() (e.g. to accumulate contact counts).
PhaseTimes measure_steps(Driver& driver, std::int64_t warmup, std::int64_t steps,
                         const std::function<void(std::int64_t)>& after_step = {});

// Kinetic energy (translational + rotational) of a snapshot, summed in id order, and its two parts.
struct KineticEnergy {
    double translational = 0.0, rotational = 0.0;
};
KineticEnergy kinetic_energy_parts(const Snapshot& s, const Setup& setup);
double kinetic_energy(const Snapshot& s, const Setup& setup);

} // namespace demmat
