// The mpi variant's instantiations for the contact laws of physics.md §9: the full model with the law's
// flags (with_law_model's seven), the pairs through the scalar law.
#include "rank_processor.hpp"

namespace demmat::mpi {

std::unique_ptr<MpiVariant> make_rank_processor_law(const ModelFeatures& need, const Comm& comm, const Plan& plan)
{
    return with_law_model(need, [&]<class M>() -> std::unique_ptr<MpiVariant> {
        if constexpr (M::restitution_damping || M::history || M::rolling)
            return std::make_unique<RankProcessor<M>>(comm, plan);
        else
            throw Error("internal: make_rank_processor_law called for the paper's law");
    });
}

} // namespace demmat::mpi
