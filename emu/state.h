// The device state: one plain struct holding everything Set* calls change (render states,
// texture stage and sampler states, bindings, transforms, viewport, scissor, pixel shader and
// its constants, FVF), initialised to Direct3D 9's defaults, hashable and comparable so draws
// can cache work per state.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <functional>

#include "emu/d3d9types.h"
#include "ps11/caps.h"
#include "ps11/ir.h"

namespace emu {

// A device object (texture, volume texture, surface, pixel shader), like a COM pointer: 0 is
// NULL; the device checks the kind at every call.
enum class Handle : uint32_t { Null = 0 };

// Stages and samplers of the device (ps11/caps.h).
constexpr int kMaxStages = ps11::kMaxTextureStages;
constexpr int kMaxSamplers = ps11::kMaxTextureStages;
// ps_1_x constant registers c0..c7 (the register file, ps11/ir.h).
constexpr int kMaxPsConstants = ps11::registerCount(ps11::RegType::Const, 1);

struct DeviceState {
    // D3DRS_* values indexed by D3DRENDERSTATETYPE; float states hold their bit pattern.
    std::array<DWORD, kRenderStateLimit> renderStates{};
    // D3DTSS_* values per stage, indexed by D3DTEXTURESTAGESTATETYPE.
    std::array<std::array<DWORD, kStageStateLimit>, kMaxStages> stageStates{};
    // D3DSAMP_* values per sampler, indexed by D3DSAMPLERSTATETYPE.
    std::array<std::array<DWORD, kSamplerStateLimit>, kMaxSamplers> samplerStates{};
    std::array<Handle, kMaxSamplers> textures{};                      // SetTexture
    Handle renderTarget = Handle::Null;                               // SetRenderTarget(0, …)
    Handle depthStencil = Handle::Null;                               // SetDepthStencilSurface
    Handle pixelShader = Handle::Null;                                // SetPixelShader; Null = fixed function
    D3DMATRIX world, view, projection;                                // identity
    std::array<D3DMATRIX, 8> texture;                                 // D3DTS_TEXTURE0..7, identity
    D3DVIEWPORT9 viewport;                                            // the render target's size when it is set
    RECT scissor;                                                     // idem
    std::array<std::array<float, 4>, kMaxPsConstants> psConstants{};  // c0..c7, 0
    DWORD fvf = 0;                                                    // SetFVF

    // Direct3D 9's defaults (docs/device.md "Defaults").
    DeviceState();

    DWORD renderState(D3DRENDERSTATETYPE s) const { return renderStates[s]; }
    DWORD stageState(int stage, D3DTEXTURESTAGESTATETYPE s) const { return stageStates[size_t(stage)][s]; }
    DWORD samplerState(int sampler, D3DSAMPLERSTATETYPE s) const { return samplerStates[size_t(sampler)][s]; }
    // A float state stored as its bit pattern (D3DRS_FOGSTART, D3DTSS_BUMPENVMAT00, …).
    float renderStateFloat(D3DRENDERSTATETYPE s) const;
    float stageStateFloat(int stage, D3DTEXTURESTAGESTATETYPE s) const;

    // Parts of the state as 32-bit words, for hashing and comparing all of it or a part.
    enum StateWords : uint32_t {
        RenderStates = 1u << 0,
        StageStates = 1u << 1,
        SamplerStates = 1u << 2,
        Textures = 1u << 3,    // the texture handles of the stages
        Bindings = 1u << 4,    // render target, depth stencil surface, pixel shader
        Transforms = 1u << 5,  // world, view, projection, texture 0..7
        ViewportScissor = 1u << 6,
        PsConstants = 1u << 7,
        Fvf = 1u << 8,
        AllFields = (1u << 9) - 1,
        // One word, bit i: stage i has a texture bound (derived from Textures; not in AllFields).
        BoundTextures = 1u << 9,
        // What the fixed-function lowering reads (emu/ffp.h): the draw caches lowered programs by it.
        FixedFunction = RenderStates | StageStates | BoundTextures,
    };

    // Hash and equality over every field, floats compared by bit pattern (so -0 != 0 and a NaN
    // equals itself, consistent with the hash).
    size_t hash() const { return hash(AllFields); }
    bool operator==(const DeviceState& other) const { return equal(other, AllFields); }
    // The same over the parts named in `parts` (StateWords bits).
    size_t hash(uint32_t parts) const;
    bool equal(const DeviceState& other, uint32_t parts) const;

    // Calls f(uint32_t) for every 32-bit word of the named parts in a fixed order (hash and
    // equal use it, and a draw's fingerprint; the order of the parts is that of StateWords).
    // A template: a call per word through std::function was a tenth of a still frame.
    template <typename F>
    void forEachWord(F&& f, uint32_t parts = AllFields) const;
    // How many words forEachWord gives for every part (a constant: the arrays are fixed).
    size_t wordCount() const {
        size_t n = 0;
        forEachWord([&n](uint32_t) { ++n; });
        return n;
    }
};

template <typename F>
void DeviceState::forEachWord(F&& f, uint32_t parts) const {
    if (parts & RenderStates)
        for (DWORD v : renderStates) f(v);
    if (parts & StageStates)
        for (const auto& st : stageStates)
            for (DWORD v : st) f(v);
    if (parts & SamplerStates)
        for (const auto& st : samplerStates)
            for (DWORD v : st) f(v);
    if (parts & Textures)
        for (Handle h : textures) f(uint32_t(h));
    if (parts & Bindings) {
        f(uint32_t(renderTarget));
        f(uint32_t(depthStencil));
        f(uint32_t(pixelShader));
    }
    if (parts & Transforms) {
        auto matrix = [&f](const D3DMATRIX& m) {
            for (const auto& row : m.m)
                for (float x : row) f(std::bit_cast<uint32_t>(x));
        };
        matrix(world);
        matrix(view);
        matrix(projection);
        for (const D3DMATRIX& m : texture) matrix(m);
    }
    if (parts & ViewportScissor) {
        f(viewport.X), f(viewport.Y), f(viewport.Width), f(viewport.Height);
        f(std::bit_cast<uint32_t>(viewport.MinZ)), f(std::bit_cast<uint32_t>(viewport.MaxZ));
        f(uint32_t(scissor.left)), f(uint32_t(scissor.top)), f(uint32_t(scissor.right)), f(uint32_t(scissor.bottom));
    }
    if (parts & PsConstants)
        for (const auto& c : psConstants)
            for (float x : c) f(std::bit_cast<uint32_t>(x));
    if (parts & Fvf) f(fvf);
    if (parts & BoundTextures) {
        uint32_t bound = 0;
        for (size_t i = 0; i < textures.size(); ++i)
            if (textures[i] != Handle::Null) bound |= 1u << i;
        f(bound);
    }
}

// True for a D3DRENDERSTATETYPE value d3d9types.h defines.
bool isRenderState(DWORD state);
// True for a D3DTEXTURESTAGESTATETYPE value d3d9types.h defines.
bool isStageState(DWORD state);
// True for a D3DSAMPLERSTATETYPE value d3d9types.h defines.
bool isSamplerState(DWORD state);
// True for render / stage states whose DWORD holds a float's bits.
bool isFloatRenderState(DWORD state);
bool isFloatStageState(DWORD state);

// The float's bit pattern as D3D passes float states: *(DWORD*)&f.
DWORD floatBits(float f);
float bitsFloat(DWORD bits);

struct DeviceStateHash {
    size_t operator()(const DeviceState& s) const { return s.hash(); }
};

}  // namespace emu
