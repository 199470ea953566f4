// Software textures (docs/textures.md): a format, 2D or volume, a mip chain, and the texels
// decoded per channel so that every precision profile reads exact values (8-bit channels as
// bytes, signed and float formats as per-profile grid integers and float32). Built from levels in
// D3D's memory layout by Texture::fromLevels() (the device's hand-over, which samples A8R8G8B8
// and float levels where they are), or texel by texel by the library's TextureBuilder
// (ps11/texture_internal.h; the .ps11test model's textureFromDesc, ps11/testfile_textures.h);
// immutable afterwards, shared by samplers.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "ps11/caps.h"
#include "ps11/formats.h"
#include "ps11/hardware.h"
#include "ps11/precision.h"

namespace ps11 {

struct TexelTiles;      // ps11/texture_tiles.h
class TextureBuilder;  // ps11/texture_internal.h

// Grid values of float texels are clamped to +-kMaxTexelGrid (about +-4112 in fx8, far beyond any
// MaxValue) so that the exact integer sums of the sampler cannot overflow.
constexpr int32_t kMaxTexelGrid = 1 << 20;

// One texture may occupy at most kMaxResourceBytes (ps11/caps.h: all levels, all decoded
// copies). A full 16384 x 16384 A8R8G8B8 level fits; larger requests are refused with an error,
// never allocated.

// How a texture keeps its texels (from its format's class, ps11/formats.h).
enum class TexelStorage : uint8_t {
    Unorm8,   // 4 bytes b g r a per texel (D3D's A8R8G8B8 order), value = byte / 255
              // (A8R8G8B8, X8R8G8B8, A8, L8, A8L8)
    Decoded,  // float32 r g b a plus fx8 and fx12 grid integers per texel (signed and float formats)
};

// Byte index of channel c (0..3 = r g b a) inside a Unorm8 texel (stored b g r a).
constexpr int kUnorm8Byte[4] = {2, 1, 0, 3};

// One level in D3D9's memory layout (what LockRect/LockBox hand out): texel (x, y, z) at
// data + z * slicePitch + y * rowPitch + x * bytesPerTexel(format). Packed formats store their
// texel word little endian (A8R8G8B8 = bytes B G R A, V8U8 = U V, ...), A16B16G16R16F four halves
// r g b a, A32B32G32R32F four floats r g b a, R32F one float.
struct TextureLevelBytes {
    uint32_t width = 1, height = 1, depth = 1;
    const uint8_t* data = nullptr;
    size_t rowPitch = 0;
    size_t slicePitch = 0;
};

struct TextureLevelInfo {
    uint32_t width = 1, height = 1, depth = 1;
    size_t offset = 0;  // index of the level's first texel in the texture's arrays
};

// A float format's texels as they lie in its levels (Texture::floatTexels): texel i's channel c
// is the float32 or IEEE half at base + i * stride + offset[c], or the constant 0 or 1 (its
// ChannelKind). Reads what the format's row (ps11/formats.h) says, with memcpy (no alignment).
struct FloatTexels {
    const uint8_t* base = nullptr;
    uint32_t stride = 16;
    std::array<ChannelKind, 4> kind{ChannelKind::Float, ChannelKind::Float, ChannelKind::Float, ChannelKind::Float};
    std::array<uint8_t, 4> offset{0, 4, 8, 12};
    inline void get(size_t i, float t[4]) const;
    // The same texels from texel `first` on (a level's offset).
    FloatTexels from(size_t first) const {
        FloatTexels f = *this;
        f.base += first * stride;
        return f;
    }
};

class Texture {
public:
    TexFormat format() const { return m_format; }
    bool isVolume() const { return m_volume; }
    TexelStorage storage() const { return m_storage; }
    int levelCount() const { return int(m_levels.size()); }
    const TextureLevelInfo& level(int i) const { return m_levels[size_t(i)]; }
    // Total texels over all levels.
    size_t texelCount() const { return m_texelCount; }

    // The decoded value of one texel (float profiles): r g b a.
    std::array<float, 4> texelValue(int level, uint32_t x, uint32_t y, uint32_t z = 0) const;
    // The grid value of one texel in a fixed-point profile (value = grid / G).
    std::array<int32_t, 4> texelGrid(int level, uint32_t x, uint32_t y, uint32_t z, Precision p) const;

