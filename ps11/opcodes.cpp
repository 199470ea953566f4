// The opcode table (ps1x-spec.md §2.1, slots per §4.1). Every other stage looks
// opcodes up here.
#include "ps11/opcodes.h"

#include <algorithm>
#include <array>
#include <cctype>

#include "ps11/ir.h"

namespace ps11 {
namespace {

using O = Opcode;
using C = OpClass;

// Read sets (srcReads, dstReads; ps1x-spec.md §2.1-2.4): W = the write mask's channels.
constexpr uint8_t W = kReadsWriteMask;
constexpr uint8_t RG = kMaskR | kMaskG, RGB = kMaskRGB, RGBA = kMaskAll;
constexpr uint8_t AR = kMaskA | kMaskR, GB = kMaskG | kMaskB;

// What the columns state, and where from:
// - srcReads: per-component instructions read the write mask's channels; dp3 reads .rgb and dp4
//   .rgba of both sources whatever the mask; bem reads .rg of both (its mask must be .rg); the
//   texture-address formulas of §2.3 read t(n).rg (texbem), .rgb (texbeml: .b is the luminance
//   input), .a/.r (texreg2ar), .g/.b (texreg2gb) and .rgb (texreg2rgb, the matrix rows, texdp3*);
//   texm3x3spec's src1 is the eye vector c#.rgb; texld and texcrd (1_4) use x, y, z of their source
//   (the .xyw selector maps the third channel to w).
// - dstReads: texkill tests x, y, z of what its destination token names (1_1-1_3: coordinate set
//   m, never the register, spec §7.9; 1_4: the r# or the t# coordinates); texdepth divides r5.r by
//   r5.g, ignoring b and a.
// - writesDst: texkill, the pads (they feed the next row of their matrix group), texm3x2depth
//   (writes depth; its t(m+1) is unusable afterwards) and texdepth write no register. texdepth:
//   "This instruction uses r5.r / r5.g in the depth buffer comparison test for this pixel ... After
//   executing this instruction, temporary register r5 is unavailable for additional use in the
//   shader" (texdepth---ps.md, [S5]; ps1x-spec.md §2.4) - it reads r5 and writes only depth, as
//   Wine's shader_glsl_texdepth does [S16]. (The 1_1-1_3 validator's list had left it writing r5.)

// clang-format off
constexpr std::array kTable = {
//  mnemonic        opcode          class       versions   tokenVers  dst  src tex a13 a14 coiss max  srcReads     dstReads writesDst summary
    OpcodeInfo{"nop",          O::Nop,          C::Arith,   kVAll,     kVAll,     false, 0, 0, 0, 0, false, 0, {},           0,   false, "no operation"},
    OpcodeInfo{"mov",          O::Mov,          C::Arith,   kVAll,     kVAll,     true, 1, 0, 1, 1, true,  0, {W},          0,   true,  "d = a"},
    OpcodeInfo{"add",          O::Add,          C::Arith,   kVAll,     kVAll,     true, 2, 0, 1, 1, true,  0, {W, W},       0,   true,  "d = a + b"},
    OpcodeInfo{"sub",          O::Sub,          C::Arith,   kVAll,     kVAll,     true, 2, 0, 1, 1, true,  0, {W, W},       0,   true,  "d = a - b"},
    OpcodeInfo{"mad",          O::Mad,          C::Arith,   kVAll,     kVAll,     true, 3, 0, 1, 1, true,  0, {W, W, W},    0,   true,  "d = a * b + c"},
    OpcodeInfo{"mul",          O::Mul,          C::Arith,   kVAll,     kVAll,     true, 2, 0, 1, 1, true,  0, {W, W},       0,   true,  "d = a * b"},
    OpcodeInfo{"dp3",          O::Dp3,          C::Arith,   kVAll,     kVAll,     true, 2, 0, 1, 1, true,  0, {RGB, RGB},   0,   true,  "d = a.rgb . b.rgb, replicated"},
    OpcodeInfo{"dp4",          O::Dp4,          C::Arith,   kV12 | kV13 | kV14, kVAll, true, 2, 0, 2, 1, false, 4, {RGBA, RGBA}, 0,   true,  "d = a . b (4 components), replicated"},
    OpcodeInfo{"lrp",          O::Lrp,          C::Arith,   kVAll,     kVAll,     true, 3, 0, 1, 1, true,  0, {W, W, W},    0,   true,  "d = f * a + (1 - f) * b"},
    OpcodeInfo{"texcoord",     O::TexCoord,     C::Texture, kV11to13,  kV11to13,  true, 0, 1, 0, 0, false, 0, {},           0,   true,  "t(m) = saturate(texcoord m), w = 1"},
    OpcodeInfo{"texcrd",       O::TexCoord,     C::Texture, kV14,      kV14,      true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "r(m) = texture coordinates of t(n), unclamped"},
    OpcodeInfo{"texkill",      O::TexKill,      C::Texture, kVAll,     kVAll,     true, 0, 1, 0, 0, false, 0, {},           RGB, false, "discard the pixel if any of x, y, z < 0"},
    OpcodeInfo{"tex",          O::Tex,          C::Texture, kV11to13,  kV11to13,  true, 0, 1, 0, 0, false, 0, {},           0,   true,  "t(m) = sample stage m at texcoord m"},
    OpcodeInfo{"texld",        O::Tex,          C::Texture, kV14,      kV14,      true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "r(m) = sample stage m at t(n) or r(n)"},
    OpcodeInfo{"texbem",       O::TexBem,       C::Texture, kV11to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RG},         0,   true,  "sample at texcoord m + bump matrix * t(n).rg"},
    OpcodeInfo{"texbeml",      O::TexBemL,      C::Texture, kV11to13,  kVAll,     true, 1, 1, 1, 1, false, 0, {RGB},        0,   true,  "texbem, then scale by luminance t(n).b"},
    OpcodeInfo{"texreg2ar",    O::TexReg2AR,    C::Texture, kV11to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {AR},         0,   true,  "sample at (t(n).a, t(n).r)"},
    OpcodeInfo{"texreg2gb",    O::TexReg2GB,    C::Texture, kV11to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {GB},         0,   true,  "sample at (t(n).g, t(n).b)"},
    OpcodeInfo{"texm3x2pad",   O::TexM3x2Pad,   C::Texture, kV11to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   false, "first row of a 3x2 matrix multiply"},
    OpcodeInfo{"texm3x2tex",   O::TexM3x2Tex,   C::Texture, kV11to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "second row of a 3x2 matrix multiply, then sample"},
    OpcodeInfo{"texm3x3pad",   O::TexM3x3Pad,   C::Texture, kV11to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   false, "first or second row of a 3x3 matrix multiply"},
    OpcodeInfo{"texm3x3tex",   O::TexM3x3Tex,   C::Texture, kV11to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "third row of a 3x3 matrix multiply, then sample"},
    OpcodeInfo{"texm3x3diff",  O::TexM3x3Diff,  C::Texture, 0,         kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "reserved; invalid in every version"},
    OpcodeInfo{"texm3x3spec",  O::TexM3x3Spec,  C::Texture, kV11to13,  kVAll,     true, 2, 1, 0, 0, false, 0, {RGB, RGB},   0,   true,  "3x3 multiply, reflect constant eye vector, sample"},
    OpcodeInfo{"texm3x3vspec", O::TexM3x3VSpec, C::Texture, kV11to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "3x3 multiply, reflect eye vector from q, sample"},
    OpcodeInfo{"cnd",          O::Cnd,          C::Arith,   kVAll,     kVAll,     true, 3, 0, 1, 1, true,  0, {W, W, W},    0,   true,  "d = (s0 > 0.5) ? a : b"},
    OpcodeInfo{"def",          O::Def,          C::Setup,   kVAll,     kVAll,     true, 0, 0, 0, 0, false, 0, {},           0,   false, "define a constant"},
    OpcodeInfo{"texreg2rgb",   O::TexReg2RGB,   C::Texture, kV12to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "sample at t(n).rgb"},
    OpcodeInfo{"texdp3tex",    O::TexDp3Tex,    C::Texture, kV12to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "sample at (texcoord m . t(n), 0, 0)"},
    OpcodeInfo{"texm3x2depth", O::TexM3x2Depth, C::Texture, kV13,      kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   false, "3x2 multiply, depth = z / w"},
    OpcodeInfo{"texdp3",       O::TexDp3,       C::Texture, kV12to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "t(m) = texcoord m . t(n), replicated"},
    OpcodeInfo{"texm3x3",      O::TexM3x3,      C::Texture, kV12to13,  kVAll,     true, 1, 1, 0, 0, false, 0, {RGB},        0,   true,  "3x3 multiply without sampling"},
    OpcodeInfo{"texdepth",     O::TexDepth,     C::Texture, kV14,      kVAll,     true, 0, 1, 0, 0, false, 0, {},           RG,  false, "depth = r5.r / r5.g"},
    OpcodeInfo{"cmp",          O::Cmp,          C::Arith,   kV12 | kV13 | kV14, kVAll, true, 3, 0, 2, 1, true, 3, {W, W, W},    0,   true,  "d = (s0 >= 0) ? a : b"},
    OpcodeInfo{"bem",          O::Bem,          C::Arith,   kV14,      kVAll,     true, 2, 0, 2, 2, false, 1, {RG, RG},     0,   true,  "d.rg = a.rg + bump matrix * b.rg"},
    OpcodeInfo{"phase",        O::Phase,        C::Setup,   kV14,      kVAll,     false, 0, 0, 0, 0, false, 0, {},           0,   false, "start of ps_1_4 phase 2"},
};
// clang-format on

bool iequal(std::string_view a, std::string_view b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
               return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
           });
}

}  // namespace

