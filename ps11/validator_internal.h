// Internal declarations shared by the validator's source files (validator.cpp: driver, ordering,
// slots and data flow; validator_rules.cpp: operand and sequencing rules; validator_stats.cpp: reports).
// Not part of the public API.
#pragma once

#include <array>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "ps11/token_format.h"
#include "ps11/validator.h"

namespace ps11::validator_detail {

// Diagnostic codes (docs/diagnostics.md).
inline constexpr const char* kBadVersion = "P2001";
inline constexpr const char* kNotInVersion = "P2002";
inline constexpr const char* kReservedOpcode = "P2003";
inline constexpr const char* kTexSlots = "P2010";
inline constexpr const char* kArithSlots = "P2011";
inline constexpr const char* kPerShaderCount = "P2012";
inline constexpr const char* kDefAfterInstruction = "P2020";
inline constexpr const char* kTexAfterArith = "P2021";
inline constexpr const char* kPhaseOrder = "P2022";
inline constexpr const char* kSecondPhase = "P2023";
inline constexpr const char* kRegRange = "P2030";
inline constexpr const char* kDstType = "P2031";
inline constexpr const char* kSrcType = "P2032";
inline constexpr const char* kTexRegIn14 = "P2033";
inline constexpr const char* kInputInPhase1 = "P2034";
inline constexpr const char* kDependentRead = "P2035";
inline constexpr const char* kReadPorts = "P2040";
inline constexpr const char* kPairReadPorts = "P2041";
inline constexpr const char* kArithMask = "P2050";
inline constexpr const char* kDp3Mask = "P2051";
inline constexpr const char* kTexMask13 = "P2052";
inline constexpr const char* kTexMask14 = "P2053";
inline constexpr const char* kDefOperand = "P2054";
inline constexpr const char* kSelector = "P2060";
inline constexpr const char* kBlueSelector = "P2061";
inline constexpr const char* kTexSelector = "P2062";
inline constexpr const char* kTexSourceForm = "P2063";
inline constexpr const char* kTooManyDz = "P2064";
inline constexpr const char* kMixedTexSelector = "P2065";
inline constexpr const char* kSrcModVersion = "P2070";
inline constexpr const char* kConstModifier = "P2071";
inline constexpr const char* kConstModifierWarn = "P2072";
inline constexpr const char* kTexSrcModifier = "P2073";
inline constexpr const char* kShiftVersion = "P2074";
inline constexpr const char* kTexInstModifier = "P2075";
inline constexpr const char* kCoissuePlacement = "P2080";
inline constexpr const char* kNotCoissuable = "P2081";
inline constexpr const char* kCoissuePipes = "P2082";
inline constexpr const char* kCoissueDp3 = "P2083";
inline constexpr const char* kUndefinedRead = "P2090";
inline constexpr const char* kR0NotWritten = "P2091";
inline constexpr const char* kR0AlphaPhase = "P2092";
inline constexpr const char* kR0Partial = "P2093";
inline constexpr const char* kPadSequence = "P2100";
inline constexpr const char* kPadRegister = "P2101";
inline constexpr const char* kPadSource = "P2102";
inline constexpr const char* kMatrixWithoutPad = "P2103";
inline constexpr const char* kBemSourceReuse = "P2104";
inline constexpr const char* kTexDstTwice = "P2105";
inline constexpr const char* kUnusableRegister = "P2106";
inline constexpr const char* kTexSrcIndex = "P2107";
inline constexpr const char* kCndSrc0 = "P2108";
inline constexpr const char* kCmpDstIsSrc = "P2109";
inline constexpr const char* kBemPhase = "P2110";
inline constexpr const char* kTexDepthReg = "P2111";
inline constexpr const char* kTexDepthPhase = "P2112";

constexpr int kRegSlots = 8;        // array bound for every register file (largest file is c0-c7)
static_assert(registerCount(RegType::Const, 4) <= kRegSlots && registerCount(RegType::Temp, 4) <= kRegSlots &&
              registerCount(RegType::Texture, 4) <= kRegSlots);
constexpr uint8_t kSwXyz = 0xA4;    // .xyz = xyzz (spec §3.4)
constexpr uint8_t kSwXyw = 0xF4;    // .xyw = xyww
constexpr uint8_t kSwAlpha = 0xFF;  // .a replicate
constexpr uint8_t kSwBlue = 0xAA;   // .b replicate

inline std::string regName(RegType t, int index) { return regPrefix(t) + std::to_string(index); }

inline std::string maskName(uint8_t mask) {
    std::string out = ".";
    for (int c = 0; c < 4; ++c)
        if (mask & (1u << c)) out += componentLetter(c);
    return mask == 0 ? std::string("(empty mask)") : out;
}

inline std::string compList(uint8_t comps) {
    std::string out;
    for (int c = 0; c < 4; ++c)
        if (comps & (1u << c)) out += componentLetter(c);
    return out;
}

inline std::string swizzleName(uint8_t sw) {
    if (sw == tok::kIdentitySwizzle) return "(none)";
    for (int c = 0; c < 4; ++c)
        if (sw == replicateSwizzle(c)) return std::string(".") + componentLetter(c);
    std::string out = ".";
    for (int c = 0; c < 4; ++c) out += "xyzw"[swizzleComponent(sw, c)];
    return out;
}

inline std::string srcModName(SrcMod m) {
    switch (m) {
        case SrcMod::None:
            return "none";
        case SrcMod::Neg:
            return "'-' (negate)";
        case SrcMod::Bias:
            return "_bias";
        case SrcMod::BiasNeg:
            return "-…_bias";
        case SrcMod::Sign:
            return "_bx2";
        case SrcMod::SignNeg:
            return "-…_bx2";
        case SrcMod::Comp:
            return "'1-' (invert)";
        case SrcMod::X2:
            return "_x2";
        case SrcMod::X2Neg:
            return "-…_x2";
        case SrcMod::Dz:
            return "_dz";
        case SrcMod::Dw:
            return "_dw";
    }
    return "?";
}

inline std::string shiftName(int shift) {
    switch (shift) {
        case 1:
            return "_x2";
        case 2:
            return "_x4";
        case 3:
            return "_x8";
        case -1:
            return "_d2";
        case -2:
            return "_d4";
        case -3:
            return "_d8";
        default:
            return "shift " + std::to_string(shift);
    }
}

inline std::string versionName(int minor) { return "ps_1_" + std::to_string(minor); }

inline std::string versionList(uint8_t bits) {
    std::string out;
    for (int minor = 1; minor <= 4; ++minor) {
        if (!(bits & versionBit(minor))) continue;
        if (!out.empty()) out += ", ";
        out += versionName(minor);
    }
    return out;
}

inline std::string lineRef(const SourceLoc& loc) {
    if (loc.line > 0) return "line " + std::to_string(loc.line);
    if (loc.tokenIndex >= 0) return "token " + std::to_string(loc.tokenIndex);
    return "an earlier instruction";
}

inline bool isTexture(const Instruction& inst) { return inst.info->cls == OpClass::Texture; }
inline bool isArith(const Instruction& inst) { return inst.info->cls == OpClass::Arith; }
inline bool isNop(const Instruction& inst) { return inst.opcode() == Opcode::Nop; }

// texm3x2 / texm3x3 rows that end a pad sequence (spec §2.3 sequencing rules).
inline bool endsM3x2(Opcode op) { return op == Opcode::TexM3x2Tex || op == Opcode::TexM3x2Depth; }
inline bool endsM3x3(Opcode op) {
    return op == Opcode::TexM3x3Tex || op == Opcode::TexM3x3 || op == Opcode::TexM3x3Spec || op == Opcode::TexM3x3VSpec;
}

enum class Pipe { Color, Alpha, Both, None };

// The pipe a write mask routes an arithmetic instruction to (spec §3.5).
inline Pipe pipeOf(uint8_t mask) {
    if (mask == kMaskA) return Pipe::Alpha;
    if (mask != 0 && (mask & kMaskA) == 0) return Pipe::Color;
    if (mask == 0) return Pipe::None;
    return Pipe::Both;
}

// Per-version limits of the validator (the register counts themselves are registerCount(), ir.h).
struct VersionLimits {
    std::array<int, 4> ports;  // read ports per instruction by RegType: r, v, c, t (spec §4.3)
    int texSlots;
    int arithSlots;
};

inline VersionLimits limitsFor(int minor) {
    if (minor == 4) return {{3, 2, 2, 1}, 6, 8};
    if (minor == 1) return {{2, 2, 2, 2}, 4, 8};
    return {{2, 2, 2, 3}, 4, 8};
}

class Validator {
public:
    Validator(const Program& program, Diagnostics& diags, const ValidateOptions& options, ShaderStats& stats)
        : m_prog(program), m_diags(diags), m_opts(options), m_stats(stats) {}

