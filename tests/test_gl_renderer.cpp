// The GL renderer against the software renderer under the same device front: overlapping
// blended and depth-tested triangles (the batches and texture barriers of emu/gl/gl_renderer.cpp),
// every render-target and depth format, random valid programs (runner/random_program.h), and a
// draw after a state block was applied (Device::applyState), each compared byte for byte
// (docs/gl-backend.md).
#include <catch2/catch.hpp>

#include <cstring>
#include <random>
#include <variant>
#include <vector>

#include "emu/device.h"
#include "emu/format.h"
#include "emu/gl/gl_internal.h"
#include "ps11/assembler.h"
#include "ps11/validator.h"
#include "runner/gl_backend.h"
#include "runner/random_program.h"
#include "runner/test_draw.h"

using namespace emu;

namespace {

// A device's handle on the process's GL renderer (runner/gl_backend.h: one context for every
// device, as the command line has; a context per device would also leave llvmpipe's per-context
// allocations behind on every destruction). The test fails (CI installs OpenGL) without one.
std::unique_ptr<Renderer> glRenderer() {
    std::string error;
    const ps11test::RendererFactory factory = ps11test::glRendererFactory("", error);
    INFO(error);
    REQUIRE(factory);
    return factory();
}

struct Vertex {
    float x, y, z, rhw;
    DWORD diffuse;
    float u, v;
};
constexpr DWORD kFvf = D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_TEX1;

// A scene of overlapping triangles drawn on `dev`: returns the colour and depth bytes.
struct Scene {
    D3DFORMAT color = D3DFMT_A8R8G8B8;
    D3DFORMAT depth = D3DFMT_D24S8;
    bool blend = true;
    uint32_t seed = 1;
};

std::vector<uint8_t> surfaceBytes(Device& dev, Handle s, UINT w, UINT h, UINT bpp) {
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(s, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    std::vector<uint8_t> out(size_t(w) * h * bpp);
    for (UINT y = 0; y < h; ++y)
        std::memcpy(&out[y * w * bpp], static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, w * bpp);
    REQUIRE(dev.UnlockRect(s) == D3D_OK);
    return out;
}

std::pair<std::vector<uint8_t>, std::vector<uint8_t>> draw(Device& dev, const Scene& sc) {
    const UINT w = 37, h = 29;
    Handle rt{}, ds{}, tex{}, ps{};
    REQUIRE(dev.CreateRenderTarget(w, h, sc.color, 1, &rt) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(w, h, sc.depth, &ds) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(ds) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET | D3DCLEAR_ZBUFFER, 0x80402010, 0.75f, 0) == D3D_OK);
    REQUIRE(dev.CreateTexture(8, 8, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    std::mt19937 rng(sc.seed);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const uint32_t t = rng();
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + 4 * x, &t, 4);
        }
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_MINFILTER, D3DTEXF_LINEAR) == D3D_OK);
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR) == D3D_OK);
    REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\nmad r0, t0, v0, v0_bias\n", &ps) == D3D_OK);
    REQUIRE(dev.SetPixelShader(ps) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ZENABLE, 1) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ZFUNC, D3DCMP_LESSEQUAL) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ZWRITEENABLE, 1) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, sc.blend ? 1 : 0) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_SRCALPHA) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_INVSRCALPHA) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_COLORWRITEENABLE, 0xb) == D3D_OK);  // r, g and a: the mask reads the old word
    REQUIRE(dev.SetFVF(kFvf) == D3D_OK);
    std::uniform_real_distribution<float> px(-6.0f, 43.0f), z(0.0f, 1.0f), uv(-1.0f, 2.0f);
    std::vector<Vertex> v;
    for (int i = 0; i < 3 * 120; ++i)
        v.push_back(Vertex{px(rng), px(rng), z(rng), 1.0f, DWORD(rng()), uv(rng), uv(rng)});
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 120, v.data(), sizeof(Vertex)) == D3D_OK);
    const UINT cb = sc.color == D3DFMT_A16B16G16R16F ? 8 : sc.color == D3DFMT_A32B32G32R32F ? 16 : 4;
    // D3D9 locks only the lockable depth formats; D24S8 is checked through the colour it leaves.
    const bool lockable = sc.depth == D3DFMT_D16_LOCKABLE || sc.depth == D3DFMT_D32F_LOCKABLE;
    const UINT db = sc.depth == D3DFMT_D16_LOCKABLE ? 2 : 4;
    return {surfaceBytes(dev, rt, w, h, cb), lockable ? surfaceBytes(dev, ds, w, h, db) : std::vector<uint8_t>{}};
}

}  // namespace

