// The fast variant's instantiations for the contact laws of physics.md §9: the full model with the
// law's flags (with_law_model's seven), gear5 in double.
#include "fast_models.hpp"
#include "fast_variant.hpp"

namespace demmat::fast {

std::unique_ptr<FastVariant> make_fast_law(const ModelFeatures& need, const FastOptions& options)
{
    return demmat::detail::branch(need.restitution_damping, [&]<bool A>() {
        return demmat::detail::branch(need.history, [&]<bool H>() {
            return demmat::detail::branch(need.rolling, [&]<bool R>() -> std::unique_ptr<FastVariant> {
                if constexpr (A || H || R)
                    return std::make_unique<Fast<Model<true, true, true, true, true, true, A, H, R>>>(options);
                else
                    throw Error("internal: make_fast_law called for the paper's law");
            });
        });
    });
}

} // namespace demmat::fast
