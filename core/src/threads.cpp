#include "demmat/threads.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace demmat {

#ifdef _OPENMP
void set_threads(int n)
{
    if (n > 0) omp_set_num_threads(n);
}
int max_threads() { return omp_get_max_threads(); }
bool openmp_enabled() { return true; }
#else
void set_threads(int) {}
int max_threads() { return 1; }
bool openmp_enabled() { return false; }
#endif

} // namespace demmat
