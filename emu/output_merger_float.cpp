// The output merger's float family (docs/output-merger.md): float arithmetic for the float and
// ideal profiles on 8-bit targets and for every profile on float targets, and the Baseline level
// of the merger's kernel table (emu/output_merger_kernels.h). The dispatch is mergePixels
// (emu/output_merger.cpp).
#include <algorithm>
#include <cassert>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "emu/output_merger_internal.h"
#include "emu/output_merger_kernels.h"
#include "ps11/sampler.h"

namespace emu {

namespace merger {
// ---------------------------------------------------------------------------------------------
// Float arithmetic: float/ideal profiles on 8-bit targets, every profile on float targets.

// s * Fs (op) d * Fd in float32, evaluated as written (two products, one sum; a ZERO factor
// contributes nothing, so 0 * inf does not make a NaN). v holds the slots.
// Not inlined: which of two NaNs ts + td passes on follows the operand order the compiler gives
// the sum, so every path blends through this one copy (the row paths' vector blend hands it its
// lanes holding a NaN).
[[gnu::noinline]] float blendFloat(const ChannelPlan& cp, const float* v, float s, float d) {
    if (cp.kind == OpKind::Min) return s < d ? s : d;
    if (cp.kind == OpKind::Max) return s > d ? s : d;
    const bool zs = cp.src.slot == kZero && !cp.src.inv, zd = cp.dst.slot == kZero && !cp.dst.inv;
    const float fs = cp.src.inv ? 1.0f - v[cp.src.slot] : v[cp.src.slot];
    const float fd = cp.dst.inv ? 1.0f - v[cp.dst.slot] : v[cp.dst.slot];
    const float ts = float(cp.cs) * (s * fs), td = float(cp.cd) * (d * fd);
    if (zs) return zd ? 0.0f : td;
    if (zd) return ts;
    return ts + td;
}

// One pixel of a float target (R32F, A16B16G16R16F, A32B32G32R32F): blended with what it holds
// when the plan blends (blendFloat per channel; v holds the plan's constant slots), then the
// enabled channels stored.
inline void blendIntoFloatTarget(const Plan& p, const ChannelPlan* ch, float* v, float s[4], uint8_t* q) {
    float d[4] = {0, 0, 0, 1};
    if (p.blend) {
        if (p.target == TargetKind::Rgba16F) {
            for (int c = 0; c < 4; ++c) {
                uint16_t h;
                std::memcpy(&h, q + 2 * c, 2);
                d[c] = floatOfHalf(h);
            }
        } else if (p.target == TargetKind::Rgba32F) {
            std::memcpy(d, q, 16);
        } else {
            std::memcpy(d, q, 4);  // R32F: g b a read 1
            d[1] = d[2] = d[3] = 1.0f;
        }
        for (int c = 0; c < 4; ++c) v[kSrc + c] = s[c], v[kDst + c] = d[c];
        v[kSat] = std::min(s[3], 1.0f - d[3]);
        for (int c = 0; c < 4; ++c) s[c] = blendFloat(ch[c], v, s[c], d[c]);
    }
    for (int c = 0; c < 4; ++c) {
        if (!(p.channels >> c & 1u)) continue;
        if (p.target == TargetKind::Rgba16F) {
            const uint16_t h = halfOf(s[c]);
            std::memcpy(q + 2 * c, &h, 2);
        } else {
            std::memcpy(q + 4 * c, &s[c], 4);  // R32F: only c = 0 is enabled
        }
    }
}

void mergeFloat(const Plan& p, const MergeInputs& in, const FloatSource& src, Counts& n) {
    const bool fx = ps11::isFixedPoint(p.precision);
    // Without a colour target (depth only) the alpha test uses the 8-bit rule.
    const bool unorm = !p.color || p.target == TargetKind::Argb8 || p.target == TargetKind::Xrgb8;
    const bool x8 = p.target == TargetKind::Xrgb8;
    const uint32_t mask = unorm ? wordMask(p) : 0;
    const Lanes lanes(in, p);
    const Surf cs = p.colorSurf;
    const DepthCtx dc = depthCtxOf(p);
    const DepthCtx* depth = p.depthTest ? &dc : nullptr;
    ChannelPlan ch[4];
    std::copy_n(p.ch, 4, ch);
    float v[kSlots];
    v[kZero] = 0.0f, v[kOne] = 1.0f;
    for (int c = 0; c < 4; ++c) v[kBf + c] = float(p.bfByte[c]) / 255.0f;
    float fogF[3];
    int32_t fogG[3];
    for (int c = 0; c < 3; ++c) fogF[c] = float(p.fogByte[c]) / 255.0f, fogG[c] = int32_t(p.fogByte[c]) * (src.G / 255);
    const int32_t G = src.G;
    for (int i = 0; i < in.count; ++i) {
        if (in.live && !in.live[i]) continue;
        uint32_t x, y;
        if (!lanes.inside(i, x, y)) continue;
        float s[4];
        bool alphaPass = true;
        if (fx) {
            // Grid values: saturated for an 8-bit target, as the executor left them (within
            // +-M) for a float target; fog exact on the grid.
            int32_t gn[4];
            for (int c = 0; c < 4; ++c) gn[c] = unorm ? std::clamp(src.grid[c][i], 0, G) : src.grid[c][i];
            if (p.fog) {
                const int32_t fq = int32_t(ps11::roundEvenSmall(double(lanes.fog(i)) * G));
                for (int c = 0; c < 3; ++c) {
                    const int64_t num = int64_t(fq) * gn[c] + int64_t(G - fq) * fogG[c];
                    gn[c] = int32_t(ps11::roundHalfEven(num, G));
                }
            }
            for (int c = 0; c < 4; ++c) s[c] = (unorm || p.fog) ? float(gn[c]) / float(G) : src.color[c][i];
            // Alpha n / G against ALPHAREF / 255, exactly.
            if (p.alphaTest) {
                if (unorm) {
                    const uint32_t a8 = G == 255 ? uint32_t(gn[3]) : uint32_t(divRoundEven<16>(gn[3]));
                    alphaPass = cmpPass(p.alphaMask, a8, p.alphaRef);
                } else {
                    alphaPass = cmpPass(p.alphaMask, int64_t(gn[3]) * 255, int64_t(p.alphaRef) * G);
                }
            }
        } else {
            for (int c = 0; c < 4; ++c) s[c] = unorm ? sat(src.color[c][i]) : src.color[c][i];
            if (p.fog) {
                const float f = lanes.fog(i);
                for (int c = 0; c < 3; ++c) s[c] = f * s[c] + (1.0f - f) * fogF[c];
            }
            if (p.alphaTest) {
                alphaPass = unorm ? cmpPass(p.alphaMask, byteOfUnit(s[3]), p.alphaRef)
                                  : cmpPass(p.alphaMask, double(s[3]) * 255.0, double(p.alphaRef));
            }
        }
        if (!tests(depth, alphaPass, x, y, lanes.z(i), n) || !p.color) continue;
        uint8_t* q = cs.at(x, y);
        if (unorm) {
            uint32_t out[4];
            if (!p.blend) {
                for (int c = 0; c < 4; ++c) out[c] = ps11::unorm8OfFloat(s[c]);
            } else {
                const uint32_t old = load32(q);
                v[kDst + 0] = kUnitOfByte[(old >> 16) & 0xffu];
                v[kDst + 1] = kUnitOfByte[(old >> 8) & 0xffu];
                v[kDst + 2] = kUnitOfByte[old & 0xffu];
                v[kDst + 3] = x8 ? 1.0f : kUnitOfByte[old >> 24];
                for (int c = 0; c < 4; ++c) v[kSrc + c] = s[c];
                v[kSat] = std::min(s[3], 1.0f - v[kDst + 3]);
                for (int c = 0; c < 4; ++c) out[c] = ps11::unorm8OfFloat(blendFloat(ch[c], v, s[c], v[kDst + c]));
            }
            uint32_t w = packArgb(out[0], out[1], out[2], x8 ? 0xffu : out[3]);
            if (mask != 0xffffffffu) w = (w & mask) | (load32(q) & ~mask);
            store32(q, w);
            continue;
        }
        blendIntoFloatTarget(p, ch, v, s, q);
    }
}

namespace {

// sat(src[i]) + the byte at bit `shift` of the i-th destination word, as its value.
void satAddUnorm8(const float* src, const uint8_t* words, int shift, int count, float* out) {
    int i = 0;
#if defined(__SSE2__)
    // sat: v > 0 selects min(v, 1), else 0 (NaN included); d = float(byte) / 255, as kUnitOfByte.
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), k255 = _mm_set1_ps(255.0f);
    const __m128i byte = _mm_set1_epi32(0xff);
    const __m128i count128 = _mm_cvtsi32_si128(shift);
    for (; i + 4 <= count; i += 4) {
        const __m128 v = _mm_loadu_ps(src + i);
        const __m128 sv = _mm_and_ps(_mm_cmpgt_ps(v, zero), _mm_min_ps(v, one));
        const __m128i w = _mm_loadu_si128(reinterpret_cast<const __m128i*>(words + 4 * i));
        const __m128 d = _mm_div_ps(_mm_cvtepi32_ps(_mm_and_si128(_mm_srl_epi32(w, count128), byte)), k255);
        _mm_storeu_ps(out + i, _mm_add_ps(sv, d));
    }
#endif
    for (; i < count; ++i) out[i] = sat(src[i]) + kUnitOfByte[(load32(words + 4 * i) >> shift) & 0xffu];
}

}  // namespace

// The Baseline level's 8-bit words (emu/output_merger_kernels.h).
void unorm8WordsBaseline(const float* const f[4], int count, uint32_t alphaFill, uint32_t* words) {
    int i = 0;
#if defined(__SSE2__)
    // Two lanes of a channel per step in double: max(v, 0) is 0 for NaN (MAXPD returns its second
    // operand), the product is exact, CVTPD2DQ rounds to nearest even (the default MXCSR mode).
    const __m128d zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0), k255 = _mm_set1_pd(255.0);
    const auto bytes4 = [&](const float* p) {
        const __m128 v = _mm_loadu_ps(p);
        const __m128d lo = _mm_mul_pd(_mm_min_pd(_mm_max_pd(_mm_cvtps_pd(v), zero), one), k255);
        const __m128d hi = _mm_mul_pd(_mm_min_pd(_mm_max_pd(_mm_cvtps_pd(_mm_movehl_ps(v, v)), zero), one), k255);
        return _mm_unpacklo_epi64(_mm_cvtpd_epi32(lo), _mm_cvtpd_epi32(hi));
    };
    const __m128i fill = _mm_set1_epi32(int32_t(alphaFill));
    for (; i + 4 <= count; i += 4) {
        const __m128i w = _mm_or_si128(
            _mm_or_si128(_mm_slli_epi32(bytes4(f[3] + i), 24), _mm_slli_epi32(bytes4(f[0] + i), 16)),
            _mm_or_si128(_mm_slli_epi32(bytes4(f[1] + i), 8), bytes4(f[2] + i)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(words + i), _mm_or_si128(w, fill));
    }
#endif
    for (; i < count; ++i)
        words[i] = packArgb(ps11::unorm8OfFloat(f[0][i]), ps11::unorm8OfFloat(f[1][i]), ps11::unorm8OfFloat(f[2][i]),
                            ps11::unorm8OfFloat(f[3][i])) |
                   alphaFill;
}

void unorm8WordsRgbaBaseline(const float* rgba, int count, uint32_t alphaFill, uint32_t* words) {
    int i = 0;
#if defined(__SSE2__)
    // A pixel's channels two at a time in double, as unorm8WordsBaseline; four pixels packed with
    // saturation (exact: every value is in [0, 255]).
    const __m128d zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0), k255 = _mm_set1_pd(255.0);
    auto bgra = [&](const float* px) {  // b g r a int32
        const __m128 v = _mm_loadu_ps(px);
        const __m128d rg = _mm_mul_pd(_mm_min_pd(_mm_max_pd(_mm_cvtps_pd(v), zero), one), k255);
        const __m128d ba = _mm_mul_pd(_mm_min_pd(_mm_max_pd(_mm_cvtps_pd(_mm_movehl_ps(v, v)), zero), one), k255);
        return _mm_shuffle_epi32(_mm_unpacklo_epi64(_mm_cvtpd_epi32(rg), _mm_cvtpd_epi32(ba)), _MM_SHUFFLE(3, 0, 1, 2));
    };
    const __m128i fill = _mm_set1_epi32(int32_t(alphaFill));
    for (; i + 4 <= count; i += 4) {
        const float* p = rgba + 4 * size_t(i);
        const __m128i lo = _mm_packs_epi32(bgra(p), bgra(p + 4)), hi = _mm_packs_epi32(bgra(p + 8), bgra(p + 12));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(words + i), _mm_or_si128(_mm_packus_epi16(lo, hi), fill));
    }
