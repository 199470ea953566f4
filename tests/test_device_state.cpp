// Device state blocks (Device::applyState, docs/device.md "State blocks"): every field of
// DeviceState set through applyState reads back as given, a captured state comes back after
// anything changed it, and a field the Set* calls refuse (a handle released since the capture, a
// slot with no D3D9 state) changes nothing and names the call. Drawing after applyState on both
// renderers: tests/test_gl_renderer.cpp.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "emu/device.h"

using namespace emu;

namespace {

// A device with objects for every handle field of a state block.
struct Objects {
    Handle textures[kMaxSamplers]{};
    Handle volume{}, target{}, otherTarget{}, depth{}, shader{};
};

Objects makeObjects(Device& dev) {
    Objects o;
    for (Handle& t : o.textures) REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &t) == D3D_OK);
    REQUIRE(dev.CreateVolumeTexture(4, 4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &o.volume) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(64, 32, D3DFMT_A8R8G8B8, 0, &o.target) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(16, 16, D3DFMT_A8R8G8B8, 0, &o.otherTarget) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(64, 32, D3DFMT_D24S8, &o.depth) == D3D_OK);
    REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\nmov r0, t0\n", &o.shader) == D3D_OK);
    return o;
}

D3DMATRIX matrix(float seed) {
    D3DMATRIX m;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m.m[r][c] = seed + float(4 * r + c) * 0.25f;
    return m;
}

// A state block unlike D3D9's defaults in every field the Set* calls take.
DeviceState everyFieldChanged(const Objects& o) {
    DeviceState s;
    for (DWORD i = 0; i < kRenderStateLimit; ++i)
        if (isRenderState(i)) s.renderStates[i] = 0x1000 + i;
    s.renderStates[D3DRS_FOGSTART] = floatBits(std::nanf(""));  // float states round-trip by bits
    s.renderStates[D3DRS_FOGEND] = floatBits(-0.0f);
    for (DWORD stage = 0; stage < DWORD(kMaxStages); ++stage) {
        for (DWORD i = 0; i < kStageStateLimit; ++i)
            if (isStageState(i)) s.stageStates[stage][i] = 0x2000 + 64 * stage + i;
        for (DWORD i = 0; i < kSamplerStateLimit; ++i)
            if (isSamplerState(i)) s.samplerStates[stage][i] = 0x3000 + 64 * stage + i;
        s.textures[stage] = stage == 5 ? o.volume : o.textures[stage];
    }
    s.renderTarget = o.target;
    s.depthStencil = o.depth;
    s.pixelShader = o.shader;
    s.world = matrix(1);
    s.view = matrix(2);
    s.projection = matrix(3);
    for (size_t t = 0; t < s.texture.size(); ++t) s.texture[t] = matrix(10 + float(t));
    s.viewport = D3DVIEWPORT9{3, 4, 20, 10, 0.25f, 0.5f};
    s.scissor = RECT{-5, 2, 300, 20};  // stored as given
    for (int c = 0; c < kMaxPsConstants; ++c)
        for (int k = 0; k < 4; ++k) s.psConstants[size_t(c)][size_t(k)] = float(c) * 3.5f - float(k);
    s.psConstants[7][3] = -0.0f;
    s.fvf = D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_TEX2;
    return s;
}

}  // namespace

