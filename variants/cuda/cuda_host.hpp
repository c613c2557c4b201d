#pragma once
// The cuda variant's kernels on the CPU (host_backend.hpp), for the tests: a seed for the shuffled
// block order and a block size. `cuda_host` in the registry is this with seed 1 and 128 threads.
#include <cstdint>
#include <memory>

#include "demmat/variant.hpp"

namespace demmat {
std::unique_ptr<Variant> make_cuda_host_variant(std::uint64_t seed, unsigned threads_per_block = 128);
} // namespace demmat
