# The distributed-memory variant (variants/mpi, docs/variants.md "mpi"), only where Open MPI (Debian's
# libopenmpi-dev, scripts/install_deps.sh) is found; elsewhere it is skipped, not failed. It is not in the
# registry: its ranks must be started by mpirun, so demmat_mpi (app/) and the mpi tests make it directly.
find_package(MPI COMPONENTS CXX QUIET)
if(MPI_CXX_FOUND)
  add_library(demmat_mpi_variant STATIC mpi/comm.cpp mpi/mpi_variant.cpp mpi/share_problem.cpp mpi/lockstep.cpp)
  target_link_libraries(demmat_mpi_variant PUBLIC demmat_common MPI::MPI_CXX)
  target_include_directories(demmat_mpi_variant PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/mpi)
  message(STATUS "demmat: the mpi variant with ${MPIEXEC_EXECUTABLE} (MPI ${MPI_CXX_VERSION})")
else()
  message(STATUS "demmat: MPI not found, the mpi variant and demmat_mpi skipped")
endif()