std::span<const OpcodeInfo> opcodeTable() { return kTable; }

const OpcodeInfo* findOpcode(std::string_view mnemonic, int minor) {
    const OpcodeInfo* any = nullptr;
    for (const OpcodeInfo& row : kTable) {
        if (!iequal(row.mnemonic, mnemonic)) continue;
        if (row.versions & versionBit(minor)) return &row;
        if (!any) any = &row;
    }
    return any;
}

bool samplesStage(Opcode op) {
    switch (op) {
        case Opcode::Tex:
        case Opcode::TexBem:
        case Opcode::TexBemL:
        case Opcode::TexReg2AR:
        case Opcode::TexReg2GB:
        case Opcode::TexReg2RGB:
        case Opcode::TexM3x2Tex:
        case Opcode::TexM3x3Tex:
        case Opcode::TexM3x3Spec:
        case Opcode::TexM3x3VSpec:
        case Opcode::TexDp3Tex:
            return true;
        default:
            return false;
    }
}

const OpcodeInfo* findOpcodeToken(uint32_t opcode, int minor) {
    for (const OpcodeInfo& row : kTable)
        if (uint32_t(row.opcode) == opcode && (row.tokenVersions & versionBit(minor))) return &row;
    return nullptr;
}

}  // namespace ps11
