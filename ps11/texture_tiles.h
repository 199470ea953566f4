// Per-tile facts of a texture's level 0 (docs/device.md "Tile skipping"): the range of each channel's values,
// as the sampler's point reads return them, over square tiles of `side` texels. The
// renderer reads them to bound what a tile of a draw can sample (ps11/intervals.h decides from
// that whether the tile needs shading); they are computed once per texture (a texture is
// immutable, so once per generation of a device resource), in tile rows a caller can share among
// threads.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace ps11 {

class Texture;

// Tiles are squares of a power of two texels, kMinTexelTileSide … kMaxTexelTileSide: the
// smallest giving at most kTexelTilesPerSide tiles a side (a small texture, such as a
// magnified blur, gets tiles as fine as the screen tiles that read it).
constexpr uint32_t kMinTexelTileSide = 4, kMaxTexelTileSide = 32, kTexelTilesPerSide = 64;

// The values of a set of texels per channel r g b a: [lo, hi] of the non-NaN values, which
// channels hold a NaN and which a −0.0. Empty: lo > hi.
struct TexelRange {
    std::array<float, 4> lo{1, 1, 1, 1}, hi{0, 0, 0, 0};
    uint8_t nan = 0;      // bit c: channel c holds a NaN
    uint8_t negZero = 0;  // bit c: channel c holds −0.0
    void add(const TexelRange& o);
};

struct TexelTiles {
    uint32_t width = 0, height = 0;    // level 0's extents
    uint32_t side = kMaxTexelTileSide;  // texels per tile side
    uint32_t tilesX = 0, tilesY = 0;
    std::vector<TexelRange> tiles;     // row-major, tilesX per row
    // The range of texels [x0, x1] × [y0, y1] (inclusive, inside the level) from the tiles
    // they touch.
    TexelRange over(uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1) const;
    TexelRange whole() const { return over(0, 0, width - 1, height - 1); }
};

// Whether texelTiles can describe the texture: a 2-D texture whose level 0 is Unorm8 or Decoded
// (every format is).
bool hasTexelTiles(const Texture& tex);
// The side of the tiles of a level of width × height texels.
uint32_t texelTileSide(uint32_t width, uint32_t height);
// Sizes `out` for the texture's level 0 (tiles empty until scanned).
void prepareTexelTiles(const Texture& tex, TexelTiles& out);
// Scans tile rows [ty0, ty1) of level 0 into `out` (prepared; disjoint rows may be scanned by
// different threads).
void scanTexelTiles(const Texture& tex, TexelTiles& out, uint32_t ty0, uint32_t ty1);

// Facts its maker knew without a scan (Texture::uniformTiles): level 0 held one value in every
// texel, then only the tiles flagged in `stale` (one byte per tile of the prepared grid,
// row-major) may have been written. uniformTileRange scans the first tile not stale into the
// prepared `out`: the range every tile not stale has (false where every tile is stale, or
// `stale` does not fit the grid).
// fillUniformTiles gives tile rows [ty0, ty1) of `out` that range where not stale and scans the
// stale ones: the same tiles scanTexelTiles gives (disjoint rows may be filled by different
// threads).
bool uniformTileRange(const Texture& tex, TexelTiles& out, const std::vector<uint8_t>& stale, TexelRange& range);
void fillUniformTiles(const Texture& tex, TexelTiles& out, const std::vector<uint8_t>& stale,
                      const TexelRange& uniform, uint32_t ty0, uint32_t ty1);

}  // namespace ps11