TEST_CASE("gl renderer: overlapping blended, masked, depth-tested triangles equal the software renderer's", "[gl]") {
    for (D3DFORMAT color : {D3DFMT_A8R8G8B8, D3DFMT_X8R8G8B8, D3DFMT_A16B16G16R16F, D3DFMT_A32B32G32R32F}) {
        for (D3DFORMAT depth : {D3DFMT_D16_LOCKABLE, D3DFMT_D24S8, D3DFMT_D32F_LOCKABLE}) {
            for (ps11::Precision p : {ps11::Precision::Fx8, ps11::Precision::Fx12, ps11::Precision::Float}) {
                Scene sc;
                sc.color = color;
                sc.depth = depth;
                sc.seed = uint32_t(color) * 31 + uint32_t(depth);
                DeviceOptions so;
                so.precision = p;
                DeviceOptions go = so;
                go.renderer = glRenderer;
                Device sw(so), gl(go);
                const auto a = draw(sw, sc);
                const auto b = draw(gl, sc);
                INFO("colour format " << color << ", depth format " << depth << ", " << ps11::precisionName(p));
                CHECK(a.first == b.first);
                CHECK(a.second == b.second);
                // The scene is not trivial: the triangles overlap and the depth test rejects some.
                CHECK(sw.lastDrawStats().pixelsWritten < sw.lastDrawStats().pixelsCovered);
                CHECK(gl.lastDrawStats().pixelsWritten == sw.lastDrawStats().pixelsWritten);
            }
        }
    }
}

TEST_CASE("gl renderer: random valid programs draw the emulator's images bit for bit", "[gl]") {
    std::string error;
    const ps11test::RendererFactory factory = glRenderer;
    int compared = 0;
    for (uint64_t seed = 1; seed <= 60; ++seed) {
        std::mt19937_64 rng(seed);
        ps11test::RandomCaseOptions ro;
        const ps11test::RandomCase c = ps11test::randomCase(rng, ro);
        ps11::TestFile file;
        std::vector<ps11::TestFileError> errors;
        REQUIRE(ps11::parseTestFile(c.testText, "random", file, errors));
        ps11::Diagnostics diags;
        std::optional<ps11::Program> program =
            ps11::parseAssembly(file.pixelShader.textWithFileLines(), "random", ps11::AssembleOptions{}, diags);
        REQUIRE(program);
        ps11::validate(*program, diags);
        REQUIRE_FALSE(diags.hasErrors());
        const ps11::HardwareConfig hw = ps11::resolveHardware(nullptr, program->version.minor, std::nullopt, 0);
        auto emu = ps11test::DrawRunner::create(file, "random", &*program, hw, error);
        auto glr = ps11test::DrawRunner::create(file, "random", &*program, hw, error, true, factory);
        REQUIRE(emu);
        REQUIRE(glr);
        for (const ps11::TestCommand& cmd : file.commands) {
            if (!std::holds_alternative<ps11::DrawPrimitives>(cmd.op) &&
                !std::holds_alternative<ps11::DrawQuad>(cmd.op))
                continue;
            INFO("seed " << seed << "\n" << c.shaderText() << "\n" << error);
            REQUIRE(emu->draw(cmd, error));
            REQUIRE(glr->draw(cmd, error));
            std::vector<ps11::Vec4> a, b;
            REQUIRE(emu->targetPixels(a, error));
            REQUIRE(glr->targetPixels(b, error));
            CHECK(a == b);
            ++compared;
        }
    }
    CHECK(compared == 60);
}

