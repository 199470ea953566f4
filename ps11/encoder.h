// The encoder: IR → D3D9 token stream, word for word as Microsoft's assembler emits it.
#pragma once

#include <cstdint>
#include <vector>

#include "ps11/ir.h"

namespace ps11 {

std::vector<uint32_t> encode(const Program& program);

}  // namespace ps11
