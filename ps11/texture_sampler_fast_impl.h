// The body of the fast Unorm8 kernels, included by texture_sampler_fast.cpp (Baseline level) and
// texture_sampler_fast_avx2.cpp (Avx2 level) with PS11_SAMPLER_LEVEL naming the level's namespace
// (baseline or avx2), whose table kSampler it defines. Everything else has internal linkage so
// the two builds never mix at link time.
//
// Exactness (docs/precision.md "Sampling"): per axis R = round_half_even((u*n - 0.5)*256) gives
// the first texel R >> 8 and the 8-bit weight R & 255 of the second; when f*256 rounds up to 256
// this moves the tap pair one texel on with weights (256, 0), the same exact sum as the general
// rule. The blend sum(w_k * byte_k) with w_k = wx'*wy' <= 65536 is an integer below 2^24, so it
// is exact in float32 whatever the order or FMA; scaling by 2^-16 (fx8) or 2^-12 (fx12, 16
// grid units per byte) is exact, and adding and removing 1.5 * 2^23 rounds to the nearest
// integer, ties to even: one rounding, as the reference does in 64-bit integers.
#include <cmath>
#include <cstring>
#ifdef __AVX2__
#include <immintrin.h>

#include "ps11/lanes_avx2.h"
#endif

#include "ps11/texture.h"
#include "ps11/texture_sampler_fast.h"
#include "ps11/texture_sampler_internal.h"

#ifndef PS11_SAMPLER_LEVEL
#error "define PS11_SAMPLER_LEVEL before including texture_sampler_fast_impl.h"
#endif

namespace ps11::fastpath {
namespace {

// Positions with |x| below this (in the axis's units) take the integer path; others (huge,
// infinite, NaN) the reference's per-lane rule.
constexpr double kFastRange = 1073741824.0;  // 2^30
constexpr float kFloatMagic = 12582912.0f;   // 1.5 * 2^23

// Lane arrays of one span, padded so vector loops may run past the end.
struct Scratch {
    alignas(64) int32_t x0[kMaxSpan], x1[kMaxSpan], wx[kMaxSpan];
    alignas(64) int32_t y0[kMaxSpan], y1[kMaxSpan], wy[kMaxSpan];
    alignas(64) uint32_t t00[kMaxSpan], t10[kMaxSpan], t01[kMaxSpan], t11[kMaxSpan];
};

// k mod n for |k| < 2^23, n <= 2^15: a double quotient is within one of the true one.
inline int32_t modSmall(int32_t k, int32_t n, double inv) {
    int32_t m = k - int32_t(double(k) * inv) * n;
    m = m < 0 ? m + n : m;
    return m >= n ? m - n : m;
}

// Maps texel index k of an axis with n texels through the address mode (-1 = border). Valid
// for |k| < 2^23; the same mapping as addressPair.
template <TextureAddress Mode>
inline int32_t address1(int32_t k, int32_t n, double inv, double inv2) {
    if constexpr (Mode == TextureAddress::Wrap) {
        return modSmall(k, n, inv);
    } else if constexpr (Mode == TextureAddress::Mirror) {
        const int32_t m = modSmall(k, 2 * n, inv2);
        return m < n ? m : 2 * n - 1 - m;
    } else if constexpr (Mode == TextureAddress::Clamp) {
        return std::min(std::max(k, 0), n - 1);
    } else if constexpr (Mode == TextureAddress::Border) {
        return uint32_t(k) < uint32_t(n) ? k : -1;
    } else {
        const int32_t j = k < 0 ? -k - 1 : k;
        return std::min(j, n - 1);
    }
}

// One axis of a run: texel pair and weight (bilinear) or texel (point) per lane.
template <TextureAddress Mode, bool Linear>
void axis(int count, const float* c, uint32_t n, int32_t* __restrict i0, int32_t* __restrict i1,
          int32_t* __restrict w) {
    const double scale = Linear ? double(n) * 256.0 : double(n);
    const double bias = Linear ? 128.0 : 0.0;
    const int32_t ni = int32_t(n);
    const double inv = 1.0 / double(n), inv2 = 0.5 / double(n);
    int bad = 0;
    for (int i = 0; i < count; ++i) {
        const double x = double(c[i]) * scale - bias;  // exact: 24 + 22 bits
        const bool ok = x > -kFastRange && x < kFastRange;
        bad += !ok;
        const double xs = ok ? x : 0.0;
        const double r = roundEvenSmall(xs);
        int32_t k;
        if constexpr (Linear) {
            const int32_t R = int32_t(r);
            k = R >> 8;
            w[i] = R & 255;
        } else {
            k = int32_t(r > xs ? r - 1.0 : r);  // floor(u*n): ties go up
        }
        i0[i] = address1<Mode>(k, ni, inv, inv2);
        if constexpr (Linear) i1[i] = address1<Mode>(k + 1, ni, inv, inv2);
    }
    if (!bad) return;
    for (int i = 0; i < count; ++i) {
        const double x = double(c[i]) * scale - bias;
        if (x > -kFastRange && x < kFastRange) continue;
        double fl, fr;
        texelPosition(c[i], n, Linear, fl, fr);
        int32_t a, b;
        addressPair<Mode>(fl, n, a, b);
        i0[i] = a;
        if constexpr (Linear) i1[i] = b, w[i] = weight8(fr);
    }
}

#ifdef __AVX2__
// The address mode on 8 int32 lanes (same mapping as address1).
template <TextureAddress Mode>
inline __m256i address8(__m256i k, __m256i n, __m256d inv, __m256i twoN, __m256d inv2) {
    const __m256i zero = _mm256_setzero_si256();
    auto modN = [&](__m256i kk, __m256i nn, __m256d iv) {
        const __m256d lo = _mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_castsi256_si128(kk)), iv);
        const __m256d hi = _mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_extracti128_si256(kk, 1)), iv);
        const __m256i q = _mm256_setr_m128i(_mm256_cvttpd_epi32(lo), _mm256_cvttpd_epi32(hi));
        __m256i m = _mm256_sub_epi32(kk, _mm256_mullo_epi32(q, nn));
        m = _mm256_add_epi32(m, _mm256_and_si256(_mm256_cmpgt_epi32(zero, m), nn));   // m < 0: + n
        m = _mm256_sub_epi32(m, _mm256_andnot_si256(_mm256_cmpgt_epi32(nn, m), nn));  // m >= n: - n
        return m;
    };
    if constexpr (Mode == TextureAddress::Wrap) {
        return modN(k, n, inv);
    } else if constexpr (Mode == TextureAddress::Mirror) {
        const __m256i m = modN(k, twoN, inv2);
        const __m256i flipped = _mm256_sub_epi32(_mm256_sub_epi32(twoN, _mm256_set1_epi32(1)), m);
        return _mm256_blendv_epi8(flipped, m, _mm256_cmpgt_epi32(n, m));
    } else if constexpr (Mode == TextureAddress::Clamp) {
        return _mm256_min_epi32(_mm256_max_epi32(k, zero), _mm256_sub_epi32(n, _mm256_set1_epi32(1)));
    } else if constexpr (Mode == TextureAddress::Border) {
        const __m256i in = _mm256_and_si256(_mm256_cmpgt_epi32(k, _mm256_set1_epi32(-1)), _mm256_cmpgt_epi32(n, k));
        return _mm256_or_si256(_mm256_and_si256(in, k), _mm256_andnot_si256(in, _mm256_set1_epi32(-1)));
    } else {
        const __m256i j = _mm256_xor_si256(k, _mm256_srai_epi32(k, 31));  // k < 0: -k - 1 = ~k
        return _mm256_min_epi32(j, _mm256_sub_epi32(n, _mm256_set1_epi32(1)));
    }
}