    bool run();

private:
    // One component of a tracked register: defined or not, and why not (for the message).
    struct Component {
        bool defined = false;
        std::string why;
    };

    void error(const char* code, const SourceLoc& loc, std::string message) {
        m_diags.error(code, loc, std::move(message));
    }
    const Instruction& inst(size_t i) const { return m_prog.instructions[i]; }
    bool legal(size_t i) const { return m_legal[i]; }
    bool is14() const { return m_minor == 4; }
    std::string vname() const { return versionName(m_minor); }
    std::string mn(const Instruction& in) const { return std::string(in.info->mnemonic); }
    bool inRange(RegType t, int index) const {
        return size_t(t) < 4 && index >= 0 && index < registerCount(t, m_minor);
    }
    int arithCost(const Instruction& in) const { return is14() ? in.info->arithSlots14 : in.info->arithSlots13; }
    // The instruction before i starts a co-issued pair with i.
    bool pairsWithPrevious(size_t i) const {
        return inst(i).coissue && i > 0 && legal(i - 1) && isArith(inst(i - 1)) && !inst(i - 1).coissue;
    }

    bool checkVersion();
    void computePhases();
    bool checkLegality(size_t i);
    void checkOrder(size_t i);
    void checkSlots(size_t i, InstructionStats& row);
    void checkRegisters(size_t i);
    void checkMasks(size_t i);
    void checkSources(size_t i);
    void checkInstructionModifiers(size_t i);
    void checkCoissue(size_t i);
    void checkReadPorts(size_t i);
    void checkSpecial(size_t i);
    void checkTexSequences();
    void checkTexRegisters(size_t i);
    void dataflowReads(size_t i);
    void dataflowWrites(size_t i);
    void readAccess(const Instruction& in, RegType type, int index, uint8_t comps, const SourceLoc& loc);
    void writeAccess(RegType type, int index, uint8_t comps, int phase);
    void undefine(RegType type, int index, uint8_t comps, const std::string& why);
    void finish();

