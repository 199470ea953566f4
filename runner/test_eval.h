// Running a .ps11test's `eval` commands and `probe eval` probes on the executor (the part of
// `ps11 test` that needs no device), and the one-pixel evaluation `ps11 eval` shares with it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "ps11/diagnostics.h"
#include "ps11/executor.h"
#include "ps11/ir.h"
#include "ps11/sampler.h"
#include "ps11/testfile.h"
#include "runner/test_draw.h"

namespace ps11test {

// The executor's types the evaluator speaks (ps11/executor.h, ps11/sampler.h), beside
// test_draw.h's.
using ps11::Diagnostics;
using ps11::Executor;
using ps11::ExecutorStats;
using ps11::kBackendEmu;
using ps11::kMaxTexCoordSets;
using ps11::Sampler;
using ps11::StageDesc;
using ps11::StageState;
using ps11::TextureDesc;

// r0 (and friends) of one evaluated pixel.
struct EvalOutcome {
    Vec4 color{0, 0, 0, 0};
    std::array<int32_t, 4> grid{};  // r0's grid integers (fx profiles only)
    bool killed = false;
    bool hasDepth = false;  // the program replaces depth
    float depth = 0;
};

// Interpolants of one pixel; a null pointer reads as 0.
struct EvalInputs {
    std::array<const Vec4*, 2> color{};    // v0, v1
    std::array<const Vec4*, kMaxTexCoordSets> texture{};  // TC[0..7]
};

// Runs the program for one pixel (one lane, quads = false).
EvalOutcome evalOnePixel(const Executor& executor, Sampler& sampler, const EvalInputs& inputs,
                         ExecutorStats* stats = nullptr);

// The sampler of a test file's [texture N] / [sampler N] sections (missing [sampler N]: D3D9
// defaults), signed texels decoded as `hardware` does. Returns null with `error` set
// ("FILE:LINE: ...") if a texture cannot be built.
std::unique_ptr<Sampler> makeTestSampler(const TestFile& file, const std::string& path,
                                         const HardwareConfig& hardware, std::string& error);

// Evals on a device renderer (the GL renderer): each eval is one pixel drawn into a 1×1
// A32B32G32R32F target (and a D32F depth surface when the program replaces depth) from a
// triangle whose attributes are the eval's inputs at every vertex, so the renderer shades
// exactly those values; r0 is read back from the float target (the grid integers recovered in
// fx profiles), a pixel the renderer did not write was killed. No quad has distinct lanes, so
// sampling takes level 0 as the executor's evals do.
class RendererEval {
public:
    static std::unique_ptr<RendererEval> create(const TestFile& file, const std::string& path, const Program& program,
                                                const HardwareConfig& hardware, const RendererFactory& factory,
                                                std::string& error);
    ~RendererEval();
    std::optional<EvalOutcome> eval(const EvalInputs& inputs, std::string& error);

private:
    RendererEval() = default;
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

// The file's [stage N] state as the executor wants it (an eval gives every coordinate set four
// components; `texture` is the stage's [texture N], or null).
StageState stageStateOf(const StageDesc& stage, const TextureDesc* texture);

// What running a file's commands produced.
struct CommandTally {
    size_t evals = 0;           // evals run on the executor
    size_t probesPassed = 0;    // eval probes that passed
    size_t probesFailed = 0;    // eval probes that failed, and todo probes that passed
    size_t probesTodo = 0;      // todo probes that failed as expected
    size_t pendingGl = 0;       // commands asked on gl that it cannot run (evals; no GL renderer)
    // --backend both: every draw's render target compared between the renderers.
    size_t comparedDraws = 0;
    uint64_t comparedPixels = 0, exactPixels = 0, overOnePixels = 0;
    double maxDiff = 0;           // 8-bit levels (values on float targets)
    size_t disagreements = 0;     // draws past the target, probes passing on one renderer only
    // --gl-mode native: the gl side is measured, not checked: its probes that would fail, and its
    // draws and evals past the target, are counted here (no failure, no disagreement).
    size_t nativeProbesDiffering = 0, nativeDrawsPastTarget = 0;
    bool error = false;         // the executor or the device refused the file's setup or a draw
    ExecutorStats stats;        // executor statistics over every eval
    uint64_t texelsFetched = 0;
    DrawTally draws;            // the device's statistics over every draw
};

struct CommandRunOptions {
    uint8_t backends = kBackendEmu;  // already intersected with [require] backend
    HardwareConfig hardware;         // the class, profile and MaxValue the file runs with (resolved)
    bool verbose = false;
    // The diagnostics the [pixel shader] was assembled with: their file names resolve the source
    // places of the executor's E40xx reports.
    const Diagnostics* shaderDiags = nullptr;
    RendererFactory glRenderer;  // the gl backend's renderer (empty: gl commands are not runnable)
    // The GL renderer runs in native mode (emu/gl/gl_renderer.h): not bit-exact by design, so its
    // results are measured against the emulator's instead of checked.
    bool glNative = false;
    // emu::DeviceOptions::software.skipTiles of the emu backend's devices (`--no-skip`: false).
    bool skipTiles = true;
};

// Runs (or counts) every command of `file` whose if(...) matches the run. `program` is the
// assembled and validated [pixel shader] (null if the file has none). Failures are printed as
// `FILE:LINE: probe failed: expected ... got ... (hardware H (class), profile P, max value M)`.
void runCommands(const TestFile& file, const std::string& path, const Program* program,
                 const CommandRunOptions& options, CommandTally& tally);

}  // namespace ps11test
