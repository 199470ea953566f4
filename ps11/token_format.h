// Token format: every bit field of the D3D9 shader token stream (ps_1_1 … ps_1_4).
// This is the only place that spells out masks and shifts; the encoder, decoder and
// validator use these helpers. Layout from the DDK token pages (spec §5).
#pragma once

#include <cstdint>

namespace ps11::tok {

// Version token: 0xFFFF (pixel) in the high half, major.minor in the low half.
constexpr uint32_t kPixelShaderTag = 0xFFFF0000u;
constexpr uint32_t kVertexShaderTag = 0xFFFE0000u;
constexpr uint32_t kTypeMask = 0xFFFF0000u;
constexpr uint32_t versionToken(unsigned major, unsigned minor) { return kPixelShaderTag | (major << 8) | minor; }
constexpr unsigned versionMajor(uint32_t t) { return (t >> 8) & 0xFFu; }
constexpr unsigned versionMinor(uint32_t t) { return t & 0xFFu; }

// Special tokens.
constexpr uint32_t kEndToken = 0x0000FFFFu;
constexpr uint32_t kPhaseToken = 0x0000FFFDu;
constexpr uint32_t kCommentOpcode = 0xFFFEu;
constexpr uint32_t kCommentLengthShift = 16;
constexpr uint32_t kCommentLengthMask = 0x7FFF0000u;  // bits 16-30

// Instruction token.
constexpr uint32_t kOpcodeMask = 0x0000FFFFu;
constexpr uint32_t kOpcodeSpecificMask = 0x00FF0000u;  // 0 in ps 1.x
constexpr uint32_t kInstLengthMask = 0x0F000000u;      // 0 in ps 1.x
constexpr uint32_t kPredicatedBit = 0x10000000u;
constexpr uint32_t kCoissueBit = 0x40000000u;
constexpr uint32_t kInstReservedMask = 0xA0000000u;  // bit 29 and bit 31 must be 0

// Parameter tokens (destination and source share the register fields).
constexpr uint32_t kParamBit = 0x80000000u;  // bit 31 always set
constexpr uint32_t kRegNumMask = 0x000007FFu;
constexpr uint32_t kRegType2Mask = 0x00001800u;  // type bits 3-4 at 11-12
constexpr uint32_t kRegType2Shift = 8;          // (t & mask2) >> 8 yields bits 3-4 of the type
constexpr uint32_t kRelativeBit = 0x00002000u;
constexpr uint32_t kParamReservedMask = 0x0000C000u;
constexpr uint32_t kRegTypeMask = 0x70000000u;
constexpr uint32_t kRegTypeShift = 28;

// Destination fields.
constexpr uint32_t kWriteMaskShift = 16;
constexpr uint32_t kWriteMaskMask = 0x000F0000u;
constexpr uint32_t kResultModShift = 20;
constexpr uint32_t kResultModMask = 0x00F00000u;
constexpr uint32_t kResultModSaturate = 0x1u;  // bit 20
constexpr uint32_t kShiftShift = 24;
constexpr uint32_t kShiftMask = 0x0F000000u;  // 4-bit two's complement scale

// Source fields.
constexpr uint32_t kSwizzleShift = 16;
constexpr uint32_t kSwizzleMask = 0x00FF0000u;
constexpr uint32_t kSrcModShift = 24;
constexpr uint32_t kSrcModMask = 0x0F000000u;
constexpr uint8_t kIdentitySwizzle = 0xE4;  // x y z w

constexpr unsigned regType(uint32_t t) {
    return ((t & kRegTypeMask) >> kRegTypeShift) | ((t & kRegType2Mask) >> kRegType2Shift);
}
constexpr uint32_t regTypeBits(unsigned type) {
    return ((type & 7u) << kRegTypeShift) | (((type >> 3) & 3u) << 11);
}
constexpr unsigned regNum(uint32_t t) { return t & kRegNumMask; }
constexpr unsigned writeMask(uint32_t t) { return (t & kWriteMaskMask) >> kWriteMaskShift; }
constexpr unsigned resultMod(uint32_t t) { return (t & kResultModMask) >> kResultModShift; }
// Sign-extends the 4-bit shift field: 1=x2, 2=x4, 3=x8, -1=d2, -2=d4, -3=d8.
constexpr int shiftScale(uint32_t t) {
    int v = int((t & kShiftMask) >> kShiftShift);
    return v >= 8 ? v - 16 : v;
}
constexpr uint32_t shiftBits(int s) { return (uint32_t(s) & 0xFu) << kShiftShift; }
constexpr unsigned swizzle(uint32_t t) { return (t & kSwizzleMask) >> kSwizzleShift; }
constexpr unsigned srcMod(uint32_t t) { return (t & kSrcModMask) >> kSrcModShift; }

// Register type values (D3DSPR_*), the ones legal in ps 1.x first.
enum : unsigned { kTypeTemp = 0, kTypeInput = 1, kTypeConst = 2, kTypeTexture = 3, kTypeMaxLegal = 3 };

}  // namespace ps11::tok
