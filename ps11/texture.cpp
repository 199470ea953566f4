// Software textures: decoding texel words and float tuples into per-channel storage,
// mip chain generation (2x2 / 2x2x2 box, rounded half-even in the stored representation) and
// the per-profile grid values the sampler reads (docs/textures.md, docs/precision.md "Inputs").
#include "ps11/texture.h"
#include "ps11/texture_internal.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

namespace ps11 {

namespace {

// Per format, from its row (ps11/formats.h): how channels are stored and, for integer formats
// stored Decoded, each channel's signed width (bump channels, decoded by the hardware class's
// SignedDecode) or, for the other channels, the denominator (value = raw / den: unsigned L, and
// the constant 1 of missing ones).
struct FormatInfo {
    TexelStorage storage = TexelStorage::Unorm8;
    bool floats = false;  // float32/float16 channels
    bool half = false;    // A16B16G16R16F: values rounded to half precision
    std::array<int8_t, 4> signedBits{0, 0, 0, 0};
    std::array<int32_t, 4> den{1, 1, 1, 1};
};

FormatInfo formatInfo(TexFormat f) {
    const FormatRow& row = formatRow(f);
    FormatInfo i;
    i.storage = row.cls == FormatClass::Unorm8 ? TexelStorage::Unorm8 : TexelStorage::Decoded;
    i.floats = row.cls == FormatClass::Float;
    for (size_t c = 0; c < 4; ++c) {
        const Channel& ch = row.rgba[c];
        i.half = i.half || ch.kind == ChannelKind::Half;
        if (ch.kind == ChannelKind::Snorm) i.signedBits[c] = int8_t(ch.bits);
        if (ch.kind == ChannelKind::Unorm) i.den[c] = int32_t((uint32_t(1) << ch.bits) - 1);
    }
    return i;
}

int32_t signExtend(uint32_t v, int bits) {
    uint32_t m = uint32_t(1) << (bits - 1);
    v &= (uint32_t(1) << bits) - 1;
    return int32_t(v ^ m) - int32_t(m);
}

uint32_t fieldOf(const Channel& ch, uint32_t w) {
    return ch.bits >= 32 ? w >> ch.shift : (w >> ch.shift) & ((uint32_t(1) << ch.bits) - 1);
}

// A packed word of an Unorm8 format -> the stored bytes b g r a (kUnorm8Byte). A8R8G8B8 keeps
// D3D's byte order, so its hand-over is a copy.
std::array<uint8_t, 4> storedUnorm8(const FormatRow& row, uint32_t w) {
    const std::array<uint8_t, 4> rgba = unorm8Channels(row, w);
    std::array<uint8_t, 4> out{};
    for (size_t c = 0; c < 4; ++c) out[size_t(kUnorm8Byte[c])] = rgba[c];
    return out;
}

// A packed word of a signed (bump) format -> raw channel integers: signed codes where
// FormatInfo::signedBits says so, else over FormatInfo::den (the row's channels:
// r = U, g = V, b = L or W (else 1), a = Q (else 1); docs/textures.md).
std::array<int32_t, 4> decodeSigned(const FormatRow& row, uint32_t w) {
    std::array<int32_t, 4> out{0, 0, 0, 1};
    if (row.cls != FormatClass::Signed) return out;
    for (size_t c = 0; c < 4; ++c) {
        const Channel& ch = row.rgba[c];
        out[c] = ch.kind == ChannelKind::Snorm   ? signExtend(w >> ch.shift, ch.bits)
                 : ch.kind == ChannelKind::Unorm ? int32_t(fieldOf(ch, w))
                 : ch.kind == ChannelKind::Zero  ? 0
                                                 : 1;
    }
    return out;
}

// Float texel values (channels not given are 0 0 0 1): the channels the format has,
// half-rounded where it stores halves; the others 1 (Zero channels 0).
std::array<float, 4> decodeFloat(const FormatRow& row, const std::array<float, 4>& value) {
    std::array<float, 4> v = value;
    for (size_t c = 0; c < 4; ++c) {
        const ChannelKind k = row.rgba[c].kind;
        v[c] = k == ChannelKind::Half    ? roundToHalf(v[c])
               : k == ChannelKind::Float ? v[c]
               : k == ChannelKind::Zero  ? 0.0f
                                         : 1.0f;
    }
    return v;
}

uint32_t extentAt(uint32_t size, uint32_t level) { return level >= 32 ? 1 : std::max<uint32_t>(1, size >> level); }

// Box-filters level `src` into level `dst` (2x2, or 2x2x2 for volumes). Source coordinates
// 2x and 2x+1 are clamped to the source extent, so a dimension already at 1 averages one texel
// twice and odd extents drop their last row/column (as D3DX's box filter for power-of-two
// chains; docs/textures.md).
template <class T, class Avg>
void boxDown(std::vector<T>& data, const TextureLevelInfo& src, const TextureLevelInfo& dst, bool volume, Avg avg) {
    int n = volume ? 8 : 4;
    for (uint32_t z = 0; z < dst.depth; ++z)
        for (uint32_t y = 0; y < dst.height; ++y)
            for (uint32_t x = 0; x < dst.width; ++x) {
                size_t taps[8];
                int k = 0;
                for (uint32_t dz = 0; dz < (volume ? 2u : 1u); ++dz)
                    for (uint32_t dy = 0; dy < 2; ++dy)
                        for (uint32_t dx = 0; dx < 2; ++dx) {
                            uint32_t sx = std::min(2 * x + dx, src.width - 1);
                            uint32_t sy = std::min(2 * y + dy, src.height - 1);
                            uint32_t sz = std::min(2 * z + dz, src.depth - 1);
                            taps[k++] = src.offset + (size_t(sz) * src.height + sy) * src.width + sx;
                        }
                size_t out = dst.offset + (size_t(z) * dst.height + y) * dst.width + x;
                for (int c = 0; c < 4; ++c) data[out * 4 + c] = avg(data, taps, n, c);
            }
}

}  // namespace

uint32_t fullMipCount(uint32_t width, uint32_t height, uint32_t depth) {
    uint32_t m = std::max({width, height, depth, 1u});
    uint32_t n = 1;
    while (m > 1) m >>= 1, ++n;
    return n;
}

uint16_t floatToHalf(float v) {
    const uint32_t x = std::bit_cast<uint32_t>(v);
    const uint16_t sign = uint16_t((x >> 16) & 0x8000);
    if (std::isnan(v)) return uint16_t(sign | 0x7e00);
    const double a = std::fabs(double(v));
    if (a >= 65520.0) return uint16_t(sign | 0x7c00);  // beyond the largest half + half a step
    if (a == 0.0) return sign;
    int e = 0;
    std::frexp(a, &e);                                            // a = m * 2^e, m in [0.5, 1)
    const int quantumExp = std::max(e - 11, -24);                 // 11 significant bits; subnormals step 2^-24
    const double q = std::nearbyint(std::ldexp(a, -quantumExp));  // ties to even
    const double r = std::ldexp(q, quantumExp);
    if (r < std::ldexp(1.0, -14)) return uint16_t(sign | uint16_t(std::ldexp(r, 24)));  // subnormal
    int re = 0;
    const double m = std::frexp(r, &re);  // r = m * 2^re, m in [0.5, 1)
    const uint32_t exponent = uint32_t(re - 1 + 15);
    const uint32_t mantissa = uint32_t(std::ldexp(m * 2.0 - 1.0, 10));
    return uint16_t(sign | (exponent << 10) | mantissa);
}

const float* Texture::unorm8Values() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = float(double(i) / 255.0);
        return t;
    }();
    return table.data();
}

