// The object-oriented processor's registration and its instantiation for the paper's law (assembly.hpp).
#include "assembly.hpp"
#include "demmat/features.hpp"
#include "demmat/registry.hpp"

namespace demmat {
namespace oop {
namespace {

// The paper's law runs the full model, as oop always has (it does not specialise); a §9 law the full
// model with that law's flags (with_law_model).
std::unique_ptr<Variant> pick(const Setup& setup)
{
    if (setup.scene->contact_model.is_paper()) return std::make_unique<Assembly<FullModel>>();
    return pick_oop_law(setup);
}

} // namespace
} // namespace oop

void register_variant_oop(Registry& r)
{
    r.add({"oop", "pure object-oriented: particle and plane objects, pointer neighbour lists (the paper's DEMMAT_CPP)",
           [] { return std::make_unique<DispatchingVariant>(oop::pick, /*all_integrators=*/false, /*all_laws=*/true); }});
}

} // namespace demmat