#endif
    for (; i < count; ++i) {
        const float* p = rgba + 4 * size_t(i);
        words[i] = packArgb(ps11::unorm8OfFloat(p[0]), ps11::unorm8OfFloat(p[1]), ps11::unorm8OfFloat(p[2]),
                            ps11::unorm8OfFloat(p[3])) |
                   alphaFill;
    }
}

// The Baseline level's ONE/ONE words (emu/output_merger_kernels.h): the sums a channel at a time,
// then their words.
void addUnorm8WordsBaseline(const float* const src[4], const uint8_t* words, int count, uint32_t alphaFill,
                            uint32_t* out) {
    constexpr int kStep = 64;
    constexpr int kShift[4] = {16, 8, 0, 24};  // r g b a in a b g r a word
    alignas(16) float sum[4][kStep];
    const float* const sums[4] = {sum[0], sum[1], sum[2], sum[3]};
    for (int at = 0; at < count; at += kStep) {
        const int n = std::min(kStep, count - at);
        for (int c = 0; c < 4; ++c) satAddUnorm8(src[c] + at, words + 4 * size_t(at), kShift[c], n, sum[c]);
        unorm8WordsBaseline(sums, n, alphaFill, out + at);
    }
}

void halvesBaseline(const float* const f[4], int count, uint16_t* out) {
    for (int i = 0; i < count; ++i)
        for (int c = 0; c < 4; ++c) out[4 * i + c] = halfOf(f[c][i]);
}

