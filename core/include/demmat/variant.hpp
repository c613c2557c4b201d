#pragma once
// The one interface every variant implements. A variant owns its data layout and its contact store;
// it knows nothing of clocks, files or statistics: the driver calls the four phases and times them.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/gear.hpp"
#include "demmat/scene.hpp"
#include "demmat/state.hpp"

namespace demmat {

// What a variant receives at start: the scene, the full initial state, and the derived constants that
// every variant must use as they are (so none derives them differently).
struct Setup {
    const Scene* scene = nullptr;
    const State* state = nullptr;
    ContactParams<double> contact;
    MemoryParams<double> memory;  // the constants of the scene's §9 law (contact_memory.hpp); zero for the paper's
    GearCoefficients<double> gear;
    std::vector<double> mass;     // per particle, id order (sphere_mass)
    std::vector<double> inertia;  // per particle, id order (sphere_inertia)
    double radius_max = 0.0;
    double cell_size = 0.0;       // m; 0 when the search is all pairs
    // Features to model although the scene does not need them (tests of bit identity, benchmarks of a
    // feature's cost); a specialising variant models features_of(scene, state) | widen (features.hpp).
    ModelFeatures widen;

    static Setup make(const Scene& scene, const State& state);
};

// Observable state after a step, in particle-id order; what the checker compares bit for bit. Before
// the first step (right after init) force and torque are zero in every variant.
struct Snapshot {
    std::int64_t step = 0;
    std::vector<Vec3d> position, velocity, angular_velocity, force, torque;
    void resize(std::size_t n) { position.resize(n); velocity.resize(n); angular_velocity.resize(n); force.resize(n); torque.resize(n); }
};

struct ContactCounts {
    std::int64_t particle_particle = 0;  // contacts with h > 0 found by the last forces phase
    std::int64_t particle_wall = 0;
    std::int64_t candidates = 0;         // pairs the last search kept for the forces phase
    // Contacts per particle among n: a pair counts for both its particles, a wall contact for one.
    double per_particle(std::size_t n) const { return (2.0 * double(particle_particle) + double(particle_wall)) / double(n); }
};

class Variant {
public:
    virtual ~Variant() = default;

    virtual void init(const Setup& setup) = 0;
    // Phases of one step (physics.md §4). `step` is the number of the step being taken: the predictor
    // puts moving walls at their position for this step.
    virtual void predict(std::int64_t step) = 0;
    virtual void search() = 0;
    virtual void forces() = 0;   // contact forces, canonical summation, a = F/m + g, α = T/I
    virtual void correct() = 0;

    virtual void snapshot(Snapshot& out) const = 0;
    virtual void save(State& out) const = 0;      // the full state, for save-and-continue
    virtual ContactCounts counts() const = 0;
    virtual std::size_t memory_bytes() const = 0;  // bytes held for particles and contacts
    // Called by the Driver after the untimed work it does between steps (a health check: on a variant
    // spread over processes, the one that gathered the snapshot checks it alone). Such a variant waits
    // here for all its processes, so that the others do not time that work as waiting in the next
    // step's exchange. Default: nothing to wait for.
    virtual void rejoin() const {}
    // The model features the instantiation picked in init() computes (model.hpp); a variant that does
    // not specialise runs the full model.
    virtual ModelFeatures model() const { return ModelFeatures::full(); }
    // The threads the variant's phases really run on (a threaded variant may run fewer than asked, e.g.
    // on one below a size threshold); what bench and run report.
    virtual int threads_used() const { return 1; }
    // Whether init() honours this integrator and precision (scene.integrator, integrators.hpp); the
    // Driver refuses a run whose variant does not. A variant that integrates with the paper's Gear scheme
    // in double only keeps this default.
    virtual bool supports(const IntegratorChoice& choice) const { return choice.is_default(); }
    // Whether init() honours this contact law (scene.contact_model, physics.md §9); the Driver refuses a
    // run whose variant does not. A variant that computes the paper's law only keeps this default.
    virtual bool supports(const ContactModel& law) const { return law.is_paper(); }

    // The name it is registered under (set by Registry::add's factory), for messages; empty otherwise.
    const std::string& registered_name() const { return registered_name_; }
    void set_registered_name(std::string name) { registered_name_ = std::move(name); }

private:
    std::string registered_name_;
};

} // namespace demmat
