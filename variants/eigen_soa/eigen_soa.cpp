// The eigen_soa variant's registration and its instantiations for the paper's law (eigen_soa_variant.hpp).
#include "eigen_soa_variant.hpp"

namespace demmat {
namespace {

// The instantiation a run gets, picked in init(): the smallest model that covers what the scene needs
// (with_model), or for a §9 law the full model with its flags (eigen_soa_laws.cpp).
std::unique_ptr<Variant> pick_eigen_soa(const Setup& setup)
{
    if (!setup.scene->contact_model.is_paper()) return eigen_soa::pick_eigen_soa_law(setup);
    return with_model(model_for(setup), []<class M>() -> std::unique_ptr<Variant> {
        return std::make_unique<eigen_soa::EigenSoaVariant<M>>();
    });
}

} // namespace

void register_variant_eigen_soa(Registry& r)
{
    r.add({"eigen_soa", "Eigen structure of arrays, whole-array predictor and corrector",
           [] { return std::make_unique<DispatchingVariant>(pick_eigen_soa, /*all_integrators=*/false,
                                                             /*all_laws=*/true); }});
}

} // namespace demmat