namespace {

// The objects of the state-block test, created in one order so two devices get the same handles.
struct BlockObjects {
    Handle target{}, otherTarget{}, depth{}, texture{}, otherTexture{}, shader{};
};

BlockObjects blockObjects(Device& dev) {
    BlockObjects o;
    REQUIRE(dev.CreateRenderTarget(24, 16, D3DFMT_A8R8G8B8, 1, &o.target) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(24, 16, D3DFMT_A8R8G8B8, 1, &o.otherTarget) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(24, 16, D3DFMT_D16_LOCKABLE, &o.depth) == D3D_OK);
    for (Handle* t : {&o.texture, &o.otherTexture}) {
        REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, t) == D3D_OK);
        D3DLOCKED_RECT lr;
        REQUIRE(dev.LockRect(*t, 0, &lr, nullptr, 0) == D3D_OK);
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 4; ++x) {
                const uint32_t c = 0x80000000u + uint32_t(x * 0x3f0000 + y * 0x3f00) + (t == &o.texture ? 0x20 : 0xc0);
                std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + 4 * x, &c, 4);
            }
        REQUIRE(dev.UnlockRect(*t, 0) == D3D_OK);
    }
    REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\nmad r0, t0, v0, c2\n", &o.shader) == D3D_OK);
    return o;
}

// The state of the draw that is compared: a shader with a constant, a linear-filtered texture,
// blending, a depth test and a viewport smaller than the target.
void setDrawState(Device& dev, const BlockObjects& o) {
    REQUIRE(dev.SetRenderTarget(0, o.target) == D3D_OK);
    const D3DVIEWPORT9 vp{2, 1, 20, 14, 0.0f, 1.0f};
    REQUIRE(dev.SetViewport(&vp) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(o.depth) == D3D_OK);
    REQUIRE(dev.SetPixelShader(o.shader) == D3D_OK);
    const float c2[4] = {0.1f, -0.2f, 0.3f, 0.0f};
    REQUIRE(dev.SetPixelShaderConstantF(2, c2, 1) == D3D_OK);
    REQUIRE(dev.SetTexture(0, o.texture) == D3D_OK);
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_MINFILTER, D3DTEXF_LINEAR) == D3D_OK);
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR) == D3D_OK);
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_ADDRESSU, D3DTADDRESS_MIRROR) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ZENABLE, 1) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ZFUNC, D3DCMP_LESS) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_CULLMODE, D3DCULL_NONE) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_SRCALPHA) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_INVSRCALPHA) == D3D_OK);
    REQUIRE(dev.SetFVF(kFvf) == D3D_OK);
}

// Clears the viewport (and the depth surface when one is bound) and draws overlapping triangles
// under whatever state the device holds.
void drawTriangles(Device& dev) {
    Handle depth{};
    const DWORD clear = D3DCLEAR_TARGET | (dev.GetDepthStencilSurface(&depth) == D3D_OK ? D3DCLEAR_ZBUFFER : 0);
    REQUIRE(dev.Clear(0, nullptr, clear, 0xff204060, 0.5f, 0) == D3D_OK);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> px(-4.0f, 28.0f), z(0.0f, 1.0f), uv(-1.0f, 2.0f);
    std::vector<Vertex> v;
    for (int i = 0; i < 3 * 40; ++i)
        v.push_back(Vertex{px(rng), px(rng), z(rng), 1.0f, DWORD(rng()), uv(rng), uv(rng)});
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 40, v.data(), sizeof(Vertex)) == D3D_OK);
}

}  // namespace

TEST_CASE("gl renderer: a draw after applyState equals the draw after the Set* calls, on both renderers", "[gl]") {
    std::vector<uint8_t> softwareColour;
    for (bool gl : {false, true}) {
        INFO((gl ? "GL renderer" : "software renderer"));
        DeviceOptions options;
        if (gl) options.renderer = glRenderer;
        // The state set by its Set* calls.
        Device direct(options);
        const BlockObjects o = blockObjects(direct);
        setDrawState(direct, o);
        drawTriangles(direct);
        const std::vector<uint8_t> colour = surfaceBytes(direct, o.target, 24, 16, 4);
        const std::vector<uint8_t> depth = surfaceBytes(direct, o.depth, 24, 16, 2);
        // The same state captured, then changed everywhere by a draw of another kind, then applied.
        Device restored(options);
        REQUIRE(blockObjects(restored).shader == o.shader);  // the same handles
        setDrawState(restored, o);
        const DeviceState captured = restored.state();
        REQUIRE(restored.SetRenderTarget(0, o.otherTarget) == D3D_OK);
        REQUIRE(restored.SetDepthStencilSurface(Handle::Null) == D3D_OK);
        REQUIRE(restored.SetPixelShader(Handle::Null) == D3D_OK);
        REQUIRE(restored.SetTexture(0, o.otherTexture) == D3D_OK);
        REQUIRE(restored.SetTextureStageState(0, D3DTSS_COLOROP, D3DTOP_ADD) == D3D_OK);
        REQUIRE(restored.SetTextureStageState(0, D3DTSS_COLORARG2, D3DTA_DIFFUSE) == D3D_OK);
        REQUIRE(restored.SetSamplerState(0, D3DSAMP_MINFILTER, D3DTEXF_POINT) == D3D_OK);
        REQUIRE(restored.SetRenderState(D3DRS_ALPHABLENDENABLE, 0) == D3D_OK);
        REQUIRE(restored.SetRenderState(D3DRS_COLORWRITEENABLE, 0x5) == D3D_OK);
        drawTriangles(restored);
        // The draw depends on the state: under the other one the same triangles gave other bytes.
        CHECK(surfaceBytes(restored, o.otherTarget, 24, 16, 4) != colour);
        REQUIRE(restored.applyState(captured) == D3D_OK);
        REQUIRE(restored.state() == captured);
        drawTriangles(restored);
        CHECK(surfaceBytes(restored, o.target, 24, 16, 4) == colour);
        CHECK(surfaceBytes(restored, o.depth, 24, 16, 2) == depth);
        if (gl) CHECK(colour == softwareColour);
        softwareColour = colour;
    }
}

