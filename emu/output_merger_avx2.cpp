// The output merger's kernels at the Avx2 level (emu/output_merger_kernels.h): CMakeLists.txt
// builds this file with -mavx2 -mfma -mf16c on x86-64 only; mergerKernels() hands the table out
// only where the CPU runs that level (CPUID F16C, AVX and OSXSAVE, and XCR0 keeping the AVX
// state: ps11::cpuFeatures).
#if !defined(__AVX2__) || !defined(__F16C__)
#error "output_merger_avx2.cpp needs the Avx2 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include <algorithm>
#include <bit>

#include "emu/lanes_avx2.h"
#include "emu/output_merger_kernels.h"
#include "emu/prefetch.h"

namespace emu {

namespace {

// VCVTPS2PH rounds to nearest even, as the Baseline conversion does.
void halvesF16c(const float* const f[4], int count, uint16_t* out) {
    constexpr int kRound = _MM_FROUND_TO_NEAREST_INT;
    int i = 0;
    for (; i + 8 <= count; i += 8) {
        const __m128i r = _mm256_cvtps_ph(_mm256_loadu_ps(f[0] + i), kRound);
        const __m128i g = _mm256_cvtps_ph(_mm256_loadu_ps(f[1] + i), kRound);
        const __m128i b = _mm256_cvtps_ph(_mm256_loadu_ps(f[2] + i), kRound);
        const __m128i a = _mm256_cvtps_ph(_mm256_loadu_ps(f[3] + i), kRound);
        const __m128i rgLo = _mm_unpacklo_epi16(r, g), rgHi = _mm_unpackhi_epi16(r, g);  // r0 g0 r1 g1 …
        const __m128i baLo = _mm_unpacklo_epi16(b, a), baHi = _mm_unpackhi_epi16(b, a);
        __m128i* d = reinterpret_cast<__m128i*>(out + 4 * i);
        _mm_storeu_si128(d + 0, _mm_unpacklo_epi32(rgLo, baLo));  // pixels 0, 1
        _mm_storeu_si128(d + 1, _mm_unpackhi_epi32(rgLo, baLo));  // 2, 3
        _mm_storeu_si128(d + 2, _mm_unpacklo_epi32(rgHi, baHi));  // 4, 5
        _mm_storeu_si128(d + 3, _mm_unpackhi_epi32(rgHi, baHi));  // 6, 7
    }
    for (; i < count; ++i) {
        const __m128i h = _mm_cvtps_ph(_mm_setr_ps(f[0][i], f[1][i], f[2][i], f[3][i]), kRound);
        _mm_storel_epi64(reinterpret_cast<__m128i*>(out + 4 * i), h);
    }
}

// Eight values as bytes: nearest even of the exact v·255 is floor(v·255 + 1/2) for every v in
// [0, 1] (the exact product is a tie only at v = 1/2, 127.5, whose even neighbour is 128). The
// fused sum, rounded to float and truncated, gives that floor or one more (where rounding
// reached the next integer n); the sign of v·255 + (1/2 − n), fused again, says which. The
// clamp is the Baseline level's (MAXPS gives its second operand, 0, for NaN). The same bytes as
// its exact product in double, for every float (checked over all 2^32 of them).
inline __m256i bytes8(__m256 x) {
    const __m256 zero = _mm256_setzero_ps(), k255 = _mm256_set1_ps(255.0f), half = _mm256_set1_ps(0.5f);
    const __m256 v = _mm256_min_ps(_mm256_max_ps(x, zero), _mm256_set1_ps(1.0f));
    const __m256i n = _mm256_cvttps_epi32(_mm256_fmadd_ps(v, k255, half));
    const __m256 below = _mm256_fmadd_ps(v, k255, _mm256_sub_ps(half, _mm256_cvtepi32_ps(n)));
    return _mm256_add_epi32(n, _mm256_castps_si256(_mm256_cmp_ps(below, zero, _CMP_LT_OQ)));  // −1 there
}

// Eight lanes of a channel per step (bytes8).
void unorm8WordsAvx2(const float* const f[4], int count, uint32_t alphaFill, uint32_t* words) {
    const auto load = [](const float* p) { return bytes8(_mm256_loadu_ps(p)); };
    const __m256i fill = _mm256_set1_epi32(int32_t(alphaFill));
    int i = 0;
    for (; i + 8 <= count; i += 8) {
        const __m256i w = _mm256_or_si256(
            _mm256_or_si256(_mm256_slli_epi32(load(f[3] + i), 24), _mm256_slli_epi32(load(f[0] + i), 16)),
            _mm256_or_si256(_mm256_slli_epi32(load(f[1] + i), 8), load(f[2] + i)));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(words + i), _mm256_or_si256(w, fill));
    }
    if (i < count) {
        const float* const rest[4] = {f[0] + i, f[1] + i, f[2] + i, f[3] + i};
        baseline::kMerger.unorm8Words(rest, count - i, alphaFill, words + i);
    }
}

// Two pixels' channels per step (bytes8); four pixels packed, then put in b g r a order.
void unorm8WordsRgbaAvx2(const float* rgba, int count, uint32_t alphaFill, uint32_t* words) {
    const __m128i toBgra = _mm_setr_epi8(2, 1, 0, 3, 6, 5, 4, 7, 10, 9, 8, 11, 14, 13, 12, 15);
    const __m128i fill = _mm_set1_epi32(int32_t(alphaFill));
    int i = 0;
    for (; i + 4 <= count; i += 4) {
        const float* p = rgba + 4 * size_t(i);
        const __m256i a = bytes8(_mm256_loadu_ps(p)), b = bytes8(_mm256_loadu_ps(p + 8));  // r g b a int32
        // As int16 within each 128-bit half: pixels 0 and 2 in the low half, 1 and 3 in the high.
        const __m256i packed = _mm256_packs_epi32(a, b);
        const __m128i lo = _mm256_castsi256_si128(packed), hi = _mm256_extracti128_si256(packed, 1);
        const __m128i ordered = _mm_packus_epi16(_mm_unpacklo_epi64(lo, hi), _mm_unpackhi_epi64(lo, hi));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(words + i), _mm_or_si128(_mm_shuffle_epi8(ordered, toBgra), fill));
    }
    if (i < count) baseline::kMerger.unorm8WordsRgba(rgba + 4 * size_t(i), count - i, alphaFill, words + i);
}

