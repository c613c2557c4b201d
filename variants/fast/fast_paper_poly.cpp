// The fast variant's instantiations for the paper's law with many radii (R* and m* per contact):
// the chain of fast_models.hpp.
#include "fast_models.hpp"
#include "fast_variant.hpp"

namespace demmat::fast {

std::unique_ptr<FastVariant> make_fast_paper_poly(int level, const FastOptions& options)
{
    return with_paper_level<true>(level, [&]<class M>() -> std::unique_ptr<FastVariant> { return std::make_unique<Fast<M>>(options); });
}

} // namespace demmat::fast
