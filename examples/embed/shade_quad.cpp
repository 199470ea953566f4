// Assembles a ps_1_1 shader from a string, draws it over a full-screen quad on the device
// (software renderer) with a 2x2 texture, and prints a few pixels read back.
#include <cstdio>
#include <cstring>
#include <optional>
#include <vector>

#include "emu/device.h"
#include "emu/fullscreen.h"
#include "ps11/assembler.h"
#include "ps11/encoder.h"
#include "ps11/validator.h"

int main() {
    // The toolchain: text -> program -> validated -> D3D9 token stream.
    const char* source =
        "ps_1_1\n"
        "def c0, 0.5, 0.5, 0.5, 1\n"
        "tex t0\n"
        "mul r0, t0, c0\n";
    ps11::Diagnostics diags;
    std::optional<ps11::Program> program = ps11::parseAssembly(source, "example.psh", {}, diags);
    if (!program || !ps11::validate(*program, diags)) {
        std::fprintf(stderr, "%s", diags.formatAll().c_str());
        return 1;
    }
    const std::vector<uint32_t> tokens = ps11::encode(*program);

    // The device: D3D9 names (D3DFMT_*, D3D_OK, … in namespace emu) and return codes; the
    // software renderer by default.
    using namespace emu;
    emu::Device device;
    emu::Handle shader{}, texture{}, target{};
    if (device.CreatePixelShader(tokens, &shader) != D3D_OK || device.SetPixelShader(shader) != D3D_OK) {
        std::fprintf(stderr, "%s\n", device.lastError().message.c_str());
        return 1;
    }

    // A 2x2 A8R8G8B8 texture: red, green / blue, white (0xAARRGGBB words).
    const uint32_t texels[4] = {0xffff0000, 0xff00ff00, 0xff0000ff, 0xffffffff};
    D3DLOCKED_RECT locked{};
    if (device.CreateTexture(2, 2, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &texture) != D3D_OK ||
        device.LockRect(texture, 0, &locked, nullptr, 0) != D3D_OK)
        return 1;
    for (int y = 0; y < 2; ++y)
        std::memcpy(static_cast<uint8_t*>(locked.pBits) + y * locked.Pitch, &texels[y * 2], 2 * sizeof(uint32_t));
    device.UnlockRect(texture, 0);
    device.SetTexture(0, texture);

    // An 8x8 render target, cleared, then the quad with its half-pixel offset (emu/fullscreen.h).
    if (device.CreateRenderTarget(8, 8, D3DFMT_A8R8G8B8, 1, &target) != D3D_OK ||
        device.SetRenderTarget(0, target) != D3D_OK || device.Clear(0, nullptr, D3DCLEAR_TARGET, 0, 1, 0) != D3D_OK ||
        emu::drawFullscreenQuad(device) != D3D_OK) {
        std::fprintf(stderr, "%s\n", device.lastError().message.c_str());
        return 1;
    }

    // Read back (GetRenderTargetData into a SYSTEMMEM surface): b g r a bytes per pixel.
    std::string error;
    std::optional<emu::SurfacePixels> pixels = emu::readSurface(device, target, error);
    if (!pixels) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return 1;
    }
    const uint32_t corners[4][2] = {{0, 0}, {7, 0}, {0, 7}, {7, 7}};
    for (const auto& [x, y] : corners) {
        const uint8_t* p = &pixels->bytes[(y * pixels->width + x) * 4];
        std::printf("pixel (%u, %u): r %3d g %3d b %3d a %3d\n", x, y, p[2], p[1], p[0], p[3]);
    }
    return 0;
}