TEST_CASE("device state blocks: every field set through applyState reads back as given", "[device]") {
    Device dev;
    const Objects o = makeObjects(dev);
    const DeviceState s = everyFieldChanged(o);
    REQUIRE(dev.applyState(s) == D3D_OK);
    CHECK(dev.lastError().code.empty());
    CHECK(dev.state() == s);
    // The Get* calls see what the Set* calls would have set.
    DWORD v = 0;
    REQUIRE(dev.GetRenderState(D3DRS_SRCBLEND, &v) == D3D_OK);
    CHECK(v == 0x1000 + D3DRS_SRCBLEND);
    REQUIRE(dev.GetTextureStageState(6, D3DTSS_COLOROP, &v) == D3D_OK);
    CHECK(v == 0x2000 + 64 * 6 + D3DTSS_COLOROP);
    REQUIRE(dev.GetSamplerState(7, D3DSAMP_MAXANISOTROPY, &v) == D3D_OK);
    CHECK(v == 0x3000 + 64 * 7 + D3DSAMP_MAXANISOTROPY);
    D3DVIEWPORT9 vp{};
    REQUIRE(dev.GetViewport(&vp) == D3D_OK);
    CHECK(vp.X == 3);
    CHECK(vp.Width == 20);
    CHECK(vp.MaxZ == 0.5f);
    Handle h{};
    REQUIRE(dev.GetTexture(5, &h) == D3D_OK);
    CHECK(h == o.volume);

    // Each field on its own: one changed slot, applied, reads back (and only it changed).
    auto roundTrip = [&](const DeviceState& t, const std::string& what) {
        INFO(what);
        REQUIRE(dev.applyState(t) == D3D_OK);
        CHECK(dev.state() == t);
        CHECK_FALSE(dev.state() == s);
    };
    for (DWORD i = 0; i < kRenderStateLimit; ++i)
        if (isRenderState(i)) {
            DeviceState t = s;
            t.renderStates[i] ^= 0x00800001u;
            roundTrip(t, "render state " + std::to_string(i));
        }
    for (size_t stage = 0; stage < size_t(kMaxStages); ++stage) {
        for (DWORD i = 0; i < kStageStateLimit; ++i)
            if (isStageState(i)) {
                DeviceState t = s;
                t.stageStates[stage][i] ^= 1;
                roundTrip(t, "stage " + std::to_string(stage) + " state " + std::to_string(i));
            }
        for (DWORD i = 0; i < kSamplerStateLimit; ++i)
            if (isSamplerState(i)) {
                DeviceState t = s;
                t.samplerStates[stage][i] ^= 1;
                roundTrip(t, "sampler " + std::to_string(stage) + " state " + std::to_string(i));
            }
        DeviceState t = s;
        t.textures[stage] = Handle::Null;
        roundTrip(t, "texture " + std::to_string(stage));
        t.textures[stage] = o.textures[(stage + 1) % kMaxSamplers];
        roundTrip(t, "another texture on " + std::to_string(stage));
        t = s;
        t.texture[stage].m[2][1] = -7;
        roundTrip(t, "texture matrix " + std::to_string(stage));
    }
    DeviceState t = s;
    t.renderTarget = o.otherTarget;  // the viewport goes with it, inside the smaller target
    t.viewport = D3DVIEWPORT9{1, 2, 8, 8, 0, 1};
    roundTrip(t, "render target and viewport");
    t = s;
    t.viewport.MinZ = 0.125f;
    roundTrip(t, "viewport");
    t = s;
    t.scissor.bottom = 7;
    roundTrip(t, "scissor rect");
    t = s;
    t.depthStencil = Handle::Null;
    roundTrip(t, "depth stencil surface");
    t = s;
    t.pixelShader = Handle::Null;
    roundTrip(t, "pixel shader");
    for (D3DMATRIX DeviceState::*m : {&DeviceState::world, &DeviceState::view, &DeviceState::projection}) {
        t = s;
        (t.*m).m[3][0] = 99;
        roundTrip(t, "a transform");
    }
    for (size_t c = 0; c < size_t(kMaxPsConstants); ++c) {
        t = s;
        t.psConstants[c][1] = 42;
        roundTrip(t, "constant " + std::to_string(c));
    }
    t = s;
    t.fvf = D3DFVF_XYZ;
    roundTrip(t, "FVF");

    // D3D9's defaults, NULL render target included (a fresh device's state).
    REQUIRE(dev.applyState(DeviceState{}) == D3D_OK);
    CHECK(dev.state() == DeviceState{});
    CHECK(dev.GetRenderTarget(0, &h) == D3DERR_NOTFOUND);
}