// 8 lanes at a time; lanes outside the integer range and the tail go to the scalar axis().
template <TextureAddress Mode, bool Linear>
void axisAvx2(int count, const float* c, uint32_t n, int32_t* __restrict i0, int32_t* __restrict i1,
              int32_t* __restrict w) {
    const __m256d scale = _mm256_set1_pd(Linear ? double(n) * 256.0 : double(n));
    const __m256d bias = _mm256_set1_pd(Linear ? 128.0 : 0.0);
    const __m256d range = _mm256_set1_pd(kFastRange);
    const __m256d absMask = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffffLL));
    const __m256i nv = _mm256_set1_epi32(int32_t(n)), twoN = _mm256_set1_epi32(int32_t(2 * n));
    const __m256d inv = _mm256_set1_pd(1.0 / double(n)), inv2 = _mm256_set1_pd(0.5 / double(n));
    const __m256i one = _mm256_set1_epi32(1);
    int i = 0;
    for (; i + 8 <= count; i += 8) {
        const __m256 uf = _mm256_loadu_ps(c + i);
        __m256d xl = _mm256_sub_pd(_mm256_mul_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(uf)), scale), bias);
        __m256d xh = _mm256_sub_pd(_mm256_mul_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(uf, 1)), scale), bias);
        const __m256d okl = _mm256_cmp_pd(_mm256_and_pd(xl, absMask), range, _CMP_LT_OQ);
        const __m256d okh = _mm256_cmp_pd(_mm256_and_pd(xh, absMask), range, _CMP_LT_OQ);
        if ((_mm256_movemask_pd(okl) & _mm256_movemask_pd(okh)) != 15) {
            axis<Mode, Linear>(8, c + i, n, i0 + i, i1 + i, w + i);  // some lane needs the general rule
            continue;
        }
        __m256i k;
        if constexpr (Linear) {
            // cvtpd rounds to nearest, ties to even (the default MXCSR mode): R = round(x * 256).
            const __m256i R = _mm256_setr_m128i(_mm256_cvtpd_epi32(xl), _mm256_cvtpd_epi32(xh));
            k = _mm256_srai_epi32(R, 8);
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(w + i), _mm256_and_si256(R, _mm256_set1_epi32(255)));
        } else {
            xl = _mm256_floor_pd(xl), xh = _mm256_floor_pd(xh);
            k = _mm256_setr_m128i(_mm256_cvttpd_epi32(xl), _mm256_cvttpd_epi32(xh));
        }
        const __m256i a0 = address8<Mode>(k, nv, inv, twoN, inv2);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(i0 + i), a0);
        if constexpr (Linear) {
            __m256i a1;
            if constexpr (Mode == TextureAddress::Wrap) {  // the next texel of a0, n wrapping to 0
                const __m256i next = _mm256_add_epi32(a0, one);
                a1 = _mm256_andnot_si256(_mm256_cmpeq_epi32(next, nv), next);
            } else {
                a1 = address8<Mode>(_mm256_add_epi32(k, one), nv, inv, twoN, inv2);
            }
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(i1 + i), a1);
        }
    }
    if (i < count) axis<Mode, Linear>(count - i, c + i, n, i0 + i, i1 + i, w + i);
}
#define PS11_AXIS axisAvx2
#else
#define PS11_AXIS axis
#endif

template <bool Linear>
void axisPass(TextureAddress mode, int count, const float* c, uint32_t n, int32_t* i0, int32_t* i1, int32_t* w) {
    switch (mode) {
        case TextureAddress::Mirror:
            return PS11_AXIS<TextureAddress::Mirror, Linear>(count, c, n, i0, i1, w);
        case TextureAddress::Clamp:
            return PS11_AXIS<TextureAddress::Clamp, Linear>(count, c, n, i0, i1, w);
        case TextureAddress::Border:
            return PS11_AXIS<TextureAddress::Border, Linear>(count, c, n, i0, i1, w);
        case TextureAddress::MirrorOnce:
            return PS11_AXIS<TextureAddress::MirrorOnce, Linear>(count, c, n, i0, i1, w);
        default:  // Wrap (and an invalid value, as the reference)
            return PS11_AXIS<TextureAddress::Wrap, Linear>(count, c, n, i0, i1, w);
    }
}

inline uint32_t load32(const uint8_t* p) {
    uint32_t w;
    std::memcpy(&w, p, 4);
    return w;
}
inline uint64_t load64(const uint8_t* p) {
    uint64_t w;
    std::memcpy(&w, p, 8);
    return w;
}

// The four taps of every lane as b g r a words: one 64-bit load per row when the pair is
// adjacent (the usual case), else two 32-bit loads or the border word.
void gatherBilinear(const Unorm8Run& run, int count, Scratch& s, int from = 0) {
    const uint8_t* base = run.texels;
    const size_t stride = size_t(run.width) * 4;
    for (int i = from; i < count; ++i) {
        const int32_t x0 = s.x0[i], x1 = s.x1[i], y0 = s.y0[i], y1 = s.y1[i];
        if ((x0 | x1 | y0 | y1) >= 0) {
            const uint8_t* r0 = base + size_t(y0) * stride;
            const uint8_t* r1 = base + size_t(y1) * stride;
            if (x1 == x0 + 1) {
                const uint64_t a = load64(r0 + size_t(x0) * 4), b = load64(r1 + size_t(x0) * 4);
                s.t00[i] = uint32_t(a), s.t10[i] = uint32_t(a >> 32);
                s.t01[i] = uint32_t(b), s.t11[i] = uint32_t(b >> 32);
            } else {
                s.t00[i] = load32(r0 + size_t(x0) * 4), s.t10[i] = load32(r0 + size_t(x1) * 4);
                s.t01[i] = load32(r1 + size_t(x0) * 4), s.t11[i] = load32(r1 + size_t(x1) * 4);
            }
            continue;
        }
        auto tap = [&](int32_t x, int32_t y) {
            return (x | y) < 0 ? run.borderWord : load32(base + size_t(y) * stride + size_t(x) * 4);
        };
        s.t00[i] = tap(x0, y0), s.t10[i] = tap(x1, y0), s.t01[i] = tap(x0, y1), s.t11[i] = tap(x1, y1);
    }
}

// True when the span is 2x2 quads (lanes TL TR BL BR) of a screen-aligned pass at the texture's
// resolution: quad q reads columns x0 + 2q + (0 | 1) (and + 1), its top lanes one row pair and its
// bottom lanes another, none of them border. Then each row's two adjacent lanes are one 64-bit copy.
bool quadContiguous(int count, const Scratch& s) {
    if (count % 4 != 0) return false;
    const int32_t x0 = s.x0[0], ya0 = s.y0[0], ya1 = s.y1[0], yb0 = s.y0[2], yb1 = s.y1[2];
    if ((x0 | ya0 | ya1 | yb0 | yb1) < 0) return false;
    // (The first quad first: scattered lanes, the usual case when this fails, fail there.)
    if (s.x0[1] != x0 + 1 || s.x0[2] != x0 || s.x0[3] != x0 + 1 || s.y0[1] != ya0 || s.y0[3] != yb0) return false;
    int bad = 0;
    int i = 0;
#ifdef __AVX2__
    // Two quads a step: columns x0 + 4k + (0 1 0 1 2 3 2 3), rows (a a b b a a b b).
    __m256i col = _mm256_add_epi32(_mm256_set1_epi32(x0), _mm256_setr_epi32(0, 1, 0, 1, 2, 3, 2, 3));
    const __m256i rows0 = _mm256_setr_epi32(ya0, ya0, yb0, yb0, ya0, ya0, yb0, yb0);
    const __m256i rows1 = _mm256_setr_epi32(ya1, ya1, yb1, yb1, ya1, ya1, yb1, yb1);
    const __m256i one = _mm256_set1_epi32(1), four = _mm256_set1_epi32(4);
    __m256i diff = _mm256_setzero_si256();
    for (; i + 8 <= count; i += 8, col = _mm256_add_epi32(col, four)) {
        auto load = [&](const int32_t* p) { return _mm256_load_si256(reinterpret_cast<const __m256i*>(p + i)); };
        diff = _mm256_or_si256(diff, _mm256_or_si256(_mm256_sub_epi32(load(s.x0), col),
                                                     _mm256_sub_epi32(load(s.x1), _mm256_add_epi32(col, one))));
        diff = _mm256_or_si256(
            diff, _mm256_or_si256(_mm256_sub_epi32(load(s.y0), rows0), _mm256_sub_epi32(load(s.y1), rows1)));
    }
    if (!_mm256_testz_si256(diff, diff)) return false;
#endif
    for (; i < count; ++i) {
        const int32_t col = x0 + 2 * (i >> 2) + (i & 1);
        const bool top = (i & 2) == 0;
        bad |= (s.x0[i] - col) | (s.x1[i] - col - 1) | (s.y0[i] - (top ? ya0 : yb0)) | (s.y1[i] - (top ? ya1 : yb1));
    }
    return bad == 0;
}

