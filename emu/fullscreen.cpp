#include "emu/fullscreen.h"

#include <cmath>
#include <cstring>

#include "emu/format.h"

namespace emu {

std::array<QuadVertex, 4> halfPixelQuad(float x0, float y0, float x1, float y1, const std::array<QuadCoords, 4>& coords,
                                        DWORD diffuse, DWORD specular) {
    std::array<QuadVertex, 4> v{};
    for (int i = 0; i < 4; ++i) {
        const bool right = i & 1, bottom = i >> 1;
        QuadVertex& q = v[size_t(i)];
        q = {right ? x1 - 0.5f : x0 - 0.5f, bottom ? y1 - 0.5f : y0 - 0.5f, 0, 1, diffuse, specular, {}};
        for (size_t t = 0; t < 4; ++t) {
            q.tex[t][0] = right ? coords[t].u1 : coords[t].u0;
            q.tex[t][1] = bottom ? coords[t].v1 : coords[t].v0;
        }
    }
    return v;
}

HRESULT drawFullscreenQuad(Device& device, const std::array<QuadCoords, 4>& coords, DWORD diffuse) {
    D3DVIEWPORT9 vp{};
    HRESULT hr = device.GetViewport(&vp);
    if (hr != D3D_OK) return hr;
    if ((hr = device.SetFVF(kQuadFvf)) != D3D_OK) return hr;
    const auto v = halfPixelQuad(float(vp.X), float(vp.Y), float(vp.X + vp.Width), float(vp.Y + vp.Height), coords, diffuse);
    return device.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, v.data(), sizeof(QuadVertex));
}

std::optional<SurfacePixels> readSurface(Device& device, Handle surface, std::string& error) {
    D3DSURFACE_DESC desc{};
    Handle copy{};
    D3DLOCKED_RECT locked{};
    auto fail = [&]() -> std::optional<SurfacePixels> {
        error = device.lastError().message;
        if (copy != Handle::Null) device.Release(copy);
        return std::nullopt;
    };
    if (device.GetDesc(surface, &desc) != D3D_OK) return fail();
    if (device.CreateOffscreenPlainSurface(desc.Width, desc.Height, desc.Format, D3DPOOL_SYSTEMMEM, &copy) != D3D_OK ||
        device.GetRenderTargetData(surface, copy) != D3D_OK ||
        device.LockRect(copy, &locked, nullptr, D3DLOCK_READONLY) != D3D_OK)
        return fail();
    SurfacePixels out;
    out.width = desc.Width;
    out.height = desc.Height;
    out.format = desc.Format;
    const FormatInfo* info = formatInfo(desc.Format);
    out.bytesPerPixel = info ? info->bytes : 4;
    const size_t row = size_t(desc.Width) * out.bytesPerPixel;
    out.bytes.resize(row * desc.Height);
    for (uint32_t y = 0; y < desc.Height; ++y)
        std::memcpy(&out.bytes[y * row], static_cast<const uint8_t*>(locked.pBits) + size_t(y) * size_t(locked.Pitch), row);
    device.UnlockRect(copy);
    device.Release(copy);
    return out;
}

SurfacePixels surfacePixels(const FloatImage& image, D3DFORMAT format) {
    const FormatInfo& info = *formatInfo(format);
    SurfacePixels px;
    px.width = image.width;
    px.height = image.height;
    px.format = format;
    px.bytesPerPixel = info.bytes;
    px.bytes.resize(size_t(image.width) * image.height * info.bytes);
    for (size_t i = 0; i < size_t(image.width) * image.height; ++i) {
        const float* v = &image.rgba[i * 4];
        uint8_t* p = &px.bytes[i * info.bytes];
        if (info.cls == FormatClass::Float) {
            encodeFloat(info, {v[0], v[1], v[2], v[3]}, p);
        } else {
            std::array<uint8_t, 4> b{};
            for (size_t c = 0; c < 4; ++c) b[c] = uint8_t(std::lround(std::fmin(std::fmax(v[c], 0.0f), 1.0f) * 255.0f));
            encodeUnorm8(info, b, p);
        }
    }
    return px;
}

bool writeSurface(Device& device, Handle surface, const SurfacePixels& pixels, std::string& error) {
    D3DSURFACE_DESC desc{};
    Handle staging{};
    D3DLOCKED_RECT locked{};
    auto fail = [&](std::string message) {
        error = std::move(message);
        if (staging != Handle::Null) device.Release(staging);
        return false;
    };
    if (device.GetDesc(surface, &desc) != D3D_OK) return fail(device.lastError().message);
    if (desc.Width != pixels.width || desc.Height != pixels.height || desc.Format != pixels.format)
        return fail("writeSurface: the pixels are " + std::to_string(pixels.width) + "x" + std::to_string(pixels.height) +
                    " and the surface " + std::to_string(desc.Width) + "x" + std::to_string(desc.Height) +
                    (desc.Format != pixels.format ? " of another format" : ""));
    const size_t row = size_t(pixels.width) * pixels.bytesPerPixel;
    if (pixels.bytes.size() != row * pixels.height) return fail("writeSurface: the pixel buffer has the wrong size");
    if (device.CreateOffscreenPlainSurface(desc.Width, desc.Height, desc.Format, D3DPOOL_DEFAULT, &staging) != D3D_OK ||
        device.LockRect(staging, &locked, nullptr, 0) != D3D_OK)
        return fail(device.lastError().message);
    for (uint32_t y = 0; y < pixels.height; ++y)
        std::memcpy(static_cast<uint8_t*>(locked.pBits) + size_t(y) * size_t(locked.Pitch), &pixels.bytes[y * row], row);
    if (device.UnlockRect(staging) != D3D_OK || device.StretchRect(staging, nullptr, surface, nullptr, D3DTEXF_POINT) != D3D_OK)
        return fail(device.lastError().message);
    device.Release(staging);
    return true;
}

}  // namespace emu
