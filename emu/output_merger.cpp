// The output merger (docs/output-merger.md): vertex fog, alpha test, depth test and write, alpha
// blending, colour write mask and the store into the render target, per pixel in D3D9's order.
// Per call, the render states are resolved into a plan (factor selectors, compare masks, write
// masks) so the per-pixel loops never switch on a D3DBLEND or D3DCMPFUNC value.
// This file: the plan, the 8-bit fx family and the dispatch (mergePixels); the float family is
// emu/output_merger_float.cpp.
#include "emu/output_merger.h"

#include "emu/merge_plan.h"
#include "emu/output_merger_internal.h"
#include "emu/output_merger_kernels.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <optional>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "ps11/sampler.h"

namespace emu {

namespace {

using ps11::Precision;
using namespace merger;

// ---------------------------------------------------------------------------------------------
// State sanitising (MergeState::from never fails; unknown values act as the state's default).

bool knownBlend(DWORD b) { return b >= D3DBLEND_ZERO && b <= D3DBLEND_INVBLENDFACTOR; }
bool knownOp(DWORD o) { return o >= D3DBLENDOP_ADD && o <= D3DBLENDOP_MAX; }
bool knownCmp(DWORD c) { return c >= D3DCMP_NEVER && c <= D3DCMP_ALWAYS; }

D3DBLEND blendOr(DWORD b, D3DBLEND dflt) { return knownBlend(b) ? D3DBLEND(b) : dflt; }
D3DBLENDOP opOr(DWORD o, D3DBLENDOP dflt) { return knownOp(o) ? D3DBLENDOP(o) : dflt; }
D3DCMPFUNC cmpOr(DWORD c, D3DCMPFUNC dflt) { return knownCmp(c) ? D3DCMPFUNC(c) : dflt; }

// Resolves the legacy pair factors: SRCBLEND BOTHSRCALPHA means (SRCALPHA, INVSRCALPHA) and
// BOTHINVSRCALPHA (INVSRCALPHA, SRCALPHA), overriding the destination factor (D3D9 docs, Wine).
// As a destination factor (which D3D9 does not define) each acts as the destination half of
// its pair.
void resolvePair(D3DBLEND& src, D3DBLEND& dst) {
    if (src == D3DBLEND_BOTHSRCALPHA) {
        src = D3DBLEND_SRCALPHA, dst = D3DBLEND_INVSRCALPHA;
    } else if (src == D3DBLEND_BOTHINVSRCALPHA) {
        src = D3DBLEND_INVSRCALPHA, dst = D3DBLEND_SRCALPHA;
    } else if (dst == D3DBLEND_BOTHSRCALPHA) {
        dst = D3DBLEND_INVSRCALPHA;
    } else if (dst == D3DBLEND_BOTHINVSRCALPHA) {
        dst = D3DBLEND_SRCALPHA;
    }
}

// ---------------------------------------------------------------------------------------------
// The per-call plan.

Factor factorOf(D3DBLEND b, int c) {
    switch (b) {
        case D3DBLEND_ZERO:
            return {kZero, false};
        case D3DBLEND_ONE:
            return {kOne, false};
        case D3DBLEND_SRCCOLOR:
            return {uint8_t(kSrc + c), false};
        case D3DBLEND_INVSRCCOLOR:
            return {uint8_t(kSrc + c), true};
        case D3DBLEND_SRCALPHA:
            return {uint8_t(kSrc + 3), false};
        case D3DBLEND_INVSRCALPHA:
            return {uint8_t(kSrc + 3), true};
        case D3DBLEND_DESTALPHA:
            return {uint8_t(kDst + 3), false};
        case D3DBLEND_INVDESTALPHA:
            return {uint8_t(kDst + 3), true};
        case D3DBLEND_DESTCOLOR:
            return {uint8_t(kDst + c), false};
        case D3DBLEND_INVDESTCOLOR:
            return {uint8_t(kDst + c), true};
        case D3DBLEND_SRCALPHASAT:
            return c < 3 ? Factor{kSat, false} : Factor{kOne, false};  // (f, f, f, 1)
        case D3DBLEND_BLENDFACTOR:
            return {uint8_t(kBf + c), false};
        case D3DBLEND_INVBLENDFACTOR:
            return {uint8_t(kBf + c), true};
        default:
            return {kZero, false};  // BOTH* are resolved before; unknown values sanitised
    }
}


Surf surfOf(Image* img) { return img ? Surf{img->bytes.data(), img->rowPitch, img->format->bytes} : Surf{}; }

// The store kernels' layout of a render-target format, from its row (ps11/formats.cpp): the b g
// r a bytes of a 32-bit word with alpha (Argb8) or an 8-bit pad read as 1 (Xrgb8); four halves
// (Rgba16F) or four floats (Rgba32F) r g b a one after another; one float r, the rest missing
// (R32F). None for any other layout.
std::optional<TargetKind> targetKindOf(const FormatInfo& f) {
    using ps11::ChannelKind;
    auto at = [&](size_t c, ChannelKind kind, uint32_t shift, uint32_t bits) {
        return f.rgba[c].kind == kind && f.rgba[c].shift == shift && f.rgba[c].bits == bits;
    };
    if (f.cls == FormatClass::Unorm8 && f.bytes == 4) {
        for (size_t c = 0; c < 3; ++c)
            if (!at(c, ChannelKind::Unorm, 8u * uint32_t(ps11::kUnorm8Byte[c]), 8)) return std::nullopt;
        if (at(3, ChannelKind::Unorm, 24, 8)) return TargetKind::Argb8;
        if (f.rgba[3].kind == ChannelKind::One && f.pad.shift == 24 && f.pad.bits == 8) return TargetKind::Xrgb8;
        return std::nullopt;
    }
    if (f.cls != FormatClass::Float) return std::nullopt;
    bool halves = true, floats = true;
    for (size_t c = 0; c < 4; ++c) {
        halves = halves && at(c, ChannelKind::Half, 16u * uint32_t(c), 16);
        floats = floats && at(c, ChannelKind::Float, 32u * uint32_t(c), 32);
    }
    if (halves) return TargetKind::Rgba16F;
    if (floats) return TargetKind::Rgba32F;
    bool rOnly = at(0, ChannelKind::Float, 0, 32);
    for (size_t c = 1; c < 4; ++c) rOnly = rOnly && f.rgba[c].kind == ChannelKind::One;
    if (rOnly) return TargetKind::R32F;
    return std::nullopt;
}

bool resolveTarget(const MergeTarget& t, Plan& p) {
    if (t.color) {
        const std::optional<TargetKind> kind = t.color->format ? targetKindOf(*t.color->format) : std::nullopt;
        if (!kind) return false;
        p.target = *kind;
    }
    if (t.depth) {
        const FormatInfo* f = t.depth->format;
        if (!f || f->cls != FormatClass::Depth) return false;
        p.depthKind = f->depthFloat        ? DepthKind::D32F
                      : f->depthBits == 16 ? DepthKind::D16
                      : f->depthBits == 24 ? DepthKind::D24
                                           : DepthKind::D32;
    }
    p.color = t.color;
    p.depth = t.depth;
    p.colorSurf = surfOf(t.color);
    p.depthSurf = surfOf(t.depth);
    p.boundW = p.boundH = ~0u;
    for (const Image* img : {t.color, t.depth})
        if (img) p.boundW = std::min(p.boundW, img->width), p.boundH = std::min(p.boundH, img->height);
    return true;
}

}  // namespace


Plan makePlan(const MergeState& s, const MergeTarget& t, bool& ok) {
    Plan p;
    ok = resolveTarget(t, p);
    p.precision = s.precision;
    p.alphaTest = s.alphaTest;
    p.alphaMask = cmpMask(cmpOr(s.alphaFunc, D3DCMP_ALWAYS));
    p.alphaRef = s.alphaRef & 0xffu;
    p.depthTest = s.depthTest && t.depth;
    p.depthWrite = p.depthTest && s.depthWrite;
    p.depthMask = cmpMask(cmpOr(s.depthFunc, D3DCMP_LESSEQUAL));
    p.fog = s.fog;
    for (int c = 0; c < 3; ++c) p.fogByte[c] = uint8_t(s.fogColor >> (16 - 8 * c));
    p.blend = s.blend;
    const uint8_t bf[4] = {uint8_t(s.blendFactor >> 16), uint8_t(s.blendFactor >> 8), uint8_t(s.blendFactor),
                           uint8_t(s.blendFactor >> 24)};
    std::copy_n(bf, 4, p.bfByte);

    // Which channels the target has and the mask enables.
    uint32_t channels = s.colorWrite & 0xfu;
    if (!t.color)
        channels = 0;
    else if (p.target == TargetKind::Xrgb8)
        channels &= 7u;  // no alpha channel (the X byte: see the store)
    else if (p.target == TargetKind::R32F)
        channels &= 1u;

    D3DBLEND src = blendOr(s.srcBlend, D3DBLEND_ONE), dst = blendOr(s.dstBlend, D3DBLEND_ZERO);
    resolvePair(src, dst);
    const D3DBLENDOP op = opOr(s.blendOp, D3DBLENDOP_ADD);
    D3DBLEND srcA = src, dstA = dst;
    D3DBLENDOP opA = op;
    if (s.separateAlpha) {
        srcA = blendOr(s.srcBlendAlpha, D3DBLEND_ONE), dstA = blendOr(s.dstBlendAlpha, D3DBLEND_ZERO);
        resolvePair(srcA, dstA);
        opA = opOr(s.blendOpAlpha, D3DBLENDOP_ADD);
    }
    for (int c = 0; c < 4; ++c) {
        const D3DBLEND fs = c < 3 ? src : srcA, fd = c < 3 ? dst : dstA;
        const D3DBLENDOP o = c < 3 ? op : opA;
        ChannelPlan& cp = p.ch[c];
        cp.src = factorOf(fs, c);
        cp.dst = factorOf(fd, c);
        cp.kind = o == D3DBLENDOP_MIN ? OpKind::Min : o == D3DBLENDOP_MAX ? OpKind::Max : OpKind::Linear;
        cp.cs = o == D3DBLENDOP_REVSUBTRACT ? -1 : 1;
        cp.cd = o == D3DBLENDOP_SUBTRACT ? -1 : 1;
        // A channel blended as 0 * src + 1 * dst (ADD or REVSUBTRACT) keeps the target: leave it
        // unwritten, so skipping such a draw (writesNothing) changes nothing either.
        if (p.blend && cp.kind == OpKind::Linear && fs == D3DBLEND_ZERO && fd == D3DBLEND_ONE && cp.cd == 1)
            channels &= ~(1u << c);
    }
    p.channels = channels;
    return p;
}

namespace {
// ---------------------------------------------------------------------------------------------
// 8-bit targets in fx profiles: integer arithmetic on the grid G (255 or 4080).

template <int32_t G>
struct Fx {
    static constexpr int32_t S = G / 255;  // grid steps per 8-bit level (1 or 16)
    // The stored byte of a saturated grid value (fx8: n; fx12: round_half_even(n / 16)).
    // n in [0, G].
    static uint32_t byteOf(int32_t n) {
        if constexpr (G == 255)
            return uint32_t(n);
        else
            return unorm8OfFx12(n);
    }
    // round_half_even(num * 255 / G^2) for num in [-G^2, 2 G^2] clamped to [0, G^2] first
    // (fx8: num / 255; fx12: num / 65280); 2 G^2 < 2^31.
    static uint32_t blendByte(int32_t num) {
        num = num < 0 ? 0 : num > G * G ? G * G : num;
        if constexpr (G == 255)
            return uint32_t(num + 127) / 255u;  // 255 is odd: no ties
        else {
            constexpr uint32_t D = uint32_t(G) * G / 255;  // 65280
            const uint32_t u = uint32_t(num), q = u / D, r = u - q * D;
            return q + ((2 * r > D || (2 * r == D && (q & 1u))) ? 1u : 0u);
        }
    }
    // The fog factor on the grid: round_half_even(f * G) (f * G is exact in double).
    static int32_t fogGrid(float f) { return int32_t(ps11::roundEvenSmall(double(f) * G)); }
};

// Bytewise min(a + b, 255) of two words (SWAR): the sum of the low 7 bits, the top bits added
// without carries, and every byte whose carry left bit 7 forced to 0xff.
inline uint32_t addSaturateBytes(uint32_t a, uint32_t b) {
    const uint32_t low = (a & 0x7f7f7f7fu) + (b & 0x7f7f7f7fu);
    const uint32_t sum = low ^ ((a ^ b) & 0x80808080u);
    const uint32_t carry = ((a & b) | ((a | b) & ~sum)) & 0x80808080u;
    return sum | ((carry >> 7) * 0xffu);
}

// The common case: no fog, no tests, no blending, an 8-bit target. Two passes: the words of all
// lanes (a loop the compiler vectorises), then the stores of the live lanes. `additive`: fx8
// ONE/ONE ADD blending, whose exact result (s·255 + d·255)/255 = s + d clamped to 255 is a
// bytewise saturating add.
template <bool Additive>
void storeUnorm8Plain(const Plan& p, const MergeInputs& in, const int32_t* const g[4], const float* const f[4],
                      Counts& n) {
    const uint32_t mask = wordMask(p);
    const uint32_t alphaFill = p.target == TargetKind::Xrgb8 ? 0xff000000u : 0u;
    const int count = in.count;
    alignas(32) uint32_t words[ps11::kMaxSpan];
    if (p.precision == Precision::Fx8) {
        const int32_t *g0 = g[0], *g1 = g[1], *g2 = g[2], *g3 = g[3];
        const auto clamp = [](int32_t v) { return uint32_t(v < 0 ? 0 : v > 255 ? 255 : v); };
        for (int i = 0; i < count; ++i)
            words[i] = packArgb(clamp(g0[i]), clamp(g1[i]), clamp(g2[i]), clamp(g3[i])) | alphaFill;
    } else if (p.precision == Precision::Fx12) {
        const int32_t *g0 = g[0], *g1 = g[1], *g2 = g[2], *g3 = g[3];
        const auto b = [](int32_t v) { return Fx<4080>::byteOf(v < 0 ? 0 : v > 4080 ? 4080 : v); };
        for (int i = 0; i < count; ++i) words[i] = packArgb(b(g0[i]), b(g1[i]), b(g2[i]), b(g3[i])) | alphaFill;
    }
    const Surf cs = p.colorSurf;
    const Lanes lanes(in, p);
    const uint8_t* live = in.live;
    // One run of a row (its first pixel, or null): the words straight into it.
    uint8_t* run = nullptr;
    if (in.row && !live && count > 0) {
        uint32_t x, y;
        const bool inside = lanes.inside(0, x, y) && x + uint32_t(count) <= p.boundW;
        assert(inside && in.x[count - 1] == in.x[0] + count - 1 && in.y[count - 1] == in.y[0]);
        if (inside) run = cs.at(x, y);
    }
    if (!ps11::isFixedPoint(p.precision)) {
        // (The float profiles' words go into the run themselves where nothing else is kept.)
        const bool straight = run && !Additive && mask == 0xffffffffu;
        mergerKernels(ps11::simdLevel())
            .unorm8Words(f, count, alphaFill, straight ? reinterpret_cast<uint32_t*>(run) : words);
        if (straight) {
            n.written += uint64_t(count);
            return;
        }
    }
    if (run) {
        uint8_t* q = run;
        if (!Additive && mask == 0xffffffffu) {
            std::memcpy(q, words, 4 * size_t(count));
        } else {
            for (int i = 0; i < count; ++i, q += 4) {
                uint32_t w = words[i];
                const uint32_t old = load32(q);
                if constexpr (Additive) w = addSaturateBytes(w, old);
                store32(q, (w & mask) | (old & ~mask));
            }
        }
        n.written += uint64_t(count);
        return;
    }
    uint64_t written = 0;
    for (int i = 0; i < count; ++i) {
        uint32_t x, y;
        if ((live && !live[i]) || !lanes.inside(i, x, y)) continue;
        uint8_t* q = cs.at(x, y);
        uint32_t w = words[i];
        if constexpr (Additive) {
            const uint32_t old = load32(q);
            w = addSaturateBytes(w, old);
            if (mask != 0xffffffffu) w = (w & mask) | (old & ~mask);
        } else if (mask != 0xffffffffu) {
            w = (w & mask) | (load32(q) & ~mask);
        }
        store32(q, w);
        ++written;
    }
    n.written += written;
}

// Blending without fog or tests into an 8-bit target in an fx profile (the post-processing
// case: additive or alpha-blended passes). Structure of arrays over the live lanes: gather the
// destination texels, then per channel one loop whose factor is base + sign * array[k], with
// base, sign and array chosen per call — no per-pixel decision at all.
template <int32_t G>
void blendFxUnorm8Simple(const Plan& p, const MergeInputs& in, const int32_t* const g[4], Counts& n) {
    constexpr int kN = ps11::kMaxSpan;
    constexpr int32_t S = G / 255;
    const bool x8 = p.target == TargetKind::Xrgb8;
    const Surf cs = p.colorSurf;
    const Lanes lanes(in, p);
    alignas(32) int32_t src[4][kN], dst[4][kN], sat[kN];
    alignas(32) uint32_t word[kN];
    uint8_t* addr[kN];
    // One run of a row (the row paths' spans, every lane live): its words are loaded and stored
    // in place, in loops the compiler vectorises; otherwise the live lanes are gathered.
    uint8_t* run = nullptr;
    if (in.row && !in.live && in.count > 0) {
        uint32_t x, y;
        if (lanes.inside(0, x, y) && x + uint32_t(in.count) <= p.boundW) {
            assert(in.x[in.count - 1] == in.x[0] + in.count - 1 && in.y[in.count - 1] == in.y[0]);
            run = cs.at(x, y);
        }
    }
    int m = 0;
    if (run) {
        m = in.count;
        for (int k = 0; k < m; ++k) word[k] = load32(run + 4 * size_t(k));
        for (int c = 0; c < 4; ++c)
            for (int k = 0; k < m; ++k) src[c][k] = std::clamp(g[c][k], 0, G);
    } else {
        for (int i = 0; i < in.count; ++i) {
            uint32_t x, y;
            if ((in.live && !in.live[i]) || !lanes.inside(i, x, y)) continue;
            uint8_t* q = cs.at(x, y);
            addr[m] = q;
            word[m] = load32(q);
            for (int c = 0; c < 4; ++c) src[c][m] = std::clamp(g[c][i], 0, G);  // the 8-bit target saturates
            ++m;
        }
    }
    for (int k = 0; k < m; ++k) {
        const uint32_t old = word[k];
        dst[0][k] = int32_t((old >> 16) & 0xffu) * S;
        dst[1][k] = int32_t((old >> 8) & 0xffu) * S;
        dst[2][k] = int32_t(old & 0xffu) * S;
        dst[3][k] = x8 ? G : int32_t(old >> 24) * S;  // X8R8G8B8's alpha reads 1
    }
    for (int k = 0; k < m; ++k) sat[k] = std::min(src[3][k], G - dst[3][k]);
    // A factor as base + sign * array[k].
    // A factor as base + (array[k] negated when neg = -1): (v ^ neg) - neg is v or -v, so the
    // loop multiplies only s * Fs and d * Fd. Constant factors read an array of zeros.
    static const int32_t kZeros[kN] = {};
    struct Term {
        int32_t base, neg;
        const int32_t* arr;
    };
    const auto term = [&](Factor f) -> Term {
        if (f.slot == kZero || f.slot == kOne || f.slot >= kBf) {
            const int32_t value = f.slot == kZero ? 0 : f.slot == kOne ? G : int32_t(p.bfByte[f.slot - kBf]) * S;
            return Term{f.inv ? G - value : value, 0, kZeros};
        }
        const int32_t* arr = f.slot == kSat ? sat : f.slot >= kDst ? dst[f.slot - kDst] : src[f.slot - kSrc];
        return Term{f.inv ? G : 0, f.inv ? -1 : 0, arr};
    };
    alignas(32) uint32_t out[4][kN];
    for (int c = 0; c < 4; ++c) {
        const ChannelPlan cp = p.ch[c];
        const int32_t* sc = src[c];
        const int32_t* dc = dst[c];
        uint32_t* o = out[c];
        if (cp.kind == OpKind::Min) {
            for (int k = 0; k < m; ++k) o[k] = Fx<G>::byteOf(std::min(sc[k], dc[k]));
        } else if (cp.kind == OpKind::Max) {
            for (int k = 0; k < m; ++k) o[k] = Fx<G>::byteOf(std::max(sc[k], dc[k]));
        } else {
            const Term ts = term(cp.src), td = term(cp.dst);
            const int32_t ns = cp.cs < 0 ? -1 : 0, nd = cp.cd < 0 ? -1 : 0;  // SUBTRACT / REVSUBTRACT
            if (ts.arr == kZeros && td.arr == kZeros && (ts.base == 0 || ts.base == G) &&
                (td.base == 0 || td.base == G)) {
                // Factors ZERO or ONE (ONE/ONE ADD, the additive passes): num = G·t with t = ±s ± d,
                // so round_half_even(num·255/G²) = round_half_even(t·255/G), the byte of t.
                // ±s and ±d by masks (no multiply): the term is 0 (ZERO), v or −v.
                const int32_t ks = ts.base == 0 ? 0 : -1, kd = td.base == 0 ? 0 : -1;
                for (int k = 0; k < m; ++k) {
                    const int32_t t = (((sc[k] & ks) ^ ns) - ns) + (((dc[k] & kd) ^ nd) - nd);
                    o[k] = Fx<G>::byteOf(t < 0 ? 0 : t > G ? G : t);
                }
                continue;
            }
            for (int k = 0; k < m; ++k) {
                const int32_t fs = ts.base + ((ts.arr[k] ^ ts.neg) - ts.neg);
                const int32_t fd = td.base + ((td.arr[k] ^ td.neg) - td.neg);
                const int32_t ps = sc[k] * fs, pd = dc[k] * fd;
                int32_t num = ((ps ^ ns) - ns) + ((pd ^ nd) - nd);
                num = num < 0 ? 0 : num > G * G ? G * G : num;
                if constexpr (G == 255) {
                    const int32_t y = num + 127;               // round(num / 255) = floor((num + 127) / 255), no ties
                    o[k] = uint32_t((y + 1 + (y >> 8)) >> 8);  // floor(y / 255) for y < 65535
                } else {
                    o[k] = Fx<G>::blendByte(num);
                }
            }
        }
    }
    const uint32_t mask = wordMask(p);
    const uint32_t alphaFill = x8 ? 0xff000000u : 0u;
    for (int k = 0; k < m; ++k) {
        uint32_t w = packArgb(out[0][k], out[1][k], out[2][k], out[3][k]) | alphaFill;
        word[k] = (w & mask) | (word[k] & ~mask);
    }
    if (run)
        std::memcpy(run, word, 4 * size_t(m));
    else
        for (int k = 0; k < m; ++k) store32(addr[k], word[k]);
    n.written += uint64_t(m);
}

template <int32_t G>
void mergeFxUnorm8(const Plan& p, const MergeInputs& in, const int32_t* const g[4], Counts& n) {
    using F = Fx<G>;
    const uint32_t mask = wordMask(p);
    const bool x8 = p.target == TargetKind::Xrgb8;
    const Lanes lanes(in, p);
    const Surf cs = p.colorSurf;
    const DepthCtx dc = depthCtxOf(p);
    const DepthCtx* depth = p.depthTest ? &dc : nullptr;
    const bool fog = p.fog, alphaTest = p.alphaTest, blend = p.blend, hasColor = p.color != nullptr;
    const uint32_t alphaMask = p.alphaMask, alphaRef = p.alphaRef;
    ChannelPlan ch[4];
    std::copy_n(p.ch, 4, ch);
    int32_t v[kSlots];
    v[kZero] = 0, v[kOne] = G;
    for (int c = 0; c < 4; ++c) v[kBf + c] = int32_t(p.bfByte[c]) * F::S;
    int32_t fogG[3];
    for (int c = 0; c < 3; ++c) fogG[c] = int32_t(p.fogByte[c]) * F::S;
    for (int i = 0; i < in.count; ++i) {
        if (in.live && !in.live[i]) continue;
        uint32_t x, y;
        if (!lanes.inside(i, x, y)) continue;
        int32_t s[4];
        for (int c = 0; c < 4; ++c) s[c] = std::clamp(g[c][i], 0, G);  // the 8-bit target saturates
        if (fog) {
            // colour = f * colour + (1 - f) * FOGCOLOR, exact on the grid, rounded once.
            const int32_t fq = F::fogGrid(lanes.fog(i));
            for (int c = 0; c < 3; ++c) s[c] = divRoundEven<G>(int64_t(fq) * s[c] + int64_t(G - fq) * fogG[c]);
        }
        const bool alphaPass = !alphaTest || cmpPass(alphaMask, F::byteOf(s[3]), alphaRef);
        if (!tests(depth, alphaPass, x, y, lanes.z(i), n) || !hasColor) continue;
        uint8_t* q = cs.at(x, y);
        uint32_t out[4];
        if (!blend) {
            for (int c = 0; c < 4; ++c) out[c] = F::byteOf(s[c]);
        } else {
            const uint32_t old = load32(q);
            for (int c = 0; c < 4; ++c) v[kSrc + c] = s[c];
            v[kDst + 0] = int32_t((old >> 16) & 0xffu) * F::S;
            v[kDst + 1] = int32_t((old >> 8) & 0xffu) * F::S;
            v[kDst + 2] = int32_t(old & 0xffu) * F::S;
            v[kDst + 3] = x8 ? G : int32_t(old >> 24) * F::S;  // X8R8G8B8's alpha reads 1
            v[kSat] = std::min(s[3], G - v[kDst + 3]);
            for (int c = 0; c < 4; ++c) {
                const ChannelPlan& cp = ch[c];
                const int32_t d = v[kDst + c];
                if (cp.kind == OpKind::Linear) {
                    const int32_t fs = cp.src.inv ? G - v[cp.src.slot] : v[cp.src.slot];
                    const int32_t fd = cp.dst.inv ? G - v[cp.dst.slot] : v[cp.dst.slot];
                    out[c] = F::blendByte(cp.cs * s[c] * fs + cp.cd * d * fd);
                } else {
                    out[c] = F::byteOf(cp.kind == OpKind::Min ? std::min(s[c], d) : std::max(s[c], d));
                }
            }
        }
        uint32_t w = packArgb(out[0], out[1], out[2], x8 ? 0xffu : out[3]);
        if (mask != 0xffffffffu) w = (w & mask) | (load32(q) & ~mask);
        store32(q, w);
    }
}

// Vertex fog of fx profiles into 8-bit targets for every lane at once, as mergeFxUnorm8 applies
// it pixel by pixel: rgb = f·s + (1 − f)·FOGCOLOR on the grid of the saturated colour, rounded
// once (every product and sum fits 32 bits: at most G² = 4080²), alpha as it is.
template <int32_t G>
void fogFxUnorm8(const Plan& p, const MergeInputs& in, const int32_t* const g[4], int32_t (*out)[ps11::kMaxSpan]) {
    using F = Fx<G>;
    const Lanes lanes(in, p);
    int first = 0;
#if defined(__SSE2__)
    if constexpr (G == 255) {
        // Eight lanes a step in 16 bits: the fog factor's byte (the exact f·255 in double,
        // converted to nearest even), the saturated s, and num = fq·s + (255 − fq)·FOG, which is
        // at most 255² and fits unsigned 16 bits; num / 255 as (num + 1 + (num >> 8)) >> 8
        // (exact below 65535) and one more where the remainder passes 127 (255 is odd: no ties).
        const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
        const __m128d k255 = _mm_set1_pd(255.0);
        const __m128i i255 = _mm_set1_epi16(255), i127 = _mm_set1_epi16(127), i1 = _mm_set1_epi16(1),
                      izero = _mm_setzero_si128();
        const auto bytes4 = [&](__m128 f) {
            const __m128 v = _mm_and_ps(_mm_cmpgt_ps(f, zero), _mm_min_ps(f, one));  // sat, NaN -> 0
            const __m128i lo = _mm_cvtpd_epi32(_mm_mul_pd(_mm_cvtps_pd(v), k255));
            const __m128i hi = _mm_cvtpd_epi32(_mm_mul_pd(_mm_cvtps_pd(_mm_movehl_ps(v, v)), k255));
            return _mm_unpacklo_epi64(lo, hi);
        };
        for (; first + 8 <= in.count; first += 8) {
            const int i = first;
            const __m128 f0 = in.fog ? _mm_loadu_ps(in.fog + i) : one, f1 = in.fog ? _mm_loadu_ps(in.fog + i + 4) : one;
            const __m128i fq = _mm_packs_epi32(bytes4(f0), bytes4(f1));
            const __m128i rest = _mm_sub_epi16(i255, fq);
            for (int c = 0; c < 3; ++c) {
                const __m128i s = _mm_min_epi16(
                    _mm_max_epi16(_mm_packs_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(g[c] + i)),
                                                  _mm_loadu_si128(reinterpret_cast<const __m128i*>(g[c] + i + 4))),
                                  izero),
                    i255);
                const __m128i num =
                    _mm_add_epi16(_mm_mullo_epi16(fq, s), _mm_mullo_epi16(rest, _mm_set1_epi16(int16_t(p.fogByte[c]))));
                const __m128i q = _mm_srli_epi16(_mm_add_epi16(_mm_add_epi16(num, i1), _mm_srli_epi16(num, 8)), 8);
                const __m128i r = _mm_sub_epi16(num, _mm_mullo_epi16(q, i255));
                const __m128i res = _mm_sub_epi16(q, _mm_cmpgt_epi16(r, i127));
                _mm_storeu_si128(reinterpret_cast<__m128i*>(out[c] + i), _mm_unpacklo_epi16(res, izero));
                _mm_storeu_si128(reinterpret_cast<__m128i*>(out[c] + i + 4), _mm_unpackhi_epi16(res, izero));
            }
        }
    }
#endif
    alignas(32) int32_t fq[ps11::kMaxSpan];
    for (int i = first; i < in.count; ++i) fq[i] = F::fogGrid(lanes.fog(i));
    for (int c = 0; c < 3; ++c) {
        const int32_t fogG = int32_t(p.fogByte[c]) * F::S;
        const int32_t* src = g[c];
        int32_t* dst = out[c];
        for (int i = first; i < in.count; ++i) {
            const int32_t s = std::clamp(src[i], 0, G);
            const uint32_t num = uint32_t(fq[i] * s + (G - fq[i]) * fogG), q = num / uint32_t(G), r = num - q * G;
            dst[i] = int32_t(q + ((2 * r > uint32_t(G) || (2 * r == uint32_t(G) && (q & 1u))) ? 1u : 0u));
        }
    }
}