inline void copy8(uint32_t* dst, const uint8_t* src) { std::memcpy(dst, src, 8); }

void gatherQuads(const Unorm8Run& run, int count, Scratch& s) {
    const size_t stride = size_t(run.width) * 4;
    const uint8_t* a0 = run.texels + size_t(s.y0[0]) * stride + size_t(s.x0[0]) * 4;
    const uint8_t* a1 = run.texels + size_t(s.y1[0]) * stride + size_t(s.x0[0]) * 4;
    const uint8_t* b0 = run.texels + size_t(s.y0[2]) * stride + size_t(s.x0[0]) * 4;
    const uint8_t* b1 = run.texels + size_t(s.y1[2]) * stride + size_t(s.x0[0]) * 4;
    for (int i = 0; i < count; i += 4) {
        const size_t o = size_t(i / 2) * 4;  // column x0 + 2q
        copy8(s.t00 + i, a0 + o), copy8(s.t00 + i + 2, b0 + o);
        copy8(s.t10 + i, a0 + o + 4), copy8(s.t10 + i + 2, b0 + o + 4);
        copy8(s.t01 + i, a1 + o), copy8(s.t01 + i + 2, b1 + o);
        copy8(s.t11 + i, a1 + o + 4), copy8(s.t11 + i + 2, b1 + o + 4);
    }
}

inline float byteOf(uint32_t w, int b) { return float(int32_t((w >> (8 * b)) & 255u)); }

inline uint32_t word(const uint8_t* p, int i) {
    uint32_t w;
    std::memcpy(&w, p + 4 * i, 4);
    return w;
}

// sum(w_k * byte_k) per channel, scaled and rounded once (see the top of this file). The taps are
// b g r a words at t00..t11 (lane i at byte 4i): the gathered scratch arrays, or texel rows
// read in place for a screen-aligned span.
void blend(int count, const uint8_t* t00p, const uint8_t* t10p, const uint8_t* t01p, const uint8_t* t11p,
           const int32_t* wxp, const int32_t* wyp, float outScale, int32_t* __restrict r, int32_t* __restrict g,
           int32_t* __restrict b, int32_t* __restrict a) {
    int i = 0;
#ifdef __AVX2__
    // Eight lanes a step: the same integer weights and exact sums, scaled and rounded alike.
    const __m256 k256 = _mm256_set1_ps(256.0f), k65536 = _mm256_set1_ps(65536.0f);
    const __m256 scale = _mm256_set1_ps(outScale), magic = _mm256_set1_ps(kFloatMagic);
    const __m256i m8 = _mm256_set1_epi32(255);
    int32_t* const planes[4] = {b, g, r, a};
    for (; i + 8 <= count; i += 8) {
        auto load = [&](const void* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); };
        const __m256 fx = _mm256_cvtepi32_ps(load(wxp + i)), fy = _mm256_cvtepi32_ps(load(wyp + i));
        const __m256 w11 = _mm256_mul_ps(fx, fy), fx256 = _mm256_mul_ps(fx, k256);
        const __m256 w10 = _mm256_sub_ps(fx256, w11), w01 = _mm256_sub_ps(_mm256_mul_ps(fy, k256), w11);
        const __m256 w00 = _mm256_sub_ps(_mm256_sub_ps(k65536, fx256), w01);
        const __m256i t00 = load(t00p + 4 * i), t10 = load(t10p + 4 * i), t01 = load(t01p + 4 * i),
                      t11 = load(t11p + 4 * i);
        auto channel = [&](__m256i t, int k) {
            return _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srl_epi32(t, _mm_cvtsi32_si128(8 * k)), m8));
        };
        for (int k = 0; k < 4; ++k) {
            const __m256 sum = _mm256_add_ps(
                _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(w00, channel(t00, k)), _mm256_mul_ps(w10, channel(t10, k))),
                              _mm256_mul_ps(w01, channel(t01, k))),
                _mm256_mul_ps(w11, channel(t11, k)));
            const __m256 rounded = _mm256_sub_ps(_mm256_add_ps(_mm256_mul_ps(sum, scale), magic), magic);
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(planes[k] + i), _mm256_cvttps_epi32(rounded));
        }
    }
#endif
    for (; i < count; ++i) {
        const float fx = float(wxp[i]), fy = float(wyp[i]);
        const float w11 = fx * fy, w10 = fx * 256.0f - w11, w01 = fy * 256.0f - w11;
        const float w00 = 65536.0f - fx * 256.0f - w01;
        const uint32_t t00 = word(t00p, i), t10 = word(t10p, i), t01 = word(t01p, i), t11 = word(t11p, i);
        auto ch = [&](int k) {
            const float sum = w00 * byteOf(t00, k) + w10 * byteOf(t10, k) + w01 * byteOf(t01, k) + w11 * byteOf(t11, k);
            return int32_t((sum * outScale + kFloatMagic) - kFloatMagic);
        };
        b[i] = ch(0), g[i] = ch(1), r[i] = ch(2), a[i] = ch(3);
    }
}

