// Tile facts the device knows without a scan (docs/device.md "Tile facts from clears"): a level 0
// cleared whole holds one value in every texel, and a draw into it afterwards can change only
// the tiles its triangles reach. The device keeps a byte per tile of the texture's tile grid
// (ps11::texelTileSide) flagging those; the tile skipper then scans one unflagged tile and the
// flagged ones instead of the whole level (ps11::uniformTileRange).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "emu/renderer.h"

namespace emu {

// The tiles of an image's tile grid, all unflagged.
size_t uniformTileCount(const Image& image);

// The bounding boxes of the triangles a renderer assembled for a call, kept as it assembles them
// (watch), so that markDrawnTiles need not assemble them a second time. Complete when every
// primitive of the call went through the watched assemble at least once.
class AssembledBoxes {
public:
    struct Box {
        double x0, y0, x1, y1;  // of the vertices' positions (any of them NaN where one is not finite)
    };
    // Wraps call.assemble (put back by the destructor).
    explicit AssembledBoxes(DrawCall& call);
    ~AssembledBoxes();
    AssembledBoxes(const AssembledBoxes&) = delete;
    AssembledBoxes& operator=(const AssembledBoxes&) = delete;
    bool complete() const { return m_watching && m_seenCount == m_seen.size(); }
    const std::vector<Box>& boxes() const { return m_boxes; }

private:
    DrawCall& m_call;
    std::function<void(uint32_t, uint32_t, std::vector<ScreenTriangle>&)> m_assemble;
    std::mutex m_mutex;
    bool m_watching = false;      // call.assemble wrapped (not for more triangles than markDrawnTiles marks)
    std::vector<uint8_t> m_seen;  // per primitive: assembled
    size_t m_seenCount = 0;
    std::vector<Box> m_boxes;
};

// `stale` with every tile flagged that a triangle of `call` may cover inside its clip rectangle
// (each triangle's bounding box, a pixel wider each side; every tile where a triangle's vertices
// are not finite). The boxes are `assembled`'s where it is complete; otherwise the triangles are
// assembled again. Null, nothing known, where every tile is then flagged, or where the draw has
// more triangles than are worth assembling a second time.
std::shared_ptr<const std::vector<uint8_t>> markDrawnTiles(const DrawCall& call, const Image& target,
                                                           const std::vector<uint8_t>& stale,
                                                           const AssembledBoxes* assembled = nullptr);

}  // namespace emu
