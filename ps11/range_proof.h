// The range proof (`ps11 check --ranges`, docs/intervals.md "The range proof"): what a ps_1_x
// program's registers can hold on a hardware class when its inputs lie in given ranges, per
// instruction; where the register clamp to ±MaxValue or _sat acts, and from which input value
// on; and per output channel a worst-case bound on how far the fx8 and fx12 profiles' r0 can be
// from the float profile's with the same MaxValue. Built on the interval evaluator
// (ps11/intervals.h); nothing here runs the executor.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "ps11/caps.h"
#include "ps11/diagnostics.h"
#include "ps11/executor.h"
#include "ps11/intervals.h"
#include "ps11/ir.h"

namespace ps11 {

struct RangeProofSetup {
    ExecutorOptions options{};  // the class's profile and MaxValue (maxValue 0: the version's default)
    std::array<std::array<float, 4>, 8> constants{};  // c0..c7 as the API sets them (a def overrides)
    // Every channel of every lookup of stage s lies in textures[s] (default [0, 1], an unsigned
    // texture); `filtered`: the stage filters bilinearly (the fx profiles weigh with 8 bits,
    // float with float32 weights: a source of difference), else it point-samples.
    std::array<ValueRange, kMaxTextureStages> textures{};
    std::array<bool, kMaxTextureStages> filtered{};
    std::array<ValueRange, 2> colors{};                   // v0, v1 (default [0, 1])
    std::array<ValueRange, kMaxTexCoordSets> texcoords{};  // TC[i], every component (default [0, 1])

    RangeProofSetup();
};

// The input names of the findings: "t0".."t7" (a stage's texels), "v0", "v1", "tc0".."tc7".
// An onset: the clamp of an instruction does not act while the input stays at or below
// (`above` true: the clamp begins above `value`) or at or above `value`, the other inputs
// keeping their whole ranges.
struct ClampOnset {
    std::string input;
    bool above = true;
    double value = 0;
};

struct InstructionRange {
    InstructionInterval step;        // dst ranges (the class's profile), clamps, saturates
    SourceLoc loc;                   // the instruction's mnemonic
    std::string text;                // as disassembled
    std::vector<ClampOnset> onsets;  // for an instruction that clamps
};

// A bound in 8-bit levels (value·255) per r0 channel; not `bounded` where the analysis cannot
// say (a dependent lookup whose coordinates differ, an unknown range).
struct LevelBound {
    std::array<double, 4> levels{};
    bool bounded = true;
    double max() const;
};

struct RangeProof {
    ExecutorOptions options;  // as resolved (maxValue filled in)
    std::vector<InstructionRange> instructions;
    IntervalResult result;  // r0 on the class
    LevelBound fx8, fx12;   // |fx − float| at the class's MaxValue
    // The first instruction whose write step clamps (nullptr: range-safe on the class).
    const InstructionRange* firstClamp() const;
};

// Runs the proof. Reports E40xx (and returns nullopt) for a program the executor could not run.
std::optional<RangeProof> proveRanges(const Program& program, const RangeProofSetup& setup, Diagnostics& diags);

}  // namespace ps11
