// The opcode table: one row per mnemonic (and per operand layout across versions).
// Lexer, parser, encoder, decoder, disassembler, validator, executor, the GLSL writer and docs
// all read this table; no other file lists opcode facts (components read, whether the
// destination is written included). Facts from ps1x-spec.md §2.1-2.4 and §4.1.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

namespace ps11 {

// Token opcode numbers (D3DSIO_*). texcoord/texcrd and tex/texld share a number.
enum class Opcode : uint16_t {
    Nop = 0x00,
    Mov = 0x01,
    Add = 0x02,
    Sub = 0x03,
    Mad = 0x04,
    Mul = 0x05,
    Dp3 = 0x08,
    Dp4 = 0x09,
    Lrp = 0x12,
    TexCoord = 0x40,  // texcoord (1_1-1_3) / texcrd (1_4)
    TexKill = 0x41,
    Tex = 0x42,  // tex (1_1-1_3) / texld (1_4)
    TexBem = 0x43,
    TexBemL = 0x44,
    TexReg2AR = 0x45,
    TexReg2GB = 0x46,
    TexM3x2Pad = 0x47,
    TexM3x2Tex = 0x48,
    TexM3x3Pad = 0x49,
    TexM3x3Tex = 0x4A,
    TexM3x3Diff = 0x4B,  // reserved, invalid in every version
    TexM3x3Spec = 0x4C,
    TexM3x3VSpec = 0x4D,
    Cnd = 0x50,
    Def = 0x51,
    TexReg2RGB = 0x52,
    TexDp3Tex = 0x53,
    TexM3x2Depth = 0x54,
    TexDp3 = 0x55,
    TexM3x3 = 0x56,
    TexDepth = 0x57,
    Cmp = 0x58,
    Bem = 0x59,
    Phase = 0xFFFD,
    Comment = 0xFFFE,
    End = 0xFFFF,
};

enum class OpClass : uint8_t {
    Arith,    // arithmetic: uses an arithmetic slot, may carry modifiers
    Texture,  // texture-address: uses a texture slot
    Setup,    // def, phase: no slot
};

// Version bits: 1_1 = bit 0 … 1_4 = bit 3 (minor version − 1).
enum VersionBits : uint8_t { kV11 = 1, kV12 = 2, kV13 = 4, kV14 = 8, kV11to13 = 7, kVAll = 15, kV12to13 = 6 };
constexpr uint8_t versionBit(int minor) { return minor >= 1 && minor <= 4 ? uint8_t(1u << (minor - 1)) : 0; }

// A source's read set (OpcodeInfo::srcReads): the channels of the result a source feeds, as a
// mask r = 1, g = 2, b = 4, a = 8 (a source's swizzle maps each channel to the component read),
// or kReadsWriteMask for a per-component instruction, whose sources feed exactly the channels
// its write mask enables.
constexpr uint8_t kReadsWriteMask = 0x10;

struct OpcodeInfo {
    std::string_view mnemonic;
    Opcode opcode;
    OpClass cls;
    uint8_t versions;      // VersionBits where the row is legal
    uint8_t tokenVersions; // VersionBits whose token layout this row describes (decoder)
    bool hasDst;           // a destination parameter token follows
    uint8_t numSrc;        // source parameter tokens after the destination
    uint8_t texSlots;      // texture slots used
    uint8_t arithSlots13;  // arithmetic slots used in 1_1-1_3
    uint8_t arithSlots14;  // arithmetic slots used in 1_4
    bool coissuable;       // may be a member of a co-issued pair
    uint8_t maxPerShader;  // 0 = unlimited (dp4: 4, cmp: 3 in 1_2/1_3; bem: 1)
    // Components each source reads (see kReadsWriteMask; unused entries 0; use componentsRead()).
    std::array<uint8_t, 3> srcReads;
    uint8_t dstReads;      // components of the register the destination token names that are read (1_4
                           // texkill .rgb, texdepth r5.rg); 0 for every other row
    bool writesDst;        // running it writes its destination register (false: nop, def, phase,
                           // texkill, the pads, texm3x2depth and texdepth)
    std::string_view summary;  // one line for docs and --help
};

// Components of source `src` that the row reads, as a mask of result channels: its fixed set
// (dp3 .rgb, dp4 .rgba, bem .rg, texture-address sources), or the channels of `writeMask` for a
// per-component instruction (mov add sub mul mad lrp cnd cmp); 0 for a source the row lacks.
// Channel c of a source reads its register component swizzle[c].
constexpr uint8_t componentsRead(const OpcodeInfo& row, int src, uint8_t writeMask) {
    if (src < 0 || src >= row.numSrc) return 0;
    const uint8_t r = row.srcReads[size_t(src)];
    return r == kReadsWriteMask ? uint8_t(writeMask & 0xF) : r;
}
// The union over the row's sources (what an op must fetch).
constexpr uint8_t componentsReadAny(const OpcodeInfo& row, uint8_t writeMask) {
    uint8_t m = 0;
    for (int s = 0; s < row.numSrc; ++s) m = uint8_t(m | componentsRead(row, s, writeMask));
    return m;
}

// All rows, in opcode order.
std::span<const OpcodeInfo> opcodeTable();

// Row for a mnemonic (case-insensitive) suited to the version's minor number, or the
// row for the mnemonic in any version when none fits; nullptr if the mnemonic is unknown.
const OpcodeInfo* findOpcode(std::string_view mnemonic, int minor);

// Row whose token layout applies to this opcode number in the version, or nullptr.
const OpcodeInfo* findOpcodeToken(uint32_t opcode, int minor);

// A texture instruction that samples the stage its destination names (tex/texld, texbem(l),
// texreg2*, texm3x2tex, texm3x3tex/spec/vspec, texdp3tex); the pads, texcoord/texcrd, texkill,
// texdp3, texm3x3 and the depth instructions compute without sampling.
bool samplesStage(Opcode op);
// texm3x2depth and texdepth replace the pixel's depth.
constexpr bool replacesDepth(Opcode op) { return op == Opcode::TexM3x2Depth || op == Opcode::TexDepth; }

}  // namespace ps11
