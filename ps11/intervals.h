// The interval evaluator (docs/intervals.md): what a validated ps_1_1 … ps_1_4 program can
// produce when its inputs lie in given ranges, with the executor's rounding and clamps in the
// profile it runs: per output channel a closed range that contains every value the executor can
// give, whether that value is one constant bit for bit, and whether r0 is bit for bit a copy of
// one texture lookup. Made once per draw from the program, the profile and the constants
// (IntervalEvaluator::create); evaluate() then runs per tile, without allocating.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "ps11/caps.h"
#include "ps11/decoded_program.h"
#include "ps11/diagnostics.h"
#include "ps11/executor.h"
#include "ps11/ir.h"

namespace ps11 {

// A set of input values: the closed range [lo, hi] (infinite bounds admit the infinities), −0.0
// when `negZero` and the range holds 0, NaN when `nan`. Only the float profiles see −0.0 and NaN:
// fx registers are grid integers. The executor's inputs are float32 and fx samplers hand back grid
// integers n (value n/G): a bound is taken to the nearest float, and in fx a grid value within a
// float's rounding of a bound is admitted, so a bound computed in double from a float value (0.4
// for the texel 102/255 = 0.4f) still admits it. Default: anything (the executor's whole range).
struct ValueRange {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    // −0.0 may occur. It compares equal to 0, so a range holding 0 admits it unless told otherwise:
    // unorm texels, interpolated colours and every fx value never are −0.0.
    bool negZero = true;
    bool nan = true;  // NaN may occur (a NaN is inside no range)

    static constexpr ValueRange any() { return {}; }
    // [lo, hi] without NaN.
    static constexpr ValueRange between(double lo, double hi, bool negZero = true) { return {lo, hi, negZero, false}; }
    // Exactly v (+0.0 for 0: pass between(0, 0) for a zero whose sign is unknown).
    static constexpr ValueRange point(double v) { return {v, v, false, false}; }
};
using ValueRange4 = std::array<ValueRange, 4>;  // r g b a (texels, colours) or u v w q (coordinates)

// What one texture stage's lookups return, as the sampler returns them (decoded, filtered; fx:
// n/G of the grid integer it hands back; a stage without a texture returns (0, 0, 0, 1)).
struct StageRange {
    ValueRange4 value{};
    // False: `value` bounds the stage's plain lookups only, those whose coordinates come from the
    // interpolated texture coordinates alone (ps_1_1-1_3 `tex`, ps_1_4 `texld r#, t#`): what a
    // tile's taps can reach. True: it bounds every lookup of the stage at any coordinates (the
    // whole texture's range), so the dependent reads (texbem(l), texreg2*, texm3x2tex, texm3x3tex,
    // texm3x3spec/vspec, texdp3tex, ps_1_4 `texld r#, r#`) are bounded too; otherwise they are
    // the profile's whole range.
    bool anyCoords = false;
};

// The ranges of one evaluation (one tile). Default: everything unknown.
struct IntervalInputs {
    std::array<StageRange, kMaxTextureStages> stages{};
    std::array<ValueRange4, 2> color{};                    // v0, v1 as interpolated (before the [0, 1] load)
    std::array<ValueRange4, kMaxTexCoordSets> texcoord{};  // TC[0..7]: u v w q
};

// The bound of one output channel.
struct ChannelInterval {
    // Every value lies in [lo, hi] (when bounded). fx: gridLo / G and gridHi / G.
    double lo = 0, hi = 0;
    int32_t gridLo = 0, gridHi = 0;  // fx: the grid integers; the executor's PixelOutputs::grid lies in them
    bool bounded = true;             // float, ideal: false when NaN may occur or a bound is infinite
    bool negZero = false;            // float, ideal: −0.0 may occur (lo <= 0 <= hi)
    // Every run gives the same value bit for bit: fx the grid integer gridLo; float and ideal the
    // float lo (+0.0 when it is 0), never NaN.
    bool constant = false;
};

// Whether texkill discards pixels.
enum class KillRange : uint8_t {
    Never,  // no pixel (also: no texkill)
    Maybe,
    Always,  // every pixel
};

struct IntervalResult {
    std::array<ChannelInterval, 4> color{};  // r0: r g b a, as the executor leaves it (before any render target)
    bool writesDepth = false;                // texm3x2depth / texdepth
    ChannelInterval depth{};                 // when writesDepth: the depth written, always within [0, 1]
    KillRange kill = KillRange::Never;
    // r0 equals, channel for channel and bit for bit, the value the plain lookup at Program
    // instruction `copyInstruction` returned from stage `copyStage` (-1: not proven). Only exact
    // identities of the profile lead there (mov; adding an exact zero; multiplying by exactly one;
    // a decided cnd/cmp; lrp by exactly 0, or 1 in fx), and only when no clamp of the way can act.
    int copyStage = -1;
    int copyInstruction = -1;
    // Per channel: the channels of r0 (bit c) that equal, bit for bit, the same channel of the
    // plain lookup at instruction `channelCopyInstruction` from stage `channelCopyStage` (−1 and
    // 0 when none); the same identities. A composite whose glare is zero but whose alpha is
    // another constant copies its scene's r g b. copyStage is set where copyMask is 0xf.
    uint8_t copyMask = 0;
    int channelCopyStage = -1;
    int channelCopyInstruction = -1;

