// The seam between the device front and a renderer (docs/device.md "Front and renderers"): the
// front (emu/device*.cpp) checks every D3D9 call, translates sampler, stage and render states into
// the resolved plain values below and processes vertices; a renderer draws, clears, stretches and
// reads back what the calls say. The software renderer (emu/software_renderer.*: rasteriser,
// executor, aligned passes, output merger, threads) works in the front's own images; the GL
// renderer (emu/gl/gl_renderer.h) keeps its own copy of every surface it has been handed and
// follows the front's contents by generation.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "emu/call_error.h"
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

class ThreadPool;

// Counts of one draw (Device::lastDrawStats) or of all draws so far (Device::totalDrawStats).
struct DrawStats {
    uint64_t draws = 0;           // DrawPrimitiveUP calls that succeeded
    uint64_t triangles = 0;       // input triangles
    uint64_t trianglesDrawn = 0;  // triangles rasterised (after clipping, culling; a clipped polygon is a fan)
    uint64_t pixelsCovered = 0;   // pixels inside a triangle and the clip rect
    uint64_t pixelsRowPath = 0;   // of those, the ones a row path drew (emu/aligned_pass.h; 0 on the GL renderer)
    uint64_t pixelsShaded = 0;    // lanes the executor ran: covered pixels plus quad helper lanes
    uint64_t pixelsWritten = 0;   // pixels that reached the colour or depth store (output merger)
    uint64_t texelsFetched = 0;   // texels read by the sampler
    uint64_t instructions = 0;    // instruction executions (per lane)
    // Tiles of row-path draws (emu/tile_skip.h): shaded, filled with a constant, copied from one
    // tap, skipped (the merge would change nothing). All zero where the renderer does not decide
    // tiles (the GL renderer, quad-path draws, skipping off).
    uint64_t tilesShaded = 0, tilesFilled = 0, tilesCopied = 0, tilesSkipped = 0;
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

// A surface as a renderer sees it: a level of a texture or a standalone surface, with the
// front's image (format, size; its bytes are current unless the renderer holds newer contents)
// and the versions of its contents. A renderer that keeps copies uploads the front's image when
// its copy's generation differs from `generation`; after writing it, its copy is `writeGeneration`.
struct SurfaceDesc {
    uint32_t resource = 0;       // the device's handle of the owning texture or surface (0: none)
    uint32_t level = 0;
    Image* image = nullptr;      // the front's copy
    uint64_t generation = 0;     // the level's contents now
    uint64_t writeGeneration = 0;  // the level's contents after this call writes it
    bool valid() const { return resource != 0 && image != nullptr; }
};

// A texture bound to a stage, for renderers that keep copies: the texture's identity and a way
// to get the front's sampler view (which first brings back any level the renderer holds newer).
struct TextureRef {
    uint32_t resource = 0;  // 0: none bound
    int levels = 0;         // every level, the hidden ones of AUTOGENMIPMAP included
    bool volume = false;
    const FormatInfo* format = nullptr;
    SurfaceDesc level0;     // level 0 (generation as the front knows it)
};

// One DrawPrimitiveUP, resolved by the front.
struct DrawCall {
    ps11::HardwareConfig hardware;  // class, profile, MaxValue, filter weights
    DrawProgram program;
    // Bound textures of the stages the program samples (null: samples (0, 0, 0, 1)) and every
    // stage's sampler state.
    std::array<std::shared_ptr<const ps11::Texture>, kMaxSamplers> textures;
    std::array<ps11::SamplerState, kMaxSamplers> samplers;
    // For renderers that keep copies (Renderer::keepsCopies): the bound textures by identity,
    // `textures` left empty; textureView(s) gives the front's sampler view of stage s when the
    // renderer needs it (null when it cannot be made).
    std::array<TextureRef, kMaxSamplers> textureRefs;
    std::function<std::shared_ptr<const ps11::Texture>(int stage)> textureView;
    MergeState merge;
    MergeTarget target;         // colour image and depth image (null: none)
    SurfaceDesc colorSurface, depthSurface;  // the same surfaces by identity (depth: when bound)
    ClipRect clip;              // viewport ∩ scissor ∩ target, in pixels
    uint64_t usedAttributes = 0;  // what the vertices carry to the pixel stage (program, fog)
    uint32_t primitiveCount = 0;
    // Vertex processing: screen triangles of primitives [first, first + count) in primitive
    // order (clipped, culled; a clipped polygon is a fan).
    std::function<void(uint32_t first, uint32_t count, std::vector<ScreenTriangle>& out)> assemble;
};

// A rectangle of pixels, x1 and y1 exclusive.
struct PixelBox {
    int64_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x0 >= x1 || y0 >= y1; }
};

