// The arrays variant's instantiations for the contact laws of physics.md §9 (a translation unit of its
// own, so the paper's instantiations in arrays.cpp do not recompile with them): the full model with the
// law's flags (with_law_model), for every integrator and precision.
#include <type_traits>

#include "arrays_variant.hpp"

namespace demmat::arrays {

std::unique_ptr<Variant> pick_arrays_law(const Setup& setup)
{
    const IntegratorChoice& choice = setup.scene->integrator;
    return with_precision(choice.precision, [&](auto value) {
        return with_scheme(choice.scheme, [&](auto scheme) -> std::unique_ptr<Variant> {
            return with_law_model(law_features(setup.scene->contact_model), [&]<class M>() -> std::unique_ptr<Variant> {
                if constexpr (M::restitution_damping || M::history || M::rolling)
                    return std::make_unique<ArraysVariant<std::decay_t<decltype(value)>, M, std::decay_t<decltype(scheme)>>>();
                else
                    throw Error("internal: pick_arrays_law called for the paper's law");
            });
        });
    });
}

} // namespace demmat::arrays
