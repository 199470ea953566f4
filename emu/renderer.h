// The seam between the device front and a renderer (docs/device.md "Front and renderers"): the
// front (emu/device*.cpp) checks every D3D9 call, translates sampler, stage and render states into
// the resolved plain values below and processes vertices; a renderer only draws what a DrawCall
// says. The software renderer (emu/software_renderer.*: rasteriser, executor, aligned passes,
// output merger, threads) is one implementation.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "emu/output_merger.h"
#include "emu/raster.h"
#include "emu/resources.h"
#include "emu/state.h"
#include "emu/vertex.h"
#include "ps11/executor.h"
#include "ps11/hardware.h"
#include "ps11/ir.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler.h"

namespace emu {

// Counts of one draw (Device::lastDrawStats) or of all draws so far (Device::totalDrawStats).
struct DrawStats {
    uint64_t draws = 0;           // DrawPrimitiveUP calls that succeeded
    uint64_t triangles = 0;       // input triangles
    uint64_t trianglesDrawn = 0;  // triangles rasterised (after clipping, culling; a clipped polygon is a fan)
    uint64_t pixelsCovered = 0;   // pixels inside a triangle and the clip rect
    uint64_t pixelsShaded = 0;    // lanes the executor ran: covered pixels plus quad helper lanes
    uint64_t pixelsWritten = 0;   // pixels that reached the colour or depth store (output merger)
    uint64_t texelsFetched = 0;   // texels read by the sampler
    uint64_t instructions = 0;    // instruction executions (per lane)
    double milliseconds = 0;      // wall time of the call
    DrawStats& operator+=(const DrawStats& o);
};

// The pixel program of a draw: a pixel shader or the lowered fixed-function stages (emu/ffp.h),
// already validated, with everything the program reads resolved.
struct DrawProgram {
    const ps11::Program* program = nullptr;
    // Identity for the renderer's caches: equal keys mean the same program (a shader handle, or
    // the fixed-function state the lowering read).
    uint64_t key = 0;
    bool fixedFunction = false;
    uint64_t attributesRead = 0;  // attribute mask (emu/vertex.h) the program reads
    bool kills = false;           // the program has texkill
    std::array<std::array<float, 4>, kMaxPsConstants> constants{};  // SetPixelShaderConstantF c0..c7
    std::array<ps11::StageState, kMaxStages> stages{};               // per-stage executor values
};

// The attributes a program reads (emu/vertex.h indices): v0/v1 as diffuse/specular, t# as
// texture-coordinate slots. Conservative: any t# operand (destination of a texture-address
// instruction in 1_1–1_3, texld/texcrd source in 1_4) marks its slot.
uint64_t attributesRead(const ps11::Program& program);

// One DrawPrimitiveUP, resolved by the front.
struct DrawCall {
    ps11::HardwareConfig hardware;  // class, profile, MaxValue, filter weights
    DrawProgram program;
    // Bound textures of the stages the program samples (null: samples (0, 0, 0, 1)) and every
    // stage's sampler state.
    std::array<std::shared_ptr<const ps11::Texture>, kMaxSamplers> textures;
    std::array<ps11::SamplerState, kMaxSamplers> samplers;
    MergeState merge;
    MergeTarget target;         // colour image and depth image (null: none)
    ClipRect clip;              // viewport ∩ scissor ∩ target, in pixels
    uint64_t usedAttributes = 0;  // what the vertices carry to the pixel stage (program, fog)
    uint32_t primitiveCount = 0;
    // Vertex processing: screen triangles of primitives [first, first + count) in primitive
    // order (clipped, culled; a clipped polygon is a fan).
    std::function<void(uint32_t first, uint32_t count, std::vector<ScreenTriangle>& out)> assemble;
};

// What a renderer reports when it cannot draw a call the front accepted.
struct RendererError {
    HRESULT hr = D3D_OK;
    std::string code;     // "E4121"
    std::string message;  // without the code: "the executor refused pixel shader 3"
};

class Renderer {
public:
    virtual ~Renderer() = default;
    // Draws the call into call.target, adding to `stats` (pixels, instructions, texels,
    // triangles drawn). False with `error` set when it cannot (nothing was written then).
    virtual bool draw(const DrawCall& call, DrawStats& stats, RendererError& error) = 0;
    // "software" (the name `ps11 test --stats` and the docs use).
    virtual const char* name() const = 0;
};

}  // namespace emu
