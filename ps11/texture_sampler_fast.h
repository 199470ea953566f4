// The fast sampling kernels for 8-bit (Unorm8) 2-D textures: point and bilinear on one mip level
// (fx: and blends of two), every address mode, in the fx profiles and in float and ideal. They
// compute exactly what the reference path of TextureSampler computes (docs/textures.md "Fast
// path"); TextureSampler decides when a span (or a run of its quads) qualifies. Internal (not
// installed): ps11/texture_sampler*.cpp and the device's row paths (emu/aligned_pass.cpp:
// axisTable, and the fx kernel for taps it samples per pixel; emu/aligned_float.cpp: the float
// kernel for its taps sampled per pixel).
#pragma once

#include <cstdint>

#include "ps11/simd_dispatch.h"
#include "ps11/texture_sampler.h"

namespace ps11::fastpath {

// One run of lanes that all read the same level with the same filter.
struct Unorm8Run {
    const uint8_t* texels = nullptr;  // the level's first texel: b g r a bytes, rows width * 4 apart
    uint32_t width = 1, height = 1;
    bool linear = false;  // bilinear (4 taps) or point
    TextureAddress addressU = TextureAddress::Wrap, addressV = TextureAddress::Wrap;
    uint32_t borderWord = 0;  // the border colour as a b g r a word (its grid value is byte * scale)
    int32_t scale = 1;        // grid units per byte: 1 (fx8) or 16 (fx12)
};

using Unorm8Kernel = void (*)(const Unorm8Run& run, int count, const float* u, const float* v, int32_t* const* dst);
// A blend of two levels (MIP filter LINEAR) in an fx profile: per lane the exact sums S = Σ w·byte
// of its taps at level0's run and at level1's (weights of 65536 in all per level, a point tap's
// byte times 65536), then round_half_even(((256 − m)·S0 + m·S1)·scale / 2^24) with m = mipW[i]:
// the reference's one rounding. Both runs share the address modes, border word and scale.
using Unorm8MipKernel = void (*)(const Unorm8Run& level0, const Unorm8Run& level1, const int32_t* mipW, int count,
                                 const float* u, const float* v, int32_t* const* dst);

// ps11::floatAxisTaps (texture_sampler.h) of a level: the reference sampler's per-lane axis rule
// for the float profiles — texel pair after the address mode (-1 = border) and float weight
// (w / 256 of the 8-bit weight when `weights8`; 0 for point) — for an axis of n texels.
using FloatAxisKernel = void (*)(TextureAddress mode, bool linear, bool weights8, int count, const float* c, uint32_t n,
                                 int32_t* i0, int32_t* i1, float* f);

// The float profiles' lanes of one level of an 8-bit 2-D texture, filtered as the reference
// sampler's combineFloat (texture_sampler.cpp): per axis the FloatAxisKernel's pair and weight,
// texels byte / 255 (the texture's value table), the border colour's floats where an index is −1,
// and the lerps (1 − f)·a + f·b along u, then v (point: the texel at i0). Texels are finite, so
// vector lerps give the reference's floats bit for bit.
struct Unorm8FloatRun {
    const uint8_t* texels = nullptr;  // the level's first texel: b g r a bytes, rows width * 4 apart
    uint32_t width = 1, height = 1;
    bool linear = false;
    bool weights8 = false;  // the class's 8-bit weights (the float profile on such a class)
    TextureAddress addressU = TextureAddress::Wrap, addressV = TextureAddress::Wrap;
    const float* border = nullptr;  // r g b a
};
// count <= kMaxSpan; dst[c][0 .. count) for c = r g b a.
using Unorm8FloatKernel = void (*)(const Unorm8FloatRun& run, int count, const float* u, const float* v,
                                   float* const* dst);

// ps11::quadLevel (texture_sampler.h) for the quads of 2-D lanes (TL TR BL BR) where the mip
// weight has 8 bits (fx, and the float profile's 8-bit weights): each quad's rho² =
// max(dx², dy²) in level-0 texels as quadLevel forms it (the same double operations), then
// LOD = ½·log2(rho²) by a polynomial within 1e-10 of the log, whose choice is the exact log's
// wherever log2(rho²) lies more than 1e-9 from a multiple of 1/256 (every edge of the choice —
// whole and half levels, the 8-bit weight's ties — lies on one). A quad nearer an edge, or with
// rho² not below 2^1000, gets slots 0: the caller asks chooseLevel(rho², rho²). Handles the
// first quads of the span, sixteen lanes at a time, and returns how many (the Baseline level:
// none); per quad k: rho2, level0, level1, slots, mipW, linear.
struct QuadLevelRun {
    int levels = 1;                             // the texture's level count
    Filter mipFilter = Filter::None;            // None, Point or Linear
    bool minLinear = false, magLinear = false;  // the min and mag filters are LINEAR
    double width = 1, height = 1;               // level 0's extents
};
using QuadLevelKernel = int (*)(const QuadLevelRun& run, int count, const float* u, const float* v, double* rho2,
                                int32_t* level0, int32_t* level1, int32_t* slots, int32_t* mipW, int32_t* linear);

// The kernels of a SIMD level (ps11/simd_dispatch.h), one source (texture_sampler_fast_impl.h)
// built per level; TextureSampler fetches the table once per span.
struct SamplerKernels {
    Unorm8Kernel unorm8;
    FloatAxisKernel floatAxis;
    Unorm8MipKernel unorm8Mip;
    Unorm8FloatKernel unorm8Float;
    QuadLevelKernel chooseQuadLevels;
};
const SamplerKernels& samplerKernels(SimdLevel level);
// The tables (the Avx2 one in x86-64 builds only); use samplerKernels().
namespace baseline {
extern const SamplerKernels kSampler;
}
namespace avx2 {
extern const SamplerKernels kSampler;
}

// One axis of the kernels above on its own, for callers that tabulate it (the device's
// aligned-pass path): per coordinate c[i] of an axis with n texels, the texel pair i0/i1 (-1 =
// border) and the 8-bit weight w of i1 (bilinear), or the texel i0 = i1 with w = 0 (point).
// Exactly the values the kernels use for the same coordinate.
void axisTable(TextureAddress mode, bool linear, int count, const float* c, uint32_t n, int32_t* i0, int32_t* i1,
               int32_t* w);

}  // namespace ps11::fastpath
