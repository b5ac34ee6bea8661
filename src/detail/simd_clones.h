// SPDX-License-Identifier: BSD-3-Clause
// The attributes of the project's SIMD loops (src/detail/kernels.cpp, src/detail/node_kernels.cpp):
// GCC on x86-64 Linux compiles each exported kernel for AVX-512, AVX2 + FMA and baseline SSE2
// and picks one at load time (target_clones); helpers are always inlined into it, so that each
// clone vectorises them for its own instruction set. Private to the library (src/).
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12 && defined(__x86_64__) && defined(__linux__)
#define PCL_PROBCOLLISION_CLONES \
  __attribute__ ((target_clones ("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define PCL_PROBCOLLISION_CLONES
#endif
#if defined(__GNUC__)
#define PCL_PROBCOLLISION_ALWAYS_INLINE inline __attribute__ ((always_inline))
#define PCL_PROBCOLLISION_LAMBDA_INLINE __attribute__ ((always_inline))
#else
#define PCL_PROBCOLLISION_ALWAYS_INLINE inline
#define PCL_PROBCOLLISION_LAMBDA_INLINE
#endif
