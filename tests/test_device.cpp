// Unit tests of the emu device (slice 1): D3D9 constants, DeviceState defaults and hashing,
// every call's success and error paths: state setters and getters, resource creation, pixel
// shaders, Release; every E41xx code documented. Expected values come from the D3D9
// documentation's formulas, worked out by hand in the comments. Lock/Unlock layouts of every
// format, lock rules, readSurface, mip generation and the sampler's views are in
// test_device_textures.cpp; Clear, StretchRect and GetRenderTargetData in test_device_blit.cpp;
// the helpers they share in device_test_util.h.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "device_test_util.h"
#include "emu/device.h"
#include "ps11/encoder.h"
#include "ps11/testfile.h"

using namespace emu;

using namespace devicetest;

namespace {

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

}  // namespace

TEST_CASE("device: D3D9 constants have their d3d9types.h values", "[device]") {
    CHECK(D3DFMT_A8R8G8B8 == 21);
    CHECK(D3DFMT_X8R8G8B8 == 22);
    CHECK(D3DFMT_A8 == 28);
    CHECK(D3DFMT_L8 == 50);
    CHECK(D3DFMT_A8L8 == 51);
    CHECK(D3DFMT_V8U8 == 60);
    CHECK(D3DFMT_L6V5U5 == 61);
    CHECK(D3DFMT_X8L8V8U8 == 62);
    CHECK(D3DFMT_Q8W8V8U8 == 63);
    CHECK(D3DFMT_V16U16 == 64);
    CHECK(D3DFMT_A16B16G16R16F == 113);
    CHECK(D3DFMT_R32F == 114);
    CHECK(D3DFMT_A32B32G32R32F == 116);
    CHECK(uint32_t(D3DERR_INVALIDCALL) == 0x8876086Cu);
    CHECK(uint32_t(D3DERR_NOTAVAILABLE) == 0x8876086Au);
    CHECK(uint32_t(E_OUTOFMEMORY) == 0x8007000Eu);
    CHECK(FAILED(D3DERR_INVALIDCALL));
    CHECK(D3DRS_COLORWRITEENABLE == 168);
    CHECK(D3DRS_SCISSORTESTENABLE == 174);
    CHECK(D3DRS_BLENDOPALPHA == 209);
    CHECK(D3DTSS_RESULTARG == 28);
    CHECK(D3DTSS_CONSTANT == 32);
    CHECK(D3DSAMP_DMAPOFFSET == 13);
    CHECK(D3DTOP_LERP == 26);
    CHECK(D3DTS_WORLD == 256);
    CHECK(D3DTS_WORLDMATRIX(1) == 257);
    CHECK(D3DFVF_TEXCOORDSIZE3(1) == (1u << 18));
    CHECK(D3DPS_VERSION(1, 4) == 0xFFFF0104u);
    CHECK(D3DCOLOR_ARGB(1, 2, 3, 4) == 0x01020304u);
}

TEST_CASE("device: the .ps11test model's names map onto D3D9 values", "[device]") {
    // Every texture format of the test model has a D3DFORMAT and maps back.
    for (int i = 0; i <= int(ps11::TexFormat::R32F); ++i) {
        const auto f = ps11::TexFormat(i);
        const D3DFORMAT d = d3dFormatOf(f);
        INFO(ps11::texFormatName(f));
        REQUIRE(formatInfo(d));
        CHECK(formatInfo(d)->texFormat == f);
        CHECK(std::string(formatInfo(d)->name) == ps11::texFormatName(f));
    }
    // The model's enumerations carry D3D9's numbers, so a cast expresses them.
    CHECK(DWORD(ps11::TextureOp::Disable) == D3DTOP_DISABLE);
    CHECK(DWORD(ps11::TextureOp::DotProduct3) == D3DTOP_DOTPRODUCT3);
    CHECK(DWORD(ps11::TextureOp::Lerp) == D3DTOP_LERP);
    CHECK(DWORD(ps11::ArgSource::Temp) == D3DTA_TEMP);
    CHECK(DWORD(ps11::ArgSource::TFactor) == D3DTA_TFACTOR);
    CHECK(DWORD(ps11::Blend::SrcAlphaSat) == D3DBLEND_SRCALPHASAT);
    CHECK(DWORD(ps11::Blend::InvBlendFactor) == D3DBLEND_INVBLENDFACTOR);
    CHECK(DWORD(ps11::BlendOp::Max) == D3DBLENDOP_MAX);
    CHECK(DWORD(ps11::CompareFunc::GreaterEqual) == D3DCMP_GREATEREQUAL);
    CHECK(DWORD(ps11::CullMode::Ccw) == D3DCULL_CCW);
    CHECK(DWORD(ps11::Filter::Linear) == D3DTEXF_LINEAR);
    CHECK(DWORD(ps11::TextureAddress::Border) == D3DTADDRESS_BORDER);
    CHECK(DWORD(ps11::TextureAddress::MirrorOnce) == D3DTADDRESS_MIRRORONCE);
    CHECK(ps11::kTtffProjected == DWORD(D3DTTFF_PROJECTED));
    CHECK(DWORD(ps11::kWriteA) == D3DCOLORWRITEENABLE_ALPHA);
}

