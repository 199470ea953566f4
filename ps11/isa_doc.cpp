// Docs generator: renders the opcode table as the markdown table in docs/isa.md. A unit
// test keeps the committed page equal to this output.
#include "ps11/isa_doc.h"

#include "ps11/opcodes.h"

#include <cstdio>

namespace ps11 {
namespace {

std::string versionList(uint8_t bits) {
    if (!bits) return "none";
    std::string out;
    for (int minor = 1; minor <= 4; ++minor) {
        if (!(bits & versionBit(minor))) continue;
        if (!out.empty()) out += ", ";
        out += "1_" + std::to_string(minor);
    }
    return out;
}

const char* className(OpClass c) {
    switch (c) {
        case OpClass::Arith: return "arithmetic";
        case OpClass::Texture: return "texture";
        case OpClass::Setup: return "setup";
    }
    return "?";
}

// ".rgb" for a component mask (rgba order), "write mask" for kReadsWriteMask.
std::string readSet(uint8_t m) {
    if (m == kReadsWriteMask) return "write mask";
    std::string out = ".";
    for (int c = 0; c < 4; ++c)
        if (m & (1u << c)) out += "rgba"[c];
    return out;
}

// Components read: one set when every source reads the same, else per source; the destination's
// register for texkill/texdepth.
std::string readsColumn(const OpcodeInfo& row) {
    std::string out;
    bool same = true;
    for (int s = 1; s < row.numSrc; ++s) same = same && row.srcReads[size_t(s)] == row.srcReads[0];
    if (row.numSrc > 0 && same) out = readSet(row.srcReads[0]);
    for (int s = 0; s < row.numSrc && !same; ++s)
        out += (s ? ", src" : "src") + std::to_string(s) + " " + readSet(row.srcReads[size_t(s)]);
    if (row.dstReads) out += (out.empty() ? "dst " : ", dst ") + readSet(row.dstReads);
    return out.empty() ? "–" : out;
}

}  // namespace

std::string isaMarkdownTable() {
    std::string out =
        "| mnemonic | opcode | class | versions | operands | tex slots | arith slots 1_1–1_3 | arith slots 1_4 | "
        "co-issue | max per shader | components read | writes dst | meaning |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const OpcodeInfo& row : opcodeTable()) {
        char opcode[16];
        std::snprintf(opcode, sizeof opcode, "0x%02X", unsigned(row.opcode));
        std::string operands = row.hasDst ? "dst" : "";
        if (row.opcode == Opcode::Def) operands += ", 4 floats";
        for (int i = 0; i < row.numSrc; ++i) operands += (operands.empty() ? "src" : ", src") + std::to_string(i);
        if (operands.empty()) operands = "–";
        out += "| `" + std::string(row.mnemonic) + "` | " + opcode + " | " + className(row.cls) + " | " +
               versionList(row.versions) + " | " + operands + " | " + std::to_string(row.texSlots) + " | " +
               std::to_string(row.arithSlots13) + " | " + std::to_string(row.arithSlots14) + " | " +
               (row.coissuable ? "yes" : "no") + " | " +
               (row.maxPerShader ? std::to_string(row.maxPerShader) : std::string("–")) + " | " +
               readsColumn(row) + " | " + (!row.hasDst ? "–" : row.writesDst ? "yes" : "no") + " | " +
               std::string(row.summary) + " |\n";
    }
    return out;
}

}  // namespace ps11
