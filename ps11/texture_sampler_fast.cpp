// The fast Unorm8 kernels for any x86-64 (or other) CPU, and the runtime choice between them
// and the AVX2 build (texture_sampler_fast_avx2.cpp).
#define PS11_FAST_KERNEL sampleUnorm8Generic
#include "ps11/texture_sampler_fast_impl.h"

#include <atomic>

namespace ps11::fastpath {

namespace {
std::atomic<bool> g_forceGeneric{false};
}

bool hasAvx2Kernel() {
#if defined(__x86_64__) && defined(PS11_HAVE_AVX2_KERNEL)
    static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    return has;
#else
    return false;
#endif
}

void setForceGeneric(bool generic) { g_forceGeneric.store(generic, std::memory_order_relaxed); }

Unorm8Kernel unorm8Kernel() {
#if defined(__x86_64__) && defined(PS11_HAVE_AVX2_KERNEL)
    if (hasAvx2Kernel() && !g_forceGeneric.load(std::memory_order_relaxed)) return &sampleUnorm8Avx2;
#endif
    return &sampleUnorm8Generic;
}

}  // namespace ps11::fastpath