    // Raw arrays for the sampler, 4 entries per texel, indexed by level offset + texel: Unorm8 as
    // b g r a bytes (kUnorm8Byte), Decoded as r g b a.
    const uint8_t* unorm8() const { return m_u8view ? m_u8view.get() : m_u8.data(); }  // Unorm8
    // Decoded: null for a float texture read in place whose texels are not four float32 r g b a
    // (A16B16G16R16F, R32F): floatTexels() reads every Decoded float texture.
    const float* values() const { return m_valueView ? m_valueView.get() : m_rawView ? nullptr : m_value.data(); }
    // A Decoded texture's texels, r g b a: where fromLevels found them when it reads them in place,
    // else values() as four float32 per texel.
    FloatTexels floatTexels() const;
    // Decoded, fx. Float formats compute a profile's grid from the values on its first use (a
    // float texture sampled only by float profiles never needs one); thread-safe. A texture read
    // in place is never converted whole this way by the sampler: it takes each texel's grid as it
    // reads it (texelGridOf), the same integers.
    const int32_t* grid(Precision p) const;
    // Float32 of byte b (b / 255), shared by all Unorm8 textures.
    static const float* unorm8Values();

    // Builds a texture from every level of a mip chain in D3D's memory layout (the device's
    // hand-over; no mip generation). `levels` must be the chain's first levels.size() levels
    // (level k has the extents of level 0 halved k times). The result reads as the one
    // TextureBuilder (the .ps11test model's textureFromDesc) gives for the same texels.
    // A8R8G8B8 and float levels laid out exactly as the texture keeps them (one buffer, rows of
    // width texels, level after level with no gap) are not copied when `owner` is given: the
    // texture reads them where they are (A16B16G16R16F and R32F through floatTexels) and keeps
    // `owner` alive; the caller must not change those bytes
    // while the texture is in use (emu's device copies them first: Device::prepareWrite). Other
    // levels are copied (A8R8G8B8 row by row) or decoded.
    // On failure returns nullopt and sets `error`; never allocates more than kMaxResourceBytes.
    // Signed channels decode as `decode` says (the hardware class's rule).
    // X8R8G8B8 levels are read in place too where the caller knows every texel's X byte is 0xff
    // (`padOnes`: the byte the sampler reads as alpha 1; emu's Resource::padOnes).
    static std::optional<Texture> fromLevels(TexFormat format, bool volume, const TextureLevelBytes* levels,
                                             size_t levelCount, SignedDecode decode, std::string& error,
                                             std::shared_ptr<const void> owner = {}, bool padOnes = false);
    // Whether the texels are read where fromLevels found them (no copy).
    bool readsInPlace() const { return m_u8view != nullptr || m_valueView != nullptr || m_rawView != nullptr; }
    // The rule the signed channels were decoded with (Snorm for textures without them).
    SignedDecode signedDecode() const { return m_signedDecode; }
    // The per-tile facts of level 0 (ps11/texture_tiles.h) once a caller computed and kept them
    // (null before); thread-safe. Copies of a texture share them.
    std::shared_ptr<const TexelTiles> texelTiles() const;
    void keepTexelTiles(std::shared_ptr<const TexelTiles> tiles) const;
    // What the texture's maker knew of level 0 before any scan (ps11/texture_tiles.h
    // "uniformTileRange"): one value in every texel but the tiles flagged stale; null when
    // nothing is known. Thread-safe; copies of a texture share it.
    std::shared_ptr<const std::vector<uint8_t>> uniformTiles() const;
    void setUniformTiles(std::shared_ptr<const std::vector<uint8_t>> stale) const;

private:
    friend class TextureBuilder;
    size_t texelIndex(int level, uint32_t x, uint32_t y, uint32_t z) const;
    // Sets format and level extents; false (with `error`) beyond kMaxResourceBytes.
    bool layout(TexFormat fmt, bool volume, uint32_t width, uint32_t height, uint32_t depth, uint32_t count,
                std::string& error);
    // Signed formats: raw channel integers -> values and grids; float formats: the floats -> grids.
    void finishDecoded(const std::vector<int32_t>& raw, std::vector<float>&& rawf, SignedDecode decode);

