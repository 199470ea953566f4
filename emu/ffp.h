// Fixed-function texture stages lowered to a ps11 program (docs/fixed-function.md): the D3D9
// combiner (COLOROP/ALPHAOP, their arguments, RESULTARG, bump mapping, texture factor, the
// specular add) becomes ps11 IR that the one executor runs, exactly like a pixel shader.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "emu/call_error.h"
#include "emu/state.h"
#include "ps11/executor.h"
#include "ps11/ir.h"

namespace emu {

// Texture stages whose TEXTURE argument the lowering can sample (D3DCAPS9
// MaxSimultaneousTextures of a ps 1.1-class part; MaxTextureBlendStages is kMaxStages = 8).
constexpr int kMaxFixedFunctionTextures = 4;

struct LoweredStages {
    // Runs on ps11::Executor like a pixel shader: executor texture stage i is device stage i
    // (SetTexture(i), sampler i) reading executor texture-coordinate slot i, which the draw
    // fills from the vertex set TEXCOORDINDEX(i) selects. v0 = diffuse, v1 = specular.
    ps11::Program program;
    uint32_t sampledStages = 0;  // bit i: stage i's texture is read
    int activeStages = 0;        // stages before the first COLOROP DISABLE
    // What the draw passes to Executor::setStageState(i, …) for executor stage i. D3D9 puts the
    // bump matrix and luminance scale/offset on the BUMPENVMAP stage i, while texbem/texbeml
    // read them from the stage they sample (i + 1): the lowering moves them there. The
    // projection flags are each stage's own TEXTURETRANSFORMFLAGS.
    std::array<ps11::StageState, kMaxStages> executorStages{};
};

// Lowers the texture stage states and the render states the combiner reads (TEXTUREFACTOR,
// SPECULARENABLE) of `state`; the texture bindings only as DeviceState::StateWords::FixedFunction
// names them. Deterministic: equal inputs give equal programs, so the draw may cache by state.
// For a setup the device cannot run (D3DERR_UNSUPPORTEDCOLOROPERATION and friends in D3D9's
// ValidateDevice) returns nullopt and sets `error` to D3DERR_INVALIDCALL, its E41xx code and
// "stage 2 D3DTSS_COLOROP: <what is wrong>"; `error` is reset (hr D3D_OK) on success.
std::optional<LoweredStages> lowerFixedFunction(const DeviceState& state, CallError& error);

}  // namespace emu
