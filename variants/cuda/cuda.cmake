# The cuda variant (docs/cuda.md), only where nvcc exists; -DDEMMAT_CUDA=OFF leaves it out. Included by
# variants/CMakeLists.txt after cuda_host, whose status messages it shares.
option(DEMMAT_CUDA "Build the cuda variant where a CUDA compiler exists" ON)
if(DEMMAT_CUDA AND NOT DEFINED CMAKE_CUDA_COMPILER AND NOT DEFINED ENV{CUDACXX})
  # nvcc off PATH: the toolkit's default install location.
  find_program(DEMMAT_NVCC nvcc PATHS /usr/local/cuda/bin)
  if(DEMMAT_NVCC)
    set(CMAKE_CUDA_COMPILER ${DEMMAT_NVCC})
  endif()
endif()
if(DEMMAT_CUDA AND CMAKE_CUDA_COMPILER AND NOT EXISTS "${CMAKE_CUDA_COMPILER}")
  message(STATUS "demmat: CUDA compiler ${CMAKE_CUDA_COMPILER} not found: the cuda variant is left out")
elseif(DEMMAT_CUDA)
  include(CheckLanguage)
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    # sm_90 machine code (H100, H200) and compute_90 PTX that later GPUs compile when they load it.
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      set(CMAKE_CUDA_ARCHITECTURES 90-real 90-virtual)
    endif()
    # The static CUDA runtime: the binaries run on a GPU machine without the toolkit (the driver suffices).
    set(CMAKE_CUDA_RUNTIME_LIBRARY Static)
    enable_language(CUDA)
    find_package(CUDAToolkit REQUIRED)
    demmat_add_variant(cuda SOURCES cuda/cuda.cu LIBS demmat_variant_cuda_host CUDA::cudart_static)
    # The directory's GCC options are not nvcc's: the file gets its own (C++20 by hand: CMake 3.25 has no CUDA 20
    # flag for nvcc 13). No FMA contraction, IEEE
    # division and square root, no flush to zero; the host side of the file as every C++ file.
    set_property(TARGET demmat_variant_cuda PROPERTY COMPILE_OPTIONS
      -std=c++20 --fmad=false -prec-div=true -prec-sqrt=true -ftz=false -Xcompiler=-ffp-contract=off,-fno-fast-math,-Wall,-Wextra)
    # No CUDA_STANDARD (CMake would take CXX_STANDARD 20 for it and knows no nvcc 13 flag): -std above.
    set_target_properties(demmat_variant_cuda PROPERTIES CUDA_RUNTIME_LIBRARY Static)
    set_property(TARGET demmat_variant_cuda PROPERTY CXX_STANDARD)
  else()
    message(STATUS "demmat: no CUDA compiler: the cuda variant is left out")
  endif()
endif()
