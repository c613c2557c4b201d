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
    # CMake 3.25 knows no C++20 flag for nvcc 13 (nvcc has it): tell it, so that CUDA_STANDARD 20 works.
    if(NOT CMAKE_CUDA20_STANDARD_COMPILE_OPTION)
      set(CMAKE_CUDA20_STANDARD_COMPILE_OPTION -std=c++20)
      set(CMAKE_CUDA20_EXTENSION_COMPILE_OPTION -std=c++20)
      list(APPEND CMAKE_CUDA_COMPILE_FEATURES cuda_std_20)
    endif()
    find_package(CUDAToolkit REQUIRED)
    demmat_add_variant(cuda SOURCES cuda/cuda.cu LIBS demmat_variant_cuda_host CUDA::cudart_static)
    # The directory's GCC options are not nvcc's: the file gets its own. No FMA contraction, IEEE
    # division and square root, no flush to zero; the host side of the file as every C++ file.
    set_property(TARGET demmat_variant_cuda PROPERTY COMPILE_OPTIONS
      --fmad=false -prec-div=true -prec-sqrt=true -ftz=false -Xcompiler=-ffp-contract=off,-fno-fast-math,-Wall,-Wextra)
    set_target_properties(demmat_variant_cuda PROPERTIES CUDA_STANDARD 20 CUDA_STANDARD_REQUIRED ON CUDA_EXTENSIONS OFF
                                                         CUDA_RUNTIME_LIBRARY Static)
  else()
    message(STATUS "demmat: no CUDA compiler: the cuda variant is left out")
  endif()
endif()
