// Device stage: Clear and StretchRect carried out in images (emu/blit.h). The front checks the
// calls and resolves the boxes and texels (emu/device_blit.cpp); the rules are in docs/device.md.
#include "emu/blit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "emu/output_merger_kernels.h"
#include "ps11/cpu_features.h"
#include "ps11/precision.h"
#include "ps11/simd_dispatch.h"

namespace emu {

namespace {

// floor(n / d) for d > 0.
int64_t floorDiv(int64_t n, int64_t d) {
    int64_t q = n / d;
    if ((n % d) != 0 && n < 0) --q;
    return q;
}

// memcpy with the destination's aligned 16-byte blocks stored around the caches (streamFence
// orders them before anything after).
void streamCopy(uint8_t* dst, const uint8_t* src, size_t n) {
#if defined(__SSE2__)
    const size_t head = std::min(n, size_t((16 - (reinterpret_cast<uintptr_t>(dst) & 15)) & 15));
    std::memcpy(dst, src, head);
    dst += head, src += head, n -= head;
    for (; n >= 16; n -= 16, dst += 16, src += 16)
        _mm_stream_si128(reinterpret_cast<__m128i*>(dst), _mm_loadu_si128(reinterpret_cast<const __m128i*>(src)));
#endif
    std::memcpy(dst, src, n);
}

#if defined(__SSE2__)
// An 8-bit word's four bytes, in memory order, as doubles two a register (`set` ORed into the word
// first: X8's alpha byte as 255).
struct ByteDoubles {
    __m128d lo, hi;
};
ByteDoubles byteDoubles(const uint8_t* p, uint32_t set) {
    uint32_t w;
    std::memcpy(&w, p, 4);
    const __m128i zero = _mm_setzero_si128();
    const __m128i q = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(int32_t(w | set)), zero), zero);
    return {_mm_cvtepi32_pd(q), _mm_cvtepi32_pd(_mm_shuffle_epi32(q, 0xEE))};
}

// stretchImages' LINEAR sum (1 − wy)·((1 − wx)·a + wx·b) + wy·((1 − wx)·c + wx·e) of four such
// words, each operation as the scalar one (no FMA at this level).
ByteDoubles lerpBytes(const uint8_t* a, const uint8_t* b, const uint8_t* c, const uint8_t* e, double wx, double wy,
                      uint32_t set) {
    const ByteDoubles pa = byteDoubles(a, set), pb = byteDoubles(b, set), pc = byteDoubles(c, set),
                      pe = byteDoubles(e, set);
    const __m128d gx = _mm_set1_pd(1 - wx), fx = _mm_set1_pd(wx), gy = _mm_set1_pd(1 - wy), fy = _mm_set1_pd(wy);
    auto sum = [&](__m128d va, __m128d vb, __m128d vc, __m128d ve) {
        return _mm_add_pd(_mm_mul_pd(gy, _mm_add_pd(_mm_mul_pd(gx, va), _mm_mul_pd(fx, vb))),
                          _mm_mul_pd(fy, _mm_add_pd(_mm_mul_pd(gx, vc), _mm_mul_pd(fx, ve))));
    };
    return {sum(pa.lo, pb.lo, pc.lo, pe.lo), sum(pa.hi, pb.hi, pc.hi, pe.hi)};
}
#endif

void streamFence() {
#if defined(__SSE2__)
    _mm_sfence();
#endif
}

PixelBox meet(const PixelBox& a, const PixelBox& b) {
    return {std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1), std::min(a.y1, b.y1)};
}

}  // namespace

