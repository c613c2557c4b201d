#pragma once
// Which model features a run needs (model.hpp): derived from the scene and its initial state, never
// chosen by hand, so a scene that needs a feature never runs a model without it.
#include <functional>
#include <memory>

#include "demmat/model.hpp"
#include "demmat/scene.hpp"
#include "demmat/state.hpp"
#include "demmat/variant.hpp"

namespace demmat {

// friction: μ ≠ 0 and γ_t ≠ 0 (else F_t = −min(μ·F_n, γ_t·m*·|u_t|)·… is zero);
// rotation: friction, or any particle starting with a rotational Gear value (ω, α, b3–b5) other than +0;
// damping: γ_n ≠ 0; walls: any wall; moving walls: any wall velocity other than +0;
// polydisperse: radii not all the same bits (masses and inertias follow from radius and density).
// The state is needed, not the scene alone: a scene that continues a saved state gets its radii, spins
// and walls from the state file.
// The contact law's flags (physics.md §9) are the scene's [contact] choice, law_features.
ModelFeatures features_of(const Scene& scene, const State& state);
ModelFeatures law_features(const ContactModel& law);

// What a variant must model for this setup: the scene's needs, widened by setup.widen (tests and
// benchmarks run a more general model on purpose; nothing can narrow it).
inline ModelFeatures model_for(const Setup& setup) { return features_of(*setup.scene, *setup.state) | setup.widen; }


// A registered variant whose init() picks the instantiation that runs: `pick(setup)` returns it (a
// specialising variant calls with_model(model_for(setup), …) there), and every phase is forwarded to
// it, one virtual call more per phase and step. Re-initialising picks again.
class DispatchingVariant final : public Variant {
public:
    using Pick = std::function<std::unique_ptr<Variant>(const Setup&)>;
    // all_integrators: pick() honours scene.integrator, every scheme and precision (integrators.hpp).
    // all_laws: pick() honours scene.contact_model, every law of physics.md §9 (with_law_model).
    explicit DispatchingVariant(Pick pick, bool all_integrators = false, bool all_laws = false)
        : pick_(std::move(pick)), all_integrators_(all_integrators), all_laws_(all_laws) {}
    bool supports(const IntegratorChoice& choice) const override { return all_integrators_ || choice.is_default(); }
    bool supports(const ContactModel& law) const override { return all_laws_ || law.is_paper(); }

    void init(const Setup& setup) override
    {
        impl_ = pick_(setup);
        impl_->init(setup);
    }
    void predict(std::int64_t step) override { impl_->predict(step); }
    void search() override { impl_->search(); }
    void forces() override { impl_->forces(); }
    void correct() override { impl_->correct(); }
    void snapshot(Snapshot& out) const override { impl_->snapshot(out); }
    void save(State& out) const override { impl_->save(out); }
    ContactCounts counts() const override { return impl_ ? impl_->counts() : ContactCounts{}; }
    std::size_t memory_bytes() const override { return impl_ ? impl_->memory_bytes() : 0; }
    ModelFeatures model() const override { return impl_ ? impl_->model() : ModelFeatures::full(); }

private:
    Pick pick_;
    bool all_integrators_ = false;
    bool all_laws_ = false;
    std::unique_ptr<Variant> impl_;
};

} // namespace demmat