// Eight pixels per step, in runs of up to 64: where a source channel is above 0, each channel's
// sum (the byte's value without dividing, unitOfByte, plus the saturated source), then the sums'
// words as unorm8WordsAvx2 makes them; elsewhere the destination word as it is.
void addUnorm8WordsAvx2(const float* const src[4], const uint8_t* words, int count, uint32_t alphaFill, uint32_t* out) {
    constexpr int kRun = 64;
    const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    const __m256i byte = _mm256_set1_epi32(0xff), fill = _mm256_set1_epi32(int32_t(alphaFill));
    constexpr int kShift[4] = {16, 8, 0, 24};  // r g b a in a b g r a word
    alignas(32) float sum[4][kRun];
    int i = 0;
    while (i + 8 <= count) {
        const int run = std::min(kRun, (count - i) & ~7);
        uint32_t lit = 0;  // the run's blocks of eight with a source above 0
        for (int b = 0; b < run; b += 8) {
            const int at = i + b;
            // The target's line ahead: a row's pass waits on each line else.
            _mm_prefetch(reinterpret_cast<const char*>(words + 4 * at) + kPrefetchAhead, _MM_HINT_T0);
            const __m256 s[4] = {_mm256_loadu_ps(src[0] + at), _mm256_loadu_ps(src[1] + at),
                                 _mm256_loadu_ps(src[2] + at), _mm256_loadu_ps(src[3] + at)};
            const __m256 above = _mm256_or_ps(
                _mm256_or_ps(_mm256_cmp_ps(s[0], zero, _CMP_GT_OQ), _mm256_cmp_ps(s[1], zero, _CMP_GT_OQ)),
                _mm256_or_ps(_mm256_cmp_ps(s[2], zero, _CMP_GT_OQ), _mm256_cmp_ps(s[3], zero, _CMP_GT_OQ)));
            const __m256i w = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(words + 4 * at));
            if (_mm256_testz_ps(above, above)) {
                _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + at), _mm256_or_si256(w, fill));
                continue;
            }
            lit |= 1u << (b / 8);
            for (int c = 0; c < 4; ++c) {
                const __m256 sv = _mm256_and_ps(_mm256_cmp_ps(s[c], zero, _CMP_GT_OQ), _mm256_min_ps(s[c], one));
                const __m256 d =
                    unitOfByte(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(w, kShift[c]), byte)));
                _mm256_store_ps(sum[c] + b, _mm256_add_ps(sv, d));
            }
        }
        for (uint32_t m = lit; m; m &= m - 1) {
            const int b = 8 * std::countr_zero(m);
            const float* const sums[4] = {sum[0] + b, sum[1] + b, sum[2] + b, sum[3] + b};
            unorm8WordsAvx2(sums, 8, alphaFill, out + i + b);
        }
        i += run;
    }
    if (i < count) {
        const float* const rest[4] = {src[0] + i, src[1] + i, src[2] + i, src[3] + i};
        baseline::kMerger.addUnorm8Words(rest, words + 4 * size_t(i), count - i, alphaFill, out + i);
    }
}

