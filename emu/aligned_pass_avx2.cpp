// The aligned-pass kernels at the Avx2 level (emu/aligned_pass_kernels.h): CMakeLists.txt builds
// this file with -mavx2 -mfma -mf16c on x86-64 only; alignedKernels() hands the table out only
// where the CPU runs that level.
#if !defined(__AVX2__)
#error "aligned_pass_avx2.cpp needs the Avx2 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include <algorithm>
#include <cstring>

#include "emu/aligned_pass_kernels.h"
#include "emu/lanes_avx2.h"
#include "emu/prefetch.h"
#include "ps11/texture.h"

namespace emu {

namespace {

inline __m256i loadu(const void* p) { return _mm256_loadu_si256(static_cast<const __m256i*>(p)); }
inline void storeu(void* p, __m256i v) { _mm256_storeu_si256(static_cast<__m256i*>(p), v); }

// 16 texels (64 bytes, b g r a) as r g b a uint16 planes at out[c] + k.
inline void deinterleave16(const uint8_t* p, uint16_t* const out[4], int k) {
    // Per 128-bit lane: b0-3 g0-3 r0-3 a0-3 of its four texels.
    const __m256i gather = _mm256_setr_epi8(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15, 0, 4, 8, 12, 1, 5, 9,
                                            13, 2, 6, 10, 14, 3, 7, 11, 15);
    const __m256i x = _mm256_shuffle_epi8(loadu(p), gather);       // texels 0-3 | 4-7
    const __m256i y = _mm256_shuffle_epi8(loadu(p + 32), gather);  // texels 8-11 | 12-15
    // Dwords: b0-3 b8-11 g0-3 g8-11 | b4-7 b12-15 g4-7 g12-15, then in texel order.
    const __m256i order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
    const __m256i bg = _mm256_permutevar8x32_epi32(_mm256_unpacklo_epi32(x, y), order);  // b0-15 | g0-15
    const __m256i ra = _mm256_permutevar8x32_epi32(_mm256_unpackhi_epi32(x, y), order);  // r0-15 | a0-15
    storeu(out[2] + k, _mm256_cvtepu8_epi16(_mm256_castsi256_si128(bg)));
    storeu(out[1] + k, _mm256_cvtepu8_epi16(_mm256_extracti128_si256(bg, 1)));
    storeu(out[0] + k, _mm256_cvtepu8_epi16(_mm256_castsi256_si128(ra)));
    storeu(out[3] + k, _mm256_cvtepu8_epi16(_mm256_extracti128_si256(ra, 1)));
}

void alignedDeinterleaveAvx2(const uint8_t* row, int count, uint16_t* const out[4]) {
    int k = 0;
    for (; k + 16 <= count; k += 16) {
        _mm_prefetch(reinterpret_cast<const char*>(row + 4 * k) + kPrefetchAhead, _MM_HINT_T0);
        deinterleave16(row + 4 * k, out, k);
    }
    if (k < count) {
        alignas(32) uint8_t last[64] = {};
        std::memcpy(last, row + 4 * k, size_t(4 * (count - k)));
        deinterleave16(last, out, k);
    }
}

void alignedPairSums4Avx2(const uint8_t* row, int n, uint16_t* const even[4], uint16_t* const odd[4]) {
    const __m256i gather = _mm256_setr_epi8(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15, 0, 4, 8, 12, 1, 5, 9,
                                            13, 2, 6, 10, 14, 3, 7, 11, 15);
    const __m256i order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
    const __m256i ones = _mm256_set1_epi8(1), low = _mm256_set1_epi32(0xffff);
    int j = 0;
    for (; j + 16 <= n; j += 16) {
        // Four groups of 16 texels (four blocks of 4): per group, the channel bytes in texel order
        // (b0-15 | g0-15, r0-15 | a0-15, as the deinterleave takes them), then the sums of byte
        // pairs: words b(4i)+b(4i+1), b(4i+2)+b(4i+3), … — a block's even and odd sums, side by side.
        __m256i bg[4], ra[4];
        for (int g = 0; g < 4; ++g) {
            const uint8_t* p = row + 64 * (j / 4 + g);
            _mm_prefetch(reinterpret_cast<const char*>(p) + kPrefetchAhead, _MM_HINT_T0);
            const __m256i x = _mm256_shuffle_epi8(loadu(p), gather), y = _mm256_shuffle_epi8(loadu(p + 32), gather);
            bg[g] = _mm256_maddubs_epi16(_mm256_permutevar8x32_epi32(_mm256_unpacklo_epi32(x, y), order), ones);
            ra[g] = _mm256_maddubs_epi16(_mm256_permutevar8x32_epi32(_mm256_unpackhi_epi32(x, y), order), ones);
        }
        // A channel's 16 blocks as dwords (even sum in the low word, odd in the high one), in two
        // registers of 8; then each half packed into 16 words in block order.
        auto store = [&](__m256i a, __m256i b, uint16_t* e, uint16_t* o) {
            storeu(e + j, _mm256_permute4x64_epi64(
                              _mm256_packus_epi32(_mm256_and_si256(a, low), _mm256_and_si256(b, low)), 0xD8));
            storeu(o + j, _mm256_permute4x64_epi64(_mm256_packus_epi32(_mm256_srli_epi32(a, 16), _mm256_srli_epi32(b, 16)),
                                                   0xD8));
        };
        store(_mm256_permute2x128_si256(bg[0], bg[1], 0x20), _mm256_permute2x128_si256(bg[2], bg[3], 0x20), even[2],
              odd[2]);
        store(_mm256_permute2x128_si256(bg[0], bg[1], 0x31), _mm256_permute2x128_si256(bg[2], bg[3], 0x31), even[1],
              odd[1]);
        store(_mm256_permute2x128_si256(ra[0], ra[1], 0x20), _mm256_permute2x128_si256(ra[2], ra[3], 0x20), even[0],
              odd[0]);
        store(_mm256_permute2x128_si256(ra[0], ra[1], 0x31), _mm256_permute2x128_si256(ra[2], ra[3], 0x31), even[3],
              odd[3]);
    }
    for (; j < n; ++j) {
        const uint8_t* t = row + 16 * j;
        for (int c = 0; c < 4; ++c) {
            const int b = ps11::kUnorm8Byte[c];
            even[c][j] = uint16_t(t[b] + t[4 + b]);
            odd[c][j] = uint16_t(t[8 + b] + t[12 + b]);
        }
    }
}

void alignedCombineAvx2(const uint16_t* const t[4], int n, int step, int32_t wx, uint16_t* const out[4]) {
    const HKind kind = hKindOf(wx);
    if (step == 1) {
        for (int c = 0; c < 4; ++c) {
            const uint16_t* a = t[c];
            uint16_t* o = out[c];
            if (kind == HKind::A) {
                std::memcpy(o, a, sizeof(uint16_t) * size_t(n));
            } else if (kind == HKind::S) {
                for (int j = 0; j < n; j += 16) storeu(o + j, _mm256_add_epi16(loadu(a + j), loadu(a + j + 1)));
            } else {
                const __m256i wa = _mm256_set1_epi16(int16_t(256 - wx)), wb = _mm256_set1_epi16(int16_t(wx));
                for (int j = 0; j < n; j += 16)
                    storeu(o + j, _mm256_add_epi16(_mm256_mullo_epi16(loadu(a + j), wa),
                                                   _mm256_mullo_epi16(loadu(a + j + 1), wb)));
            }
        }
        return;
    }
    // Steps 2 and 4: pairs (t[k], t[k + 1]) by pmaddwd with weights (1, 0), (1, 1) or
    // (256 − wx, wx): at most 65280, packed back to uint16 with unsigned saturation (exact).
    const int32_t wa = kind == HKind::A ? 1 : (kind == HKind::S ? 1 : 256 - wx);
    const int32_t wb = kind == HKind::A ? 0 : (kind == HKind::S ? 1 : wx);
    const __m256i w = _mm256_set1_epi32(int32_t(uint32_t(wa) | (uint32_t(wb) << 16)));
    if (step == 4) {
        // 64 staged values give 16 outputs: the pairs at 4j are the even dwords of each madd.
        const __m256i words = _mm256_setr_epi8(0, 1, 4, 5, 2, 3, 6, 7, 8, 9, 12, 13, 10, 11, 14, 15, 0, 1, 4, 5, 2, 3,
                                               6, 7, 8, 9, 12, 13, 10, 11, 14, 15);
        const __m256i dwords = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
        for (int c = 0; c < 4; ++c) {
            const uint16_t* a = t[c];
            uint16_t* o = out[c];
            for (int j = 0; j < n; j += 16) {
                const uint16_t* p = a + 4 * j;
                const __m256i m0 = _mm256_madd_epi16(loadu(p), w), m1 = _mm256_madd_epi16(loadu(p + 16), w);
                const __m256i m2 = _mm256_madd_epi16(loadu(p + 32), w), m3 = _mm256_madd_epi16(loadu(p + 48), w);
                // x: j0 j4 j1 j5 | j2 j6 j3 j7 (dwords), y: j8 j12 j9 j13 | j10 j14 j11 j15.
                const __m256i x = _mm256_blend_epi32(m0, _mm256_slli_epi64(m1, 32), 0xAA);
                const __m256i y = _mm256_blend_epi32(m2, _mm256_slli_epi64(m3, 32), 0xAA);
                const __m256i packed = _mm256_shuffle_epi8(_mm256_packus_epi32(x, y), words);
                storeu(o + j, _mm256_permutevar8x32_epi32(packed, dwords));
            }
        }
        return;
    }
    if (step == 2) {
        for (int c = 0; c < 4; ++c) {
            const uint16_t* a = t[c];
            uint16_t* o = out[c];
            for (int j = 0; j < n; j += 16) {
                const __m256i lo = _mm256_madd_epi16(loadu(a + 2 * j), w);
                const __m256i hi = _mm256_madd_epi16(loadu(a + 2 * j + 16), w);
                storeu(o + j, _mm256_permute4x64_epi64(_mm256_packus_epi32(lo, hi), 0xD8));
            }
        }
        return;
    }
    for (int c = 0; c < 4; ++c)
        for (int j = 0; j < n; ++j) {
            const uint32_t a = t[c][step * j], b = t[c][step * j + 1];
            out[c][j] =
                uint16_t(kind == HKind::A ? a : (kind == HKind::S ? a + b : a * uint32_t(256 - wx) + b * uint32_t(wx)));
        }
}

void alignedBuildTabulatedAvx2(const uint8_t* row, int rowTexels, const int32_t* off0, const int32_t* off1,
                               const int32_t* w, int n, uint16_t* const out[4], int shift) {
    const __m128i shiftV = _mm_cvtsi32_si128(shift);
    static constexpr int kByte[4] = {2, 1, 0, 3};  // r g b a within a b g r a word
    // Per channel: byte of a to bits 0-7 of each dword, byte of b to bits 16-23 (pmaddwd pairs).
    // Made once (a sprite's rows call this for a hundred columns: building them per call was a
    // third of its time).
    struct Selectors {
        alignas(32) int8_t a[4][32], b[4][32];
    };
    static constexpr Selectors kSel = [] {
        Selectors t{};
        for (int c = 0; c < 4; ++c)
            for (int i = 0; i < 32; ++i) {
                const int k = i & ~3, pos = i & 3;
                t.a[c][i] = pos == 0 ? int8_t(k % 16 + kByte[c]) : int8_t(-128);
                t.b[c][i] = pos == 2 ? int8_t(k % 16 + kByte[c]) : int8_t(-128);
            }
        return t;
    }();
    __m256i selA[4], selB[4];
    for (int c = 0; c < 4; ++c) {
        selA[c] = loadu(kSel.a[c]);
        selB[c] = loadu(kSel.b[c]);
    }
    const __m256i zero = _mm256_setzero_si256(), w256 = _mm256_set1_epi32(256);
    const __m256i three = _mm256_set1_epi32(3), four = _mm256_set1_epi32(4);
    const __m256i evensOdds = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
    const int* base = reinterpret_cast<const int*>(row);
    // Columns k .. k + 7: per channel the eight sums a·(256 − w) + b·w as dwords.
    auto columns = [&](int k, __m256i m[4]) __attribute__((always_inline)) {
        const __m256i i0 = _mm256_max_epi32(loadu(off0 + k), zero), i1 = _mm256_max_epi32(loadu(off1 + k), zero);
        // Eight columns over at most eight texels from the first one's (a magnification): one
        // load and two permutes; over at most sixteen (a nearly 1:1 mapping: the glare
        // sprites'), two loads and four permutes; each column's texel and the next one (a
        // minification's bilinear taps inside the row), eight 8-byte loads; else two gathers.
        __m256i a, b;
        const int first = std::max(off0[k], 0) >> 2;
        const __m256i firstV = _mm256_set1_epi32(first);
        const __m256i r0 = _mm256_sub_epi32(_mm256_srli_epi32(i0, 2), firstV);
        const __m256i r1 = _mm256_sub_epi32(_mm256_srli_epi32(i1, 2), firstV);
        const __m256i unaligned = _mm256_and_si256(_mm256_or_si256(i0, i1), three);  // byte offsets of whole texels
        const bool whole = _mm256_testz_si256(unaligned, unaligned);
        const __m256i apart = _mm256_xor_si256(_mm256_sub_epi32(i1, i0), four);
        if (whole && first + 8 <= rowTexels && withinEight(r0, r1)) {
            const __m256i words = loadu(base + first);
            a = _mm256_permutevar8x32_epi32(words, r0);
            b = _mm256_permutevar8x32_epi32(words, r1);
        } else if (whole && first + 16 <= rowTexels && withinSixteen(r0, r1)) {
            const __m256i lo = loadu(base + first), hi = loadu(base + first + 8);
            a = permuteSixteen(lo, hi, r0);
            b = permuteSixteen(lo, hi, r1);
        } else if (_mm256_testz_si256(apart, apart)) {
            // (off1 = off0 + 4 bytes: both texels lie in the row wherever off1 does.)
            auto pair = [&](int l) {
                int64_t v;
                std::memcpy(&v, row + std::max(off0[k + l], 0), 8);
                return v;
            };
            const __m256i lo = _mm256_permutevar8x32_epi32(_mm256_setr_epi64x(pair(0), pair(1), pair(2), pair(3)), evensOdds);
            const __m256i hi = _mm256_permutevar8x32_epi32(_mm256_setr_epi64x(pair(4), pair(5), pair(6), pair(7)), evensOdds);
            a = _mm256_permute2x128_si256(lo, hi, 0x20);
            b = _mm256_permute2x128_si256(lo, hi, 0x31);
        } else {
            a = _mm256_i32gather_epi32(base, i0, 1);
            b = _mm256_i32gather_epi32(base, i1, 1);
        }
        const __m256i wv = loadu(w + k);
        const __m256i wp = _mm256_or_si256(_mm256_sub_epi32(w256, wv), _mm256_slli_epi32(wv, 16));
        for (int c = 0; c < 4; ++c)
            m[c] = _mm256_madd_epi16(_mm256_or_si256(_mm256_shuffle_epi8(a, selA[c]), _mm256_shuffle_epi8(b, selB[c])),
                                     wp);
    };
    int j = 0;
    for (; j + 16 <= n; j += 16) {
        __m256i m[2][4];
        columns(j, m[0]);
        columns(j + 8, m[1]);
        for (int c = 0; c < 4; ++c)
            storeu(out[c] + j, _mm256_permute4x64_epi64(
                                   _mm256_packus_epi32(_mm256_srl_epi32(m[0][c], shiftV), _mm256_srl_epi32(m[1][c], shiftV)),
                                   0xD8));
    }
    // The last columns (a small sprite's rows are a few dozen) eight at a time, the last eight
    // ending at n (columns computed twice get the same values).
    auto eight = [&](int k) __attribute__((always_inline)) {
        __m256i m[4];
        columns(k, m);
        for (int c = 0; c < 4; ++c) {
            const __m256i packed = _mm256_packus_epi32(_mm256_srl_epi32(m[c], shiftV), zero);
            _mm_storeu_si128(reinterpret_cast<__m128i*>(out[c] + k),
                             _mm256_castsi256_si128(_mm256_permute4x64_epi64(packed, 0xD8)));
        }
    };
    if (j + 8 <= n) eight(j), j += 8;
    if (j < n && n >= 8) eight(n - 8), j = n;
    for (; j < n; ++j) {
        uint32_t a, b;
        std::memcpy(&a, row + std::max(off0[j], 0), 4);
        std::memcpy(&b, row + std::max(off1[j], 0), 4);
        for (int c = 0; c < 4; ++c)
            out[c][j] = uint16_t((((a >> (8 * kByte[c])) & 0xffu) * uint32_t(256 - w[j]) +
                                  ((b >> (8 * kByte[c])) & 0xffu) * uint32_t(w[j])) >>
                                 shift);
    }
}

// Dword lanes [0, t) all ones, the others 0 (a mask for maskload / maskstore).
inline __m256i firstDwords(int t) {
    return _mm256_cmpgt_epi32(_mm256_set1_epi32(t), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
}

// The first t (< 16) int16 lanes of v to dst: masked dwords, then the odd last lane.
inline void storeFirstLanes(int16_t* dst, __m256i v, int t) {
    _mm256_maskstore_epi32(reinterpret_cast<int*>(dst), firstDwords(t >> 1), v);
    if (t & 1) {
        alignas(32) int16_t lanes[16];
        storeu(lanes, v);
        dst[t - 1] = lanes[t - 1];
    }
}

// One group of 16 lanes of every channel: f(c, k) gives the vector of channel c at element k.
template <typename F>
inline void verticalGroups(int count, int lane, int16_t* const out[4], F f) {
    int k = 0;
    for (; k + 16 <= count; k += 16)
        for (int c = 0; c < 4; ++c) storeu(out[c] + lane + k, f(c, k));
    if (k < count)
        for (int c = 0; c < 4; ++c) storeFirstLanes(out[c] + lane + k, f(c, k), count - k);
}

// The 16-bit lanes the vertical blends are written over (emu/aligned_vertical.inc).
using VI = __m256i;
using VF = __m256;
inline VI add16(VI a, VI b) { return _mm256_add_epi16(a, b); }
inline VI and_(VI a, VI b) { return _mm256_and_si256(a, b); }
inline VI xor_(VI a, VI b) { return _mm256_xor_si256(a, b); }
inline VI mullo16(VI a, VI b) { return _mm256_mullo_epi16(a, b); }
inline VI madd16(VI a, VI b) { return _mm256_madd_epi16(a, b); }
inline VI packs32(VI a, VI b) { return _mm256_packs_epi32(a, b); }
inline VI unpacklo16(VI a, VI b) { return _mm256_unpacklo_epi16(a, b); }
inline VI unpackhi16(VI a, VI b) { return _mm256_unpackhi_epi16(a, b); }
inline VI unpacklo8(VI a, VI b) { return _mm256_unpacklo_epi8(a, b); }
inline VI unpackhi8(VI a, VI b) { return _mm256_unpackhi_epi8(a, b); }
inline VI packus16(VI a, VI b) { return _mm256_packus_epi16(a, b); }
inline VI set16(int16_t x) { return _mm256_set1_epi16(x); }
inline VI set32(int32_t x) { return _mm256_set1_epi32(x); }
inline VF setf(float x) { return _mm256_set1_ps(x); }
template <int S>
inline VI slli16(VI v) {
    return _mm256_slli_epi16(v, S);
}
template <int S>
inline VI srli16(VI v) {
    return _mm256_srli_epi16(v, S);
}
inline VI roundToInt(VF v) { return _mm256_cvtps_epi32(v); }
inline VF cvtf(VI v) { return _mm256_cvtepi32_ps(v); }
inline VF fmaddf(VF a, VF b, VF c) { return _mm256_fmadd_ps(a, b, c); }

// 16 pixels' words (b g r a bytes, `om` or-ed in) from int16 r g b a lanes, each clamped to
// [0, 255]: pixels 0-7 in `first`, 8-15 in `second`.
inline void packWords(__m256i r, __m256i g, __m256i b, __m256i a, __m256i om, __m256i& first, __m256i& second) {
    // packus: int16 -> uint8 with saturation to [0, 255], per 128-bit lane.
    const __m256i bg = _mm256_packus_epi16(b, g);                             // lane0: b0-7 g0-7, lane1: b8-15 g8-15
    const __m256i ra = _mm256_packus_epi16(r, a);                             // r, a likewise
    const __m256i bgLo = _mm256_unpacklo_epi8(bg, _mm256_srli_si256(bg, 8));  // b0 g0 b1 g1 ... (lane-wise)
    const __m256i raLo = _mm256_unpacklo_epi8(ra, _mm256_srli_si256(ra, 8));
    const __m256i w0 = _mm256_or_si256(_mm256_unpacklo_epi16(bgLo, raLo), om);  // px 0-3 | 8-11
    const __m256i w1 = _mm256_or_si256(_mm256_unpackhi_epi16(bgLo, raLo), om);  // px 4-7 | 12-15
    first = _mm256_permute2x128_si256(w0, w1, 0x20);                            // px 0-7
    second = _mm256_permute2x128_si256(w0, w1, 0x31);                           // px 8-15
}

// Every group of 16 lanes of every channel as 16 b g r a words at out + 4k (whole groups: up to
// 15 words past the count).
template <typename F>
inline void bytesGroups(int count, uint8_t* out, F f) {
    const __m256i none = _mm256_setzero_si256();
    for (int k = 0; k < count; k += 16) {
        __m256i first, second;
        packWords(f(0, k), f(1, k), f(2, k), f(3, k), none, first, second);
        storeu(out + 4 * k, first);
        storeu(out + 4 * k + 32, second);
    }
}

// 16 b g r a words (first: pixels 0-7, second: 8-15) to dst, or (Additive) those added with
// saturation to the words at `base` (dst, or the source of a copy into it not made yet); fewer
// than 16 `words`: those alone, by masked loads and stores (neither is touched past them).
template <bool Additive>
inline void putWords(const uint8_t* base, uint8_t* dst, __m256i first, __m256i second, int words) {
    __m256i* d0 = reinterpret_cast<__m256i*>(dst);
    __m256i* d1 = reinterpret_cast<__m256i*>(dst + 32);
    if (words < 16) {
        const __m256i m0 = firstDwords(words), m1 = firstDwords(words - 8);
        if constexpr (Additive) {
            first = _mm256_adds_epu8(first, _mm256_maskload_epi32(reinterpret_cast<const int*>(base), m0));
            second = _mm256_adds_epu8(second, _mm256_maskload_epi32(reinterpret_cast<const int*>(base + 32), m1));
        }
        _mm256_maskstore_epi32(reinterpret_cast<int*>(d0), m0, first);
        _mm256_maskstore_epi32(reinterpret_cast<int*>(d1), m1, second);
        return;
    }
    if constexpr (Additive) {
        first = _mm256_adds_epu8(first, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(base)));
        second = _mm256_adds_epu8(second, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(base + 32)));
    }
    _mm256_storeu_si256(d0, first);
    _mm256_storeu_si256(d1, second);
}

// Every group of 16 lanes of every channel as 16 b g r a words, each (word & keep) | set, stored
// at dst + 4k or (Additive) added with saturation to base's (putWords: never past the count).
template <bool Additive, typename F>
inline void storeGroups(int count, uint32_t keep, uint32_t set, const uint8_t* base, uint8_t* dst, F f) {
    const __m256i none = _mm256_setzero_si256();
    const __m256i kv = _mm256_set1_epi32(int32_t(keep)), sv = _mm256_set1_epi32(int32_t(set));
    for (int k = 0; k < count; k += 16) {
        // (The lines ahead asked for: a RowSource's row and the target's come from memory.)
        if constexpr (Additive) _mm_prefetch(reinterpret_cast<const char*>(base + 4 * k) + kPrefetchAhead, _MM_HINT_T0);
        if (!Additive || base != dst)
            _mm_prefetch(reinterpret_cast<const char*>(dst + 4 * k) + kPrefetchAhead, _MM_HINT_T0);
        __m256i first, second;
        packWords(f(0, k), f(1, k), f(2, k), f(3, k), none, first, second);
        putWords<Additive>(base + 4 * k, dst + 4 * k, _mm256_or_si256(_mm256_and_si256(first, kv), sv),
                           _mm256_or_si256(_mm256_and_si256(second, kv), sv), count - k);
    }
}

#include "emu/aligned_vertical.inc"

// Words of r0 (int16 r g b a planes) as b g r a bytes: clamp to [0, 255] and pack; `orMask`
// is or-ed in (X8R8G8B8's X = 0xff). Additive: saturating byte add onto the target row.
template <bool Additive>
int storeRow(const int16_t* const r[4], int count, uint32_t orMask, const uint8_t* base, uint8_t* dst) {
    const __m256i om = _mm256_set1_epi32(int32_t(orMask));
    for (int i = 0; i < count; i += 16) {
        auto ld = [&](int c) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(r[c] + i)); };
        __m256i first, second;
        packWords(ld(0), ld(1), ld(2), ld(3), om, first, second);
        _mm_prefetch(reinterpret_cast<const char*>(dst + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
        putWords<Additive>(base + 4 * i, dst + 4 * i, first, second, count - i);  // (the last pixels: their words alone)
    }
    return count;
}

int alignedStoreRowAvx2(bool additive, const int16_t* const r[4], int count, uint32_t orMask, const uint8_t* base,
                        uint8_t* dst) {
    return additive ? storeRow<true>(r, count, orMask, base, dst) : storeRow<false>(r, count, orMask, base, dst);
}

// fx12 words: each channel's grid value n clamped to [0, 4080] (additive: n + 16·d, the target
// byte d, clamped again), then its byte round_half_even(n / 16) = (n + 7 + (n >> 4 & 1)) >> 4,
// all in int16 lanes (at most 8160).
template <bool Additive>
int storeRow12(const int16_t* const r[4], int count, uint32_t orMask, const uint8_t* base, uint8_t* dst) {
    const __m256i om = _mm256_set1_epi32(int32_t(orMask)), zero = _mm256_setzero_si256();
    const __m256i top = _mm256_set1_epi16(int16_t(ps11::gridScale(ps11::Precision::Fx12))),
                  seven = _mm256_set1_epi16(7), one = _mm256_set1_epi16(1);
    const __m256i m8 = _mm256_set1_epi32(0xff);
    for (int i = 0; i < count; i += 16) {
        const bool tail = count - i < 16;
        const __m256i m0 = firstDwords(count - i), m1 = firstDwords(count - i - 8);
        __m256i old0 = zero, old1 = zero;
        if constexpr (Additive) {
            const int* b0 = reinterpret_cast<const int*>(base + 4 * i);
            const int* b1 = reinterpret_cast<const int*>(base + 4 * i + 32);
            old0 = tail ? _mm256_maskload_epi32(b0, m0) : _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b0));
            old1 = tail ? _mm256_maskload_epi32(b1, m1) : _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b1));
        }
        __m256i ch[4];
        for (int c = 0; c < 4; ++c) {
            __m256i n = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(r[c] + i));
            n = _mm256_min_epi16(_mm256_max_epi16(n, zero), top);
            if constexpr (Additive) {
                // The target's channel bytes of the 16 pixels as int16 lanes, in order.
                const int shift = 8 * ps11::kUnorm8Byte[c];
                const __m256i lo = _mm256_and_si256(_mm256_srl_epi32(old0, _mm_cvtsi32_si128(shift)), m8);
                const __m256i hi = _mm256_and_si256(_mm256_srl_epi32(old1, _mm_cvtsi32_si128(shift)), m8);
                const __m256i d = _mm256_permute4x64_epi64(_mm256_packs_epi32(lo, hi), 0xD8);
                n = _mm256_min_epi16(_mm256_add_epi16(n, _mm256_slli_epi16(d, 4)), top);
            }
            const __m256i odd = _mm256_and_si256(_mm256_srli_epi16(n, 4), one);
            ch[c] = _mm256_srli_epi16(_mm256_add_epi16(_mm256_add_epi16(n, seven), odd), 4);
        }
        __m256i first, second;
        packWords(ch[0], ch[1], ch[2], ch[3], om, first, second);
        _mm_prefetch(reinterpret_cast<const char*>(dst + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
        putWords<false>(dst + 4 * i, dst + 4 * i, first, second, count - i);  // (the sums are made: stored)
    }
    return count;
}

int alignedStoreRow12Avx2(bool additive, const int16_t* const r[4], int count, uint32_t orMask, const uint8_t* base,
                          uint8_t* dst) {
    return additive ? storeRow12<true>(r, count, orMask, base, dst) : storeRow12<false>(r, count, orMask, base, dst);
}

}  // namespace

const AlignedKernels avx2::kAligned{&alignedDeinterleaveAvx2, &alignedCombineAvx2,  &alignedPairSums4Avx2,
                                    &alignedBuildTabulatedAvx2, &verticalBlend,   &verticalBlend12,
                                    &verticalBytes,           &verticalStore,       &meanBytes,
                                    &alignedStoreRowAvx2,     &alignedStoreRow12Avx2};

}  // namespace emu
