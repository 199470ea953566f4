// Lane helpers shared by the Avx2 kernels of the library and the device
// (ps11/texture_sampler_fast_impl.h, emu/lanes_avx2.h); included only by files built with the
// Avx2 level's flags (CMakeLists.txt).
#pragma once

#if !defined(__AVX2__) || !defined(__FMA__)
#error "ps11/lanes_avx2.h is for files built with the Avx2 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

namespace ps11 {

// float(b) / 255 correctly rounded (ps11::Texture::unorm8Values()[b]) for bytes b held as floats:
// q = b·(1/255), then one Newton step with the exact residual b − 255·q (an FMA). The quotient for
// every byte (tests/test_simd_dispatch.cpp checks all 256 at every level), in a third of a
// division's time.
inline __m256 unitOfByte(__m256 b) {
    const __m256 inv = _mm256_set1_ps(1.0f / 255.0f);
    const __m256 q = _mm256_mul_ps(b, inv);
    return _mm256_fmadd_ps(_mm256_fnmadd_ps(q, _mm256_set1_ps(255.0f), b), inv, q);
}

}  // namespace ps11
