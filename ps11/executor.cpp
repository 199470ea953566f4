// The executor, stage 1 and driver: create() decodes a validated Program once into a compact op
// list (register slots, modifiers, masks, shifts, co-issue holds, constants converted to the
// profile), reports E40xx for what it cannot run; run() cuts a span into chunks, loads the
// inputs, dispatches each op over the chunk's lanes and stores the outputs.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <string>

#include "ps11/executor_fast.h"
#include "ps11/executor_internal.h"

namespace ps11 {
namespace exec {

const float* texcoordLanes(const RunState& st, int set, int comp) {
    const float* p = (set >= 0 && set < kMaxTexCoordSets) ? st.in->texcoord[set][comp] : nullptr;
    return p ? p + st.offset : kZeroLanes;
}

void constantOf(Precision precision, float v, int32_t& grid, float& value) {
    // D3D9 constants are clamped to [-1, 1] on load (Wine, DXVK, nine; spec §7.2), then rounded
    // to the grid exactly in fx profiles (docs/precision.md "Inputs").
    const float f = v == v ? std::min(1.0f, std::max(-1.0f, v)) : 0.0f;
    if (isFixedPoint(precision)) {
        grid = toGrid(double(f), precision);
        value = float(grid) / float(gridScale(precision));
    } else {
        grid = 0;
        value = f;
    }
}

namespace {

// DOp::plainRead: `tex t#` in ps_1_1–1_3; in ps_1_4 `texld r#, t#` reading .xy as written,
// plain or divided by z or w (_dz/_dw).
bool isPlainRead(const DOp& op, int minor) {
    if (op.op != Opcode::Tex) return false;
    if (minor < 4) return true;
    const DSrc& s = op.src[0];
    const bool divided = s.mod == SrcMod::Dz || s.mod == SrcMod::Dw;
    return s.kind == SrcKind::TexCoord && (s.mod == SrcMod::None || divided) && s.sw[0] == 0 && s.sw[1] == 1;
}

// A process-wide unique, non-zero number per set of constants (see runFast's constsId).
uint64_t nextConstsId() {
    static std::atomic<uint64_t> next{0};
    return ++next;
}

class ExecutorImpl final : public Executor {
public:
    ExecutorImpl(const ExecutorOptions& options, Profile profile, std::vector<DOp> ops,
                 std::array<std::array<float, 4>, kNumConsts> defs, uint8_t defMask, uint32_t stagesUsed, bool depth,
                 uint8_t vUsed)
        : m_options(options),
          m_p(profile),
          m_ops(std::move(ops)),
          m_defs(defs),
          m_defMask(defMask),
          m_stagesUsed(stagesUsed),
          m_writesDepth(depth),
          m_vUsed(vUsed),
          m_r0Preset(r0PresetChannels(m_ops)) {
        for (DOp& op : m_ops) op.plainRead = isPlainRead(op, m_p.minor);
        for (auto& c : m_api) c = {0, 0, 0, 0};
        for (int i = 0; i < kNumConsts; ++i) refreshConstant(i);
        m_constsId = nextConstsId();
        if (options.path != ExecPath::Generic) {
            buildFastProgram(m_p, m_ops, m_fast);
            refreshPresampled();
        }
    }

    void setConstant(int index, const std::array<float, 4>& value) override {
        if (index < 0 || index >= kNumConsts) return;
        // The same bits as now (a device sets all eight before every draw): nothing changes, and
        // the fast program's constant-dependent plans and the threads' constant lanes are kept.
        if (std::memcmp(m_api[size_t(index)].data(), value.data(), sizeof value) == 0) return;
        m_api[size_t(index)] = value;
        refreshConstant(index);
        m_constsId = nextConstsId();
        if (m_fast.ready) refreshPresampled();
    }
    void setStageState(int stage, const StageState& state) override {
        if (stage >= 0 && stage < kMaxTextureStages) m_p.stages[size_t(stage)] = state;
    }
    bool writesDepth() const override { return m_writesDepth; }
    uint32_t sampledStages() const override { return m_stagesUsed; }
    const ExecutorOptions& options() const override { return m_options; }
    const char* pathName() const override {
        return m_fast.ready ? fastKernels(simdLevel())->name : "generic";
    }

