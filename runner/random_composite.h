// Random composites over a put-off copy (docs/device.md "StretchRect"): a whole-surface copy of a
// scene into a target larger than kComparedResourceBytes (so the software renderer may put it
// off), then a draw into that target that samples a magnified texture of zero, constant and
// random blocks, and the same draw again without a copy. With the fx row path drawing tile by
// tile the draw makes the put-off copy itself (drawAlignedRows' RowSource); every other way the
// copy is made first. The unit tests draw these cases from a seeded generator, the composite
// fuzzer from its input's bytes; both draw each case on several devices (copies put off or made
// at once, row paths or 2×2 quads) and require the same bytes.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "emu/d3d9types.h"
#include "emu/device.h"
#include "ps11/precision.h"

namespace ps11test {

struct CompositeCase {
    uint32_t width = 0, height = 0;                     // the scene and the target
    uint32_t texWidth = 0, texHeight = 0;               // the sampled texture (A8R8G8B8), magnified 1× to 8×
    emu::D3DFORMAT format = emu::D3DFMT_A8R8G8B8;       // the target: A8R8G8B8 or X8R8G8B8
    emu::D3DFORMAT sceneFormat = emu::D3DFMT_A8R8G8B8;  // the scene; now and then the other one (a copy that converts)
    std::string program;                                // ps_1_1 text
    std::array<float, 12> constants{};                  // c0 … c2
    int blend = 0;       // 0: none; 1: ONE/ONE; 2: SRCALPHA/INVSRCALPHA (the output merger's)
    bool linear = true;  // MIN and MAG filter of both stages
    ps11::Precision precision = ps11::Precision::Fx8;
    bool skip = true;  // SoftwareRendererOptions::skipTiles
    // Each quad: the pixel rectangle x0 y0 x1 y1 and stage 0's texel offset du dv (stage 1 samples
    // a hundredth further right). All quads are one draw; later ones blend onto earlier ones.
    std::vector<std::array<float, 6>> quads;
    std::vector<uint8_t> scene;   // width × height × 4, the scene's bytes (b g r a)
    std::vector<uint8_t> texels;  // texWidth × texHeight × 4
    std::string describe() const;
};

// A case drawn from `next`, a source of 32-bit words (a seeded engine, or a fuzzer's bytes: the
// same words give the same case with every standard library).
CompositeCase randomComposite(const std::function<uint32_t()>& next);

// The device options of composite cases: `precision`, two threads, deterministic tile decisions
// (untimed), tiles skipped or not; copies put off or made at once; row paths or 2×2 quads with
// the reference sampler.
emu::DeviceOptions compositeDeviceOptions(ps11::Precision precision, bool skip, bool putOff, bool rowPaths = true);
inline emu::DeviceOptions compositeDeviceOptions(const CompositeCase& c, bool putOff, bool rowPaths = true) {
    return compositeDeviceOptions(c.precision, c.skip, putOff, rowPaths);
}

// Draws the case on a device made with `options`: the copy and the draw, then the draw again
// without a copy. `out` gets the target's bytes after each (width × 4 per row, rows after one
// another); `putOff`, where given, whether the renderer put the copy off. False, with `error`
// naming the call, where the device refused one.
bool drawComposite(const CompositeCase& c, const emu::DeviceOptions& options, std::vector<uint8_t>& out,
                   std::string& error, bool* putOff = nullptr);

}  // namespace ps11test
