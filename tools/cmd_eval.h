// `ps11 eval`: runs a pixel shader for one pixel with interpolants, constants and 1×1 textures
// given on the command line, and prints r0. The parsing and the set-up are shared with `ps11
// debug` (tools/cmd_debug.h), which takes the same inputs.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ps11/executor.h"
#include "ps11/formats.h"
#include "ps11/hardware.h"
#include "ps11/ir.h"
#include "ps11/testfile.h"
#include "ps11/texture_sampler.h"
#include "runner/test_eval.h"

namespace ps11 {

// The inputs of one pixel as `ps11 eval` takes them.
struct EvalArgs {
    std::string shader;
    std::array<std::optional<Vec4>, 2> color;
    std::array<std::optional<Vec4>, kMaxTexCoordSets> texcoord;
    std::array<std::optional<Vec4>, 8> constant;
    std::array<std::optional<uint32_t>, kMaxTextureStages> texture;  // 1x1 texel word per stage
    std::array<TexFormat, kMaxTextureStages> textureFormat{};        // its format (A8R8G8B8 unless FORMAT: given)
    const HardwareClass* hardware = nullptr;                         // null = the default class of the version
    std::optional<Precision> precision;                              // overrides the class's profile
    float maxValue = 0;                                              // overrides the class's MaxValue (0 = none)

    ps11test::EvalInputs inputs() const;  // pointers into this object
};

// parseEvalArgs' result for -h/--help (the usage was printed).
constexpr int kHelpShown = -1;
// Parses eval's arguments for `command` (messages "ps11: COMMAND: ..." and `usage` on usage
// errors). Returns cli::kOk, kHelpShown or an exit code after printing the error.
int parseEvalArgs(const std::vector<std::string>& args, const char* command, const char* usage, EvalArgs& ea);
// Assembles and validates ea.shader and resolves its hardware class; an exit code otherwise.
int loadEvalProgram(const EvalArgs& ea, std::optional<Program>& program, HardwareConfig& hw);
// The executor of `hw` with the constants given (null after printing E40xx).
std::unique_ptr<Executor> makeEvalExecutor(const Program& program, const HardwareConfig& hw, const EvalArgs& ea);
// Binds the --texN textures (decoded as hw's class does, its filter weights); notes stages the
// shader samples without one. An exit code on failure.
int bindEvalTextures(const EvalArgs& ea, const HardwareConfig& hw, uint32_t sampled, TextureSampler& sampler);

// `ps11 eval SHADER.psh [v0=r,g,b,a] [t0=u,v,w,q] [c0=x,y,z,w] ... [--precision P]
// [--max-value M] [--texN 0xAARRGGBB]`. Returns 0 on success, 1 on user errors, 2 on usage errors.
int cmdEval(const std::vector<std::string>& args);

}  // namespace ps11
