// The fast Unorm8 kernels at the Baseline level (any x86-64, or other, CPU), the choice of a
// level's table, and axisTable.
#define PS11_SAMPLER_LEVEL baseline
#include "ps11/texture_sampler_fast_impl.h"

#include <type_traits>

namespace ps11::fastpath {

const SamplerKernels& samplerKernels(SimdLevel level) {
#ifdef PS11_HAVE_AVX2
    return *simdTable(level, &baseline::kSampler, &avx2::kSampler);
#else
    (void)level;
    return baseline::kSampler;
#endif
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
