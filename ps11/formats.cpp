// Texture formats: the one table of every format's facts (D3DFORMAT value, name, size, class,
// the sampler's channels, the device's uses) and the lookups derived from it (ps11/formats.h).
#include "ps11/formats.h"

#include <cctype>
#include <iterator>

namespace ps11 {

namespace {

constexpr Channel U(uint8_t shift, uint8_t bits) { return {ChannelKind::Unorm, shift, bits}; }
constexpr Channel S(uint8_t shift, uint8_t bits) { return {ChannelKind::Snorm, shift, bits}; }
constexpr Channel H(uint8_t shift) { return {ChannelKind::Half, shift, 16}; }
constexpr Channel F(uint8_t shift) { return {ChannelKind::Float, shift, 32}; }
constexpr Channel kOne{ChannelKind::One, 0, 0};
constexpr Channel kZero{ChannelKind::Zero, 0, 0};
constexpr Channel kNoPad{ChannelKind::One, 0, 0};

using FC = FormatClass;
using TF = TexFormat;

}  // namespace

// D3D9 memory layouts (d3d9types.h names list channels from the most significant bit; a texel
// is one little-endian word): A8R8G8B8 = bytes B G R A; A8L8 = L A; V8U8 = U V; L6V5U5 = U in
// bits 0-4, V 5-9, L 10-15; X8L8V8U8 = U V L X; Q8W8V8U8 = U V W Q; V16U16 = U (16) V (16);
// A16B16G16R16F = halves R G B A; A32B32G32R32F = floats R G B A. The sampler's view
// (docs/textures.md, ps1x-spec §6.4): missing channels read 1, except A8's rgb which read 0;
// bump formats map r = U, g = V, b = L or W, a = Q.
// D3DFORMAT values as in d3d9types.h (the SDK header emu/d3d9types.h mirrors).
// One row per line:
// clang-format off
constexpr FormatRow kFormatRows[19] = {
    // d3d, name, bytes, class, r g b a, pad, texture, render target, lockable depth, depth, stencil, float depth, TexFormat
    {21, "A8R8G8B8", 4, FC::Unorm8, {U(16, 8), U(8, 8), U(0, 8), U(24, 8)}, kNoPad, true, true, false, 0, 0, false, TF::A8R8G8B8},
    {22, "X8R8G8B8", 4, FC::Unorm8, {U(16, 8), U(8, 8), U(0, 8), kOne}, U(24, 8), true, true, false, 0, 0, false, TF::X8R8G8B8},
    {28, "A8", 1, FC::Unorm8, {kZero, kZero, kZero, U(0, 8)}, kNoPad, true, false, false, 0, 0, false, TF::A8},
    {50, "L8", 1, FC::Unorm8, {U(0, 8), U(0, 8), U(0, 8), kOne}, kNoPad, true, false, false, 0, 0, false, TF::L8},
    {51, "A8L8", 2, FC::Unorm8, {U(0, 8), U(0, 8), U(0, 8), U(8, 8)}, kNoPad, true, false, false, 0, 0, false, TF::A8L8},
    {60, "V8U8", 2, FC::Signed, {S(0, 8), S(8, 8), kOne, kOne}, kNoPad, true, false, false, 0, 0, false, TF::V8U8},
    {61, "L6V5U5", 2, FC::Signed, {S(0, 5), S(5, 5), U(10, 6), kOne}, kNoPad, true, false, false, 0, 0, false, TF::L6V5U5},
    {62, "X8L8V8U8", 4, FC::Signed, {S(0, 8), S(8, 8), U(16, 8), kOne}, U(24, 8), true, false, false, 0, 0, false, TF::X8L8V8U8},
    {63, "Q8W8V8U8", 4, FC::Signed, {S(0, 8), S(8, 8), S(16, 8), S(24, 8)}, kNoPad, true, false, false, 0, 0, false, TF::Q8W8V8U8},
    {64, "V16U16", 4, FC::Signed, {S(0, 16), S(16, 16), kOne, kOne}, kNoPad, true, false, false, 0, 0, false, TF::V16U16},
    {113, "A16B16G16R16F", 8, FC::Float, {H(0), H(16), H(32), H(48)}, kNoPad, true, true, false, 0, 0, false, TF::A16B16G16R16F},
    {116, "A32B32G32R32F", 16, FC::Float, {F(0), F(32), F(64), F(96)}, kNoPad, true, true, false, 0, 0, false, TF::A32B32G32R32F},
    {114, "R32F", 4, FC::Float, {F(0), kOne, kOne, kOne}, kNoPad, true, true, false, 0, 0, false, TF::R32F},
    {80, "D16", 2, FC::Depth, {}, kNoPad, false, false, false, 16, 0, false},
    {70, "D16_LOCKABLE", 2, FC::Depth, {}, kNoPad, false, false, true, 16, 0, false},
    {75, "D24S8", 4, FC::Depth, {}, kNoPad, false, false, false, 24, 8, false},
    {77, "D24X8", 4, FC::Depth, {}, kNoPad, false, false, false, 24, 0, false},
    {71, "D32", 4, FC::Depth, {}, kNoPad, false, false, false, 32, 0, false},
    {82, "D32F_LOCKABLE", 4, FC::Depth, {}, kNoPad, false, false, true, 32, 0, true},
};
// clang-format on

namespace {

constexpr bool texturesInEnumOrder() {
    for (size_t i = 0; i < kTexFormatCount; ++i)
        if (!kFormatRows[i].texture || kFormatRows[i].texFormat != TexFormat(i)) return false;
    for (size_t i = kTexFormatCount; i < std::size(kFormatRows); ++i)
        if (kFormatRows[i].texture) return false;
    return true;
}
static_assert(texturesInEnumOrder(), "kFormatRows: the texture formats first, row i is TexFormat i");

}  // namespace

const FormatRow& formatRow(TexFormat f) { return kFormatRows[size_t(f)]; }

namespace {
constexpr NameEntry<TexFormat> nameOf(size_t i) { return {kFormatRows[i].name, TexFormat(i)}; }
}  // namespace

const NameEntry<TexFormat> kTexFormatNames[kTexFormatCount] = {
    nameOf(0), nameOf(1), nameOf(2), nameOf(3),  nameOf(4),  nameOf(5),  nameOf(6),
    nameOf(7), nameOf(8), nameOf(9), nameOf(10), nameOf(11), nameOf(12),
};
static_assert(kTexFormatCount == 13, "kTexFormatNames names every texture row");

namespace {
// The k-th texture row (in enum order) that a render target may take.
constexpr NameEntry<TexFormat> renderTargetName(size_t k) {
    for (size_t i = 0; i < kTexFormatCount; ++i)
        if (kFormatRows[i].renderTarget && k-- == 0) return nameOf(i);
    return {"", TexFormat::A8R8G8B8};
}
constexpr size_t renderTargetRows() {
    size_t n = 0;
    for (size_t i = 0; i < kTexFormatCount; ++i) n += kFormatRows[i].renderTarget ? 1 : 0;
    return n;
}
static_assert(renderTargetRows() == kRenderTargetFormatCount, "kRenderTargetFormatNames names every render target");
}  // namespace

const NameEntry<TexFormat> kRenderTargetFormatNames[kRenderTargetFormatCount] = {
    renderTargetName(0), renderTargetName(1), renderTargetName(2), renderTargetName(3), renderTargetName(4),
};

const char* texFormatName(TexFormat f) { return size_t(f) < kTexFormatCount ? formatRow(f).name : "?"; }

std::optional<TexFormat> parseTexFormat(std::string_view name) {
    for (const auto& e : kTexFormatNames) {
        std::string_view n = e.name;
        if (n.size() != name.size()) continue;
        bool same = true;
        for (size_t i = 0; i < n.size() && same; ++i)
            same = std::tolower(static_cast<unsigned char>(n[i])) == std::tolower(static_cast<unsigned char>(name[i]));
        if (same) return e.value;
    }
    return std::nullopt;
}

bool isFloatFormat(TexFormat f) { return formatRow(f).cls == FormatClass::Float; }

int formatBits(TexFormat f) { return isFloatFormat(f) ? 0 : int(formatRow(f).bytes * 8); }

}  // namespace ps11
