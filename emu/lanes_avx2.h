// Lane helpers shared by the emulator's Avx2 kernels (emu/aligned_pass_avx2.cpp,
// emu/aligned_float_avx2.cpp, emu/output_merger_avx2.cpp); included only by files built with the
// Avx2 level's flags.
#pragma once

#if !defined(__AVX2__)
#error "emu/lanes_avx2.h is for files built with the Avx2 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include "ps11/lanes_avx2.h"

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

// float(b) / 255 for bytes held as floats (ps11/lanes_avx2.h).
using ps11::unitOfByte;

}  // namespace emu