TEST_CASE("device: DeviceState starts at D3D9's defaults", "[device]") {
    Device dev;
    const DeviceState& s = dev.state();
    // D3DTEXTURESTAGESTATETYPE reference: stage 0 MODULATE / SELECTARG1, the rest DISABLE.
    CHECK(s.stageState(0, D3DTSS_COLOROP) == D3DTOP_MODULATE);
    CHECK(s.stageState(0, D3DTSS_ALPHAOP) == D3DTOP_SELECTARG1);
    for (int i = 1; i < 8; ++i) {
        CHECK(s.stageState(i, D3DTSS_COLOROP) == D3DTOP_DISABLE);
        CHECK(s.stageState(i, D3DTSS_ALPHAOP) == D3DTOP_DISABLE);
    }
    for (int i = 0; i < 8; ++i) {
        CHECK(s.stageState(i, D3DTSS_COLORARG1) == D3DTA_TEXTURE);
        CHECK(s.stageState(i, D3DTSS_COLORARG2) == D3DTA_CURRENT);
        CHECK(s.stageState(i, D3DTSS_ALPHAARG1) == D3DTA_TEXTURE);
        CHECK(s.stageState(i, D3DTSS_ALPHAARG2) == D3DTA_CURRENT);
        CHECK(s.stageState(i, D3DTSS_COLORARG0) == D3DTA_CURRENT);
        CHECK(s.stageState(i, D3DTSS_ALPHAARG0) == D3DTA_CURRENT);
        CHECK(s.stageState(i, D3DTSS_RESULTARG) == D3DTA_CURRENT);
        CHECK(s.stageState(i, D3DTSS_TEXCOORDINDEX) == DWORD(i));
        CHECK(s.stageState(i, D3DTSS_TEXTURETRANSFORMFLAGS) == D3DTTFF_DISABLE);
        CHECK(s.stageStateFloat(i, D3DTSS_BUMPENVMAT00) == 0.0f);
        CHECK(s.stageStateFloat(i, D3DTSS_BUMPENVLSCALE) == 0.0f);
        CHECK(s.samplerState(i, D3DSAMP_ADDRESSU) == D3DTADDRESS_WRAP);
        CHECK(s.samplerState(i, D3DSAMP_ADDRESSV) == D3DTADDRESS_WRAP);
        CHECK(s.samplerState(i, D3DSAMP_ADDRESSW) == D3DTADDRESS_WRAP);
        CHECK(s.samplerState(i, D3DSAMP_BORDERCOLOR) == 0u);
        CHECK(s.samplerState(i, D3DSAMP_MAGFILTER) == D3DTEXF_POINT);
        CHECK(s.samplerState(i, D3DSAMP_MINFILTER) == D3DTEXF_POINT);
        CHECK(s.samplerState(i, D3DSAMP_MIPFILTER) == D3DTEXF_NONE);
        CHECK(s.samplerState(i, D3DSAMP_MAXANISOTROPY) == 1u);
        CHECK(s.textures[size_t(i)] == Handle::Null);
    }
    // D3DRENDERSTATETYPE reference page defaults.
    CHECK(s.renderState(D3DRS_SRCBLEND) == D3DBLEND_ONE);
    CHECK(s.renderState(D3DRS_DESTBLEND) == D3DBLEND_ZERO);
    CHECK(s.renderState(D3DRS_BLENDOP) == D3DBLENDOP_ADD);
    CHECK(s.renderState(D3DRS_ALPHABLENDENABLE) == 0u);
    CHECK(s.renderState(D3DRS_ALPHATESTENABLE) == 0u);
    CHECK(s.renderState(D3DRS_ALPHAFUNC) == D3DCMP_ALWAYS);
    CHECK(s.renderState(D3DRS_ALPHAREF) == 0u);
    CHECK(s.renderState(D3DRS_ZFUNC) == D3DCMP_LESSEQUAL);
    CHECK(s.renderState(D3DRS_ZWRITEENABLE) == 1u);
    CHECK(s.renderState(D3DRS_ZENABLE) == D3DZB_FALSE);  // no automatic depth buffer
    CHECK(s.renderState(D3DRS_CULLMODE) == D3DCULL_CCW);
    CHECK(s.renderState(D3DRS_SHADEMODE) == D3DSHADE_GOURAUD);
    CHECK(s.renderState(D3DRS_FILLMODE) == D3DFILL_SOLID);
    CHECK(s.renderState(D3DRS_COLORWRITEENABLE) == 0xFu);
    CHECK(s.renderState(D3DRS_TEXTUREFACTOR) == 0xFFFFFFFFu);
    CHECK(s.renderState(D3DRS_SCISSORTESTENABLE) == 0u);
    CHECK(s.renderState(D3DRS_FOGENABLE) == 0u);
    CHECK(s.renderState(D3DRS_FOGCOLOR) == 0u);
    CHECK(s.renderStateFloat(D3DRS_FOGEND) == 1.0f);
    CHECK(s.renderStateFloat(D3DRS_FOGDENSITY) == 1.0f);
    CHECK(s.renderState(D3DRS_LIGHTING) == 1u);
    CHECK(s.renderState(D3DRS_STENCILMASK) == 0xFFFFFFFFu);
    CHECK(s.renderState(D3DRS_BLENDFACTOR) == 0xFFFFFFFFu);
    CHECK(s.renderState(D3DRS_SRCBLENDALPHA) == D3DBLEND_ONE);
    CHECK(s.renderState(D3DRS_DESTBLENDALPHA) == D3DBLEND_ZERO);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            CHECK(s.world.m[r][c] == (r == c ? 1.0f : 0.0f));
            CHECK(s.texture[7].m[r][c] == (r == c ? 1.0f : 0.0f));
        }
    CHECK(s.psConstants[7][3] == 0.0f);
    CHECK(s.pixelShader == Handle::Null);
    CHECK(s.renderTarget == Handle::Null);
    CHECK(s.viewport.Width == 0);
}

