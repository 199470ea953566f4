// The executor: runs a validated ps_1_1 … ps_1_4 program (the IR, never raw tokens) over spans
// of pixels in structure-of-arrays lanes, in one of the precision profiles of
// docs/precision.md. Texture instructions call a Sampler. Errors are E40xx diagnostics.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "ps11/caps.h"
#include "ps11/diagnostics.h"
#include "ps11/hardware.h"
#include "ps11/ir.h"
#include "ps11/precision.h"
#include "ps11/sampler.h"

namespace ps11 {

// Which interpreter runs a program (not a SIMD level: both run their kernels at
// ps11::simdLevel(), ps11/simd_dispatch.h). Results are bit-identical; tests and benchmarks
// compare them in one process. Auto: the fx8 fast path (int16 lanes) where it applies (fx8,
// round(M·G) <= 2040, no bem, an x86-64 build), the generic path otherwise. Generic: always the
// generic path (the reference).
enum class ExecPath : uint8_t { Auto, Generic };

struct ExecutorOptions {
    Precision precision = Precision::Fx8;
    float maxValue = 0;  // PixelShader1xMaxValue; 0 = the default hardware class's for the version
    ExecPath path = ExecPath::Auto;
    CoissuedCnd coissuedCnd = CoissuedCnd::Parallel;  // what a co-issued cnd reads (hardware class)
};
// The options a hardware class (with its overrides) gives.
ExecutorOptions executorOptionsFor(const HardwareConfig& hardware);

// Texture stage states the pixel shader reads (D3DTSS_*), per stage.
struct StageState {
    std::array<float, 4> bumpMat{0, 0, 0, 0};  // BUMPENVMAT00, 01, 10, 11
    float lumScale = 0;                        // BUMPENVLSCALE
    float lumOffset = 0;                       // BUMPENVLOFFSET
    // The luminance factor LSCALE·b + LOFFSET clamped to [0, 1]: the fixed-function
    // BUMPENVMAPLUMINANCE does (Wine's fixed_function_bumpmap_test on Windows drivers); ps_1_x
    // texbeml does not (docs/precision.md).
    bool clampLuminance = false;
    uint32_t transformFlags = 0;               // TEXTURETRANSFORMFLAGS as set: any DWORD (D3D9 checks none)
    // What D3DTTFF_PROJECTED resolves against (projectionDivisor): the components the draw's
    // vertex data gives the stage's coordinate set, and the dimensions of its texture.
    uint8_t coordComponents = 4;    // 1-4
    uint8_t textureDimensions = 2;  // 2 (2-D texture) or 3 (volume texture)
};
constexpr uint32_t kTtffProjected = 256;

// The TC component that ps_1_1 … 1_3 `tex` and `texbem(l)` divide by under D3DTTFF_PROJECTED,
// or -1 when the stage does not project (docs/precision.md "Projected coordinates", from Wine's
// projected_textures_test on Windows drivers): the count is the COUNT field, or the set's
// component count when that field is 0 or larger (PROJECTED alone, 0xffffffff); the division
// happens only when that count exceeds the texture's dimensions (COUNT1, and COUNT3 on a
// two-component set, draw unprojected) and is by the count's last component.
int projectionDivisor(const StageState& stage);

// Interpolated inputs of `count` pixels (count <= kMaxSpan), structure of arrays. A null
// pointer reads as 0 for every lane.
struct PixelInputs {
    int count = 0;
    bool quads = false;  // lanes 4i..4i+3 are 2x2 quads (see SampleRequest::quads)
    const float* color[2][4] = {};     // v0, v1: r g b a
    const float* texcoord[kMaxTexCoordSets][4] = {};  // TC[0..7]: u v w q
    // Bit 4·v + c: v#'s channel c is one value in every lane (a colour constant over a triangle),
    // read from color[v][c][0] alone and converted once.
    uint8_t uniformColor = 0;
};

// Results of `count` pixels. color is always filled (r0 as a real value); grid, if given,
// receives r0's grid integers in fx profiles; killed (if given) is 1 for pixels discarded by
// texkill; depth is written only where the shader replaces depth (writesDepth()).
struct PixelOutputs {
    float* color[4] = {};
    int32_t* grid[4] = {};
    uint8_t* killed = nullptr;
    float* depth = nullptr;
};

struct ExecutorStats {
    uint64_t pixels = 0;
    uint64_t instructions = 0;  // instruction executions (per pixel)
};

// One executed instruction of a traced pixel (Executor::trace).
struct TraceStep {
    int instruction = -1;  // index in Program::instructions
    bool writes = false;   // writes its destination register (the opcode table's writesDst)
    uint8_t mask = 0;      // the channels it writes (texture-address instructions: all four)
    // The destination register after the instruction, r g b a (a co-issued first member: the
    // values it writes once its partner has read); fx profiles also as grid integers.
    std::array<float, 4> value{};
    std::array<int32_t, 4> grid{};
};

class Executor {
public:
    // Prepares the program (decode once). Reports E40xx and returns null for programs it cannot
    // run (unsupported version, invalid program). The program should have passed validate().
    static std::unique_ptr<Executor> create(const Program& program, const ExecutorOptions& options,
                                            Diagnostics& diags);
    virtual ~Executor() = default;

    // SetPixelShaderConstantF: c0..c7. A def in the shader overrides the API value.
    virtual void setConstant(int index, const std::array<float, 4>& value) = 0;
    virtual void setStageState(int stage, const StageState& state) = 0;
    // True if the program replaces depth (texm3x2depth, texdepth).
    virtual bool writesDepth() const = 0;
    // Stages the program samples (bit per stage).
    virtual uint32_t sampledStages() const = 0;
    virtual const ExecutorOptions& options() const = 0;
    // The implementation run() uses now: "generic", or the fast path's kernels at the current
    // SIMD level, "fast-sse2", "fast-avx2" or "fast-avx512".
    virtual const char* pathName() const = 0;

    // Runs the program for inputs.count pixels (<= kMaxSpan). Thread-safe for distinct
    // outputs when the sampler is (run keeps no per-call state in the object).
    virtual void run(const PixelInputs& inputs, Sampler& sampler, PixelOutputs& outputs,
                     ExecutorStats* stats = nullptr) const = 0;
    // run() on the generic path (the same results), recording each executed instruction of the
    // first pixel (phase excluded) into `steps` (`ps11 debug`).
    virtual void trace(const PixelInputs& inputs, Sampler& sampler, PixelOutputs& outputs,
                       std::vector<TraceStep>& steps) const = 0;
};

}  // namespace ps11
