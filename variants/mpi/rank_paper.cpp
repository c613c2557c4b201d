// The mpi variant's instantiations for the paper's law: with_model's models, the pairs on the shared
// kernel's lanes (rank_pair_kernel.hpp).
#include "rank_processor.hpp"

namespace demmat::mpi {

std::unique_ptr<MpiVariant> make_rank_processor_paper(const ModelFeatures& need, const Comm& comm, const Plan& plan)
{
    return with_model(need, [&]<class M>() -> std::unique_ptr<MpiVariant> { return std::make_unique<RankProcessor<M>>(comm, plan); });
}

} // namespace demmat::mpi