    TexFormat m_format = TexFormat::A8R8G8B8;
    bool m_volume = false;
    TexelStorage m_storage = TexelStorage::Unorm8;
    SignedDecode m_signedDecode = SignedDecode::Snorm;
    std::vector<TextureLevelInfo> m_levels;
    size_t m_texelCount = 0;
    std::vector<uint8_t> m_u8;
    std::shared_ptr<const uint8_t> m_u8view;  // fromLevels' levels, read in place (owner kept)
    std::vector<float> m_value;
    std::shared_ptr<const float> m_valueView;  // fromLevels' A32B32G32R32F levels, read in place
    std::shared_ptr<const uint8_t> m_rawView;  // fromLevels' other float levels, read in place
    struct Grids {
        std::once_flag once8, once12;  // float formats: filled on first use
        std::vector<int32_t> g8, g12;
    };
    std::shared_ptr<Grids> m_grids = std::make_shared<Grids>();
    struct TileCache {
        std::mutex mutex;
        std::shared_ptr<const TexelTiles> tiles;
        std::shared_ptr<const std::vector<uint8_t>> uniformStale;
    };
    std::shared_ptr<TileCache> m_tileCache = std::make_shared<TileCache>();
};

// The value of one texel word of a signed (bump) format (V8U8, L6V5U5, X8L8V8U8, Q8W8V8U8,
// V16U16) as the sampler reads it, r g b a, under `decode`.
std::array<float, 4> signedTexelValue(TexFormat f, uint32_t word, SignedDecode decode);

// Number of levels of a full chain (down to 1x1x1).
uint32_t fullMipCount(uint32_t width, uint32_t height, uint32_t depth);

// Bytes per texel of a format in D3D's memory layout.
uint32_t bytesPerTexel(TexFormat f);

// One texel's channels as the sampler reads them, from its format's row (ps1x-spec §6.4: missing
// channels read 1, A8's rgb 0): an Unorm8 format's packed word as the bytes r g b a (other
// classes: 0 0 0 255); a Float format's texel at p, D3D9 layout, as the values r g b a (other
// classes: 0 0 0 1). The device's conversions and the textures' hand-over both decode with these.
std::array<uint8_t, 4> unorm8Channels(const FormatRow& row, uint32_t word);
std::array<float, 4> floatChannels(const FormatRow& row, const uint8_t* p);

// float32 -> nearest IEEE half bits (ties to even, overflow to infinity, NaN kept quiet).
uint16_t floatToHalf(float v);
// IEEE half bits -> float32 (exact; a NaN reads as the quiet NaN 0x7fc00000 with the half's sign).
inline float halfToFloat(uint16_t h) {
    const uint32_t sign = uint32_t(h & 0x8000u) << 16, exponent = (h >> 10) & 31u, mantissa = h & 1023u;
    if (exponent == 0) {  // zero and subnormals: mantissa * 2^-24, exact in float32
        const float v = float(mantissa) * 0x1p-24f;
        return sign ? -v : v;
    }
    const uint32_t bits = exponent == 31 ? (mantissa ? 0x7fc00000u : 0x7f800000u)
                                         : ((exponent + 112u) << 23) | (mantissa << 13);  // rebias 15 -> 127
    float v;
    std::memcpy(&v, &bits, 4);
    return sign ? -v : v;
}

// The grid value a fixed-point profile samples for a float texel's channel: toGrid clamped to
// +-kMaxTexelGrid (Texture::grid's integers, one at a time).
inline int32_t texelGridOf(float v, Precision p) {
    return std::clamp(toGrid(double(v), p), -kMaxTexelGrid, kMaxTexelGrid);
}

void FloatTexels::get(size_t i, float t[4]) const {
    const uint8_t* p = base + i * stride;
    for (size_t c = 0; c < 4; ++c) {
        const uint8_t* q = p + offset[c];
        switch (kind[c]) {
            case ChannelKind::Float:
                std::memcpy(&t[c], q, 4);
                break;
            case ChannelKind::Half: {
                uint16_t h;
                std::memcpy(&h, q, 2);
                t[c] = halfToFloat(h);
                break;
            }
            case ChannelKind::Zero:
                t[c] = 0.0f;
                break;
            default:
                t[c] = 1.0f;
                break;
        }
    }
}
// float32 -> nearest IEEE half -> float32.
inline float roundToHalf(float v) { return halfToFloat(floatToHalf(v)); }

}  // namespace ps11
