#include "glare/shade.h"

#include <cmath>
#include <cstring>

#include "emu/format.h"
#include "emu/fullscreen.h"

namespace glare {

using namespace emu;

std::optional<FloatImage> shade(const DeviceOptions& options, const ShadeRequest& request, std::string& error) {
    Device d(options);
    const bool ideal = d.hardware().precision == ps11::Precision::Ideal;
    const D3DFORMAT f = ideal ? D3DFMT_A32B32G32R32F : D3DFMT_A8R8G8B8;
    const FormatInfo& info = *formatInfo(f);
    uint32_t w = request.width, h = request.height;
    if (w == 0 || h == 0) {
        if (request.textures.empty() || !request.textures[0]) {
            error = "the output size is not given and there is no texture 0 to take it from";
            return std::nullopt;
        }
        w = request.textures[0]->image.width;
        h = request.textures[0]->image.height;
    }
    auto fail = [&](const std::string& what) -> std::optional<FloatImage> {
        error = what.empty() ? d.lastError().message : what;
        return std::nullopt;
    };
    Handle ps{};
    if (d.CreatePixelShaderFromText(request.shaderText, &ps) != D3D_OK || d.SetPixelShader(ps) != D3D_OK) return fail("");
    std::array<QuadCoords, 4> coords{};
    for (size_t s = 0; s < request.textures.size(); ++s) {
        if (!request.textures[s]) continue;
        const ShadeTexture& t = *request.textures[s];
        Handle tex{};
        D3DLOCKED_RECT lr{};
        if (d.CreateTexture(t.image.width, t.image.height, 1, 0, f, D3DPOOL_MANAGED, &tex) != D3D_OK ||
            d.LockRect(tex, 0, &lr, nullptr, 0) != D3D_OK)
            return fail("");
        const SurfacePixels px = surfacePixels(t.image, f);
        const size_t row = size_t(t.image.width) * px.bytesPerPixel;
        for (uint32_t y = 0; y < t.image.height; ++y)
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch), &px.bytes[y * row], row);
        const DWORD stage = DWORD(s);
        if (d.UnlockRect(tex, 0) != D3D_OK || d.SetTexture(stage, tex) != D3D_OK ||
            d.SetSamplerState(stage, D3DSAMP_MINFILTER, t.filter) != D3D_OK ||
            d.SetSamplerState(stage, D3DSAMP_MAGFILTER, t.filter) != D3D_OK ||
            d.SetSamplerState(stage, D3DSAMP_ADDRESSU, D3DTADDRESS_CLAMP) != D3D_OK ||
            d.SetSamplerState(stage, D3DSAMP_ADDRESSV, D3DTADDRESS_CLAMP) != D3D_OK)
            return fail("");
    }
    for (const auto& [reg, v] : request.constants)
        if (d.SetPixelShaderConstantF(UINT(reg), v.data(), 1) != D3D_OK) return fail("");
    Handle target{};
    if (d.CreateRenderTarget(w, h, f, 1, &target) != D3D_OK || d.SetRenderTarget(0, target) != D3D_OK ||
        d.Clear(0, nullptr, D3DCLEAR_TARGET, 0, 1, 0) != D3D_OK || drawFullscreenQuad(d, coords) != D3D_OK)
        return fail("");
    std::optional<SurfacePixels> px = readSurface(d, target, error);
    if (!px) return std::nullopt;
    FloatImage out;
    out.width = w;
    out.height = h;
    out.rgba.resize(size_t(w) * h * 4);
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        const auto v = decodeTexel(info, &px->bytes[i * info.bytes], ps11::SignedDecode{});
        std::memcpy(&out.rgba[i * 4], v.data(), sizeof(float) * 4);
    }
    return out;
}

}  // namespace glare
