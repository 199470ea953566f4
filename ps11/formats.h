// Texture formats, filters and address modes as the runtime names them: the textures, the
// sampler, the device and the .ps11test model all use these (the model reads its words from
// here, not the other way round).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace ps11 {

// A name and the value it stands for (format names, and the .ps11test reader's word tables).
template <class E>
struct NameEntry {
    const char* name;
    E value;
};

// Texture formats (D3DFMT_* without the prefix) the textures and the sampler decode; each is
// the index of its row in kFormatRows.
enum class TexFormat : uint8_t {
    A8R8G8B8,
    X8R8G8B8,
    A8,
    L8,
    A8L8,
    V8U8,
    L6V5U5,
    X8L8V8U8,
    Q8W8V8U8,
    V16U16,
    A16B16G16R16F,
    A32B32G32R32F,
    R32F,
};
constexpr size_t kTexFormatCount = 13;

enum class FormatClass : uint8_t {
    Unorm8,  // 8-bit unsigned channels (A8R8G8B8, X8R8G8B8, A8, L8, A8L8)
    Signed,  // bump formats with signed channels (V8U8, L6V5U5, X8L8V8U8, Q8W8V8U8, V16U16)
    Float,   // R32F, A16B16G16R16F, A32B32G32R32F
    Depth,   // D16, D24S8, D24X8, D32, D16_LOCKABLE, D32F_LOCKABLE
};

// Where one channel of the sampler's view (r g b a) comes from.
enum class ChannelKind : uint8_t {
    Zero,   // the constant 0 (A8's rgb, ps1x-spec §6.4)
    One,    // the constant 1 (a channel the format lacks)
    Unorm,  // an unsigned field, value = field / (2^bits - 1)
    Snorm,  // a signed (bump) field, decoded by the hardware class's SignedDecode
    Half,   // an IEEE half at bit `shift` of the texel
    Float,  // an IEEE float at bit `shift` of the texel
};

// One channel: its kind and the bit field of the texel (little endian, bit 0 = first byte's
// lowest) that holds it.
struct Channel {
    ChannelKind kind = ChannelKind::One;
    uint8_t shift = 0, bits = 0;
};

// Everything about one D3DFORMAT, stated once: the device, the textures, the sampler and the
// .ps11test model derive their facts from these rows (docs/device.md "Formats").
struct FormatRow {
    uint32_t d3d = 0;       // its D3DFORMAT value (d3d9types.h)
    const char* name = "";  // D3DFMT_ name without the prefix
    uint32_t bytes = 0;     // per texel in D3D9's memory layout
    FormatClass cls = FormatClass::Unorm8;
    std::array<Channel, 4> rgba{};  // the sampler's view: r g b a (texture formats)
    Channel pad{};                  // stored bits no channel reads (the X of X8*): written 1s, mip-averaged
    bool texture = false;           // CreateTexture / CreateVolumeTexture take it
    bool renderTarget = false;      // D3DUSAGE_RENDERTARGET / CreateRenderTarget / StretchRect
    bool lockableDepth = false;     // a depth format LockRect may lock (the _LOCKABLE ones)
    uint32_t depthBits = 0, stencilBits = 0;
    bool depthFloat = false;                    // a depth format whose depth is a float32 (D32F_LOCKABLE), else unorm
    TexFormat texFormat = TexFormat::A8R8G8B8;  // the sampler's name for it (texture formats)
};

// Every format the project knows: first the texture formats in TexFormat order (row i is
// TexFormat i), then the depth formats.
extern const FormatRow kFormatRows[19];
// The row of a texture format.
const FormatRow& formatRow(TexFormat f);

// Every texture format with its name, in enum order (from kFormatRows).
extern const NameEntry<TexFormat> kTexFormatNames[kTexFormatCount];
// The texture formats a render target may take (kFormatRows' renderTarget), with their names,
// in enum order: what a .ps11test [render target] accepts.
constexpr size_t kRenderTargetFormatCount = 5;
extern const NameEntry<TexFormat> kRenderTargetFormatNames[kRenderTargetFormatCount];
const char* texFormatName(TexFormat f);
std::optional<TexFormat> parseTexFormat(std::string_view name);  // case-insensitive
bool isFloatFormat(TexFormat f);
int formatBits(TexFormat f);  // bits per texel of a packed format (0 for float formats)

enum class Filter : uint8_t { None = 0, Point = 1, Linear = 2 };  // D3DTEXF_*
// D3DTADDRESS_* (values as in d3d9types.h).
enum class TextureAddress : uint8_t { Wrap = 1, Mirror = 2, Clamp = 3, Border = 4, MirrorOnce = 5 };

}  // namespace ps11