size_t Texture::texelIndex(int level, uint32_t x, uint32_t y, uint32_t z) const {
    const TextureLevelInfo& l = m_levels[size_t(level)];
    x = std::min(x, l.width - 1), y = std::min(y, l.height - 1), z = std::min(z, l.depth - 1);
    return l.offset + (size_t(z) * l.height + y) * l.width + x;
}

FloatTexels Texture::floatTexels() const {
    FloatTexels f;
    if (!m_rawView) {
        f.base = reinterpret_cast<const uint8_t*>(values());
        return f;
    }
    const FormatRow& row = formatRow(m_format);
    f.base = m_rawView.get();
    f.stride = row.bytes;
    for (size_t c = 0; c < 4; ++c) {
        f.kind[c] = row.rgba[c].kind;
        f.offset[c] = uint8_t(row.rgba[c].shift / 8);
    }
    return f;
}

std::array<float, 4> Texture::texelValue(int level, uint32_t x, uint32_t y, uint32_t z) const {
    const size_t i = texelIndex(level, x, y, z);
    std::array<float, 4> v;
    if (m_storage == TexelStorage::Unorm8) {
        for (size_t c = 0; c < 4; ++c) v[c] = unorm8Values()[unorm8()[i * 4 + size_t(kUnorm8Byte[c])]];
    } else {
        floatTexels().get(i, v.data());
    }
    return v;
}

