// Lane helpers shared by the emulator's Avx2 kernels (emu/aligned_pass_avx2.cpp,
// emu/aligned_float_avx2.cpp, emu/output_merger_avx2.cpp); included only by files built with the
// Avx2 level's flags.
#pragma once

#if !defined(__AVX2__)
#error "emu/lanes_avx2.h is for files built with the Avx2 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

namespace emu {

// Whether every lane of r0 and r1 (texel indices relative to a block's first texel) lies in
// [0, 7]: then one load of eight texels and a permute each serve the block instead of two
// gathers (a magnification's columns).
inline bool withinEight(__m256i r0, __m256i r1) {
    const __m256i seven = _mm256_set1_epi32(7);
    const __m256i bad = _mm256_or_si256(_mm256_or_si256(_mm256_cmpgt_epi32(r0, seven), _mm256_cmpgt_epi32(r1, seven)),
                                        _mm256_srai_epi32(_mm256_or_si256(r0, r1), 31));
    return _mm256_testz_si256(bad, bad);
}

// The same for [0, 15]: two loads of eight texels and two permutes each, blended (a nearly 1:1
// mapping's eight columns reach a ninth texel, which withinEight refuses).
inline bool withinSixteen(__m256i r0, __m256i r1) {
    const __m256i fifteen = _mm256_set1_epi32(15);
    const __m256i bad = _mm256_or_si256(_mm256_or_si256(_mm256_cmpgt_epi32(r0, fifteen), _mm256_cmpgt_epi32(r1, fifteen)),
                                        _mm256_srai_epi32(_mm256_or_si256(r0, r1), 31));
    return _mm256_testz_si256(bad, bad);
}
// Lane k of the sixteen dwords lo ‖ hi at index r[k] in [0, 15].
inline __m256i permuteSixteen(__m256i lo, __m256i hi, __m256i r) {
    const __m256i fromHi = _mm256_cmpgt_epi32(r, _mm256_set1_epi32(7));
    return _mm256_blendv_epi8(_mm256_permutevar8x32_epi32(lo, r), _mm256_permutevar8x32_epi32(hi, r), fromHi);
}

// float(b) / 255 correctly rounded (ps11::Texture::unorm8Values()[b]) for bytes b held as floats:
// q = b·(1/255), then one Newton step with the exact residual b − 255·q (an FMA). The quotient for
// every byte (tests/test_simd_dispatch.cpp checks all 256 at every level), in a third of a
// division's time.
inline __m256 unitOfByte(__m256 b) {
    const __m256 inv = _mm256_set1_ps(1.0f / 255.0f);
    const __m256 q = _mm256_mul_ps(b, inv);
    return _mm256_fmadd_ps(_mm256_fnmadd_ps(q, _mm256_set1_ps(255.0f), b), inv, q);
}

}  // namespace emu
