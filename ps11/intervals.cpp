// Interval evaluator, driver and texture instructions: create() decodes the program as the
// executor does (exec::decodeProgram: the same op list, co-issue holds, constants and profile);
// evaluate() loads the input ranges as the executor loads inputs, runs the op list over ranges in
// the executor's order (executor.cpp runChunk), bounds the texture-address instructions as
// executor_texture.cpp computes them, and reports r0, depth, texkill and the copy tag
// (docs/intervals.md). The arithmetic is intervals_arith.cpp.
#include "ps11/intervals.h"

#include <algorithm>
#include <cmath>

#include "ps11/intervals_internal.h"
#include "ps11/opcodes.h"

namespace ps11 {
namespace intervals {

FI fromRange(const ValueRange& r) {
    if (r.lo != r.lo || r.hi != r.hi || r.lo > r.hi) return fTop();
    // Bounds to the nearest float: a float inside [lo, hi] stays inside, and a bound computed in
    // double from a float value (0.4 for the texel 102/255 = 0.4f) still admits that value.
    return norm({float(r.lo), float(r.hi), r.nan, r.negZero});
}

AV wholeRange(const exec::Profile& p) {
    AV a;
    a.nlo = -p.nMax, a.nhi = p.nMax;
    a.f = p.clampRange ? FI{-p.maxValue, p.maxValue, true, true} : fTop();
    return a;
}

namespace {

using exec::DOp;
using exec::DSrc;
using exec::Profile;
using exec::SrcKind;

// A register component as the texture stage reads it (executor_texture.cpp regFloat): fx n/G as
// a float (monotone), then _bx2 (2x − 1) if given.
FI regFloat(const Profile& p, const AV& r, SrcMod mod) {
    FI x = isFixedPoint(p.precision) ? FI{float(r.nlo) / float(p.g), float(r.nhi) / float(p.g), false, false} : r.f;
    if (mod == SrcMod::Sign) x = norm({2.0f * x.lo - 1.0f, 2.0f * x.hi - 1.0f, x.nan, false});
    return x;
}

struct State {
    State(const Profile& p_, const IntervalInputs& in_) : p(p_), in(in_) {}
    const Profile& p;
    const IntervalInputs& in;
    Regs regs;
    FI tc[kMaxTexCoordSets][4];  // the sets the program reads as values (m_tcRead)
    FI pad[2]{};
    FI depth{0.0f, 1.0f, false, false};
    bool depthWritten = false;
    bool mayKill = false, allKilled = false;
    WriteFindings wf;  // the current instruction's (trace)

