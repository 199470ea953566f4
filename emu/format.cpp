// Device stage: surface formats. The device's view of ps11/formats.h's rows (what each
// D3DFORMAT is: size in D3D9's memory layout, allowed uses, channels) and the texel conversions
// they drive, used by Clear, StretchRect, mip generation and the hand-over to the sampler's
// ps11::Texture.
#include "emu/format.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "ps11/texture.h"

namespace emu {

namespace {

using ps11::Channel;
using ps11::ChannelKind;

// The device's view of every row of ps11::kFormatRows, in the same order.
const std::array<FormatInfo, std::size(ps11::kFormatRows)>& formats() {
    static const auto table = [] {
        std::array<FormatInfo, std::size(ps11::kFormatRows)> t{};
        for (size_t i = 0; i < t.size(); ++i) {
            static_cast<ps11::FormatRow&>(t[i]) = ps11::kFormatRows[i];
            t[i].format = D3DFORMAT(ps11::kFormatRows[i].d3d);
        }
        return t;
    }();
    return table;
}

uint32_t fieldMask(const Channel& ch) { return ch.bits >= 32 ? ~0u : ((uint32_t(1) << ch.bits) - 1) << ch.shift; }

void storeFloat(float f, uint8_t* p) { std::memcpy(p, &f, 4); }

}  // namespace

const FormatInfo* formatInfo(D3DFORMAT format) {
    for (const FormatInfo& f : formats())
        if (f.format == format) return &f;
    return nullptr;
}

D3DFORMAT d3dFormatOf(ps11::TexFormat format) {
    return size_t(format) < ps11::kTexFormatCount ? formats()[size_t(format)].format : D3DFMT_UNKNOWN;
}

const char* formatName(D3DFORMAT format) {
    const FormatInfo* f = formatInfo(format);
    if (f) return f->name;
    static thread_local char buf[32];
    std::snprintf(buf, sizeof buf, "format %u", unsigned(format));
    return buf;
}

namespace {

template <class Takes>
std::string namesOf(Takes takes) {
    std::string out;
    for (const FormatInfo& f : formats())
        if (takes(f)) out += (out.empty() ? "" : ", ") + std::string(f.name);
    return out;
}

}  // namespace

const std::string& renderTargetFormatList() {
    static const std::string names = namesOf([](const FormatInfo& f) { return f.renderTarget; });
    return names;
}

const std::string& depthFormatList() {
    static const std::string names = namesOf([](const FormatInfo& f) { return f.cls == FormatClass::Depth; });
    return names;
}

uint32_t loadWord(const uint8_t* p, uint32_t bytes) {
    uint32_t w = 0;
    for (uint32_t i = 0; i < bytes && i < 4; ++i) w |= uint32_t(p[i]) << (8 * i);
    return w;
}

std::array<uint8_t, 4> decodeUnorm8(const FormatInfo& f, const uint8_t* p) {
    return ps11::unorm8Channels(f, f.cls == FormatClass::Unorm8 ? loadWord(p, f.bytes) : 0);
}

void encodeUnorm8(const FormatInfo& f, const std::array<uint8_t, 4>& c, uint8_t* p) {
    if (f.cls != FormatClass::Unorm8) return;
    // Each field from the first channel it holds (L8's L from r); the pad bits (X) are 1s.
    uint32_t w = 0, written = 0;
    for (size_t i = 0; i < 4; ++i) {
        const Channel& ch = f.rgba[i];
        if (ch.kind != ChannelKind::Unorm || (written & fieldMask(ch))) continue;
        w |= uint32_t(c[i]) << ch.shift;
        written |= fieldMask(ch);
    }
    if (f.pad.bits) w |= fieldMask(f.pad);
    for (uint32_t b = 0; b < f.bytes; ++b) p[b] = uint8_t(w >> (8 * b));
}

std::array<float, 4> decodeTexel(const FormatInfo& f, const uint8_t* p, ps11::SignedDecode decode) {
    if (f.cls == FormatClass::Unorm8) {
        std::array<uint8_t, 4> b = decodeUnorm8(f, p);
        return {float(b[0] / 255.0), float(b[1] / 255.0), float(b[2] / 255.0), float(b[3] / 255.0)};
    }
    if (f.cls == FormatClass::Signed) return ps11::signedTexelValue(f.texFormat, loadWord(p, f.bytes), decode);
    return ps11::floatChannels(f, p);
}

void encodeFloat(const FormatInfo& f, const std::array<float, 4>& v, uint8_t* p) {
    if (f.cls != FormatClass::Float) return;
    for (size_t c = 0; c < 4; ++c) {
        const Channel& ch = f.rgba[c];
        uint8_t* q = p + ch.shift / 8;
        if (ch.kind == ChannelKind::Float) {
            storeFloat(v[c], q);
        } else if (ch.kind == ChannelKind::Half) {
            const uint16_t h = floatToHalf(v[c]);
            q[0] = uint8_t(h & 0xff), q[1] = uint8_t(h >> 8);
        }
    }
}

}  // namespace emu
