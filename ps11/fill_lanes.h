// A run of lanes set to one value. GCC 12 at -O2 compiles std::fill_n over a run of unknown
// length to one scalar store a lane (at -O3, the default build's level under GCC, it vectorises
// it itself); the row paths and the fast executor fill runs of up to kMaxSpan lanes per channel
// (constant colours, filled tiles, unbound stages), so on x86-64 these store 16 bytes at a time
// (SSE2: every x86-64 level), the value's bits unchanged. Elsewhere they are std::fill_n.
#pragma once

#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#else
#include <algorithm>
#endif

namespace ps11 {

#if defined(__SSE2__)

// (The last lanes of a run of at least one store's width: one more store ending at n, over lanes
// already set to the same value; shorter runs one lane at a time.)
inline void fillLanes(float* dst, int n, float value) {
    const __m128 v = _mm_set1_ps(value);
    if (n < 4) {
        for (int i = 0; i < n; ++i) dst[i] = value;
        return;
    }
    for (int i = 0; i + 4 <= n; i += 4) _mm_storeu_ps(dst + i, v);
    if (n & 3) _mm_storeu_ps(dst + n - 4, v);
}

inline void fillLanes(int16_t* dst, int n, int16_t value) {
    const __m128i v = _mm_set1_epi16(value);
    if (n < 8) {
        for (int i = 0; i < n; ++i) dst[i] = value;
        return;
    }
    for (int i = 0; i + 8 <= n; i += 8) _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + i), v);
    if (n & 7) _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + n - 8), v);
}

#else

inline void fillLanes(float* dst, int n, float value) {
    if (n > 0) std::fill_n(dst, n, value);
}

inline void fillLanes(int16_t* dst, int n, int16_t value) {
    if (n > 0) std::fill_n(dst, n, value);
}

#endif

}  // namespace ps11
