// The output merger's kernels, a table per SIMD level (ps11/simd_dispatch.h) that mergePixels
// fetches once per call, as do the blits' float-to-8-bit copies. Internal to emu/ (and its tests).
#pragma once

#include <cstdint>

#include "ps11/simd_dispatch.h"

namespace emu {

// A blend with constant factors into an A32B32G32R32F target (blendFloatTarget), per channel c:
// t_s = ks·(s·fs), t_d = kd·(d·fd); the result is zs ? (zd ? 0 : t_d) : (zd ? t_s : t_s + t_d),
// stored where `on` (the write mask) is set, d kept elsewhere. Masks are all ones or zeros.
struct FloatBlendConsts {
    alignas(16) float fs[4], fd[4], ks[4], kd[4];
    alignas(16) uint32_t zs[4], zd[4], on[4];
};

struct MergerKernels {
    // The IEEE halves (round to nearest even) of `count` lanes of r g b a, interleaved:
    // out[4·i + c] = half(f[c][i]). Baseline: by bit manipulation; Avx2: F16C (VCVTPS2PH). The
    // same half for every non-NaN value; a NaN stays a NaN (its payload may differ).
    void (*halves)(const float* const f[4], int count, uint16_t* out);
    // The A8R8G8B8 words of `count` lanes of float r g b a: each channel ps11::unorm8OfFloat
    // (clamped to [0, 1], NaN 0, round_half_even(v * 255) in double), ORed with `alphaFill`.
    void (*unorm8Words)(const float* const f[4], int count, uint32_t alphaFill, uint32_t* words);
    // The same words of `count` pixels of interleaved float r g b a (an A32B32G32R32F row): the
    // ideal profile's float frame into an 8-bit target (StretchRect).
    void (*unorm8WordsRgba)(const float* rgba, int count, uint32_t alphaFill, uint32_t* words);
    // ONE/ONE into an 8-bit target under the float profiles: the A8R8G8B8 words (as unorm8Words,
    // ORed with `alphaFill`) of the float sums sat(src[c][i]) + d, d the destination word
    // words[i]'s channel c as its value float(d) / 255 (correctly rounded: the texture's value
    // table). Avx2 and Avx512: a product and two FMAs in place of the division, the same float for
    // every byte (checked for all 256); eight (Avx512: sixteen) pixels whose sources are all 0, negative or NaN keep
    // their words (the sum is d, whose byte is d's), without converting.
    // out may be `words` itself (each group's words are read before its own are written).
    void (*addUnorm8Words)(const float* const src[4], const uint8_t* words, int count, uint32_t alphaFill,
                           uint32_t* out);
    // The FloatBlendConsts blend of planar sources f[c][i] onto the interleaved float pixels
    // q[4·i + c], for i from `from` on, a group of pixels at a time while no source or
    // destination value of the group is NaN; returns the first pixel not blended (a group with a
    // NaN, or the last pixels short of a group: the caller blends them on its own). Baseline:
    // none (returns `from`); Avx2: eight pixels a group, the same float operations in the same
    // order per pixel.
    int (*blendRgba32F)(const FloatBlendConsts& k, const float* const f[4], int from, int count, float* q);
};

const MergerKernels& mergerKernels(ps11::SimdLevel level);
// The tables (the Avx2 one in x86-64 builds only); use mergerKernels().
namespace baseline {
extern const MergerKernels kMerger;
}
namespace avx2 {
extern const MergerKernels kMerger;
}
// The Avx512 table: the Avx2 one with its own float-to-8-bit words (built on first use, from the
// Avx2 table); use mergerKernels().
namespace avx512 {
const MergerKernels& mergerTable();
}

}  // namespace emu
