// Per-tile facts of a texture's level 0 (ps11/texture_tiles.h).
#include "ps11/texture_tiles.h"

#include <emmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

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
    // add() over the tiles with the four channels at once: minps(o, r) is std::min(r, o) and
    // maxps(o, r) std::max(r, o), NaN and signed zeros included (each returns its second operand
    // unless the first compares below, or above, it).
    TexelRange r;
    if (tilesX == 0 || tilesY == 0) return r;
    const uint32_t tx0 = x0 / side, tx1 = std::min(x1 / side, tilesX - 1);
    const uint32_t ty0 = y0 / side, ty1 = std::min(y1 / side, tilesY - 1);
    // Two accumulators (even and odd tiles of a row), folded at the end: minima and maxima are
    // order-free but for which of +0.0 and −0.0 stays, which `negZero` records on its own.
    __m128 lo = _mm_loadu_ps(r.lo.data()), hi = _mm_loadu_ps(r.hi.data());
    __m128 lo2 = lo, hi2 = hi;
    uint8_t nan = 0, negZero = 0;
    for (uint32_t ty = ty0; ty <= ty1 && tx0 <= tx1; ++ty) {
        const TexelRange* t = &tiles[size_t(ty) * tilesX + tx0];
        uint32_t tx = tx0;
        for (; tx + 1 <= tx1; tx += 2, t += 2) {
            lo = _mm_min_ps(_mm_loadu_ps(t[0].lo.data()), lo);
            hi = _mm_max_ps(_mm_loadu_ps(t[0].hi.data()), hi);
            lo2 = _mm_min_ps(_mm_loadu_ps(t[1].lo.data()), lo2);
            hi2 = _mm_max_ps(_mm_loadu_ps(t[1].hi.data()), hi2);
            nan = uint8_t(nan | t[0].nan | t[1].nan);
            negZero = uint8_t(negZero | t[0].negZero | t[1].negZero);
        }
        if (tx <= tx1) {
            lo = _mm_min_ps(_mm_loadu_ps(t->lo.data()), lo);
            hi = _mm_max_ps(_mm_loadu_ps(t->hi.data()), hi);
            nan = uint8_t(nan | t->nan);
            negZero = uint8_t(negZero | t->negZero);
        }
    }
    lo = _mm_min_ps(lo2, lo);
    hi = _mm_max_ps(hi2, hi);
    _mm_storeu_ps(r.lo.data(), lo);
    _mm_storeu_ps(r.hi.data(), hi);
    r.nan = nan, r.negZero = negZero;
    return r;
}

bool hasTexelTiles(const Texture& tex) { return !tex.isVolume() && tex.levelCount() >= 1; }

uint32_t texelTileSide(uint32_t width, uint32_t height) {
    uint32_t side = kMinTexelTileSide;
    while (side < kMaxTexelTileSide && std::max(width, height) > side * kTexelTilesPerSide) side *= 2;
    return side;
}

void prepareTexelTiles(const Texture& tex, TexelTiles& out) {
    const TextureLevelInfo& l = tex.level(0);
    out.width = l.width;
    out.height = l.height;
    out.side = texelTileSide(l.width, l.height);
    out.tilesX = (l.width + out.side - 1) / out.side;
    out.tilesY = (l.height + out.side - 1) / out.side;
    out.tiles.assign(size_t(out.tilesX) * out.tilesY, TexelRange{});
}

namespace {

// Per-byte minima and maxima of texels [x0, x1) of one Unorm8 row, folded into `mn`/`mx` with the
// texels' four bytes b g r a in every 4-byte group (a tail under four texels fills a vector
// with repeats of its first texel).
inline void unorm8Row(const uint8_t* row, uint32_t x0, uint32_t x1, __m128i& mn, __m128i& mx) {
    uint32_t x = x0;
    for (; x + 8 <= x1; x += 8) {
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + size_t(x) * 4));
        const __m128i u = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + size_t(x) * 4 + 16));
        mn = _mm_min_epu8(mn, _mm_min_epu8(v, u));
        mx = _mm_max_epu8(mx, _mm_max_epu8(v, u));
    }
    if (x + 4 <= x1) {
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + size_t(x) * 4));
        mn = _mm_min_epu8(mn, v);
        mx = _mm_max_epu8(mx, v);
        x += 4;
    }
    if (x < x1) {
        int32_t t[4];
        for (uint32_t k = 0; k < 4; ++k) std::memcpy(&t[k], row + size_t(x + std::min(k, x1 - 1 - x)) * 4, 4);
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(t));
        mn = _mm_min_epu8(mn, v);
        mx = _mm_max_epu8(mx, v);
    }
}

