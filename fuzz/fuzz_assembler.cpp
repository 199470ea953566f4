// libFuzzer target for the assembler: arbitrary bytes as shader text through the
// preprocessor, parser, validator and encoder; the encoded tokens must decode again.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "ps11/assembler.h"
#include "ps11/decoder.h"
#include "ps11/encoder.h"
#include "ps11/validator.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string text(reinterpret_cast<const char*>(data), size);
    ps11::Diagnostics diags;
    ps11::AssembleOptions options;
    // Includes resolve only to an in-memory file, never to the real filesystem.
    options.preprocess.readFile = [](const std::string& path) -> std::optional<std::string> {
        if (path.find("inc.h") != std::string::npos) return std::string("#define INC 1\nmov r0, v0\n");
        return std::nullopt;
    };
    std::optional<ps11::Program> prog = ps11::parseAssembly(text, "fuzz.psh", options, diags);
    if (!prog) return 0;
    ps11::ShaderStats stats;
    ps11::validate(*prog, diags, &stats);
    // The assembler refuses every register the version lacks (P1114), so the validator's range
    // check (P2030) never fires on assembled text.
    if (diags.has("P2030")) std::abort();
    (void)ps11::statsToJson(stats);
    std::vector<uint32_t> tokens = ps11::encode(*prog);
    if (diags.hasErrors()) return 0;
    ps11::Diagnostics d2;
    // Every valid program must encode into a stream the decoder reads back.
    if (!ps11::decode(tokens, 0, d2)) std::abort();
    return 0;
}
