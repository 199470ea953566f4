// Executor internals shared by its stages: the decoded op list (built once by create()), the
// per-run register file in structure-of-arrays lanes, and the kernels of each family
// (executor_arith.cpp, executor_texture.cpp). Not part of the public API.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "ps11/executor.h"

namespace ps11::exec {

// Lanes processed at once inside run(): a span is cut into chunks of this size so the working
// set (registers + scratch) stays in L1.
constexpr int kChunk = 128;

// Register file slots: r0..r5, t0..t5 (1_1-1_3 texture registers), v0, v1.
constexpr int kSlotR = 0;
constexpr int kSlotT = 6;
constexpr int kSlotV = 12;
constexpr int kNumSlots = 14;

enum class SrcKind : uint8_t { Reg, Const, TexCoord };

struct DSrc {
    SrcKind kind = SrcKind::Reg;
    uint8_t slot = 0;          // register slot, constant index or texture-coordinate set
    std::array<uint8_t, 4> sw{0, 1, 2, 3};  // component read for each output channel
    SrcMod mod = SrcMod::None;
};

struct DOp {
    Opcode op = Opcode::Nop;
    bool texture = false;   // texture-address instruction
    bool hold = false;      // first member of a co-issued pair: result held until the partner has read
    uint8_t dstSlot = 0;
    uint8_t mask = kMaskAll;
    bool sat = false;
    int8_t shift = 0;
    uint8_t numSrc = 0;
    std::array<DSrc, 3> src{};
    // Texture-address data: stage sampled / coordinate set of the destination, the pad index
    // (0 or 1) of texm3x2pad/texm3x3pad, the first row's stage of a matrix group.
    uint8_t stage = 0;
    uint8_t padIndex = 0;
    uint8_t rowBase = 0;
};

// Register storage of one chunk. Only one of the int / float banks is used per profile.
template <class T>
struct Bank {
    alignas(64) T reg[kNumSlots][4][kChunk];
    alignas(64) T hold[4][kChunk];  // held result of a co-issued pair's first member
};

struct RunState {
    int n = 0;  // lanes in this chunk
    int offset = 0;  // lane offset of the chunk inside the span
    const PixelInputs* in = nullptr;
    Sampler* sampler = nullptr;
    Bank<int32_t> bi;
    Bank<float> bf;
    alignas(64) int32_t k[3][4][kChunk];   // fx: fetched sources as k (value k/(2G))
    alignas(64) float x[3][4][kChunk];     // float: fetched sources
    alignas(64) float pad[2][kChunk];      // texm3x2pad / texm3x3pad dot products
    alignas(64) float zeros[kChunk];
    alignas(64) uint8_t killed[kChunk];
    alignas(64) float depth[kChunk];
    bool depthWritten = false;
    // Set by the fx8 fast path around tex/texld: sampleInto then leaves the ±M clamp of the
    // texels to the caller, which clamps while converting to its int16 registers.
    bool deferTexelClamp = false;
};

// What the kernels need from the executor (read-only during run()).
struct Profile {
    Precision precision = Precision::Fx8;
    int minor = 1;
    int32_t g = 255;       // grid scale
    int32_t nMax = 255;    // fx: round(M*G)
    float maxValue = 1;    // M
    bool wide = false;     // fx: products need 64-bit lanes
    bool clampRange = true;  // false for ideal
    std::array<std::array<int32_t, 4>, 8> constGrid{};  // fx: constants as grid integers
    std::array<std::array<float, 4>, 8> constF{};       // float: constants (fx: n/G)
    std::array<StageState, 8> stages{};
};

// Arithmetic instruction (mov … bem, not nop) into out (the destination or the hold buffer).
void execArithFx(const Profile& p, const DOp& op, RunState& st, int32_t (*out)[kChunk]);
void execArithFloat(const Profile& p, const DOp& op, RunState& st, float (*out)[kChunk]);
// Texture-address instruction.
void execTexture(const Profile& p, const DOp& op, RunState& st);

// A validated program decoded once for running (Executor::create) or translating (the GL
// renderer's GLSL, emu/gl/glsl.h): the op list with register slots, the profile, the def
// constants (defMask: which of c0..c7 a def sets), the stages sampled, whether depth is
// replaced, and which of v0/v1 are read.
struct DecodedProgram {
    Profile profile;
    std::vector<DOp> ops;
    std::array<std::array<float, 4>, 8> defs{};
    uint8_t defMask = 0;
    uint32_t stagesUsed = 0;
    bool writesDepth = false;
    uint8_t vUsed = 0;
};
// Decodes `program` for `options`; false with E40xx diagnostics when it cannot be run.
bool decodeProgram(const Program& program, const ExecutorOptions& options, Diagnostics& diags, DecodedProgram& out);

// A constant as the profile loads it: clamped to [-1, 1] (NaN: 0); fx: grid = round_half_even(v·G)
// and value = grid / G; float profiles: value only (grid 0).
void constantOf(Precision precision, float v, int32_t& grid, float& value);

// Pointer to TC[set][comp] lanes of the chunk (zeros when absent).
const float* texcoordLanes(const RunState& st, int set, int comp);

}  // namespace ps11::exec
