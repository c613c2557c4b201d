// The object-oriented processor's instantiations for the contact laws of physics.md §9 (a translation
// unit of its own, with its own copies of the searches, so that the paper's in oop.cpp and
// neighbour_search.cpp compile as they did before the laws existed): the full model with the law's
// flags (with_law_model).
#include "assembly.hpp"
#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "neighbour_search_impl.hpp"

namespace demmat::oop {

std::unique_ptr<Variant> pick_oop_law(const Setup& setup)
{
    return with_law_model(law_features(setup.scene->contact_model), []<class M>() -> std::unique_ptr<Variant> {
        if constexpr (beyond_paper<M>) return std::make_unique<Assembly<M>>();
        else throw Error("internal: pick_oop_law called for the paper's law");
    });
}

} // namespace demmat::oop
