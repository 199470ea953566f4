// The float row path's kernels at the Avx2 level (emu/aligned_float_kernels.h): CMakeLists.txt
// builds this file with -mavx2 -mfma -mf16c -ffp-contract=off on x86-64 only;
// floatRowKernels() hands the table out only where the CPU runs that level.
#if !defined(__AVX2__)
#error "aligned_float_avx2.cpp needs the Avx2 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include "emu/aligned_float_kernels.h"
#include "emu/lanes_avx2.h"
#include "ps11/texture.h"

namespace emu {

namespace {

// (1 − f)·a + f·b: the reference sampler's lerp, operation for operation.
inline __m256 lerp8(__m256 a, __m256 b, __m256 f) {
    return _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(1.0f), f), a), _mm256_mul_ps(f, b));
}
inline float lerp1(float a, float b, float f) { return (1.0f - f) * a + f * b; }

void lerpColumnsAvx2(const float* a, const float* b, const float* f, int n, float* out) {
    int j = 0;
    for (; j + 8 <= n; j += 8)
        _mm256_storeu_ps(out + j, lerp8(_mm256_loadu_ps(a + j), _mm256_loadu_ps(b + j), _mm256_loadu_ps(f + j)));
    for (; j < n; ++j) out[j] = lerp1(a[j], b[j], f[j]);
}

void lerpGatherAvx2(const float* d, int len, const int32_t* i0, const int32_t* i1, const float* f, int n, float* out) {
    int j = 0;
    for (; j + 8 <= n; j += 8) {
        const __m256i k0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(i0 + j));
        const __m256i k1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(i1 + j));
        __m256 a, b;
        const int base = i0[j];
        const __m256i r0 = _mm256_sub_epi32(k0, _mm256_set1_epi32(base));
        const __m256i r1 = _mm256_sub_epi32(k1, _mm256_set1_epi32(base));
        // Eight columns over at most eight texels from the first one's (a magnification): one
        // load and two permutes; over at most sixteen (nearly 1:1), two loads and four; else two
        // gathers.
        if (base + 8 <= len && withinEight(r0, r1)) {
            const __m256 row = _mm256_loadu_ps(d + base);
            a = _mm256_permutevar8x32_ps(row, r0);
            b = _mm256_permutevar8x32_ps(row, r1);
        } else if (base + 16 <= len && withinSixteen(r0, r1)) {
            const __m256i lo = _mm256_castps_si256(_mm256_loadu_ps(d + base));
            const __m256i hi = _mm256_castps_si256(_mm256_loadu_ps(d + base + 8));
            a = _mm256_castsi256_ps(permuteSixteen(lo, hi, r0));
            b = _mm256_castsi256_ps(permuteSixteen(lo, hi, r1));
        } else {
            a = _mm256_i32gather_ps(d, k0, 4);
            b = _mm256_i32gather_ps(d, k1, 4);
        }
        _mm256_storeu_ps(out + j, lerp8(a, b, _mm256_loadu_ps(f + j)));
    }
    for (; j < n; ++j) out[j] = lerp1(d[i0[j]], d[i1[j]], f[j]);
}

void lerpRowAvx2(const float* a, const float* b, float f, int n, float* out) {
    const __m256 fv = _mm256_set1_ps(f), gv = _mm256_set1_ps(1.0f - f);
    int j = 0;
    for (; j + 8 <= n; j += 8)
        _mm256_storeu_ps(out + j, _mm256_add_ps(_mm256_mul_ps(gv, _mm256_loadu_ps(a + j)),
                                                _mm256_mul_ps(fv, _mm256_loadu_ps(b + j))));
    for (; j < n; ++j) out[j] = lerp1(a[j], b[j], f);
}

void decodeAvx2(const uint8_t* row, int n, float* out, size_t stride) {
    // float(b) / 255 is unorm8Values()[b] (unitOfByte).
    const __m256i byte = _mm256_set1_epi32(0xff);
    constexpr int kShift[4] = {16, 8, 0, 24};  // r g b a in a b g r a word
    int i = 0;
    const bool ahead = 4 * n >= kPrefetchRowBytes;
    for (; i + 8 <= n; i += 8) {
        if (ahead) _mm_prefetch(reinterpret_cast<const char*>(row + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
        const __m256i w = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + 4 * i));
        _mm256_storeu_ps(out + i, unitOfByte(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(w, 16), byte))));
        _mm256_storeu_ps(out + stride + i,
                         unitOfByte(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(w, 8), byte))));
        _mm256_storeu_ps(out + 2 * stride + i, unitOfByte(_mm256_cvtepi32_ps(_mm256_and_si256(w, byte))));
        _mm256_storeu_ps(out + 3 * stride + i, unitOfByte(_mm256_cvtepi32_ps(_mm256_srli_epi32(w, 24))));
    }
    const float* unit = ps11::Texture::unorm8Values();
    for (; i < n; ++i) {
        const uint32_t w = uint32_t(row[4 * i]) | uint32_t(row[4 * i + 1]) << 8 | uint32_t(row[4 * i + 2]) << 16 |
                           uint32_t(row[4 * i + 3]) << 24;
        for (size_t c = 0; c < 4; ++c) out[c * stride + size_t(i)] = unit[(w >> kShift[c]) & 0xffu];
    }
}

}  // namespace

const FloatRowKernels avx2::kFloatRow{&lerpColumnsAvx2, &lerpGatherAvx2, &lerpRowAvx2, &decodeAvx2};

}  // namespace emu
