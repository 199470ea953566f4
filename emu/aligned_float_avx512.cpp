// The float row path's kernels at the Avx512 level (emu/aligned_float_kernels.h): the decode of
// 8-bit rows and the lerps of whole rows and of consecutive columns sixteen lanes a step; every
// other kernel is the Avx2 level's. CMakeLists.txt builds this file with the Avx2 level's flags,
// AVX-512 F, DQ, BW and VL and -ffp-contract=off (no lerp's product is fused into its sum) on
// x86-64 only; floatRowKernels() hands the table out only where the CPU runs that level.
#if !defined(__AVX512F__) || !defined(__AVX512BW__) || !defined(__AVX2__)
#error "aligned_float_avx512.cpp needs the Avx512 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include "emu/aligned_float_kernels.h"
#include "emu/lanes_avx512.h"

namespace emu {

namespace {

// (1 − f)·a + f·b: the reference sampler's lerp, operation for operation.
inline __m512 lerp16(__m512 a, __m512 b, __m512 f) {
    return _mm512_add_ps(_mm512_mul_ps(_mm512_sub_ps(_mm512_set1_ps(1.0f), f), a), _mm512_mul_ps(f, b));
}

void lerpColumnsAvx512(const float* a, const float* b, const float* f, int n, float* out) {
    int j = 0;
    for (; j + 16 <= n; j += 16)
        _mm512_storeu_ps(out + j,
                         lerp16(_mm512_loadu_ps(a + j), _mm512_loadu_ps(b + j), _mm512_loadu_ps(f + j)));
    if (j < n) avx2::kFloatRow.lerpColumns(a + j, b + j, f + j, n - j, out + j);
}

void lerpRowAvx512(const float* a, const float* b, float f, int n, float* out) {
    const __m512 fv = _mm512_set1_ps(f), gv = _mm512_set1_ps(1.0f - f);
    int j = 0;
    for (; j + 16 <= n; j += 16)
        _mm512_storeu_ps(out + j, _mm512_add_ps(_mm512_mul_ps(gv, _mm512_loadu_ps(a + j)),
                                                _mm512_mul_ps(fv, _mm512_loadu_ps(b + j))));
    if (j < n) avx2::kFloatRow.lerpRow(a + j, b + j, f, n - j, out + j);
}

void decodeAvx512(const uint8_t* row, int n, float* out, size_t stride) {
    // float(b) / 255 is unorm8Values()[b] (unitOfByte).
    const __m512i byte = _mm512_set1_epi32(0xff);
    int i = 0;
    const bool ahead = 4 * n >= kPrefetchRowBytes;
    for (; i + 16 <= n; i += 16) {
        if (ahead) _mm_prefetch(reinterpret_cast<const char*>(row + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
        const __m512i w = _mm512_loadu_si512(row + 4 * size_t(i));
        const auto value = [&](__m512i bytes) { return unitOfByte(_mm512_cvtepi32_ps(bytes)); };
        _mm512_storeu_ps(out + i, value(_mm512_and_si512(_mm512_srli_epi32(w, 16), byte)));
        _mm512_storeu_ps(out + stride + i, value(_mm512_and_si512(_mm512_srli_epi32(w, 8), byte)));
        _mm512_storeu_ps(out + 2 * stride + i, value(_mm512_and_si512(w, byte)));
        _mm512_storeu_ps(out + 3 * stride + i, value(_mm512_srli_epi32(w, 24)));
    }
    if (i < n) avx2::kFloatRow.decode(row + 4 * size_t(i), n - i, out + i, stride);
}

}  // namespace

const FloatRowKernels& avx512::floatRowTable() {
    static const FloatRowKernels table = [] {
        FloatRowKernels k = avx2::kFloatRow;
        k.lerpColumns = &lerpColumnsAvx512;
        k.lerpRow = &lerpRowAvx512;
        k.decode = &decodeAvx512;
        return k;
    }();
    return table;
}

}  // namespace emu