TEST_CASE("device state blocks: a captured state comes back after Set* calls changed it", "[device]") {
    Device dev;
    const Objects o = makeObjects(dev);
    REQUIRE(dev.SetRenderTarget(0, o.target) == D3D_OK);
    const D3DVIEWPORT9 vp{2, 2, 30, 20, 0.0f, 1.0f};
    REQUIRE(dev.SetViewport(&vp) == D3D_OK);
    REQUIRE(dev.SetTexture(0, o.textures[0]) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
    const DeviceState captured = dev.state();

    REQUIRE(dev.SetRenderTarget(0, o.otherTarget) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(o.depth) == D3D_OK);
    REQUIRE(dev.SetPixelShader(o.shader) == D3D_OK);
    REQUIRE(dev.SetTexture(0, Handle::Null) == D3D_OK);
    REQUIRE(dev.SetTexture(3, o.volume) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 0) == D3D_OK);
    REQUIRE(dev.SetTextureStageState(2, D3DTSS_COLOROP, D3DTOP_ADD) == D3D_OK);
    REQUIRE(dev.SetSamplerState(1, D3DSAMP_MINFILTER, D3DTEXF_LINEAR) == D3D_OK);
    const float c[4] = {1, 2, 3, 4};
    REQUIRE(dev.SetPixelShaderConstantF(6, c, 1) == D3D_OK);
    const D3DMATRIX m = matrix(5);
    REQUIRE(dev.SetTransform(D3DTS_TEXTURE3, &m) == D3D_OK);
    REQUIRE(dev.SetFVF(D3DFVF_XYZ) == D3D_OK);
    REQUIRE_FALSE(dev.state() == captured);

    REQUIRE(dev.applyState(captured) == D3D_OK);
    CHECK(dev.state() == captured);
}