// The four texels' bytes of a 16-byte group folded into its low four bytes.
inline uint32_t fold4(__m128i v, bool max) {
    if (max) {
        v = _mm_max_epu8(v, _mm_srli_si128(v, 8));
        v = _mm_max_epu8(v, _mm_srli_si128(v, 4));
    } else {
        v = _mm_min_epu8(v, _mm_srli_si128(v, 8));
        v = _mm_min_epu8(v, _mm_srli_si128(v, 4));
    }
    return uint32_t(_mm_cvtsi128_si32(v));
}

// One band of Unorm8 tiles (tile row `ty`): every texel row of the band once, folded into the
// tiles' accumulators side by side (a small texture's tiles are 4 texels wide: one vector per
// tile and row, so the rows' loop, not a call per tile and row, is what runs).
// Tiles [t0, t1) of the band, at most kTexelTilesPerSide of them.
void scanUnorm8Band(const Texture& tex, TexelTiles& out, uint32_t ty, uint32_t t0, uint32_t t1) {
    const uint32_t w = out.width, y0 = ty * out.side, y1 = std::min(out.height, y0 + out.side);
    __m128i mn[kTexelTilesPerSide], mx[kTexelTilesPerSide];
    const uint32_t n = t1 - t0;
    for (uint32_t k = 0; k < n; ++k) mn[k] = _mm_set1_epi8(char(0xff)), mx[k] = _mm_setzero_si128();
    const uint8_t* texels = tex.unorm8();
    for (uint32_t y = y0; y < y1; ++y) {
        const uint8_t* row = texels + size_t(y) * w * 4;
        for (uint32_t k = 0; k < n; ++k) {
            const uint32_t x0 = (t0 + k) * out.side, x1 = std::min(w, x0 + out.side);
            unorm8Row(row, x0, x1, mn[k], mx[k]);
        }
    }
    const float* v = Texture::unorm8Values();
    for (uint32_t k = 0; k < n; ++k) {
        TexelRange& r = out.tiles[size_t(ty) * out.tilesX + t0 + k];
        r = TexelRange{};
        const uint32_t lo = fold4(mn[k], false), hi = fold4(mx[k], true);
        for (int c = 0; c < 4; ++c) {
            const int shift = 8 * kUnorm8Byte[c];
            r.lo[size_t(c)] = v[(lo >> shift) & 0xff];
            r.hi[size_t(c)] = v[(hi >> shift) & 0xff];
        }
    }
}