void clearImages(const ClearCall& call, RowRange rows) {
    // A box's part within the image and the rows asked for.
    auto within = [&](const PixelBox& b, const Image& image) {
        PixelBox c = meet(b, PixelBox{0, 0, image.width, image.height});
        c.y0 = std::max(c.y0, rows.first);
        c.y1 = std::min(c.y1, rows.last);
        return c;
    };
    if (call.color.valid()) {
        Image* target = call.color.image;
        const FormatInfo& f = *target->format;
        for (const PixelBox& b : call.boxes) {
            const PixelBox c = within(b, *target);
            if (c.empty()) continue;
            // Fill the first row, then copy it to the others.
            for (int64_t x = c.x0; x < c.x1; ++x)
                std::copy_n(call.colorTexel.data(), f.bytes, target->texel(uint32_t(x), uint32_t(c.y0)));
            const size_t row = size_t(c.x1 - c.x0) * f.bytes;
            // A target of more than half the last cache level does not stay in it beside the
            // surfaces a frame reads with it: its rows are written around the caches (no read for
            // ownership: the clear moves half the bytes). Smaller ones stay cached for the draws
            // that follow (with a 32 MB cache, the sprites' 8 MB glare buffer drew 15 % slower
            // after a streamed clear, its 33 MB float one 25 % faster).
            const uint64_t cache = ps11::cpuFeatures().lastLevelCacheBytes;
            const bool stream = cache > 0 && uint64_t(target->width) * target->height * f.bytes > cache / 2;
            for (int64_t y = c.y0 + 1; y < c.y1; ++y) {
                uint8_t* dst = target->texel(uint32_t(c.x0), uint32_t(y));
                const uint8_t* src = target->texel(uint32_t(c.x0), uint32_t(c.y0));
                if (stream) {
                    streamCopy(dst, src, row);
                    continue;
                }
                std::memcpy(dst, src, row);
            }
            if (stream) streamFence();
        }
    }
    if (call.depth.valid()) {
        Image* depth = call.depth.image;
        const FormatInfo& f = *depth->format;
        for (const PixelBox& b : call.boxes) {
            const PixelBox c = within(b, *depth);
            for (int64_t y = c.y0; y < c.y1; ++y) {
                uint8_t* p = c.x0 < c.x1 ? depth->texel(uint32_t(c.x0), uint32_t(y)) : nullptr;
                for (int64_t x = c.x0; x < c.x1; ++x, p += f.bytes) {
                    const uint32_t w = (loadWord(p, f.bytes) & call.depthKeep) | call.depthSet;
                    for (uint32_t k = 0; k < f.bytes; ++k) p[k] = uint8_t(w >> (8 * k));
                }
            }
        }
    }
}

std::vector<StretchTap> stretchTaps(const StretchCall& call, bool horizontal) {
    const int64_t s0 = horizontal ? call.sourceRect.x0 : call.sourceRect.y0;
    const int64_t sn = horizontal ? call.sourceRect.x1 - s0 : call.sourceRect.y1 - s0;
    const int64_t dn = horizontal ? call.destRect.x1 - call.destRect.x0 : call.destRect.y1 - call.destRect.y0;
    std::vector<StretchTap> taps(size_t(std::max<int64_t>(dn, 0)));
    // Texel-centre mapping (docs/device.md): destination pixel i of the rect has its centre at
    // i + 1/2, which maps to source position s0 + (i + 1/2) * sn / dn. As exact fractions over
    // 2*dn: POINT takes floor(position) (a tie goes to the higher texel); LINEAR works in texel
    // space x = position - 1/2 = i0 + f.
    for (int64_t i = 0; i < dn; ++i) {
        StretchTap& t = taps[size_t(i)];
        if (!call.linear) {
            t.i0 = t.i1 = s0 + floorDiv((2 * i + 1) * sn, 2 * dn);
            continue;
        }
        const int64_t num2 = (2 * i + 1) * sn - dn;  // (x - s0) * 2dn
        const int64_t den = 2 * dn;
        const int64_t k = floorDiv(num2, den);
        const int64_t rem = num2 - k * den;  // f = rem / den in [0, 1)
        // fx profiles: 8 bits of sub-texel weight, round_half_even(f * 256) (docs/precision.md).
        t.w1 = call.fixedPoint ? double(ps11::roundHalfEven(rem * 256, den)) / 256.0 : double(rem) / double(den);
        // Taps outside the source rect are clamped to its edge texels.
        t.i0 = std::clamp(s0 + k, s0, s0 + sn - 1);
        t.i1 = std::clamp(s0 + k + 1, s0, s0 + sn - 1);
    }
    return taps;
}