TEST_CASE("device: DeviceState hash and equality", "[device]") {
    DeviceState a, b;
    CHECK(a == b);
    CHECK(a.hash() == b.hash());
    b.renderStates[D3DRS_SRCBLEND] = D3DBLEND_SRCALPHA;
    CHECK_FALSE(a == b);
    CHECK(a.hash() != b.hash());
    b = a;
    CHECK(a == b);
    b.psConstants[3][1] = -0.0f;  // bitwise: -0 differs from 0
    CHECK_FALSE(a == b);
    CHECK(a.hash() != b.hash());
    b = a;
    b.psConstants[0][0] = std::nanf("");
    DeviceState c = b;
    CHECK(b == c);  // a NaN equals itself, consistent with the hash
    CHECK(b.hash() == c.hash());
    std::unordered_set<DeviceState, DeviceStateHash> set{a, b, c};
    CHECK(set.size() == 2);
    b = a;
    b.stageStates[7][D3DTSS_TEXCOORDINDEX] = 0;
    CHECK_FALSE(a == b);
    b = a;
    b.scissor.right = 1;
    CHECK_FALSE(a == b);
}

TEST_CASE("device: DeviceState hash and equality over a part", "[device]") {
    const uint32_t ffp = DeviceState::FixedFunction;
    DeviceState a, b;
    CHECK(a.equal(b, ffp));
    CHECK(a.hash(ffp) == b.hash(ffp));
    CHECK(a.hash(DeviceState::AllFields) == a.hash());
    CHECK(a.hash(ffp) != a.hash());
    // Outside the part: sampler states, constants, the FVF, which texture is bound.
    b.samplerStates[2][D3DSAMP_MINFILTER] = D3DTEXF_LINEAR;
    b.psConstants[1][2] = 0.5f;
    b.fvf = 0x104;
    b.textures[0] = Handle(5);
    a.textures[0] = Handle(6);
    CHECK_FALSE(a == b);
    CHECK(a.equal(b, ffp));
    CHECK(a.hash(ffp) == b.hash(ffp));
    // Inside: stage states, render states, whether a stage has a texture.
    b = a;
    b.stageStates[1][D3DTSS_COLOROP] = D3DTOP_ADD;
    CHECK_FALSE(a.equal(b, ffp));
    CHECK(a.hash(ffp) != b.hash(ffp));
    b = a;
    b.renderStates[D3DRS_TEXTUREFACTOR] = 0x80808080u;
    CHECK_FALSE(a.equal(b, ffp));
    CHECK(a.hash(ffp) != b.hash(ffp));
    b = a;
    b.textures[3] = Handle(9);
    CHECK_FALSE(a.equal(b, ffp));
    CHECK(a.hash(ffp) != b.hash(ffp));
    CHECK(a.equal(b, DeviceState::RenderStates | DeviceState::StageStates));
    // Each part on its own.
    b = a;
    b.viewport.MaxZ = 0.5f;
    CHECK_FALSE(a.equal(b, DeviceState::ViewportScissor));
    CHECK(a.equal(b, DeviceState::AllFields & ~uint32_t(DeviceState::ViewportScissor)));
}

