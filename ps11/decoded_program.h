// The lowered form of a ps_1_x program: what the executor runs (ps11/executor.cpp decodes it
// once in Executor::create) and what a translator reads (the GL renderer's GLSL writer,
// emu/gl/glsl.h). A validated Program becomes an op list over one register file of slots, with
// the precision profile (grid scale, range, constants converted to it, stage states), the def
// constants and what the program uses. The executor's run state and kernels stay internal
// (ps11/executor_internal.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "ps11/caps.h"
#include "ps11/diagnostics.h"
#include "ps11/executor.h"
#include "ps11/ir.h"
#include "ps11/opcodes.h"
#include "ps11/precision.h"

namespace ps11::exec {

// ---- the register file ----
// One file of slots holds every register an op reads or writes: r0..r5, then t0..t5 (texture
// registers of ps_1_1-1_3; ps_1_4's t# are coordinate sets, SrcKind::TexCoord), then v0, v1.
// DOp::dstSlot and DSrc::slot (SrcKind::Reg) index it. Constants are not slots: c0..c7 are
// read from the profile (SrcKind::Const, DSrc::slot = the constant's index).
constexpr int kNumRegR = 6;  // r# slots: ps_1_4's r0..r5 (ps_1_1-1_3 use r0, r1)
constexpr int kNumRegT = 6;  // t# slots (ps_1_1-1_3 use t0..t3)
constexpr int kNumRegV = registerCount(RegType::Input, 4);     // v0, v1
constexpr int kNumConsts = registerCount(RegType::Const, 4);   // c0..c7
constexpr int kSlotR = 0;                    // r# is slot kSlotR + #
constexpr int kSlotT = kSlotR + kNumRegR;    // t# is slot kSlotT + #
constexpr int kSlotV = kSlotT + kNumRegT;    // v# is slot kSlotV + #
constexpr int kNumSlots = kSlotV + kNumRegV;  // slots in the file

static_assert(kNumRegR >= registerCount(RegType::Temp, 4) && kNumRegR >= registerCount(RegType::Temp, 3));
static_assert(kNumRegT >= registerCount(RegType::Texture, 3));
static_assert(kSlotT == 6 && kSlotV == 12 && kNumSlots == 14, "the slot layout the executor and GLSL share");

// ---- the op list ----
enum class SrcKind : uint8_t { Reg, Const, TexCoord };

struct DSrc {
    SrcKind kind = SrcKind::Reg;
    uint8_t slot = 0;          // register slot, constant index or texture-coordinate set
    std::array<uint8_t, 4> sw{0, 1, 2, 3};  // component read for each output channel
    SrcMod mod = SrcMod::None;
};

struct DOp {
    Opcode op = Opcode::Nop;
    int32_t instruction = -1;  // its index in Program::instructions (diagnostics, traces)
    const OpcodeInfo* info = nullptr;  // the opcode-table row (components read, writes its destination)
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
    // A plain read (ps11/executor_presampled_internal.h "tapPlan"): `tex t#` (ps_1_1–1_3), or
    // `texld r#, t#` with .xy as written or _dz/_dw (ps_1_4). Pre-sampled runs take its texels
    // from the caller; every other texture instruction they execute themselves.
    bool plainRead = false;
};

// A source modifier of an fx profile as k = a·n + b: the source's exact value is k/(2G) for the
// register's grid integer n (docs/precision.md, "One arithmetic instruction in an fx profile"; bias
// and _bx2 give half-grid values, hence the denominator 2G). The one statement of that table: the
// generic fx stage, the fx8 fast path and the interval evaluator (ps11/intervals.h) read it.
// _dz/_dw (texture coordinates, never an arithmetic source) give the plain {2, 0}.
struct SourceAffine {
    int32_t a, b;
};
constexpr SourceAffine sourceAffine(SrcMod m, int32_t g) {
    switch (m) {
        case SrcMod::Neg: return {-2, 0};
        case SrcMod::Bias: return {2, -g};
        case SrcMod::BiasNeg: return {-2, g};
        case SrcMod::Sign: return {4, -2 * g};
        case SrcMod::SignNeg: return {-4, 2 * g};
        case SrcMod::Comp: return {-2, 2 * g};
        case SrcMod::X2: return {4, 0};
        case SrcMod::X2Neg: return {-4, 0};
        default: return {2, 0};
    }
}

// A source modifier of the float profiles on one value, the formulas of docs/precision.md
// ("float and ideal") as written, signed zeros included: the float stage's constants and the
// interval evaluator's bounds. (2x is exact, so no contraction can change 2x − 1.)
constexpr float applySourceModifier(SrcMod m, float x) {
    switch (m) {
        case SrcMod::Neg: return -x;
        case SrcMod::Bias: return x - 0.5f;
        case SrcMod::BiasNeg: return -(x - 0.5f);
        case SrcMod::Sign: return 2.0f * x - 1.0f;
        case SrcMod::SignNeg: return -(2.0f * x - 1.0f);
        case SrcMod::Comp: return 1.0f - x;
        case SrcMod::X2: return 2.0f * x;
        case SrcMod::X2Neg: return -(2.0f * x);
        default: return x;
    }
}

// What the kernels need from the executor (read-only during run()).
struct Profile {
    Precision precision = Precision::Fx8;
    int minor = 1;
    int32_t g = 255;       // grid scale
    int32_t nMax = 255;    // fx: round(M*G)
    float maxValue = 1;    // M
    bool wide = false;     // fx: product numerators may pass 2^31 (GL exact mode: int64_t)
    bool exactDouble = false;  // fx: every product numerator below 2^52, formed in double (else int64)
    bool clampRange = true;  // false for ideal
    std::array<std::array<int32_t, 4>, kNumConsts> constGrid{};  // fx: constants as grid integers
    std::array<std::array<float, 4>, kNumConsts> constF{};       // float: constants (fx: n/G)
    std::array<StageState, kMaxTextureStages> stages{};
};

// A validated program decoded once for running (Executor::create) or translating (the GL
// renderer's GLSL, emu/gl/glsl.h): the op list with register slots, the profile, the def
// constants (defMask: which of c0..c7 a def sets), the stages sampled, whether depth is
// replaced, and which of v0/v1 are read.
struct DecodedProgram {
    Profile profile;
    std::vector<DOp> ops;
    std::array<std::array<float, 4>, kNumConsts> defs{};
    uint8_t defMask = 0;
    uint32_t stagesUsed = 0;
    bool writesDepth = false;
    uint8_t vUsed = 0;
};
// Decodes `program` for `options`; false with E40xx diagnostics when it cannot be run.
bool decodeProgram(const Program& program, const ExecutorOptions& options, Diagnostics& diags, DecodedProgram& out);

// The channels of r0 a run must set to 0 before the first instruction: those some instruction
// reads before any writes them, and those none writes (r0 is the output). The others are
// written before they are read, so their lanes' earlier contents are never seen.
uint8_t r0PresetChannels(const std::vector<DOp>& ops);

// A constant as the profile loads it: clamped to [-1, 1] (NaN: 0); fx: grid = round_half_even(v·G)
// and value = grid / G; float profiles: value only (grid 0).
void constantOf(Precision precision, float v, int32_t& grid, float& value);

}  // namespace ps11::exec