    void run(const PixelInputs& inputs, Sampler& sampler, PixelOutputs& outputs,
             ExecutorStats* stats) const override;
    void trace(const PixelInputs& inputs, Sampler& sampler, PixelOutputs& outputs,
               std::vector<TraceStep>& steps) const override {
        steps.clear();
        runGeneric(inputs, sampler, outputs, &steps);
    }
    // ps11/executor_presampled_internal.h
    bool tapPlan(TapPlan& plan, bool executes) const;
    bool plainTaps(TapPlan& plan, bool executes = false) const;
    void runPresampled(const PixelInputs& inputs, TapFill fill, ResultSink sink, void* ctx, ExecutorStats* stats,
                       const PresampledRun& run) const;
    bool chainRows() const { return m_chainRows.ready; }
    void runChainRow(const ChainRowTap* taps, int count, uint8_t* out, const ChainRowStore& store,
                     ExecutorStats* stats) const {
        exec::runChainRow(m_chainRows, m_presampled, taps, count, out, store);
        countRun(stats, std::clamp(count, 0, kMaxSpan));
    }

private:
    // The pre-sampled runs' sign analyses (plain reads' texels >= 0, and of any sign) and chain
    // rows for the constants now.
    void refreshPresampled() {
        presampledOps(m_fast, m_p, m_ops, m_presampled, true);
        presampledOps(m_fast, m_p, m_ops, m_presampledAnySign, false);
        chainRowPlan(m_fast, m_p, m_ops, m_presampled, m_vUsed, m_chainRows);
    }
    void refreshConstant(int i) {
        // A def in the shader overrides the API value (spec §1.1, def page).
        const std::array<float, 4>& v = (m_defMask >> i) & 1 ? m_defs[size_t(i)] : m_api[size_t(i)];
        for (int c = 0; c < 4; ++c)
            constantOf(m_p.precision, v[size_t(c)], m_p.constGrid[size_t(i)][size_t(c)], m_p.constF[size_t(i)][size_t(c)]);
    }
    void runGeneric(const PixelInputs& inputs, Sampler& sampler, PixelOutputs& outputs,
                    std::vector<TraceStep>* steps = nullptr) const;
    // Adds count pixels and their executed instructions (phase excluded) to stats, if given.
    void countRun(ExecutorStats* stats, int count) const {
        if (!stats) return;
        uint64_t executed = 0;
        for (const DOp& op : m_ops)
            if (op.op != Opcode::Phase) ++executed;
        stats->pixels += uint64_t(count);
        stats->instructions += executed * uint64_t(count);
    }
    void loadColors(RunState& st) const;
    void runChunk(RunState& st, const FxArithKernels& fxArith, const FloatArithKernels& floatArith,
                  std::vector<TraceStep>* steps) const;

