// The eigen_soa variant's instantiations for the contact laws of physics.md §9 (a translation unit of its
// own, so that the paper's instantiations in eigen_soa.cpp compile as they did before the laws existed):
// the full model with the law's flags (with_law_model).
#include "eigen_soa_variant.hpp"

namespace demmat::eigen_soa {

std::unique_ptr<Variant> pick_eigen_soa_law(const Setup& setup)
{
    return with_law_model(law_features(setup.scene->contact_model), []<class M>() -> std::unique_ptr<Variant> {
        if constexpr (M::restitution_damping || M::history || M::rolling) return std::make_unique<EigenSoaVariant<M>>();
        else throw Error("internal: pick_eigen_soa_law called for the paper's law");
    });
}

} // namespace demmat::eigen_soa