std::array<int32_t, 4> Texture::texelGrid(int level, uint32_t x, uint32_t y, uint32_t z, Precision p) const {
    const size_t i = texelIndex(level, x, y, z);
    std::array<int32_t, 4> g{};
    if (m_storage == TexelStorage::Unorm8) {
        const int32_t scale = gridScale(p) / 255;
        for (size_t c = 0; c < 4; ++c) g[c] = int32_t(unorm8()[i * 4 + size_t(kUnorm8Byte[c])]) * scale;
    } else if (readsInPlace()) {  // one texel's grid, not the whole texture's (grid())
        const std::array<float, 4> v = texelValue(level, x, y, z);
        for (size_t c = 0; c < 4; ++c) g[c] = texelGridOf(v[c], p);
    } else {
        for (size_t c = 0; c < 4; ++c) g[c] = grid(p)[i * 4 + c];
    }
    return g;
}

bool Texture::layout(TexFormat fmt, bool volume, uint32_t width, uint32_t height, uint32_t depth, uint32_t count,
                     std::string& error) {
    const FormatInfo info = formatInfo(fmt);
    m_format = fmt;
    m_volume = volume;
    m_storage = info.storage;
    m_levels.clear();
    size_t total = 0;
    for (uint32_t k = 0; k < count; ++k) {
        TextureLevelInfo l;
        l.width = extentAt(width, k);
        l.height = extentAt(height, k);
        l.depth = extentAt(depth, k);
        l.offset = total;
        total += size_t(l.width) * l.height * l.depth;
        m_levels.push_back(l);
    }
    m_texelCount = total;
    // Unorm8: 4 bytes; Decoded: 16 (float) + 32 (two grids) + 16 (raw while building).
    const uint64_t bytesPerTexel = info.storage == TexelStorage::Unorm8 ? 4 : 64;
    if (uint64_t(total) * bytesPerTexel > kMaxResourceBytes) {
        error = "texture needs " + std::to_string(uint64_t(total) * bytesPerTexel) + " bytes (" +
                std::to_string(total) + " texels of " + texFormatName(fmt) + "), more than the limit of " +
                std::to_string(kMaxResourceBytes);
        return false;
    }
    return true;
}

void Texture::finishDecoded(const std::vector<int32_t>& raw, std::vector<float>&& rawf, SignedDecode decode) {
    m_signedDecode = decode;
    const FormatInfo info = formatInfo(m_format);
    if (info.floats) {
        m_value = std::move(rawf);  // the grids follow on first use (grid())
        return;
    }
    const size_t n = m_texelCount * 4;
    m_value.resize(n);
    Grids& g = *m_grids;
    g.g8.resize(n);
    g.g12.resize(n);
    for (size_t i = 0; i < n; ++i) {
        const size_t c = i & 3;
        // docs/precision.md "Signed texels": the class's rational num/den; fx grids
        // round_half_even(num*G/den), exact.
        const SignedValue sv = info.signedBits[c] ? decodeSignedChannel(decode, raw[i], info.signedBits[c])
                                                  : SignedValue{raw[i], info.den[c]};
        m_value[i] = float(double(sv.num) / double(sv.den));
        g.g8[i] = int32_t(roundHalfEven(sv.num * 255, sv.den));
        g.g12[i] = int32_t(roundHalfEven(sv.num * 4080, sv.den));
    }
}