// r g b a floats: minima and maxima of the non-NaN values, NaN channels, −0.0 channels.
void scanDecodedTile(const Texture& tex, uint32_t w, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
                     TexelRange& r) {
    const float inf = std::numeric_limits<float>::infinity();
    __m128 lo = _mm_set1_ps(inf), hi = _mm_set1_ps(-inf);
    __m128i nan = _mm_setzero_si128(), negZero = _mm_setzero_si128();
    const __m128i negZeroBits = _mm_set1_epi32(int32_t(0x80000000u));
    const float* values = tex.values();
    const FloatTexels texels = tex.floatTexels();  // a float texture read in place in its own layout
    for (uint32_t y = y0; y < y1; ++y) {
        for (uint32_t x = x0; x < x1; ++x) {
            const size_t i = size_t(y) * w + x;
            float own[4];
            if (!values) texels.get(i, own);
            const __m128 v = _mm_loadu_ps(values ? values + i * 4 : own);
            // minps/maxps give their second operand where either is NaN: the NaN is passed over.
            lo = _mm_min_ps(v, lo);
            hi = _mm_max_ps(v, hi);
            nan = _mm_or_si128(nan, _mm_castps_si128(_mm_cmpunord_ps(v, v)));
            // −0.0: the sign bit alone.
            negZero = _mm_or_si128(negZero, _mm_cmpeq_epi32(_mm_castps_si128(v), negZeroBits));
        }
    }
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo);
    _mm_store_ps(h, hi);
    const int nanBits = _mm_movemask_ps(_mm_castsi128_ps(nan)), negBits = _mm_movemask_ps(_mm_castsi128_ps(negZero));
    for (int c = 0; c < 4; ++c) {
        // A channel of NaNs only keeps the empty range (lo > hi), as TexelRange{} says.
        if (l[c] > h[c]) continue;
        r.lo[size_t(c)] = l[c];
        r.hi[size_t(c)] = h[c];
    }
    r.nan = uint8_t(nanBits);
    r.negZero = uint8_t(negBits);
}

// Scans tiles [t0, t1) of tile row ty.
void scanRun(const Texture& tex, TexelTiles& out, uint32_t ty, uint32_t t0, uint32_t t1) {
    if (tex.storage() == TexelStorage::Unorm8) {
        for (uint32_t t = t0; t < t1; t += kTexelTilesPerSide)
            scanUnorm8Band(tex, out, ty, t, std::min(t1, t + kTexelTilesPerSide));
        return;
    }
    const uint32_t w = out.width, y0 = ty * out.side, y1 = std::min(out.height, y0 + out.side);
    for (uint32_t tx = t0; tx < t1; ++tx) {
        const uint32_t x0 = tx * out.side, x1 = std::min(w, x0 + out.side);
        TexelRange& r = out.tiles[size_t(ty) * out.tilesX + tx];
        r = TexelRange{};
        scanDecodedTile(tex, w, x0, x1, y0, y1, r);
    }
}

}  // namespace

void scanTexelTiles(const Texture& tex, TexelTiles& out, uint32_t ty0, uint32_t ty1) {
    for (uint32_t ty = ty0; ty < ty1 && ty < out.tilesY; ++ty) scanRun(tex, out, ty, 0, out.tilesX);
}

bool uniformTileRange(const Texture& tex, TexelTiles& out, const std::vector<uint8_t>& stale, TexelRange& range) {
    if (stale.size() != out.tiles.size()) return false;
    for (size_t i = 0; i < stale.size(); ++i) {
        if (stale[i]) continue;
        const uint32_t tx = uint32_t(i % out.tilesX), ty = uint32_t(i / out.tilesX);
        scanRun(tex, out, ty, tx, tx + 1);
        range = out.tiles[i];
        return true;
    }
    return false;
}

void fillUniformTiles(const Texture& tex, TexelTiles& out, const std::vector<uint8_t>& stale,
                      const TexelRange& uniform, uint32_t ty0, uint32_t ty1) {
    for (uint32_t ty = ty0; ty < ty1 && ty < out.tilesY; ++ty) {
        const size_t row = size_t(ty) * out.tilesX;
        for (uint32_t tx = 0; tx < out.tilesX;) {
            if (!stale[row + tx]) {
                out.tiles[row + tx] = uniform;
                ++tx;
                continue;
            }
            // A run of stale tiles, scanned together.
            uint32_t end = tx + 1;
            while (end < out.tilesX && stale[row + end]) ++end;
            scanRun(tex, out, ty, tx, end);
            tx = end;
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

std::shared_ptr<const std::vector<uint8_t>> Texture::uniformTiles() const {
    std::lock_guard<std::mutex> lock(m_tileCache->mutex);
    return m_tileCache->uniformStale;
}

void Texture::setUniformTiles(std::shared_ptr<const std::vector<uint8_t>> stale) const {
    std::lock_guard<std::mutex> lock(m_tileCache->mutex);
    m_tileCache->uniformStale = std::move(stale);
}

}  // namespace ps11