    FI srcFloat(const DSrc& s, int comp) const {
        return s.kind == SrcKind::TexCoord ? tc[s.slot & 7][comp] : regFloat(p, regs.reg[s.slot][comp], s.mod);
    }
    // executor_texture.cpp writeFloat: fx rounds (nearbyint, ties to even) then clamps, NaN to the
    // lower clamp; float saturates (NaN to 0) or keeps NaN, then clamps to ±M.
    AV writeValue(const FI& v, bool sat, uint8_t channel = 0) {
        AV a;
        if (isFixedPoint(p.precision)) {
            const double g = p.g;
            const double lo = sat ? 0.0 : -double(p.nMax), hi = sat ? double(p.g < p.nMax ? p.g : p.nMax) : p.nMax;
            if (v.nan || std::nearbyint(double(v.lo) * g) < lo || std::nearbyint(double(v.hi) * g) > hi)
                (sat ? wf.saturate : wf.clamp) |= channel;
            if (v.lo != v.hi || std::nearbyint(double(v.lo) * g) != double(v.lo) * g) wf.round |= channel;
            auto f = [&](float x) {
                double t = std::nearbyint(double(x) * g);
                t = t > lo ? t : lo;
                return t < hi ? t : hi;
            };
            a.nlo = int32_t(v.nan ? lo : f(v.lo));
            a.nhi = int32_t(f(v.hi));
            return a;
        }
        const float lo = p.clampRange ? -p.maxValue : -kInf, hi = p.clampRange ? p.maxValue : kInf;
        auto clamp = [&](float x) {
            x = x < lo ? lo : x;
            return x > hi ? hi : x;
        };
        if (sat ? (v.nan || v.lo < 0.0f || v.hi > 1.0f) : (v.lo < lo || v.hi > hi))
            (sat ? wf.saturate : wf.clamp) |= channel;
        if (sat) {
            auto f = [&](float x) {
                x = x > 0.0f ? x : 0.0f;
                return clamp(x < 1.0f ? x : 1.0f);
            };
            a.f = {v.nan ? std::min(f(v.lo), f(0.0f)) : f(v.lo), v.nan ? std::max(f(v.hi), f(0.0f)) : f(v.hi), false,
                   false};
        } else {
            a.f = norm({clamp(v.lo), clamp(v.hi), v.nan, v.nz});
        }
        return a;
    }
    // TC[row].xyz · T[n].rgb as ((x·r + y·g) + z·b) (executor_texture.cpp rowDot).
    FI rowDot(int row, const DSrc& s) const {
        const FI* t = tc[row & 7];
        const AV* r = regs.reg[s.slot];
        return fAdd(fAdd(fMul(t[0], regFloat(p, r[0], s.mod)), fMul(t[1], regFloat(p, r[1], s.mod))),
                    fMul(t[2], regFloat(p, r[2], s.mod)));
    }
    // A lookup lands in the destination: the stage's range when it bounds this lookup, else
    // anything; then the register clamp to ±M (not in ideal). A plain lookup inside ±M tags each
    // channel as a copy of itself.
    void sample(const DOp& op, int opIndex, bool plain) {
        const StageRange& sr = in.stages[op.stage];
        const bool known = plain || sr.anyCoords;
        for (int c = 0; c < 4; ++c) {
            const ValueRange& vr = known ? sr.value[size_t(c)] : ValueRange::any();
            AV& a = regs.reg[op.dstSlot][c];
            a = AV{};
            bool inside = false;
            if (isFixedPoint(p.precision)) {
                // Grid integers n with n/G in [lo, hi], outward by a float's rounding (bounds
                // computed in float, 0.4f for 102/255, still admit their grid value); an infinite
                // bound reaches past ±M, so the clamp may act.
                const double g = p.g, m = p.nMax;
                auto tol = [](double x) { return 1e-6 + std::fabs(x) * 0x1p-20; };
                double lo = std::isfinite(vr.lo) ? std::ceil(vr.lo * g - tol(vr.lo * g)) : vr.lo;
                double hi = std::isfinite(vr.hi) ? std::floor(vr.hi * g + tol(vr.hi * g)) : vr.hi;
                if (!(lo <= hi)) std::swap(lo, hi);  // no grid value inside: keep the hull sound
                if (lo != lo || hi != hi) lo = -INFINITY, hi = INFINITY;
                inside = lo >= -m && hi <= m;
                a.nlo = int32_t(std::clamp(lo, -m, m));
                a.nhi = int32_t(std::clamp(hi, -m, m));
            } else {
                const FI v = fromRange(vr);
                const float m = p.clampRange ? p.maxValue : kInf;
                inside = !v.nan && v.lo >= -m && v.hi <= m;
                auto clamp = [&](float x) { return x < -m ? -m : (x > m ? m : x); };
                a.f = norm({clamp(v.lo), clamp(v.hi), v.nan, v.nz});
            }
            if (plain && inside) a.tap = int8_t(opIndex), a.ch = uint8_t(c);
            if (!inside) wf.clamp |= uint8_t(1u << c);
        }
    }
    // depth = (w == 0) ? 1 : z/w, then clamped to [0, 1] with NaN to 0 (texm3x2depth, texdepth).
    void writeDepth(const FI& z, const FI& w) {
        depthWritten = true;
        if (isPoint(w, 0.0f)) {
            depth = {1.0f, 1.0f, false, false};
            return;
        }
        if (has0(w) || w.nan) {
            depth = {0.0f, 1.0f, false, false};
            return;
        }
        const FI q = fDiv(z, w);
        auto f = [](float x) {
            x = x > 0.0f ? x : 0.0f;
            return x < 1.0f ? x : 1.0f;
        };
        depth = {q.nan ? 0.0f : f(q.lo), q.nan ? std::max(f(q.hi), 0.0f) : f(q.hi), false, false};
    }
    void kill(const FI* x) {
        // Discards when any of x, y, z < 0 (a NaN never does, −0.0 neither).
        bool any = false, all = false;
        for (int c = 0; c < 3; ++c) {
            any = any || x[c].lo < 0.0f;
            all = all || (!x[c].nan && x[c].hi < 0.0f);
        }
        mayKill = mayKill || any;
        allKilled = allKilled || all;
    }
};

// The texture-address instructions (executor_texture.cpp execTexture).
void evalTexture(const Profile& p, bool stagesKnown, const DOp& op, int opIndex, bool plain, State& st) {
    const bool v14 = p.minor >= 4;
    switch (op.op) {
        case Opcode::TexCoord:
            if (!v14) {
                // texcoord: (sat u, sat v, sat w, 1).
                for (int c = 0; c < 3; ++c)
                    st.regs.reg[op.dstSlot][c] = st.writeValue(st.tc[op.stage][c], true, uint8_t(1u << c));
                st.regs.reg[op.dstSlot][3] = st.writeValue(fPoint(1.0f), false);
            } else {
                // texcrd: the swizzled coordinates, _dz/_dw dividing x and y (a zero divisor gives
                // 1.0, a small one anything), rounded and clamped like a result.
                const DSrc& s = op.src[0];
                FI raw[4], c[4];
                for (int k = 0; k < 4; ++k) raw[k] = st.srcFloat(s, k);
                for (int k = 0; k < 4; ++k) c[k] = raw[s.sw[size_t(k)]];
                if (s.mod == SrcMod::Dz || s.mod == SrcMod::Dw) {
                    const FI& d = raw[s.mod == SrcMod::Dz ? 2 : 3];
                    for (int k = 0; k < 2; ++k)
                        c[k] = isPoint(d, 0.0f) ? fPoint(1.0f) : (has0(d) || d.nan) ? fTop() : fDiv(c[k], d);
                }
                for (int k = 0; k < 4; ++k)
                    if ((op.mask >> k) & 1) st.regs.reg[op.dstSlot][k] = st.writeValue(c[k], op.sat, uint8_t(1u << k));
            }
            break;
        case Opcode::Tex:
            st.sample(op, opIndex, plain);
            break;
        case Opcode::TexKill: {
            FI x[3];
            for (int c = 0; c < 3; ++c) x[c] = st.srcFloat(op.src[0], c);
            st.kill(x);
            break;
        }
        case Opcode::TexBemL: {
            // texbem, then every channel times L = b·LSCALE + LOFFSET (clamped to [0, 1] only for
            // the fixed-function stage), rounded once; an unknown stage state gives anything.
            st.sample(op, opIndex, false);
            const StageState& ss = p.stages[op.stage];
            FI l = fAdd(fMul(regFloat(p, st.regs.reg[op.src[0].slot][2], op.src[0].mod), fPoint(ss.lumScale)),
                        fPoint(ss.lumOffset));
            if (ss.clampLuminance) {
                auto f = [](float x) { return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x); };
                l = norm({f(l.lo), f(l.hi), l.nan, l.nz});
            }
            for (int c = 0; c < 4; ++c) {
                AV& a = st.regs.reg[op.dstSlot][c];
                if (!stagesKnown) {
                    a = wholeRange(p);
                } else if (isFixedPoint(p.precision)) {
                    // nearbyint(d·L) clamped to ±M, NaN to −M.
                    const double m = p.nMax;
                    if (!finite(l)) {
                        a.nlo = -p.nMax, a.nhi = p.nMax;
                        continue;
                    }
                    double lo = INFINITY, hi = -INFINITY;
                    for (int k = 0; k < 4; ++k) {
                        double x = std::nearbyint(double(k & 1 ? a.nhi : a.nlo) * double(k & 2 ? l.hi : l.lo));
                        x = x > -m ? x : -m;
                        x = x < m ? x : m;
                        lo = std::min(lo, x), hi = std::max(hi, x);
                    }
                    a.nlo = int32_t(lo), a.nhi = int32_t(hi);
                } else {
                    const float lo = p.clampRange ? -p.maxValue : -kInf, hi = p.clampRange ? p.maxValue : kInf;
                    const FI x = fMul(a.f, l);
                    auto f = [&](float v) { return v < lo ? lo : (v > hi ? hi : v); };
                    a.f = norm({f(x.lo), f(x.hi), x.nan, x.nz});
                }
                a.tap = -1;
            }
            break;
        }
        case Opcode::TexM3x2Pad:
        case Opcode::TexM3x3Pad:
            st.pad[op.padIndex] = st.rowDot(op.stage, op.src[0]);
            break;
        case Opcode::TexM3x2Depth:
            st.writeDepth(st.pad[0], st.rowDot(op.stage, op.src[0]));
            break;
        case Opcode::TexM3x3: {
            const FI w = st.rowDot(op.stage, op.src[0]);
            AV* d = st.regs.reg[op.dstSlot];
            d[0] = st.writeValue(st.pad[0], false, 1);
            d[1] = st.writeValue(st.pad[1], false, 2);
            d[2] = st.writeValue(w, false, 4);
            d[3] = st.writeValue(fPoint(1.0f), false);
            break;
        }
        case Opcode::TexDp3: {
            const AV v = st.writeValue(st.rowDot(op.stage, op.src[0]), false, 0xf);
            for (int c = 0; c < 4; ++c) st.regs.reg[op.dstSlot][c] = v;
            break;
        }
        case Opcode::TexDepth:
            st.writeDepth(regFloat(p, st.regs.reg[op.dstSlot][0], SrcMod::None),
                          regFloat(p, st.regs.reg[op.dstSlot][1], SrcMod::None));
            break;
        default:
            // Every other lookup (texbem, texreg2*, texm3x2tex, texm3x3tex/spec/vspec, texdp3tex)
            // is dependent: its coordinates come from registers.
            if (samplesStage(op.op)) st.sample(op, opIndex, false);
            break;
    }
}

ChannelInterval channelOf(const Profile& p, const AV& a) {
    ChannelInterval ci;
    if (isFixedPoint(p.precision)) {
        ci.gridLo = a.nlo, ci.gridHi = a.nhi;
        ci.lo = double(a.nlo) / p.g, ci.hi = double(a.nhi) / p.g;
        ci.constant = a.nlo == a.nhi;
        return ci;
    }
    ci.lo = a.f.lo == 0.0f ? 0.0 : double(a.f.lo);
    ci.hi = a.f.hi == 0.0f ? 0.0 : double(a.f.hi);
    ci.bounded = !a.f.nan && std::isfinite(ci.lo) && std::isfinite(ci.hi);
    ci.negZero = a.f.nz && has0(a.f);
    ci.constant = !a.f.nan && a.f.lo == a.f.hi && !ci.negZero;
    return ci;
}

}  // namespace
}  // namespace intervals

