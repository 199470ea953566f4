// The output merger's kernels at the Avx512 level (emu/output_merger_kernels.h): the float to
// 8-bit words conversions and the ONE/ONE sums into 8-bit words sixteen floats a step; every other
// kernel is the Avx2 level's.
// CMakeLists.txt builds this file with the Avx2 level's flags and AVX-512 F, DQ, BW and VL (and
// -ffp-contract=off: no product is fused into a sum) on x86-64 only; mergerKernels() hands the
// table out only where the CPU runs that level.
#if !defined(__AVX512F__) || !defined(__AVX512BW__) || !defined(__AVX2__)
#error "output_merger_avx512.cpp needs the Avx512 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include "emu/lanes_avx512.h"
#include "emu/output_merger_kernels.h"
#include "emu/prefetch.h"

namespace emu {

namespace {

// Sixteen channels as bytes: nearest even of the exact v·255 is floor(v·255 + 1/2) for every v in
// [0, 1] (the exact product is a tie only at v = 1/2, 127.5, whose even neighbour is 128), and
// that floor is the floor of the sum rounded down (a fused product and sum in that rounding
// mode, then truncated). The clamp is the other levels' (VMAXPS gives its second operand, 0, for
// NaN). The same bytes as the Baseline level's exact product in double, for every float (checked
// over all 2^32 of them).
inline __m512i bytes16(__m512 x) {
    const __m512 v = _mm512_min_ps(_mm512_max_ps(x, _mm512_setzero_ps()), _mm512_set1_ps(1.0f));
    const __m512 sum = _mm512_fmadd_round_ps(v, _mm512_set1_ps(255.0f), _mm512_set1_ps(0.5f),
                                             _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    return _mm512_cvtt_roundps_epi32(sum, _MM_FROUND_NO_EXC);
}
inline __m512i bytes16(const float* p) { return bytes16(_mm512_loadu_ps(p)); }

void unorm8WordsAvx512(const float* const f[4], int count, uint32_t alphaFill, uint32_t* words) {
    const __m512i fill = _mm512_set1_epi32(int32_t(alphaFill));
    int i = 0;
    for (; i + 16 <= count; i += 16) {
        const __m512i w = _mm512_or_si512(
            _mm512_or_si512(_mm512_slli_epi32(bytes16(f[3] + i), 24), _mm512_slli_epi32(bytes16(f[0] + i), 16)),
            _mm512_or_si512(_mm512_slli_epi32(bytes16(f[1] + i), 8), bytes16(f[2] + i)));
        _mm512_storeu_si512(words + i, _mm512_or_si512(w, fill));
    }
    if (i < count) {
        const float* const rest[4] = {f[0] + i, f[1] + i, f[2] + i, f[3] + i};
        avx2::kMerger.unorm8Words(rest, count - i, alphaFill, words + i);
    }
}

// Four pixels' r g b a a register: their bytes in order (VPMOVDB), then put in b g r a order.
void unorm8WordsRgbaAvx512(const float* rgba, int count, uint32_t alphaFill, uint32_t* words) {
    const __m128i toBgra = _mm_setr_epi8(2, 1, 0, 3, 6, 5, 4, 7, 10, 9, 8, 11, 14, 13, 12, 15);
    const __m128i fill = _mm_set1_epi32(int32_t(alphaFill));
    int i = 0;
    for (; i + 4 <= count; i += 4) {
        const __m128i bytes = _mm_shuffle_epi8(_mm512_cvtepi32_epi8(bytes16(rgba + 4 * size_t(i))), toBgra);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(words + i), _mm_or_si128(bytes, fill));
    }
    if (i < count) avx2::kMerger.unorm8WordsRgba(rgba + 4 * size_t(i), count - i, alphaFill, words + i);
}

// Sixteen pixels a step: where a source channel is above 0, each channel's sum sat(s) + d (d the
// byte's value, unitOfByte) and its byte (bytes16); elsewhere the destination word as it is.
void addUnorm8WordsAvx512(const float* const src[4], const uint8_t* words, int count, uint32_t alphaFill,
                          uint32_t* out) {
    const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
    const __m512i byte = _mm512_set1_epi32(0xff), fill = _mm512_set1_epi32(int32_t(alphaFill));
    constexpr unsigned kShift[4] = {16, 8, 0, 24};  // r g b a in a b g r a word
    int i = 0;
    for (; i + 16 <= count; i += 16) {
        // The target's line ahead: a row's pass waits on each line else.
        _mm_prefetch(reinterpret_cast<const char*>(words + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
        const __m512i w = _mm512_loadu_si512(words + 4 * size_t(i));
        __mmask16 above[4], any = 0;
        __m512 s[4];
        for (int c = 0; c < 4; ++c) {
            s[c] = _mm512_loadu_ps(src[c] + i);
            above[c] = _mm512_cmp_ps_mask(s[c], zero, _CMP_GT_OQ);  // false for NaN
            any |= above[c];
        }
        if (!any) {
            _mm512_storeu_si512(out + i, _mm512_or_si512(w, fill));
            continue;
        }
        __m512i r = fill;
        for (int c = 0; c < 4; ++c) {
            const __m512 sv = _mm512_maskz_min_ps(above[c], s[c], one);  // sat: min(s, 1) above 0, else 0
            const __m512 d = unitOfByte(_mm512_cvtepi32_ps(_mm512_and_si512(_mm512_srli_epi32(w, kShift[c]), byte)));
            r = _mm512_or_si512(r, _mm512_slli_epi32(bytes16(_mm512_add_ps(sv, d)), kShift[c]));
        }
        _mm512_storeu_si512(out + i, r);
    }
    if (i < count) {
        const float* const rest[4] = {src[0] + i, src[1] + i, src[2] + i, src[3] + i};
        avx2::kMerger.addUnorm8Words(rest, words + 4 * size_t(i), count - i, alphaFill, out + i);
    }
}

}  // namespace

const MergerKernels& avx512::mergerTable() {
    static const MergerKernels table = [] {
        MergerKernels k = avx2::kMerger;
        k.unorm8Words = &unorm8WordsAvx512;
        k.unorm8WordsRgba = &unorm8WordsRgbaAvx512;
        k.addUnorm8Words = &addUnorm8WordsAvx512;
        return k;
    }();
    return table;
}

}  // namespace emu