const int32_t* Texture::grid(Precision p) const {
    Grids& g = *m_grids;
    const bool fx12 = p == Precision::Fx12;
    std::vector<int32_t>& out = fx12 ? g.g12 : g.g8;
    if (formatInfo(m_format).floats)
        std::call_once(fx12 ? g.once12 : g.once8, [&] {
            const Precision q = fx12 ? Precision::Fx12 : Precision::Fx8;
            const FloatTexels f = floatTexels();
            out.resize(m_texelCount * 4);
            for (size_t i = 0; i < m_texelCount; ++i) {
                float v[4];
                f.get(i, v);
                for (size_t c = 0; c < 4; ++c) out[i * 4 + c] = texelGridOf(v[c], q);
            }
        });
    return out.data();
}

std::array<float, 4> signedTexelValue(TexFormat f, uint32_t word, SignedDecode decode) {
    const FormatInfo info = formatInfo(f);
    const std::array<int32_t, 4> raw = decodeSigned(formatRow(f), word);
    std::array<float, 4> v{0, 0, 0, 1};
    for (size_t c = 0; c < 4; ++c) {
        const SignedValue sv = info.signedBits[c] ? decodeSignedChannel(decode, raw[c], info.signedBits[c])
                                                  : SignedValue{raw[c], info.den[c]};
        v[c] = float(double(sv.num) / double(sv.den));
    }
    return v;
}

bool TextureBuilder::start(TexFormat fmt, bool volume, uint32_t width, uint32_t height, uint32_t depth,
                           uint32_t count, std::string& error) {
    const FormatInfo info = formatInfo(fmt);
    m_row = &formatRow(fmt);
    m_storage = info.storage;
    m_floats = info.floats;
    m_half = info.half;
    depth = volume ? depth : 1;
    if (width == 0 || height == 0) {
        error = "texture has no size";
        return false;
    }
    if (width > kMaxTextureSide || height > kMaxTextureSide || depth > kMaxVolumeSide) {
        error = "texture size " + std::to_string(width) + "x" + std::to_string(height) +
                (volume ? "x" + std::to_string(depth) : "") + " is beyond the limits (" +
                std::to_string(kMaxTextureSide) + " per side, depth " + std::to_string(kMaxVolumeSide) + ")";
        return false;
    }
    const uint32_t possible = fullMipCount(width, height, depth);
    if (count == 0) count = possible;
    if (count > possible) {
        error = "levels " + std::to_string(count) + " is more than the texture has (" + std::to_string(possible) + ")";
        return false;
    }
    if (!m_texture.layout(fmt, volume, width, height, depth, count, error)) return false;
    const size_t total = m_texture.m_texelCount;
    if (m_storage == TexelStorage::Unorm8)
        m_texture.m_u8.assign(total * 4, 0);
    else if (m_floats)
        m_rawf.assign(total * 4, 0.0f);
    else
        m_raw.assign(total * 4, 0);
    return true;
}

uint32_t TextureBuilder::levelCount() const { return uint32_t(m_texture.m_levels.size()); }

const TextureLevelInfo& TextureBuilder::level(uint32_t k) const { return m_texture.m_levels[k]; }

void TextureBuilder::storeWord(size_t index, uint32_t word) {
    if (m_storage == TexelStorage::Unorm8) {
        const std::array<uint8_t, 4> b = storedUnorm8(*m_row, word);
        std::copy(b.begin(), b.end(), m_texture.m_u8.begin() + ptrdiff_t(index * 4));
    } else if (!m_floats) {
        const std::array<int32_t, 4> r = decodeSigned(*m_row, word);
        std::copy(r.begin(), r.end(), m_raw.begin() + ptrdiff_t(index * 4));
    }
}

void TextureBuilder::storeFloats(size_t index, const std::array<float, 4>& value) {
    if (!m_floats) return;
    const std::array<float, 4> v = decodeFloat(*m_row, value);
    std::copy(v.begin(), v.end(), m_rawf.begin() + ptrdiff_t(index * 4));
}

