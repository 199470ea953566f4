// The ISA table of docs/isa.md, generated from the opcode table (so the docs cannot drift
// from what the assembler, decoder and validator use).
#pragma once

#include <string>

namespace ps11 {

std::string isaMarkdownTable();

}  // namespace ps11
