#pragma once
// The sanitizer build's leak check for a program that runs MPI (docs/testing.md, "The mpi variant under
// mpirun"). At exit, after MPI_Finalize, LeakSanitizer would report what Open MPI never frees in its
// components, which MPI_Finalize has unloaded (dlclose): frames in "<unknown module>" that no
// suppression can name. So the check runs just before MPI_Finalize, while Open MPI's memory is still
// reachable from its own globals and its libraries still loaded (what it has lost by then is named in
// tests/mpi/lsan.supp); the suite's own leaks are all there is to find. The check at exit is then off
// (LeakSanitizer checks once).
#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

namespace demmat::mpi {

inline void check_leaks_before_finalize()
{
#if defined(__SANITIZE_ADDRESS__)
    __lsan_do_leak_check();
#endif
}

} // namespace demmat::mpi