void TextureBuilder::generateLevel(uint32_t k) {
    const TextureLevelInfo& src = m_texture.m_levels[k - 1];
    const TextureLevelInfo& li = m_texture.m_levels[k];
    const bool volume = m_texture.m_volume;
    if (m_storage == TexelStorage::Unorm8) {
        boxDown(m_texture.m_u8, src, li, volume, [](const std::vector<uint8_t>& d, const size_t* taps, int m, int c) {
            int64_t s = 0;
            for (int i = 0; i < m; ++i) s += d[taps[i] * 4 + size_t(c)];
            return uint8_t(roundHalfEven(s, m));
        });
    } else if (m_floats) {
        const bool half = m_half;
        boxDown(m_rawf, src, li, volume, [half](const std::vector<float>& d, const size_t* taps, int m, int c) {
            double s = 0;
            for (int i = 0; i < m; ++i) s += double(d[taps[i] * 4 + size_t(c)]);
            float v = float(s / m);
            return half ? roundToHalf(v) : v;
        });
    } else {
        boxDown(m_raw, src, li, volume, [](const std::vector<int32_t>& d, const size_t* taps, int m, int c) {
            int64_t s = 0;
            for (int i = 0; i < m; ++i) s += d[taps[i] * 4 + size_t(c)];
            return int32_t(roundHalfEven(s, m));
        });
    }
}

Texture TextureBuilder::finish(SignedDecode decode) {
    if (m_storage == TexelStorage::Decoded) m_texture.finishDecoded(m_raw, std::move(m_rawf), decode);
    return std::move(m_texture);
}

uint32_t bytesPerTexel(TexFormat f) { return formatRow(f).bytes; }

namespace {

inline uint32_t loadLE(const uint8_t* p, uint32_t bytes) {
    uint32_t w = 0;
    for (uint32_t i = 0; i < bytes; ++i) w |= uint32_t(p[i]) << (8 * i);
    return w;
}

inline float loadF32(const uint8_t* p) {
    float f;
    std::memcpy(&f, p, 4);
    return f;
}

// The bytes per texel of a format whose D3D9 texels are already the texture's stored form, so
// that its levels can be read where they lie: an Unorm8 format whose four channels sit in the b g r
// a bytes of a word (kUnorm8Byte: A8R8G8B8; with `padOnes`, X8R8G8B8 too, its alpha read 1 from
// pad bits known to be 1s), or a Float format of four float32 r g b a (A32B32G32R32F); 0 for every
// other format.
uint32_t storedAsIs(const FormatRow& row, bool padOnes = false) {
    const uint32_t unit = row.cls == FormatClass::Unorm8 ? 8 : row.cls == FormatClass::Float ? 32 : 0;
    if (!unit || row.bytes != 4 * unit / 8) return 0;
    for (size_t c = 0; c < 4; ++c) {
        const ChannelKind kind = unit == 8 ? ChannelKind::Unorm : ChannelKind::Float;
        const uint32_t at = unit == 8 ? uint32_t(kUnorm8Byte[c]) * 8 : uint32_t(c) * 32;
        // (A channel that reads 1 where the pad's 8 bits of 1s sit reads the same from them.)
        const Channel ch = padOnes && unit == 8 && row.rgba[c].kind == ChannelKind::One && row.pad.bits == 8
                               ? Channel{ChannelKind::Unorm, row.pad.shift, row.pad.bits}
                               : row.rgba[c];
        if (ch.kind != kind || ch.shift != at || ch.bits != unit) return 0;
    }
    return row.bytes;
}

// One row of an Unorm8 format into b g r a words: a copy where the format's layout is the stored
// one (storedAsIs), else each stored byte from the texel byte that holds its channel, or a constant.
void unorm8Row(const FormatRow& row, const uint8_t* src, uint32_t width, uint8_t* dst) {
    std::array<int, 4> from{};      // per stored byte: the texel byte it copies, or -1
    std::array<uint8_t, 4> fill{};  // the constant of a byte no texel byte gives
    for (size_t c = 0; c < 4; ++c) {
        const Channel& ch = row.rgba[c];
        const size_t b = size_t(kUnorm8Byte[c]);
        from[b] = ch.kind == ChannelKind::Unorm ? ch.shift / 8 : -1;
        fill[b] = ch.kind == ChannelKind::Zero ? 0 : 255;
    }
    if (storedAsIs(row)) {
        std::memcpy(dst, src, size_t(width) * 4);  // D3D's byte order is the stored order
        return;
    }
    for (uint32_t x = 0; x < width; ++x, src += row.bytes, dst += 4)
        for (size_t b = 0; b < 4; ++b) dst[b] = from[b] >= 0 ? src[from[b]] : fill[b];
}

}  // namespace

