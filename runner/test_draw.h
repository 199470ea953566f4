// Running a .ps11test's `draw` commands and pixel probes on the emu device (the part of
// `ps11 test` that needs a render target): the file's sections become the D3D9 calls a user
// would make (CreateTexture + LockRect, SetSamplerState, SetTextureStageState, SetRenderState,
// SetTransform, SetPixelShader, SetPixelShaderConstantF), each draw becomes DrawPrimitiveUP and
// each probe reads the target back through GetRenderTargetData.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ps11/hardware.h"
#include "ps11/ir.h"
#include "ps11/precision.h"
#include "ps11/testfile.h"
#include "runner/gl_backend.h"

namespace emu {
class Device;
}

namespace ps11test {

// The test model and toolchain types the runner speaks (ps11/testfile.h, ps11/ir.h, ps11/hardware.h).
using ps11::HardwareConfig;
using ps11::Probe;
using ps11::Program;
using ps11::TestCommand;
using ps11::TestFile;
using ps11::TexFormat;
using ps11::Vec4;

// Statistics over a file's draws (Device::lastDrawStats summed).
struct DrawTally {
    size_t draws = 0;
    uint64_t pixelsShaded = 0;
    uint64_t pixelsWritten = 0;
    uint64_t texelsFetched = 0;
    uint64_t instructions = 0;
    double milliseconds = 0;
    // The software renderer's 16x64 tiles by decision (docs/device.md "Tile skipping"); 0 on
    // renderers and draws that do not tile.
    uint64_t tilesShaded = 0, tilesFilled = 0, tilesCopied = 0, tilesSkipped = 0;
};

class DrawRunner {
public:
    // Sets up the device for `file`: render target (and depth buffer), textures, sampler, stage
    // and render states, transforms, constants and the pixel shader (`program`, null = fixed
    // function) on a device of `hardware`. Returns null with `error` set ("FILE:LINE: …") when
    // the device refuses a call. `fastPaths` false draws the general way: the software renderer's
    // alignedPasses and fastSampler off, every triangle in 2×2 quads and every lookup by the
    // reference sampler (the fuzzer and the random-program test draw both ways and compare);
    // `renderer` makes the device's renderer (empty: the software renderer);
    // `skipTiles` is emu::DeviceOptions::software.skipTiles (`ps11 test --no-skip` turns it off).
    static std::unique_ptr<DrawRunner> create(const TestFile& file, const std::string& path, const Program* program,
                                              const HardwareConfig& hardware, std::string& error,
                                              bool fastPaths = true, const RendererFactory& renderer = {},
                                              bool skipTiles = true);
    ~DrawRunner();

    // Runs a `draw quad` / `draw triangles|strip|fan` command; false with `error` set when the
    // device refuses it.
    bool draw(const TestCommand& command, std::string& error);
    // Checks a pixel, rect or all probe against the render target: "" when it passes, else
    // what was expected and what the first failing pixel holds.
    std::string probe(const Probe& probe, std::string& error);

    const DrawTally& tally() const { return m_tally; }

    // The render target as read back (8-bit levels, or values on float targets), row by row;
    // false with `error` set when the device refuses the read-back.
    bool targetPixels(std::vector<Vec4>& out, std::string& error);
    uint32_t width() const { return m_width; }
    uint32_t height() const { return m_height; }
    // The target stores floats (values), not 8-bit levels.
    bool floatTarget() const;
    // The device the file is set up on (the fuzzer takes fingerprints on it).
    emu::Device& device() { return *m_device; }

private:
    DrawRunner() = default;
    bool readBack(std::string& error);

    std::unique_ptr<emu::Device> m_device;
    std::string m_path;
    uint32_t m_width = 0, m_height = 0;
    TexFormat m_format = TexFormat::A8R8G8B8;
    uint32_t m_target = 0;  // emu::Handle of the render target
    bool m_readBackValid = false;
    std::vector<Vec4> m_pixels;          // read-back values: 8-bit levels, or floats on float targets
    std::vector<uint32_t> m_pixelWords;  // read-back 0xAARRGGBB (8-bit targets)
    DrawTally m_tally;
};

}  // namespace ps11test
