// libFuzzer target for the .ps11test reader: arbitrary bytes as a test file. Besides "no
// crash, no sanitizer report", the result must be consistent: errors carry real line numbers,
// a file without errors has complete texel data, and the shader block maps to file lines.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "ps11/testfile.h"

namespace {

void check(bool condition) {
    if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string_view text(reinterpret_cast<const char*>(data), size);
    ps11::TestFile file;
    std::vector<ps11::TestFileError> errors;
    bool ok = ps11::parseTestFile(text, "fuzz.ps11test", file, errors);
    check(ok == errors.empty());

    size_t lines = 1;
    for (char c : text) lines += c == '\n';
    for (const ps11::TestFileError& e : errors) {
        check(e.line <= lines);
        check(!e.message.empty());
        (void)ps11::formatTestFileError(file.fileName, e);
    }
    if (file.pixelShader.present()) {
        std::string shifted = file.pixelShader.textWithFileLines();
        size_t shaderLines = 1;
        for (char c : shifted) shaderLines += c == '\n';
        check(shaderLines <= lines + 1);
    }
    if (!ok) return 0;
    for (const ps11::TextureDesc& t : file.textures) {
        check(t.width >= 1 && t.width <= ps11::kMaxTextureSide && t.height >= 1 && t.height <= ps11::kMaxTextureSide);
        check(!t.data.empty());
        for (const ps11::TextureLevel& l : t.data) {
            if (!l.hasFill) check(l.texels.size() == size_t(l.width) * l.height * l.depth);
        }
    }
    for (const ps11::TestCommand& cmd : file.commands) {
        check(cmd.line >= 1 && cmd.line <= lines);
        if (const auto* d = std::get_if<ps11::DrawPrimitives>(&cmd.op)) check(d->vertices.size() >= 3);
        if (const auto* p = std::get_if<ps11::Probe>(&cmd.op)) {
            if (p->kind == ps11::ProbeKind::Pixel || p->kind == ps11::ProbeKind::Rect) {
                check(p->rect[2] <= file.renderTarget.size.value[0]);
                check(p->rect[3] <= file.renderTarget.size.value[1]);
            }
        }
    }
    return 0;
}