std::array<uint8_t, 4> unorm8Channels(const FormatRow& row, uint32_t word) {
    std::array<uint8_t, 4> out{0, 0, 0, 255};
    if (row.cls != FormatClass::Unorm8) return out;
    for (size_t c = 0; c < 4; ++c) {
        const Channel& ch = row.rgba[c];
        out[c] = ch.kind == ChannelKind::Unorm ? uint8_t(fieldOf(ch, word)) : ch.kind == ChannelKind::Zero ? 0 : 255;
    }
    return out;
}

std::array<float, 4> floatChannels(const FormatRow& row, const uint8_t* p) {
    std::array<float, 4> out{0, 0, 0, 1};
    if (row.cls != FormatClass::Float) return out;
    for (size_t c = 0; c < 4; ++c) {
        const Channel& ch = row.rgba[c];
        const uint8_t* q = p + ch.shift / 8;
        out[c] = ch.kind == ChannelKind::Float  ? loadF32(q)
                 : ch.kind == ChannelKind::Half ? halfToFloat(uint16_t(loadLE(q, 2)))
                 : ch.kind == ChannelKind::Zero ? 0.0f
                                                : 1.0f;
    }
    return out;
}

std::optional<Texture> Texture::fromLevels(TexFormat fmt, bool volume, const TextureLevelBytes* levels,
                                           size_t levelCount, SignedDecode decode, std::string& error,
                                           std::shared_ptr<const void> owner, bool padOnes) {
    static_assert(std::endian::native == std::endian::little, "Unorm8 words are stored little endian");
    if (levelCount == 0 || !levels) {
        error = "texture has no levels";
        return std::nullopt;
    }
    const TextureLevelBytes& l0 = levels[0];
    const uint32_t depth = volume ? l0.depth : 1;
    if (l0.width == 0 || l0.height == 0 || depth == 0) {
        error = "texture has no size";
        return std::nullopt;
    }
    if (l0.width > kMaxTextureSide || l0.height > kMaxTextureSide || depth > kMaxVolumeSide) {
        error = "texture size " + std::to_string(l0.width) + "x" + std::to_string(l0.height) +
                (volume ? "x" + std::to_string(depth) : "") + " is beyond the limits (" +
                std::to_string(kMaxTextureSide) + " per side, depth " + std::to_string(kMaxVolumeSide) + ")";
        return std::nullopt;
    }
    const uint32_t possible = fullMipCount(l0.width, l0.height, depth);
    if (levelCount > possible) {
        error =
            "levels " + std::to_string(levelCount) + " is more than the texture has (" + std::to_string(possible) + ")";
        return std::nullopt;
    }
    Texture t;
    if (!t.layout(fmt, volume, l0.width, l0.height, depth, uint32_t(levelCount), error)) return std::nullopt;
    const uint32_t bpt = bytesPerTexel(fmt);
    for (size_t k = 0; k < levelCount; ++k) {
        const TextureLevelInfo& li = t.m_levels[k];
        const TextureLevelBytes& lb = levels[k];
        if (lb.width != li.width || lb.height != li.height || (volume ? lb.depth : 1) != li.depth) {
            error = "level " + std::to_string(k) + " is " + std::to_string(lb.width) + "x" + std::to_string(lb.height) +
                    (volume ? "x" + std::to_string(lb.depth) : "") + ", expected " + std::to_string(li.width) + "x" +
                    std::to_string(li.height) + (volume ? "x" + std::to_string(li.depth) : "");
            return std::nullopt;
        }
        if (!lb.data || lb.rowPitch < size_t(li.width) * bpt ||
            (li.depth > 1 && lb.slicePitch < lb.rowPitch * li.height)) {
            error = "level " + std::to_string(k) + " has no data or a pitch smaller than its rows";
            return std::nullopt;
        }
    }

    const FormatInfo info = formatInfo(fmt);
    const FormatRow& row = formatRow(fmt);
    const size_t total = t.m_texelCount;
    auto forEachRow = [&](auto&& row) {
        for (size_t k = 0; k < levelCount; ++k) {
            const TextureLevelInfo& li = t.m_levels[k];
            const TextureLevelBytes& lb = levels[k];
            for (uint32_t z = 0; z < li.depth; ++z)
                for (uint32_t y = 0; y < li.height; ++y)
                    row(lb.data + z * lb.slicePitch + y * lb.rowPitch, li.width,
                        li.offset + (size_t(z) * li.height + y) * li.width);
        }
    };
    // In place: a format stored as it is (storedAsIs: A8R8G8B8's word is the stored b g r a order,
    // A32B32G32R32F's four floats the stored r g b a values), or any other float format (read
    // through its row: floatTexels), when the levels follow each other exactly at the texture's
    // own texel offsets.
    const size_t asIs = storedAsIs(row, padOnes);
    const bool viaRow = !asIs && row.cls == FormatClass::Float;
    const size_t inPlaceBytes = viaRow ? row.bytes : asIs;
    bool inPlace =
        owner && inPlaceBytes && (inPlaceBytes == 4 || viaRow || reinterpret_cast<uintptr_t>(levels[0].data) % 4 == 0);
    for (size_t k = 0; inPlace && k < levelCount; ++k) {
        const TextureLevelInfo& li = t.m_levels[k];
        const TextureLevelBytes& lb = levels[k];
        inPlace = lb.data == levels[0].data + li.offset * inPlaceBytes && lb.rowPitch == size_t(li.width) * inPlaceBytes &&
                  (li.depth == 1 || lb.slicePitch == lb.rowPitch * li.height);
    }
    if (inPlace && viaRow) {
        t.m_signedDecode = decode;
        t.m_rawView = std::shared_ptr<const uint8_t>(std::move(owner), levels[0].data);
        return t;
    }
    if (inPlace && inPlaceBytes == 4) {
        t.m_u8view = std::shared_ptr<const uint8_t>(std::move(owner), levels[0].data);
        return t;
    }
    if (inPlace) {
        t.m_signedDecode = decode;
        t.m_valueView = std::shared_ptr<const float>(std::move(owner), reinterpret_cast<const float*>(levels[0].data));
        return t;
    }
    if (info.storage == TexelStorage::Unorm8) {
        t.m_u8.resize(total * 4);
        forEachRow([&](const uint8_t* src, uint32_t width, size_t first) {
            unorm8Row(row, src, width, t.m_u8.data() + first * 4);
        });
        return t;
    }
    std::vector<int32_t> raw;
    std::vector<float> rawf;
    if (info.floats) {
        rawf.resize(total * 4);
        forEachRow([&](const uint8_t* src, uint32_t width, size_t first) {
            float* d = rawf.data() + first * 4;
            for (uint32_t x = 0; x < width; ++x, d += 4) {
                const std::array<float, 4> v = floatChannels(row, src + size_t(x) * bpt);
                std::copy(v.begin(), v.end(), d);
            }
        });
    } else {
        raw.resize(total * 4);
        forEachRow([&](const uint8_t* src, uint32_t width, size_t first) {
            int32_t* d = raw.data() + first * 4;
            for (uint32_t x = 0; x < width; ++x, d += 4) {
                const std::array<int32_t, 4> r = decodeSigned(row, loadLE(src + size_t(x) * bpt, bpt));
                std::copy(r.begin(), r.end(), d);
            }
        });
    }
    t.finishDecoded(raw, std::move(rawf), decode);
    return t;
}

}  // namespace ps11