std::optional<IntervalEvaluator> IntervalEvaluator::create(const Program& program, const IntervalSetup& setup,
                                                           Diagnostics& diags) {
    exec::DecodedProgram d;
    if (!exec::decodeProgram(program, setup.options, diags, d)) return std::nullopt;
    IntervalEvaluator e;
    e.m_p = d.profile;
    e.m_ops = std::move(d.ops);
    e.m_stagesKnown = setup.stagesKnown;
    e.m_writesDepth = d.writesDepth;
    if (setup.stagesKnown) e.m_p.stages = setup.stages;
    // Constants as the executor loads them (a def overrides the API value).
    for (int i = 0; i < exec::kNumConsts; ++i) {
        const auto& v = (d.defMask >> i) & 1 ? d.defs[size_t(i)] : setup.constants[size_t(i)];
        for (int c = 0; c < 4; ++c)
            exec::constantOf(e.m_p.precision, v[size_t(c)], e.m_p.constGrid[size_t(i)][size_t(c)],
                             e.m_p.constF[size_t(i)][size_t(c)]);
    }
    e.m_taps.resize(e.m_ops.size());
    for (size_t k = 0; k < e.m_ops.size(); ++k) {
        const exec::DOp& op = e.m_ops[k];
        Tap& t = e.m_taps[k];
        t.instruction = int16_t(op.instruction);
        // Plain lookups: 1_1-1_3 tex (TC[m]), 1_4 texld from a t# (coordinates only).
        t.plain = op.op == Opcode::Tex && (e.m_p.minor < 4 || op.src[0].kind == exec::SrcKind::TexCoord);
        if (samplesStage(op.op)) (t.plain ? e.m_plainStages : e.m_dependentStages) |= 1u << op.stage;
        // The coordinate sets read as values (lookups read coordinates only to sample).
        const int srcSet = op.src[0].kind == exec::SrcKind::TexCoord ? op.src[0].slot & 7 : -1;
        switch (op.op) {
            case Opcode::TexCoord:
                e.m_tcRead |= uint8_t(1u << (e.m_p.minor < 4 ? op.stage : std::max(srcSet, 0)));
                break;
            case Opcode::TexKill:
                e.m_tcRead |= uint8_t(srcSet >= 0 ? 1u << srcSet : 0);
                break;
            case Opcode::TexM3x2Pad:
            case Opcode::TexM3x3Pad:
            case Opcode::TexM3x2Depth:
            case Opcode::TexM3x3:
            case Opcode::TexDp3:
                e.m_tcRead |= uint8_t(1u << (op.stage & 7));
                break;
            default:
                break;
        }
    }
    e.m_vRead = d.vUsed;
    // The slots an op names (sources, destination; a texture op any t#, as matrix rows read the
    // rows before), and r0: what run() must set before the first op.
    e.m_slotsNamed = 1u << exec::kSlotR;
    for (const exec::DOp& op : e.m_ops) {
        e.m_slotsNamed |= 1u << op.dstSlot;
        for (const exec::DSrc& src : op.src)
            if (src.kind == exec::SrcKind::Reg) e.m_slotsNamed |= 1u << src.slot;
        if (op.texture)
            for (int t = 0; t < exec::kNumRegT; ++t) e.m_slotsNamed |= 1u << (exec::kSlotT + t);
    }
    return e;
}

