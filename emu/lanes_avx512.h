// Lane helpers of emu/'s Avx512 kernels (included only by *_avx512.cpp files, which
// CMakeLists.txt builds with that level's flags).
#pragma once

#include <immintrin.h>

namespace emu {

// float(b) / 255 correctly rounded for sixteen bytes held as floats: the Avx2 level's unitOfByte
// (ps11/lanes_avx2.h), a product and one Newton step with the exact residual b − 255·q.
inline __m512 unitOfByte(__m512 b) {
    const __m512 inv = _mm512_set1_ps(1.0f / 255.0f);
    const __m512 q = _mm512_mul_ps(b, inv);
    return _mm512_fmadd_ps(_mm512_fnmadd_ps(q, _mm512_set1_ps(255.0f), b), inv, q);
}

}  // namespace emu
