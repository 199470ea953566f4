// The fast Unorm8 kernels at the Avx2 level: CMakeLists.txt builds this file with -mavx2 -mfma
// -mf16c on x86-64 only; samplerKernels() hands them out only where the CPU runs that level.
#if !defined(__AVX2__) || !defined(__FMA__)
#error "texture_sampler_fast_avx2.cpp needs the Avx2 level's flags (CMakeLists.txt)"
#endif
#define PS11_SAMPLER_LEVEL avx2
#include "ps11/texture_sampler_fast_impl.h"