// The depth test (and write where it passes) of the live lanes, as the per-pixel merges make it
// when no alpha test comes first: live[i] says which lanes go on to the colour stages. True when
// every lane was live and passed.
bool depthFirst(const Plan& p, const MergeInputs& in, uint8_t* live, Counts& n) {
    const Lanes lanes(in, p);
    const DepthCtx dc = depthCtxOf(p);
    bool all = true;
    uint32_t x0 = 0, y0 = 0;
    if (dc.kind == DepthKind::D24 && in.row && !in.live && in.count > 0 && lanes.inside(0, x0, y0) &&
        x0 + uint32_t(in.count) <= p.boundW) {
        // One run of a row into a 24-bit depth buffer: depthStage lane by lane without its
        // switch and branches (the code, at most 2^24 − 1, converts as an int32).
        uint8_t* const q = dc.surf.at(x0, y0);
        const uint32_t lt = dc.mask & 1u, eq = (dc.mask >> 1) & 1u, gt = (dc.mask >> 2) & 1u;
        const uint32_t keep = dc.write ? 0xffu : 0xffffffffu;
        uint32_t passed = 0;
        for (int i = 0; i < in.count; ++i) {
            const float zIn = in.z ? in.z[i] : 0.0f;
            const float z = zIn > 0.0f ? (zIn < 1.0f ? zIn : 1.0f) : 0.0f;  // NaN -> 0
            const uint32_t code = uint32_t(int32_t(ps11::roundEvenSmall(double(z) * 16777215.0)));
            const uint32_t old = load32(q + 4 * size_t(i)), d = old >> 8;
            const uint32_t pass = code < d ? lt : code == d ? eq : gt;
            live[i] = uint8_t(pass);
            passed += pass;
            const uint32_t moved = (old & keep) | (dc.write ? code << 8 : 0u);
            store32(q + 4 * size_t(i), pass ? moved : old);
        }
        n.depthRejected += uint64_t(in.count) - passed;
        return passed == uint32_t(in.count);
    }
    for (int i = 0; i < in.count; ++i) {
        uint32_t x, y;
        bool go = (!in.live || in.live[i]) && lanes.inside(i, x, y);
        if (go && !depthStage(dc, x, y, lanes.z(i))) go = false, ++n.depthRejected;
        live[i] = uint8_t(go);
        all = all && go;
    }
    return all;
}