#ifdef __AVX2__
// Eight lanes [i, i + 8) of a bilinear fx run, gathered and blended in integers: the same sum as
// blend()'s, one rounding. Lanes whose texel lies on the border take the border word (a masked
// gather reads no memory for them). Per channel h = a·(256 − wx) + b·wx per texel row (below
// 2^16: 16-bit products), then pmaddwd forms (h0 − 2^15)·(256 − wy) + (h1 − 2^15)·wy = sum − 2^23
// exactly, and round_half_even(sum / 2^Shift) is taken with shifts: Shift 16 gives fx8's bytes,
// packed back into b g r a words and split into the planes; Shift 12 gives fx12's grid values
// (16·sum / 2^16, at most 4080), transposed from 16-bit lanes into the planes.
template <int Shift>
void blendLinear8(const Unorm8Run& run, const Scratch& s, int i, int32_t* r, int32_t* g, int32_t* b, int32_t* a) {
    static_assert(Shift == 16 || Shift == 12);
    auto load = [&](const int32_t* p) { return _mm256_load_si256(reinterpret_cast<const __m256i*>(p + i)); };
    const __m256i x0 = load(s.x0), x1 = load(s.x1), y0 = load(s.y0), y1 = load(s.y1);
    const __m256i wx = load(s.wx), wy = load(s.wy);
    const __m256i width = _mm256_set1_epi32(int32_t(run.width)), none = _mm256_set1_epi32(-1);
    const __m256i border = _mm256_set1_epi32(int32_t(run.borderWord));
    const int* base = reinterpret_cast<const int*>(run.texels);
    const __m256i r0 = _mm256_mullo_epi32(y0, width), r1 = _mm256_mullo_epi32(y1, width);
    auto tap = [&](__m256i row, __m256i y, __m256i x) {
        const __m256i inside = _mm256_cmpgt_epi32(_mm256_or_si256(x, y), none);
        return _mm256_mask_i32gather_epi32(border, base, _mm256_add_epi32(row, x), inside, 4);
    };
    const __m256i t00 = tap(r0, y0, x0), t10 = tap(r0, y0, x1), t01 = tap(r1, y1, x0), t11 = tap(r1, y1, x1);
    // Weights as 16-bit lanes, each pixel's repeated over its four channels.
    const __m256i wxs = _mm256_or_si256(wx, _mm256_slli_epi32(wx, 16));
    const __m256i wyp = _mm256_or_si256(_mm256_sub_epi32(_mm256_set1_epi32(256), wy), _mm256_slli_epi32(wy, 16));
    const __m256i full = _mm256_set1_epi16(256), flip = _mm256_set1_epi16(int16_t(-32768));
    const __m256i round = _mm256_set1_epi32((1 << 23) + (1 << (Shift - 1)) - 1), one = _mm256_set1_epi32(1);
    __m256i words[2];
    for (int half = 0; half < 2; ++half) {
        auto bytes16 = [&](__m256i t) {
            return _mm256_cvtepu8_epi16(half ? _mm256_extracti128_si256(t, 1) : _mm256_castsi256_si128(t));
        };
        const int q = 4 * half;
        const __m256i w =
            _mm256_permutevar8x32_epi32(wxs, _mm256_setr_epi32(q, q, q + 1, q + 1, q + 2, q + 2, q + 3, q + 3));
        const __m256i wc = _mm256_sub_epi16(full, w);
        const __m256i h0 = _mm256_xor_si256(
            _mm256_add_epi16(_mm256_mullo_epi16(bytes16(t00), wc), _mm256_mullo_epi16(bytes16(t10), w)), flip);
        const __m256i h1 = _mm256_xor_si256(
            _mm256_add_epi16(_mm256_mullo_epi16(bytes16(t01), wc), _mm256_mullo_epi16(bytes16(t11), w)), flip);
        // unpacklo: pixels q and q + 2 (one per 128-bit lane); unpackhi: q + 1 and q + 3.
        const __m256i wlo = _mm256_permutevar8x32_epi32(wyp, _mm256_setr_epi32(q, q, q, q, q + 2, q + 2, q + 2, q + 2));
        const __m256i whi =
            _mm256_permutevar8x32_epi32(wyp, _mm256_setr_epi32(q + 1, q + 1, q + 1, q + 1, q + 3, q + 3, q + 3, q + 3));
        auto rounded = [&](__m256i m) {  // m = sum − 2^23; 2^23 is a multiple of 2^(Shift + 1)
            const __m256i odd = _mm256_and_si256(_mm256_srai_epi32(m, Shift), one);
            return _mm256_srai_epi32(_mm256_add_epi32(_mm256_add_epi32(m, round), odd), Shift);
        };
        const __m256i lo = rounded(_mm256_madd_epi16(_mm256_unpacklo_epi16(h0, h1), wlo));
        const __m256i hi = rounded(_mm256_madd_epi16(_mm256_unpackhi_epi16(h0, h1), whi));
        words[half] = _mm256_packus_epi32(lo, hi);  // per 128-bit lane: pixels q, q + 1 | q + 2, q + 3
    }
    auto store = [&](int32_t* p, __m256i v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p + i), v); };
    if constexpr (Shift == 12) {
        // words[h]: pixels 4h … 4h + 3, each b g r a as 16-bit lanes. Within each 128-bit lane the
        // pairs of a channel are gathered ((b0 b1) (g0 g1) (r0 r1) (a0 a1)), the lanes' pairs put
        // side by side, then one channel's eight values are the low or high 64 bits of both words.
        const __m256i pairs = _mm256_setr_epi8(0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15, 0, 1, 8, 9, 2, 3,
                                               10, 11, 4, 5, 12, 13, 6, 7, 14, 15);
        const __m256i order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
        const __m256i w0 = _mm256_permutevar8x32_epi32(_mm256_shuffle_epi8(words[0], pairs), order);
        const __m256i w1 = _mm256_permutevar8x32_epi32(_mm256_shuffle_epi8(words[1], pairs), order);
        const __m256i br = _mm256_unpacklo_epi64(w0, w1), ga = _mm256_unpackhi_epi64(w0, w1);  // b | r, g | a
        store(b, _mm256_cvtepu16_epi32(_mm256_castsi256_si128(br)));
        store(r, _mm256_cvtepu16_epi32(_mm256_extracti128_si256(br, 1)));
        store(g, _mm256_cvtepu16_epi32(_mm256_castsi256_si128(ga)));
        store(a, _mm256_cvtepu16_epi32(_mm256_extracti128_si256(ga, 1)));
        return;
    }
    const __m256i packed =
        _mm256_permutevar8x32_epi32(_mm256_packus_epi16(words[0], words[1]), _mm256_setr_epi32(0, 1, 4, 5, 2, 3, 6, 7));
    const __m256i m8 = _mm256_set1_epi32(255);
    store(b, _mm256_and_si256(packed, m8));
    store(g, _mm256_and_si256(_mm256_srli_epi32(packed, 8), m8));
    store(r, _mm256_and_si256(_mm256_srli_epi32(packed, 16), m8));
    store(a, _mm256_srli_epi32(packed, 24));
}
#endif

// True when the span reads two texel rows in order: one row pair (no border) and column pairs
// x0 + i, x0 + i + 1 (a screen-aligned pass at the texture's resolution, any fixed fraction).
// Then the taps are read in place instead of gathered.
bool rowContiguous(int count, const Scratch& s) {
    const int32_t x0 = s.x0[0], y0 = s.y0[0], y1 = s.y1[0];
    if ((x0 | y0 | y1) < 0) return false;
    if (count > 1 && (s.x0[1] != x0 + 1 || s.y0[1] != y0)) return false;  // (scattered lanes fail here)
    int bad = 0;
    for (int i = 0; i < count; ++i)
        bad |= (s.x0[i] - i - x0) | (s.x1[i] - i - 1 - x0) | (s.y0[i] - y0) | (s.y1[i] - y1);
    return bad == 0;
}

void pointOut(int count, const Unorm8Run& run, const Scratch& s, int32_t* __restrict r, int32_t* __restrict g,
              int32_t* __restrict b, int32_t* __restrict a) {
    const uint8_t* base = run.texels;
    const size_t stride = size_t(run.width) * 4;
    uint32_t* words = const_cast<uint32_t*>(s.t00);
    for (int i = 0; i < count; ++i) {
        const int32_t x = s.x0[i], y = s.y0[i];
        words[i] = (x | y) < 0 ? run.borderWord : load32(base + size_t(y) * stride + size_t(x) * 4);
    }
    const int32_t sc = run.scale;
    for (int i = 0; i < count; ++i) {
        const uint32_t w = words[i];
        b[i] = int32_t(w & 255u) * sc, g[i] = int32_t((w >> 8) & 255u) * sc;
        r[i] = int32_t((w >> 16) & 255u) * sc, a[i] = int32_t(w >> 24) * sc;
    }
}

