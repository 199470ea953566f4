// Tile facts from clears and the tiles draws reach (emu/tile_facts.h).
#include "emu/tile_facts.h"

#include <algorithm>
#include <cmath>

#include "ps11/texture_tiles.h"

namespace emu {

namespace {

// Triangles assembled per pass over a draw's primitives (memory stays bounded for any count).
constexpr uint32_t kMarkChunk = 1024;
// A draw of more triangles forgets the facts instead of assembling its triangles a second time
// (a scene's geometry; a frame's sprites are a few hundred).
constexpr uint32_t kMaxMarkedTriangles = 16384;

}  // namespace

size_t uniformTileCount(const Image& image) {
    const uint32_t side = ps11::texelTileSide(image.width, image.height);
    return size_t((image.width + side - 1) / side) * ((image.height + side - 1) / side);
}

std::shared_ptr<const std::vector<uint8_t>> markDrawnTiles(const DrawCall& call, const Image& target,
                                                           const std::vector<uint8_t>& stale) {
    if (call.primitiveCount > kMaxMarkedTriangles || stale.size() != uniformTileCount(target)) return nullptr;
    auto out = std::make_shared<std::vector<uint8_t>>(stale);
    const uint32_t side = ps11::texelTileSide(target.width, target.height);
    const int64_t tilesX = (int64_t(target.width) + side - 1) / side;
    const ClipRect& clip = call.clip;
    const int64_t cx0 = std::max(0, clip.x0), cy0 = std::max(0, clip.y0);
    const int64_t cx1 = std::min<int64_t>(clip.x1, target.width), cy1 = std::min<int64_t>(clip.y1, target.height);
    if (cx0 >= cx1 || cy0 >= cy1) return out;
    auto mark = [&](int64_t x0, int64_t y0, int64_t x1, int64_t y1) {  // pixels [x0, x1) × [y0, y1)
        x0 = std::max(x0, cx0), y0 = std::max(y0, cy0), x1 = std::min(x1, cx1), y1 = std::min(y1, cy1);
        if (x0 >= x1 || y0 >= y1) return;
        for (int64_t ty = y0 / side; ty <= (y1 - 1) / side; ++ty)
            std::fill_n(out->begin() + ty * tilesX + x0 / side, (x1 - 1) / side - x0 / side + 1, uint8_t(1));
    };
    std::vector<ScreenTriangle> tris;
    for (uint32_t first = 0; first < call.primitiveCount; first += kMarkChunk) {
        tris.clear();
        call.assemble(first, std::min(kMarkChunk, call.primitiveCount - first), tris);
        for (const ScreenTriangle& t : tris) {
            double x0 = t.v[0].x, x1 = x0, y0 = t.v[0].y, y1 = y0;
            for (const ScreenVertex& v : t.v) x0 = std::min(x0, v.x), x1 = std::max(x1, v.x), y0 = std::min(y0, v.y), y1 = std::max(y1, v.y);
            if (!std::isfinite(x0) || !std::isfinite(x1) || !std::isfinite(y0) || !std::isfinite(y1)) {
                mark(cx0, cy0, cx1, cy1);
                continue;
            }
            // Pixel centres at integer coordinates: a covered pixel lies within the box; one
            // pixel more each side for the snapping of positions.
            const double lim = 1e9;
            mark(int64_t(std::floor(std::clamp(x0, -lim, lim))) - 1, int64_t(std::floor(std::clamp(y0, -lim, lim))) - 1,
                 int64_t(std::ceil(std::clamp(x1, -lim, lim))) + 2, int64_t(std::ceil(std::clamp(y1, -lim, lim))) + 2);
        }
    }
    // Every tile stale: nothing is known any more (a full-screen pass), and later draws need not
    // look at their triangles.
    if (std::find(out->begin(), out->end(), uint8_t(0)) == out->end()) return nullptr;
    return out;
}

}  // namespace emu
