// libFuzzer target for the device through the .ps11test runner: arbitrary bytes as a test file;
// files the reader accepts are set up on emu::Device and their draws and pixel probes run. The
// device must never crash, hang or trip a sanitizer on any setup, state or vertex data the
// format can express; a refused call must carry a message. Sizes are capped so each input
// stays fast (the limits themselves are tested elsewhere). In fx8, fx12, float and ideal every file
// is also drawn with the row paths off (the fx aligned passes, the float profiles' row path, the
// spans of one row of draws whose lookups are lodFree, and with them tile skipping, which the
// first device does by default) and the sampler's fast kernels off: every triangle in 2×2 quads,
// every lookup by the reference sampler. After every draw both render
// targets must be identical bit for bit (docs/device.md "Rasterisation", "Aligned passes", "Tile skipping"; `fill`
// textures and constant regions make the tiles that are filled, copied or skipped). A third device checks fingerprints
// (docs/device.md "Fingerprints") at every draw: a dry run of the draw writes nothing; and when the draw's fingerprint
// after running it equals the one before, running it again must leave the target's bytes as they are (what lets a pass
// graph skip a pass whose fingerprint and outputs are last frame's).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/diagnostics.h"
#include "ps11/testfile.h"
#include "ps11/validator.h"
#include "emu/device.h"
#include "runner/test_draw.h"

namespace {

void check(bool condition) {
    if (!condition) std::abort();
}

bool samePixels(const std::vector<ps11::Vec4>& a, const std::vector<ps11::Vec4>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof a[0]) == 0);
}

std::vector<ps11::Vec4> pixels(ps11test::DrawRunner& r) {
    std::vector<ps11::Vec4> out;
    std::string error;
    check(r.targetPixels(out, error));
    return out;
}

// The fingerprint of one command run as a dry run on `r`'s device.
emu::Device::Fingerprint dryRun(ps11test::DrawRunner& r, const ps11::TestCommand& cmd) {
    r.device().beginFingerprint();
    std::string error;
    (void)r.draw(cmd, error);
    return r.device().endFingerprint();
}

bool small(const ps11::TestFile& file) {
    const auto& size = file.renderTarget.size.value;
    if (uint64_t(size[0]) * size[1] > 64 * 64) return false;
    uint64_t texels = 0;
    for (const ps11::TextureDesc& t : file.textures) texels += uint64_t(t.width) * t.height * std::max(t.depth, 1u);
    if (texels > 64 * 64 * 4) return false;
    size_t vertices = 0;
    for (const ps11::TestCommand& cmd : file.commands)
        if (const auto* d = std::get_if<ps11::DrawPrimitives>(&cmd.op)) vertices += d->vertices.size();
    return vertices <= 96 && file.commands.size() <= 32;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string_view text(reinterpret_cast<const char*>(data), size);
    ps11::TestFile file;
    std::vector<ps11::TestFileError> errors;
    if (!ps11::parseTestFile(text, "fuzz.ps11test", file, errors) || !small(file)) return 0;

    std::optional<ps11::Program> program;
    if (file.pixelShader.present()) {
        if (file.pixelShader.expectFail) return 0;
        ps11::Diagnostics diags;
        ps11::AssembleOptions options;
        program = ps11::parseAssembly(file.pixelShader.textWithFileLines(), "fuzz.ps11test", options, diags);
        if (program) ps11::validate(*program, diags);
        if (!program || diags.hasErrors()) return 0;
    }
    for (ps11::Precision p :
         {ps11::Precision::Fx8, ps11::Precision::Fx12, ps11::Precision::Float, ps11::Precision::Ideal}) {
        std::string error;
        const ps11::HardwareConfig hw = ps11::resolveHardware(file.require.hardware.value, program ? program->version.minor : 1,
                                                              p, file.require.maxValue.value);
        auto runner = ps11test::DrawRunner::create(file, "fuzz.ps11test", program ? &*program : nullptr, hw, error);
        if (!runner) {
            check(!error.empty());
            continue;
        }
        std::string quadError;
        std::unique_ptr<ps11test::DrawRunner> quads =
            ps11test::DrawRunner::create(file, "fuzz.ps11test", program ? &*program : nullptr, hw, quadError, false);
        check(quads != nullptr);
        std::string fpError;
        std::unique_ptr<ps11test::DrawRunner> prints =
            ps11test::DrawRunner::create(file, "fuzz.ps11test", program ? &*program : nullptr, hw, fpError);
        check(prints != nullptr);
        for (const ps11::TestCommand& cmd : file.commands) {
            if (std::holds_alternative<ps11::Eval>(cmd.op)) continue;
            error.clear();
            if (const auto* probe = std::get_if<ps11::Probe>(&cmd.op)) {
                if (ps11::isEvalProbe(probe->kind)) continue;
                (void)runner->probe(*probe, error);
                continue;
            }
            const bool drawn = runner->draw(cmd, error);
            if (!drawn) check(!error.empty());
            {
                const std::vector<ps11::Vec4> before = pixels(*prints);
                const emu::Device::Fingerprint first = dryRun(*prints, cmd);
                check(samePixels(pixels(*prints), before));  // a dry run writes nothing
                std::string e;
                check(prints->draw(cmd, e) == drawn);
                const std::vector<ps11::Vec4> once = pixels(*prints);
                const emu::Device::Fingerprint again = dryRun(*prints, cmd);
                if (drawn && first.complete && again.complete && first.words == again.words) {
                    check(prints->draw(cmd, e));
                    check(samePixels(pixels(*prints), once));  // equal fingerprints: the same bytes
                }
            }
            if (!quads) continue;
            std::string quadError;
            check(quads->draw(cmd, quadError) == drawn);
            std::vector<ps11::Vec4> a, b;
            std::string e1, e2;
            check(runner->targetPixels(a, e1) == quads->targetPixels(b, e2));
            check(a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof a[0]) == 0));
        }
    }
    return 0;
}
