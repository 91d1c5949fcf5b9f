// SNAG_HD marks functions that both backends run: __host__ __device__ under nvcc, nothing
// under a plain C++ compiler. Everything written once for the CPU (OpenMP) and the GPU (CUDA)
// path lives in headers that include this one and nothing CUDA-specific.
#pragma once

#if defined(__CUDACC__)
#define SNAG_HD __host__ __device__
#define SNAG_HD_INLINE __host__ __device__ __forceinline__
#else
#define SNAG_HD
#define SNAG_HD_INLINE inline
#endif