// Float targets without fog, tests or blending: convert and store the live lanes' channels.
void storeFloatPlain(const Plan& p, const MergeInputs& in, const float* const f[4], Counts& n) {
    const Surf cs = p.colorSurf;
    const Lanes lanes(in, p);
    const uint32_t channels = p.channels;
    const float *f0 = f[0], *f1 = f[1], *f2 = f[2], *f3 = f[3];
    const uint8_t* live = in.live;
    const bool half = p.target == TargetKind::Rgba16F;
    alignas(16) uint16_t halves[4 * ps11::kMaxSpan];
    if (half) mergerKernels(ps11::simdLevel()).halves(f, in.count, halves);
    uint64_t written = 0;
    for (int i = 0; i < in.count; ++i) {
        uint32_t x, y;
        if ((live && !live[i]) || !lanes.inside(i, x, y)) continue;
        uint8_t* q = cs.at(x, y);
        ++written;
        if (half) {
            const uint16_t* h = halves + 4 * i;
            if (channels == 0xfu) {
                std::memcpy(q, h, 8);
            } else {
                for (int c = 0; c < 4; ++c)
                    if (channels >> c & 1u) std::memcpy(q + 2 * c, &h[c], 2);
            }
        } else {
            const float v[4] = {f0[i], f1[i], f2[i], f3[i]};
            if (channels == 0xfu) {
                std::memcpy(q, v, 16);
            } else {
                for (int c = 0; c < 4; ++c)
                    if (channels >> c & 1u) std::memcpy(q + 4 * c, &v[c], 4);  // R32F: only red is enabled
            }
        }
    }
    n.written += written;
}

