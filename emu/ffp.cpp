// Fixed-function texture stages lowered to a ps_1_1 program (docs/fixed-function.md). Every
// D3DTOP operation is one arithmetic instruction whose exact result is the D3D formula, so the
// executor rounds each stage once, like any shader instruction (PREMODULATE adds an exact select
// and one multiply in the next stage; bump mapping is texbem/texbeml); colour and alpha halves are
// a co-issued pair (both read before either writes, as the two halves of a stage do).
#include "emu/ffp.h"

#include <array>
#include <string_view>
#include <vector>

#include "ps11/opcodes.h"

namespace emu {
namespace {

using ps11::Dst;
using ps11::Instruction;
using ps11::RegType;
using ps11::Src;
using ps11::SrcMod;

constexpr uint8_t kSwizzleAlpha = ps11::replicateSwizzle(3);

const ps11::OpcodeInfo* opcode(std::string_view mnemonic) { return ps11::findOpcode(mnemonic, 1); }

bool colorOnly(DWORD op) {
    // "This operation is supported only for color operations" (D3DTEXTUREOP reference page).
    switch (op) {
        case D3DTOP_MODULATEALPHA_ADDCOLOR:
        case D3DTOP_MODULATECOLOR_ADDALPHA:
        case D3DTOP_MODULATEINVALPHA_ADDCOLOR:
        case D3DTOP_MODULATEINVCOLOR_ADDALPHA:
        case D3DTOP_BUMPENVMAP:
        case D3DTOP_BUMPENVMAPLUMINANCE:
            return true;
        default:
            return false;
    }
}

bool isBump(DWORD op) { return op == D3DTOP_BUMPENVMAP || op == D3DTOP_BUMPENVMAPLUMINANCE; }

// 1 - x of a fetched argument: the complement flag toggles (1 - (1 - x) = x).
SrcMod invert(SrcMod m) { return m == SrcMod::Comp ? SrcMod::None : SrcMod::Comp; }
// x - 0.5 of an argument: 1 - x becomes 0.5 - x = -(x - 0.5).
SrcMod biased(SrcMod m) { return m == SrcMod::Comp ? SrcMod::BiasNeg : SrcMod::Bias; }
// 2x - 1 of an argument: 1 - x becomes 1 - 2x = -(2x - 1).
SrcMod signedMod(SrcMod m) { return m == SrcMod::Comp ? SrcMod::SignNeg : SrcMod::Sign; }

Src withMod(Src s, SrcMod m) {
    s.mod = m;
    return s;
}
Src alphaOf(Src s) {
    s.swizzle = kSwizzleAlpha;
    return s;
}

std::string hex(DWORD v) {
    static const char* digits = "0123456789abcdef";
    std::string s;
    for (int shift = 28; shift >= 0; shift -= 4) s += digits[(v >> shift) & 15];
    return "0x" + s;
}

std::array<float, 4> colorFloats(DWORD argb) {
    return {float((argb >> 16) & 255) / 255.0f, float((argb >> 8) & 255) / 255.0f, float(argb & 255) / 255.0f,
            float((argb >> 24) & 255) / 255.0f};
}

class Lowering {
public:
    Lowering(const DeviceState& state, CallError& error) : m_state(state), m_error(error) {}

    std::optional<LoweredStages> run();

private:
    DWORD tss(int stage, D3DTEXTURESTAGESTATETYPE s) const { return m_state.stageState(stage, s); }
    bool fail(const char* code, int stage, const char* stateName, const std::string& what) {
        m_error = CallError{D3DERR_INVALIDCALL, code, "stage " + std::to_string(stage) + " " + stateName + ": " + what};
        return false;
    }

    bool checkOp(int stage, D3DTEXTURESTAGESTATETYPE which, bool alpha);
    bool texture(int stage, const char* stateName, Src& out);
    int constant(const std::array<float, 4>& value);
    bool arg(int stage, D3DTEXTURESTAGESTATETYPE which, Src& out);
    bool lowerHalf(int stage, bool alpha, const Dst& dst, Instruction& out);
    bool lowerBump(int stage, int active);
    bool lowerStage(int stage);
    bool lowerPremodulate(int stage);
    void lowerOutput();
    void assemble(LoweredStages& out) const;
    Src current() const { return reg(m_r0Written ? RegType::Temp : RegType::Input, 0); }
    Src temp() { return m_r1Written ? reg(RegType::Temp, 1) : constSrc(constant({0, 0, 0, 0})); }
    static Src reg(RegType t, int index) {
        Src s;
        s.type = t;
        s.index = uint8_t(index);
        return s;
    }
    static Src constSrc(int index) { return reg(RegType::Const, index < 0 ? 0 : index); }
    void emit(const char* mnemonic, const Dst& dst, std::initializer_list<Src> srcs, Instruction& out) const;

