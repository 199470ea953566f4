// The AVX2 kernels of the aligned-pass path (emu/aligned_pass_kernels.h), compiled with -mavx2
// (CMakeLists.txt) and called only when the CPU has AVX2.
#include <immintrin.h>

#include <algorithm>
#include <cstring>

#include "emu/aligned_pass_kernels.h"

namespace emu {

namespace {

// 16 b g r a words as int16 (4 registers: pixels 0-3, 4-7, 8-11, 12-15, channels in b g r a
// order within each pixel) transposed into r g b a planes of 16 lanes, stored at out[c] + lane.
inline void storePlanes(__m256i p0, __m256i p1, __m256i p2, __m256i p3, int16_t* const out[4], int lane) {
    // Each register holds pixels (k, k+1) in its low lane and (k+2, k+3) in its high lane:
    // vpmovzxbw of 4 words keeps them in order. Transpose 4x4 blocks of int16 per 128-bit lane.
    const __m256i a = _mm256_unpacklo_epi16(p0, p1);  // px0 b0 b4 g0 g4 r0 r4 a0 a4 | ...
    const __m256i b = _mm256_unpackhi_epi16(p0, p1);
    const __m256i c = _mm256_unpacklo_epi16(p2, p3);
    const __m256i d = _mm256_unpackhi_epi16(p2, p3);
    const __m256i e = _mm256_unpacklo_epi16(a, b);  // b0 b1 b4 b5 g0 g1 g4 g5 | (lane 1: px 2,3,6,7)
    const __m256i f = _mm256_unpackhi_epi16(a, b);  // r0 r1 r4 r5 a0 a1 a4 a5
    const __m256i g = _mm256_unpacklo_epi16(c, d);  // b8 b9 b12 b13 g8 ...
    const __m256i h = _mm256_unpackhi_epi16(c, d);
    const __m256i bg0 = _mm256_unpacklo_epi64(e, g);  // b0 b1 b4 b5 b8 b9 b12 b13 | b2 b3 b6 b7 b10 ...
    const __m256i bg1 = _mm256_unpackhi_epi64(e, g);  // g ...
    const __m256i ra0 = _mm256_unpacklo_epi64(f, h);  // r ...
    const __m256i ra1 = _mm256_unpackhi_epi64(f, h);  // a ...
    // Lane 0 holds pixels {0,1,4,5,8,9,12,13}, lane 1 {2,3,6,7,10,11,14,15}: interleave pairs.
    const __m256i order = _mm256_setr_epi8(0, 1, 2, 3, 8, 9, 10, 11, 4, 5, 6, 7, 12, 13, 14, 15, 0, 1, 2, 3, 8, 9, 10,
                                           11, 4, 5, 6, 7, 12, 13, 14, 15);
    auto fix = [&](__m256i v) {
        // lane0: 0 1 4 5 8 9 12 13 -> shuffle to 0 1 8 9 4 5 12 13; lane1 likewise 2 3 10 11 6 7 14 15
        v = _mm256_shuffle_epi8(v, order);
        // 64-bit blocks: [0 1 8 9][4 5 12 13][2 3 10 11][6 7 14 15] -> [0 1 2 3][4 5 6 7]...
        v = _mm256_permute4x64_epi64(v, 0xD8);  // blocks 0 2 1 3: [0 1 8 9][2 3 10 11][4 5 12 13][6 7 14 15]
        // now 32-bit pairs: (0 1)(8 9)(2 3)(10 11)(4 5)(12 13)(6 7)(14 15)
        return _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
    };
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out[2] + lane), fix(bg0));  // b
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out[1] + lane), fix(bg1));  // g
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out[0] + lane), fix(ra0));  // r
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out[3] + lane), fix(ra1));  // a
}

// 4 b g r a words at p as 16 int16 lanes.
inline __m256i load4(const uint8_t* p) {
    return _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}

