// The disassembler: IR → canonical assembly text (ps_1_x header, one instruction per
// line, lower case, co-issued members prefixed with '+').
#pragma once

#include <string>

#include "ps11/ir.h"

namespace ps11 {

std::string disassemble(const Program& program);

// One instruction in canonical form, without a newline (used by diagnostics and stats).
std::string formatInstruction(const Instruction& inst, Version version);

}  // namespace ps11
