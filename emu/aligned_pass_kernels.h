// The vector kernels of the aligned-pass path (emu/aligned_pass.h): a table per SIMD level
// (ps11/simd_dispatch.h), fetched once per draw (AlignedDraw::kernels): the Avx2 level's
// (aligned_pass_avx2.cpp), and the Avx512 level's, which replaces its vertical blends, texel
// means and deinterleave (aligned_pass_avx512.cpp; the vertical blends are one source for both,
// aligned_vertical.inc); at Baseline there is none and every pixel is filtered
// and stored one at a time. Internal to emu/aligned_pass*.cpp.
//
// Filtering is split in two passes (docs/device.md "Aligned passes"): a horizontal pass turns a
// texel row into an "H row" once (combine, or buildTabulated), and each tap of each pixel row
// combines two H rows vertically (vertical). An H row of weight wx holds, per output j, planar
// (r, g, b, a) uint16 values in one of three forms, all exact:
//   kind A (wx = 0):   a           (h = 256·a)
//   kind S (wx = 128): a + b       (h = 128·(a + b))
//   kind H (other wx): a·(256 − wx) + b·wx = h
//   kind Q (a tabulated row whose every weight is a multiple of 16, as a 2×, 4× or 8×
//           magnification's are): h / 16, exact, at most 4080
// where a, b are the channel bytes of texels i = step·j + phase and i + 1. The blend of the
// reference sampler is round_half_even((h0·(256 − wy) + h1·wy) / 65536); for kind Q with wy a
// multiple of 16 that is round_half_even((q0·(16 − wy/16) + q1·wy/16) / 256) in 16 bits.
#pragma once

#include <cstdint>

#include "emu/prefetch.h"
#include "ps11/simd_dispatch.h"

namespace emu {

enum class HKind : uint8_t { A, S, H, Q };

inline HKind hKindOf(int32_t wx) { return wx == 0 ? HKind::A : (wx == 128 ? HKind::S : HKind::H); }

// Padding (elements) every plane of an H row keeps past its end: the kernels write whole groups of
// 16 and read whole groups of 16 (32 at Avx512). Staged rows keep kStagePad: the combine reads up to 16 groups of
// `step` past the last element it needs.
constexpr int kHRowPad = 32;
constexpr int kStagePad = 16 * 8 + 32;

struct AlignedKernels {
    // Texels [0, count) of a b g r a row as r g b a uint16 planes out[c][0 .. count) (and up to
    // the next multiple of 16: whatever the row holds there, or 0 past the row's end; never read
    // past row + 4·count).
    void (*deinterleave)(const uint8_t* row, int count, uint16_t* const out[4]);

    // H row j in [0, n) from staged planes t (t[c][k] = channel c of texel i_first + k): texels
    // k = step·j and k + 1 with weight wx, in the form of hKindOf(wx). Steps 1, 2 and 4 are
    // vectorised, others run one element at a time. t's planes must hold kStagePad elements past
    // the last one read.
    void (*combine)(const uint16_t* const t[4], int n, int step, int32_t wx, uint16_t* const out[4]);

    // The two weight-½ H rows of a 4:1 reduction straight from a b g r a texel row, with no
    // staged planes: for j in [0, n), even[c][j] = the sum of channel c of texels 4j and 4j + 1,
    // odd[c][j] = that of texels 4j + 2 and 4j + 3 (combine's step 4, kind S, phases 0 and 2).
    // Reads texels [0, 4n) only; writes the planes up to the next multiple of 16.
    void (*pairSums4)(const uint8_t* row, int n, uint16_t* const even[4], uint16_t* const odd[4]);

    // Tabulated H row j in [0, n): ((256 − w[j])·a + w[j]·b) >> shift with a, b the channel bytes
    // of the b g r a words at row + off0[j], row + off1[j] (byte offsets within the row's
    // `rowTexels` words; negative offsets read texel 0: such elements are never used). Shift 0
    // gives kind H for every weight; shift 4, where every w[j] is a multiple of 16, kind Q.
    void (*buildTabulated)(const uint8_t* row, int rowTexels, const int32_t* off0, const int32_t* off1,
                           const int32_t* w, int n, uint16_t* const out[4], int shift);

    // Lanes [lane, lane + count) of out[c] from H rows h0, h1 (planes, read from element 0) of
    // kind `kind` with vertical weight wy (h1 unused when wy = 0): the blended channel bytes.
    void (*vertical)(HKind kind, const uint16_t* const h0[4], const uint16_t* const h1[4], int32_t wy, int count,
                     int lane, int16_t* const out[4]);
    // The same blend for fx12: round_half_even(16·(h0·(256 − wy) + h1·wy) / 65536), the grid
    // integers (at most 4080) of the fx12 sampler.
    void (*vertical12)(HKind kind, const uint16_t* const h0[4], const uint16_t* const h1[4], int32_t wy, int count,
                       int lane, int16_t* const out[4]);

    // vertical's blends (fx8) as b g r a words at out[0 .. count), in whole groups of lanes: up to
    // 31 words past the count are written too.
    void (*verticalBytes)(HKind kind, const uint16_t* const h0[4], const uint16_t* const h1[4], int32_t wy, int count,
                          uint8_t* out);
    // The same words, each (word & keep) | set, stored at dst[0 .. count) or, with `additive`
    // (ONE/ONE into an 8-bit target), added with saturation to the bytes at `base` (dst itself,
    // or the source of a copy into dst not made yet: RowSource), as storeRow stores and adds
    // lanes; neither is touched past its `count` words.
    void (*verticalStore)(HKind kind, const uint16_t* const h0[4], const uint16_t* const h1[4], int32_t wy, int count,
                          uint32_t keep, uint32_t set, bool additive, const uint8_t* base, uint8_t* dst);
    // Texel bytes' rounded means, what a 1:1 tap at weight 0 or 128 each way filters:
    // out[i] = round_half_even((src[0][i] + ... + src[sources - 1][i]) / sources) for i in [0, n),
    // sources 2 or 4. Reads src[k][0, n) only; writes out[0, n) only.
    void (*meanBytes)(const uint8_t* const src[4], int sources, int n, uint8_t* out);
    // Stores `count` pixels of r0 (int16 r g b a planes, clamped to [0, 255]) as b g r a words at
    // dst, or-ing orMask (additive: a saturating byte add onto what dst holds); returns how many
    // it stored (the caller stores the rest). The planes are read in whole groups of 16 lanes
    // (the lanes past `count` are ignored); dst is never touched past its `count` words.
    // `base`: where an additive store reads the bytes it adds to (dst, or verticalStore's).
    int (*storeRow)(bool additive, const int16_t* const r[4], int count, uint32_t orMask, const uint8_t* base,
                    uint8_t* dst);
    // The same for fx12 lanes: each channel's byte round_half_even(n / 16) of n clamped to
    // [0, 4080]; additive: of n + 16·(the target's byte), clamped again (the merger's ONE/ONE).
    int (*storeRow12)(bool additive, const int16_t* const r[4], int count, uint32_t orMask, const uint8_t* base,
                      uint8_t* dst);
};

// The table of a level, or null (no vector kernels at that level).
const AlignedKernels* alignedKernels(ps11::SimdLevel level);
// The Avx2 table (x86-64 builds only); use alignedKernels().
namespace avx2 {
extern const AlignedKernels kAligned;
}
// The Avx512 table: the Avx2 one with its own vertical blends, means and deinterleave (built on first
// use, from the Avx2 table); use alignedKernels().
namespace avx512 {
const AlignedKernels& alignedTable();
}

}  // namespace emu
