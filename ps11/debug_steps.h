// One traced pixel of a program on a hardware class beside `ideal`, instruction by instruction,
// with why the two part (`ps11 debug`, docs/debug.md; `ps11 debug --technique`, which traces
// every pass of a glare frame that led to one output pixel: glare/frame_debug.h). The two traces
// come from Executor::trace; the "why" from the interval evaluator run over the pixel's own
// inputs, each a single point, so its findings are exact.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ps11/caps.h"
#include "ps11/executor.h"
#include "ps11/hardware.h"
#include "ps11/ir.h"
#include "ps11/texture_sampler.h"

namespace ps11 {

// The pixel's inputs as the interval evaluator takes them: constants as set (a def overrides),
// v0/v1 as interpolated, the texture coordinates, and per stage the value its lookups return
// (the class's, as sampled).
struct DebugInputs {
    std::array<std::array<float, 4>, 8> constants{};
    std::array<std::array<float, 4>, 2> color{};
    std::array<std::array<float, 4>, kMaxTexCoordSets> texcoord{};
    std::array<std::array<float, 4>, kMaxTextureStages> stage{};
    // Stages whose texels differ between the class's and ideal's textures (a frame's earlier
    // passes stored them differently): a lookup that differs there takes its difference from
    // its sources, not from the lookup.
    std::array<bool, kMaxTextureStages> texelsDiffer{};
};

// One executed instruction: its destination on the class and in ideal.
struct DebugStep {
    int instruction = -1;  // index in Program::instructions
    uint32_t line = 0;     // its source line
    std::string text;      // as the disassembler writes it
    bool writes = false;   // writes its destination (values below are meaningful)
    uint8_t mask = 0;      // the channels it writes
    std::array<float, 4> emulated{}, ideal{};
    std::array<int32_t, 4> grid{};  // the class's grid integers (fx profiles)
    double levels = 0;              // max |class − ideal| over the written channels, 8-bit levels
    // What the class's write step did here: round, clamp, saturate, signed_decode, filter_weight.
    std::vector<std::string> why;
};

// The rows of two traces of one program (`emulated` on `hardware`, `ideal` under Precision::Ideal
// on the same class) over one pixel. `sampler` is the class's (its textures name
// signed_decode and filter_weight).
std::vector<DebugStep> debugSteps(const Program& program, const HardwareConfig& hardware, const DebugInputs& inputs,
                                  const std::vector<TraceStep>& emulated, const std::vector<TraceStep>& ideal,
                                  const TextureSampler& sampler);

// The index of the first step where the two part by more than one 8-bit level, or -1.
int firstDivergence(const std::vector<DebugStep>& steps);

}  // namespace ps11
