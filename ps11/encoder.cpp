// Encoder: IR → D3D9 token stream, as Microsoft's assembler writes it for ps 1.x:
// version token, then per instruction its token (co-issue bit, no length field),
// destination and source parameter tokens (def: four raw float words), then the end token.
#include "ps11/encoder.h"

#include "ps11/token_format.h"

namespace ps11 {
namespace {

uint32_t encodeDst(const Dst& d) {
    uint32_t t = tok::kParamBit | tok::regTypeBits(unsigned(d.type)) | (uint32_t(d.index) & tok::kRegNumMask);
    t |= (uint32_t(d.mask) << tok::kWriteMaskShift) & tok::kWriteMaskMask;
    if (d.saturate) t |= tok::kResultModSaturate << tok::kResultModShift;
    t |= tok::shiftBits(d.shift);
    return t;
}

uint32_t encodeSrc(const Src& s) {
    uint32_t t = tok::kParamBit | tok::regTypeBits(unsigned(s.type)) | (uint32_t(s.index) & tok::kRegNumMask);
    t |= uint32_t(s.swizzle) << tok::kSwizzleShift;
    t |= (uint32_t(s.mod) << tok::kSrcModShift) & tok::kSrcModMask;
    return t;
}

}  // namespace

std::vector<uint32_t> encode(const Program& program) {
    std::vector<uint32_t> out;
    out.reserve(2 + program.instructions.size() * 4);
    out.push_back(tok::versionToken(unsigned(program.version.major), unsigned(program.version.minor)));
    for (const Instruction& inst : program.instructions) {
        if (inst.opcode() == Opcode::Phase) {
            out.push_back(tok::kPhaseToken);
            continue;
        }
        uint32_t it = uint32_t(inst.opcode()) & tok::kOpcodeMask;
        if (inst.coissue) it |= tok::kCoissueBit;
        out.push_back(it);
        if (inst.info->hasDst) out.push_back(encodeDst(inst.dst));
        if (inst.opcode() == Opcode::Def) {
            for (uint32_t bits : inst.defBits) out.push_back(bits);
        }
        for (int i = 0; i < inst.info->numSrc; ++i) out.push_back(encodeSrc(inst.src[size_t(i)]));
    }
    out.push_back(tok::kEndToken);
    return out;
}

}  // namespace ps11
