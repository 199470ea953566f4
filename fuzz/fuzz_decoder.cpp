// libFuzzer target for the decoder stage: the input bytes are read as a little-endian token
// stream (tokensFromBinary → decode) and as hex text (tokensFromHex → decode); whatever
// decodes is disassembled. Seeds and regression inputs live in fuzz/corpus_decoder/.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ps11/decoder.h"
#include "ps11/disassembler.h"

namespace {

void decodeAndPrint(const std::vector<uint32_t>& tokens, ps11::Diagnostics& diags) {
    const auto program = ps11::decode(tokens, 0, diags);
    if (!program) return;
    const std::string text = ps11::disassemble(*program);
    // The printed text never contains control characters other than newlines.
    for (char c : text)
        if (static_cast<unsigned char>(c) < 0x20 && c != '\n') __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    ps11::Diagnostics diags;
    if (const auto tokens = ps11::tokensFromBinary(bytes, 0, diags)) decodeAndPrint(*tokens, diags);
    if (const auto tokens = ps11::tokensFromHex(bytes, 0, diags)) decodeAndPrint(*tokens, diags);
    // Formatting every diagnostic exercises the message paths too.
    (void)diags.formatAll();
    return 0;
}