// One Clear, resolved by the front: the boxes (viewport ∩ scissor ∩ rects, inside the surfaces)
// and what each cleared texel becomes.
struct ClearCall {
    SurfaceDesc color;              // not valid: the colour target is not cleared
    SurfaceDesc depth;              // not valid: neither depth nor stencil is cleared
    std::vector<PixelBox> boxes;
    std::array<uint8_t, 16> colorTexel{};  // the colour in the target's format (format->bytes bytes)
    uint32_t depthKeep = 0, depthSet = 0;  // the stored depth word becomes (old & keep) | set
};

// One StretchRect, resolved by the front (rects checked, surfaces distinct, formats drawable).
struct StretchCall {
    SurfaceDesc source, dest;
    PixelBox sourceRect, destRect;
    bool linear = false;             // D3DTEXF_LINEAR (else POINT)
    bool fixedPoint = false;         // fx profiles: 8-bit sub-texel weights
    ps11::SignedDecode decode = ps11::SignedDecode::Snorm;
    // The renderer may put the copy off (StretchRect: the destination then reads as newer in the
    // renderer, Renderer::leftNewer); never where the front reads the destination unsynced.
    bool mayPutOff = false;
};

// Counts of what crossed between the front's images and a renderer's copies.
struct TransferStats {
    uint64_t uploads = 0, uploadBytes = 0;      // front image → renderer copy
    uint64_t readBacks = 0, readBackBytes = 0;  // renderer copy → front image
    TransferStats& operator+=(const TransferStats& o);
};

class Renderer {
public:
    virtual ~Renderer() = default;
    // Draws the call into call.target, adding to `stats` (pixels, instructions, texels,
    // triangles drawn). False with `error` set when it cannot (nothing was written then): the
    // same CallError the front's own draw stages report (emu/call_error.h).
    virtual bool draw(const DrawCall& call, DrawStats& stats, CallError& error) = 0;
    // Clear and StretchRect. False when this renderer does not do this call: the front then
    // brings the surfaces back, does it in its own images (emu/blit.h) and the renderer's
    // copies follow by generation.
    virtual bool clear(const ClearCall& call) = 0;
    virtual bool stretchRect(const StretchCall& call) = 0;
    // Whether the renderer keeps its own copies of surfaces (then the front calls readBack
    // before it reads or writes a level the renderer wrote).
    virtual bool keepsCopies() const { return false; }
    // After a call of the renderer wrote the level: whether its newest bytes are still not in
    // surface.image (a copy the renderer keeps, or a copy it put off); the front then calls
    // readBack before it reads or writes the level.
    virtual bool leftNewer(const SurfaceDesc& surface) const {
        (void)surface;
        return keepsCopies();
    }
    // Writes the renderer's newest bytes of the surface into surface.image.
    virtual void readBack(const SurfaceDesc& surface) { (void)surface; }
    // Before anything writes the resource's levels (the front, a lock, a call of the renderer):
    // a copy put off that reads them is made now.
    virtual void beforeWrite(uint32_t resource) { (void)resource; }
    // The resource is about to go (its images still there): its copies can go, and copies put
    // off that read it are made now.
    virtual void release(uint32_t resource) { (void)resource; }
    // Returns when every call so far has finished (for timings; the software renderer's calls
    // finish before they return).
    virtual void finish() {}
    // Uploads and read-backs so far.
    virtual TransferStats transfers() const { return {}; }
    // "software" (the name `ps11 test --stats` and the docs use).
    virtual const char* name() const = 0;
    // The renderer's worker threads, for CPU work between its calls (the glare sprites' sensors),
    // or null if it has none. Not while a call of the renderer runs.
    virtual ThreadPool* workers() { return nullptr; }
};

}  // namespace emu
