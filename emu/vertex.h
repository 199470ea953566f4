// Vertex processing of DrawPrimitiveUP (docs/device.md "Drawing"): the FVF layout, reading a
// user-pointer stream, the World·View·Projection transform and homogeneous clipping of
// untransformed vertices, the viewport mapping, pre-transformed XYZRHW vertices as given,
// texture-coordinate routing (TEXCOORDINDEX) and texture transforms, and the assembly of
// triangle lists, strips and fans with culling and flat shading. The output is screen-space
// triangles for the rasteriser (emu/raster.h).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "emu/d3d9types.h"
#include "emu/state.h"

namespace emu {

constexpr int kMaxTexSets = ps11::kMaxTexCoordSets;  // ps11/caps.h

// Interpolated attributes of a vertex: diffuse rgba, specular rgba (alpha = vertex fog factor),
// then the eight executor texture-coordinate slots u v w q (slot i, not vertex set i: the
// routing by TEXCOORDINDEX has been applied).
enum : int { kAttrDiffuse = 0, kAttrSpecular = 4, kAttrTex = 8, kAttrCount = 8 + 4 * kMaxTexSets };
constexpr int attrTex(int slot, int comp) { return kAttrTex + 4 * slot + comp; }

// An FVF's memory layout. Only the bits the device takes: XYZ or XYZRHW, NORMAL and PSIZE
// (skipped), DIFFUSE, SPECULAR, TEX0..TEX8 with TEXCOORDSIZE1..4 per set.
struct VertexLayout {
    bool pretransformed = false;  // D3DFVF_XYZRHW
    bool hasDiffuse = false, hasSpecular = false;
    int texCount = 0;
    std::array<uint8_t, kMaxTexSets> texSize{};  // components of each set, 1..4
    uint32_t diffuseOffset = 0, specularOffset = 0;
    std::array<uint32_t, kMaxTexSets> texOffset{};
    uint32_t size = 0;  // bytes of one vertex (the smallest stride DrawPrimitiveUP takes)
};

// Parses an FVF; nullopt and `error` (what is wrong, without a code) for one the device refuses.
std::optional<VertexLayout> parseFvf(DWORD fvf, std::string& error);

// Whether D3DRS_CULLMODE `cull` removes a screen-space polygon whose doubled signed area (the
// sum of x_i·y_(i+1) − x_(i+1)·y_i; > 0: clockwise on the screen, y down) is `area2`. A
// polygon of no area is always removed.
inline bool culledByWinding(DWORD cull, double area2) {
    return !(area2 != 0) || (cull == D3DCULL_CW && area2 > 0) || (cull == D3DCULL_CCW && area2 < 0);
}

// A vertex after processing, in screen space: x, y in pixels (pixel centres at integers), z in
// [MinZ, MaxZ] after the viewport, rhw = 1/w (1 for a vertex given without perspective).
struct ScreenVertex {
    double x = 0, y = 0;
    float z = 0;
    float rhw = 1;
    std::array<float, kAttrCount> attr{};
};

// A triangle ready for the rasteriser, its vertices in the order given (winding preserved).
struct ScreenTriangle {
    std::array<ScreenVertex, 3> v;
};

// What vertex processing needs from the draw besides the device state.
struct VertexSetup {
    const VertexLayout* layout = nullptr;
    // Attribute mask (bit per attribute index): which attributes the pixel stage reads. Others
    // are left 0 (cheaper clipping and setup).
    uint64_t usedAttrs = ~uint64_t(0);
};

// Processes triangles [first, first + count) of a draw of type `type` (TRIANGLELIST, STRIP or
// FAN) from the stream: transforms, clips, culls (D3DRS_CULLMODE), applies flat shading
// (D3DRS_SHADEMODE) and appends the resulting screen triangles to `out`, in order. Triangles with
// non-finite positions, or XYZRHW vertices with rhw <= 0, are dropped. `stats` (optional) is
// added to. The draw calls it in chunks so memory stays bounded for any primitive count.
struct VertexStats {
    uint64_t triangles = 0;  // input triangles
    uint64_t culled = 0;     // removed by culling or as degenerate
    uint64_t clipped = 0;    // wholly outside (or dropped as invalid)
};
void processTriangles(const DeviceState& state, const VertexSetup& setup, D3DPRIMITIVETYPE type, uint32_t first,
                      uint32_t count, const uint8_t* data, uint32_t stride, std::vector<ScreenTriangle>& out,
                      VertexStats* stats = nullptr);

// Number of vertices a draw of `primitiveCount` triangles reads (0 for other types).
uint64_t vertexCountOf(D3DPRIMITIVETYPE type, uint64_t primitiveCount);

// Guard band: screen coordinates are kept within ±kGuardBand pixels (clipped polygons beyond),
// so the rasteriser's fixed-point edge functions cannot overflow.
constexpr double kGuardBand = 1 << 20;

}  // namespace emu
