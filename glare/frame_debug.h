// One output pixel of a glare frame followed back through the passes that made it
// (`ps11 debug --technique`, docs/debug.md "A frame"): the frame runs twice, on the hardware class
// and under `ideal` on the same class, each pass's inputs and outputs captured as it ran
// (transient textures are aliased and overwritten later); from the final pass's pixel the walk
// goes to the texels each tap read (the largest filter weight followed, all of them listed) and
// into the pass that wrote them, and retraces every shader pass it visits with Executor::trace
// on both profiles, from the captured textures, the pass's coordinates at that pixel and its
// constants (ps11/debug_steps.h: the steps and why they part). Per pass: the output pixel on
// both, their difference in 8-bit levels, and how much of it the pass added over its inputs.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "emu/image_file.h"
#include "glare/technique.h"
#include "ps11/debug_steps.h"
#include "ps11/hardware.h"

namespace glare {

struct FrameDebugRequest {
    const Technique* technique = nullptr;
    Settings settings;
    // The input: a built-in scene at width x height, or an image (its own size).
    std::string scene;
    std::optional<emu::FloatImage> image;
    uint32_t width = 480, height = 270;
    int frame = 0;  // frames 0 … frame run; the last one is followed
    const ps11::HardwareClass* hardware = nullptr;  // null: the default 1.1-class card
    uint32_t x = 0, y = 0;                          // the output pixel
};

// One texel a tap's filter reads, with its weight (the class's, 8-bit in fx).
struct DebugTexel {
    uint32_t x = 0, y = 0;
    double weight = 1;
};

// What a visited pass read at its pixel: a shader stage's texture, a StretchRect's source, or
// the target a blend reads.
struct DebugSource {
    std::string role;  // "t0" … "t3", "source" (StretchRect), "target" (a blend reads it)
    int stage = -1;    // the shader stage (−1: none)
    std::string texture;  // the graph's texture name
    uint32_t width = 0, height = 0;
    float u = 0, v = 0;  // the tap's coordinates at the pixel (stage −1: the pixel's own)
    bool linear = false;
    std::vector<DebugTexel> texels;  // largest weight first
    double levels = 0;               // max |class − ideal| over those texels, 8-bit levels
    // The pass that wrote what was read there: an index into FrameDebug::passes, or −1 with
    // `origin` saying what it was ("scene input", "kept from the previous frame", …). Each pass
    // is traced once, at the first pixel the walk reached it by (sources are followed largest
    // difference first, each at its largest-weight texel): `from` may be traced elsewhere.
    int from = -1;
    std::string origin;
};

struct DebugPass {
    std::string pass, kind, shader, note;
    int graphIndex = -1;                  // the pass's index in the frame's graph
    std::string target;                   // the texture it writes
    uint32_t width = 0, height = 0;       // the target's size
    uint32_t x = 0, y = 0;                // the pixel followed
    std::vector<ps11::DebugStep> steps;   // shader passes: the trace, the class beside ideal
    int firstDivergence = -1;             // index in steps (ps11::firstDivergence)
    // The output pixel as the frame stored it (as a sampler reads it back: 8-bit targets n/255,
    // float targets their float), and |class − ideal| over r g b a in 8-bit levels.
    std::array<float, 4> emulated{}, ideal{};
    double levels = 0;
    // levels minus the largest difference among the texels it read: what this pass added.
    double added = 0;
    // Shader passes: the trace's r0 taken through the pass's blend and store on both profiles:
    // equal to `emulated` / `ideal` when the trace reproduces what the frame computed.
    bool traced = false;
    std::array<float, 4> tracedEmulated{}, tracedIdeal{};
    std::vector<DebugSource> sources;
};

struct FrameDebug {
    std::string technique, hardware;
    uint32_t width = 0, height = 0;
    int frame = 0;
    uint32_t x = 0, y = 0;
    bool fx = true;  // the class's profile is fixed point (grid integers in the steps)
    // The visited passes in the order the frame ran them (the final pass last).
    std::vector<DebugPass> passes;
    int mostError = -1;  // index in passes of the largest `added`
};

// Runs the request's frames and follows its pixel. False with `error` (naming the argument:
// an unknown scene, a pixel outside the frame, a failed pass).
bool debugFrame(const FrameDebugRequest& request, FrameDebug& out, std::string& error);

}  // namespace glare
