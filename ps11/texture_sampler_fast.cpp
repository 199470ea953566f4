// The fast Unorm8 kernels for any x86-64 (or other) CPU, and the runtime choice between them
// and the AVX2 build (texture_sampler_fast_avx2.cpp).
#define PS11_FAST_KERNEL sampleUnorm8Generic
#include "ps11/cpu_features.h"
#include "ps11/texture_sampler_fast_impl.h"

#include <atomic>
#include <type_traits>

namespace ps11::fastpath {

namespace {
std::atomic<bool> g_forceGeneric{false};
}

bool hasAvx2Kernel() {
#if defined(__x86_64__) && defined(PS11_HAVE_AVX2_KERNEL)
    return cpuFeatures().avx2Fma();
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

void axisTable(TextureAddress mode, bool linear, int count, const float* c, uint32_t n, int32_t* i0, int32_t* i1,
               int32_t* w) {
    auto run = [&](auto modeTag) {
        constexpr TextureAddress M = decltype(modeTag)::value;
        if (linear) {
            axis<M, true>(count, c, n, i0, i1, w);
        } else {
            axis<M, false>(count, c, n, i0, i1, w);
            for (int i = 0; i < count; ++i) i1[i] = i0[i], w[i] = 0;
        }
    };
    switch (mode) {
        case TextureAddress::Wrap: run(std::integral_constant<TextureAddress, TextureAddress::Wrap>{}); break;
        case TextureAddress::Mirror: run(std::integral_constant<TextureAddress, TextureAddress::Mirror>{}); break;
        case TextureAddress::Clamp: run(std::integral_constant<TextureAddress, TextureAddress::Clamp>{}); break;
        case TextureAddress::Border: run(std::integral_constant<TextureAddress, TextureAddress::Border>{}); break;
        case TextureAddress::MirrorOnce:
            run(std::integral_constant<TextureAddress, TextureAddress::MirrorOnce>{});
            break;
    }
}

}  // namespace ps11::fastpath