void sampleUnorm8(const Unorm8Run& run, int count, const float* u, const float* v, int32_t* const* dst) {
    static thread_local Scratch s;
    if (run.linear) {
        axisPass<true>(run.addressU, count, u, run.width, s.x0, s.x1, s.wx);
        axisPass<true>(run.addressV, count, v, run.height, s.y0, s.y1, s.wy);
        const float outScale = run.scale == 1 ? 1.0f / 65536.0f : 1.0f / 4096.0f;
        if (rowContiguous(count, s)) {
            const size_t stride = size_t(run.width) * 4;
            const uint8_t* r0 = run.texels + size_t(s.y0[0]) * stride + size_t(s.x0[0]) * 4;
            const uint8_t* r1 = run.texels + size_t(s.y1[0]) * stride + size_t(s.x0[0]) * 4;
            blend(count, r0, r0 + 4, r1, r1 + 4, s.wx, s.wy, outScale, dst[0], dst[1], dst[2], dst[3]);
        } else {
#ifdef __AVX2__
            if ((run.scale == 1 || run.scale == 16) && !quadContiguous(count, s)) {
                const int whole = count & ~7;
                for (int i = 0; i < whole; i += 8)
                    if (run.scale == 1)
                        blendLinear8<16>(run, s, i, dst[0], dst[1], dst[2], dst[3]);
                    else
                        blendLinear8<12>(run, s, i, dst[0], dst[1], dst[2], dst[3]);
                if (whole == count) return;
                // The last lanes: gathered and blended one by one, from the front of the scratch.
                Scratch& t = s;
                const int rest = count - whole;
                for (int32_t* p : {t.x0, t.x1, t.y0, t.y1, t.wx, t.wy})
                    std::memmove(p, p + whole, sizeof(int32_t) * size_t(rest));
                gatherBilinear(run, rest, t);
                auto bytes = [](const uint32_t* p) { return reinterpret_cast<const uint8_t*>(p); };
                blend(rest, bytes(t.t00), bytes(t.t10), bytes(t.t01), bytes(t.t11), t.wx, t.wy, outScale,
                      dst[0] + whole, dst[1] + whole, dst[2] + whole, dst[3] + whole);
                return;
            }
#endif
            if (quadContiguous(count, s))
                gatherQuads(run, count, s);
            else
                gatherBilinear(run, count, s);
            auto bytes = [](const uint32_t* p) { return reinterpret_cast<const uint8_t*>(p); };
            blend(count, bytes(s.t00), bytes(s.t10), bytes(s.t01), bytes(s.t11), s.wx, s.wy, outScale, dst[0], dst[1],
                  dst[2], dst[3]);
        }
    } else {
        axisPass<false>(run.addressU, count, u, run.width, s.x0, s.x1, s.wx);
        axisPass<false>(run.addressV, count, v, run.height, s.y0, s.y1, s.wy);
        pointOut(count, run, s, dst[0], dst[1], dst[2], dst[3]);
    }
}

#ifdef __AVX2__
// gatherBilinear's words by masked AVX2 gathers, eight lanes a step (a border lane reads the
// border word, no memory); the last lanes by gatherBilinear itself.
void gatherBilinear8(const Unorm8Run& run, int count, Scratch& s) {
    const __m256i width = _mm256_set1_epi32(int32_t(run.width)), none = _mm256_set1_epi32(-1);
    const __m256i border = _mm256_set1_epi32(int32_t(run.borderWord));
    const int* base = reinterpret_cast<const int*>(run.texels);
    auto load = [&](const int32_t* p) { return _mm256_load_si256(reinterpret_cast<const __m256i*>(p)); };
    auto tap = [&](__m256i row, __m256i y, __m256i x) {
        const __m256i inside = _mm256_cmpgt_epi32(_mm256_or_si256(x, y), none);
        return _mm256_mask_i32gather_epi32(border, base, _mm256_add_epi32(row, x), inside, 4);
    };
    int i = 0;
    for (; i + 8 <= count; i += 8) {
        const __m256i x0 = load(s.x0 + i), x1 = load(s.x1 + i), y0 = load(s.y0 + i), y1 = load(s.y1 + i);
        const __m256i r0 = _mm256_mullo_epi32(y0, width), r1 = _mm256_mullo_epi32(y1, width);
        _mm256_store_si256(reinterpret_cast<__m256i*>(s.t00 + i), tap(r0, y0, x0));
        _mm256_store_si256(reinterpret_cast<__m256i*>(s.t10 + i), tap(r0, y0, x1));
        _mm256_store_si256(reinterpret_cast<__m256i*>(s.t01 + i), tap(r1, y1, x0));
        _mm256_store_si256(reinterpret_cast<__m256i*>(s.t11 + i), tap(r1, y1, x1));
    }
    gatherBilinear(run, count, s, i);
}
#endif

// Per lane and channel (b g r a) the exact sum Σ w·byte of one level's taps (bilinear weights
// w = wx'·wy' of 65536 in all; a point tap's byte times 65536): below 2^24, exact in float.
void levelSums(const Unorm8Run& run, int count, const float* u, const float* v, Scratch& s,
               float (*sum)[kMaxSpan]) {
    if (run.linear) {
        axisPass<true>(run.addressU, count, u, run.width, s.x0, s.x1, s.wx);
        axisPass<true>(run.addressV, count, v, run.height, s.y0, s.y1, s.wy);
        if (quadContiguous(count, s))
            gatherQuads(run, count, s);
        else
#ifdef __AVX2__
            gatherBilinear8(run, count, s);
#else
            gatherBilinear(run, count, s);
#endif
        int i = 0;
#ifdef __AVX2__
        // Eight lanes a step: every weight, product and partial sum is an integer below 2^24.
        const __m256 k256 = _mm256_set1_ps(256.0f), k65536 = _mm256_set1_ps(65536.0f);
        const __m256i m8 = _mm256_set1_epi32(255);
        for (; i + 8 <= count; i += 8) {
            auto load = [&](const auto* p) { return _mm256_load_si256(reinterpret_cast<const __m256i*>(p + i)); };
            const __m256 fx = _mm256_cvtepi32_ps(load(s.wx)), fy = _mm256_cvtepi32_ps(load(s.wy));
            const __m256 w11 = _mm256_mul_ps(fx, fy), fx256 = _mm256_mul_ps(fx, k256);
            const __m256 w10 = _mm256_sub_ps(fx256, w11), w01 = _mm256_sub_ps(_mm256_mul_ps(fy, k256), w11);
            const __m256 w00 = _mm256_sub_ps(_mm256_sub_ps(k65536, fx256), w01);
            const __m256i t00 = load(s.t00), t10 = load(s.t10), t01 = load(s.t01), t11 = load(s.t11);
            auto channel = [&](__m256i t, int k) {
                return _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srl_epi32(t, _mm_cvtsi32_si128(8 * k)), m8));
            };
            for (int k = 0; k < 4; ++k) {
                const __m256 a =
                    _mm256_add_ps(_mm256_mul_ps(w00, channel(t00, k)), _mm256_mul_ps(w10, channel(t10, k)));
                const __m256 b =
                    _mm256_add_ps(_mm256_mul_ps(w01, channel(t01, k)), _mm256_mul_ps(w11, channel(t11, k)));
                _mm256_store_ps(sum[k] + i, _mm256_add_ps(a, b));
            }
        }
