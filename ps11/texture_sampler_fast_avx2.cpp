// The fast Unorm8 kernels compiled for AVX2 + FMA (CMakeLists.txt gives this file -mavx2
// -mfma); chosen at run time by unorm8Kernel() only on CPUs that have both.
#if defined(__x86_64__) && defined(PS11_HAVE_AVX2_KERNEL)
#define PS11_FAST_KERNEL sampleUnorm8Avx2
#include "ps11/texture_sampler_fast_impl.h"
#endif
