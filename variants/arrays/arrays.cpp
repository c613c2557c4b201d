// The arrays variant's registration and its instantiations for the paper's law (arrays_variant.hpp).
#include "arrays_variant.hpp"

namespace demmat {
namespace {

using arrays::ArraysVariant;

// The instantiation a run gets, picked in init(): the smallest model that covers what the scene needs
// (with_model, model.hpp).
std::unique_ptr<Variant> pick_arrays(const Setup& setup)
{
    if (!setup.scene->contact_model.is_paper()) return arrays::pick_arrays_law(setup);
    const IntegratorChoice& choice = setup.scene->integrator;
    if (choice.is_default())
        return with_model(model_for(setup), []<class M>() -> std::unique_ptr<Variant> {
            return std::make_unique<ArraysVariant<double, M>>();
        });
    // Another integrator or precision (scene.integrator) runs the general model: the model specialisations
    // are instantiated for the paper's gear5 in double only, not for every (integrator, precision) pair.
    return with_precision(choice.precision, [&](auto value) {
        return with_scheme(choice.scheme, [](auto scheme) -> std::unique_ptr<Variant> {
            return std::make_unique<ArraysVariant<decltype(value), FullModel, decltype(scheme)>>();
        });
    });
}

} // namespace

void register_variant_arrays(Registry& r)
{
    r.add({"arrays", "plain arrays, procedural, Fortran-90 style (the paper's DEMMAT_F90)",
           [] { return std::make_unique<DispatchingVariant>(pick_arrays, /*all_integrators=*/true,
                                                             /*all_laws=*/true); }});
}

} // namespace demmat
