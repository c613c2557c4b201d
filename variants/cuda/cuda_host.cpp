// Registers cuda_host: the cuda variant's kernels (kernels.hpp, gpu_variant.hpp) compiled by the host
// compiler and run by the host backend, so that every machine checks the GPU code against arrays.
#include "cuda_host.hpp"

#include "demmat/registry.hpp"
#include "gpu_variant.hpp"
#include "host_backend.hpp"

namespace demmat {

std::unique_ptr<Variant> make_cuda_host_variant(std::uint64_t seed, unsigned threads_per_block)
{
    return gpu::make_dispatching<gpu::HostBackend>([seed, threads_per_block] {
        return gpu::HostBackend({seed, threads_per_block});
    });
}

void register_variant_cuda_host(Registry& r)
{
    r.add({"cuda_host", "the cuda variant's kernels on the CPU, blocks in shuffled order (checks the GPU code anywhere; slow)",
           [] { return make_cuda_host_variant(1); }});
}

} // namespace demmat