void IntervalEvaluator::evaluate(const IntervalInputs& inputs, IntervalResult& result) const {
    run(inputs, result, nullptr);
}

void IntervalEvaluator::trace(const IntervalInputs& inputs, IntervalResult& result,
                              std::vector<InstructionInterval>& steps) const {
    steps.clear();
    run(inputs, result, &steps);
}

void IntervalEvaluator::run(const IntervalInputs& inputs, IntervalResult& result,
                            std::vector<InstructionInterval>* steps) const {
    using namespace intervals;
    const Profile& p = m_p;
    State st{p, inputs};
    // Registers a validated program reads only after writing them: the whole range. r0 starts at
    // 0 (the executor zeroes it).
    // (Slots no op names are never read: left as they are.)
    const AV whole = wholeRange(p);
    for (int r = 0; r < exec::kNumSlots; ++r)
        if ((m_slotsNamed >> r) & 1)
            for (AV& a : st.regs.reg[r]) a = whole;
    for (AV& a : st.regs.reg[exec::kSlotR]) a = AV{}, a.f = fPoint(0.0f);
    // v# saturated to [0, 1] (NaN and −0.0 to +0.0) and, in fx, rounded to the grid (loadColors).
    for (int v = 0; v < exec::kNumRegV; ++v) {
        if (!((m_vRead >> v) & 1)) continue;
        for (int c = 0; c < 4; ++c) {
            const FI x = fromRange(inputs.color[size_t(v)][size_t(c)]);
            auto sat = [](float s) { return s > 0.0f ? (s < 1.0f ? s : 1.0f) : 0.0f; };
            const float lo = x.nan ? 0.0f : sat(x.lo), hi = sat(x.hi);
            AV& a = st.regs.reg[exec::kSlotV + v][c];
            a = AV{};
            a.f = {lo, hi, false, false};
            a.nlo = int32_t(std::nearbyint(double(lo) * p.g));
            a.nhi = int32_t(std::nearbyint(double(hi) * p.g));
        }
    }
    for (int t = 0; t < kMaxTexCoordSets; ++t)
        if ((m_tcRead >> t) & 1)
            for (int c = 0; c < 4; ++c) st.tc[t][c] = fromRange(inputs.texcoord[size_t(t)][size_t(c)]);

    AV hold[4];
    for (size_t i = 0; i < m_ops.size(); ++i) {
        const exec::DOp& op = m_ops[i];
        if (op.op == Opcode::Phase) continue;  // r#.a keep their values
        st.wf = WriteFindings{};
        if (op.texture) {
            evalTexture(p, m_stagesKnown, op, int(i), m_taps[i].plain, st);
        } else {
            AV out[4];
            evalArith(p, m_stagesKnown, op, st.regs, out, steps ? &st.wf : nullptr);
            AV* dst = op.hold ? hold : st.regs.reg[op.dstSlot];
            for (int c = 0; c < 4; ++c)
                if ((op.mask >> c) & 1) dst[c] = out[c];
        }
        if (steps) {
            InstructionInterval s;
            s.instruction = m_taps[i].instruction;
            s.op = int(i);
            s.writes = op.info->writesDst;
            if (s.writes) {
                // The destination as the instruction leaves it (a co-issued first member: what it
                // is about to write), every channel.
                const AV* d = op.hold ? hold : st.regs.reg[op.dstSlot];
                for (int c = 0; c < 4; ++c)
                    s.dst[size_t(c)] = channelOf(p, (op.mask >> c) & 1 || !op.hold ? d[c] : st.regs.reg[op.dstSlot][c]);
                s.mask = op.texture ? uint8_t(0xf) : op.mask;
            }
            s.clamps = st.wf.clamp;
            s.saturates = st.wf.saturate;
            s.rounds = st.wf.round;
            steps->push_back(s);
        }
        if (!op.hold && i > 0 && m_ops[i - 1].hold) {
            // Co-issued pair: both have read; now the first member writes.
            const exec::DOp& first = m_ops[i - 1];
            for (int c = 0; c < 4; ++c)
                if ((first.mask >> c) & 1) st.regs.reg[first.dstSlot][c] = hold[c];
        }
    }

    const AV* r0 = st.regs.reg[exec::kSlotR];
    for (int c = 0; c < 4; ++c) result.color[size_t(c)] = channelOf(p, r0[c]);
    result.writesDepth = m_writesDepth;
    result.depth = ChannelInterval{};
    if (m_writesDepth) {
        const FI d = st.depthWritten ? st.depth : FI{0.0f, 1.0f, false, false};
        result.depth.lo = d.lo, result.depth.hi = d.hi;
        result.depth.constant = d.lo == d.hi;
    }
    result.kill = st.allKilled ? KillRange::Always : st.mayKill ? KillRange::Maybe : KillRange::Never;
    result.copyStage = result.copyInstruction = -1;
    result.channelCopyStage = result.channelCopyInstruction = -1;
    result.copyMask = 0;
    // The first channel that is its own channel of a lookup names the lookup; every channel
    // that is that lookup's same channel joins it.
    int tap = -1;
    for (int c = 0; c < 4 && tap < 0; ++c)
        if (r0[c].tap >= 0 && r0[c].ch == c) tap = r0[c].tap;
    if (tap < 0) return;
    for (int c = 0; c < 4; ++c)
        if (r0[c].tap == tap && r0[c].ch == c) result.copyMask |= uint8_t(1u << c);
    result.channelCopyStage = m_ops[size_t(tap)].stage;
    result.channelCopyInstruction = m_taps[size_t(tap)].instruction;
    if (result.copyMask == 0xf) {
        result.copyStage = result.channelCopyStage;
        result.copyInstruction = result.channelCopyInstruction;
    }
}

}  // namespace ps11
