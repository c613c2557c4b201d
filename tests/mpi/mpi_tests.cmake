# The mpi variant's tests (variants/mpi), where MPI was found: each ctest starts a program under mpirun.
# Open MPI's --oversubscribe lets R ranks share the machine's cores (CI has 2), --allow-run-as-root lets
# CI run them as root. The short runs at R = 1–4 are in the default set; R = 8 and the long runs carry the
# label `long` (scripts/run_long_tests.sh), as the gtest suites named *Long do.
set(DEMMAT_MPIRUN ${MPIEXEC_EXECUTABLE} --oversubscribe --allow-run-as-root ${MPIEXEC_PREFLAGS})
set(DEMMAT_MPIRUN ${DEMMAT_MPIRUN} PARENT_SCOPE)

# The sanitizer build: LeakSanitizer is told of Open MPI's own leaks (lsan.supp, docs/testing.md), with
# the slow unwinder so that a leak's stack reaches the Open MPI library that made it (the fast one stops
# at the first frame of a component without frame pointers); the environment reaches the ranks through
# mpirun. The leak check runs before MPI_Finalize (variants/mpi/leak_check.hpp).
set(DEMMAT_MPI_TEST_ENV "")
if(DEMMAT_SANITIZE)
  set(DEMMAT_MPI_TEST_ENV "LSAN_OPTIONS=exitcode=88:fast_unwind_on_malloc=0:suppressions=${CMAKE_CURRENT_SOURCE_DIR}/mpi/lsan.supp")
endif()

add_executable(demmat_mpi_tests mpi/test_mpi.cpp)
target_link_libraries(demmat_mpi_tests PRIVATE demmat_mpi_variant demmat_variants GTest::gtest)
target_include_directories(demmat_mpi_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
if(DEMMAT_SANITIZE)
  target_compile_definitions(demmat_mpi_tests PRIVATE DEMMAT_SANITIZED=1)
endif()

function(demmat_mpi_test name ranks filter)
  cmake_parse_arguments(T "LONG" "" "" ${ARGN})
  add_test(NAME ${name}
           COMMAND ${DEMMAT_MPIRUN} ${MPIEXEC_NUMPROC_FLAG} ${ranks} $<TARGET_FILE:demmat_mpi_tests> --gtest_filter=${filter}
                   ${MPIEXEC_POSTFLAGS}
           WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})  # beside demmat_tests: the settled bed's cache is shared
  set_tests_properties(${name} PROPERTIES TIMEOUT 1800 PROCESSORS ${ranks} ENVIRONMENT "${DEMMAT_MPI_TEST_ENV}")
  if(T_LONG)
    set_tests_properties(${name} PROPERTIES LABELS long)
  endif()
endfunction()

foreach(r 1 2 3 4)
  demmat_mpi_test(mpi.equivalence.np${r} ${r} "MpiEquivalence.*")
endforeach()
demmat_mpi_test(mpi.equivalence.np8 8 "MpiEquivalence.*" LONG)
foreach(r 1 2 3 4 8)
  demmat_mpi_test(mpi.equivalence_long.np${r} ${r} "MpiEquivalenceLong.*" LONG)
endforeach()

# demmat_mpi's command line: bad input, compare, save at 3 and continue at 2 (check_cli.sh).
if(TARGET demmat_mpi)
  add_test(NAME mpi.cli COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/mpi/check_cli.sh $<TARGET_FILE:demmat> $<TARGET_FILE:demmat_mpi>
                                  ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/mpi_cli_work ${DEMMAT_MPIRUN})
  set_tests_properties(mpi.cli PROPERTIES TIMEOUT 300 PROCESSORS 3 ENVIRONMENT "${DEMMAT_MPI_TEST_ENV}")
endif()

# The benchmark's pipeline at a tiny size (scripts/run_mpi_bench.sh; results in the build folder): it
# settles, runs every configuration, LAMMPS where installed, and the analysis. Long: a minute of runs.
if(TARGET demmat_mpi)
  add_test(NAME scripts.mpi_bench_tiny
           COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/run_mpi_bench.sh --build-dir ${CMAKE_BINARY_DIR} --n 800 --halo-n 800 --steps 10
                   --repetitions 1 --settle-time 0.002 --imbalance-steps 10 --out ${CMAKE_CURRENT_BINARY_DIR}/mpi_bench_tiny)
  set_tests_properties(scripts.mpi_bench_tiny PROPERTIES TIMEOUT 600 LABELS long PASS_REGULAR_EXPRESSION "results in")
endif()
