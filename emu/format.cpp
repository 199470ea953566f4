// Device stage: surface formats. The table of what each D3DFORMAT is (size in D3D9's memory
// layout, allowed uses) and the texel conversions used by Clear, StretchRect, mip generation
// and the hand-over to the sampler's ps11::Texture.
#include "emu/format.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "ps11/texture.h"

namespace emu {

namespace {

using TF = ps11::TexFormat;

// D3D9 memory layouts (d3d9types.h names list channels from the most significant bit; a texel
// is one little-endian word): A8R8G8B8 = bytes B G R A; A8L8 = L A; V8U8 = U V; L6V5U5 = U in
// bits 0-4, V 5-9, L 10-15; X8L8V8U8 = U V L X; Q8W8V8U8 = U V W Q; V16U16 = U (16) V (16);
// A16B16G16R16F = halves R G B A; A32B32G32R32F = floats R G B A.
constexpr FormatInfo kFormats[] = {
    {D3DFMT_A8R8G8B8, "A8R8G8B8", 4, FormatClass::Unorm8, true, true, false, 0, 0, TF::A8R8G8B8},
    {D3DFMT_X8R8G8B8, "X8R8G8B8", 4, FormatClass::Unorm8, true, true, false, 0, 0, TF::X8R8G8B8},
    {D3DFMT_A8, "A8", 1, FormatClass::Unorm8, true, false, false, 0, 0, TF::A8},
    {D3DFMT_L8, "L8", 1, FormatClass::Unorm8, true, false, false, 0, 0, TF::L8},
    {D3DFMT_A8L8, "A8L8", 2, FormatClass::Unorm8, true, false, false, 0, 0, TF::A8L8},
    {D3DFMT_V8U8, "V8U8", 2, FormatClass::Signed, true, false, false, 0, 0, TF::V8U8},
    {D3DFMT_L6V5U5, "L6V5U5", 2, FormatClass::Signed, true, false, false, 0, 0, TF::L6V5U5},
    {D3DFMT_X8L8V8U8, "X8L8V8U8", 4, FormatClass::Signed, true, false, false, 0, 0, TF::X8L8V8U8},
    {D3DFMT_Q8W8V8U8, "Q8W8V8U8", 4, FormatClass::Signed, true, false, false, 0, 0, TF::Q8W8V8U8},
    {D3DFMT_V16U16, "V16U16", 4, FormatClass::Signed, true, false, false, 0, 0, TF::V16U16},
    {D3DFMT_R32F, "R32F", 4, FormatClass::Float, true, true, false, 0, 0, TF::R32F},
    {D3DFMT_A16B16G16R16F, "A16B16G16R16F", 8, FormatClass::Float, true, true, false, 0, 0, TF::A16B16G16R16F},
    {D3DFMT_A32B32G32R32F, "A32B32G32R32F", 16, FormatClass::Float, true, true, false, 0, 0, TF::A32B32G32R32F},
    {D3DFMT_D16, "D16", 2, FormatClass::Depth, false, false, false, 16, 0, TF::A8R8G8B8},
    {D3DFMT_D16_LOCKABLE, "D16_LOCKABLE", 2, FormatClass::Depth, false, false, true, 16, 0, TF::A8R8G8B8},
    {D3DFMT_D24S8, "D24S8", 4, FormatClass::Depth, false, false, false, 24, 8, TF::A8R8G8B8},
    {D3DFMT_D24X8, "D24X8", 4, FormatClass::Depth, false, false, false, 24, 0, TF::A8R8G8B8},
    {D3DFMT_D32, "D32", 4, FormatClass::Depth, false, false, false, 32, 0, TF::A8R8G8B8},
    {D3DFMT_D32F_LOCKABLE, "D32F_LOCKABLE", 4, FormatClass::Depth, false, false, true, 32, 0, TF::A8R8G8B8},
};

float loadFloat(const uint8_t* p) {
    float f;
    std::memcpy(&f, p, 4);
    return f;
}

void storeFloat(float f, uint8_t* p) { std::memcpy(p, &f, 4); }

}  // namespace

const FormatInfo* formatInfo(D3DFORMAT format) {
    for (const FormatInfo& f : kFormats)
        if (f.format == format) return &f;
    return nullptr;
}

D3DFORMAT d3dFormatOf(ps11::TexFormat format) {
    for (const FormatInfo& f : kFormats)
        if (f.texture && f.texFormat == format) return f.format;
    return D3DFMT_UNKNOWN;
}

const char* formatName(D3DFORMAT format) {
    const FormatInfo* f = formatInfo(format);
    if (f) return f->name;
    static thread_local char buf[32];
    std::snprintf(buf, sizeof buf, "format %u", unsigned(format));
    return buf;
}

uint32_t loadWord(const uint8_t* p, uint32_t bytes) {
    uint32_t w = 0;
    for (uint32_t i = 0; i < bytes && i < 4; ++i) w |= uint32_t(p[i]) << (8 * i);
    return w;
}

std::array<uint8_t, 4> decodeUnorm8(const FormatInfo& f, const uint8_t* p) {
    switch (f.format) {
        case D3DFMT_A8R8G8B8:
            return {p[2], p[1], p[0], p[3]};
        case D3DFMT_X8R8G8B8:
            return {p[2], p[1], p[0], 255};
        case D3DFMT_A8:
            return {0, 0, 0, p[0]};
        case D3DFMT_L8:
            return {p[0], p[0], p[0], 255};
        case D3DFMT_A8L8:
            return {p[0], p[0], p[0], p[1]};
        default:
            return {0, 0, 0, 255};
    }
}

void encodeUnorm8(const FormatInfo& f, const std::array<uint8_t, 4>& c, uint8_t* p) {
    switch (f.format) {
        case D3DFMT_A8R8G8B8:
            p[0] = c[2], p[1] = c[1], p[2] = c[0], p[3] = c[3];
            break;
        case D3DFMT_X8R8G8B8:
            p[0] = c[2], p[1] = c[1], p[2] = c[0], p[3] = 255;
            break;
        case D3DFMT_A8:
            p[0] = c[3];
            break;
        case D3DFMT_L8:
            p[0] = c[0];
            break;
        case D3DFMT_A8L8:
            p[0] = c[0], p[1] = c[3];
            break;
        default:
            break;
    }
}

std::array<float, 4> decodeTexel(const FormatInfo& f, const uint8_t* p, ps11::SignedDecode decode) {
    if (f.cls == FormatClass::Unorm8) {
        std::array<uint8_t, 4> b = decodeUnorm8(f, p);
        return {float(b[0] / 255.0), float(b[1] / 255.0), float(b[2] / 255.0), float(b[3] / 255.0)};
    }
    const uint32_t w = loadWord(p, f.bytes);
    if (f.cls == FormatClass::Signed) return ps11::signedTexelValue(f.texFormat, w, decode);
    switch (f.format) {
        case D3DFMT_R32F:
            return {loadFloat(p), 1.0f, 1.0f, 1.0f};
        case D3DFMT_A16B16G16R16F: {
            std::array<float, 4> v;
            for (int c = 0; c < 4; ++c) v[size_t(c)] = halfToFloat(uint16_t(p[2 * c] | (p[2 * c + 1] << 8)));
            return v;
        }
        case D3DFMT_A32B32G32R32F:
            return {loadFloat(p), loadFloat(p + 4), loadFloat(p + 8), loadFloat(p + 12)};
        default:
            return {0, 0, 0, 1};
    }
}

void encodeFloat(const FormatInfo& f, const std::array<float, 4>& v, uint8_t* p) {
    switch (f.format) {
        case D3DFMT_R32F:
            storeFloat(v[0], p);
            break;
        case D3DFMT_A16B16G16R16F:
            for (int c = 0; c < 4; ++c) {
                const uint16_t h = floatToHalf(v[size_t(c)]);
                p[2 * c] = uint8_t(h & 0xff), p[2 * c + 1] = uint8_t(h >> 8);
            }
            break;
        case D3DFMT_A32B32G32R32F:
            for (int c = 0; c < 4; ++c) storeFloat(v[size_t(c)], p + 4 * c);
            break;
        default:
            break;
    }
}

}  // namespace emu
