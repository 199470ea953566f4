// The vector kernels of the aligned-pass path (emu/aligned_pass.h), built for AVX2 in
// aligned_pass_avx2.cpp; callers check the CPU first. Internal to emu/aligned_pass*.cpp.
#pragma once

#include <cstdint>

namespace emu {

// Filters `count` pixels (a multiple of 16) whose texels are r0 + 4i and r0 + 4i + 4 (and the
// same on r1) with the fixed 8-bit weights wx, wy into int16 r g b a planes out[c] + lane: the
// exact sum rounded once, half to even. r1 is read only when wy != 0, texel i + 1 only when
// wx != 0.
void alignedFilterRunAvx2(const uint8_t* r0, const uint8_t* r1, int32_t wx, int32_t wy, int count, int lane,
                          int16_t* const out[4]);

// Stores the first pixels of r0 (int16 r g b a planes, clamped to [0, 255]) as b g r a words at
// dst, or-ing orMask (additive: a saturating byte add onto what dst holds), in whole groups of
// 16; returns how many it stored (the caller stores the rest).
int alignedStoreRowAvx2(bool additive, const int16_t* const r[4], int count, uint32_t orMask, uint8_t* dst);

}  // namespace emu
