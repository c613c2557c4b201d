# The distributed-memory variant (variants/mpi, docs/variants/mpi.md), only where Open MPI (Debian's
# libopenmpi-dev, scripts/install_deps.sh) is found; elsewhere it is skipped, not failed. It is not in the
# registry: its ranks must be started by mpirun, so demmat_mpi (app/) and the mpi tests make it directly.
find_package(MPI COMPONENTS CXX QUIET)
if(MPI_CXX_FOUND)
  # The ranks' code runs the shared pair kernel on lanes (demmat/soa/), compiled for this CPU as fast's is
  # (DEMMAT_FAST_FLAGS), so it is a shared object of its own for the same reason as fast's
  # (variants/CMakeLists.txt): it exports only the variant's factory (mpi/exports.map), and its native
  # copies of shared inline and template code stay inside it. It holds its own copy of comm.cpp.
  add_library(demmat_mpi_ranks SHARED mpi/mpi_variant.cpp mpi/rank_paper.cpp mpi/rank_laws.cpp mpi/comm.cpp)
  target_link_libraries(demmat_mpi_ranks PUBLIC demmat_common MPI::MPI_CXX)
  target_include_directories(demmat_mpi_ranks PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/mpi)
  target_compile_options(demmat_mpi_ranks PRIVATE ${DEMMAT_FAST_FLAGS})
  set(DEMMAT_MPI_EXPORTS ${CMAKE_CURRENT_SOURCE_DIR}/mpi/exports.map)
  target_link_options(demmat_mpi_ranks PRIVATE -Wl,--version-script=${DEMMAT_MPI_EXPORTS} -Wl,-z,defs)
  set_target_properties(demmat_mpi_ranks PROPERTIES LINK_DEPENDS ${DEMMAT_MPI_EXPORTS})
  if(NOT OpenMP_CXX_FOUND)  # its vectorised loops are marked `omp simd`, as fast's
    target_compile_options(demmat_mpi_ranks PRIVATE -Wno-unknown-pragmas)
  endif()
  # What the programs call beside the ranks (the exchange, the shared problem, the lockstep check), baseline.
  add_library(demmat_mpi_variant STATIC mpi/comm.cpp mpi/share_problem.cpp mpi/lockstep.cpp)
  target_link_libraries(demmat_mpi_variant PUBLIC demmat_mpi_ranks demmat_common MPI::MPI_CXX)
  target_include_directories(demmat_mpi_variant PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/mpi)
  message(STATUS "demmat: the mpi variant with ${MPIEXEC_EXECUTABLE} (MPI ${MPI_CXX_VERSION})")
else()
  message(STATUS "demmat: MPI not found, the mpi variant and demmat_mpi skipped")
endif()
