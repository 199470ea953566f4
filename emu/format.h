// Surface formats of the device: the rows of ps11/formats.h (bytes per texel in D3D9's memory
// layout, which uses each format allows) and the conversions between a texel's bytes and its
// channel values, driven by the rows' channels (docs/device.md "Formats").
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <string>

#include "emu/d3d9types.h"
#include "ps11/formats.h"
#include "ps11/hardware.h"
#include "ps11/texture.h"

namespace emu {

using ps11::FormatClass;

// A row of ps11/formats.h's table (the one place each format is described) with its D3DFORMAT
// typed for the device.
struct FormatInfo : ps11::FormatRow {
    D3DFORMAT format = D3DFMT_UNKNOWN;
};

// Facts about a format; nullptr for a format the device does not know.
const FormatInfo* formatInfo(D3DFORMAT format);
// The D3DFORMAT of a .ps11test format name (ps11::TexFormat), so the device can express the
// test model.
D3DFORMAT d3dFormatOf(ps11::TexFormat format);
// "A8R8G8B8", or "format 23" for an unknown value.
const char* formatName(D3DFORMAT format);
// The names of the render-target formats ("A8R8G8B8, X8R8G8B8, …") and of the depth formats,
// in row order, from the rows: what an error message lists as the formats a call takes.
const std::string& renderTargetFormatList();
const std::string& depthFormatList();

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
// The 32-bit word at p (any alignment), in the machine's byte order.
inline uint32_t load32(const uint8_t* p) {
    uint32_t w;
    std::memcpy(&w, p, 4);
    return w;
}

// IEEE half <-> float (round to nearest even, overflow to infinity): ps11/texture.h's, the one
// conversion of the project.
using ps11::floatToHalf;
using ps11::halfToFloat;

}  // namespace emu