// Float profiles' ONE/ONE ADD into an 8-bit target, no fog or tests: mergeFloat's result. With
// both factors ONE, blendFloat's 1·(s·1) + 1·(d·1) is s + d exactly (s is saturated, d a byte's
// value: both finite), saturated and rounded as mergeFloat does.
void addUnorm8Float(const Plan& p, const MergeInputs& in, const float* const f[4], Counts& n) {
    const Lanes lanes(in, p);
    const Surf cs = p.colorSurf;
    const bool x8 = p.target == TargetKind::Xrgb8;
    const uint32_t mask = wordMask(p);
    const uint8_t* live = in.live;
    const int count = in.count;
    // The destination words of the lanes that store (0 for the others), then per channel
    // sat(s) + d in float, then the words (the merger's 8-bit words kernel), then the stores.
    alignas(32) uint32_t old[ps11::kMaxSpan];
    alignas(32) uint8_t stores[ps11::kMaxSpan];
    uint8_t* run = nullptr;  // a row path's run: its first pixel
    if (in.row && !live && count > 0) {
        uint32_t x, y;
        if (lanes.inside(0, x, y) && x + uint32_t(count) <= p.boundW) run = cs.at(x, y);
        assert(run && in.x[count - 1] == in.x[0] + count - 1 && in.y[count - 1] == in.y[0]);
    }
    // A run's destination words are read where they are (a copy first cost as much as the blend).
    const uint8_t* dst = reinterpret_cast<const uint8_t*>(old);
    if (run) {
        dst = run;
    } else {
        for (int i = 0; i < count; ++i) {
            uint32_t x, y;
            stores[i] = uint8_t((!live || live[i]) && lanes.inside(i, x, y));
            old[i] = stores[i] ? load32(cs.at(x, y)) : 0u;
        }
    }
    alignas(32) uint32_t words[ps11::kMaxSpan];
    // X8R8G8B8 reads its missing alpha as 1 and stores 0xff: the fill gives both. A run whose
    // every channel changes takes the sums in place.
    const bool inPlace = run && mask == 0xffffffffu;
    mergerKernels(ps11::simdLevel())
        .addUnorm8Words(f, dst, count, x8 ? 0xff000000u : 0u, inPlace ? reinterpret_cast<uint32_t*>(run) : words);
    if (run) {
        if (!inPlace) {
            for (int i = 0; i < count; ++i) words[i] = (words[i] & mask) | (load32(dst + 4 * i) & ~mask);
            std::memcpy(run, words, 4 * size_t(count));
        }
        n.written += uint64_t(count);
        return;
    }
    uint64_t written = 0;
    for (int i = 0; i < count; ++i) {
        if (!stores[i]) continue;
        ++written;
        const uint32_t x = uint32_t(in.x[i]), y = uint32_t(in.y[i]);
        uint32_t w = words[i];
        if (mask != 0xffffffffu) w = (w & mask) | (old[i] & ~mask);
        store32(cs.at(x, y), w);
    }
    n.written += written;
}