TEST_CASE("device: state setters, getters and their errors", "[device]") {
    Device dev;
    const DeviceState before = dev.state();

    SECTION("errors name the call and the argument and leave the state alone") {
        CHECK(dev.SetTextureStageState(9, D3DTSS_COLOROP, D3DTOP_ADD) == D3DERR_INVALIDCALL);
        CHECK(dev.lastError().message == "E4101 SetTextureStageState: stage 9 out of range 0..7");
        CHECK(dev.lastError().code == "E4101");
        CHECK(dev.SetTextureStageState(0, D3DTEXTURESTAGESTATETYPE(12), 1) == D3DERR_INVALIDCALL);
        CHECK(contains(dev.lastError().message, "unknown texture stage state 12"));
        CHECK(dev.SetRenderState(D3DRENDERSTATETYPE(10), 1) == D3DERR_INVALIDCALL);
        CHECK(contains(dev.lastError().message, "SetRenderState: unknown render state 10"));
        CHECK(dev.SetRenderState(D3DRENDERSTATETYPE(210), 1) == D3DERR_INVALIDCALL);
        CHECK(dev.SetSamplerState(8, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR) == D3DERR_INVALIDCALL);
        CHECK(contains(dev.lastError().message, "SetSamplerState: sampler 8 out of range 0..7"));
        CHECK(dev.SetSamplerState(0, D3DSAMPLERSTATETYPE(14), 0) == D3DERR_INVALIDCALL);
        CHECK(dev.SetTexture(8, Handle::Null) == D3DERR_INVALIDCALL);
        CHECK(dev.SetTexture(0, Handle(999)) == D3DERR_INVALIDCALL);
        CHECK(dev.lastError().code == "E4102");
        CHECK(dev.SetTransform(D3DTS_VIEW, nullptr) == D3DERR_INVALIDCALL);
        CHECK(dev.lastError().code == "E4103");
        D3DMATRIX m;
        CHECK(dev.SetTransform(D3DTRANSFORMSTATETYPE(4), &m) == D3DERR_INVALIDCALL);
        CHECK(dev.SetTransform(D3DTS_WORLDMATRIX(1), &m) == D3DERR_INVALIDCALL);
        D3DVIEWPORT9 vp{0, 0, 4, 4, 0, 1};
        CHECK(dev.SetViewport(&vp) == D3DERR_INVALIDCALL);  // no render target
        CHECK(dev.SetViewport(nullptr) == D3DERR_INVALIDCALL);
        CHECK(dev.SetScissorRect(nullptr) == D3DERR_INVALIDCALL);
        const float c[8] = {1, 2, 3, 4, 5, 6, 7, 8};
        CHECK(dev.SetPixelShaderConstantF(7, c, 2) == D3DERR_INVALIDCALL);
        CHECK(contains(dev.lastError().message, "c7 + 2"));
        CHECK(dev.SetPixelShaderConstantF(0xFFFFFFFFu, c, 2) == D3DERR_INVALIDCALL);
        CHECK(dev.SetPixelShaderConstantF(0, nullptr, 1) == D3DERR_INVALIDCALL);
        CHECK(dev.SetRenderTarget(1, Handle::Null) == D3DERR_INVALIDCALL);
        CHECK(dev.SetRenderTarget(0, Handle::Null) == D3DERR_INVALIDCALL);
        CHECK(dev.SetDepthStencilSurface(Handle(77)) == D3DERR_INVALIDCALL);
        CHECK(dev.SetPixelShader(Handle(5)) == D3DERR_INVALIDCALL);
        DWORD v;
        CHECK(dev.GetRenderState(D3DRS_ZFUNC, nullptr) == D3DERR_INVALIDCALL);
        CHECK(dev.GetTextureStageState(8, D3DTSS_COLOROP, &v) == D3DERR_INVALIDCALL);
        Handle h;
        CHECK(dev.GetRenderTarget(0, &h) == D3DERR_NOTFOUND);
        CHECK(dev.state() == before);
    }

    SECTION("setters store D3D values, floats as bit patterns") {
        CHECK(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_SRCALPHA) == D3D_OK);
        CHECK(dev.lastError().hr == D3D_OK);
        CHECK(dev.lastError().message.empty());
        CHECK(dev.state().renderState(D3DRS_SRCBLEND) == D3DBLEND_SRCALPHA);
        CHECK(dev.SetRenderState(D3DRS_FOGSTART, floatBits(0.25f)) == D3D_OK);
        CHECK(dev.state().renderStateFloat(D3DRS_FOGSTART) == 0.25f);
        CHECK(dev.SetTextureStageState(3, D3DTSS_BUMPENVMAT10, floatBits(-0.5f)) == D3D_OK);
        CHECK(dev.state().stageStateFloat(3, D3DTSS_BUMPENVMAT10) == -0.5f);
        DWORD v = 0;
        CHECK(dev.GetTextureStageState(3, D3DTSS_BUMPENVMAT10, &v) == D3D_OK);
        CHECK(v == floatBits(-0.5f));
        CHECK(dev.SetTextureStageState(1, D3DTSS_COLORARG1, D3DTA_TFACTOR | D3DTA_COMPLEMENT) == D3D_OK);
        CHECK(dev.state().stageState(1, D3DTSS_COLORARG1) == 0x13u);
        CHECK(dev.SetSamplerState(7, D3DSAMP_ADDRESSU, D3DTADDRESS_BORDER) == D3D_OK);
        CHECK(dev.SetSamplerState(7, D3DSAMP_BORDERCOLOR, 0x80FF0000) == D3D_OK);
        CHECK(dev.GetSamplerState(7, D3DSAMP_BORDERCOLOR, &v) == D3D_OK);
        CHECK(v == 0x80FF0000u);
        D3DMATRIX m;
        m.m[3][0] = 5.0f;
        CHECK(dev.SetTransform(D3DTS_WORLD, &m) == D3D_OK);
        CHECK(dev.SetTransform(D3DTS_TEXTURE7, &m) == D3D_OK);
        D3DMATRIX back;
        CHECK(dev.GetTransform(D3DTS_TEXTURE7, &back) == D3D_OK);
        CHECK(back.m[3][0] == 5.0f);
        CHECK(dev.state().world.m[3][0] == 5.0f);
        const float c[8] = {1, 2, 3, 4, -5, 6, 7, 8};
        CHECK(dev.SetPixelShaderConstantF(6, c, 2) == D3D_OK);
        CHECK(dev.state().psConstants[7][0] == -5.0f);  // stored unclamped
        float out[4];
        CHECK(dev.GetPixelShaderConstantF(6, out, 1) == D3D_OK);
        CHECK(out[3] == 4.0f);
        CHECK(dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_TEX1) == D3D_OK);
        CHECK(dev.state().fvf == 0x144u);
        RECT sc{1, 2, 3, 4};
        CHECK(dev.SetScissorRect(&sc) == D3D_OK);
        RECT sb;
        CHECK(dev.GetScissorRect(&sb) == D3D_OK);
        CHECK(sb == sc);
        CHECK_FALSE(dev.state() == before);
    }

    SECTION("SetRenderTarget resets the viewport and scissor; SetViewport is checked against it") {
        Handle rt{}, tex{}, level{};
        REQUIRE(dev.CreateRenderTarget(64, 32, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);
        RECT sc{1, 2, 3, 4};
        REQUIRE(dev.SetScissorRect(&sc) == D3D_OK);
        REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
        CHECK(dev.state().viewport.Width == 64);
        CHECK(dev.state().viewport.Height == 32);
        CHECK(dev.state().viewport.MaxZ == 1.0f);
        CHECK(dev.state().scissor == RECT{0, 0, 64, 32});
        Handle got{};
        CHECK(dev.GetRenderTarget(0, &got) == D3D_OK);
        CHECK(got == rt);
        D3DVIEWPORT9 vp{32, 0, 33, 32, 0, 1};
        CHECK(dev.SetViewport(&vp) == D3DERR_INVALIDCALL);
        CHECK(contains(dev.lastError().message, "outside the 64x32 render target"));
        vp = {32, 16, 32, 16, 0.25f, 0.75f};
        CHECK(dev.SetViewport(&vp) == D3D_OK);
        vp.MinZ = 0.9f;
        CHECK(dev.SetViewport(&vp) == D3DERR_INVALIDCALL);
        CHECK(dev.state().viewport.MinZ == 0.25f);
        // A texture level works as a target only with D3DUSAGE_RENDERTARGET.
        REQUIRE(dev.CreateTexture(8, 8, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        CHECK(dev.SetRenderTarget(0, level) == D3DERR_INVALIDCALL);
        CHECK(dev.lastError().code == "E4104");
        CHECK(dev.SetRenderTarget(0, tex) == D3DERR_INVALIDCALL);  // a texture, not a surface
        CHECK(dev.lastError().code == "E4102");
        CHECK(dev.SetDepthStencilSurface(rt) == D3DERR_INVALIDCALL);
        Handle ds{};
        REQUIRE(dev.CreateDepthStencilSurface(64, 32, D3DFMT_D24S8, &ds) == D3D_OK);
        CHECK(dev.SetDepthStencilSurface(ds) == D3D_OK);
        CHECK(dev.SetDepthStencilSurface(Handle::Null) == D3D_OK);
        CHECK(dev.SetTexture(0, rt) == D3DERR_INVALIDCALL);  // a surface is not a texture
        CHECK(dev.SetTexture(0, tex) == D3D_OK);
        CHECK(dev.state().textures[0] == tex);
    }
}

TEST_CASE("device: resource creation rules and refusals", "[device]") {
    Device dev;
    Handle h{};
    CHECK(dev.CreateTexture(0, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) == D3DERR_INVALIDCALL);
    CHECK(dev.CreateTexture(16385, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "beyond 16384 per side"));
    CHECK(dev.CreateTexture(4, 4, 1, 0, D3DFORMAT(23), D3DPOOL_MANAGED, &h) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().message == "E4104 CreateTexture: format format 23 not taken for textures");
    CHECK(dev.CreateTexture(4, 4, 1, 0, D3DFMT_D16, D3DPOOL_MANAGED, &h) == D3DERR_INVALIDCALL);
    CHECK(dev.CreateTexture(4, 4, 1, D3DUSAGE_RENDERTARGET, D3DFMT_L8, D3DPOOL_DEFAULT, &h) == D3DERR_INVALIDCALL);
    // The formats a refusal lists come from the format rows, in row order.
    CHECK(dev.lastError().message ==
          "E4104 CreateTexture: format L8 cannot be a render target (A8R8G8B8, X8R8G8B8, "
          "A16B16G16R16F, A32B32G32R32F, R32F)");
    CHECK(dev.CreateDepthStencilSurface(4, 4, D3DFMT_A8R8G8B8, &h) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().message ==
          "E4104 CreateDepthStencilSurface: format A8R8G8B8 is not a depth format (D16, "
          "D16_LOCKABLE, D24S8, D24X8, D32, D32F_LOCKABLE)");
    CHECK(dev.CreateTexture(4, 4, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) ==
          D3DERR_INVALIDCALL);
    CHECK(dev.CreateTexture(4, 4, 1, D3DUSAGE_DYNAMIC, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) == D3DERR_INVALIDCALL);
    CHECK(dev.CreateTexture(4, 4, 2, D3DUSAGE_AUTOGENMIPMAP, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) ==
          D3DERR_INVALIDCALL);
    CHECK(dev.CreateTexture(4, 4, 0, D3DUSAGE_AUTOGENMIPMAP, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &h) ==
          D3DERR_INVALIDCALL);
    CHECK(dev.CreateTexture(4, 4, 4, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) == D3DERR_INVALIDCALL);  // 4x4 has 3
    CHECK(dev.CreateTexture(4, 4, 1, 0x80000000u, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) == D3DERR_INVALIDCALL);
    CHECK(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL(7), &h) == D3DERR_INVALIDCALL);
    CHECK(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, nullptr) == D3DERR_INVALIDCALL);
    CHECK(dev.CreateVolumeTexture(4, 4, 2049, 1, 0, D3DFMT_L8, D3DPOOL_MANAGED, &h) == D3DERR_INVALIDCALL);
    CHECK(dev.CreateVolumeTexture(4, 4, 4, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &h) ==
          D3DERR_INVALIDCALL);
    CHECK(dev.CreateRenderTarget(4, 4, D3DFMT_V8U8, 0, &h) == D3DERR_INVALIDCALL);
    CHECK(dev.CreateDepthStencilSurface(4, 4, D3DFMT_A8R8G8B8, &h) == D3DERR_INVALIDCALL);
    CHECK(dev.CreateOffscreenPlainSurface(4, 4, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) == D3DERR_INVALIDCALL);

    // Huge requests are refused by arithmetic before anything is allocated: 16384^2 texels of
    // 16 bytes = 4 GiB; 16384^2 A8R8G8B8 with its chain = 1 GiB + 1/3 GiB > 1 GiB.
    CHECK(dev.CreateTexture(16384, 16384, 1, 0, D3DFMT_A32B32G32R32F, D3DPOOL_MANAGED, &h) == D3DERR_OUTOFVIDEOMEMORY);
    CHECK(dev.lastError().code == "E4105");
    CHECK(contains(dev.lastError().message, "4294967296 bytes"));
    CHECK(dev.CreateTexture(16384, 16384, 0, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) == D3DERR_OUTOFVIDEOMEMORY);
    CHECK(dev.CreateVolumeTexture(2048, 2048, 2048, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) ==
          D3DERR_OUTOFVIDEOMEMORY);
    CHECK(dev.CreateRenderTarget(16384, 16384, D3DFMT_A16B16G16R16F, 0, &h) == D3DERR_OUTOFVIDEOMEMORY);
    DeviceOptions small;
    small.maxResourceBytes = 1000;
    Device tiny(small);
    CHECK(tiny.CreateTexture(16, 16, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) == D3DERR_OUTOFVIDEOMEMORY);
    CHECK(tiny.CreateTexture(15, 16, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &h) == D3D_OK);  // 960 bytes

    // A texture the sampler's copy cannot hold is refused when sampled, not allocated: signed
    // formats take 64 bytes per texel there (docs/textures.md), and a full 4096x4096 chain has
    // (4^13 - 1) / 3 = 22369621 texels, 1431655744 bytes > 2^30.
    Handle big{};
    REQUIRE(dev.CreateTexture(4096, 4096, 0, 0, D3DFMT_V8U8, D3DPOOL_MANAGED, &big) == D3D_OK);  // 43 MiB
    CHECK(dev.sampledTexture(big) == nullptr);
    CHECK(dev.lastError().hr == D3DERR_OUTOFVIDEOMEMORY);
    CHECK(contains(dev.lastError().message, "texture needs 1431655744 bytes (22369621 texels of V8U8)"));
    CHECK(dev.Release(big) == D3D_OK);

    // Levels: 0 = the full chain; levels and their sizes.
    REQUIRE(dev.CreateTexture(8, 2, 0, 0, D3DFMT_L8, D3DPOOL_MANAGED, &h) == D3D_OK);
    CHECK(dev.GetLevelCount(h) == 4);  // 8x2, 4x1, 2x1, 1x1
    D3DSURFACE_DESC desc;
    CHECK(dev.GetLevelDesc(h, 2, &desc) == D3D_OK);
    CHECK(desc.Width == 2);
    CHECK(desc.Height == 1);
    CHECK(desc.Format == D3DFMT_L8);
    CHECK(desc.Pool == D3DPOOL_MANAGED);
    CHECK(dev.GetLevelDesc(h, 4, &desc) == D3DERR_INVALIDCALL);
    Handle s1{}, s1again{};
    CHECK(dev.GetSurfaceLevel(h, 1, &s1) == D3D_OK);
    CHECK(dev.GetSurfaceLevel(h, 1, &s1again) == D3D_OK);
    CHECK(s1 == s1again);
    CHECK(dev.GetDesc(s1, &desc) == D3D_OK);
    CHECK(desc.Width == 4);
    CHECK(dev.GetSurfaceLevel(h, 4, &s1) == D3DERR_INVALIDCALL);
    CHECK(dev.GetLevelCount(Handle(12345)) == 0);
    CHECK(dev.lastError().hr == D3DERR_INVALIDCALL);
    CHECK(dev.GetLevelCount(s1) == 0);  // a surface has no levels
}

