// Building blocks every post-processing pass of the D3D8/9 era repeats, written once: the
// half-pixel full-screen quad (D3D9 pixel centres sit at integer coordinates, so a quad from
// (−0.5, −0.5) to (w − 0.5, h − 0.5) with texture coordinates 0..1 lands every pixel on a texel
// centre of a same-sized texture), the read-back of a render target and the upload of pixels into
// one. Everything goes through emu::Device's D3D9 calls, so it runs on either renderer.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "emu/d3d9types.h"
#include "emu/device.h"
#include "emu/image_file.h"

namespace emu {

// A pre-transformed vertex with diffuse, specular and four 2D texture-coordinate sets.
struct QuadVertex {
    float x, y, z, rhw;
    DWORD diffuse, specular;
    float tex[4][2];
};
inline constexpr DWORD kQuadFvf = D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_SPECULAR | D3DFVF_TEX4;

// Per texture-coordinate set: where the quad's corners sample, in texture coordinates. The default
// covers (0,0)–(1,1); `offset` moves it (a tap `k` texels right of the pixel's own texel is
// offset = k / textureWidth).
struct QuadCoords {
    float u0 = 0, v0 = 0, u1 = 1, v1 = 1;
};
inline QuadCoords shifted(float du, float dv) { return {du, dv, 1 + du, 1 + dv}; }

// The four corners of the half-pixel quad over the rectangle [x0, x1) × [y0, y1) of a target,
// as a triangle strip; every vertex carries `diffuse` and `specular`.
std::array<QuadVertex, 4> halfPixelQuad(float x0, float y0, float x1, float y1, const std::array<QuadCoords, 4>& coords,
                                        DWORD diffuse = 0xffffffff, DWORD specular = 0);

// Draws the half-pixel quad over the whole of the bound render target (size from the viewport):
// SetFVF(kQuadFvf), then one DrawPrimitiveUP strip. Returns the device's HRESULT.
HRESULT drawFullscreenQuad(Device& device, const std::array<QuadCoords, 4>& coords = {},
                           DWORD diffuse = 0xffffffff);

// A render target's pixels, read back through GetRenderTargetData into a SYSTEMMEM surface:
// `bytes` in the surface's own layout (A8R8G8B8: b g r a per pixel), rows without padding.
struct SurfacePixels {
    uint32_t width = 0, height = 0;
    D3DFORMAT format = D3DFMT_A8R8G8B8;
    uint32_t bytesPerPixel = 4;
    std::vector<uint8_t> bytes;
};
// nullopt with `error` = the device's message on failure.
std::optional<SurfacePixels> readSurface(Device& device, Handle surface, std::string& error);
// A float image in `format`'s layout: 8-bit formats clamp to [0, 1] and round to nearest, float
// formats keep the values (A8R8G8B8 and A32B32G32R32F, what the glare runner and `ps11 shade` use;
// any Unorm8 or Float-class format works).
SurfacePixels surfacePixels(const FloatImage& image, D3DFORMAT format);
// Writes `pixels` (same size and format) into a DEFAULT-pool surface (a render target or a render-
// target texture level) through a DEFAULT offscreen plain surface and a 1:1 POINT StretchRect.
bool writeSurface(Device& device, Handle surface, const SurfacePixels& pixels, std::string& error);

}  // namespace emu
