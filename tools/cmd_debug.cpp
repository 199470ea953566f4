// `ps11 debug` (tools/cmd_debug.h): one pixel of a shader instruction by instruction on the
// emulated class beside `ideal`. Both run the executor's generic path with a trace
// (Executor::trace); the interval evaluator over the pixel's own inputs (one point each) says
// what each write step of the class did — rounded off the grid, clamped at MaxValue, cut by
// _sat — which names why the two part.
#include "tools/cmd_debug.h"

#include <cmath>
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "ps11/decoded_program.h"
#include "ps11/disassembler.h"
#include "ps11/formats.h"
#include "ps11/intervals.h"
#include "ps11/opcodes.h"
#include "tools/cli_util.h"
#include "tools/cmd_eval.h"

namespace ps11 {
namespace {

constexpr const char* kUsage =
    "usage: ps11 debug SHADER.psh [v0=r,g,b,a] [v1=...] [t0=u,v,w,q] ... [c0=x,y,z,w] ...\n"
    "                  [--tex0 [FORMAT:]WORD] ... [--hardware H] [--json]\n"
    "  runs one pixel as `ps11 eval` does (the same inputs) on the hardware class and on `ideal`,\n"
    "  and prints every instruction's destination in both, why they differ (round, clamp,\n"
    "  saturate, signed_decode, filter_weight) and the first instruction where they part by more\n"
    "  than one 8-bit level\n";

// One pixel's inputs as the executor takes them (lane 0).
struct OnePixel {
    float color[2][4] = {};
    float tc[kMaxTexCoordSets][4] = {};
    PixelInputs in;
    explicit OnePixel(const ps11test::EvalInputs& e) {
        in.count = 1;
        for (int v = 0; v < 2; ++v)
            for (int c = 0; c < 4; ++c) {
                color[v][c] = e.color[size_t(v)] ? (*e.color[size_t(v)])[size_t(c)] : 0.0f;
                in.color[v][c] = &color[v][c];
            }
        for (int t = 0; t < kMaxTexCoordSets; ++t)
            for (int c = 0; c < 4; ++c) {
                tc[t][c] = e.texture[size_t(t)] ? (*e.texture[size_t(t)])[size_t(c)] : 0.0f;
                in.texcoord[t][c] = &tc[t][c];
            }
    }
};

struct Run {
    std::vector<TraceStep> steps;
    float r0[4] = {};
    uint8_t killed = 0;
};

Run trace(const Executor& e, Sampler& s, const OnePixel& px) {
    Run r;
    PixelOutputs out;
    for (int c = 0; c < 4; ++c) out.color[c] = &r.r0[c];
    out.killed = &r.killed;
    e.trace(px.in, s, out, r.steps);
    return r;
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4f", v);
    return buf;
}

std::string levelText(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", v);
    return buf;
}

// The interval evaluator's write findings of the class over this pixel's inputs, per
// instruction index.
std::vector<InstructionInterval> classFindings(const Program& program, const HardwareConfig& hw, const EvalArgs& ea,
                                               const TextureSampler& sampler) {
    IntervalSetup setup;
    setup.options = executorOptionsFor(hw);
    for (int c = 0; c < 8; ++c)
        if (ea.constant[size_t(c)]) setup.constants[size_t(c)] = *ea.constant[size_t(c)];
    Diagnostics quiet;
    std::optional<IntervalEvaluator> e = IntervalEvaluator::create(program, setup, quiet);
    std::vector<InstructionInterval> steps;
    if (!e) return steps;
    IntervalInputs in;
    const ps11test::EvalInputs ei = ea.inputs();
    for (int v = 0; v < 2; ++v)
        for (int c = 0; c < 4; ++c)
            in.color[size_t(v)][size_t(c)] = ValueRange::point(ei.color[size_t(v)] ? (*ei.color[size_t(v)])[size_t(c)] : 0.0f);
    for (int t = 0; t < kMaxTexCoordSets; ++t)
        for (int c = 0; c < 4; ++c)
            in.texcoord[size_t(t)][size_t(c)] =
                ValueRange::point(ei.texture[size_t(t)] ? (*ei.texture[size_t(t)])[size_t(c)] : 0.0f);
    // The 1×1 textures: every lookup returns the texel (a stage without one: 0, 0, 0, 1).
    for (int s = 0; s < kMaxTextureStages; ++s) {
        const Texture* tex = sampler.texture(s);
        const Vec4 v = tex ? tex->texelValue(0, 0, 0) : Vec4{0, 0, 0, 1};
        for (int c = 0; c < 4; ++c) in.stages[size_t(s)].value[size_t(c)] = ValueRange::point(v[size_t(c)]);
        in.stages[size_t(s)].anyCoords = true;
    }
    IntervalResult r;
    e->trace(in, r, steps);
    return steps;
}

}  // namespace

int debugPixel(const EvalArgs& ea, DebugTrace& out) {
    std::optional<Program> program;
    HardwareConfig hw;
    if (int rc = loadEvalProgram(ea, program, hw); rc != cli::kOk) return rc;
    // ideal on the same class: the same signed decode, no grid, no clamp, float32 filter weights.
    const HardwareConfig ideal = resolveHardware(hw.hardware, program->version.minor, Precision::Ideal, 0);
    std::unique_ptr<Executor> ex = makeEvalExecutor(*program, hw, ea), ei = makeEvalExecutor(*program, ideal, ea);
    if (!ex || !ei) return cli::kUserError;
    TextureSampler sx, si;
    if (int rc = bindEvalTextures(ea, hw, ex->sampledStages(), sx); rc != cli::kOk) return rc;
    {
        std::streambuf* saved = std::cerr.rdbuf(nullptr);  // the notes were printed once
        const int rc = bindEvalTextures(ea, ideal, ei->sampledStages(), si);
        std::cerr.rdbuf(saved);
        if (rc != cli::kOk) return rc;
    }
    const OnePixel px(ea.inputs());
    const Run a = trace(*ex, sx, px), b = trace(*ei, si, px);
    const std::vector<InstructionInterval> findings = classFindings(*program, hw, ea, sx);
    const bool fx = isFixedPoint(hw.precision);
    out = DebugTrace{};
    out.shader = ea.shader;
    out.hardware = std::string(hw.hardware->name);
    out.describe = hw.describe();
    out.precision = hw.precision;
    out.version = "ps_" + std::to_string(program->version.major) + "_" + std::to_string(program->version.minor);
    for (int c = 0; c < 4; ++c) out.r0Emulated[size_t(c)] = a.r0[c], out.r0Ideal[size_t(c)] = b.r0[c];
    out.killedEmulated = a.killed != 0, out.killedIdeal = b.killed != 0;
    for (size_t k = 0; k < a.steps.size() && k < b.steps.size(); ++k) {
        const TraceStep &s = a.steps[k], &si_ = b.steps[k];
        const Instruction& inst = program->instructions[size_t(s.instruction)];
        DebugRow row;
        row.line = inst.loc.line;
        row.text = formatInstruction(inst, program->version);
        row.writes = s.writes;
        row.mask = s.mask;
        row.emulated = s.value, row.grid = s.grid, row.ideal = si_.value;
        for (int c = 0; c < 4; ++c)
            if (s.writes && ((s.mask >> c) & 1))
                row.levels = std::max(row.levels, std::fabs(double(s.value[size_t(c)]) - si_.value[size_t(c)]) * 255.0);
        const InstructionInterval* f = nullptr;
        for (const InstructionInterval& i : findings)
            if (i.instruction == s.instruction) f = &i;
        const bool differs = row.levels > 0;
        if (f && f->rounds && fx) row.why.push_back("round");
        if (f && f->clamps) row.why.push_back("clamp");
        if (f && f->saturates && differs) row.why.push_back("saturate");
        if (samplesStage(inst.opcode()) && differs) {
            const int stage = inst.dst.index;  // ps_1_1 … 1_3 t#, ps_1_4 the sampler stage of texld
            const Texture* tex = stage >= 0 && stage < kMaxTextureStages ? sx.texture(stage) : nullptr;
            if (tex && formatRow(tex->format()).cls == FormatClass::Signed)
                row.why.push_back("signed_decode");
            else if (tex && (tex->level(0).width > 1 || tex->level(0).height > 1))
                row.why.push_back("filter_weight");
            else if (fx && row.why.empty())
                row.why.push_back("round");
        }
        if (out.firstDivergence < 0 && row.levels > 1.0) out.firstDivergence = int(out.rows.size());
        out.rows.push_back(std::move(row));
    }
    return cli::kOk;
}

int cmdDebug(const std::vector<std::string>& argsIn) {
    bool json = false;
    std::vector<std::string> args;
    for (const std::string& a : argsIn) (a == "--json" ? json = true : (args.push_back(a), false));
    EvalArgs ea;
    if (int rc = parseEvalArgs(args, "debug", kUsage, ea); rc != cli::kOk) return rc == kHelpShown ? cli::kOk : rc;
    if (ea.precision == Precision::Ideal) {
        std::cerr << "ps11: debug: --precision ideal is the reference it is compared with; pick another profile\n";
        return cli::kUsage;
    }
    DebugTrace d;
    if (int rc = debugPixel(ea, d); rc != cli::kOk) return rc;
    const bool fx = isFixedPoint(d.precision);

    if (json) {
        nlohmann::ordered_json j;
        j["file"] = d.shader;
        j["hardware"] = d.hardware;
        j["precision"] = precisionName(d.precision);
        nlohmann::ordered_json steps = nlohmann::ordered_json::array();
        for (const DebugRow& r : d.rows) {
            nlohmann::ordered_json s;
            s["line"] = r.line;
            s["text"] = r.text;
            if (r.writes) {
                s["emulated"] = r.emulated;
                if (fx) s["grid"] = r.grid;
                s["ideal"] = r.ideal;
            } else {
                s["emulated"] = nullptr;
                s["ideal"] = nullptr;
            }
            s["levels"] = r.levels;
            s["why"] = r.why;
            steps.push_back(s);
        }
        j["steps"] = steps;
        j["first_divergence"] = d.firstDivergence >= 0 ? nlohmann::ordered_json(d.rows[size_t(d.firstDivergence)].line)
                                                       : nlohmann::ordered_json(nullptr);
        j["r0"] = {{"emulated", d.r0Emulated}, {"ideal", d.r0Ideal}};
        j["killed"] = {{"emulated", d.killedEmulated}, {"ideal", d.killedIdeal}};
        std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
        return cli::kOk;
    }

    std::cout << d.shader << ": " << d.version << " on " << d.describe << ", beside ideal\n";
    std::printf("   %-5s %-26s %-36s %-32s %-6s %s\n", "line", "instruction", d.hardware.c_str(), "ideal", "Δ lvl", "why");
    for (size_t k = 0; k < d.rows.size(); ++k) {
        const DebugRow& r = d.rows[k];
        std::string e, i;
        for (int c = 0; c < 4; ++c) {
            if (!r.writes || !((r.mask >> c) & 1)) {
                e += c ? "       " : "      ", i += c ? "       " : "      ";
                continue;
            }
            e += (c ? " " : "") + num(r.emulated[size_t(c)]);
            i += (c ? " " : "") + num(r.ideal[size_t(c)]);
        }
        if (fx && r.writes) {
            e += " [";
            for (int c = 0; c < 4; ++c)
                if ((r.mask >> c) & 1) e += (e.back() == '[' ? "" : " ") + std::to_string(r.grid[size_t(c)]);
            e += "]";
        }
        std::string why;
        for (const std::string& w : r.why) why += (why.empty() ? "" : ", ") + w;
        if (why.empty() && r.levels > 0) why = "(from its sources)";
        std::string text = r.text.size() > 26 ? r.text.substr(0, 25) + "~" : r.text;
        std::printf("%s %-5u %-26s %-36s %-32s %-6s %s\n", int(k) == d.firstDivergence ? ">>" : "  ", r.line,
                    text.c_str(), e.c_str(), r.writes ? i.c_str() : "", r.writes ? levelText(r.levels).c_str() : "",
                    why.c_str());
    }
    if (d.firstDivergence >= 0)
        std::cout << ">> line " << d.rows[size_t(d.firstDivergence)].line
                  << ": the first instruction where the class and ideal part by more than one 8-bit level\n";
    else
        std::cout << "the class stays within one 8-bit level of ideal at every instruction\n";
    return cli::kOk;
}

}  // namespace ps11
