// The output merger (docs/output-merger.md): vertex fog, alpha test, depth test and write, alpha
// blending, colour write mask and the store into the render target, per pixel in D3D9's order.
// Per call, the render states are resolved into a plan (factor selectors, compare masks, write
// masks) so the per-pixel loops never switch on a D3DBLEND or D3DCMPFUNC value.
#include "emu/output_merger.h"

#include "emu/merge_plan.h"
#include "emu/output_merger_kernels.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cstring>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "ps11/sampler.h"

namespace emu {

namespace {

using ps11::Precision;

// ---------------------------------------------------------------------------------------------
// Small exact helpers.

// round_half_even(num / den) for num >= 0, den > 0 a compile-time constant.
template <int64_t Den>
inline int32_t divRoundEven(int64_t num) {
    const int64_t q = num / Den, r = num % Den;
    return int32_t(q + ((2 * r > Den || (2 * r == Den && (q & 1))) ? 1 : 0));
}

// Saturate to [0, 1]; NaN becomes 0.
inline float sat(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }

// float(b) / 255.0f for every byte b (a destination byte as the float blend reads it): the texture
// values' table.
const float* const kUnitOfByte = ps11::Texture::unorm8Values();

// round_half_even(v * 255) of a float already in [0, 1] (ps11::unorm8OfFloat without the clamp).
inline uint32_t byteOfUnit(float v) { return uint32_t(ps11::roundEvenSmall(double(v) * 255.0)); }

template <typename T>
inline bool cmpPass(uint32_t mask, T a, T b) {
    const uint32_t outcome = a < b ? 0u : a == b ? 1u : a > b ? 2u : 3u;
    return (mask >> outcome) & 1u;
}

inline uint32_t load32(const uint8_t* p) {
    uint32_t w;
    std::memcpy(&w, p, 4);
    return w;
}
inline void store32(uint8_t* p, uint32_t w) { std::memcpy(p, &w, 4); }

// IEEE half <-> float by bits, round to nearest even; the same results as emu::floatToHalf /
// halfToFloat (tests check every half and a sweep of floats) at a fraction of the cost.
inline uint16_t halfOf(float f) {
    const uint32_t bits = std::bit_cast<uint32_t>(f);
    const uint16_t sign = uint16_t((bits >> 16) & 0x8000u);
    const uint32_t x = bits & 0x7fffffffu;
    if (x > 0x7f800000u) return uint16_t(sign | 0x7e00u);       // NaN
    if (x >= 0x477ff000u) return uint16_t(sign | 0x7c00u);      // >= 65520 (and infinity): infinity
    if (x < 0x38800000u) {                                      // below 2^-14: subnormal half
        const float v = std::bit_cast<float>(x) * 16777216.0f;  // exact: value in units of 2^-24
        const float r = (v + 8388608.0f) - 8388608.0f;          // round to an integer, ties to even
        return uint16_t(sign | uint16_t(r));
    }
    uint32_t h = (x - 0x38000000u) >> 13;  // rebias 127 -> 15, keep 10 mantissa bits
    const uint32_t rest = x & 0x1fffu;
    // Round up above half, or at half when odd (a carry into the exponent is right).
    h += uint32_t(rest + (h & 1u) > 0x1000u);
    return uint16_t(sign | h);
}
inline float floatOfHalf(uint16_t h) {
    const uint32_t sign = uint32_t(h & 0x8000u) << 16;
    const uint32_t e = (h >> 10) & 31u, m = h & 1023u;
    if (e == 0) {
        const float v = float(m) * 5.9604644775390625e-8f;  // m * 2^-24, exact
        return sign ? -v : v;
    }
    if (e == 31) return std::bit_cast<float>(sign | 0x7f800000u | (m ? 0x400000u | (m << 13) : 0u));
    return std::bit_cast<float>(sign | ((e + 112u) << 23) | (m << 13));
}

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

bool resolveTarget(const MergeTarget& t, Plan& p) {
    if (t.color) {
        switch (t.color->format ? t.color->format->format : D3DFMT_UNKNOWN) {
            case D3DFMT_A8R8G8B8:
                p.target = TargetKind::Argb8;
                break;
            case D3DFMT_X8R8G8B8:
                p.target = TargetKind::Xrgb8;
                break;
            case D3DFMT_A16B16G16R16F:
                p.target = TargetKind::Rgba16F;
                break;
            case D3DFMT_A32B32G32R32F:
                p.target = TargetKind::Rgba32F;
                break;
            case D3DFMT_R32F:
                p.target = TargetKind::R32F;
                break;
            default:
                return false;
        }
    }
    if (t.depth) {
        const FormatInfo* f = t.depth->format;
        if (!f || f->cls != FormatClass::Depth) return false;
        p.depthKind = f->format == D3DFMT_D32F_LOCKABLE ? DepthKind::D32F
                      : f->depthBits == 16              ? DepthKind::D16
                      : f->depthBits == 24              ? DepthKind::D24
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
// Depth.

// The depth surface's stored value for z in [0, 1]: the nearest of 2^bits - 1 steps, ties to
// even, exactly as Clear stores it (emu/device_blit.cpp, docs/device.md "Clear").
inline uint32_t depthCode(DepthKind k, float z) {
    switch (k) {
        case DepthKind::D16:
            return uint32_t(ps11::roundEvenSmall(double(z) * 65535.0));
        case DepthKind::D24:
            return uint32_t(ps11::roundEvenSmall(double(z) * 16777215.0));
        case DepthKind::D32:
            return uint32_t(ps11::roundEvenSmall(double(z) * 4294967295.0));
        default:
            return std::bit_cast<uint32_t>(z);
    }
}

struct DepthCtx {
    Surf surf;
    DepthKind kind = DepthKind::D16;
    uint32_t mask = 0;
    bool write = false;
};

// Depth test (and write when it passes). True when the pixel passes.
inline bool depthStage(const DepthCtx& p, uint32_t x, uint32_t y, float zIn) {
    const float z = zIn > 0.0f ? (zIn < 1.0f ? zIn : 1.0f) : 0.0f;  // NaN -> 0
    uint8_t* q = p.surf.at(x, y);
    const uint32_t code = depthCode(p.kind, z);
    bool pass;
    switch (p.kind) {
        case DepthKind::D16: {
            uint16_t old;
            std::memcpy(&old, q, 2);
            pass = cmpPass(p.mask, code, uint32_t(old));
            if (pass && p.write) {
                const uint16_t w = uint16_t(code);
                std::memcpy(q, &w, 2);
            }
            break;
        }
        case DepthKind::D24: {
            const uint32_t old = load32(q);
            pass = cmpPass(p.mask, code, old >> 8);
            if (pass && p.write) store32(q, (old & 0xffu) | (code << 8));  // keeps stencil / X
            break;
        }
        case DepthKind::D32: {
            pass = cmpPass(p.mask, code, load32(q));
            if (pass && p.write) store32(q, code);
            break;
        }
        default: {
            float old;
            std::memcpy(&old, q, 4);
            pass = cmpPass(p.mask, z, old);
            if (pass && p.write) std::memcpy(q, &z, 4);
            break;
        }
    }
    return pass;
}

// ---------------------------------------------------------------------------------------------
// Lane access.

struct Lanes {
    const MergeInputs& in;
    uint32_t w, h;  // the targets' common extent
    Lanes(const MergeInputs& inputs, const Plan& p) : in(inputs), w(p.boundW), h(p.boundH) {}
    bool inside(int i, uint32_t& x, uint32_t& y) const {
        x = uint32_t(in.x[i]), y = uint32_t(in.y[i]);  // negative coordinates become huge
        assert(x < w && y < h);
        return x < w && y < h;
    }
    float fog(int i) const {
        if (!in.fog) return 1.0f;
        return sat(in.fog[i]);
    }
    float z(int i) const { return in.z ? in.z[i] : 0.0f; }
};

// The stats of one call, added to the caller's at the end.
struct Counts {
    uint64_t written = 0, alphaRejected = 0, depthRejected = 0;
};

// Runs alpha test then depth test; counts. `alphaPass` is the alpha test's outcome.
inline bool tests(const DepthCtx* depth, bool alphaPass, uint32_t x, uint32_t y, float z, Counts& n) {
    if (!alphaPass) {
        ++n.alphaRejected;
        return false;
    }
    if (depth && !depthStage(*depth, x, y, z)) {
        ++n.depthRejected;
        return false;
    }
    ++n.written;
    return true;
}

// Packs r g b a bytes into the target's word (bytes B G R A; X8R8G8B8 stores X = 0xff).
inline uint32_t packArgb(uint32_t r, uint32_t g, uint32_t b, uint32_t a) {
    return b | (g << 8) | (r << 16) | (a << 24);
}

DepthCtx depthCtxOf(const Plan& p) { return DepthCtx{p.depthSurf, p.depthKind, p.depthMask, p.depthWrite}; }

// The byte mask of the enabled channels in an 8-bit ARGB word. For X8R8G8B8 the X byte is
// written (as 0xff) whenever any colour channel is.
uint32_t wordMask(const Plan& p) {
    uint32_t m = 0;
    if (p.channels & 1u) m |= 0x00ff0000u;
    if (p.channels & 2u) m |= 0x0000ff00u;
    if (p.channels & 4u) m |= 0x000000ffu;
    if (p.channels & 8u) m |= 0xff000000u;
    if (p.target == TargetKind::Xrgb8 && (p.channels & 7u)) m |= 0xff000000u;
    return m;
}

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
        else  // n = 16q + r rounds up when r > 8, or r == 8 and q is odd
            return uint32_t(n + 7 + ((n >> 4) & 1)) >> 4;
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
    } else {
        mergerKernels(ps11::simdLevel()).unorm8Words(f, count, alphaFill, words);
    }
    const Surf cs = p.colorSurf;
    const Lanes lanes(in, p);
    const uint8_t* live = in.live;
    if (in.row && !live && count > 0) {
        // One run of a row: the words straight into it.
        uint32_t x, y;
        const bool inside = lanes.inside(0, x, y) && x + uint32_t(count) <= p.boundW;
        assert(inside && in.x[count - 1] == in.x[0] + count - 1 && in.y[count - 1] == in.y[0]);
        if (inside) {
            uint8_t* q = cs.at(x, y);
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
    int m = 0;
    for (int i = 0; i < in.count; ++i) {
        uint32_t x, y;
        if ((in.live && !in.live[i]) || !lanes.inside(i, x, y)) continue;
        uint8_t* q = cs.at(x, y);
        const uint32_t old = load32(q);
        addr[m] = q;
        word[m] = old;
        for (int c = 0; c < 4; ++c) src[c][m] = std::clamp(g[c][i], 0, G);  // the 8-bit target saturates
        dst[0][m] = int32_t((old >> 16) & 0xffu) * S;
        dst[1][m] = int32_t((old >> 8) & 0xffu) * S;
        dst[2][m] = int32_t(old & 0xffu) * S;
        dst[3][m] = x8 ? G : int32_t(old >> 24) * S;  // X8R8G8B8's alpha reads 1
        ++m;
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
        if (mask != 0xffffffffu) w = (w & mask) | (word[k] & ~mask);
        store32(addr[k], w);
    }
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

// Real source values: color[] (fx profiles: n / G rounded to float, as the executor gives them).
struct FloatSource {
    const float* const* color;
    const int32_t* const* grid;  // fx profiles, for exact fog and alpha test
    int32_t G;
};

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

// The Baseline level's half conversion (emu/output_merger_kernels.h).
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
    alignas(32) float sum[4][ps11::kMaxSpan];
    constexpr int kShift[4] = {16, 8, 0, 24};  // r g b a in a b g r a word
    for (int c = 0; c < 4; ++c) {
        const float* src = f[c];
        float* out = sum[c];
        int i = 0;
#if defined(__SSE2__)
        // sat: v > 0 selects min(v, 1), else 0 (NaN included); d = float(byte) / 255, as kUnitOfByte.
        const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), k255 = _mm_set1_ps(255.0f);
        const __m128i byte = _mm_set1_epi32(0xff);
        for (; i + 4 <= count; i += 4) {
            const __m128 v = _mm_loadu_ps(src + i);
            const __m128 sv = _mm_and_ps(_mm_cmpgt_ps(v, zero), _mm_min_ps(v, one));
            const __m128i w = _mm_loadu_si128(reinterpret_cast<const __m128i*>(dst + 4 * i));
            const __m128 d = _mm_div_ps(_mm_cvtepi32_ps(_mm_and_si128(_mm_srli_epi32(w, kShift[c]), byte)), k255);
            _mm_store_ps(out + i, _mm_add_ps(sv, d));
        }
#endif
        for (; i < count; ++i) out[i] = sat(src[i]) + kUnitOfByte[(load32(dst + 4 * i) >> kShift[c]) & 0xffu];
    }
    alignas(32) uint32_t words[ps11::kMaxSpan];
    const float* const sums[4] = {sum[0], sum[1], sum[2], sum[3]};
    // X8R8G8B8 reads its missing alpha as 1 and stores 0xff: the fill gives both.
    mergerKernels(ps11::simdLevel()).unorm8Words(sums, count, x8 ? 0xff000000u : 0u, words);
    if (run) {
        if (mask != 0xffffffffu)
            for (int i = 0; i < count; ++i) words[i] = (words[i] & mask) | (load32(dst + 4 * i) & ~mask);
        std::memcpy(run, words, 4 * size_t(count));
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
        alignas(16) float fs[4], fd[4], ks[4], kd[4];
        alignas(16) uint32_t zs[4], zd[4], on[4];
        for (int c = 0; c < 4; ++c) {
            const ChannelPlan& cp = ch[c];
            fs[c] = cp.src.inv ? 1.0f - v[cp.src.slot] : v[cp.src.slot];
            fd[c] = cp.dst.inv ? 1.0f - v[cp.dst.slot] : v[cp.dst.slot];
            ks[c] = float(cp.cs), kd[c] = float(cp.cd);
            zs[c] = cp.src.slot == kZero && !cp.src.inv ? ~0u : 0u;
            zd[c] = cp.dst.slot == kZero && !cp.dst.inv ? ~0u : 0u;
            on[c] = (p.channels >> c & 1u) ? ~0u : 0u;
        }
        const __m128 fsv = _mm_load_ps(fs), fdv = _mm_load_ps(fd), ksv = _mm_load_ps(ks), kdv = _mm_load_ps(kd);
        const __m128 zsv = _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(zs)));
        const __m128 zdv = _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(zd)));
        const __m128 onv = _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(on)));
        float* q = reinterpret_cast<float*>(cs.at(x0, y0));
        const float *f0 = f[0], *f1 = f[1], *f2 = f[2], *f3 = f[3];
        for (int i = 0; i < in.count; ++i, q += 4) {
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

[[maybe_unused]] bool supportedColor(const Image* img) { return img && img->format && img->format->renderTarget; }

}  // namespace

const MergerKernels baseline::kMerger{&halvesBaseline, &unorm8WordsBaseline, &unorm8WordsRgbaBaseline};

const MergerKernels& mergerKernels(ps11::SimdLevel level) {
#ifdef PS11_HAVE_AVX2
    return *ps11::simdTable(level, &baseline::kMerger, &avx2::kMerger);
#else
    (void)level;
    return baseline::kMerger;
#endif
}

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

void mergePixels(const MergeState& state, const MergeInputs& in, const MergeTarget& target, MergeStats* stats) {
    // A colour target of another format, or a depth target of a non-depth format, is the
    // caller's programming error: asserted, and in release builds nothing is written.
    assert(!target.color || supportedColor(target.color));
    bool ok = false;
    const Plan p = makePlan(state, target, ok);
    assert(ok);
    if (!ok || in.count <= 0 || (!p.color && !p.depth)) return;
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