    ExecutorOptions m_options;
    Profile m_p;
    std::vector<DOp> m_ops;
    std::array<std::array<float, 4>, kNumConsts> m_defs;
    std::array<std::array<float, 4>, kNumConsts> m_api{};
    uint8_t m_defMask = 0;
    uint32_t m_stagesUsed = 0;
    bool m_writesDepth = false;
    uint8_t m_vUsed = 0;
    uint8_t m_r0Preset = 0xF;          // r0PresetChannels(m_ops)
    FastProgram m_fast;                // not ready: the generic path runs
    std::vector<FastOp> m_presampled;  // m_fast.ops with the sign analysis of runPresampled
    std::vector<FastOp> m_presampledAnySign;  // the same, plain reads' texels of any sign (PresampledRun::executedTaps)
    ChainRowPlan m_chainRows;          // from m_presampled
    uint64_t m_constsId = 0;           // names the constants (a thread's fast bank keeps them)
};

void ExecutorImpl::loadColors(RunState& st) const {
    // v# are saturated to [0, 1] and rounded to the grid once per pixel (docs/precision.md "Inputs").
    const bool fx = isFixedPoint(m_p.precision);
    const int32_t g = m_p.g;
    for (int v = 0; v < kNumRegV; ++v) {
        if (!((m_vUsed >> v) & 1)) continue;
        for (int c = 0; c < 4; ++c) {
            const float* src = colorLanes(*st.in, v, c, st.offset);
            const bool uniform = uniformColor(*st.in, v, c);
            if (fx) {
                int32_t* d = st.bi.reg[kSlotV + v][c];
                if (uniform)
                    std::fill_n(d, st.n, colorGrid(src[0], g));
                else
                    for (int i = 0; i < st.n; ++i) d[i] = colorGrid(src[i], g);
            } else {
                float* d = st.bf.reg[kSlotV + v][c];
                if (uniform)
                    fillLanes(d, st.n, saturateColor(src[0]));
                else
                    for (int i = 0; i < st.n; ++i) d[i] = saturateColor(src[i]);
            }
        }
    }
}

void ExecutorImpl::runChunk(RunState& st, const FxArithKernels& fxArith, const FloatArithKernels& floatArith,
                            std::vector<TraceStep>* steps) const {
    const bool fx = isFixedPoint(m_p.precision);
    std::memset(st.killed, 0, sizeof st.killed);
    loadColors(st);
    int tap = 0;  // texture instructions so far (pre-sampled runs: the tap they read)
    for (const DOp& op : m_ops) {
        if (op.op == Opcode::Phase) continue;  // r#.a keep their values (docs/precision.md "ps_1_4")
        // (The caller tests TapPlan::killSets; a register's texkill runs.)
        if (op.op == Opcode::TexKill && st.fill && op.src[0].kind == SrcKind::TexCoord) continue;
        // A plain read (plainTaps): all four channels from `fill`, clamped to ±M as sampled texels
        // are; or, one the caller leaves to the executor (executedTaps), sampled as run() does.
        const bool filled = op.texture && st.fill && op.plainRead && !((st.executedTaps >> tap) & 1);
        if (op.texture && st.fill && op.plainRead) ++tap;
        if (filled) {
            alignas(64) int16_t texels[4][kChunk];
            int16_t* const dst[4] = {texels[0], texels[1], texels[2], texels[3]};
            const int n = st.n;
            st.fill(st.fillCtx, tap - 1, st.offset, n, dst);
            // (Texels lie in [0, G]: the clamp to M changes nothing where M >= 1.)
            const int32_t hi = m_p.nMax >= m_p.g ? INT16_MAX : m_p.nMax;
            for (int c = 0; c < 4; ++c) fxArith.widen(texels[c], st.bi.reg[op.dstSlot][c], n, hi);
        } else if (op.texture) {
            execTexture(m_p, op, st);
        } else if (fx) {
            fxArith.arith(m_p, op, st, op.hold ? st.bi.hold : st.bi.reg[op.dstSlot]);
        } else {
            floatArith.arith(m_p, op, st, op.hold ? st.bf.hold : st.bf.reg[op.dstSlot]);
        }
        if (steps) {
            // Lane 0 of the destination (a first member's held result where it writes).
            TraceStep t;
            t.instruction = op.instruction;
            t.writes = op.info->writesDst;
            t.mask = op.texture ? uint8_t(0xf) : op.mask;
            for (int c = 0; c < 4 && t.writes; ++c) {
                const bool held = op.hold && ((op.mask >> c) & 1);
                if (fx) {
                    t.grid[size_t(c)] = held ? st.bi.hold[c][0] : st.bi.reg[op.dstSlot][c][0];
                    t.value[size_t(c)] = float(t.grid[size_t(c)]) / float(m_p.g);
                } else {
                    t.value[size_t(c)] = held ? st.bf.hold[c][0] : st.bf.reg[op.dstSlot][c][0];
                }
            }
            steps->push_back(t);
        }
        if (!op.hold && (&op != m_ops.data()) && (&op - 1)->hold) {
            // Co-issued pair: the second member has read and written; now the first writes
            // (both read before either writes, spec §3.5).
            const DOp& first = *(&op - 1);
            for (int c = 0; c < 4; ++c) {
                if (!((first.mask >> c) & 1)) continue;
                if (fx)
                    std::memcpy(st.bi.reg[first.dstSlot][c], st.bi.hold[c], sizeof(int32_t) * size_t(st.n));
                else
                    std::memcpy(st.bf.reg[first.dstSlot][c], st.bf.hold[c], sizeof(float) * size_t(st.n));
            }
        }
    }
}

bool ExecutorImpl::tapPlan(TapPlan& plan, bool executes) const {
    plan = TapPlan{};
    // The fast path's runs, or the generic path's in an fx profile whose register values fit the
    // int16 lanes of TapFill and ResultSink (|n| <= round(M·G) <= 32767: fx8 to M = 128, fx12 to 8).
    const bool generic = isFixedPoint(m_p.precision) && m_p.nMax <= INT16_MAX;
    return (m_fast.ready || generic) && plainTaps(plan, executes);
}

bool ExecutorImpl::plainTaps(TapPlan& plan, bool executes) const {
    plan = TapPlan{};
    for (const DOp& op : m_ops) {
        if (!op.texture) continue;
        if (op.op == Opcode::TexKill) {
            if (op.src[0].kind != SrcKind::TexCoord) {  // (r#: a register's value)
                if (!executes) return false;
                plan.executes = plan.registerKills = true;
                continue;
            }
            plan.killSets = uint8_t(plan.killSets | (1u << (op.src[0].slot & 7)));
            continue;
        }
        if (!op.plainRead) {
            if (!executes) return false;
            plan.executes = true;
            plan.executedStages = uint8_t(plan.executedStages | (1u << (op.stage & 7)));
            // The sets it reads: its own (ps_1_1–1_3: texbem, matrix rows, texcoord), or ps_1_4's
            // coordinate sources (texcrd, texld r#, t#.xyz).
            if (m_p.minor < 4) plan.executedSets = uint8_t(plan.executedSets | (1u << (op.stage & 7)));
            for (int s = 0; s < op.numSrc; ++s)
                if (op.src[size_t(s)].kind == SrcKind::TexCoord)
                    plan.executedSets = uint8_t(plan.executedSets | (1u << (op.src[size_t(s)].slot & 7)));
            continue;
        }
        if (plan.count >= int(plan.stage.size())) return false;
        uint8_t set = op.stage;
        int divisor = -1;
        bool zeroIsOne = false;
        if (m_p.minor < 4) {
            divisor = projectionDivisor(m_p.stages[op.stage]);
        } else {
            const DSrc& s = op.src[0];
            const bool divided = s.mod == SrcMod::Dz || s.mod == SrcMod::Dw;
            set = s.slot;
            if (divided) {
                divisor = s.mod == SrcMod::Dz ? 2 : 3;  // the raw component (coords14)
                zeroIsOne = true;
            }
        }
        const size_t i = size_t(plan.count);
        plan.stage[i] = op.stage;
        plan.coordSet[i] = set;
        plan.divisor[i] = int8_t(divisor);
        if (zeroIsOne) plan.zeroDivisorIsOne = uint8_t(plan.zeroDivisorIsOne | (1u << i));
        ++plan.count;
    }
    return true;
}

void ExecutorImpl::runPresampled(const PixelInputs& inputs, TapFill fill, ResultSink sink, void* ctx,
                                 ExecutorStats* stats, const PresampledRun& run) const {
    const int count = std::clamp(inputs.count, 0, kMaxSpan);
    const PixelOutputs* outputs = run.outputs;
    if (m_fast.ready) {
        // (Plain reads executed hold texels of any sign: the sign analysis without theirs.)
        runFastPresampled(m_fast, m_p, m_constsId, m_ops, run.executedTaps ? m_presampledAnySign : m_presampled, m_vUsed,
                          m_writesDepth, inputs, fill, sink, ctx, run);
        countRun(stats, count);
        return;
    }
    // The generic path: runChunk with the plain reads from `fill` (the other texture
    // instructions sampled as run() samples them), r0 narrowed to int16 for `sink`.
    const ThreadCached<RunState> st;
    st->in = &inputs;
    st->sampler = run.sampler;
    st->executedTaps = run.executedTaps;
    st->fill = fill;
    st->fillCtx = ctx;
    for (int c = 0; c < 4; ++c)
        if ((m_r0Preset >> c) & 1) std::memset(st->bi.reg[kSlotR][c], 0, sizeof st->bi.reg[kSlotR][c]);
    const FxArithKernels& fxArith = fxArithKernels(simdLevel());
    const FloatArithKernels& floatArith = floatArithKernels(simdLevel());
    alignas(64) int16_t r0[4][kChunk];
    const int16_t* const out[4] = {r0[0], r0[1], r0[2], r0[3]};
    for (int off = 0; off < count; off += kChunk) {
        st->offset = off;
        st->n = std::min(kChunk, count - off);
        st->depthWritten = false;
        runChunk(*st, fxArith, floatArith, nullptr);
        for (int c = 0; c < 4; ++c) fxArith.narrow(st->bi.reg[kSlotR][c], r0[c], st->n);  // |r0| <= nMax
        sink(ctx, off, st->n, out);
        if (outputs && outputs->killed) std::memcpy(outputs->killed + off, st->killed, size_t(st->n));
        if (outputs && outputs->depth && m_writesDepth && st->depthWritten)
            std::memcpy(outputs->depth + off, st->depth, sizeof(float) * size_t(st->n));
    }
    st->fill = nullptr;
    countRun(stats, count);
}

void ExecutorImpl::run(const PixelInputs& inputs, Sampler& sampler, PixelOutputs& outputs,
                       ExecutorStats* stats) const {
    const int count = std::clamp(inputs.count, 0, kMaxSpan);
    if (m_fast.ready) {
        runFast(m_fast, m_p, m_constsId, m_ops, m_vUsed, m_writesDepth, inputs, sampler, outputs);
    } else {
        runGeneric(inputs, sampler, outputs);
    }
    countRun(stats, count);
}

void ExecutorImpl::runGeneric(const PixelInputs& inputs, Sampler& sampler, PixelOutputs& outputs,
                              std::vector<TraceStep>* steps) const {
    const int count = std::clamp(inputs.count, 0, kMaxSpan);
    const ThreadCached<RunState> st;  // no 60 KB allocation (nor zero fill) per call
    st->in = &inputs;
    st->sampler = &sampler;
    st->fill = nullptr;
    const bool fx = isFixedPoint(m_p.precision);
    // r0 is the output: its channels read before written, or never written, are 0, in the bank
    // the profile uses (a trace shows the whole register after each step: all of it).
    const uint8_t preset = steps ? 0xF : m_r0Preset;
    for (int c = 0; c < 4; ++c) {
        if (!((preset >> c) & 1)) continue;
        if (fx)
            std::memset(st->bi.reg[kSlotR][c], 0, sizeof st->bi.reg[kSlotR][c]);
        else
            std::memset(st->bf.reg[kSlotR][c], 0, sizeof st->bf.reg[kSlotR][c]);
    }
    const float g = float(m_p.g);
    const FxArithKernels& fxArith = fxArithKernels(simdLevel());
    const FloatArithKernels& floatArith = floatArithKernels(simdLevel());
    for (int off = 0; off < count; off += kChunk) {
        st->offset = off;
        st->n = std::min(kChunk, count - off);
        st->depthWritten = false;
        runChunk(*st, fxArith, floatArith, off == 0 ? steps : nullptr);
        for (int c = 0; c < 4; ++c) {
            if (fx) {
                const int32_t* r = st->bi.reg[kSlotR][c];
                if (outputs.color[c])
                    for (int i = 0; i < st->n; ++i) outputs.color[c][off + i] = float(r[i]) / g;
                if (outputs.grid[c]) std::memcpy(outputs.grid[c] + off, r, sizeof(int32_t) * size_t(st->n));
            } else if (outputs.color[c]) {
                std::memcpy(outputs.color[c] + off, st->bf.reg[kSlotR][c], sizeof(float) * size_t(st->n));
            }
        }
        if (outputs.killed) std::memcpy(outputs.killed + off, st->killed, size_t(st->n));
        if (outputs.depth && m_writesDepth && st->depthWritten)
            std::memcpy(outputs.depth + off, st->depth, sizeof(float) * size_t(st->n));
    }
}

// Decoding ------------------------------------------------------------------------------------

struct Decoder {
    const Program& prog;
    Diagnostics& diags;
    int minor = 1;
    bool ok = true;