TEST_CASE("device state blocks: a refused field changes nothing and names the call", "[device]") {
    Device dev;
    Objects o = makeObjects(dev);
    Handle scratch{}, level{}, owner{};
    REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_SCRATCH, &scratch) == D3D_OK);
    REQUIRE(dev.CreateTexture(8, 8, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &owner) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(owner, 0, &level) == D3D_OK);
    const DeviceState good = everyFieldChanged(o);
    // The device holds another valid state: a refused block must leave exactly it.
    DeviceState current = good;
    current.renderTarget = o.otherTarget;
    current.viewport = D3DVIEWPORT9{0, 0, 16, 16, 0, 1};
    current.renderStates[D3DRS_SRCBLEND] = D3DBLEND_ONE;
    current.textures[4] = Handle::Null;
    current.fvf = D3DFVF_XYZ;
    REQUIRE(dev.applyState(current) == D3D_OK);
    REQUIRE(dev.state() == current);

    auto refused = [&](const DeviceState& block, HRESULT hr, const std::string& message) {
        INFO(message);
        CHECK(dev.applyState(block) == hr);
        CHECK(dev.lastError().hr == hr);
        CHECK(dev.lastError().message == message);
        CHECK(dev.state() == current);
    };
    const std::string scratchId = std::to_string(uint32_t(scratch));
    DeviceState b = good;
    b.textures[2] = scratch;
    refused(b, D3DERR_INVALIDCALL,
            "E4112 applyState: SetTexture: texture " + scratchId +
                " is in D3DPOOL_SCRATCH, which cannot be bound (the block's texture of stage 2)");
    b = good;
    b.textures[1] = o.target;
    refused(b, D3DERR_INVALIDCALL,
            "E4102 applyState: SetTexture: handle " + std::to_string(uint32_t(o.target)) +
                " is a surface, not a texture (the block's texture of stage 1)");
    b = good;
    b.viewport.Width = 63;  // 3 + 63 > 64
    refused(b, D3DERR_INVALIDCALL,
            "E4105 applyState: SetViewport: viewport (3, 4) 63x10 is outside the 64x32 render target (the block's "
            "viewport)");
    b = good;
    b.renderTarget = level;  // a texture's level is a render target as well as a standalone surface
    b.viewport = D3DVIEWPORT9{0, 0, 8, 8, 0, 1};
    REQUIRE(dev.applyState(b) == D3D_OK);
    CHECK(dev.state() == b);
    REQUIRE(dev.applyState(current) == D3D_OK);
    b = good;
    b.renderTarget = o.depth;
    refused(b, D3DERR_INVALIDCALL,
            "E4104 applyState: SetRenderTarget: surface " + std::to_string(uint32_t(o.depth)) +
                " was not created with D3DUSAGE_RENDERTARGET (the block's render target)");
    // Slots that are no D3D9 state: the Set* calls refuse them, so a block holding a value there does too.
    b = good;
    b.renderStates[0] = 1;
    refused(b, D3DERR_INVALIDCALL, "E4101 applyState: SetRenderState: unknown render state 0");
    b = good;
    b.stageStates[3][12] = 1;
    refused(b, D3DERR_INVALIDCALL,
            "E4101 applyState: SetTextureStageState: unknown texture stage state 12 (the block's stage 3)");
    b = good;
    b.samplerStates[6][0] = 1;
    refused(b, D3DERR_INVALIDCALL,
            "E4101 applyState: SetSamplerState: unknown sampler state 0 (the block's sampler 6)");
    b = good;
    b.pixelShader = Handle(uint32_t(0xFFFFFFFF));
    refused(b, D3DERR_INVALIDCALL,
            "E4102 applyState: SetPixelShader: handle 4294967295 is not a pixel shader of this device (the block's "
            "pixel shader)");

    // Objects released since the capture: each handle field in turn.
    const std::string shaderId = std::to_string(uint32_t(o.shader)), depthId = std::to_string(uint32_t(o.depth)),
                      targetId = std::to_string(uint32_t(o.target)),
                      textureId = std::to_string(uint32_t(o.textures[4])), levelId = std::to_string(uint32_t(level));
    REQUIRE(dev.Release(o.textures[4]) == D3D_OK);
    refused(good, D3DERR_INVALIDCALL,
            "E4102 applyState: SetTexture: handle " + textureId +
                " is not an object of this device (the block's texture of stage 4)");
    b = good;
    b.textures[4] = Handle::Null;
    REQUIRE(dev.Release(o.shader) == D3D_OK);
    current.pixelShader = Handle::Null;
    refused(b, D3DERR_INVALIDCALL,
            "E4102 applyState: SetPixelShader: handle " + shaderId +
                " is not a pixel shader of this device (the block's pixel shader)");
    b.pixelShader = Handle::Null;
    REQUIRE(dev.Release(o.depth) == D3D_OK);
    // Release resets the device's own bindings to what it frees; `current` follows.
    current.depthStencil = Handle::Null;
    REQUIRE(dev.state() == current);
    refused(b, D3DERR_INVALIDCALL,
            "E4102 applyState: SetDepthStencilSurface: surface " + depthId +
                " is not an object of this device (the block's depth stencil surface)");
    b.depthStencil = Handle::Null;
    REQUIRE(dev.Release(o.target) == D3D_OK);
    refused(b, D3DERR_INVALIDCALL,
            "E4102 applyState: SetRenderTarget: surface " + targetId +
                " is not an object of this device (the block's render target)");
    // A texture level bound as the target dies with its texture.
    b.renderTarget = level;
    b.viewport = D3DVIEWPORT9{0, 0, 8, 8, 0, 1};
    REQUIRE(dev.Release(owner) == D3D_OK);
    refused(b, D3DERR_INVALIDCALL,
            "E4102 applyState: SetRenderTarget: surface " + levelId +
                " is not an object of this device (the block's render target)");
    // With the released handles gone from it, the block applies.
    b.renderTarget = o.otherTarget;
    b.viewport = D3DVIEWPORT9{0, 0, 16, 16, 0, 1};
    REQUIRE(dev.applyState(b) == D3D_OK);
    CHECK(dev.state() == b);
}