TEST_CASE("gl renderer: native mode keeps every surface format in the GL format its row describes", "[gl]") {
    using emu::gl::NativeFormat;
    struct Want {
        emu::D3DFORMAT format;
        bool kept;
        NativeFormat nf;
    };
    // The GL format whose client layout is D3D's texel (glTexImage2D's tables), per format.
    const Want wants[] = {
        {emu::D3DFMT_A8R8G8B8, true, {GL_RGBA8, GL_BGRA, GL_UNSIGNED_BYTE}},
        {emu::D3DFMT_X8R8G8B8, true, {GL_RGBA8, GL_BGRA, GL_UNSIGNED_BYTE}},
        {emu::D3DFMT_A16B16G16R16F, true, {GL_RGBA16F, GL_RGBA, GL_HALF_FLOAT}},
        {emu::D3DFMT_A32B32G32R32F, true, {GL_RGBA32F, GL_RGBA, GL_FLOAT}},
        {emu::D3DFMT_R32F, true, {GL_R32F, GL_RED, GL_FLOAT}},
        {emu::D3DFMT_D16, true, {GL_DEPTH_COMPONENT16, GL_DEPTH_COMPONENT, GL_UNSIGNED_SHORT, true, false}},
        {emu::D3DFMT_D16_LOCKABLE, true, {GL_DEPTH_COMPONENT16, GL_DEPTH_COMPONENT, GL_UNSIGNED_SHORT, true, false}},
        {emu::D3DFMT_D24S8, true, {GL_DEPTH24_STENCIL8, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, true, true}},
        {emu::D3DFMT_D24X8, true, {GL_DEPTH24_STENCIL8, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, true, true}},
        {emu::D3DFMT_D32, true, {GL_DEPTH_COMPONENT32, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, true, false}},
        {emu::D3DFMT_D32F_LOCKABLE, true, {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, true, false}},
        {emu::D3DFMT_A8, false, {}},
        {emu::D3DFMT_L8, false, {}},
        {emu::D3DFMT_A8L8, false, {}},
        {emu::D3DFMT_V8U8, false, {}},
        {emu::D3DFMT_L6V5U5, false, {}},
        {emu::D3DFMT_X8L8V8U8, false, {}},
        {emu::D3DFMT_Q8W8V8U8, false, {}},
        {emu::D3DFMT_V16U16, false, {}},
    };
    CHECK(std::size(wants) == std::size(ps11::kFormatRows));  // every row
    for (const Want& w : wants) {
        const emu::FormatInfo* f = emu::formatInfo(w.format);
        INFO(emu::formatName(w.format));
        REQUIRE(f);
        NativeFormat nf;
        REQUIRE(emu::gl::nativeFormatOf(*f, nf) == w.kept);
        if (!w.kept) continue;
        CHECK(nf.internal == w.nf.internal);
        CHECK(nf.format == w.nf.format);
        CHECK(nf.type == w.nf.type);
        CHECK(nf.depth == w.nf.depth);
        CHECK(nf.stencil == w.nf.stencil);
    }
}