#endif
        for (; i < count; ++i) {
            const float fx = float(s.wx[i]), fy = float(s.wy[i]);
            const float w11 = fx * fy, w10 = fx * 256.0f - w11, w01 = fy * 256.0f - w11;
            const float w00 = 65536.0f - fx * 256.0f - w01;
            for (int k = 0; k < 4; ++k)
                sum[k][i] = w00 * byteOf(s.t00[i], k) + w10 * byteOf(s.t10[i], k) + w01 * byteOf(s.t01[i], k) +
                            w11 * byteOf(s.t11[i], k);
        }
        return;
    }
    axisPass<false>(run.addressU, count, u, run.width, s.x0, s.x1, s.wx);
    axisPass<false>(run.addressV, count, v, run.height, s.y0, s.y1, s.wy);
    const size_t stride = size_t(run.width) * 4;
    for (int i = 0; i < count; ++i) {
        const int32_t x = s.x0[i], y = s.y0[i];
        const uint32_t w = (x | y) < 0 ? run.borderWord : load32(run.texels + size_t(y) * stride + size_t(x) * 4);
        for (int k = 0; k < 4; ++k) sum[k][i] = byteOf(w, k) * 65536.0f;
    }
}

void sampleUnorm8Mip(const Unorm8Run& level0, const Unorm8Run& level1, const int32_t* mipW, int count, const float* u,
                     const float* v, int32_t* const* dst) {
    static thread_local Scratch s;
    alignas(64) static thread_local float s0[4][kMaxSpan], s1[4][kMaxSpan];
    levelSums(level0, count, u, v, s, s0);
    levelSums(level1, count, u, v, s, s1);
    // (256 − m)·S0 + m·S1 < 2^32, exact in double, as is its product with scale / 2^24 (a power of
    // two); rounding it to an integer in the default mode is round-half-even.
    const double k = double(level0.scale) / 16777216.0;
    static constexpr int kPlane[4] = {2, 1, 0, 3};  // b g r a sums into the r g b a planes
    for (int c = 0; c < 4; ++c) {
        int32_t* out = dst[kPlane[c]];
        int i = 0;
#ifdef __AVX2__
        // Four lanes a step in double: the same exact values, rounded by the conversion (the
        // default mode: half to even).
        const __m256d kk = _mm256_set1_pd(k), full = _mm256_set1_pd(256.0);
        for (; i + 4 <= count; i += 4) {
            const __m256d m = _mm256_cvtepi32_pd(_mm_loadu_si128(reinterpret_cast<const __m128i*>(mipW + i)));
            const __m256d a = _mm256_cvtps_pd(_mm_loadu_ps(s0[c] + i)), b = _mm256_cvtps_pd(_mm_loadu_ps(s1[c] + i));
            const __m256d sum = _mm256_add_pd(_mm256_mul_pd(_mm256_sub_pd(full, m), a), _mm256_mul_pd(m, b));
            _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm256_cvtpd_epi32(_mm256_mul_pd(sum, kk)));
        }
#endif
        for (; i < count; ++i) {
            const double m = double(mipW[i]);
            out[i] = int32_t(std::nearbyint(((256.0 - m) * double(s0[c][i]) + m * double(s1[c][i])) * k));
        }
    }
}

// The float profiles' axis rule (texelPosition, addressPair, weight8 of
// texture_sampler_internal.h) lane by lane.
template <TextureAddress Mode>
void floatAxisScalar(bool linear, bool weights8, int count, const float* coord, uint32_t n, int32_t* i0, int32_t* i1,
                     float* f) {
    for (int i = 0; i < count; ++i) {
        double fl, fr;
        texelPosition(coord[i], n, linear, fl, fr);
        addressPair<Mode>(fl, n, i0[i], i1[i]);
        f[i] = !linear ? 0.0f : weights8 ? float(weight8(fr)) / 256.0f : float(fr);
    }
}

#ifdef __AVX2__
// The same rule four lanes a step in double: x = u·n − ½ (linear) or u·n, exact; fl = floor(x),
// fr = x − fl, exact; the float weight float(fr) (the default rounding) or round_half_even(fr·256)
// / 256; the texel pair by the integer address modes (address8, the same mapping as addressPair
// for |fl| < 2^23). Lanes beyond that (huge, infinite, NaN) and the tail take the scalar rule.
template <TextureAddress Mode>
void floatAxisAvx2(bool linear, bool weights8, int count, const float* coord, uint32_t n, int32_t* i0, int32_t* i1,
                   float* f) {
    const __m256d scale = _mm256_set1_pd(double(n)), bias = _mm256_set1_pd(linear ? 0.5 : 0.0);
    const __m256d range = _mm256_set1_pd(8388608.0);  // 2^23
    const __m256d absMask = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffffLL));
    const __m128i nv = _mm_set1_epi32(int32_t(n)), twoN = _mm_set1_epi32(int32_t(2 * n));
    const __m256d inv = _mm256_set1_pd(1.0 / double(n)), inv2 = _mm256_set1_pd(0.5 / double(n));
    int i = 0;
    for (; i + 4 <= count; i += 4) {
        const __m256d x = _mm256_sub_pd(_mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(coord + i)), scale), bias);
        if (_mm256_movemask_pd(_mm256_cmp_pd(_mm256_and_pd(x, absMask), range, _CMP_LT_OQ)) != 15) {
            floatAxisScalar<Mode>(linear, weights8, 4, coord + i, n, i0 + i, i1 + i, f + i);
            continue;
        }
        const __m256d fl = _mm256_floor_pd(x);
        const __m128i k = _mm256_cvttpd_epi32(fl);
        // address8 works on eight int32 lanes: the four here in the low half.
        auto address = [&](__m128i kk) {
            return _mm256_castsi256_si128(address8<Mode>(_mm256_zextsi128_si256(kk), _mm256_zextsi128_si256(nv), inv,
                                                         _mm256_zextsi128_si256(twoN), inv2));
        };
        _mm_storeu_si128(reinterpret_cast<__m128i*>(i0 + i), address(k));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(i1 + i), address(_mm_add_epi32(k, _mm_set1_epi32(1))));
        const __m256d fr = _mm256_sub_pd(x, fl);
        __m128 w;
        if (!linear) {
            w = _mm_setzero_ps();
        } else if (weights8) {
            const __m256d r = _mm256_round_pd(_mm256_mul_pd(fr, _mm256_set1_pd(256.0)),
                                              _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
            w = _mm_div_ps(_mm256_cvtpd_ps(r), _mm_set1_ps(256.0f));
        } else {
            w = _mm256_cvtpd_ps(fr);
        }
        _mm_storeu_ps(f + i, w);
    }
    if (i < count) floatAxisScalar<Mode>(linear, weights8, count - i, coord + i, n, i0 + i, i1 + i, f + i);
}
#define PS11_FLOAT_AXIS floatAxisAvx2
#else
#define PS11_FLOAT_AXIS floatAxisScalar
#endif

void floatAxis(TextureAddress mode, bool linear, bool weights8, int count, const float* c, uint32_t n, int32_t* i0,
               int32_t* i1, float* f) {
    switch (mode) {
        case TextureAddress::Mirror:
            return PS11_FLOAT_AXIS<TextureAddress::Mirror>(linear, weights8, count, c, n, i0, i1, f);
        case TextureAddress::Clamp:
            return PS11_FLOAT_AXIS<TextureAddress::Clamp>(linear, weights8, count, c, n, i0, i1, f);
        case TextureAddress::Border:
            return PS11_FLOAT_AXIS<TextureAddress::Border>(linear, weights8, count, c, n, i0, i1, f);
        case TextureAddress::MirrorOnce:
            return PS11_FLOAT_AXIS<TextureAddress::MirrorOnce>(linear, weights8, count, c, n, i0, i1, f);
        default:  // Wrap (and an invalid value, as the reference)
            return PS11_FLOAT_AXIS<TextureAddress::Wrap>(linear, weights8, count, c, n, i0, i1, f);
    }
}

// (1 − f)·a + f·b: the reference sampler's lerp (texture_sampler.cpp lerpf), operation for
// operation (this file is built without FMA contraction).
inline float lerpFloat(float a, float b, float f) { return (1.0f - f) * a + f * b; }

