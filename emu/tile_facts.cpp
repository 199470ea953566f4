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

AssembledBoxes::Box boxOf(const ScreenTriangle& t) {
    AssembledBoxes::Box b{t.v[0].x, t.v[0].y, t.v[0].x, t.v[0].y};
    for (const ScreenVertex& v : t.v) {
        if (!std::isfinite(v.x) || !std::isfinite(v.y)) return {NAN, NAN, NAN, NAN};
        b.x0 = std::min(b.x0, v.x), b.x1 = std::max(b.x1, v.x), b.y0 = std::min(b.y0, v.y), b.y1 = std::max(b.y1, v.y);
    }
    return b;
}

}  // namespace

AssembledBoxes::AssembledBoxes(DrawCall& call) : m_call(call), m_assemble(call.assemble) {
    if (call.primitiveCount > kMaxMarkedTriangles || !m_assemble) return;
    m_watching = true;
    m_seen.assign(call.primitiveCount, 0);
    call.assemble = [this](uint32_t first, uint32_t count, std::vector<ScreenTriangle>& out) {
        const size_t before = out.size();
        m_assemble(first, count, out);
        std::lock_guard<std::mutex> lock(m_mutex);
        for (size_t i = before; i < out.size(); ++i) m_boxes.push_back(boxOf(out[i]));
        for (uint32_t p = first; p < first + count && p < m_seen.size(); ++p)
            if (!m_seen[p]) m_seen[p] = 1, ++m_seenCount;
    };
}

AssembledBoxes::~AssembledBoxes() { m_call.assemble = m_assemble; }

size_t uniformTileCount(const Image& image) {
    const uint32_t side = ps11::texelTileSide(image.width, image.height);
    return size_t((image.width + side - 1) / side) * ((image.height + side - 1) / side);
}

std::shared_ptr<const std::vector<uint8_t>> markDrawnTiles(const DrawCall& call, const Image& target,
                                                           const std::vector<uint8_t>& stale,
                                                           const AssembledBoxes* assembled) {
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
    auto markBox = [&](const AssembledBoxes::Box& b) {
        if (!std::isfinite(b.x0) || !std::isfinite(b.x1) || !std::isfinite(b.y0) || !std::isfinite(b.y1)) {
            mark(cx0, cy0, cx1, cy1);
            return;
        }
        // Pixel centres at integer coordinates: a covered pixel lies within the box; one
        // pixel more each side for the snapping of positions.
        const double lim = 1e9;
        mark(int64_t(std::floor(std::clamp(b.x0, -lim, lim))) - 1, int64_t(std::floor(std::clamp(b.y0, -lim, lim))) - 1,
             int64_t(std::ceil(std::clamp(b.x1, -lim, lim))) + 2, int64_t(std::ceil(std::clamp(b.y1, -lim, lim))) + 2);
    };
    if (assembled && assembled->complete()) {
        for (const AssembledBoxes::Box& b : assembled->boxes()) markBox(b);
    } else {
        std::vector<ScreenTriangle> tris;
        for (uint32_t first = 0; first < call.primitiveCount; first += kMarkChunk) {
            tris.clear();
            call.assemble(first, std::min(kMarkChunk, call.primitiveCount - first), tris);
            for (const ScreenTriangle& t : tris) markBox(boxOf(t));
        }
    }
    // Every tile stale: nothing is known any more (a full-screen pass), and later draws need not
    // look at their triangles.
    if (std::find(out->begin(), out->end(), uint8_t(0)) == out->end()) return nullptr;
    return out;
}

}  // namespace emu
