// IR helpers shared by every stage.
#include "ps11/ir.h"

#include <bit>

namespace ps11 {

float Instruction::defValue(int i) const { return std::bit_cast<float>(defBits[size_t(i)]); }

char componentLetter(int c) { return "rgba"[c & 3]; }

const char* regPrefix(RegType t) {
    switch (t) {
        case RegType::Temp: return "r";
        case RegType::Input: return "v";
        case RegType::Const: return "c";
        case RegType::Texture: return "t";
    }
    return "?";
}

std::string registerRange(RegType t, int minor) {
    return regPrefix(t) + std::string("0-") + regPrefix(t) + std::to_string(registerCount(t, minor) - 1);
}

uint32_t sampledStages(const Program& program) {
    uint32_t stages = 0;
    for (const Instruction& ins : program.instructions)
        if (ins.info && ins.info->cls == OpClass::Texture && samplesStage(ins.opcode()))
            stages |= 1u << (ins.dst.index & 7);
    return stages;
}

}  // namespace ps11