// Bilinear lanes of 8-bit texels in float: corners (i0, j0) (i1, j0) (i0, j1) (i1, j1), an index
// −1 reading the border colour.
void bilinearFloatScalar(const uint8_t* texels, uint32_t width, const int32_t* i0, const int32_t* i1,
                         const int32_t* j0, const int32_t* j1, const float* fu, const float* fv, const float* border,
                         int n, float* const* out) {
    const float* values = Texture::unorm8Values();
    for (int j = 0; j < n; ++j) {
        const int32_t xs[4] = {i0[j], i1[j], i0[j], i1[j]}, ys[4] = {j0[j], j0[j], j1[j], j1[j]};
        float t[4][4];
        for (int k = 0; k < 4; ++k)
            for (size_t c = 0; c < 4; ++c)
                t[k][c] = (xs[k] | ys[k]) < 0
                              ? border[c]
                              : values[texels[(size_t(ys[k]) * width + size_t(xs[k])) * 4 + size_t(kUnorm8Byte[c])]];
        for (size_t c = 0; c < 4; ++c)
            out[c][j] = lerpFloat(lerpFloat(t[0][c], t[1][c], fu[j]), lerpFloat(t[2][c], t[3][c], fu[j]), fv[j]);
    }
}

#ifdef __AVX2__
inline __m256 lerpFloat8(__m256 a, __m256 b, __m256 f) {
    return _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(1.0f), f), a), _mm256_mul_ps(f, b));
}

// Eight lanes a step: each corner's b g r a words gathered once for all four channels (the lanes
// whose corner is the border masked off, never read), then the border colour blended in.
void bilinearFloatAvx2(const uint8_t* texels, uint32_t width, const int32_t* i0, const int32_t* i1, const int32_t* j0,
                       const int32_t* j1, const float* fu, const float* fv, const float* border, int n,
                       float* const* out) {
    const __m256i byte = _mm256_set1_epi32(0xff), w = _mm256_set1_epi32(int32_t(width)), none = _mm256_set1_epi32(-1);
    const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), one = _mm256_set1_epi32(1);
    const int* words = reinterpret_cast<const int*>(texels);
    constexpr int kShift[4] = {16, 8, 0, 24};  // r g b a in a b g r a word
    int j = 0;
    for (; j + 8 <= n; j += 8) {
        const __m256i x0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(i0 + j));
        const __m256i x1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(i1 + j));
        const __m256i y0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(j0 + j));
        const __m256i y1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(j1 + j));
        const __m256i xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
        __m256i word[4];
        __m256 inside[4];
        // Eight columns in order on one pair of rows (a row of a plain read): plain loads.
        const int32_t cx = i0[j], cy0 = j0[j], cy1 = j1[j];
        const __m256i x0Run = _mm256_add_epi32(_mm256_set1_epi32(cx), iota);
        const __m256i off = _mm256_or_si256(
            _mm256_or_si256(_mm256_xor_si256(x0, x0Run), _mm256_xor_si256(x1, _mm256_add_epi32(x0Run, one))),
            _mm256_or_si256(_mm256_xor_si256(y0, _mm256_set1_epi32(cy0)), _mm256_xor_si256(y1, _mm256_set1_epi32(cy1))));
        if (_mm256_testz_si256(off, off) && (cx | cy0 | cy1) >= 0 && uint32_t(cx) + 9 <= width) {
            const int* r0 = words + size_t(cy0) * width + size_t(cx);
            const int* r1 = words + size_t(cy1) * width + size_t(cx);
            auto at = [](const int* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); };
            word[0] = at(r0), word[1] = at(r0 + 1), word[2] = at(r1), word[3] = at(r1 + 1);
            for (__m256& in : inside) in = _mm256_castsi256_ps(none);
        } else {
            for (int k = 0; k < 4; ++k) {
                const __m256i in = _mm256_cmpgt_epi32(_mm256_or_si256(xs[k], ys[k]), none);
                const __m256i at = _mm256_and_si256(_mm256_add_epi32(_mm256_mullo_epi32(ys[k], w), xs[k]), in);
                inside[k] = _mm256_castsi256_ps(in);
                word[k] = _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), words, at, in, 4);
            }
        }
        const __m256 u = _mm256_loadu_ps(fu + j), v = _mm256_loadu_ps(fv + j);
        for (int c = 0; c < 4; ++c) {
            const __m256 b = _mm256_set1_ps(border[c]);
            __m256 t[4];
            for (int k = 0; k < 4; ++k)
                t[k] = _mm256_blendv_ps(
                    b, unitOfByte(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(word[k], kShift[c]), byte))),
                    inside[k]);
            _mm256_storeu_ps(out[c] + j, lerpFloat8(lerpFloat8(t[0], t[1], u), lerpFloat8(t[2], t[3], u), v));
        }
    }
    if (j < n) {
        float* const rest[4] = {out[0] + j, out[1] + j, out[2] + j, out[3] + j};
        bilinearFloatScalar(texels, width, i0 + j, i1 + j, j0 + j, j1 + j, fu + j, fv + j, border, n - j, rest);
    }
}
#define PS11_BILINEAR_FLOAT bilinearFloatAvx2
#else
#define PS11_BILINEAR_FLOAT bilinearFloatScalar
#endif

void sampleUnorm8Float(const Unorm8FloatRun& run, int count, const float* u, const float* v, float* const* dst) {
    alignas(32) int32_t i0[kMaxSpan], i1[kMaxSpan], j0[kMaxSpan], j1[kMaxSpan];
    alignas(32) float fu[kMaxSpan], fv[kMaxSpan];
    count = count < kMaxSpan ? count : kMaxSpan;
    floatAxis(run.addressU, run.linear, run.weights8, count, u, run.width, i0, i1, fu);
    floatAxis(run.addressV, run.linear, run.weights8, count, v, run.height, j0, j1, fv);
    if (run.linear) {
        PS11_BILINEAR_FLOAT(run.texels, run.width, i0, i1, j0, j1, fu, fv, run.border, count, dst);
        return;
    }
    const float* values = Texture::unorm8Values();
    for (int i = 0; i < count; ++i) {
        const bool border = (i0[i] | j0[i]) < 0;
        const uint8_t* t = run.texels + (border ? 0 : (size_t(j0[i]) * run.width + size_t(i0[i])) * 4);
        for (size_t c = 0; c < 4; ++c) dst[c][i] = border ? run.border[c] : values[t[kUnorm8Byte[c]]];
    }
}