    // All four channels of r0 are constants.
    bool constantColor() const {
        return color[0].constant && color[1].constant && color[2].constant && color[3].constant;
    }
};

// Everything of a draw the bounds depend on besides the per-tile ranges.
struct IntervalSetup {
    ExecutorOptions options{};  // profile, MaxValue (0 = the version's default class), co-issued cnd
    std::array<std::array<float, 4>, 8> constants{};  // c0..c7 as SetPixelShaderConstantF set them (a def overrides)
    // The texture stage states (bump matrices, luminance scale and offset). Unknown: bem and
    // texbeml give the profile's whole range (texbem's matrix only moves coordinates).
    bool stagesKnown = false;
    std::array<StageState, kMaxTextureStages> stages{};
};

// What one instruction leaves over the ranges (IntervalEvaluator::trace).
struct InstructionInterval {
    int instruction = -1;  // index in Program::instructions
    int op = -1;           // index in the decoded op list (phase included)
    bool writes = false;   // writes its destination register (the opcode table's writesDst)
    uint8_t mask = 0;      // the channels it writes (texture-address instructions: all four)
    // The destination register after the instruction, all four channels (a co-issued first
    // member: the values it writes once its partner has read).
    std::array<ChannelInterval, 4> dst{};
    // Channels (bit per channel) whose value before the write step can leave [−MaxValue,
    // MaxValue], so the register clamp acts (without _sat), and those _sat cuts (outside [0, 1]).
    uint8_t clamps = 0;
    uint8_t saturates = 0;
    // fx profiles: channels whose result can fall off the grid, so the write rounds it.
    uint8_t rounds = 0;
};

class IntervalEvaluator {
public:
    // Decodes the program as Executor::create does (the same E40xx diagnostics, nullopt when the
    // executor could not run it). The program should have passed validate().
    static std::optional<IntervalEvaluator> create(const Program& program, const IntervalSetup& setup,
                                                   Diagnostics& diags);

    // Bounds the program's results over `inputs`. Allocates nothing; thread-safe.
    void evaluate(const IntervalInputs& inputs, IntervalResult& result) const;
    // evaluate(), and per executed instruction (phase excluded) what it leaves (`ps11 check
    // --ranges`, ps11/range_proof.h).
    void trace(const IntervalInputs& inputs, IntervalResult& result, std::vector<InstructionInterval>& steps) const;

    // What evaluate() reads, so a caller gathers only those ranges (bit per stage, set or v#):
    // the stages of plain and of dependent lookups, the coordinate sets read as values
    // (texcoord, texcrd, texkill, the matrix rows), the colours.
    uint32_t plainLookupStages() const { return m_plainStages; }
    uint32_t dependentLookupStages() const { return m_dependentStages; }
    uint8_t texcoordSetsRead() const { return m_tcRead; }
    uint8_t colorsRead() const { return m_vRead; }

    Precision precision() const { return m_p.precision; }
    // The decoded profile: grid scale, round(M·G), M, the constants as loaded.
    const exec::Profile& profile() const { return m_p; }
    // The decoded op list trace() steps through (ps11/decoded_program.h).
    const std::vector<exec::DOp>& ops() const { return m_ops; }

private:
    void run(const IntervalInputs& inputs, IntervalResult& result, std::vector<InstructionInterval>* steps) const;
    struct Tap {
        int16_t instruction = -1;  // index in Program::instructions of the op
        bool plain = false;        // a plain lookup (see StageRange::anyCoords)
    };
    exec::Profile m_p;
    std::vector<exec::DOp> m_ops;
    std::vector<Tap> m_taps;  // per op
    bool m_stagesKnown = false;
    bool m_writesDepth = false;
    uint8_t m_tcRead = 0;  // texture coordinate sets read as values (texcoord, texcrd, texkill, matrix rows)
    uint8_t m_vRead = 0;   // v0, v1 read
    uint32_t m_plainStages = 0, m_dependentStages = 0;
    uint32_t m_slotsNamed = 0;  // bit per register slot (ps11/decoded_program.h) some op reads or writes
};

}  // namespace ps11