void stretchImages(const StretchCall& call, RowRange rows) {
    const Image* s = call.source.image;
    Image* d = call.dest.image;
    const PixelBox& sr = call.sourceRect;
    const PixelBox& dr = call.destRect;
    const FormatInfo& sf = *s->format;
    const FormatInfo& df = *d->format;
    const int64_t sw = sr.x1 - sr.x0, sh = sr.y1 - sr.y0;
    const int64_t dw = dr.x1 - dr.x0;
    // Destination rows [j0, dh) of the rect.
    const int64_t j0 = std::clamp<int64_t>(rows.first, 0, dr.y1 - dr.y0);
    const int64_t dh = std::clamp<int64_t>(rows.last, j0, dr.y1 - dr.y0);
    const int64_t fullHeight = dr.y1 - dr.y0;
    const bool unormSource = sf.cls == FormatClass::Unorm8;
    // Channel values in source units: bytes for 8-bit sources (exact sums), values otherwise.
    auto fetch = [&](int64_t x, int64_t y) {
        std::array<double, 4> v;
        const uint8_t* p = s->texel(uint32_t(x), uint32_t(y));
        if (unormSource) {
            std::array<uint8_t, 4> b = decodeUnorm8(sf, p);
            for (size_t c = 0; c < 4; ++c) v[c] = b[c];
        } else {
            std::array<float, 4> f = decodeTexel(sf, p, call.decode);
            for (size_t c = 0; c < 4; ++c) v[c] = f[c];
        }
        return v;
    };
    auto store = [&](int64_t x, int64_t y, const std::array<double, 4>& v) {
        uint8_t* p = d->texel(uint32_t(x), uint32_t(y));
        if (df.cls == FormatClass::Unorm8) {
            std::array<uint8_t, 4> b;
            for (size_t c = 0; c < 4; ++c)
                b[c] = unormSource ? uint8_t(std::clamp(std::nearbyint(v[c]), 0.0, 255.0)) : ps11::unorm8OfFloat(v[c]);
            encodeUnorm8(df, b, p);
        } else {
            std::array<float, 4> f;
            for (size_t c = 0; c < 4; ++c) f[c] = float(unormSource ? v[c] / 255.0 : v[c]);
            encodeFloat(df, f, p);
        }
    };
    const bool linear = call.linear;
    const bool sameFormat = &sf == &df;
    // Fast path: an unscaled copy in one format is a row copy with either filter (LINEAR has
    // f = 0 at every pixel, so it reproduces the texels exactly).
    if (sameFormat && sw == dw && sh == fullHeight) {
        const size_t row = size_t(sw) * sf.bytes;
        for (int64_t j = j0; j < dh; ++j)
            std::memmove(d->texel(uint32_t(dr.x0), uint32_t(dr.y0 + j)), s->texel(uint32_t(sr.x0), uint32_t(sr.y0 + j)),
                         row);
        return;
    }
    // Fast path: an unscaled copy of 8-bit b g r a words into A32B32G32R32F (the ideal profile's
    // float targets) stores each byte's value float(b / 255), what store() makes of it.
    if (sw == dw && sh == fullHeight && unormSource && sf.bytes == 4 && df.format == D3DFMT_A32B32G32R32F) {
        static const std::array<float, 256> value = [] {
            std::array<float, 256> t{};
            for (size_t b = 0; b < 256; ++b) t[b] = float(double(b) / 255.0);
            return t;
        }();
        const bool x8 = sf.format == D3DFMT_X8R8G8B8;
        for (int64_t j = j0; j < dh; ++j) {
            const uint8_t* in = s->texel(uint32_t(sr.x0), uint32_t(sr.y0 + j));
            uint8_t* out = d->texel(uint32_t(dr.x0), uint32_t(dr.y0 + j));
            for (int64_t i = 0; i < dw; ++i, in += 4, out += 16) {
                const float v[4] = {value[in[2]], value[in[1]], value[in[0]], x8 ? 1.0f : value[in[3]]};
                std::memcpy(out, v, 16);
            }
        }
        return;
    }
    // Fast path: an unscaled copy of A32B32G32R32F into 8-bit b g r a words (the ideal
    // profile's float frame into an 8-bit output): store()'s rounding (ps11::unorm8OfFloat), by
    // the merger's kernel for such rows; X8R8G8B8 gets 0xff.
    if (sw == dw && sh == fullHeight && sf.format == D3DFMT_A32B32G32R32F && df.cls == FormatClass::Unorm8 && df.bytes == 4) {
        const MergerKernels& k = mergerKernels(ps11::simdLevel());
        const uint32_t fill = df.format == D3DFMT_X8R8G8B8 ? 0xFF000000u : 0u;
        std::vector<uint32_t> words(static_cast<size_t>(dw));
        for (int64_t j = j0; j < dh; ++j) {
            const uint8_t* in = s->texel(uint32_t(sr.x0), uint32_t(sr.y0 + j));
            uint8_t* out = d->texel(uint32_t(dr.x0), uint32_t(dr.y0 + j));
            k.unorm8WordsRgba(reinterpret_cast<const float*>(in), int(dw), fill, words.data());
            std::memcpy(out, words.data(), 4 * size_t(dw));
        }
        return;
    }
    // Fast path: an exact 2:1 LINEAR reduction of A8R8G8B8/X8R8G8B8 has f = 1/2 on both axes
    // (weight 128/256 in fx profiles, 1/2 exactly otherwise), so each byte is
    // round_half_even((a + b + c + d) / 4) of a 2x2 block, the general path's result.
    if (linear && sameFormat && sf.bytes == 4 && sf.cls == FormatClass::Unorm8 && sw == 2 * dw && sh == 2 * fullHeight) {
        const bool x8 = sf.format == D3DFMT_X8R8G8B8;
        for (int64_t j = j0; j < dh; ++j) {
            const uint8_t* r0 = s->texel(uint32_t(sr.x0), uint32_t(sr.y0 + 2 * j));
            const uint8_t* r1 = r0 + s->rowPitch;
            uint8_t* out = d->texel(uint32_t(dr.x0), uint32_t(dr.y0 + j));
            for (int64_t i = 0; i < dw; ++i, r0 += 8, r1 += 8, out += 4)
                for (int b = 0; b < 4; ++b) {
                    const int sum = r0[b] + r0[b + 4] + r1[b] + r1[b + 4];
                    // (sum + 1 + ((sum >> 2) & 1)) >> 2 is round_half_even(sum / 4).
                    out[b] = uint8_t((sum + 1 + ((sum >> 2) & 1)) >> 2);
                }
            if (x8)
                for (int64_t i = 0; i < dw; ++i) d->texel(uint32_t(dr.x0 + i), uint32_t(dr.y0 + j))[3] = 0xFF;
        }
        return;
    }
    const std::vector<StretchTap> tapX = stretchTaps(call, true), tapY = stretchTaps(call, false);
    // Fast path: LINEAR between 8-bit b g r a words of one format in an fx profile. The weights
    // are k/256, so the general path's double sum is exactly S / 65536 with the integer
    // S = (256-ky)((256-kx)a + kx b) + ky((256-kx)c + kx e), and its rounding round_half_even(S / 65536).
    if (linear && sameFormat && call.fixedPoint && sf.bytes == 4 && sf.cls == FormatClass::Unorm8) {
        const bool x8 = sf.format == D3DFMT_X8R8G8B8;
        std::vector<int32_t> kx(static_cast<size_t>(dw)), x0(static_cast<size_t>(dw)), x1(static_cast<size_t>(dw));
        for (int64_t i = 0; i < dw; ++i) {
            const StretchTap& t = tapX[size_t(i)];
            kx[size_t(i)] = int32_t(t.w1 * 256.0);
            x0[size_t(i)] = int32_t(t.i0) * 4, x1[size_t(i)] = int32_t(t.i1) * 4;
        }
        for (int64_t j = j0; j < dh; ++j) {
            const StretchTap& ty = tapY[size_t(j)];
            const int64_t ky = int64_t(ty.w1 * 256.0);
            const uint8_t* r0 = s->texel(0, uint32_t(ty.i0));
            const uint8_t* r1 = s->texel(0, uint32_t(ty.i1));
            uint8_t* out = d->texel(uint32_t(dr.x0), uint32_t(dr.y0 + j));
            int64_t i = 0;
#if defined(__SSE2__)
            // The next row's texels are asked for while this row's are combined: a minification
            // (a 1080p frame to 128×128) reads a line or two per pixel, each from memory.
            const bool ahead = j + 1 < dh;
            const uint8_t* n0 = ahead ? s->texel(0, uint32_t(tapY[size_t(j + 1)].i0)) : r0;
            const uint8_t* n1 = ahead ? s->texel(0, uint32_t(tapY[size_t(j + 1)].i1)) : r1;
            // The same sum in float, one pixel's four channels at a time: every product and partial
            // sum is an integer below 2^24 (S <= 65536 * 255), so exact; S / 65536 is exact too, and
            // the conversion rounds to nearest even (the default MXCSR mode).
            const __m128 ya = _mm_set1_ps(float(256 - ky)), yb = _mm_set1_ps(float(ky));
            const __m128 scale = _mm_set1_ps(1.0f / 65536.0f);
            const __m128i zero = _mm_setzero_si128(), alpha = _mm_set1_epi32(x8 ? int32_t(0xff000000u) : 0);
            auto channels = [&](const uint8_t* p) {
                int32_t w;
                std::memcpy(&w, p, 4);
                return _mm_cvtepi32_ps(_mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(w), zero), zero));
            };
            for (; i < dw; ++i, out += 4) {
                const __m128 xb = _mm_set1_ps(float(kx[size_t(i)])), xa = _mm_set1_ps(float(256 - kx[size_t(i)]));
                const size_t o0 = size_t(x0[size_t(i)]), o1 = size_t(x1[size_t(i)]);
                _mm_prefetch(reinterpret_cast<const char*>(n0 + o0), _MM_HINT_T0);
                _mm_prefetch(reinterpret_cast<const char*>(n1 + o0), _MM_HINT_T0);
                const __m128 top = _mm_add_ps(_mm_mul_ps(channels(r0 + o0), xa), _mm_mul_ps(channels(r0 + o1), xb));
                const __m128 bottom = _mm_add_ps(_mm_mul_ps(channels(r1 + o0), xa), _mm_mul_ps(channels(r1 + o1), xb));
                const __m128i q = _mm_cvtps_epi32(_mm_mul_ps(_mm_add_ps(_mm_mul_ps(top, ya), _mm_mul_ps(bottom, yb)), scale));
                const __m128i packed = _mm_packus_epi16(_mm_packs_epi32(q, zero), zero);
                const uint32_t word = uint32_t(_mm_cvtsi128_si32(_mm_or_si128(packed, alpha)));
                std::memcpy(out, &word, 4);
            }
#endif
            for (; i < dw; ++i, out += 4) {
                const int64_t wx = kx[size_t(i)];
                const uint8_t *a = r0 + x0[size_t(i)], *b = r0 + x1[size_t(i)], *c = r1 + x0[size_t(i)], *e = r1 + x1[size_t(i)];
                for (int k = 0; k < (x8 ? 3 : 4); ++k) {
                    const int64_t top = (256 - wx) * a[k] + wx * b[k], bottom = (256 - wx) * c[k] + wx * e[k];
                    out[k] = uint8_t(ps11::roundHalfEven((256 - ky) * top + ky * bottom, 65536));
                }
                if (x8) out[3] = 0xFF;
            }
        }
        return;
    }
    // Fast paths: LINEAR between 8-bit b g r a words of one format with the float profiles'
    // weights, and between A32B32G32R32F images: the general path's double sum in the same
    // order, one pixel's four channels at a time, with the next row's texels asked for ahead (a
    // reduction of a 1080p frame reads a line or two of memory per pixel).
    const bool words8 = sameFormat && sf.bytes == 4 && unormSource;
    const bool floats = sameFormat && sf.format == D3DFMT_A32B32G32R32F;
    if (linear && (words8 || floats)) {
        const bool x8 = sf.format == D3DFMT_X8R8G8B8;
        const size_t bytes = sf.bytes;
        for (int64_t j = j0; j < dh; ++j) {
            const StretchTap& ty = tapY[size_t(j)];
            const double wy = ty.w1;
            const uint8_t* r0 = s->texel(0, uint32_t(ty.i0));
            const uint8_t* r1 = s->texel(0, uint32_t(ty.i1));
            const bool ahead = j + 1 < dh;
            const uint8_t* n0 = ahead ? s->texel(0, uint32_t(tapY[size_t(j + 1)].i0)) : r0;
            const uint8_t* n1 = ahead ? s->texel(0, uint32_t(tapY[size_t(j + 1)].i1)) : r1;
            uint8_t* out = d->texel(uint32_t(dr.x0), uint32_t(dr.y0 + j));
            for (int64_t i = 0; i < dw; ++i, out += bytes) {
                const StretchTap& tx = tapX[size_t(i)];
                const double wx = tx.w1;
                const size_t o0 = size_t(tx.i0) * bytes, o1 = size_t(tx.i1) * bytes;
                __builtin_prefetch(n0 + o0);
                __builtin_prefetch(n1 + o0);
                double v[4];
                if (floats) {
                    float a[4], b[4], c[4], e[4];
                    std::memcpy(a, r0 + o0, 16), std::memcpy(b, r0 + o1, 16);
                    std::memcpy(c, r1 + o0, 16), std::memcpy(e, r1 + o1, 16);
                    for (int k = 0; k < 4; ++k)
                        v[k] = (1 - wy) * ((1 - wx) * double(a[k]) + wx * double(b[k])) +
                               wy * ((1 - wx) * double(c[k]) + wx * double(e[k]));
                    float f[4];
                    for (int k = 0; k < 4; ++k) f[k] = float(v[k]);
                    std::memcpy(out, f, 16);
                } else {
                    const uint8_t *a = r0 + o0, *b = r0 + o1, *c = r1 + o0, *e = r1 + o1;
#if defined(__SSE2__)
                    // The same sums two channels a register (lerpBytes); the conversion rounds to
                    // nearest even as nearbyint does under the default mode, and the packs
                    // saturate as the clamp does.
                    const ByteDoubles sum = lerpBytes(a, b, c, e, wx, wy, 0);
                    const __m128i zero = _mm_setzero_si128();
                    const __m128i words = _mm_unpacklo_epi64(_mm_cvtpd_epi32(sum.lo), _mm_cvtpd_epi32(sum.hi));
                    uint32_t word = uint32_t(_mm_cvtsi128_si32(_mm_packus_epi16(_mm_packs_epi32(words, zero), zero)));
                    if (x8) word |= 0xFF000000u;
                    std::memcpy(out, &word, 4);
#else
                    for (int k = 0; k < 4; ++k)
                        v[k] = (1 - wy) * ((1 - wx) * double(a[k]) + wx * double(b[k])) +
                               wy * ((1 - wx) * double(c[k]) + wx * double(e[k]));
                    for (int k = 0; k < 4; ++k) out[k] = uint8_t(std::clamp(std::nearbyint(v[k]), 0.0, 255.0));
                    if (x8) out[3] = 0xFF;
#endif
                }
            }
        }
        return;
    }
    // Fast path: A8R8G8B8 or X8R8G8B8 into A32B32G32R32F at any scale, either filter (the ideal
    // profile reading an 8-bit scene: a 1080p frame to a 128×128 float target). The general
    // path's sum over bytes in the same order (X8's alpha the byte 255 through it too), then
    // store()'s float(v / 255), one pixel's r g b a at a time.
    if ((sf.format == D3DFMT_A8R8G8B8 || sf.format == D3DFMT_X8R8G8B8) && df.format == D3DFMT_A32B32G32R32F) {
        const bool x8 = sf.format == D3DFMT_X8R8G8B8;
#if !defined(__SSE2__)
        auto bytesOf = [&](const uint8_t* p) {
            return std::array<double, 4>{double(p[2]), double(p[1]), double(p[0]), x8 ? 255.0 : double(p[3])};
        };
#endif
        for (int64_t j = j0; j < dh; ++j) {
            const StretchTap& ty = tapY[size_t(j)];
            const double wy = ty.w1;
            const uint8_t* r0 = s->texel(0, uint32_t(ty.i0));
            const uint8_t* r1 = s->texel(0, uint32_t(ty.i1));
            const bool ahead = j + 1 < dh;
            const uint8_t* n0 = ahead ? s->texel(0, uint32_t(tapY[size_t(j + 1)].i0)) : r0;
            const uint8_t* n1 = ahead ? s->texel(0, uint32_t(tapY[size_t(j + 1)].i1)) : r1;
            uint8_t* out = d->texel(uint32_t(dr.x0), uint32_t(dr.y0 + j));
            for (int64_t i = 0; i < dw; ++i, out += 16) {
                const StretchTap& tx = tapX[size_t(i)];
                const size_t o0 = size_t(tx.i0) * 4, o1 = size_t(tx.i1) * 4;
                __builtin_prefetch(n0 + o0);
                if (linear) __builtin_prefetch(n1 + o0);
#if defined(__SSE2__)
                // b g r a as doubles (the sum two channels a register: lerpBytes), over 255,
                // rounded to float as the scalar conversion does, then put in r g b a order.
                const uint32_t set = x8 ? 0xFF000000u : 0u;
                const ByteDoubles v = linear ? lerpBytes(r0 + o0, r0 + o1, r1 + o0, r1 + o1, tx.w1, wy, set)
                                             : byteDoubles(r0 + o0, set);
                const __m128d unit = _mm_set1_pd(255.0);
                const __m128 bgra = _mm_movelh_ps(_mm_cvtpd_ps(_mm_div_pd(v.lo, unit)), _mm_cvtpd_ps(_mm_div_pd(v.hi, unit)));
                _mm_storeu_ps(reinterpret_cast<float*>(out), _mm_shuffle_ps(bgra, bgra, _MM_SHUFFLE(3, 0, 1, 2)));
#else
                std::array<double, 4> v = bytesOf(r0 + o0);
                if (linear) {
                    const double wx = tx.w1;
                    const std::array<double, 4> b = bytesOf(r0 + o1), c = bytesOf(r1 + o0), e = bytesOf(r1 + o1);
                    for (size_t k = 0; k < 4; ++k)
                        v[k] = (1 - wy) * ((1 - wx) * v[k] + wx * b[k]) + wy * ((1 - wx) * c[k] + wx * e[k]);
                }
                const float f[4] = {float(v[0] / 255.0), float(v[1] / 255.0), float(v[2] / 255.0), float(v[3] / 255.0)};
                std::memcpy(out, f, 16);
#endif
            }
        }
        return;
    }
    for (int64_t j = j0; j < dh; ++j) {
        for (int64_t i = 0; i < dw; ++i) {
            const int64_t dx = dr.x0 + i, dy = dr.y0 + j;
            if (!linear) {
                const int64_t sx = tapX[size_t(i)].i0, sy = tapY[size_t(j)].i0;
                if (sameFormat)
                    std::copy_n(s->texel(uint32_t(sx), uint32_t(sy)), sf.bytes, d->texel(uint32_t(dx), uint32_t(dy)));
                else
                    store(dx, dy, fetch(sx, sy));
                continue;
            }
            const StretchTap& tx = tapX[size_t(i)];
            const StretchTap& ty = tapY[size_t(j)];
            const std::array<double, 4> a = fetch(tx.i0, ty.i0), b = fetch(tx.i1, ty.i0);
            const std::array<double, 4> c = fetch(tx.i0, ty.i1), e = fetch(tx.i1, ty.i1);
            std::array<double, 4> v;
            // Exact weighted sum (8-bit weights and 8-bit texels: products of dyadic numbers are
            // exact in double), rounded once in store().
            for (size_t k = 0; k < 4; ++k)
                v[k] = (1 - ty.w1) * ((1 - tx.w1) * a[k] + tx.w1 * b[k]) + ty.w1 * ((1 - tx.w1) * c[k] + tx.w1 * e[k]);
            store(dx, dy, v);
        }
    }
}

}  // namespace emu
