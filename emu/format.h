// Surface formats of the device: bytes per texel in D3D9's memory layout, which uses each
// format allows, and the conversions between a texel's bytes and its channel values
// (docs/device.md "Formats").
#pragma once

#include <array>
#include <cstdint>

#include "emu/d3d9types.h"
#include "ps11/hardware.h"
#include "ps11/testfile.h"
#include "ps11/texture.h"

namespace emu {

enum class FormatClass : uint8_t {
    Unorm8,  // 8-bit unsigned channels (A8R8G8B8, X8R8G8B8, A8, L8, A8L8)
    Signed,  // bump formats with signed channels (V8U8, L6V5U5, X8L8V8U8, Q8W8V8U8, V16U16)
    Float,   // R32F, A16B16G16R16F, A32B32G32R32F
    Depth,   // D16, D24S8, D24X8, D32, D16_LOCKABLE, D32F_LOCKABLE
};

struct FormatInfo {
    D3DFORMAT format = D3DFMT_UNKNOWN;
    const char* name = "UNKNOWN";
    uint32_t bytes = 0;  // per texel
    FormatClass cls = FormatClass::Unorm8;
    bool texture = false;        // CreateTexture / CreateVolumeTexture take it
    bool renderTarget = false;   // D3DUSAGE_RENDERTARGET / CreateRenderTarget / StretchRect
    bool lockableDepth = false;  // a depth format LockRect may lock (the _LOCKABLE ones)
    uint32_t depthBits = 0, stencilBits = 0;
    ps11::TexFormat texFormat = ps11::TexFormat::A8R8G8B8;  // the sampler's name for it
};

// Facts about a format; nullptr for a format the device does not know.
const FormatInfo* formatInfo(D3DFORMAT format);
// The D3DFORMAT of a .ps11test format name (ps11::TexFormat), so the device can express the
// test model.
D3DFORMAT d3dFormatOf(ps11::TexFormat format);
// "A8R8G8B8", or "format 23" for an unknown value.
const char* formatName(D3DFORMAT format);

// Channel values of one texel stored at p (D3D layout), as the sampler reads them: r g b a,
// missing channels 1 except A8's rgb 0 (ps1x-spec §6.4); signed channels decoded by the
// hardware class's rule (ps11::signedTexelValue). Not for depth formats.
std::array<float, 4> decodeTexel(const FormatInfo& f, const uint8_t* p, ps11::SignedDecode decode);
// Unorm8 formats only: the four channel bytes r g b a (missing channels 255, A8's rgb 0).
std::array<uint8_t, 4> decodeUnorm8(const FormatInfo& f, const uint8_t* p);
// Writes r g b a bytes into a Unorm8 texel (channels the format lacks are dropped; X8's X byte
// gets 0xff).
void encodeUnorm8(const FormatInfo& f, const std::array<uint8_t, 4>& rgba, uint8_t* p);
// Writes float channels into a Float-class texel (half-precision for A16B16G16R16F).
void encodeFloat(const FormatInfo& f, const std::array<float, 4>& rgba, uint8_t* p);
// The texel word a packed (<= 32-bit) format stores at p, little endian.
uint32_t loadWord(const uint8_t* p, uint32_t bytes);

// IEEE half <-> float (round to nearest even, overflow to infinity): ps11/texture.h's, the one
// conversion of the project.
using ps11::floatToHalf;
using ps11::halfToFloat;

}  // namespace emu