[[maybe_unused]] bool supportedColor(const Image* img) { return img && img->format && img->format->renderTarget; }

}  // namespace

// ---------------------------------------------------------------------------------------------

MergeState MergeState::from(const DeviceState& st, bool hasDepth, ps11::Precision precision) {
    MergeState m;
    const auto rs = [&](D3DRENDERSTATETYPE s) { return st.renderState(s); };
    m.alphaTest = rs(D3DRS_ALPHATESTENABLE) != 0;
    m.alphaFunc = cmpOr(rs(D3DRS_ALPHAFUNC), D3DCMP_ALWAYS);
    m.alphaRef = rs(D3DRS_ALPHAREF) & 0xffu;                     // D3D9 takes 0x00..0xff; the low byte
    m.depthTest = hasDepth && rs(D3DRS_ZENABLE) != D3DZB_FALSE;  // USEW acts as TRUE
    m.depthWrite = m.depthTest && rs(D3DRS_ZWRITEENABLE) != 0;   // ZENABLE FALSE: no depth writes either
    m.depthFunc = cmpOr(rs(D3DRS_ZFUNC), D3DCMP_LESSEQUAL);
    m.fog = rs(D3DRS_FOGENABLE) != 0 && rs(D3DRS_FOGTABLEMODE) == D3DFOG_NONE;
    m.fogColor = rs(D3DRS_FOGCOLOR);
    m.blend = rs(D3DRS_ALPHABLENDENABLE) != 0;
    m.srcBlend = blendOr(rs(D3DRS_SRCBLEND), D3DBLEND_ONE);
    m.dstBlend = blendOr(rs(D3DRS_DESTBLEND), D3DBLEND_ZERO);
    m.blendOp = opOr(rs(D3DRS_BLENDOP), D3DBLENDOP_ADD);
    m.separateAlpha = rs(D3DRS_SEPARATEALPHABLENDENABLE) != 0;
    m.srcBlendAlpha = blendOr(rs(D3DRS_SRCBLENDALPHA), D3DBLEND_ONE);
    m.dstBlendAlpha = blendOr(rs(D3DRS_DESTBLENDALPHA), D3DBLEND_ZERO);
    m.blendOpAlpha = opOr(rs(D3DRS_BLENDOPALPHA), D3DBLENDOP_ADD);
    m.blendFactor = rs(D3DRS_BLENDFACTOR);
    m.colorWrite = rs(D3DRS_COLORWRITEENABLE) & 0xfu;
    m.precision = precision;
    return m;
}

