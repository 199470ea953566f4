// Unit tests of the emu device (slice 1): D3D9 constants, DeviceState defaults and hashing,
// every call's success and error paths, Lock/Unlock layouts of every format, Clear,
// StretchRect, GetRenderTargetData, mip generation. Expected values come from the D3D9
// documentation's formulas, worked out by hand in the comments.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <unordered_set>
#include <vector>

#include "emu/blit.h"
#include "emu/device.h"
#include "ps11/assembler.h"
#include "ps11/encoder.h"
#include "ps11/executor.h"
#include "ps11/testfile.h"
#include "ps11/texture_sampler.h"

using namespace emu;

namespace {

// A lockable render target filled from a function of (x, y) giving 0xAARRGGBB.
template <class F>
Handle makeTarget(Device& dev, UINT w, UINT h, F colour, D3DFORMAT fmt = D3DFMT_A8R8G8B8) {
    Handle rt{};
    REQUIRE(dev.CreateRenderTarget(w, h, fmt, 1, &rt) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(rt, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < h; ++y)
        for (UINT x = 0; x < w; ++x) {
            const uint32_t c = colour(x, y);
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, &c, 4);
        }
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);
    return rt;
}

uint32_t readPixel(Device& dev, Handle surface, UINT x, UINT y) {
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(surface, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    uint32_t c;
    std::memcpy(&c, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, 4);
    REQUIRE(dev.UnlockRect(surface) == D3D_OK);
    return c;
}

float readFloat(Device& dev, Handle surface, UINT x, UINT y, UINT channel = 0) {
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(surface, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    float f;
    D3DSURFACE_DESC desc;
    REQUIRE(dev.GetDesc(surface, &desc) == D3D_OK);
    const UINT bytes = desc.Format == D3DFMT_R32F ? 4 : 16;
    std::memcpy(&f, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * bytes + 4 * channel, 4);
    REQUIRE(dev.UnlockRect(surface) == D3D_OK);
    return f;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

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

namespace {

struct FormatCase {
    D3DFORMAT format;
    UINT bytes;
    std::vector<uint8_t> texel;  // in D3D memory order
    std::array<float, 4> value;  // what the sampler reads (r g b a)
};

std::vector<uint8_t> wordBytes(uint32_t w, UINT n) {
    std::vector<uint8_t> b;
    for (UINT i = 0; i < n; ++i) b.push_back(uint8_t(w >> (8 * i)));
    return b;
}

std::vector<uint8_t> floatBytes(std::initializer_list<float> fs) {
    std::vector<uint8_t> b;
    for (float f : fs) {
        uint8_t t[4];
        std::memcpy(t, &f, 4);
        b.insert(b.end(), t, t + 4);
    }
    return b;
}

}  // namespace

TEST_CASE("device: LockRect hands out D3D's memory layout for every format", "[device]") {
    // Each texel written as D3D lays it out (little-endian words, d3d9types.h channel order from
    // the most significant bit) and the value the sampler must then read (ps1x-spec §6.4:
    // missing channels 1, A8's rgb 0; signed channels b/den clamped to [-1, 1]).
    const std::vector<FormatCase> cases = {
        // 0x80FF4000: A 0x80, R 0xFF, G 0x40, B 0x00.
        {D3DFMT_A8R8G8B8, 4, wordBytes(0x80FF4000u, 4), {1.0f, float(64 / 255.0), 0.0f, float(128 / 255.0)}},
        {D3DFMT_X8R8G8B8,
         4,
         wordBytes(0x00102030u, 4),
         {float(16 / 255.0), float(32 / 255.0), float(48 / 255.0), 1.0f}},
        {D3DFMT_A8, 1, {0x7F}, {0, 0, 0, float(127 / 255.0)}},
        {D3DFMT_L8, 1, {0x33}, {float(51 / 255.0), float(51 / 255.0), float(51 / 255.0), 1.0f}},
        // A8L8 0x8040: L low byte 0x40, A high byte 0x80.
        {D3DFMT_A8L8,
         2,
         wordBytes(0x8040u, 2),
         {float(64 / 255.0), float(64 / 255.0), float(64 / 255.0), float(128 / 255.0)}},
        // V8U8 0x7F81: U = 0x81 = -127 -> -1, V = 127 -> 1.
        {D3DFMT_V8U8, 2, wordBytes(0x7F81u, 2), {-1.0f, 1.0f, 1.0f, 1.0f}},
        // L6V5U5: U = 3 (3/15), V = 0b11011 = -5 (-5/15), L = 21 (21/63): 21<<10 | 27<<5 | 3.
        {D3DFMT_L6V5U5,
         2,
         wordBytes((21u << 10) | (27u << 5) | 3u, 2),
         {float(3.0 / 15), float(-5.0 / 15), float(21.0 / 63), 1.0f}},
        // X8L8V8U8 0xFF8040C0: U = 0xC0 = -64, V = 64, L = 128 (unsigned), X ignored.
        {D3DFMT_X8L8V8U8,
         4,
         wordBytes(0xFF8040C0u, 4),
         {float(-64.0 / 127), float(64.0 / 127), float(128.0 / 255), 1.0f}},
        // Q8W8V8U8 0x7F8001FF: U = -1, V = 1, W = -128 (clamped to -1), Q = 127.
        {D3DFMT_Q8W8V8U8, 4, wordBytes(0x7F8001FFu, 4), {float(-1.0 / 127), float(1.0 / 127), -1.0f, 1.0f}},
        // V16U16 0x80017FFF: U = 32767 -> 1, V = -32767 -> -1.
        {D3DFMT_V16U16, 4, wordBytes(0x80017FFFu, 4), {1.0f, -1.0f, 1.0f, 1.0f}},
        {D3DFMT_R32F, 4, floatBytes({0.25f}), {0.25f, 1.0f, 1.0f, 1.0f}},
        // A16B16G16R16F: halves in memory order R G B A: 0.5 = 0x3800, -2 = 0xC000, 1 = 0x3C00,
        // 0.25 = 0x3400.
        {D3DFMT_A16B16G16R16F, 8, {0x00, 0x38, 0x00, 0xC0, 0x00, 0x3C, 0x00, 0x34}, {0.5f, -2.0f, 1.0f, 0.25f}},
        {D3DFMT_A32B32G32R32F, 16, floatBytes({0.1f, 2.0f, -3.0f, 0.5f}), {0.1f, 2.0f, -3.0f, 0.5f}},
    };
    for (const FormatCase& fc : cases) {
        INFO("format " << formatName(fc.format));
        Device dev;
        Handle tex{};
        REQUIRE(dev.CreateTexture(3, 2, 1, 0, fc.format, D3DPOOL_MANAGED, &tex) == D3D_OK);
        D3DLOCKED_RECT lr;
        REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
        // Pitch: 3 texels rounded up to a DWORD multiple.
        CHECK(lr.Pitch == int32_t((3 * fc.bytes + 3) / 4 * 4));
        auto* base = static_cast<uint8_t*>(lr.pBits);
        std::memcpy(base + 1 * lr.Pitch + 2 * fc.bytes, fc.texel.data(), fc.bytes);
        REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
        std::shared_ptr<const ps11::Texture> t = dev.sampledTexture(tex);
        REQUIRE(t);
        const ps11::Vec4 v = t->texelValue(0, 2, 1);
        for (size_t c = 0; c < 4; ++c) CHECK(v[c] == fc.value[c]);
        // A sub-rectangle lock points at its first texel.
        RECT r{2, 1, 3, 2};
        REQUIRE(dev.LockRect(tex, 0, &lr, &r, D3DLOCK_READONLY) == D3D_OK);
        CHECK(std::memcmp(lr.pBits, fc.texel.data(), fc.bytes) == 0);
        REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    }
    // fx8 grid of a signed texel: round_half_even(b * 255 / 127) (docs/precision.md "Inputs").
    Device dev;
    Handle tex{};
    REQUIRE(dev.CreateTexture(1, 1, 1, 0, D3DFMT_V8U8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    static_cast<uint8_t*>(lr.pBits)[0] = 0x81;  // U = -127
    static_cast<uint8_t*>(lr.pBits)[1] = 0x20;  // V = 32 -> 32 * 255 / 127 = 64.25 -> 64
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    auto g = dev.sampledTexture(tex)->texelGrid(0, 0, 0, 0, ps11::Precision::Fx8);
    CHECK(g[0] == -255);
    CHECK(g[1] == 64);
}

TEST_CASE("device: the TextureSampler reads a device texture as bound", "[device]") {
    Device dev;
    Handle tex{};
    REQUIRE(dev.CreateTexture(4, 2, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < 2; ++y)
        for (UINT x = 0; x < 4; ++x) {
            const uint32_t c = 0xFF000000u | (40 * x + 100 * y) << 16 | 7u;
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, &c, 4);
        }
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    ps11::TextureSampler sampler;
    REQUIRE(sampler.bind(0, dev.sampledTexture(tex)));
    // Point sampling at the centre of texel (2, 1): u = 2.5/4, v = 1.5/2 (ps1x-spec §6.2).
    const float u = 2.5f / 4, v = 1.5f / 2;
    int32_t r = 0, g = 0, b = 0, a = 0;
    ps11::SampleRequest req;
    req.count = 1;
    req.u = &u;
    req.v = &v;
    ps11::SampleResult out;
    out.grid[0] = &r, out.grid[1] = &g, out.grid[2] = &b, out.grid[3] = &a;
    sampler.sample(req, out);
    CHECK(r == 180);  // 40 * 2 + 100
    CHECK(g == 0);
    CHECK(b == 7);
    CHECK(a == 255);
}

TEST_CASE("device: lock rules", "[device]") {
    Device dev;
    Handle def{}, man{}, dyn{}, rt{}, rtLock{}, ds{}, dsLock{}, level{};
    REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &def) == D3D_OK);
    REQUIRE(dev.CreateTexture(4, 4, 2, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &man) == D3D_OK);
    REQUIRE(dev.CreateTexture(4, 4, 1, D3DUSAGE_DYNAMIC, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &dyn) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(4, 4, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(4, 4, D3DFMT_A8R8G8B8, 1, &rtLock) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(4, 4, D3DFMT_D24S8, &ds) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(4, 4, D3DFMT_D16_LOCKABLE, &dsLock) == D3D_OK);
    D3DLOCKED_RECT lr;
    // D3D9: DEFAULT-pool resources lock only with DYNAMIC; render targets only if created lockable;
    // depth only in the _LOCKABLE formats.
    CHECK(dev.LockRect(def, 0, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4106");
    CHECK(dev.LockRect(dyn, 0, &lr, nullptr, 0) == D3D_OK);
    CHECK(dev.UnlockRect(dyn, 0) == D3D_OK);
    CHECK(dev.LockRect(rt, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.LockRect(rtLock, &lr, nullptr, 0) == D3D_OK);
    CHECK(dev.UnlockRect(rtLock) == D3D_OK);
    CHECK(dev.LockRect(ds, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.LockRect(dsLock, &lr, nullptr, 0) == D3D_OK);
    CHECK(lr.Pitch == 8);
    CHECK(dev.UnlockRect(dsLock) == D3D_OK);
    // Twice, unlock without lock, bad level, bad rect, null out.
    CHECK(dev.LockRect(man, 1, &lr, nullptr, 0) == D3D_OK);
    CHECK(lr.Pitch == 8);
    CHECK(dev.LockRect(man, 1, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "already locked"));
    CHECK(dev.UnlockRect(man, 1) == D3D_OK);
    CHECK(dev.UnlockRect(man, 1) == D3DERR_INVALIDCALL);
    CHECK(dev.LockRect(man, 2, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    RECT out{2, 2, 5, 3};
    CHECK(dev.LockRect(man, 0, &lr, &out, 0) == D3DERR_INVALIDCALL);
    RECT empty{2, 2, 2, 3};
    CHECK(dev.LockRect(man, 0, &lr, &empty, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.LockRect(man, 0, nullptr, nullptr, 0) == D3DERR_INVALIDCALL);
    RECT r{1, 2, 3, 4};
    D3DLOCKED_RECT whole;
    REQUIRE(dev.LockRect(man, 0, &whole, nullptr, D3DLOCK_READONLY) == D3D_OK);
    REQUIRE(dev.UnlockRect(man, 0) == D3D_OK);
    REQUIRE(dev.LockRect(man, 0, &lr, &r, 0) == D3D_OK);
    CHECK(static_cast<uint8_t*>(lr.pBits) - static_cast<uint8_t*>(whole.pBits) == 2 * 16 + 1 * 4);
    REQUIRE(dev.UnlockRect(man, 0) == D3D_OK);
    // A level's surface shares the level's lock.
    REQUIRE(dev.GetSurfaceLevel(man, 0, &level) == D3D_OK);
    REQUIRE(dev.LockRect(level, &lr, nullptr, 0) == D3D_OK);
    CHECK(dev.LockRect(man, 0, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.UnlockRect(man, 0) == D3D_OK);
    CHECK(dev.LockRect(man, &lr, nullptr, 0) == D3DERR_INVALIDCALL);  // a texture handle is not a surface
    CHECK(dev.LockBox(man, 0, nullptr, nullptr, 0) == D3DERR_INVALIDCALL);
}

TEST_CASE("device: volume textures lock as boxes", "[device]") {
    Device dev;
    Handle vol{};
    REQUIRE(dev.CreateVolumeTexture(3, 2, 4, 0, 0, D3DFMT_L8, D3DPOOL_MANAGED, &vol) == D3D_OK);
    CHECK(dev.GetLevelCount(vol) == 3);  // 3x2x4, 1x1x2, 1x1x1
    D3DLOCKED_BOX lb;
    REQUIRE(dev.LockBox(vol, 0, &lb, nullptr, 0) == D3D_OK);
    CHECK(lb.RowPitch == 4);
    CHECK(lb.SlicePitch == 8);
    auto* p = static_cast<uint8_t*>(lb.pBits);
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 3; ++x) p[z * 8 + y * 4 + x] = uint8_t(100 * z + 10 * y + x);
    REQUIRE(dev.UnlockBox(vol, 0) == D3D_OK);
    D3DBOX box{1, 1, 3, 2, 2, 4};
    REQUIRE(dev.LockBox(vol, 0, &lb, &box, D3DLOCK_READONLY) == D3D_OK);
    CHECK(static_cast<uint8_t*>(lb.pBits)[0] == 211);
    CHECK(static_cast<uint8_t*>(lb.pBits)[lb.SlicePitch] == uint8_t(311));  // 100 * 3 + 11, wrapped to a byte
    REQUIRE(dev.UnlockBox(vol, 0) == D3D_OK);
    D3DBOX bad{0, 0, 3, 2, 0, 5};
    CHECK(dev.LockBox(vol, 0, &lb, &bad, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.LockBox(vol, 3, &lb, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.UnlockBox(vol, 1) == D3DERR_INVALIDCALL);
    D3DLOCKED_RECT lr;
    CHECK(dev.LockRect(vol, 0, &lr, nullptr, 0) == D3DERR_INVALIDCALL);  // not a 2D texture
    Handle s{};
    CHECK(dev.GetSurfaceLevel(vol, 0, &s) == D3DERR_INVALIDCALL);
    // Levels 1 and 2 hold zeros (not written); level 0 reaches the sampler as a volume.
    auto t = dev.sampledTexture(vol);
    REQUIRE(t);
    CHECK(t->isVolume());
    CHECK(t->texelValue(0, 2, 1, 3)[0] == float((312 & 0xff) / 255.0));
    CHECK(dev.SetTexture(2, vol) == D3D_OK);
}

TEST_CASE("device: Clear honours viewport, scissor and rects", "[device]") {
    Device dev;
    Handle rt = makeTarget(dev, 4, 4, [](UINT, UINT) { return 0u; });
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    auto count = [&](uint32_t colour) {
        int n = 0;
        for (UINT y = 0; y < 4; ++y)
            for (UINT x = 0; x < 4; ++x) n += readPixel(dev, rt, x, y) == colour;
        return n;
    };

    CHECK(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF102030u, 1.0f, 0) == D3D_OK);
    CHECK(count(0xFF102030u) == 16);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(rt, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    const uint8_t* b = static_cast<const uint8_t*>(lr.pBits);
    CHECK((b[0] == 0x30 && b[1] == 0x20 && b[2] == 0x10 && b[3] == 0xFF));  // B G R A in memory
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);

    // Two rects, one inverted (clears nothing).
    D3DRECT rects[2] = {{1, 1, 3, 2}, {3, 3, 1, 1}};
    CHECK(dev.Clear(2, rects, D3DCLEAR_TARGET, 0x00000001u, 1.0f, 0) == D3D_OK);
    CHECK(count(1u) == 2);
    CHECK(readPixel(dev, rt, 1, 1) == 1u);
    CHECK(readPixel(dev, rt, 2, 1) == 1u);

    // A count with NULL rects clears nothing (Wine's d3d9 behaviour); rects with count 0 are
    // ignored (the whole viewport).
    CHECK(dev.Clear(1, nullptr, D3DCLEAR_TARGET, 0x00000002u, 1.0f, 0) == D3D_OK);
    CHECK(count(2u) == 0);
    CHECK(dev.Clear(0, rects, D3DCLEAR_TARGET, 0x00000002u, 1.0f, 0) == D3D_OK);
    CHECK(count(2u) == 16);

    // Scissor (when enabled) ∩ rect.
    RECT sc{0, 0, 2, 2};
    REQUIRE(dev.SetScissorRect(&sc) == D3D_OK);
    D3DRECT big{1, 1, 4, 4};
    CHECK(dev.Clear(1, &big, D3DCLEAR_TARGET, 0x00000003u, 1.0f, 0) == D3D_OK);
    CHECK(count(3u) == 9);  // scissor test off: the rect alone
    REQUIRE(dev.SetRenderState(D3DRS_SCISSORTESTENABLE, 1) == D3D_OK);
    CHECK(dev.Clear(1, &big, D3DCLEAR_TARGET, 0x00000004u, 1.0f, 0) == D3D_OK);
    CHECK(count(4u) == 1);
    CHECK(readPixel(dev, rt, 1, 1) == 4u);
    REQUIRE(dev.SetRenderState(D3DRS_SCISSORTESTENABLE, 0) == D3D_OK);

    // The viewport bounds every clear; COLORWRITEENABLE does not mask it.
    D3DVIEWPORT9 vp{2, 0, 2, 4, 0, 1};
    REQUIRE(dev.SetViewport(&vp) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_COLORWRITEENABLE, 0) == D3D_OK);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x00000005u, 1.0f, 0) == D3D_OK);
    CHECK(count(5u) == 8);
    CHECK(readPixel(dev, rt, 1, 0) != 5u);
    CHECK(readPixel(dev, rt, 2, 0) == 5u);

    // Errors.
    CHECK(dev.Clear(0, nullptr, 0, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.Clear(0, nullptr, 8, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4109");
    Device empty;
    CHECK(empty.Clear(0, nullptr, D3DCLEAR_TARGET, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    D3DLOCKED_RECT held;
    REQUIRE(dev.LockRect(rt, &held, nullptr, 0) == D3D_OK);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);
}

TEST_CASE("device: Clear shared by worker threads writes exactly its rects", "[device]") {
    // 320×240: enough texels for up to 4 workers, whose row bands cut through the rects.
    for (int threads : {1, 2, 3, 4}) {
        DeviceOptions o;
        o.software.threads = threads;
        Device dev(o);
        Handle rt = makeTarget(dev, 320, 240, [](UINT x, UINT y) { return 0xFF000000u | (y << 9) | x; });
        REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
        const D3DRECT rects[3] = {{0, 0, 320, 61}, {17, 50, 300, 239}, {5, 119, 6, 121}};
        REQUIRE(dev.Clear(3, rects, D3DCLEAR_TARGET, 0x80402010u, 1.0f, 0) == D3D_OK);
        int wrong = 0;
        for (UINT y = 0; y < 240; ++y)
            for (UINT x = 0; x < 320; ++x) {
                bool in = false;
                for (const D3DRECT& r : rects) in = in || (LONG(x) >= r.x1 && LONG(x) < r.x2 && LONG(y) >= r.y1 && LONG(y) < r.y2);
                wrong += readPixel(dev, rt, x, y) != (in ? 0x80402010u : 0xFF000000u | (y << 9) | x);
            }
        CHECK(wrong == 0);
    }
}

TEST_CASE("device: Clear converts the colour, depth and stencil to the surface formats", "[device]") {
    Device dev;
    Handle f32{}, f16{}, x8{};
    REQUIRE(dev.CreateRenderTarget(2, 2, D3DFMT_A32B32G32R32F, 1, &f32) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, f32) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x33804000u, 1.0f, 0) == D3D_OK);
    CHECK(readFloat(dev, f32, 1, 1, 0) == float(128.0 / 255));
    CHECK(readFloat(dev, f32, 1, 1, 1) == float(64.0 / 255));
    CHECK(readFloat(dev, f32, 1, 1, 2) == 0.0f);
    CHECK(readFloat(dev, f32, 1, 1, 3) == float(51.0 / 255));
    REQUIRE(dev.CreateRenderTarget(2, 2, D3DFMT_A16B16G16R16F, 1, &f16) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, f16) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFFFF0000u, 1.0f, 0) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(f16, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    const uint8_t* p = static_cast<const uint8_t*>(lr.pBits);
    CHECK((p[0] == 0x00 && p[1] == 0x3C));  // R = 1.0 = 0x3C00
    CHECK((p[2] == 0x00 && p[3] == 0x00));  // G = 0
    CHECK((p[6] == 0x00 && p[7] == 0x3C));  // A = 1.0
    REQUIRE(dev.UnlockRect(f16) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(2, 2, D3DFMT_X8R8G8B8, 1, &x8) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, x8) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x00123456u, 1.0f, 0) == D3D_OK);
    CHECK(readPixel(dev, x8, 0, 0) == 0xFF123456u);  // X written as 0xFF

    Handle ds{}, d16{};
    REQUIRE(dev.CreateDepthStencilSurface(2, 2, D3DFMT_D24S8, &ds) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(2, 2, D3DFMT_D16_LOCKABLE, &d16) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(d16) == D3D_OK);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_STENCIL, 0, 1.0f, 7) == D3DERR_INVALIDCALL);  // D16 has no stencil
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, 1.5f, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, std::nanf(""), 0) == D3DERR_INVALIDCALL);
    // z = 0.5 on 16 bits: 0.5 * 65535 = 32767.5 -> 32768 (nearest, ties to even).
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, 0.5f, 0) == D3D_OK);
    REQUIRE(dev.LockRect(d16, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    p = static_cast<const uint8_t*>(lr.pBits);
    CHECK((p[lr.Pitch + 2] | (p[lr.Pitch + 3] << 8)) == 32768);
    REQUIRE(dev.UnlockRect(d16) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(ds) == D3D_OK);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER | D3DCLEAR_STENCIL | D3DCLEAR_TARGET, 0, 0.25f, 0x1A5) == D3D_OK);
}

TEST_CASE("device: a depth-only Clear without a render target covers the depth surface", "[device]") {
    Device dev;
    Handle ds{};
    REQUIRE(dev.CreateDepthStencilSurface(3, 2, D3DFMT_D16_LOCKABLE, &ds) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(ds) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, 1.0f, 0) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(ds, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    const uint8_t* p = static_cast<const uint8_t*>(lr.pBits);
    CHECK((p[lr.Pitch + 4] == 0xFF && p[lr.Pitch + 5] == 0xFF));  // z = 1 -> 65535
    REQUIRE(dev.UnlockRect(ds) == D3D_OK);
}

TEST_CASE("device: StretchRect point and linear", "[device]") {
    Device dev;  // fx8

    SECTION("4x4 -> 2x2 linear averages 2x2 blocks, rounded once (ties to even)") {
        // Red channel per block: {10, 20, 31, 40} -> 25.25 -> 25; {1, 2, 2, 2} -> 1.75 -> 2;
        // {0, 1, 0, 1} -> 0.5 -> 0; {1, 2, 1, 2} -> 1.5 -> 2. Other channels constant.
        const uint8_t red[4][4] = {{10, 20, 1, 2}, {31, 40, 2, 2}, {0, 1, 1, 2}, {0, 1, 1, 2}};
        Handle src = makeTarget(dev, 4, 4, [&](UINT x, UINT y) { return 0xFF004080u | (uint32_t(red[y][x]) << 16); });
        Handle dst = makeTarget(dev, 2, 2, [](UINT, UINT) { return 0u; });
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst, 0, 0) == 0xFF194080u);  // 25
        CHECK(readPixel(dev, dst, 1, 0) == 0xFF024080u);  // 2
        CHECK(readPixel(dev, dst, 0, 1) == 0xFF004080u);  // 0
        CHECK(readPixel(dev, dst, 1, 1) == 0xFF024080u);  // 2
        // POINT: destination pixel i maps to source floor((i + 1/2) * 2) = 2i + 1.
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_POINT) == D3D_OK);
        CHECK(readPixel(dev, dst, 0, 0) >> 16 == (0xFF00u | red[1][1]));
        CHECK(readPixel(dev, dst, 1, 1) >> 16 == (0xFF00u | red[3][3]));
        CHECK(readPixel(dev, dst, 1, 0) >> 16 == (0xFF00u | red[1][3]));
    }

    SECTION("1:1 copies are exact with either filter") {
        auto colour = [](UINT x, UINT y) { return (x * 2654435761u) ^ (y * 40503u) ^ 0x5A5A5A5Au; };
        Handle src = makeTarget(dev, 5, 3, colour);
        Handle dst = makeTarget(dev, 5, 3, [](UINT, UINT) { return 0u; });
        for (D3DTEXTUREFILTERTYPE f : {D3DTEXF_NONE, D3DTEXF_POINT, D3DTEXF_LINEAR}) {
            REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, f) == D3D_OK);
            for (UINT y = 0; y < 3; ++y)
                for (UINT x = 0; x < 5; ++x) CHECK(readPixel(dev, dst, x, y) == colour(x, y));
        }
    }

    SECTION("2:1 reductions of random data: every byte is the 2x2 block's mean, ties to even") {
        auto colour = [](UINT x, UINT y) { return (x * 2654435761u + 7) ^ (y * 2246822519u) ^ (x * y * 374761393u); };
        for (D3DFORMAT fmt : {D3DFMT_A8R8G8B8, D3DFMT_X8R8G8B8}) {
            Handle src = makeTarget(dev, 10, 6, colour);
            Handle dst{};
            REQUIRE(dev.CreateRenderTarget(7, 5, fmt, 1, &dst) == D3D_OK);
            Handle srcFmt{};
            REQUIRE(dev.CreateRenderTarget(10, 6, fmt, 1, &srcFmt) == D3D_OK);
            REQUIRE(dev.StretchRect(src, nullptr, srcFmt, nullptr, D3DTEXF_POINT) == D3D_OK);  // 1:1 copy
            RECT sr{2, 0, 10, 6}, dr{1, 1, 5, 4};
            REQUIRE(dev.StretchRect(srcFmt, &sr, dst, &dr, D3DTEXF_LINEAR) == D3D_OK);
            for (UINT j = 0; j < 3; ++j)
                for (UINT i = 0; i < 4; ++i) {
                    uint32_t expect = 0;
                    for (int b = 0; b < 4; ++b) {
                        int sum = 0;
                        for (UINT dy = 0; dy < 2; ++dy)
                            for (UINT dx = 0; dx < 2; ++dx) {
                                uint32_t c = colour(2 + 2 * i + dx, 2 * j + dy);
                                if (fmt == D3DFMT_X8R8G8B8 && b == 3) c |= 0xFF000000u;
                                sum += int((c >> (8 * b)) & 0xFF);
                            }
                        const int q = sum / 4, r = sum % 4;
                        const int rounded = r < 2 ? q : r > 2 ? q + 1 : q + (q & 1);
                        expect |= uint32_t(rounded) << (8 * b);
                    }
                    INFO("format " << formatName(fmt) << " pixel " << i << ", " << j);
                    CHECK(readPixel(dev, dst, 1 + i, 1 + j) == expect);
                }
            CHECK(readPixel(dev, dst, 0, 0) == 0u);  // outside the rect
        }
    }

    SECTION("sub-rectangles, upscaling and edge clamping") {
        // Source row [0, 255] (red); 2 -> 4 linear: x = (i + 1/2)/2 - 1/2 = -0.25, 0.25, 0.75,
        // 1.25; taps clamp to the rect, so 0, 0.25 * 255 = 63.75 -> 64, 191.25 -> 191, 255.
        Handle src = makeTarget(dev, 4, 1, [](UINT x, UINT) { return x == 2 ? 0xFFFF0000u : 0xFF000000u; });
        Handle dst = makeTarget(dev, 6, 2, [](UINT, UINT) { return 0x11111111u; });
        RECT sr{1, 0, 3, 1}, dr{1, 1, 5, 2};
        REQUIRE(dev.StretchRect(src, &sr, dst, &dr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst, 1, 1) == 0xFF000000u);
        CHECK(readPixel(dev, dst, 2, 1) == 0xFF400000u);
        CHECK(readPixel(dev, dst, 3, 1) == 0xFFBF0000u);
        CHECK(readPixel(dev, dst, 4, 1) == 0xFFFF0000u);
        CHECK(readPixel(dev, dst, 0, 1) == 0x11111111u);  // outside the rect: untouched
        CHECK(readPixel(dev, dst, 5, 1) == 0x11111111u);
        CHECK(readPixel(dev, dst, 2, 0) == 0x11111111u);
    }

    SECTION("3 -> 2 and 8-bit weights") {
        // 3 -> 2: x = (i + 1/2) * 3/2 - 1/2 = 0.25, 1.75. Red [0, 100, 200]: 25, 175 exactly.
        Handle src = makeTarget(dev, 3, 1, [](UINT x, UINT) { return 0xFF000000u | (100u * x) << 16; });
        Handle dst = makeTarget(dev, 2, 1, [](UINT, UINT) { return 0u; });
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst, 0, 0) == 0xFF190000u);
        CHECK(readPixel(dev, dst, 1, 0) == 0xFFAF0000u);
        // 2 -> 7: pixel 1 has x = 1.5 * 2/7 - 1/2 = 3/7 - 1/2 < 0 -> pixel 2: x = 2.5*2/7 - 0.5 =
        // 3/14 = 0.2142857: fx8 weight round(0.2142857 * 256) = round(54.857) = 55, so red
        // 255 * 55/256 = 54.785 -> 55; exact (ideal) 255 * 3/14 = 54.643 -> 55 too. Pixel 3:
        // x = 3.5 * 2/7 - 0.5 = 0.5 exactly: 127.5 -> 128 (ties to even). Pixel 4: x = 11/14:
        // fx8 weight round(201.14) = 201, 255 * 201/256 = 200.21 -> 200; ideal 200.36 -> 200.
        Handle src2 = makeTarget(dev, 2, 1, [](UINT x, UINT) { return x ? 0xFFFF0000u : 0xFF000000u; });
        Handle dst2 = makeTarget(dev, 7, 1, [](UINT, UINT) { return 0u; });
        REQUIRE(dev.StretchRect(src2, nullptr, dst2, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst2, 0, 0) == 0xFF000000u);
        CHECK(readPixel(dev, dst2, 1, 0) == 0xFF000000u);
        CHECK(readPixel(dev, dst2, 2, 0) == 0xFF370000u);
        CHECK(readPixel(dev, dst2, 3, 0) == 0xFF800000u);
        CHECK(readPixel(dev, dst2, 4, 0) == 0xFFC80000u);
        CHECK(readPixel(dev, dst2, 6, 0) == 0xFFFF0000u);
        // Where 8-bit weights change the result: 3 -> 7 red [0, 0, 255], pixel 4: x = 4.5 * 3/7 -
        // 0.5 = 1.4285714 -> f = 3/7: fx8 weight round(109.714) = 110, 255 * 110/256 = 109.57 ->
        // 110; ideal 255 * 3/7 = 109.286 -> 109.
        Handle src3 = makeTarget(dev, 3, 1, [](UINT x, UINT) { return x == 2 ? 0xFFFF0000u : 0xFF000000u; });
        Handle dst3 = makeTarget(dev, 7, 1, [](UINT, UINT) { return 0u; });
        REQUIRE(dev.StretchRect(src3, nullptr, dst3, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst3, 4, 0) == 0xFF6E0000u);
        DeviceOptions o;
        o.precision = ps11::Precision::Ideal;
        Device ideal(o);
        Handle s4 = makeTarget(ideal, 3, 1, [](UINT x, UINT) { return x == 2 ? 0xFFFF0000u : 0xFF000000u; });
        Handle d4 = makeTarget(ideal, 7, 1, [](UINT, UINT) { return 0u; });
        REQUIRE(ideal.StretchRect(s4, nullptr, d4, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(ideal, d4, 4, 0) == 0xFF6D0000u);
    }

    SECTION("format conversion into a float target") {
        Handle src = makeTarget(dev, 2, 2, [](UINT x, UINT y) { return 0xFF000000u | ((x + 2 * y) * 51u) << 16; });
        Handle dst{};
        REQUIRE(dev.CreateRenderTarget(1, 1, D3DFMT_R32F, 1, &dst) == D3D_OK);
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        // (0 + 51 + 102 + 153) / 4 = 76.5 bytes -> 76.5 / 255 = 0.3 exactly representable? as float
        CHECK(readFloat(dev, dst, 0, 0) == float(76.5 / 255.0));
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_POINT) == D3D_OK);
        CHECK(readFloat(dev, dst, 0, 0) == float(153.0 / 255.0));  // point picks (1, 1)
        // Unscaled into A32B32G32R32F (a fast path): every byte value, each channel, X8's alpha 1.
        for (D3DFORMAT from : {D3DFMT_A8R8G8B8, D3DFMT_X8R8G8B8}) {
            Handle bytes = makeTarget(
                dev, 16, 16, [](UINT x, UINT y) { const uint32_t b = y * 16 + x; return (b << 24) | ((255 - b) << 16) | (b << 8) | (b ^ 0x5a); },
                from);
            Handle f32{};
            REQUIRE(dev.CreateRenderTarget(16, 16, D3DFMT_A32B32G32R32F, 1, &f32) == D3D_OK);
            REQUIRE(dev.StretchRect(bytes, nullptr, f32, nullptr, D3DTEXF_LINEAR) == D3D_OK);
            int wrong = 0;
            for (UINT y = 0; y < 16; ++y)
                for (UINT x = 0; x < 16; ++x) {
                    const uint32_t b = y * 16 + x;
                    const double want[4] = {double(255 - b), double(b), double(b ^ 0x5a), from == D3DFMT_X8R8G8B8 ? 255.0 : double(b)};
                    for (UINT c = 0; c < 4; ++c) wrong += readFloat(dev, f32, x, y, c) != float(want[c] / 255.0);
                }
            CHECK(wrong == 0);
        }
        // And back (another fast path): nearest byte, ties to even, clamped, NaN 0.
        const float values[] = {0.0f, 1.0f, -0.5f, 2.0f, 0.5f / 255, 1.5f / 255, 2.5f / 255, 254.5f / 255,
                                 0.3f, 0.7f, float(NAN), float(INFINITY), -float(INFINITY), 1e-30f, 0.999f, 0.0019607f};
        const size_t nv = sizeof values / sizeof values[0];
        for (D3DFORMAT to : {D3DFMT_A8R8G8B8, D3DFMT_X8R8G8B8}) {
            Handle f32{}, bytes{};
            REQUIRE(dev.CreateRenderTarget(UINT(nv), 1, D3DFMT_A32B32G32R32F, 1, &f32) == D3D_OK);
            REQUIRE(dev.CreateRenderTarget(UINT(nv), 1, to, 1, &bytes) == D3D_OK);
            D3DLOCKED_RECT lr{};
            REQUIRE(dev.LockRect(f32, &lr, nullptr, 0) == D3D_OK);
            for (size_t i = 0; i < nv; ++i) {
                const float px[4] = {values[i], values[(i + 1) % nv], values[(i + 2) % nv], values[(i + 3) % nv]};
                std::memcpy(static_cast<uint8_t*>(lr.pBits) + i * 16, px, 16);
            }
            REQUIRE(dev.UnlockRect(f32) == D3D_OK);
            REQUIRE(dev.StretchRect(f32, nullptr, bytes, nullptr, D3DTEXF_POINT) == D3D_OK);
            auto byteOf = [](float v) {
                return std::isnan(v) ? 0u : uint32_t(std::nearbyint(std::clamp(double(v), 0.0, 1.0) * 255.0));
            };
            for (size_t i = 0; i < nv; ++i) {
                const uint32_t a = to == D3DFMT_X8R8G8B8 ? 255u : byteOf(values[(i + 3) % nv]);
                const uint32_t want = a << 24 | byteOf(values[i]) << 16 | byteOf(values[(i + 1) % nv]) << 8 | byteOf(values[(i + 2) % nv]);
                CHECK(readPixel(dev, bytes, UINT(i), 0) == want);
            }
        }
    }

    SECTION("into a render-target texture, which its sampler view then shows") {
        Handle src = makeTarget(dev, 2, 2, [](UINT, UINT) { return 0xFF336699u; });
        Handle tex{}, level{};
        REQUIRE(dev.CreateTexture(2, 2, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        auto before = dev.sampledTexture(tex);
        REQUIRE(before);
        CHECK(before->texelValue(0, 1, 1)[0] == 0.0f);
        REQUIRE(dev.StretchRect(src, nullptr, level, nullptr, D3DTEXF_POINT) == D3D_OK);
        auto after = dev.sampledTexture(tex);
        REQUIRE(after);
        CHECK(after != before);
        CHECK(after->texelValue(0, 1, 1)[0] == float(0x33 / 255.0));
        CHECK(dev.sampledTexture(tex) == after);  // cached until the next write
    }

    SECTION("errors") {
        Handle rt = makeTarget(dev, 4, 4, [](UINT, UINT) { return 0u; });
        Handle rt2 = makeTarget(dev, 4, 4, [](UINT, UINT) { return 0u; });
        Handle sys{}, a8{}, tex{}, level{};
        REQUIRE(dev.CreateOffscreenPlainSurface(4, 4, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
        REQUIRE(dev.CreateOffscreenPlainSurface(4, 4, D3DFMT_A8, D3DPOOL_DEFAULT, &a8) == D3D_OK);
        REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        CHECK(dev.StretchRect(rt, nullptr, rt, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(rt, nullptr, rt2, nullptr, D3DTEXF_ANISOTROPIC) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(rt, nullptr, sys, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(level, nullptr, rt2, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(rt, nullptr, a8, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.lastError().code == "E4104");
        RECT outside{0, 0, 5, 4};
        CHECK(dev.StretchRect(rt, &outside, rt2, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(contains(dev.lastError().message, "source rect (0, 0)-(5, 4)"));
        RECT inverted{2, 0, 1, 4};
        CHECK(dev.StretchRect(rt, nullptr, rt2, &inverted, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(tex, nullptr, rt2, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(Handle(4242), nullptr, rt2, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
    }
}

TEST_CASE("device: GetRenderTargetData of a large target over two workers copies every byte", "[device]") {
    // 301x217: more rows than the workers' share and an odd width (the software renderer moves the
    // rows as an unscaled StretchRect over its workers).
    DeviceOptions o;
    o.software.threads = 2;
    Device dev(o);
    const UINT w = 301, h = 217;
    Handle rt{}, sys{};
    REQUIRE(dev.CreateRenderTarget(w, h, D3DFMT_A8R8G8B8, 1, &rt) == D3D_OK);
    std::mt19937 rng(5);
    std::vector<uint8_t> bytes(size_t(w) * h * 4);
    for (uint8_t& b : bytes) b = uint8_t(rng());
    D3DLOCKED_RECT lr{};
    REQUIRE(dev.LockRect(rt, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < h; ++y) std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &bytes[size_t(y) * w * 4], w * 4);
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);
    REQUIRE(dev.CreateOffscreenPlainSurface(w, h, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
    REQUIRE(dev.GetRenderTargetData(rt, sys) == D3D_OK);
    REQUIRE(dev.LockRect(sys, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    size_t wrong = 0;
    for (UINT y = 0; y < h; ++y)
        wrong += std::memcmp(static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch, &bytes[size_t(y) * w * 4], w * 4) != 0;
    REQUIRE(dev.UnlockRect(sys) == D3D_OK);
    CHECK(wrong == 0);
}

TEST_CASE("device: GetRenderTargetData copies into SYSTEMMEM", "[device]") {
    Device dev;
    Handle rt{}, sys{}, sysSmall{}, def{}, sysTex{}, sysLevel{};
    REQUIRE(dev.CreateRenderTarget(3, 2, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);  // not lockable
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    D3DRECT r{1, 0, 3, 1};
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF000080u, 1.0f, 0) == D3D_OK);
    REQUIRE(dev.Clear(1, &r, D3DCLEAR_TARGET, 0x80FF0000u, 1.0f, 0) == D3D_OK);
    REQUIRE(dev.CreateOffscreenPlainSurface(3, 2, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
    REQUIRE(dev.GetRenderTargetData(rt, sys) == D3D_OK);
    CHECK(readPixel(dev, sys, 0, 0) == 0xFF000080u);
    CHECK(readPixel(dev, sys, 2, 0) == 0x80FF0000u);
    CHECK(readPixel(dev, sys, 2, 1) == 0xFF000080u);
    REQUIRE(dev.CreateTexture(3, 2, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sysTex) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(sysTex, 0, &sysLevel) == D3D_OK);
    REQUIRE(dev.GetRenderTargetData(rt, sysLevel) == D3D_OK);
    CHECK(readPixel(dev, sysLevel, 1, 0) == 0x80FF0000u);

    REQUIRE(dev.CreateOffscreenPlainSurface(2, 2, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sysSmall) == D3D_OK);
    REQUIRE(dev.CreateOffscreenPlainSurface(3, 2, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &def) == D3D_OK);
    CHECK(dev.GetRenderTargetData(rt, sysSmall) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "destination is 2x2 A8R8G8B8, the render target 3x2 A8R8G8B8"));
    CHECK(dev.GetRenderTargetData(rt, def) == D3DERR_INVALIDCALL);
    CHECK(dev.GetRenderTargetData(sys, sysLevel) == D3DERR_INVALIDCALL);  // source not a render target
    CHECK(dev.GetRenderTargetData(rt, Handle::Null) == D3DERR_INVALIDCALL);
}

TEST_CASE("device: readSurface hands the newest bytes in place, and nothing writes them meanwhile", "[device]") {
    Device dev;
    Handle rt{}, tex{}, level{};
    REQUIRE(dev.CreateRenderTarget(3, 2, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);  // not lockable
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    const D3DRECT r{1, 0, 3, 1};
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF000080u, 1.0f, 0) == D3D_OK);
    REQUIRE(dev.Clear(1, &r, D3DCLEAR_TARGET, 0x80FF0000u, 1.0f, 0) == D3D_OK);
    int calls = 0;
    const auto pixel = [](const D3DLOCKED_RECT& lr, UINT x, UINT y) {
        uint32_t c;
        std::memcpy(&c, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, 4);
        return c;
    };
    REQUIRE(dev.readSurface(rt, [&](const D3DLOCKED_RECT& lr) {
        ++calls;
        CHECK(lr.Pitch >= 12);
        CHECK(pixel(lr, 0, 0) == 0xFF000080u);
        CHECK(pixel(lr, 2, 0) == 0x80FF0000u);
        CHECK(pixel(lr, 2, 1) == 0xFF000080u);
        // Held like a lock: a write to it is refused while `read` runs.
        CHECK(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0u, 1.0f, 0) == D3DERR_INVALIDCALL);
        CHECK(dev.lastError().code == "E4106");
        CHECK(dev.readSurface(rt, [](const D3DLOCKED_RECT&) {}) == D3DERR_INVALIDCALL);
    }) == D3D_OK);
    CHECK(calls == 1);
    // Released afterwards: writes go through and the next read sees them.
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x01020304u, 1.0f, 0) == D3D_OK);
    REQUIRE(dev.readSurface(rt, [&](const D3DLOCKED_RECT& lr) { CHECK(pixel(lr, 1, 1) == 0x01020304u); }) == D3D_OK);
    // A texture's level, and a level locked by LockRect (refused, the callback never runs).
    REQUIRE(dev.CreateTexture(2, 2, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
    D3DLOCKED_RECT lr{};
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    std::memcpy(lr.pBits, "\x11\x22\x33\x44", 4);
    calls = 0;
    CHECK(dev.readSurface(level, [&](const D3DLOCKED_RECT&) { ++calls; }) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "is locked"));
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    REQUIRE(dev.readSurface(level, [&](const D3DLOCKED_RECT& l) {
        ++calls;
        CHECK(pixel(l, 0, 0) == 0x44332211u);
    }) == D3D_OK);
    CHECK(calls == 1);
    // A handle that is no surface, and a fingerprint (which cannot hand contents back).
    CHECK(dev.readSurface(Handle(4242), [](const D3DLOCKED_RECT&) {}) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "readSurface"));
    dev.beginFingerprint();
    CHECK(dev.readSurface(rt, [](const D3DLOCKED_RECT&) {}) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4125");
    CHECK_FALSE(dev.endFingerprint().complete);
    // The callback may release the surface's owner: the hold is dropped by handle.
    REQUIRE(dev.readSurface(level, [&](const D3DLOCKED_RECT&) { CHECK(dev.Release(tex) == D3D_OK); }) == D3D_OK);
}

TEST_CASE("device: automatic mip generation", "[device]") {
    Device dev;
    Handle tex{};
    REQUIRE(dev.CreateTexture(4, 4, 0, D3DUSAGE_AUTOGENMIPMAP, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    CHECK(dev.GetLevelCount(tex) == 1);  // D3D9: the sublevels are not exposed
    D3DLOCKED_RECT lr;
    CHECK(dev.LockRect(tex, 1, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    // Blue channel = 10 * (x + 4y) + (x & 1); alpha 255.
    for (UINT y = 0; y < 4; ++y)
        for (UINT x = 0; x < 4; ++x) {
            uint8_t* p = static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4;
            p[0] = uint8_t(10 * (x + 4 * y) + (x & 1)), p[1] = 0, p[2] = 0, p[3] = 255;
        }
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    auto t = dev.sampledTexture(tex);
    REQUIRE(t);
    REQUIRE(t->levelCount() == 3);
    // Level 1 texel (0, 0): (0 + 11 + 40 + 51) / 4 = 25.5 -> 26 (ties to even). Texel (1, 0):
    // (20 + 31 + 60 + 71) / 4 = 45.5 -> 46. Texel (0, 1): (80 + 91 + 120 + 131) / 4 = 105.5 -> 106.
    // Texel (1, 1): (100 + 111 + 140 + 151) / 4 = 125.5 -> 126. Level 2: (26+46+106+126)/4 = 76.
    CHECK(t->texelGrid(1, 0, 0, 0, ps11::Precision::Fx8)[2] == 26);
    CHECK(t->texelGrid(1, 1, 0, 0, ps11::Precision::Fx8)[2] == 46);
    CHECK(t->texelGrid(1, 0, 1, 0, ps11::Precision::Fx8)[2] == 106);
    CHECK(t->texelGrid(1, 1, 1, 0, ps11::Precision::Fx8)[2] == 126);
    CHECK(t->texelGrid(2, 0, 0, 0, ps11::Precision::Fx8)[2] == 76);
    CHECK(t->texelGrid(2, 0, 0, 0, ps11::Precision::Fx8)[3] == 255);
    CHECK(dev.GenerateMipSubLevels(tex) == D3D_OK);
    CHECK(dev.sampledTexture(tex) == t);  // nothing changed since
    CHECK(dev.GenerateMipSubLevels(Handle(999)) == D3DERR_INVALIDCALL);

    // Signed formats average their signed fields: U {-1, -2, 3, 5} -> 5/4 = 1.25 -> 1.
    Handle bump{};
    REQUIRE(dev.CreateTexture(2, 2, 0, D3DUSAGE_AUTOGENMIPMAP, D3DFMT_V8U8, D3DPOOL_MANAGED, &bump) == D3D_OK);
    REQUIRE(dev.LockRect(bump, 0, &lr, nullptr, 0) == D3D_OK);
    const int8_t u[4] = {-1, -2, 3, 5};
    for (int i = 0; i < 4; ++i) {
        uint8_t* p = static_cast<uint8_t*>(lr.pBits) + (i / 2) * lr.Pitch + (i % 2) * 2;
        p[0] = uint8_t(u[i]), p[1] = uint8_t(-8);
    }
    REQUIRE(dev.UnlockRect(bump, 0) == D3D_OK);
    REQUIRE(dev.GenerateMipSubLevels(bump) == D3D_OK);
    auto b = dev.sampledTexture(bump);
    REQUIRE(b);
    CHECK(b->texelValue(1, 0, 0)[0] == float(1.0 / 127));
    CHECK(b->texelValue(1, 0, 0)[1] == float(-8.0 / 127));

    // A float chain: R32F {0.5, 1.5, 2.5, 4.0} -> 2.125.
    Handle fl{};
    REQUIRE(dev.CreateTexture(2, 2, 0, D3DUSAGE_AUTOGENMIPMAP, D3DFMT_R32F, D3DPOOL_MANAGED, &fl) == D3D_OK);
    REQUIRE(dev.LockRect(fl, 0, &lr, nullptr, 0) == D3D_OK);
    const float v[4] = {0.5f, 1.5f, 2.5f, 4.0f};
    for (int i = 0; i < 4; ++i)
        std::memcpy(static_cast<uint8_t*>(lr.pBits) + (i / 2) * lr.Pitch + (i % 2) * 4, &v[i], 4);
    REQUIRE(dev.UnlockRect(fl, 0) == D3D_OK);
    auto f = dev.sampledTexture(fl);
    REQUIRE(f);
    CHECK(f->texelValue(1, 0, 0)[0] == 2.125f);

    // A textures without AUTOGENMIPMAP keeps its levels as written (D3D9: no effect).
    Handle plain{};
    REQUIRE(dev.CreateTexture(2, 2, 2, 0, D3DFMT_L8, D3DPOOL_MANAGED, &plain) == D3D_OK);
    REQUIRE(dev.LockRect(plain, 0, &lr, nullptr, 0) == D3D_OK);
    std::memset(lr.pBits, 200, 2);
    REQUIRE(dev.UnlockRect(plain, 0) == D3D_OK);
    REQUIRE(dev.GenerateMipSubLevels(plain) == D3D_OK);
    CHECK(dev.sampledTexture(plain)->texelValue(1, 0, 0)[0] == 0.0f);
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

TEST_CASE("device: A8R8G8B8 textures are sampled in place, and a held view never changes", "[device]") {
    Device dev;
    auto fill = [&](Handle tex, UINT level, uint32_t word) {
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(tex, level, &lr, nullptr, 0) == D3D_OK);
        D3DSURFACE_DESC desc{};
        REQUIRE(dev.GetLevelDesc(tex, level, &desc) == D3D_OK);
        for (UINT y = 0; y < desc.Height; ++y)
            for (UINT x = 0; x < desc.Width; ++x)
                std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, &word, 4);
        REQUIRE(dev.UnlockRect(tex, level) == D3D_OK);
    };
    auto red = [](const std::shared_ptr<const ps11::Texture>& t, int level) {
        return int(std::lround(t->texelValue(level, 0, 0)[0] * 255.0f));
    };

    SECTION("a mip chain is read where it is; X8R8G8B8 and A8 are copied") {
        Handle tex{}, x8{}, a8{};
        REQUIRE(dev.CreateTexture(8, 4, 0, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
        for (UINT l = 0; l < 4; ++l) fill(tex, l, 0xFF000000u | ((10u + l) << 16));
        auto t = dev.sampledTexture(tex);
        REQUIRE(t);
        CHECK(t->readsInPlace());
        for (int l = 0; l < 4; ++l) CHECK(red(t, l) == 10 + l);
        REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_X8R8G8B8, D3DPOOL_MANAGED, &x8) == D3D_OK);
        fill(x8, 0, 0x00FF0000u);  // alpha byte 0: the sampler must read 1
        auto tx = dev.sampledTexture(x8);
        REQUIRE(tx);
        CHECK_FALSE(tx->readsInPlace());
        CHECK(tx->texelValue(0, 0, 0)[3] == 1.0f);
        REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8, D3DPOOL_MANAGED, &a8) == D3D_OK);
        CHECK_FALSE(dev.sampledTexture(a8)->readsInPlace());
    }

    SECTION("every write leaves a view someone holds as it was") {
        Handle tex{}, level{}, src{};
        REQUIRE(dev.CreateTexture(4, 4, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        src = makeTarget(dev, 4, 4, [](UINT, UINT) { return 0xFF330000u; });
        REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF010000u, 1.0f, 0) == D3D_OK);
        auto v1 = dev.sampledTexture(tex);
        REQUIRE(v1);
        CHECK(v1->readsInPlace());
        CHECK(red(v1, 0) == 1);
        // Clear, StretchRect and a lock each write the level while v1 is held.
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF020000u, 1.0f, 0) == D3D_OK);
        CHECK(red(v1, 0) == 1);
        auto v2 = dev.sampledTexture(tex);
        CHECK(red(v2, 0) == 2);
        REQUIRE(dev.StretchRect(src, nullptr, level, nullptr, D3DTEXF_POINT) == D3D_OK);
        CHECK(red(v1, 0) == 1);
        CHECK(red(v2, 0) == 2);
        auto v3 = dev.sampledTexture(tex);
        CHECK(red(v3, 0) == 0x33);
        // A draw into the level (a clear-coloured quad through the fixed function's diffuse).
        struct V { float x, y, z, rhw; DWORD c; };
        const V quad[4] = {{-0.5f, -0.5f, 0, 1, 0xFF440000u}, {3.5f, -0.5f, 0, 1, 0xFF440000u},
                           {-0.5f, 3.5f, 0, 1, 0xFF440000u}, {3.5f, 3.5f, 0, 1, 0xFF440000u}};
        REQUIRE(dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_DIFFUSE) == D3D_OK);
        REQUIRE(dev.SetTextureStageState(0, D3DTSS_COLOROP, D3DTOP_SELECTARG1) == D3D_OK);
        REQUIRE(dev.SetTextureStageState(0, D3DTSS_COLORARG1, D3DTA_DIFFUSE) == D3D_OK);
        REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, quad, sizeof(V)) == D3D_OK);
        CHECK(red(v3, 0) == 0x33);
        CHECK(red(dev.sampledTexture(tex), 0) == 0x44);
    }

    SECTION("a texture a draw sampled is written in place afterwards (nothing keeps the view)") {
        Handle tex{}, level{}, out{};
        REQUIRE(dev.CreateTexture(8, 8, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        out = makeTarget(dev, 8, 8, [](UINT, UINT) { return 0u; });
        struct V { float x, y, z, rhw, u, v; };
        const V quad[4] = {{-0.5f, -0.5f, 0, 1, 0, 0}, {7.5f, -0.5f, 0, 1, 1, 0}, {-0.5f, 7.5f, 0, 1, 0, 1}, {7.5f, 7.5f, 0, 1, 1, 1}};
        REQUIRE(dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_TEX1) == D3D_OK);
        auto drawFrom = [&] {
            REQUIRE(dev.SetRenderTarget(0, out) == D3D_OK);
            REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
            REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, quad, sizeof(V)) == D3D_OK);
            REQUIRE(dev.SetTexture(0, Handle::Null) == D3D_OK);
            REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
            REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF102030u, 1.0f, 0) == D3D_OK);
        };
        drawFrom();
        const void* before = dev.sampledTexture(tex)->unorm8();
        drawFrom();
        CHECK(dev.sampledTexture(tex)->unorm8() == before);  // the clear wrote the same buffer
        CHECK(red(dev.sampledTexture(tex), 0) == 0x10);
    }

    SECTION("a lock after the view was made, then a write to another level") {
        Handle tex{};
        REQUIRE(dev.CreateTexture(4, 4, 2, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
        fill(tex, 0, 0xFF050000u);
        fill(tex, 1, 0xFF060000u);
        auto v = dev.sampledTexture(tex);
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(tex, 1, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
        fill(tex, 0, 0xFF070000u);  // level 0 written while level 1 stays locked
        CHECK(static_cast<const uint8_t*>(lr.pBits)[2] == 6);
        REQUIRE(dev.UnlockRect(tex, 1) == D3D_OK);
        CHECK(red(v, 0) == 5);
        auto w = dev.sampledTexture(tex);
        CHECK(red(w, 0) == 7);
        CHECK(red(w, 1) == 6);
        // Released while held: the view keeps its bytes alive.
        REQUIRE(dev.Release(tex) == D3D_OK);
        CHECK(red(w, 0) == 7);
    }
}

namespace {

// A random source rect of sw×sh and destination rect of dw×dh (each at least one pixel, inside),
// and the tap mapping stretchTaps gives them (fx weights or the float profiles').
struct RandomStretch {
    RECT sr{}, dr{};
    std::vector<StretchTap> tx, ty;
};
RandomStretch randomStretch(std::mt19937& rng, UINT sw, UINT sh, UINT dw, UINT dh, bool fixedPoint) {
    RandomStretch r;
    r.sr = RECT{LONG(rng() % sw), LONG(rng() % sh), 0, 0};
    r.dr = RECT{LONG(rng() % dw), LONG(rng() % dh), 0, 0};
    r.sr.right = r.sr.left + 1 + LONG(rng() % (sw - UINT(r.sr.left)));
    r.sr.bottom = r.sr.top + 1 + LONG(rng() % (sh - UINT(r.sr.top)));
    r.dr.right = r.dr.left + 1 + LONG(rng() % (dw - UINT(r.dr.left)));
    r.dr.bottom = r.dr.top + 1 + LONG(rng() % (dh - UINT(r.dr.top)));
    StretchCall call;
    call.sourceRect = PixelBox{r.sr.left, r.sr.top, r.sr.right, r.sr.bottom};
    call.destRect = PixelBox{r.dr.left, r.dr.top, r.dr.right, r.dr.bottom};
    call.linear = true;
    call.fixedPoint = fixedPoint;
    r.tx = stretchTaps(call, true);
    r.ty = stretchTaps(call, false);
    return r;
}

}  // namespace

TEST_CASE("device: LINEAR StretchRect between 8-bit targets equals the weighted sum, any scale and rect", "[device]") {
    // The filter written out from the one tap mapping (emu/blit.h stretchTaps): fx weights k/256
    // (the double sum exact), the float profiles' weights rem/den; rounded to nearest, ties to
    // even; X8's alpha 255.
    std::mt19937 rng(11);
    for (int round = 0; round < 80; ++round) {
        DeviceOptions o;
        o.software.threads = 1 + int(rng() % 2);
        const bool fixedPoint = round % 2 == 0;
        o.precision = fixedPoint ? ps11::Precision::Fx8 : ps11::Precision::Float;
        Device dev(o);
        const D3DFORMAT fmt = rng() % 3 ? D3DFMT_A8R8G8B8 : D3DFMT_X8R8G8B8;
        const UINT sw = 1 + rng() % 70, sh = 1 + rng() % 70, dw = 1 + rng() % 70, dh = 1 + rng() % 90;
        std::vector<uint32_t> texels(size_t(sw) * sh);
        for (uint32_t& t : texels) t = rng();
        Handle src = makeTarget(dev, sw, sh, [&](UINT x, UINT y) { return texels[size_t(y) * sw + x]; }, fmt);
        Handle dst = makeTarget(dev, dw, dh, [](UINT, UINT) { return 0x12345678u; }, fmt);
        const RandomStretch rs = randomStretch(rng, sw, sh, dw, dh, fixedPoint);
        const RECT &sr = rs.sr, &dr = rs.dr;
        const std::vector<StretchTap>&tx = rs.tx, &ty = rs.ty;
        INFO("round " << round << ": " << sw << "x" << sh << " -> " << dw << "x" << dh);
        REQUIRE(dev.StretchRect(src, &sr, dst, &dr, D3DTEXF_LINEAR) == D3D_OK);
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(dst, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
        int wrong = 0;
        for (UINT y = 0; y < dh; ++y)
            for (UINT x = 0; x < dw; ++x) {
                uint32_t got;
                std::memcpy(&got, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, 4);
                const bool inside = LONG(x) >= dr.left && LONG(x) < dr.right && LONG(y) >= dr.top && LONG(y) < dr.bottom;
                uint32_t want = 0x12345678u;  // outside the rect: as written
                if (inside) {
                    const StretchTap& a = tx[size_t(LONG(x) - dr.left)];
                    const StretchTap& b = ty[size_t(LONG(y) - dr.top)];
                    want = 0;
                    for (int k = 0; k < 4; ++k) {
                        auto byte = [&](int64_t sx, int64_t sy) { return double((texels[size_t(sy) * sw + size_t(sx)] >> (8 * k)) & 0xFF); };
                        const double v = (1 - b.w1) * ((1 - a.w1) * byte(a.i0, b.i0) + a.w1 * byte(a.i1, b.i0)) +
                                         b.w1 * ((1 - a.w1) * byte(a.i0, b.i1) + a.w1 * byte(a.i1, b.i1));
                        const uint32_t r = k == 3 && fmt == D3DFMT_X8R8G8B8 ? 255u : uint32_t(std::nearbyint(v));
                        want |= r << (8 * k);
                    }
                }
                wrong += got != want;
            }
        REQUIRE(dev.UnlockRect(dst) == D3D_OK);
        CHECK(wrong == 0);
    }
}

TEST_CASE("device: LINEAR StretchRect between A32B32G32R32F targets is the double sum rounded to float", "[device]") {
    // The ideal profile's reductions: the tap mapping's weights (fx ones too), the sum in double
    // in the documented order, stored as float; values of any sign and size, infinities, NaN.
    std::mt19937 rng(12);
    const float specials[] = {0.0f, -0.0f, 1.0f, 1e30f, -3e38f, 1e-40f, float(INFINITY), float(NAN)};
    for (int round = 0; round < 40; ++round) {
        DeviceOptions o;
        o.software.threads = 1 + int(rng() % 2);
        const bool fixedPoint = round % 4 == 0;
        o.precision = fixedPoint ? ps11::Precision::Fx8 : ps11::Precision::Ideal;
        Device dev(o);
        const UINT sw = 1 + rng() % 70, sh = 1 + rng() % 70, dw = 1 + rng() % 70, dh = 1 + rng() % 90;
        std::vector<float> texels(size_t(sw) * sh * 4);
        std::uniform_real_distribution<float> value(-2.0f, 2.0f);
        for (float& t : texels) t = rng() % 16 ? value(rng) : specials[rng() % 8];
        Handle src{}, dst{};
        REQUIRE(dev.CreateRenderTarget(sw, sh, D3DFMT_A32B32G32R32F, 1, &src) == D3D_OK);
        REQUIRE(dev.CreateRenderTarget(dw, dh, D3DFMT_A32B32G32R32F, 1, &dst) == D3D_OK);
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(src, &lr, nullptr, 0) == D3D_OK);
        for (UINT y = 0; y < sh; ++y)
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &texels[size_t(y) * sw * 4], size_t(sw) * 16);
        REQUIRE(dev.UnlockRect(src) == D3D_OK);
        const RandomStretch rs = randomStretch(rng, sw, sh, dw, dh, fixedPoint);
        const RECT &sr = rs.sr, &dr = rs.dr;
        const std::vector<StretchTap>&tx = rs.tx, &ty = rs.ty;
        INFO("round " << round << ": " << sw << "x" << sh << " -> " << dw << "x" << dh);
        REQUIRE(dev.StretchRect(src, &sr, dst, &dr, D3DTEXF_LINEAR) == D3D_OK);
        int wrong = 0, inside = 0;
        REQUIRE(dev.LockRect(dst, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
        for (UINT y = UINT(dr.top); y < UINT(dr.bottom); ++y)
            for (UINT x = UINT(dr.left); x < UINT(dr.right); ++x) {
                const StretchTap& a = tx[size_t(LONG(x) - dr.left)];
                const StretchTap& b = ty[size_t(LONG(y) - dr.top)];
                for (UINT k = 0; k < 4; ++k) {
                    auto at = [&](int64_t sx, int64_t sy) {
                        return double(texels[(size_t(sy) * sw + size_t(sx)) * 4 + k]);
                    };
                    const float want = float((1 - b.w1) * ((1 - a.w1) * at(a.i0, b.i0) + a.w1 * at(a.i1, b.i0)) +
                                             b.w1 * ((1 - a.w1) * at(a.i0, b.i1) + a.w1 * at(a.i1, b.i1)));
                    float got;
                    std::memcpy(&got, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * 16 + 4 * k, 4);
                    // (A NaN's payload follows the operands' order, which the compiler may swap.)
                    wrong += std::memcmp(&got, &want, 4) != 0 && !(std::isnan(got) && std::isnan(want));
                    ++inside;
                }
            }
        REQUIRE(dev.UnlockRect(dst) == D3D_OK);
        CHECK(inside > 0);
        CHECK(wrong == 0);
    }
}
