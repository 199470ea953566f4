#include "ps11/debug_steps.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "ps11/disassembler.h"
#include "ps11/formats.h"
#include "ps11/intervals.h"
#include "ps11/opcodes.h"

namespace ps11 {
namespace {

// The interval evaluator's write findings of the class over the pixel's inputs (each a point),
// per executed instruction.
std::vector<InstructionInterval> classFindings(const Program& program, const HardwareConfig& hw, const DebugInputs& di) {
    IntervalSetup setup;
    setup.options = executorOptionsFor(hw);
    setup.constants = di.constants;
    Diagnostics quiet;
    std::optional<IntervalEvaluator> e = IntervalEvaluator::create(program, setup, quiet);
    std::vector<InstructionInterval> steps;
    if (!e) return steps;
    IntervalInputs in;
    for (size_t v = 0; v < 2; ++v)
        for (size_t c = 0; c < 4; ++c) in.color[v][c] = ValueRange::point(di.color[v][c]);
    for (size_t t = 0; t < size_t(kMaxTexCoordSets); ++t)
        for (size_t c = 0; c < 4; ++c) in.texcoord[t][c] = ValueRange::point(di.texcoord[t][c]);
    for (size_t s = 0; s < size_t(kMaxTextureStages); ++s) {
        for (size_t c = 0; c < 4; ++c) in.stages[s].value[c] = ValueRange::point(di.stage[s][c]);
        in.stages[s].anyCoords = true;
    }
    IntervalResult r;
    e->trace(in, r, steps);
    return steps;
}

}  // namespace

std::vector<DebugStep> debugSteps(const Program& program, const HardwareConfig& hw, const DebugInputs& inputs,
                                  const std::vector<TraceStep>& emulated, const std::vector<TraceStep>& ideal,
                                  const TextureSampler& sampler) {
    const std::vector<InstructionInterval> findings = classFindings(program, hw, inputs);
    const bool fx = isFixedPoint(hw.precision);
    std::vector<DebugStep> rows;
    for (size_t k = 0; k < emulated.size() && k < ideal.size(); ++k) {
        const TraceStep& s = emulated[k];
        const Instruction& inst = program.instructions[size_t(s.instruction)];
        DebugStep row;
        row.instruction = s.instruction;
        row.line = inst.loc.line;
        row.text = formatInstruction(inst, program.version);
        row.writes = s.writes;
        row.mask = s.mask;
        row.emulated = s.value;
        row.ideal = ideal[k].value;
        row.grid = s.grid;
        for (size_t c = 0; c < 4; ++c)
            if (s.writes && ((s.mask >> c) & 1))
                row.levels = std::max(row.levels, std::fabs(double(s.value[c]) - ideal[k].value[c]) * 255.0);
        const InstructionInterval* f = nullptr;
        for (const InstructionInterval& i : findings)
            if (i.instruction == s.instruction) f = &i;
        const bool differs = row.levels > 0;
        if (f && f->rounds && fx) row.why.push_back("round");
        if (f && f->clamps) row.why.push_back("clamp");
        if (f && f->saturates && differs) row.why.push_back("saturate");
        if (samplesStage(inst.opcode()) && differs) {
            const int stage = inst.dst.index;  // ps_1_1 … 1_3 t#, ps_1_4 the sampler stage of texld
            const bool inStages = stage >= 0 && stage < kMaxTextureStages;
            const Texture* tex = inStages ? sampler.texture(stage) : nullptr;
            const bool linear = inStages && (sampler.samplerState(stage).minFilter == Filter::Linear ||
                                             sampler.samplerState(stage).magFilter == Filter::Linear);
            if (inStages && inputs.texelsDiffer[size_t(stage)]) {
                // the texels differ: the difference came in with them
            } else if (tex && formatRow(tex->format()).cls == FormatClass::Signed)
                row.why.push_back("signed_decode");
            else if (tex && linear && (tex->level(0).width > 1 || tex->level(0).height > 1))
                row.why.push_back("filter_weight");
            else if (fx && row.why.empty())
                row.why.push_back("round");
        }
        rows.push_back(std::move(row));
    }
    return rows;
}

int firstDivergence(const std::vector<DebugStep>& steps) {
    for (size_t k = 0; k < steps.size(); ++k)
        if (steps[k].levels > 1.0) return int(k);
    return -1;
}

}  // namespace ps11