TEST_CASE("device: pixel shaders from tokens and text", "[device]") {
    Device dev;
    Handle ps{}, ps2{};
    const char* text = "ps_1_1\ntex t0\nmul r0, t0, v0\n";
    REQUIRE(dev.CreatePixelShaderFromText(text, &ps) == D3D_OK);
    const ps11::Program* program = dev.pixelShaderProgram(ps);
    REQUIRE(program);
    CHECK(program->version.minor == 1);
    std::vector<uint32_t> tokens = ps11::encode(*program);
    REQUIRE(dev.CreatePixelShader(tokens.data(), &ps2) == D3D_OK);  // scanned to the end token
    CHECK(ps2 != ps);
    CHECK(dev.pixelShaderProgram(ps2)->instructions.size() == program->instructions.size());
    CHECK(dev.SetPixelShader(ps2) == D3D_OK);
    CHECK(dev.state().pixelShader == ps2);

    // A comment whose payload holds 0x0000ffff does not end the scan early.
    std::vector<uint32_t> withComment = {tokens[0], 0x0001FFFEu, 0x0000FFFFu};
    withComment.insert(withComment.end(), tokens.begin() + 1, tokens.end());
    Handle ps3{};
    CHECK(dev.CreatePixelShader(withComment.data(), &ps3) == D3D_OK);

    const DWORD ps20[] = {D3DPS_VERSION(2, 0), 0x0000FFFF};
    CHECK(dev.CreatePixelShader(ps20, &ps3) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().message ==
          "E4107 CreatePixelShader: version ps_2_0 not taken (hardware geforce4 runs ps_1_1 ... ps_1_3)");
    const DWORD vs[] = {0xFFFE0101u, 0x0000FFFF};
    CHECK(dev.CreatePixelShader(vs, &ps3) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "vertex shader"));
    const DWORD bad[] = {D3DPS_VERSION(1, 1), 0x00001234u, 0x0000FFFF};
    CHECK(dev.CreatePixelShader(bad, &ps3) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4107");
    CHECK(dev.CreatePixelShader(std::span<const DWORD>(tokens.data(), 1), &ps3) == D3DERR_INVALIDCALL);
    CHECK(dev.CreatePixelShader(static_cast<const DWORD*>(nullptr), &ps3) == D3DERR_INVALIDCALL);
    CHECK(dev.CreatePixelShader(tokens.data(), nullptr) == D3DERR_INVALIDCALL);
    // Validation failures carry the validator's diagnostic; a register the version lacks is the
    // assembler's (P1114) in text and the validator's (P2030) in tokens.
    CHECK(dev.CreatePixelShaderFromText("ps_1_1\nmov r2, v0\nmov r0, v0\n", &ps3) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "P1114"));
    const DWORD r2Tokens[] = {D3DPS_VERSION(1, 1), 0x00000001, 0x800f0002, 0x90e40000, 0x0000FFFF};
    CHECK(dev.CreatePixelShader(r2Tokens, &ps3) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "P2030"));
    CHECK(dev.CreatePixelShaderFromText("ps_1_1\nmov r0, v0.g\n", &ps3) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "P2060"));
    CHECK(dev.CreatePixelShaderFromText("ps_2_0\nmov r0, v0\n", &ps3) == D3DERR_INVALIDCALL);
    // D3DCAPS9::PixelShaderVersion is the hardware class's: the default 1.1-class card runs up
    // to ps_1_3, the 1.4-class card ps_1_4, GeForce3 only ps_1_1.
    CHECK(dev.CreatePixelShaderFromText("ps_1_4\ntexld r0, t0\n", &ps3) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().message ==
          "E4107 CreatePixelShaderFromText: version ps_1_4 not taken (hardware geforce4 runs ps_1_1 ... ps_1_3)");
    {
        DeviceOptions r200;
        r200.hardware = ps11::findHardware("radeon8500");
        Device dev14(r200);
        Handle ps14{};
        CHECK(dev14.CreatePixelShaderFromText("ps_1_4\ntexld r0, t0\n", &ps14) == D3D_OK);
        CHECK(dev14.hardware().maxValue == 8.0f);
        CHECK(dev14.hardware().precision == ps11::Precision::Fx12);
        DeviceOptions gf3;
        gf3.hardware = ps11::findHardware("geforce3");
        Device dev11(gf3);
        CHECK(dev11.CreatePixelShaderFromText("ps_1_1\nmov r0, v0\n", &ps14) == D3D_OK);
        CHECK(dev11.CreatePixelShaderFromText("ps_1_2\nmov r0, v0\n", &ps14) == D3DERR_INVALIDCALL);
        CHECK(dev11.CreatePixelShader(tokens.data(), &ps14) == D3D_OK);  // tokens: ps_1_1
    }

    // Release unbinds.
    CHECK(dev.Release(ps2) == D3D_OK);
    CHECK(dev.state().pixelShader == Handle::Null);
    CHECK(dev.SetPixelShader(ps2) == D3DERR_INVALIDCALL);
    CHECK(dev.SetPixelShader(Handle::Null) == D3D_OK);
}

