// The vector kernels of the float row path (emu/aligned_float.h): a table per SIMD level
// (ps11/simd_dispatch.h), fetched once per draw (FloatRowDraw::kernels). Every kernel performs
// the reference sampler's float operations in its order, one lane at a time as far as the
// result is concerned (IEEE single precision, no fused multiply-add in the lerps: the Avx2
// and Avx512 files are built with -ffp-contract=off; the decode's quotient by 255 is exact either
// way), so every level gives the same floats bit for bit. Internal to emu/aligned_float*.cpp.
#pragma once

#include <cstddef>
#include <cstdint>

#include "emu/prefetch.h"
#include "ps11/simd_dispatch.h"

namespace emu {

struct FloatRowKernels {
    // out[j] = (1 − f[j])·a[j] + f[j]·b[j] for j in [0, n): the horizontal lerps of a run of
    // columns whose texel pairs are consecutive (a = the row at the run's first texel, b = a + 1).
    void (*lerpColumns)(const float* a, const float* b, const float* f, int n, float* out);
    // out[j] = (1 − f[j])·d[i0[j]] + f[j]·d[i1[j]] for j in [0, n), every index in [0, len): the
    // horizontal lerps of any columns whose texels lie in the row (a magnified tap's).
    void (*lerpGather)(const float* d, int len, const int32_t* i0, const int32_t* i1, const float* f, int n,
                       float* out);
    // The same lerps straight from an 8-bit b g r a row, all four channels: out[c·stride + j] =
    // (1 − f[j])·v(i0[j], c) + f[j]·v(i1[j], c), v(i, c) texel i's channel c as its value (as
    // decode), every index in [0, len). A minified tap's columns, which skip texels: a gather
    // of words serves four channels, where the decoded row needs one per channel.
    void (*lerpWords)(const uint8_t* row, int len, const int32_t* i0, const int32_t* i1, const float* f, int n,
                      float* out, size_t stride);
    // The same from a row of float r g b a texels (A32B32G32R32F as the sampler holds it): each
    // column's two texels loaded whole, no gathers. False when a result is NaN: which of two NaNs a
    // sum returns depends on the order of its operands, so the caller filters that run one column
    // at a time as the reference sampler does (out unspecified then).
    bool (*lerpValues)(const float* rgba, int len, const int32_t* i0, const int32_t* i1, const float* f, int n,
                       float* out, size_t stride);
    // out[j] = (1 − f)·a[j] + f·b[j] for j in [0, n): a pixel row's vertical lerp of two H rows.
    void (*lerpRow)(const float* a, const float* b, float f, int n, float* out);
    // Texels [0, n) of a b g r a row as planar r g b a floats, byte / 255 (ps11::Texture::
    // unorm8Values()): channel c of texel i at out[c·stride + i].
    void (*decode)(const uint8_t* row, int n, float* out, size_t stride);
    // Texels [0, n) of a row of float r g b a texels as planar floats, bit for bit (NaNs too):
    // channel c of texel i at out[c·stride + i].
    void (*transpose)(const float* rgba, int n, float* out, size_t stride);
};

// The table of a level (Baseline: SSE2 on x86-64, scalar elsewhere).
const FloatRowKernels& floatRowKernels(ps11::SimdLevel level);
// The Avx2 table (x86-64 builds only); use floatRowKernels().
namespace avx2 {
extern const FloatRowKernels kFloatRow;
}
// The Avx512 table: the Avx2 one with its own decode and row and column lerps (built on first
// use, from the Avx2 table); use floatRowKernels().
namespace avx512 {
const FloatRowKernels& floatRowTable();
}

}  // namespace emu
