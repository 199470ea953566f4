// The disassembler stage: IR → canonical assembly text (docs/disassembly.md). The output
// parses back to the same tokens: masks in rgba order, swizzles as one letter (replicate)
// or the shortest letter string that repeats to the swizzle (.rgb = .rgbb), def values as the shortest decimal that reads back to the same bits,
// non-finite def values as bits(0x%08x).
#include "ps11/disassembler.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace ps11 {
namespace {

// Instruction modifier suffix for a shift scale: 1 = _x2 … 3 = _x8, -1 = _d2 … -3 = _d8.
std::string shiftSuffix(int shift) {
    if (shift == 0) return {};
    const int magnitude = shift < 0 ? -shift : shift;
    const unsigned factor = magnitude < 31 ? 1u << magnitude : 0u;
    return (shift > 0 ? "_x" : "_d") + std::to_string(factor);
}

std::string regName(RegType type, unsigned index) { return regPrefix(type) + std::to_string(index); }

std::string formatMask(uint8_t mask) {
    if ((mask & kMaskAll) == kMaskAll) return {};
    std::string out = ".";
    for (int c = 0; c < 4; ++c)
        if (mask & (1u << c)) out += componentLetter(c);
    return out;
}

std::string formatSwizzle(uint8_t sw) {
    if (sw == 0xE4) return {};
    for (int c = 0; c < 4; ++c)
        if (sw == replicateSwizzle(c)) return std::string(".") + componentLetter(c);
    // The shortest spelling: trailing letters equal to the one before them are implied,
    // since the assembler repeats a partial selector's last letter (.rgbb prints as .rgb).
    int len = 4;
    while (len > 1 && swizzleComponent(sw, len - 1) == swizzleComponent(sw, len - 2)) --len;
    std::string out = ".";
    for (int c = 0; c < len; ++c) out += componentLetter(swizzleComponent(sw, c));
    return out;
}

std::string formatDst(const Dst& dst) { return regName(dst.type, dst.index) + formatMask(dst.mask); }

// Source modifier spelling (ps1x-spec.md §3.1): prefix, then register, then suffix, then selector.
std::string formatSrc(const Src& src) {
    const char* prefix = "";
    const char* suffix = "";
    switch (src.mod) {
        case SrcMod::None: break;
        case SrcMod::Neg: prefix = "-"; break;
        case SrcMod::Bias: suffix = "_bias"; break;
        case SrcMod::BiasNeg: prefix = "-"; suffix = "_bias"; break;
        case SrcMod::Sign: suffix = "_bx2"; break;
        case SrcMod::SignNeg: prefix = "-"; suffix = "_bx2"; break;
        case SrcMod::Comp: prefix = "1-"; break;
        case SrcMod::X2: suffix = "_x2"; break;
        case SrcMod::X2Neg: prefix = "-"; suffix = "_x2"; break;
        case SrcMod::Dz: suffix = "_dz"; break;
        case SrcMod::Dw: suffix = "_dw"; break;
    }
    return prefix + regName(src.type, src.index) + suffix + formatSwizzle(src.swizzle);
}

// Shortest decimal that parses back to the same float (std::to_chars); NaN and infinities have
// no decimal form, so they are written as their raw bits, which the assembler's def also reads.
std::string formatDefValue(uint32_t bits) {
    const float value = std::bit_cast<float>(bits);
    if (!std::isfinite(value)) {
        char buf[24];
        std::snprintf(buf, sizeof buf, "bits(0x%08x)", bits);
        return buf;
    }
    char buf[64];
    const auto result = std::to_chars(buf, buf + sizeof buf, value);
    return std::string(buf, result.ptr);
}

}  // namespace

std::string formatInstruction(const Instruction& inst, Version /*version*/) {
    // The row already names the version-specific mnemonic (tex/texld, texcoord/texcrd).
    if (inst.info == nullptr) return "<invalid>";
    const OpcodeInfo& info = *inst.info;
    std::string out;
    if (inst.coissue) out += '+';
    out += info.mnemonic;
    if (info.hasDst) {
        out += shiftSuffix(inst.dst.shift);
        if (inst.dst.saturate) out += "_sat";
    }
    std::string sep = " ";
    if (info.hasDst) {
        out += sep + formatDst(inst.dst);
        sep = ", ";
    }
    for (size_t s = 0; s < info.numSrc && s < inst.src.size(); ++s) {
        out += sep + formatSrc(inst.src[s]);
        sep = ", ";
    }
    if (info.opcode == Opcode::Def) {
        for (uint32_t bits : inst.defBits) {
            out += sep + formatDefValue(bits);
            sep = ", ";
        }
    }
    return out;
}

std::string disassemble(const Program& program) {
    std::string out = "ps_" + std::to_string(program.version.major) + "_" + std::to_string(program.version.minor) + "\n";
    for (const Instruction& inst : program.instructions) {
        out += formatInstruction(inst, program.version);
        out += '\n';
    }
    return out;
}

}  // namespace ps11