    void fail(const char* code, SourceLoc loc, std::string msg) {
        diags.error(code, loc, std::move(msg));
        ok = false;
    }

    // Register slot of an r#/t#/v# operand, or -1 after an E4004.
    int slotOf(RegType type, int index, SourceLoc loc) {
        switch (type) {
            case RegType::Temp:
                if (index < registerCount(type, minor)) return kSlotR + index;
                break;
            case RegType::Texture:  // a register only in 1_1-1_3; 1_4's t# are coordinates (SrcKind::TexCoord)
                if (minor < 4 && index < registerCount(type, minor)) return kSlotT + index;
                break;
            case RegType::Input:
                if (index < registerCount(type, minor)) return kSlotV + index;
                break;
            case RegType::Const:
                break;
        }
        fail("E4004", loc,
             std::string("register ") + regPrefix(type) + std::to_string(index) +
                 " cannot be used here by the executor (the program should have failed validation)");
        return -1;
    }

    DSrc src(const Src& s, bool textureOp) {
        DSrc d;
        for (int c = 0; c < 4; ++c) d.sw[size_t(c)] = uint8_t(swizzleComponent(s.swizzle, c));
        d.mod = s.mod;
        if (s.type == RegType::Const) {
            d.kind = SrcKind::Const;
            if (s.index >= registerCount(RegType::Const, minor))
                fail("E4004", s.loc, "constant c" + std::to_string(s.index) + " out of range");
            d.slot = uint8_t(s.index & 7);
        } else if (s.type == RegType::Texture && minor >= 4 && textureOp) {
            d.kind = SrcKind::TexCoord;
            if (s.index >= kMaxTexCoordSets) fail("E4004", s.loc, "texture coordinate t" + std::to_string(s.index) + " out of range");
            d.slot = uint8_t(s.index & 7);
        } else {
            int slot = slotOf(s.type, s.index, s.loc);
            d.slot = uint8_t(slot < 0 ? 0 : slot);
        }
        if ((s.mod == SrcMod::Dz || s.mod == SrcMod::Dw) && !textureOp)
            fail("E4005", s.loc, "modifier _dz/_dw on an arithmetic instruction cannot be executed");
        return d;
    }
};

}  // namespace
}  // namespace exec

int projectionDivisor(const StageState& stage) {
    if (!(stage.transformFlags & kTtffProjected)) return -1;
    uint32_t count = stage.transformFlags & ~kTtffProjected;
    if (count == 0 || count > stage.coordComponents) count = stage.coordComponents;
    if (count <= stage.textureDimensions) return -1;
    return int(count) - 1;
}

ExecutorOptions executorOptionsFor(const HardwareConfig& hardware) {
    ExecutorOptions o;
    o.precision = hardware.precision;
    o.maxValue = hardware.maxValue;
    o.coissuedCnd = hardware.hardware->coissuedCnd;
    return o;
}

uint8_t exec::r0PresetChannels(const std::vector<DOp>& ops) {
    uint8_t written = 0, preset = 0, held = 0;
    for (const DOp& d : ops) {
        // Reads first: a co-issued pair's second member reads before its first member's result
        // lands (held until then).
        uint8_t reads = 0;
        for (int s = 0; s < d.numSrc; ++s) {
            const DSrc& src = d.src[size_t(s)];
            if (src.kind != SrcKind::Reg || src.slot != kSlotR) continue;
            const uint8_t channels = componentsRead(*d.info, s, d.mask);
            for (int c = 0; c < 4; ++c)
                if ((channels >> c) & 1) reads = uint8_t(reads | (1u << src.sw[size_t(c)]));
        }
        if (d.dstSlot == kSlotR) reads = uint8_t(reads | d.info->dstReads);
        preset = uint8_t(preset | (reads & ~written));
        written = uint8_t(written | held);
        held = 0;
        if (d.dstSlot == kSlotR && d.info->writesDst) {
            if (d.hold)
                held = d.mask;
            else
                written = uint8_t(written | d.mask);
        }
    }
    written = uint8_t(written | held);
    return uint8_t((preset | ~written) & 0xF);
}

bool exec::decodeProgram(const Program& program, const ExecutorOptions& options, Diagnostics& diags,
                         DecodedProgram& out) {
    using namespace exec;
    Decoder dec{program, diags};
    const Version& ver = program.version;
    if (ver.major != 1 || ver.minor < 1 || ver.minor > 4) {
        diags.error("E4001", program.versionLoc,
                    "unsupported shader version ps_" + std::to_string(ver.major) + "_" + std::to_string(ver.minor) +
                        ": the executor runs ps_1_1 to ps_1_4");
        return false;
    }
    dec.minor = ver.minor;

    Profile p;
    p.precision = options.precision;
    p.minor = ver.minor;
    p.g = gridScale(options.precision);
    p.clampRange = options.precision != Precision::Ideal;
    float m = options.maxValue == 0 ? defaultHardware(ver.minor).maxValue : options.maxValue;
    // kMaxGridBound keeps the fx lanes' products inside int64 (precision.h).
    if (!(m > 0) || !(m <= 1e6) || (isFixedPoint(p.precision) && std::nearbyint(double(m) * p.g) > kMaxGridBound) ||
        (isFixedPoint(p.precision) && std::nearbyint(double(m) * p.g) < 1)) {
        diags.error("E4003", program.versionLoc,
                    "max value " + std::to_string(m) + " out of range for profile " + precisionName(p.precision) +
                        " (needs 0 < M <= 1e6 and 1 <= round(M*G) <= 2^24)");
        return false;
    }
    p.maxValue = m;
    p.nMax = isFixedPoint(p.precision) ? int32_t(std::nearbyint(double(m) * p.g)) : 0;
    if (isFixedPoint(p.precision)) {
        // Largest |numerator| of a product instruction: 4 terms of k*k (dp4) plus slack, times 2^3.
        double kmax = 4.0 * p.nMax + 2.0 * p.g;
        double bound = (4.0 * kmax * kmax + 4.0 * p.g * kmax) * 8.0;
        p.wide = bound >= 2147483647.0;
        p.exactDouble = bound < 4503599627370496.0;  // 2^52 (executor_arith_fx.inc roundClampDouble)
    }

    std::vector<DOp> ops;
    std::array<std::array<float, 4>, kNumConsts> defs{};
    uint8_t defMask = 0;
    uint32_t stages = 0;
    bool depth = false;
    uint8_t vUsed = 0;
    int padRun = 0;
    for (const Instruction& ins : program.instructions) {
        if (!ins.info) {
            dec.fail("E4002", ins.loc, "instruction without an opcode row");
            continue;
        }
        const Opcode opc = ins.opcode();
        if (opc == Opcode::Def) {
            int i = ins.dst.index;
            if (i >= kNumConsts) {
                dec.fail("E4004", ins.dst.loc, "def of c" + std::to_string(i) + " out of range");
                continue;
            }
            for (int c = 0; c < 4; ++c) defs[size_t(i)][size_t(c)] = ins.defValue(c);
            defMask = uint8_t(defMask | (1u << i));
            continue;
        }
        if (opc == Opcode::Nop || opc == Opcode::Comment || opc == Opcode::End) continue;
        if (!(ins.info->versions & versionBit(ver.minor)) || opc == Opcode::TexM3x3Diff) {
            dec.fail("E4002", ins.loc,
                     "instruction '" + std::string(ins.info->mnemonic) + "' cannot be run in ps_1_" +
                         std::to_string(ver.minor));
            continue;
        }
        DOp d;
        d.op = opc;
        d.info = ins.info;
        d.instruction = int32_t(&ins - program.instructions.data());
        if (opc == Opcode::Phase) {
            ops.push_back(d);
            continue;
        }
        d.texture = ins.info->cls == OpClass::Texture;
        if (ins.coissue) {
            if (ops.empty() || ops.back().texture || ops.back().op == Opcode::Phase || d.texture) {
                dec.fail("E4006", ins.loc, "co-issued instruction without an arithmetic partner");
                continue;
            }
            // A co-issued ps_1_1 … 1_3 cnd on a CoissuedCnd::Sequential class reads what its
            // partner has just written (NVIDIA's Windows driver in Wine's cnd_test); every other
            // pair reads before either member writes.
            const bool sequential =
                opc == Opcode::Cnd && ver.minor < 4 && options.coissuedCnd == CoissuedCnd::Sequential;
            if (!sequential) ops.back().hold = true;
        }
        d.numSrc = ins.info->numSrc;
        for (int s = 0; s < d.numSrc; ++s) {
            d.src[size_t(s)] = dec.src(ins.src[size_t(s)], d.texture);
            if (ins.src[size_t(s)].type == RegType::Input && ins.src[size_t(s)].index < 2)
                vUsed = uint8_t(vUsed | (1u << ins.src[size_t(s)].index));
        }
        if (ins.info->hasDst) {
            d.mask = ins.dst.mask;
            d.sat = ins.dst.saturate;
            d.shift = ins.dst.shift;
            if (d.shift < -3 || d.shift > 3) dec.fail("E4005", ins.dst.loc, "shift out of range");
            if (ins.dst.type == RegType::Const || ins.dst.type == RegType::Input) {
                dec.fail("E4004", ins.dst.loc, "destination register file cannot be written");
            } else if (opc == Opcode::TexKill && ins.dst.type == RegType::Texture && ver.minor >= 4) {
                // ps_1_4 texkill t#: tests the coordinate set, writes nothing (spec §2.4).
                d.dstSlot = 0;
            } else {
                int slot = dec.slotOf(ins.dst.type, ins.dst.index, ins.dst.loc);
                d.dstSlot = uint8_t(slot < 0 ? 0 : slot);
            }
            d.stage = uint8_t(ins.dst.index & 7);
        }
        if (!d.texture && opc == Opcode::Cnd && ver.minor < 4) {
            // 1_1-1_3: the condition is r0.a for every component (spec §3.6); force the
            // replicate so the per-component kernel implements the version rule.
            d.src[0].sw = {3, 3, 3, 3};
        }
        if (d.texture) {
            const bool isPad = opc == Opcode::TexM3x2Pad || opc == Opcode::TexM3x3Pad;
            d.padIndex = uint8_t(isPad ? std::min(padRun, 1) : 0);
            d.rowBase = uint8_t(std::max(0, int(d.stage) - padRun));
            padRun = isPad ? padRun + 1 : 0;
            if (ver.minor < 4 && ins.info->hasDst && ins.dst.type != RegType::Texture && opc != Opcode::TexDepth)
                dec.fail("E4004", ins.dst.loc, "texture instruction destination must be t#");
            if (samplesStage(opc)) stages |= 1u << d.stage;
            if (replacesDepth(opc)) depth = true;
            if (opc == Opcode::TexKill && ver.minor < 4) {
                // 1_1-1_3 texkill names t(m) but tests TC[m] (spec §7.9).
                d.src[0].kind = SrcKind::TexCoord;
                d.src[0].slot = d.stage;
            }
            if (opc == Opcode::TexKill && ver.minor >= 4) {
                // 1_4: the destination token names the register tested.
                const Dst& t = ins.dst;
                if (t.type == RegType::Texture) {
                    d.src[0].kind = SrcKind::TexCoord;
                    d.src[0].slot = uint8_t(t.index & 7);
                } else {
                    d.src[0].kind = SrcKind::Reg;
                    int slot = dec.slotOf(t.type, t.index, t.loc);
                    d.src[0].slot = uint8_t(slot < 0 ? 0 : slot);
                }
                d.src[0].sw = {0, 1, 2, 3};
            }
        } else {
            padRun = 0;
        }
        ops.push_back(d);
    }
    if (!ops.empty() && ops.back().hold) {
        dec.fail("E4006", program.instructions.back().loc, "co-issued pair without its second member");
    }
    if (!dec.ok) return false;
    out = DecodedProgram{p, std::move(ops), defs, defMask, stages, depth, vUsed};
    return true;
}

std::unique_ptr<Executor> Executor::create(const Program& program, const ExecutorOptions& options,
                                           Diagnostics& diags) {
    exec::DecodedProgram d;
    if (!exec::decodeProgram(program, options, diags, d)) return nullptr;
    return std::make_unique<exec::ExecutorImpl>(options, d.profile, std::move(d.ops), d.defs, d.defMask,
                                                d.stagesUsed, d.writesDepth, d.vUsed);
}

// ExecutorImpl is the only Executor (Executor::create makes it).
bool tapPlan(const Executor& executor, TapPlan& plan, bool executes) {
    return static_cast<const exec::ExecutorImpl&>(executor).tapPlan(plan, executes);
}

bool plainTaps(const Executor& executor, TapPlan& plan, bool executes) {
    return static_cast<const exec::ExecutorImpl&>(executor).plainTaps(plan, executes);
}

void runPresampled(const Executor& executor, const PixelInputs& inputs, TapFill fill, ResultSink sink, void* ctx,
                   ExecutorStats* stats, const PresampledRun& run) {
    static_cast<const exec::ExecutorImpl&>(executor).runPresampled(inputs, fill, sink, ctx, stats, run);
}

bool chainRows(const Executor& executor) {
    return static_cast<const exec::ExecutorImpl&>(executor).chainRows();
}

void runChainRow(const Executor& executor, const ChainRowTap* taps, int count, uint8_t* out,
                 const ChainRowStore& store, ExecutorStats* stats) {
    static_cast<const exec::ExecutorImpl&>(executor).runChainRow(taps, count, out, store, stats);
}

}  // namespace ps11