// Float targets with blending and no fog or tests: mergeFloat's float-target step
// (blendIntoFloatTarget) without its per-pixel branches.
void blendFloatTarget(const Plan& p, const MergeInputs& in, const float* const f[4], Counts& n) {
    const Lanes lanes(in, p);
    const Surf cs = p.colorSurf;
    ChannelPlan ch[4];
    std::copy_n(p.ch, 4, ch);
    float v[kSlots];
    v[kZero] = 0.0f, v[kOne] = 1.0f;
    for (int c = 0; c < 4; ++c) v[kBf + c] = float(p.bfByte[c]) / 255.0f;
    const uint8_t* live = in.live;
#if defined(__SSE2__)
    // A row path's run into an A32B32G32R32F target whose blend factors are constants (ZERO, ONE,
    // the blend factor: the additive passes): blendFloat's operations four channels at a time,
    // pixel by pixel along the run.
    const auto constant = [](const Factor& fa) { return fa.slot == kZero || fa.slot == kOne || fa.slot >= kBf; };
    bool constFactors = p.target == TargetKind::Rgba32F && in.row && !live && in.count > 0;
    for (int c = 0; c < 4 && constFactors; ++c)
        constFactors = ch[c].kind == OpKind::Linear && constant(ch[c].src) && constant(ch[c].dst);
    uint32_t x0 = 0, y0 = 0;
    if (constFactors && lanes.inside(0, x0, y0) && x0 + uint32_t(in.count) <= p.boundW) {
        assert(in.x[in.count - 1] == in.x[0] + in.count - 1 && in.y[in.count - 1] == in.y[0]);
        FloatBlendConsts k;
        for (int c = 0; c < 4; ++c) {
            const ChannelPlan& cp = ch[c];
            k.fs[c] = cp.src.inv ? 1.0f - v[cp.src.slot] : v[cp.src.slot];
            k.fd[c] = cp.dst.inv ? 1.0f - v[cp.dst.slot] : v[cp.dst.slot];
            k.ks[c] = float(cp.cs), k.kd[c] = float(cp.cd);
            k.zs[c] = cp.src.slot == kZero && !cp.src.inv ? ~0u : 0u;
            k.zd[c] = cp.dst.slot == kZero && !cp.dst.inv ? ~0u : 0u;
            k.on[c] = (p.channels >> c & 1u) ? ~0u : 0u;
        }
        const __m128 fsv = _mm_load_ps(k.fs), fdv = _mm_load_ps(k.fd), ksv = _mm_load_ps(k.ks), kdv = _mm_load_ps(k.kd);
        const __m128 zsv = _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(k.zs)));
        const __m128 zdv = _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(k.zd)));
        const __m128 onv = _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(k.on)));
        float* const q0 = reinterpret_cast<float*>(cs.at(x0, y0));
        const float *f0 = f[0], *f1 = f[1], *f2 = f[2], *f3 = f[3];
        const MergerKernels& kern = mergerKernels(ps11::simdLevel());
        for (int i = 0; i < in.count;) {
            // The kernel's groups, then pixel by pixel up to a group's length (a group with a
            // NaN, or the last pixels).
            i = kern.blendRgba32F(k, f, i, in.count, q0);
            for (const int stop = std::min(in.count, i + 8); i < stop; ++i) {
                float* const q = q0 + 4 * size_t(i);
                const __m128 sv = _mm_setr_ps(f0[i], f1[i], f2[i], f3[i]), dv = _mm_loadu_ps(q);
                if (_mm_movemask_ps(_mm_cmpunord_ps(sv, dv))) {  // a NaN: blendFloat's own order
                    float sc[4] = {f0[i], f1[i], f2[i], f3[i]};
                    blendIntoFloatTarget(p, ch, v, sc, reinterpret_cast<uint8_t*>(q));
                    continue;
                }
                const __m128 ts = _mm_mul_ps(ksv, _mm_mul_ps(sv, fsv)), td = _mm_mul_ps(kdv, _mm_mul_ps(dv, fdv));
                // zs: (zd ? 0 : td); else zd ? ts : ts + td.
                const __m128 a = _mm_andnot_ps(zdv, td);
                const __m128 b = _mm_or_ps(_mm_and_ps(zdv, ts), _mm_andnot_ps(zdv, _mm_add_ps(ts, td)));
                const __m128 r = _mm_or_ps(_mm_and_ps(zsv, a), _mm_andnot_ps(zsv, b));
                _mm_storeu_ps(q, _mm_or_ps(_mm_and_ps(onv, r), _mm_andnot_ps(onv, dv)));
            }
        }
        n.written += uint64_t(in.count);
        return;
    }