    const DeviceState& m_state;
    CallError& m_error;
    std::vector<std::array<float, 4>> m_consts;  // c0, c1, … in order of first use
    bool m_constOverflow = false;
    bool m_r0Written = false, m_r1Written = false;
    uint32_t m_sampled = 0;
    std::array<bool, kMaxStages> m_bumpInto{};  // stage i's texture is looked up by texbem(l)
    std::vector<Instruction> m_arith;
    // PREMODULATE of the previous stage: its destination and the channels to modulate.
    uint8_t m_premodMask = 0;
    uint8_t m_premodReg = 0;
    bool m_premodAlpha = false;  // the alpha half was PREMODULATE (for the error's state name)
};

bool Lowering::checkOp(int stage, D3DTEXTURESTAGESTATETYPE which, bool alpha) {
    const char* name = alpha ? "D3DTSS_ALPHAOP" : "D3DTSS_COLOROP";
    const DWORD op = tss(stage, which);
    if (op < D3DTOP_DISABLE || op > D3DTOP_LERP)
        return fail("E4140", stage, name, "unknown texture operation " + std::to_string(op) + " (D3DTOP_* is 1..26)");
    if (alpha && colorOnly(op))
        return fail("E4144", stage, name,
                    "texture operation " + std::to_string(op) + " is a colour-only operation (D3DTSS_COLOROP only)");
    return true;
}

bool Lowering::texture(int stage, const char* stateName, Src& out) {
    if (stage >= kMaxFixedFunctionTextures)
        return fail("E4142", stage, stateName,
                    "reads the stage's texture, but only stages 0.." + std::to_string(kMaxFixedFunctionTextures - 1) +
                        " can sample (MaxSimultaneousTextures " + std::to_string(kMaxFixedFunctionTextures) + ")");
    m_sampled |= 1u << stage;
    out = reg(RegType::Texture, stage);
    return true;
}

int Lowering::constant(const std::array<float, 4>& value) {
    for (size_t i = 0; i < m_consts.size(); ++i)
        if (m_consts[i] == value) return int(i);
    if (m_consts.size() >= 8) {
        m_constOverflow = true;
        return -1;
    }
    m_consts.push_back(value);
    return int(m_consts.size() - 1);
}

bool Lowering::arg(int stage, D3DTEXTURESTAGESTATETYPE which, Src& out) {
    static constexpr const char* kNames[] = {"D3DTSS_COLORARG1", "D3DTSS_COLORARG2", "D3DTSS_ALPHAARG1",
                                             "D3DTSS_ALPHAARG2", "D3DTSS_COLORARG0", "D3DTSS_ALPHAARG0"};
    const char* name = which == D3DTSS_COLORARG1   ? kNames[0]
                       : which == D3DTSS_COLORARG2 ? kNames[1]
                       : which == D3DTSS_ALPHAARG1 ? kNames[2]
                       : which == D3DTSS_ALPHAARG2 ? kNames[3]
                       : which == D3DTSS_COLORARG0 ? kNames[4]
                                                   : kNames[5];
    const DWORD a = tss(stage, which);
    const DWORD sel = a & D3DTA_SELECTMASK;
    if ((a & ~DWORD(D3DTA_SELECTMASK | D3DTA_COMPLEMENT | D3DTA_ALPHAREPLICATE)) != 0 || sel > D3DTA_CONSTANT)
        return fail("E4141", stage, name,
                    "unknown texture argument " + hex(a) +
                        " (D3DTA_DIFFUSE..D3DTA_CONSTANT with D3DTA_COMPLEMENT / D3DTA_ALPHAREPLICATE)");
    switch (sel) {
        case D3DTA_DIFFUSE:
            out = reg(RegType::Input, 0);
            break;
        case D3DTA_CURRENT:
            out = current();
            break;  // stage 0 (nothing written yet): diffuse
        case D3DTA_TEXTURE:
            if (!texture(stage, name, out)) return false;
            break;
        case D3DTA_TFACTOR:
            out = constSrc(constant(colorFloats(m_state.renderState(D3DRS_TEXTUREFACTOR))));
            break;
        case D3DTA_SPECULAR:
            out = reg(RegType::Input, 1);
            break;
        case D3DTA_TEMP:
            out = temp();
            break;  // unwritten TEMP reads 0 (DXVK, Wine)
        default:
            out = constSrc(constant(colorFloats(tss(stage, D3DTSS_CONSTANT))));
            break;
    }
    if (a & D3DTA_COMPLEMENT) out.mod = SrcMod::Comp;
    // The modifier applies after the selector, and 1 - x.a = (1 - x).a, so the order of the two
    // flags does not matter.
    if (a & D3DTA_ALPHAREPLICATE) out.swizzle = kSwizzleAlpha;
    if (m_constOverflow)
        return fail("E4147", stage, name, "more than 8 distinct constants (TFACTOR, per-stage CONSTANT, TEMP's 0)");
    return true;
}

void Lowering::emit(const char* mnemonic, const Dst& dst, std::initializer_list<Src> srcs, Instruction& out) const {
    out = Instruction{};
    out.info = opcode(mnemonic);
    out.dst = dst;
    size_t i = 0;
    for (const Src& s : srcs) out.src[i++] = s;
}

// One half of a stage (colour: dst.rgb, alpha: dst.a) as one instruction whose exact result is
// the D3DTEXTUREOP formula; _sat on dst keeps every stage in [0, 1] like the 8-bit combiners.
bool Lowering::lowerHalf(int stage, bool alpha, const Dst& dst, Instruction& out) {
    const DWORD op = tss(stage, alpha ? D3DTSS_ALPHAOP : D3DTSS_COLOROP);
    const auto A0 = alpha ? D3DTSS_ALPHAARG0 : D3DTSS_COLORARG0;
    const auto A1 = alpha ? D3DTSS_ALPHAARG1 : D3DTSS_COLORARG1;
    const auto A2 = alpha ? D3DTSS_ALPHAARG2 : D3DTSS_COLORARG2;
    Src a0, a1, a2;
    const bool uses0 = op == D3DTOP_MULTIPLYADD || op == D3DTOP_LERP;
    const bool uses2 = op != D3DTOP_SELECTARG1 && op != D3DTOP_PREMODULATE;
    const bool uses1 = op != D3DTOP_SELECTARG2;
    if (uses1 && !arg(stage, A1, a1)) return false;
    if (uses2 && !arg(stage, A2, a2)) return false;
    if (uses0 && !arg(stage, A0, a0)) return false;
    const char* opName = alpha ? "D3DTSS_ALPHAOP" : "D3DTSS_COLOROP";
    Dst d = dst;
    switch (op) {
        case D3DTOP_SELECTARG1:
        case D3DTOP_PREMODULATE:  // ARG1 now; the next stage first multiplies it by its texture
            emit("mov", d, {a1}, out);
            break;
        case D3DTOP_SELECTARG2:
            emit("mov", d, {a2}, out);
            break;
        case D3DTOP_MODULATE:
            emit("mul", d, {a1, a2}, out);
            break;
        case D3DTOP_MODULATE2X:
            d.shift = 1;
            emit("mul", d, {a1, a2}, out);
            break;
        case D3DTOP_MODULATE4X:
            d.shift = 2;
            emit("mul", d, {a1, a2}, out);
            break;
        case D3DTOP_ADD:
            emit("add", d, {a1, a2}, out);
            break;
        case D3DTOP_ADDSIGNED:
            emit("add", d, {a1, withMod(a2, biased(a2.mod))}, out);
            break;
        case D3DTOP_ADDSIGNED2X:
            d.shift = 1;
            emit("add", d, {a1, withMod(a2, biased(a2.mod))}, out);
            break;
        case D3DTOP_SUBTRACT:
            emit("sub", d, {a1, a2}, out);
            break;
        case D3DTOP_ADDSMOOTH:  // a1 + a2 - a1·a2 = (1 - a1)·a2 + a1
            emit("mad", d, {withMod(a1, invert(a1.mod)), a2, a1}, out);
            break;
        case D3DTOP_BLENDDIFFUSEALPHA:
            emit("lrp", d, {alphaOf(reg(RegType::Input, 0)), a1, a2}, out);
            break;
        case D3DTOP_BLENDTEXTUREALPHA: {
            Src t;
            if (!texture(stage, opName, t)) return false;
            emit("lrp", d, {alphaOf(t), a1, a2}, out);
            break;
        }
        case D3DTOP_BLENDFACTORALPHA: {
            Src f = constSrc(constant(colorFloats(m_state.renderState(D3DRS_TEXTUREFACTOR))));
            if (m_constOverflow) return fail("E4147", stage, opName, "more than 8 distinct constants");
            emit("lrp", d, {alphaOf(f), a1, a2}, out);
            break;
        }
        case D3DTOP_BLENDTEXTUREALPHAPM: {  // a1 + a2·(1 - texture.a)
            Src t;
            if (!texture(stage, opName, t)) return false;
            emit("mad", d, {a2, withMod(alphaOf(t), SrcMod::Comp), a1}, out);
            break;
        }
        case D3DTOP_BLENDCURRENTALPHA:
            emit("lrp", d, {alphaOf(current()), a1, a2}, out);
            break;
        case D3DTOP_MODULATEALPHA_ADDCOLOR:  // a1.rgb + a1.a·a2.rgb
            emit("mad", d, {alphaOf(a1), a2, a1}, out);
            break;
        case D3DTOP_MODULATECOLOR_ADDALPHA:  // a1.rgb·a2.rgb + a1.a
            emit("mad", d, {a1, a2, alphaOf(a1)}, out);
            break;
        case D3DTOP_MODULATEINVALPHA_ADDCOLOR:  // (1 - a1.a)·a2.rgb + a1.rgb
            emit("mad", d, {withMod(alphaOf(a1), invert(a1.mod)), a2, a1}, out);
            break;
        case D3DTOP_MODULATEINVCOLOR_ADDALPHA:  // (1 - a1.rgb)·a2.rgb + a1.a
            emit("mad", d, {withMod(a1, invert(a1.mod)), a2, alphaOf(a1)}, out);
            break;
        case D3DTOP_DOTPRODUCT3:  // Σ (2·a1 - 1)(2·a2 - 1) over rgb
            emit("dp3", d, {withMod(a1, signedMod(a1.mod)), withMod(a2, signedMod(a2.mod))}, out);
            break;
        case D3DTOP_MULTIPLYADD:
            emit("mad", d, {a1, a2, a0}, out);
            break;
        case D3DTOP_LERP:
            emit("lrp", d, {a0, a1, a2}, out);
            break;
        default:
            return fail("E4140", stage, opName, "texture operation " + std::to_string(op) + " cannot be lowered");
    }
    return true;
}

bool sameInstruction(const Instruction& a, const Instruction& b) {
    if (a.info != b.info || a.dst.type != b.dst.type || a.dst.index != b.dst.index || a.dst.shift != b.dst.shift ||
        a.dst.saturate != b.dst.saturate)
        return false;
    for (int i = 0; i < a.info->numSrc; ++i) {
        const Src &x = a.src[size_t(i)], &y = b.src[size_t(i)];
        if (x.type != y.type || x.index != y.index || x.swizzle != y.swizzle || x.mod != y.mod) return false;
    }
    return true;
}

// A BUMPENVMAP(LUMINANCE) stage: it samples its own texture (du, dv[, l]) and perturbs the next
// stage's lookup; it outputs nothing, so CURRENT after it is still the value before it
// (D3DTA_CURRENT page), and its ALPHAOP and RESULTARG are not used.
bool Lowering::lowerBump(int i, int active) {
    if (i + 1 >= active)
        return fail("E4143", i, "D3DTSS_COLOROP",
                    "D3DTOP_BUMPENVMAP needs an enabled next stage whose texture it perturbs");
    Src t;
    if (!texture(i, "D3DTSS_COLOROP", t)) return false;
    if (i + 1 >= kMaxFixedFunctionTextures)
        return fail("E4142", i, "D3DTSS_COLOROP",
                    "D3DTOP_BUMPENVMAP looks up stage " + std::to_string(i + 1) + "'s texture, but only stages 0.." +
                        std::to_string(kMaxFixedFunctionTextures - 1) + " can sample");
    m_sampled |= 1u << (i + 1);
    m_bumpInto[size_t(i + 1)] = true;
    return true;
}

// A blending stage: its colour and alpha halves as a co-issued pair into CURRENT or TEMP.
bool Lowering::lowerStage(int i) {
    const DWORD cop = tss(i, D3DTSS_COLOROP);
    const DWORD result = tss(i, D3DTSS_RESULTARG);
    if (result != D3DTA_CURRENT && result != D3DTA_TEMP)
        return fail("E4146", i, "D3DTSS_RESULTARG",
                    "result argument " + hex(result) + " is neither D3DTA_CURRENT nor D3DTA_TEMP");
    const bool toTemp = result == D3DTA_TEMP;
    Dst dst;
    dst.type = RegType::Temp;
    dst.index = toTemp ? 1 : 0;
    dst.saturate = true;
    bool& written = toTemp ? m_r1Written : m_r0Written;

    m_premodReg = dst.index;
    m_premodMask = cop == D3DTOP_PREMODULATE ? ps11::kMaskRGB : 0;
    m_premodAlpha = false;
    if (cop == D3DTOP_DOTPRODUCT3) {
        // Replicated to all four channels, alpha included: the stage's ALPHAOP is not used.
        Instruction ins;
        dst.mask = ps11::kMaskAll;
        if (!lowerHalf(i, false, dst, ins)) return false;
        m_arith.push_back(ins);
        written = true;
        return true;
    }
    const DWORD aop = tss(i, D3DTSS_ALPHAOP);
    if (!checkOp(i, D3DTSS_ALPHAOP, true)) return false;
    Instruction color, alpha;
    Dst cd = dst, ad = dst;
    cd.mask = ps11::kMaskRGB;
    ad.mask = ps11::kMaskA;
    if (!lowerHalf(i, false, cd, color)) return false;
    if (aop == D3DTOP_PREMODULATE) {
        m_premodMask = uint8_t(m_premodMask | ps11::kMaskA);
        m_premodAlpha = true;
    }
    if (aop != D3DTOP_DISABLE) {
        if (!lowerHalf(i, true, ad, alpha)) return false;
    } else if (!written) {
        // ALPHAOP DISABLE keeps the destination's alpha (DXVK; the docs call it undefined). An
        // unwritten register holds its initial value (diffuse, or TEMP's 0) only virtually: copy it.
        emit("mov", ad, {toTemp ? temp() : current()}, alpha);
    }
    if (alpha.info && sameInstruction(color, alpha)) {
        color.dst.mask = ps11::kMaskAll;  // identical halves: one instruction
        m_arith.push_back(color);
    } else {
        m_arith.push_back(color);
        if (alpha.info) {
            alpha.coissue = true;
            m_arith.push_back(alpha);
        }
    }
    written = true;
    return true;
}

// PREMODULATE in stage i - 1 ("modulate with next texture before use", d3d8types.h): before
// stage i runs, the channels it wrote are multiplied by stage i's texture. The select was exact,
// so the product rounds once.
bool Lowering::lowerPremodulate(int i) {
    const uint8_t mask = m_premodMask;
    m_premodMask = 0;
    if (!mask) return true;
    if (i >= kMaxFixedFunctionTextures)
        return fail("E4142", i - 1, m_premodAlpha && mask == ps11::kMaskA ? "D3DTSS_ALPHAOP" : "D3DTSS_COLOROP",
                    "D3DTOP_PREMODULATE modulates with stage " + std::to_string(i) + "'s texture, but only stages 0.." +
                        std::to_string(kMaxFixedFunctionTextures - 1) + " can sample");
    m_sampled |= 1u << i;
    Dst d;
    d.index = m_premodReg;
    d.mask = mask;
    d.saturate = true;
    Instruction mul;
    emit("mul", d, {reg(RegType::Temp, m_premodReg), reg(RegType::Texture, i)}, mul);
    m_arith.push_back(mul);
    return true;
}

// The pixel is CURRENT, plus the specular rgb with D3DRS_SPECULARENABLE (alpha unchanged).
void Lowering::lowerOutput() {
    Dst r0;
    r0.saturate = true;
    if (m_state.renderState(D3DRS_SPECULARENABLE) != 0) {
        Instruction add;
        r0.mask = ps11::kMaskRGB;
        emit("add", r0, {current(), reg(RegType::Input, 1)}, add);
        m_arith.push_back(add);
        if (!m_r0Written) {
            Instruction mov;
            r0.mask = ps11::kMaskA;
            emit("mov", r0, {reg(RegType::Input, 0)}, mov);
            mov.coissue = true;
            m_arith.push_back(mov);
        }
    } else if (!m_r0Written) {
        Instruction mov;
        emit("mov", r0, {reg(RegType::Input, 0)}, mov);  // no stage wrote CURRENT: the diffuse colour
        m_arith.push_back(mov);
    }
}

// defs, then the texture instructions in stage order, then the blending; and the executor
// stage states (the bump data of a BUMPENVMAP stage moves to the stage its texbem samples).
void Lowering::assemble(LoweredStages& out) const {
    ps11::Program& prog = out.program;
    prog.version = {1, 1};
    for (size_t c = 0; c < m_consts.size(); ++c) {
        Instruction def;
        def.info = opcode("def");
        def.dst.type = RegType::Const;
        def.dst.index = uint8_t(c);
        for (int k = 0; k < 4; ++k) def.defBits[size_t(k)] = floatBits(m_consts[c][size_t(k)]);
        prog.instructions.push_back(def);
    }
    for (int i = 0; i < kMaxStages; ++i) {
        ps11::StageState& es = out.executorStages[size_t(i)];
        es.transformFlags = tss(i, D3DTSS_TEXTURETRANSFORMFLAGS);
        const int from = m_bumpInto[size_t(i)] ? i - 1 : i;
        es.bumpMat = {
            m_state.stageStateFloat(from, D3DTSS_BUMPENVMAT00), m_state.stageStateFloat(from, D3DTSS_BUMPENVMAT01),
            m_state.stageStateFloat(from, D3DTSS_BUMPENVMAT10), m_state.stageStateFloat(from, D3DTSS_BUMPENVMAT11)};
        es.lumScale = m_state.stageStateFloat(from, D3DTSS_BUMPENVLSCALE);
        es.lumOffset = m_state.stageStateFloat(from, D3DTSS_BUMPENVLOFFSET);
        es.clampLuminance = true;  // BUMPENVMAPLUMINANCE clamps its factor (ps11::StageState)
        if (!((m_sampled >> i) & 1)) continue;
        Instruction tex;
        Dst t;
        t.type = RegType::Texture;
        t.index = uint8_t(i);
        if (m_bumpInto[size_t(i)]) {
            const bool lum = tss(i - 1, D3DTSS_COLOROP) == D3DTOP_BUMPENVMAPLUMINANCE;
            emit(lum ? "texbeml" : "texbem", t, {reg(RegType::Texture, i - 1)}, tex);
        } else {
            emit("tex", t, {}, tex);
        }
        prog.instructions.push_back(tex);
    }
    prog.instructions.insert(prog.instructions.end(), m_arith.begin(), m_arith.end());
    out.sampledStages = m_sampled;
}

std::optional<LoweredStages> Lowering::run() {
    LoweredStages out;
    int active = 0;
    for (; active < kMaxStages; ++active) {
        const DWORD cop = tss(active, D3DTSS_COLOROP);
        if (cop == D3DTOP_DISABLE) break;  // disables this stage and every later one, alpha included
        if (!checkOp(active, D3DTSS_COLOROP, false)) return std::nullopt;
    }
    out.activeStages = active;
    for (int i = 0; i < active; ++i) {
        if (!lowerPremodulate(i)) return std::nullopt;
        const bool ok = isBump(tss(i, D3DTSS_COLOROP)) ? lowerBump(i, active) : lowerStage(i);
        if (!ok) return std::nullopt;
    }
    lowerOutput();
    assemble(out);
    return out;
}

}  // namespace

std::optional<LoweredStages> lowerFixedFunction(const DeviceState& state, CallError& error) {
    error = CallError{};
    Lowering lowering(state, error);
    return lowering.run();
}

}  // namespace emu