bool MergeState::writesNothing() const {
    if (alphaTest && cmpOr(alphaFunc, D3DCMP_ALWAYS) == D3DCMP_NEVER) return true;
    if (depthTest && cmpOr(depthFunc, D3DCMP_LESSEQUAL) == D3DCMP_NEVER) return true;
    if (depthWrite) return false;
    // The colour channels that change: makePlan drops disabled ones and those blended as
    // 0 * src + 1 * dst. An A8R8G8B8 target stands for "every channel present".
    Image probe;
    static const FormatInfo* argb = formatInfo(D3DFMT_A8R8G8B8);
    probe.format = argb;
    bool ok = false;
    const Plan p = makePlan(*this, MergeTarget{&probe, nullptr}, ok);
    return p.channels == 0;
}

std::optional<CallError> mergeStateError(const DeviceState& st) {
    const auto rs = [&](D3DRENDERSTATETYPE s) { return st.renderState(s); };
    const auto bad = [&](const char* state, DWORD value, const char* what) {
        return CallError{D3DERR_INVALIDCALL, "E4160",
                         std::string(state) + " " + std::to_string(value) + " is not a " + what + " value"};
    };
    if (rs(D3DRS_ALPHATESTENABLE) && !knownCmp(rs(D3DRS_ALPHAFUNC)))
        return bad("D3DRS_ALPHAFUNC", rs(D3DRS_ALPHAFUNC), "D3DCMPFUNC");
    if (rs(D3DRS_ZENABLE) != D3DZB_FALSE && !knownCmp(rs(D3DRS_ZFUNC)))
        return bad("D3DRS_ZFUNC", rs(D3DRS_ZFUNC), "D3DCMPFUNC");
    if (rs(D3DRS_ALPHABLENDENABLE)) {
        if (!knownBlend(rs(D3DRS_SRCBLEND))) return bad("D3DRS_SRCBLEND", rs(D3DRS_SRCBLEND), "D3DBLEND");
        if (!knownBlend(rs(D3DRS_DESTBLEND))) return bad("D3DRS_DESTBLEND", rs(D3DRS_DESTBLEND), "D3DBLEND");
        if (!knownOp(rs(D3DRS_BLENDOP))) return bad("D3DRS_BLENDOP", rs(D3DRS_BLENDOP), "D3DBLENDOP");
        if (rs(D3DRS_SEPARATEALPHABLENDENABLE)) {
            if (!knownBlend(rs(D3DRS_SRCBLENDALPHA)))
                return bad("D3DRS_SRCBLENDALPHA", rs(D3DRS_SRCBLENDALPHA), "D3DBLEND");
            if (!knownBlend(rs(D3DRS_DESTBLENDALPHA)))
                return bad("D3DRS_DESTBLENDALPHA", rs(D3DRS_DESTBLENDALPHA), "D3DBLEND");
            if (!knownOp(rs(D3DRS_BLENDOPALPHA)))
                return bad("D3DRS_BLENDOPALPHA", rs(D3DRS_BLENDOPALPHA), "D3DBLENDOP");
        }
    }
    return std::nullopt;
}