int blendRgba32FAvx2(const FloatBlendConsts& k, const float* const f[4], int i, int count, float* q) {
    const auto both = [](const float* x) { return _mm256_broadcast_ps(reinterpret_cast<const __m128*>(x)); };
    const auto mask = [&](const uint32_t* m) { return both(reinterpret_cast<const float*>(m)); };
    const __m256 fs = both(k.fs), fd = both(k.fd), ks = both(k.ks), kd = both(k.kd);
    const __m256 zs = mask(k.zs), zd = mask(k.zd), on = mask(k.on);
    for (; i + 8 <= count; i += 8) {
        // Planar r g b a of pixels i .. i + 7 to four registers of two interleaved pixels each.
        const __m256 r = _mm256_loadu_ps(f[0] + i), g = _mm256_loadu_ps(f[1] + i), b = _mm256_loadu_ps(f[2] + i),
                     a = _mm256_loadu_ps(f[3] + i);
        const __m256d rg0 = _mm256_castps_pd(_mm256_unpacklo_ps(r, g));  // r0 g0 r1 g1 | r4 g4 r5 g5
        const __m256d rg1 = _mm256_castps_pd(_mm256_unpackhi_ps(r, g));  // r2 g2 r3 g3 | r6 g6 r7 g7
        const __m256d ba0 = _mm256_castps_pd(_mm256_unpacklo_ps(b, a));
        const __m256d ba1 = _mm256_castps_pd(_mm256_unpackhi_ps(b, a));
        const __m256 p04 = _mm256_castpd_ps(_mm256_unpacklo_pd(rg0, ba0));  // pixel 0 | pixel 4
        const __m256 p15 = _mm256_castpd_ps(_mm256_unpackhi_pd(rg0, ba0));
        const __m256 p26 = _mm256_castpd_ps(_mm256_unpacklo_pd(rg1, ba1));
        const __m256 p37 = _mm256_castpd_ps(_mm256_unpackhi_pd(rg1, ba1));
        const __m256 s[4] = {_mm256_permute2f128_ps(p04, p15, 0x20), _mm256_permute2f128_ps(p26, p37, 0x20),
                             _mm256_permute2f128_ps(p04, p15, 0x31), _mm256_permute2f128_ps(p26, p37, 0x31)};
        float* const dst = q + 4 * size_t(i);
        const __m256 d[4] = {_mm256_loadu_ps(dst), _mm256_loadu_ps(dst + 8), _mm256_loadu_ps(dst + 16),
                             _mm256_loadu_ps(dst + 24)};
        __m256 nan = _mm256_setzero_ps();
        for (int h = 0; h < 4; ++h) nan = _mm256_or_ps(nan, _mm256_cmp_ps(s[h], d[h], _CMP_UNORD_Q));
        if (_mm256_movemask_ps(nan)) return i;  // the caller blends this group pixel by pixel
        for (int h = 0; h < 4; ++h) {
            const __m256 ts = _mm256_mul_ps(ks, _mm256_mul_ps(s[h], fs)),
                         td = _mm256_mul_ps(kd, _mm256_mul_ps(d[h], fd));
            const __m256 x = _mm256_andnot_ps(zd, td);
            const __m256 y = _mm256_or_ps(_mm256_and_ps(zd, ts), _mm256_andnot_ps(zd, _mm256_add_ps(ts, td)));
            const __m256 res = _mm256_or_ps(_mm256_and_ps(zs, x), _mm256_andnot_ps(zs, y));
            _mm256_storeu_ps(dst + 8 * h, _mm256_or_ps(_mm256_and_ps(on, res), _mm256_andnot_ps(on, d[h])));
        }
    }
    return i;
}

}  // namespace

const MergerKernels avx2::kMerger{&halvesF16c, &unorm8WordsAvx2, &unorm8WordsRgbaAvx2, &addUnorm8WordsAvx2,
                                  &blendRgba32FAvx2};

}  // namespace emu