// round_half_even(t / 65536) of 32-bit lanes.
inline __m256i roundBlend8(__m256i t) {
    const __m256i odd = _mm256_and_si256(_mm256_srli_epi32(t, 16), _mm256_set1_epi32(1));
    return _mm256_srli_epi32(_mm256_add_epi32(_mm256_add_epi32(t, _mm256_set1_epi32(0x7fff)), odd), 16);
}

}  // namespace

// Pixels [0, count) (count a multiple of 16) whose texels are a0 + 4i, a0 + 4i + 4 on both rows
// with the fixed weights wx, wy. Four kernels by weight: copy, horizontal or vertical only, both.
void alignedFilterRunAvx2(const uint8_t* r0, const uint8_t* r1, int32_t wx, int32_t wy, int count, int lane,
                          int16_t* const out[4]) {
    if (wx == 0 && wy == 0) {
        for (int i = 0; i < count; i += 16) {
            const uint8_t* p = r0 + 4 * i;
            storePlanes(load4(p), load4(p + 16), load4(p + 32), load4(p + 48), out, lane + i);
        }
        return;
    }
    if (wy == 0 || wx == 0) {
        // One axis: round_half_even((a·(256 − w) + b·w) / 256), all in 16 bits (a·(256 − w) + b·w
        // <= 65280, so +127 + 1 stays below 2^16).
        const int32_t w = wy == 0 ? wx : wy;
        const uint8_t* pa = r0;
        const uint8_t* pb = wy == 0 ? r0 + 4 : r1;
        const __m256i wa = _mm256_set1_epi16(int16_t(256 - w)), wb = _mm256_set1_epi16(int16_t(w));
        const __m256i c127 = _mm256_set1_epi16(127), one = _mm256_set1_epi16(1);
        auto px = [&](const uint8_t* a, const uint8_t* b) {
            const __m256i h = _mm256_add_epi16(_mm256_mullo_epi16(load4(a), wa), _mm256_mullo_epi16(load4(b), wb));
            const __m256i odd = _mm256_and_si256(_mm256_srli_epi16(h, 8), one);
            return _mm256_srli_epi16(_mm256_add_epi16(_mm256_add_epi16(h, c127), odd), 8);
        };
        for (int i = 0; i < count; i += 16) {
            const int o = 4 * i;
            storePlanes(px(pa + o, pb + o), px(pa + o + 16, pb + o + 16), px(pa + o + 32, pb + o + 32),
                        px(pa + o + 48, pb + o + 48), out, lane + i);
        }
        return;
    }
    if (wx == 128 && wy == 128) {
        // The half-texel blur tap: round_half_even((a + b + c + d) / 4).
        const __m256i one = _mm256_set1_epi16(1);
        auto px = [&](int o) {
            const __m256i s = _mm256_add_epi16(_mm256_add_epi16(load4(r0 + o), load4(r0 + o + 4)),
                                               _mm256_add_epi16(load4(r1 + o), load4(r1 + o + 4)));
            const __m256i odd = _mm256_and_si256(_mm256_srli_epi16(s, 2), one);
            return _mm256_srli_epi16(_mm256_add_epi16(_mm256_add_epi16(s, one), odd), 2);
        };
        for (int i = 0; i < count; i += 16) {
            const int o = 4 * i;
            storePlanes(px(o), px(o + 16), px(o + 32), px(o + 48), out, lane + i);
        }
        return;
    }
    // General weights: h = a·(256 − wx) + b·wx <= 65280 per row (exact in unsigned 16 bits), then
    // t = h0·(256 − wy) + h1·wy in 32 bits by pmaddwd on (h − 32768): t = madd + 32768·256.
    const __m256i wa = _mm256_set1_epi16(int16_t(256 - wx)), wb = _mm256_set1_epi16(int16_t(wx));
    const __m256i wv = _mm256_set1_epi32(int32_t(uint32_t(256 - wy) | (uint32_t(wy) << 16)));
    const __m256i flip = _mm256_set1_epi16(int16_t(0x8000)), bias = _mm256_set1_epi32(32768 * 256);
    auto px = [&](int o) {
        const __m256i h0 =
            _mm256_add_epi16(_mm256_mullo_epi16(load4(r0 + o), wa), _mm256_mullo_epi16(load4(r0 + o + 4), wb));
        const __m256i h1 =
            _mm256_add_epi16(_mm256_mullo_epi16(load4(r1 + o), wa), _mm256_mullo_epi16(load4(r1 + o + 4), wb));
        const __m256i s0 = _mm256_xor_si256(h0, flip), s1 = _mm256_xor_si256(h1, flip);
        const __m256i lo = roundBlend8(_mm256_add_epi32(_mm256_madd_epi16(_mm256_unpacklo_epi16(s0, s1), wv), bias));
        const __m256i hi = roundBlend8(_mm256_add_epi32(_mm256_madd_epi16(_mm256_unpackhi_epi16(s0, s1), wv), bias));
        return _mm256_packs_epi32(lo, hi);  // per 128-bit lane: the unpacks' order undone
    };
    for (int i = 0; i < count; i += 16) {
        const int o = 4 * i;
        storePlanes(px(o), px(o + 16), px(o + 32), px(o + 48), out, lane + i);
    }
}