TEST_CASE("device: Release, handles and draws", "[device]") {
    Device dev;
    Handle tex{}, level{}, rt{}, ds{};
    REQUIRE(dev.CreateTexture(4, 4, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(4, 4, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(4, 4, D3DFMT_D16, &ds) == D3D_OK);
    REQUIRE(dev.SetTexture(3, tex) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(ds) == D3D_OK);
    CHECK(dev.Release(level) == D3DERR_INVALIDCALL);  // owned by the texture
    CHECK(dev.Release(tex) == D3D_OK);
    CHECK(dev.state().textures[3] == Handle::Null);
    CHECK(dev.state().renderTarget == Handle::Null);
    D3DSURFACE_DESC d;
    CHECK(dev.GetDesc(level, &d) == D3DERR_INVALIDCALL);
    CHECK(dev.Release(tex) == D3DERR_INVALIDCALL);
    CHECK(dev.Release(ds) == D3D_OK);
    CHECK(dev.state().depthStencil == Handle::Null);
    CHECK(dev.sampledTexture(rt) == nullptr);  // a surface is not a texture

    // A draw after the render target was released has no target (tests/test_draw.cpp has the rest).
    const float v[12] = {};
    CHECK(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 1, v, 16) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().message == "E4109 DrawPrimitiveUP: no render target");
}

TEST_CASE("device: every E41xx code in emu/ is documented", "[device][docs]") {
    namespace fs = std::filesystem;
    const std::string doc = slurp(fs::path(PS11_SOURCE_DIR) / "docs" / "diagnostics.md");
    REQUIRE_FALSE(doc.empty());
    std::set<std::string> seen, missing;
    for (const auto& entry : fs::directory_iterator(fs::path(PS11_SOURCE_DIR) / "emu")) {
        if (entry.path().extension() != ".cpp" && entry.path().extension() != ".h") continue;
        const std::string src = slurp(entry.path());
        // String literals "E4ddd".
        for (size_t at = src.find("\"E4"); at != std::string::npos; at = src.find("\"E4", at + 1)) {
            if (at + 6 >= src.size() || src[at + 6] != '"') continue;
            const std::string c = src.substr(at + 1, 5);
            if (c.find_first_not_of("0123456789", 2) != std::string::npos) continue;
            seen.insert(c);
            if (doc.find("| " + c + " |") == std::string::npos) missing.insert(c);
        }
    }
    CHECK(seen.size() >= 10);
    std::string list;
    for (const std::string& c : missing) list += c + " ";
    INFO("undocumented codes: " << list);
    CHECK(missing.empty());
}
