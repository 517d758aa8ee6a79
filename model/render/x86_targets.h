// The function targets of the x86 vector kernels (render/fixed_simd.cpp, the vertex transform
// of render/pipeline.cpp). With GCC or Clang on x86-64, SHD_X86_KERNELS is defined and the
// intrinsics are available inside functions marked SHD_AVX512, SHD_AVX2 or SHD_AVX2_PRFCHW,
// which run only where fixed_simd::available() or availableAvx2() holds; elsewhere those
// files build their scalar paths alone.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define SHD_X86_KERNELS 1
#define SHD_AVX512 __attribute__((target("avx512f,avx512dq,avx512cd,avx512vl,avx512bw")))
#define SHD_AVX2 __attribute__((target("avx2")))
// The AVX2 colour kernel: PREFETCHW too (executed as a NOP by Intel CPUs before Broadwell).
#define SHD_AVX2_PRFCHW __attribute__((target("avx2,prfchw")))
#endif
