#pragma once
// DEMMAT_HD marks the shared functions that the cuda variant also compiles for the GPU: nvcc makes them
// __host__ __device__, every other compiler sees nothing. The arithmetic is the same text either way.
#if defined(__CUDACC__)
#define DEMMAT_HD __host__ __device__
#else
#define DEMMAT_HD
#endif