#endif
    uint64_t written = 0;
    for (int i = 0; i < in.count; ++i) {
        uint32_t x, y;
        if ((live && !live[i]) || !lanes.inside(i, x, y)) continue;
        ++written;
        uint8_t* q = cs.at(x, y);
        float s[4] = {f[0][i], f[1][i], f[2][i], f[3][i]};
        blendIntoFloatTarget(p, ch, v, s, q);
    }
    n.written += written;
}

// No vector groups at Baseline: blendFloatTarget blends every pixel on its own.
int blendRgba32FBaseline(const FloatBlendConsts&, const float* const[4], int from, int, float*) { return from; }

}  // namespace merger

const MergerKernels baseline::kMerger{&merger::halvesBaseline, &merger::unorm8WordsBaseline,
                                      &merger::unorm8WordsRgbaBaseline, &merger::addUnorm8WordsBaseline,
                                      &merger::blendRgba32FBaseline};

const MergerKernels& mergerKernels(ps11::SimdLevel level) {
#if defined(PS11_HAVE_AVX512)
    return *ps11::simdTable(level, &baseline::kMerger, &avx2::kMerger,
                            ps11::madeTable(level, ps11::SimdLevel::Avx512, &avx512::mergerTable));
#elif defined(PS11_HAVE_AVX2)
    return *ps11::simdTable(level, &baseline::kMerger, &avx2::kMerger);
#else
    (void)level;
    return baseline::kMerger;
#endif
}

}  // namespace emu
