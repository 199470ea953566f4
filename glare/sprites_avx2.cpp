// The sensor row at the Avx2 level (glare/sensors_kernels.h): eight pixels at a time, the same float
// operations as the Baseline level (no FMA: built with -ffp-contract=off), then the rest there;
// and the float frames' bytes, 32 values at a time.
#if !defined(__AVX2__)
#error "sprites_avx2.cpp needs the Avx2 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include "glare/sensors_kernels.h"

namespace glare {

namespace {

void fireRowAvx2(const uint8_t* row, uint32_t width, int rs, int bs, float sumAtLeast, uint64_t* fires) {
    const __m256i m = _mm256_set1_epi32(0xff);
    const __m256 kr = _mm256_set1_ps(0.30f), kg = _mm256_set1_ps(0.59f), kb = _mm256_set1_ps(0.11f);
    const __m256 t = _mm256_set1_ps(sumAtLeast);
    const __m128i sr = _mm_cvtsi32_si128(rs), sb = _mm_cvtsi32_si128(bs);
    uint32_t x = 0;
    for (; x + 8 <= width; x += 8) {
        const __m256i w = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + size_t(x) * 4));
        const __m256 r = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srl_epi32(w, sr), m));
        const __m256 g = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(w, 8), m));
        const __m256 b = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srl_epi32(w, sb), m));
        const __m256 l = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(kr, r), _mm256_mul_ps(kg, g)), _mm256_mul_ps(kb, b));
        fires[x / 64] |= uint64_t(uint32_t(_mm256_movemask_ps(_mm256_cmp_ps(l, t, _CMP_GE_OQ)))) << (x % 64);
    }
    if (x < width) {
        // The rest at the Baseline level, into a word of its own (x is a multiple of 8).
        uint64_t rest[1] = {0};
        baseline::kSensors.fireRow(row + size_t(x) * 4, width - x, rs, bs, sumAtLeast, rest);
        fires[x / 64] |= rest[0] << (x % 64);
    }
}

// frameByte of 32 floats a step: min(max(v, 0), 1)·255 + 0.5 truncated, as the Baseline level
// computes it (MAXPS returns its second operand, 0, for NaN); the 32-bit integers packed to
// bytes in order (packs and packus work per 128-bit lane: a dword permute puts them back).
void frameBytesAvx2(const float* in, size_t n, uint8_t* out) {
    const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f), k255 = _mm256_set1_ps(255.0f),
                 half = _mm256_set1_ps(0.5f);
    const __m256i order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
    auto ints = [&](const float* p) {
        const __m256 x = _mm256_min_ps(_mm256_max_ps(_mm256_loadu_ps(p), zero), one);
        return _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(x, k255), half));
    };
    size_t i = 0;
    for (; i + 32 <= n; i += 32) {
        const __m256i lo = _mm256_packs_epi32(ints(in + i), ints(in + i + 8));
        const __m256i hi = _mm256_packs_epi32(ints(in + i + 16), ints(in + i + 24));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i),
                            _mm256_permutevar8x32_epi32(_mm256_packus_epi16(lo, hi), order));
    }
    baseline::kSensors.frameBytes(in + i, n - i, out + i);
}

}  // namespace

const SensorKernels avx2::kSensors{&fireRowAvx2, &frameBytesAvx2};

}  // namespace glare