// QuadLevelKernel (texture_sampler_fast.h), four quads a step.
int chooseQuadLevels(const QuadLevelRun& run, int count, const float* u, const float* v, double* rho2, int32_t* level0,
                     int32_t* level1, int32_t* slots, int32_t* mipW, int32_t* linear) {
    int q = 0;
#ifdef __AVX2__
    const int quads = count / 16 * 4;
    const __m256d width = _mm256_set1_pd(run.width), height = _mm256_set1_pd(run.height);
    const __m256d one = _mm256_set1_pd(1.0), huge = _mm256_set1_pd(0x1p1000);
    const __m256d sqrt2 = _mm256_set1_pd(1.4142135623730951), half = _mm256_set1_pd(0.5);
    const __m256d invLn2 = _mm256_set1_pd(1.4426950408889634), k256 = _mm256_set1_pd(256.0);
    const __m256d edge = _mm256_set1_pd(256.0 * 1e-9);
    const __m256d absMask = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffffLL));
    const __m256d last = _mm256_set1_pd(double(run.levels - 1));
    const __m256i mantissa = _mm256_set1_epi64x(0x000fffffffffffffLL),
                  oneBits = _mm256_set1_epi64x(0x3ff0000000000000LL);
    const __m256i lowHalves = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
    // A double lane mask (or 64-bit integers small enough) as four 32-bit lanes.
    auto narrow = [&](__m256i v) { return _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(v, lowHalves)); };
    const __m128i zero4 = _mm_setzero_si128(), one4 = _mm_set1_epi32(1), two4 = _mm_set1_epi32(2);
    const __m128i w256 = _mm_set1_epi32(256);
    const __m128i minLin = _mm_set1_epi32(run.minLinear), magLin = _mm_set1_epi32(run.magLinear);
    const bool mips = run.levels > 1 && run.mipFilter != Filter::None;
    for (; q + 4 <= quads; q += 4) {
        // Lanes TL TR BL BR of quads q … q + 3, transposed: one vector per corner.
        __m128 u0 = _mm_loadu_ps(u + 4 * q), u1 = _mm_loadu_ps(u + 4 * q + 4), u2 = _mm_loadu_ps(u + 4 * q + 8),
               u3 = _mm_loadu_ps(u + 4 * q + 12);
        __m128 v0 = _mm_loadu_ps(v + 4 * q), v1 = _mm_loadu_ps(v + 4 * q + 4), v2 = _mm_loadu_ps(v + 4 * q + 8),
               v3 = _mm_loadu_ps(v + 4 * q + 12);
        _MM_TRANSPOSE4_PS(u0, u1, u2, u3);
        _MM_TRANSPOSE4_PS(v0, v1, v2, v3);
        // quadLevel's derivatives: c0 = tl·n, ∂x = tr·n − c0, ∂y = bl·n − c0 per axis, squared and summed.
        auto deriv = [&](__m128 tl, __m128 other, __m256d n) {
            const __m256d c0 = _mm256_mul_pd(_mm256_cvtps_pd(tl), n);
            return _mm256_sub_pd(_mm256_mul_pd(_mm256_cvtps_pd(other), n), c0);
        };
        const __m256d dxu = deriv(u0, u1, width), dyu = deriv(u0, u2, width);
        const __m256d dxv = deriv(v0, v1, height), dyv = deriv(v0, v2, height);
        const __m256d dx2 = _mm256_add_pd(_mm256_mul_pd(dxu, dxu), _mm256_mul_pd(dxv, dxv));
        const __m256d dy2 = _mm256_add_pd(_mm256_mul_pd(dyu, dyu), _mm256_mul_pd(dyv, dyv));
        const __m256d r = _mm256_max_pd(dy2, dx2);  // std::max(dx2, dy2): dx2 where either is NaN
        _mm256_storeu_pd(rho2 + q, r);
        const __m256d minified = _mm256_cmp_pd(r, one, _CMP_GT_OQ);  // LOD > 0 (false for NaN)
        const __m128i min4 = narrow(_mm256_castpd_si256(minified));
        __m128i l0 = zero4, l1 = zero4, sl = one4, w = zero4;
        __m128i fallback = zero4;
        if (mips && _mm256_movemask_pd(minified) != 0) {
            // log2(r) = e + log2(m), m in [√½, √2): ln m = 2·atanh(t), t = (m − 1)/(m + 1), |t| < 0.172,
            // by its series to t^11 (the next term is below 2e-11).
            const __m256i bits = _mm256_castpd_si256(r);
            __m256d m = _mm256_castsi256_pd(_mm256_or_si256(_mm256_and_si256(bits, mantissa), oneBits));
            const __m256d up = _mm256_cmp_pd(m, sqrt2, _CMP_GT_OQ);
            m = _mm256_blendv_pd(m, _mm256_mul_pd(m, half), up);
            const __m256i e64 = _mm256_sub_epi64(_mm256_srli_epi64(bits, 52), _mm256_set1_epi64x(1023));
            const __m128i e = _mm_sub_epi32(narrow(e64), narrow(_mm256_castpd_si256(up)));  // (a true mask is −1)
            const __m256d t = _mm256_div_pd(_mm256_sub_pd(m, one), _mm256_add_pd(m, one)), t2 = _mm256_mul_pd(t, t);
            __m256d p = _mm256_set1_pd(1.0 / 11);
            for (double c : {1.0 / 9, 1.0 / 7, 1.0 / 5, 1.0 / 3, 1.0})
                p = _mm256_add_pd(_mm256_mul_pd(p, t2), _mm256_set1_pd(c));
            const __m256d L =
                _mm256_add_pd(_mm256_cvtepi32_pd(e), _mm256_mul_pd(_mm256_mul_pd(_mm256_add_pd(t, t), p), invLn2));
            // Near an edge, or beyond the polynomial's range: chooseLevel decides.
            const __m256d s = _mm256_mul_pd(L, k256);
            const __m256d dist = _mm256_and_pd(
                _mm256_sub_pd(s, _mm256_round_pd(s, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC)), absMask);
            const __m256d unsure =
                _mm256_or_pd(_mm256_cmp_pd(dist, edge, _CMP_LT_OQ), _mm256_cmp_pd(r, huge, _CMP_NLT_UQ));
            fallback = _mm_and_si128(min4, narrow(_mm256_castpd_si256(unsure)));
            const __m256d lod = _mm256_mul_pd(L, half);
            if (run.mipFilter == Filter::Point) {
                // floor(LOD + ½), the last level from there on.
                l0 = _mm256_cvttpd_epi32(_mm256_min_pd(_mm256_add_pd(lod, half), last));
            } else {
                const __m256d beyond = _mm256_cmp_pd(lod, last, _CMP_GE_OQ);
                const __m256d lodIn = _mm256_min_pd(lod, last);  // (beyond lanes are replaced below)
                const __m128i a = _mm256_cvttpd_epi32(lodIn);
                const __m256d frac = _mm256_sub_pd(lodIn, _mm256_cvtepi32_pd(a));
                w = _mm256_cvtpd_epi32(_mm256_mul_pd(frac, k256));  // round half even (the default mode)
                const __m128i top = _mm_cmpeq_epi32(w, w256), none = _mm_cmpeq_epi32(w, zero4);
                l0 = _mm_sub_epi32(a, top);  // (a true mask is −1: one level up)
                l1 = _mm_add_epi32(a, one4);
                sl = _mm_blendv_epi8(two4, one4, _mm_or_si128(top, none));
                const __m128i b4 = narrow(_mm256_castpd_si256(beyond));
                const __m128i lastLevel = _mm_set1_epi32(run.levels - 1);
                l0 = _mm_blendv_epi8(l0, lastLevel, b4);
                l1 = _mm_andnot_si128(b4, l1);
                sl = _mm_blendv_epi8(sl, one4, b4);
                w = _mm_andnot_si128(b4, w);
            }
            // Magnified quads: level 0 alone.
            l0 = _mm_and_si128(l0, min4), l1 = _mm_and_si128(l1, min4), w = _mm_and_si128(w, min4);
            sl = _mm_blendv_epi8(one4, sl, min4);
        }
        auto store = [&](int32_t* p, __m128i v) { _mm_storeu_si128(reinterpret_cast<__m128i*>(p + q), v); };
        store(level0, l0), store(level1, l1), store(mipW, w);
        store(slots, _mm_andnot_si128(fallback, sl));
        store(linear, _mm_blendv_epi8(magLin, minLin, min4));
    }
#else
    (void)run, (void)count, (void)u, (void)v, (void)rho2, (void)level0, (void)level1, (void)slots, (void)mipW,
        (void)linear;
#endif
    return q;
}

}  // namespace

const SamplerKernels PS11_SAMPLER_LEVEL::kSampler{&sampleUnorm8, &floatAxis, &sampleUnorm8Mip, &sampleUnorm8Float,
                                                  &chooseQuadLevels};

}  // namespace ps11::fastpath