bool mergeReadsColor(ps11::Precision precision, const MergeTarget& target) {
    if (!ps11::isFixedPoint(precision) || !target.color) return !ps11::isFixedPoint(precision);
    Plan p;
    return !resolveTarget(target, p) || (p.target != TargetKind::Argb8 && p.target != TargetKind::Xrgb8);
}

bool depthTestFirst(const MergeState& state, const MergeInputs& in, const MergeTarget& target, uint8_t* passed,
                    MergeStats* stats) {
    assert(state.depthTest && !state.alphaTest && target.depth && in.count <= ps11::kMaxSpan);
    bool ok = false;
    const Plan p = makePlan(state, target, ok);
    if (!ok || !p.depthTest || p.alphaTest || in.count <= 0) {
        std::fill_n(passed, std::max(in.count, 0), uint8_t(0));
        return false;
    }
    Counts n;
    const bool all = depthFirst(p, in, passed, n);
    if (stats) stats->depthRejected += n.depthRejected;
    return all;
}

void fogGridFirst(const MergeState& state, const MergeInputs& in, const MergeTarget& target,
                  int32_t (*grid)[ps11::kMaxSpan]) {
    assert(state.fog && ps11::isFixedPoint(state.precision) && in.count <= ps11::kMaxSpan);
    bool ok = false;
    const Plan p = makePlan(state, target, ok);
    if (!ok || in.count <= 0) return;
    const int32_t* const g[4] = {grid[0], grid[1], grid[2], grid[3]};
    if (state.precision == Precision::Fx8)
        fogFxUnorm8<255>(p, in, g, grid);
    else
        fogFxUnorm8<4080>(p, in, g, grid);
}

