// The fast Unorm8 kernels for any x86-64 (or other) CPU, and the runtime choice between them
// and the AVX2 build (texture_sampler_fast_avx2.cpp).
#define PS11_FAST_KERNEL sampleUnorm8Generic
#include "ps11/texture_sampler_fast_impl.h"

namespace ps11::fastpath {

Unorm8Kernel unorm8Kernel() {
#if defined(__x86_64__) && defined(PS11_HAVE_AVX2_KERNEL)
    static const Unorm8Kernel k = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")
                                      ? &sampleUnorm8Avx2
                                      : &sampleUnorm8Generic;
    return k;
#else
    return &sampleUnorm8Generic;
#endif
}

}  // namespace ps11::fastpath
