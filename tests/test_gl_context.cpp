// GL backend contexts (emu/gl/context.h): each kind makes an OpenGL 3.3+ core context on this
// machine (Mesa llvmpipe; CI installs the same packages through .ci/setup), clears an FBO to a
// known colour and reads it back exactly; unreachable requests return an error, never crash.
#include <catch2/catch.hpp>

#include <array>
#include <cstdint>
#include <vector>

#include "emu/gl/context.h"

using namespace emu::gl;

namespace {

// Clears a 4x4 RGBA8 renderbuffer to `rgba` (bytes, given as exact k/255 floats) and reads it back.
std::vector<uint8_t> clearFbo(Context& ctx, std::array<uint8_t, 4> rgba) {
    REQUIRE(ctx.makeCurrent());
    const GlFunctions& gl = ctx.gl();
    GLuint fbo = 0, rb = 0;
    gl.GenFramebuffers(1, &fbo);
    gl.GenRenderbuffers(1, &rb);
    gl.BindRenderbuffer(GL_RENDERBUFFER, rb);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 4, 4);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
    CHECK(gl.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
    gl.Viewport(0, 0, 4, 4);
    gl.ClearColor(rgba[0] / 255.0f, rgba[1] / 255.0f, rgba[2] / 255.0f, rgba[3] / 255.0f);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    std::vector<uint8_t> pixels(4 * 4 * 4, 0xEE);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, 4, 4, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
    CHECK(gl.GetError() == GL_NO_ERROR);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteFramebuffers(1, &fbo);
    gl.DeleteRenderbuffers(1, &rb);
    return pixels;
}

bool allPixels(const std::vector<uint8_t>& pixels, std::array<uint8_t, 4> rgba) {
    for (size_t i = 0; i < pixels.size(); ++i)
        if (pixels[i] != rgba[i % 4]) return false;
    return true;
}

void checkCoreContext(Context& ctx, ContextKind kind) {
    INFO(ctx.platform() << ": GL_RENDERER " << ctx.renderer() << ", GL_VERSION " << ctx.version());
    CHECK(ctx.kind() == kind);
    CHECK(ctx.versionNumber() >= 33);
    CHECK(!ctx.renderer().empty());
    CHECK(!ctx.version().empty());
    CHECK(!ctx.shadingLanguageVersion().empty());
    CHECK(ctx.getProcAddress("glClear") != nullptr);
    const std::array<uint8_t, 4> colour{51, 102, 153, 204};
    CHECK(allPixels(clearFbo(ctx, colour), colour));
}

}  // namespace

TEST_CASE("gl context: kind names", "[gl]") {
    CHECK(parseContextKind("osmesa") == ContextKind::OSMesa);
    CHECK(parseContextKind("egl") == ContextKind::Egl);
    CHECK(!parseContextKind("glx"));
    CHECK(contextKindName(ContextKind::OSMesa) == "osmesa");
    CHECK(contextKindName(ContextKind::Egl) == "egl");
}

TEST_CASE("gl context: OSMesa makes a 3.3 core context and clears an FBO", "[gl]") {
    if (!contextKindBuilt(ContextKind::OSMesa)) return;  // built with PS11_GL_OSMESA=OFF
    std::string error;
    std::unique_ptr<Context> ctx = createContext(ContextKind::OSMesa, error);
    INFO(error);
    REQUIRE(ctx);
    CHECK(error.empty());
    CHECK(ctx->platform() == "OSMesa");
    checkCoreContext(*ctx, ContextKind::OSMesa);
}

TEST_CASE("gl context: EGL makes a 3.3 core context and clears an FBO", "[gl]") {
    std::string error;
    std::unique_ptr<Context> ctx = createContext(ContextKind::Egl, error);
    INFO(error);
    REQUIRE(ctx);
    CHECK(error.empty());
    // Mesa's surfaceless platform is tried first and exists on Debian 12.
    CHECK(ctx->platform() == "EGL surfaceless");
    checkCoreContext(*ctx, ContextKind::Egl);
}

TEST_CASE("gl context: the default is OSMesa, then EGL", "[gl]") {
    std::string error;
    std::unique_ptr<Context> ctx = createContext(std::nullopt, error);
    INFO(error);
    REQUIRE(ctx);
    CHECK(ctx->kind() == (contextKindBuilt(ContextKind::OSMesa) ? ContextKind::OSMesa : ContextKind::Egl));
}

TEST_CASE("gl context: the EGL device platform", "[gl]") {
    // Mesa lists its software device (EGL_MESA_device_software) even without a GPU.
    ContextOptions options;
    options.kind = ContextKind::Egl;
    options.eglPlatform = EglPlatform::Device;
    std::string error;
    std::unique_ptr<Context> ctx = createContext(options, error);
    INFO(error);
    REQUIRE(ctx);
    CHECK(ctx->platform().rfind("EGL device ", 0) == 0);
    checkCoreContext(*ctx, ContextKind::Egl);

    // A device index past the list is an error that says so, not a crash.
    options.eglDevice = 1000;
    error.clear();
    CHECK(createContext(options, error) == nullptr);
    CHECK(error.rfind("EGL: device 1000 asked for, but eglQueryDevicesEXT lists ", 0) == 0);
}

TEST_CASE("gl context: two contexts on one EGL display live and die independently", "[gl]") {
    std::string error;
    std::unique_ptr<Context> a = createContext(ContextKind::Egl, error);
    std::unique_ptr<Context> b = createContext(ContextKind::Egl, error);
    INFO(error);
    REQUIRE(a);
    REQUIRE(b);
    const std::array<uint8_t, 4> red{255, 0, 0, 255}, blue{0, 0, 255, 128};
    CHECK(allPixels(clearFbo(*a, red), red));
    CHECK(allPixels(clearFbo(*b, blue), blue));
    // The display is shared: destroying one context must not terminate it under the other.
    a.reset();
    CHECK(allPixels(clearFbo(*b, red), red));
}

TEST_CASE("gl context: OSMesa and EGL contexts side by side", "[gl]") {
    if (!contextKindBuilt(ContextKind::OSMesa)) return;  // built with PS11_GL_OSMESA=OFF
    std::string error;
    std::unique_ptr<Context> os = createContext(ContextKind::OSMesa, error);
    std::unique_ptr<Context> egl = createContext(ContextKind::Egl, error);
    INFO(error);
    REQUIRE(os);
    REQUIRE(egl);
    const std::array<uint8_t, 4> green{0, 255, 0, 255}, grey{128, 128, 128, 0};
    CHECK(allPixels(clearFbo(*os, green), green));
    CHECK(allPixels(clearFbo(*egl, grey), grey));
    CHECK(allPixels(clearFbo(*os, grey), grey));
}