void mergePixels(const MergeState& state, const MergeInputs& in, const MergeTarget& target, MergeStats* stats) {
    // A colour target of another format, or a depth target of a non-depth format, is the
    // caller's programming error: asserted, and in release builds nothing is written.
    assert(!target.color || supportedColor(target.color));
    bool ok = false;
    const Plan p = makePlan(state, target, ok);
    assert(ok);
    if (ok) mergePixels(p, state, in, stats);
}

void mergePixels(const Plan& plan, const MergeState& state, const MergeInputs& in, MergeStats* stats) {
    Plan p = plan;  // (the merges below drop the stages they take first)
    if (in.count <= 0 || (!p.color && !p.depth)) return;
    assert(in.count <= ps11::kMaxSpan && in.x && in.y);
    const int count = std::min(in.count, int(ps11::kMaxSpan));
    MergeInputs lanes = in;
    lanes.count = count;

    // Missing channels read as 0; fx profiles without grid values take them from color.
    static const float zeros[ps11::kMaxSpan] = {};
    const bool fx = ps11::isFixedPoint(state.precision);
    const int32_t G = ps11::gridScale(state.precision);
    int32_t gridBuf[4][ps11::kMaxSpan];
    const int32_t* grid[4];
    const float* color[4];
    for (int c = 0; c < 4; ++c) {
        color[c] = in.color[c] ? in.color[c] : zeros;
        grid[c] = in.grid[c];
        if (fx && !grid[c]) {
            for (int i = 0; i < count; ++i) gridBuf[c][i] = ps11::toGrid(double(color[c][i]), state.precision);
            grid[c] = gridBuf[c];
        }
    }

    Counts n;
    const bool unorm = p.color && (p.target == TargetKind::Argb8 || p.target == TargetKind::Xrgb8);
    // Stages that can go first over every lane, so that the rest takes the merges without them:
    // a depth test with no alpha test before it, and fx profiles' fog into 8-bit targets.
    alignas(32) uint8_t passed[ps11::kMaxSpan];
    if (p.depthTest && !p.alphaTest) {
        // (Every lane passing keeps a row's run whole: the merges store it at once.)
        if (!depthFirst(p, lanes, passed, n)) lanes.live = passed;
        p.depthTest = false;
        if (!p.color) {
            for (int i = 0; i < count; ++i) n.written += passed[i];  // (the per-pixel merges count them so)
            if (stats) stats->written += n.written, stats->depthRejected += n.depthRejected;
            return;
        }
    }
    alignas(32) int32_t fogged[3][ps11::kMaxSpan];
    if (unorm && fx && p.fog) {
        if (state.precision == Precision::Fx8)
            fogFxUnorm8<255>(p, lanes, grid, fogged);
        else
            fogFxUnorm8<4080>(p, lanes, grid, fogged);
        for (int c = 0; c < 3; ++c) grid[c] = fogged[c];
        p.fog = false;
    }
    // ONE/ONE ADD on every channel (additive passes); fx8's has an exact byte path.
    bool oneOneAdd = p.blend;
    for (const ChannelPlan& cp : p.ch)
        oneOneAdd = oneOneAdd && cp.kind == OpKind::Linear && cp.cs == 1 && cp.cd == 1 && cp.src.slot == kOne &&
                    !cp.src.inv && cp.dst.slot == kOne && !cp.dst.inv;
    const bool additive = oneOneAdd && state.precision == Precision::Fx8;
    if (unorm && !p.fog && !p.alphaTest && !p.depthTest && (!p.blend || additive) && p.channels) {
        if (additive)
            storeUnorm8Plain<true>(p, lanes, grid, color, n);
        else
            storeUnorm8Plain<false>(p, lanes, grid, color, n);
    } else if (unorm && fx && !p.fog && !p.alphaTest && !p.depthTest && p.channels) {
        if (state.precision == Precision::Fx8)
            blendFxUnorm8Simple<255>(p, lanes, grid, n);
        else
            blendFxUnorm8Simple<4080>(p, lanes, grid, n);
    } else if (unorm && !fx && oneOneAdd && !p.fog && !p.alphaTest && !p.depthTest) {
        addUnorm8Float(p, lanes, color, n);
    } else if (!p.color || unorm) {
        if (state.precision == Precision::Fx8) {
            mergeFxUnorm8<255>(p, lanes, grid, n);
        } else if (state.precision == Precision::Fx12) {
            mergeFxUnorm8<4080>(p, lanes, grid, n);
        } else {
            mergeFloat(p, lanes, FloatSource{color, grid, G}, n);
        }
    } else if (!p.fog && !p.alphaTest && !p.depthTest && !p.blend) {
        storeFloatPlain(p, lanes, color, n);
    } else if (!fx && p.color && !p.fog && !p.alphaTest && !p.depthTest) {
        blendFloatTarget(p, lanes, color, n);
    } else {
        mergeFloat(p, lanes, FloatSource{color, grid, G}, n);
    }
    if (stats) {
        stats->written += n.written;
        stats->alphaRejected += n.alphaRejected;
        stats->depthRejected += n.depthRejected;
    }
}

}  // namespace emu
