// Tile facts the device knows without a scan (docs/device.md "Tile facts from clears"): a level 0
// cleared whole holds one value in every texel, and a draw into it afterwards can change only
// the tiles its triangles reach. The device keeps a byte per tile of the texture's tile grid
// (ps11::texelTileSide) flagging those; the tile skipper then scans one unflagged tile and the
// flagged ones instead of the whole level (ps11::uniformTileRange).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "emu/renderer.h"

namespace emu {

// The tiles of an image's tile grid, all unflagged.
size_t uniformTileCount(const Image& image);
// `stale` with every tile flagged that a triangle of `call` may cover inside its clip rectangle
// (each triangle's bounding box, a pixel wider each side; every tile where a triangle's vertices
// are not finite). Null, nothing known, where every tile is then flagged, or where the draw has
// more triangles than are worth assembling a second time.
std::shared_ptr<const std::vector<uint8_t>> markDrawnTiles(const DrawCall& call, const Image& target,
                                                           const std::vector<uint8_t>& stale);

}  // namespace emu
