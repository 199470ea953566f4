// The IR: a small flat program shared by the assembler, decoder, validator, disassembler
// and (later) the executor. Program = version + instructions; each instruction names its
// opcode row, a destination, up to three sources, the co-issue flag, a def payload and the
// source location of the instruction and of each operand.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ps11/diagnostics.h"
#include "ps11/opcodes.h"

namespace ps11 {

// Register files legal in ps 1.x (values are the D3DSPR_* token values).
enum class RegType : uint8_t {
    Temp = 0,     // r#
    Input = 1,    // v#
    Const = 2,    // c#
    Texture = 3,  // t#
};

// Source modifiers (D3DSPSM_* token values). x = the value after the selector.
enum class SrcMod : uint8_t {
    None = 0,     // x
    Neg = 1,      // -x
    Bias = 2,     // x - 0.5
    BiasNeg = 3,  // -(x - 0.5)
    Sign = 4,     // 2x - 1           (_bx2)
    SignNeg = 5,  // -(2x - 1)
    Comp = 6,     // 1 - x
    X2 = 7,       // 2x               (1_4)
    X2Neg = 8,    // -2x              (1_4)
    Dz = 9,       // x/z, y/z         (1_4 texld/texcrd)
    Dw = 10,      // x/w, y/w         (1_4 texld/texcrd)
};

// Write mask bits.
enum : uint8_t { kMaskR = 1, kMaskG = 2, kMaskB = 4, kMaskA = 8, kMaskRGB = 7, kMaskAll = 15 };

struct Dst {
    RegType type = RegType::Temp;
    uint8_t index = 0;
    uint8_t mask = kMaskAll;  // bit 0 = r … bit 3 = a
    bool saturate = false;    // _sat
    int8_t shift = 0;         // 1 = _x2, 2 = _x4, 3 = _x8, -1 = _d2, -2 = _d4, -3 = _d8
    SourceLoc loc;
};

struct Src {
    RegType type = RegType::Temp;
    uint8_t index = 0;
    uint8_t swizzle = 0xE4;  // 2 bits per output channel, x in the low bits
    SrcMod mod = SrcMod::None;
    SourceLoc loc;
};

struct Instruction {
    const OpcodeInfo* info = nullptr;  // never null in a well-formed program
    bool coissue = false;              // second member of a co-issued pair ('+')
    Dst dst;                           // valid when info->hasDst
    std::array<Src, 3> src{};          // info->numSrc of them are valid
    std::array<uint32_t, 4> defBits{}; // def: IEEE-754 bit patterns of the four floats
    SourceLoc loc;                     // the mnemonic (or '+')

    Opcode opcode() const { return info->opcode; }
    float defValue(int i) const;
};

struct Version {
    int major = 1;
    int minor = 1;
    bool operator==(const Version&) const = default;
};

struct Program {
    Version version;
    SourceLoc versionLoc;
    std::vector<Instruction> instructions;
};

// Component letters for masks and swizzles.
char componentLetter(int c);  // 0..3 -> 'r','g','b','a'
// Swizzle component of output channel c (0..3).
constexpr int swizzleComponent(uint8_t sw, int c) { return (sw >> (2 * c)) & 3; }
constexpr uint8_t replicateSwizzle(int c) { return uint8_t(c | (c << 2) | (c << 4) | (c << 6)); }

const char* regPrefix(RegType t);  // "r", "v", "c", "t"

// How many registers of a file the version has (ps1x-spec.md §1.1): c0-c7, v0-v1 in every
// version; r0-r1 and t0-t3 in 1_1-1_3, r0-r5 and t0-t5 in 1_4. The one statement of these
// counts: the assembler (P1114), the validator (P2030) and the executor read it.
constexpr int registerCount(RegType t, int minor) {
    switch (t) {
        case RegType::Temp:
            return minor == 4 ? 6 : 2;
        case RegType::Input:
            return 2;
        case RegType::Const:
            return 8;
        case RegType::Texture:
            return minor == 4 ? 6 : 4;
    }
    return 0;
}
// The registers of a file in the version, for messages: "r0-r1".
std::string registerRange(RegType t, int minor);

// Stages the program's texture instructions sample (bit per stage; samplesStage in
// ps11/opcodes.h), what the device must bind before it draws.
uint32_t sampledStages(const Program& program);

}  // namespace ps11