    const Program& m_prog;
    Diagnostics& m_diags;
    const ValidateOptions& m_opts;
    ShaderStats& m_stats;
    int m_minor = 1;
    VersionLimits m_limits{};
    std::vector<bool> m_legal;
    std::vector<int> m_phaseOf;    // per instruction: 1, 2 (1_4) or 0
    long m_phaseInstruction = -1;  // index of the (first) phase instruction
    // Ordering state.
    bool m_seenNonDef = false;
    bool m_seenArith = false;  // in the current phase (1_4) or the shader
    SourceLoc m_firstArithLoc;
    // Slot counters, [0] phase 1 / [1] phase 2 (1_1-1_3 use [1]).
    std::array<int, 2> m_tex{}, m_arith{};
    std::array<bool, 2> m_texReported{}, m_arithReported{};
    std::array<int, 256> m_opCount{};
    // Data flow.
    std::array<std::array<std::array<Component, 4>, kRegSlots>, 4> m_regs{};
    std::array<std::array<std::string, kRegSlots>, 4> m_unusable{};  // non-empty: why the register is dead
    std::array<uint8_t, kRegSlots> m_writtenPhase2{};                // 1_4 r#: components written in phase 2
    std::array<std::string, kRegSlots> m_bemRead{};                  // t#: where texbem/texbeml read it
    std::array<SourceLoc, kRegSlots> m_texDst{};                     // 1_1-1_3 t#: first texture dst
    std::array<bool, kRegSlots> m_texDstSeen{};
    std::array<int, kRegSlots> m_tSelector{};  // 1_4 t#: 1 = .xyz, 2 = .xyw
    int m_dzCount = 0;
    bool m_r0Written = false;
    size_t m_pendingWrites = SIZE_MAX;  // first member of a pair whose writes wait for the second
    std::set<int> m_constRead, m_constDefined;
};

}  // namespace ps11::validator_detail