namespace {

// Words of r0 (int16 r g b a planes) as b g r a bytes: clamp to [0, 255] and pack; `orMask`
// is or-ed in (X8R8G8B8's X = 0xff). Additive: saturating byte add onto the target row.
template <bool Additive>
int storeRow(const int16_t* const r[4], int count, uint32_t orMask, uint8_t* dst) {
    int i = 0;
    const __m256i om = _mm256_set1_epi32(int32_t(orMask));
    for (; i + 16 <= count; i += 16) {
        auto ld = [&](int c) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(r[c] + i)); };
        // packus: int16 -> uint8 with saturation to [0, 255], per 128-bit lane.
        const __m256i bg = _mm256_packus_epi16(ld(2), ld(1));  // lane0: b0-7 g0-7, lane1: b8-15 g8-15
        const __m256i ra = _mm256_packus_epi16(ld(0), ld(3));  // r, a likewise
        const __m256i bgLo = _mm256_unpacklo_epi8(bg, _mm256_srli_si256(bg, 8));  // b0 g0 b1 g1 ... (lane-wise)
        const __m256i raLo = _mm256_unpacklo_epi8(ra, _mm256_srli_si256(ra, 8));
        const __m256i w0 = _mm256_or_si256(_mm256_unpacklo_epi16(bgLo, raLo), om);  // px 0-3 | 8-11
        const __m256i w1 = _mm256_or_si256(_mm256_unpackhi_epi16(bgLo, raLo), om);  // px 4-7 | 12-15
        __m256i first = _mm256_permute2x128_si256(w0, w1, 0x20);                    // px 0-7
        __m256i second = _mm256_permute2x128_si256(w0, w1, 0x31);                   // px 8-15
        __m256i* d0 = reinterpret_cast<__m256i*>(dst + 4 * i);
        __m256i* d1 = reinterpret_cast<__m256i*>(dst + 4 * i + 32);
        if constexpr (Additive) {
            first = _mm256_adds_epu8(first, _mm256_loadu_si256(d0));
            second = _mm256_adds_epu8(second, _mm256_loadu_si256(d1));
        }
        _mm256_storeu_si256(d0, first);
        _mm256_storeu_si256(d1, second);
    }
    return i;
}

}  // namespace

int alignedStoreRowAvx2(bool additive, const int16_t* const r[4], int count, uint32_t orMask, uint8_t* dst) {
    return additive ? storeRow<true>(r, count, orMask, dst) : storeRow<false>(r, count, orMask, dst);
}

}  // namespace emu
