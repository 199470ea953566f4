// Internal to the output merger (emu/output_merger.cpp, the 8-bit fx family and the dispatch;
// emu/output_merger_float.cpp, the float family): the exact helpers, the depth stage, lane access
// and the per-call counts both families use, and the float family's entry points.
#pragma once

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstdint>
#include <cstring>

#include "emu/format.h"
#include "emu/merge_plan.h"
#include "emu/output_merger.h"
#include "ps11/precision.h"
#include "ps11/texture.h"

namespace emu::merger {

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
inline const float* const kUnitOfByte = ps11::Texture::unorm8Values();

// round_half_even(v * 255) of a float already in [0, 1] (ps11::unorm8OfFloat without the clamp).
inline uint32_t byteOfUnit(float v) { return uint32_t(ps11::roundEvenSmall(double(v) * 255.0)); }

template <typename T>
inline bool cmpPass(uint32_t mask, T a, T b) {
    const uint32_t outcome = a < b ? 0u : a == b ? 1u : a > b ? 2u : 3u;
    return (mask >> outcome) & 1u;
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

inline DepthCtx depthCtxOf(const Plan& p) { return DepthCtx{p.depthSurf, p.depthKind, p.depthMask, p.depthWrite}; }

// The byte mask of the enabled channels in an 8-bit ARGB word. For X8R8G8B8 the X byte is
// written (as 0xff) whenever any colour channel is.
inline uint32_t wordMask(const Plan& p) {
    uint32_t m = 0;
    if (p.channels & 1u) m |= 0x00ff0000u;
    if (p.channels & 2u) m |= 0x0000ff00u;
    if (p.channels & 4u) m |= 0x000000ffu;
    if (p.channels & 8u) m |= 0xff000000u;
    if (p.target == TargetKind::Xrgb8 && (p.channels & 7u)) m |= 0xff000000u;
    return m;
}

// ---------------------------------------------------------------------------------------------
// The float family (emu/output_merger_float.cpp).

// Real source values: color[] (fx profiles: n / G rounded to float, as the executor gives them).
struct FloatSource {
    const float* const* color;
    const int32_t* const* grid;  // fx profiles, for exact fog and alpha test
    int32_t G;
};

// Any state, in float arithmetic: float/ideal profiles on 8-bit targets, every profile on float
// targets (and depth-only draws of float profiles).
void mergeFloat(const Plan& p, const MergeInputs& in, const FloatSource& src, Counts& n);
// A float target, no fog, tests or blending.
void storeFloatPlain(const Plan& p, const MergeInputs& in, const float* const f[4], Counts& n);
// Float profiles' ONE/ONE ADD into an 8-bit target, no fog or tests.
void addUnorm8Float(const Plan& p, const MergeInputs& in, const float* const f[4], Counts& n);
// A float target with blending, no fog or tests (float profiles).
void blendFloatTarget(const Plan& p, const MergeInputs& in, const float* const f[4], Counts& n);

}  // namespace emu::merger
