// The decoder: D3D9 token stream → IR. Malformed streams give P3xxx diagnostics naming
// the token index and its hex value.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "ps11/diagnostics.h"
#include "ps11/ir.h"

namespace ps11 {

// Decodes tokens; fileId names the input in diags. Each instruction's loc.tokenIndex is
// the index of its instruction token. Returns nullopt on a malformed stream.
std::optional<Program> decode(std::span<const uint32_t> tokens, uint32_t fileId, Diagnostics& diags);

// Reads a little-endian binary blob into tokens (error P3001 if its size is not a
// multiple of 4).
std::optional<std::vector<uint32_t>> tokensFromBinary(std::string_view bytes, uint32_t fileId, Diagnostics& diags);

// Reads hex text ("0xffff0101 0x00000042 …", commas/whitespace/newlines allowed, 0x
// optional) into tokens; bad words are reported with line and column.
std::optional<std::vector<uint32_t>> tokensFromHex(std::string_view text, uint32_t fileId, Diagnostics& diags);

}  // namespace ps11
