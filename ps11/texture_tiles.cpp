// Per-tile facts of a texture's level 0 (ps11/texture_tiles.h).
#include "ps11/texture_tiles.h"

#include <emmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "ps11/texture.h"

namespace ps11 {

void TexelRange::add(const TexelRange& o) {
    for (int c = 0; c < 4; ++c) {
        lo[size_t(c)] = std::min(lo[size_t(c)], o.lo[size_t(c)]);
        hi[size_t(c)] = std::max(hi[size_t(c)], o.hi[size_t(c)]);
    }
    nan |= o.nan;
    negZero |= o.negZero;
}

TexelRange TexelTiles::over(uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1) const {
    TexelRange r;
    for (uint32_t ty = y0 / side; ty <= y1 / side && ty < tilesY; ++ty)
        for (uint32_t tx = x0 / side; tx <= x1 / side && tx < tilesX; ++tx)
            r.add(tiles[size_t(ty) * tilesX + tx]);
    return r;
}

bool hasTexelTiles(const Texture& tex) { return !tex.isVolume() && tex.levelCount() >= 1; }

void prepareTexelTiles(const Texture& tex, TexelTiles& out) {
    const TextureLevelInfo& l = tex.level(0);
    out.width = l.width;
    out.height = l.height;
    out.side = kMinTexelTileSide;
    while (out.side < kMaxTexelTileSide && std::max(l.width, l.height) > out.side * kTexelTilesPerSide) out.side *= 2;
    out.tilesX = (l.width + out.side - 1) / out.side;
    out.tilesY = (l.height + out.side - 1) / out.side;
    out.tiles.assign(size_t(out.tilesX) * out.tilesY, TexelRange{});
}

namespace {

// Byte minima and maxima of texels [x0, x1) of one Unorm8 row, b g r a per lane group.
void unorm8Row(const uint8_t* row, uint32_t x0, uint32_t x1, __m128i& mn, __m128i& mx, uint8_t (&smn)[4],
               uint8_t (&smx)[4]) {
    uint32_t x = x0;
    for (; x + 4 <= x1; x += 4) {
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + size_t(x) * 4));
        mn = _mm_min_epu8(mn, v);
        mx = _mm_max_epu8(mx, v);
    }
    for (; x < x1; ++x)
        for (int b = 0; b < 4; ++b) {
            smn[b] = std::min(smn[b], row[size_t(x) * 4 + size_t(b)]);
            smx[b] = std::max(smx[b], row[size_t(x) * 4 + size_t(b)]);
        }
}

}  // namespace

void scanTexelTiles(const Texture& tex, TexelTiles& out, uint32_t ty0, uint32_t ty1) {
    const uint32_t w = out.width, h = out.height;
    for (uint32_t ty = ty0; ty < ty1 && ty < out.tilesY; ++ty) {
        const uint32_t y0 = ty * out.side, y1 = std::min(h, y0 + out.side);
        for (uint32_t tx = 0; tx < out.tilesX; ++tx) {
            const uint32_t x0 = tx * out.side, x1 = std::min(w, x0 + out.side);
            TexelRange& r = out.tiles[size_t(ty) * out.tilesX + tx];
            r = TexelRange{};
            if (tex.storage() == TexelStorage::Unorm8) {
                __m128i mn = _mm_set1_epi8(char(0xff)), mx = _mm_setzero_si128();
                uint8_t smn[4] = {255, 255, 255, 255}, smx[4] = {0, 0, 0, 0};
                for (uint32_t y = y0; y < y1; ++y) unorm8Row(tex.unorm8() + size_t(y) * w * 4, x0, x1, mn, mx, smn, smx);
                alignas(16) uint8_t vmn[16], vmx[16];
                _mm_store_si128(reinterpret_cast<__m128i*>(vmn), mn);
                _mm_store_si128(reinterpret_cast<__m128i*>(vmx), mx);
                for (int k = 0; k < 16; ++k) {
                    smn[k % 4] = std::min(smn[k % 4], vmn[k]);
                    smx[k % 4] = std::max(smx[k % 4], vmx[k]);
                }
                const float* v = Texture::unorm8Values();
                for (int c = 0; c < 4; ++c) {
                    r.lo[size_t(c)] = v[smn[kUnorm8Byte[c]]];
                    r.hi[size_t(c)] = v[smx[kUnorm8Byte[c]]];
                }
                continue;
            }
            const float* values = tex.values();
            for (uint32_t y = y0; y < y1; ++y)
                for (uint32_t x = x0; x < x1; ++x) {
                    const float* t = values + (size_t(y) * w + x) * 4;
                    for (int c = 0; c < 4; ++c) {
                        const float f = t[c];
                        if (std::isnan(f)) {
                            r.nan |= uint8_t(1u << c);
                            continue;
                        }
                        if (f == 0 && std::signbit(f)) r.negZero |= uint8_t(1u << c);
                        r.lo[size_t(c)] = std::min(r.lo[size_t(c)], f);
                        r.hi[size_t(c)] = std::max(r.hi[size_t(c)], f);
                    }
                }
        }
    }
}

std::shared_ptr<const TexelTiles> Texture::texelTiles() const {
    std::lock_guard<std::mutex> lock(m_tileCache->mutex);
    return m_tileCache->tiles;
}

void Texture::keepTexelTiles(std::shared_ptr<const TexelTiles> tiles) const {
    std::lock_guard<std::mutex> lock(m_tileCache->mutex);
    m_tileCache->tiles = std::move(tiles);
}

}  // namespace ps11
