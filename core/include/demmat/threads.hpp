#pragma once
// The thread count of the variants that use OpenMP (fast, fast_unordered). The Variant interface knows
// no options, so the thread count is process-wide: the demmat program's --threads and the tests set it
// here. Without OpenMP every function is a no-op and max_threads() is 1.
namespace demmat {

// n > 0: parallel regions use n threads from now on; n = 0 leaves OpenMP's default (OMP_NUM_THREADS,
// else one per core).
void set_threads(int n);
// The threads the next parallel region will use.
int max_threads();
// Whether this build has OpenMP at all.
bool openmp_enabled();

} // namespace demmat
