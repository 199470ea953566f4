// The GL renderer's native mode (emu/gl/glsl.h FragmentSpec::native, emu/gl/native_merge.h):
// D3D9 merge states → GL blend and depth state, native shaders free of doubles and of the exact
// mode's triangle record, and (on this machine's GL context) the native vertex and fragment
// shaders compiling and linking, the merge state applying without GL errors, and a drawn quad
// landing on D3D9's pixel centres.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "emu/gl/context.h"
#include "emu/gl/glsl.h"
#include "emu/gl/native_merge.h"
#include "emu/gl/shader_program.h"
#include "ps11/assembler.h"
#include "ps11/executor.h"
#include "ps11/decoded_program.h"
#include "ps11/validator.h"

using namespace emu;
using namespace emu::gl;

namespace {

ps11::exec::DecodedProgram decode(const std::string& text, ps11::Precision precision = ps11::Precision::Float) {
    ps11::Diagnostics diags;
    std::optional<ps11::Program> program = ps11::parseAssembly(text, "t.psh", {}, diags);
    INFO(text << diags.formatAll());
    REQUIRE(program.has_value());
    REQUIRE(ps11::validate(*program, diags));
    ps11::ExecutorOptions options;
    options.precision = precision;
    ps11::exec::DecodedProgram decoded;
    REQUIRE(ps11::exec::decodeProgram(*program, options, diags, decoded));
    return decoded;
}

// A native spec of `decoded` with every sampled stage bound to a 2-D texture.
FragmentSpec nativeSpec(const ps11::exec::DecodedProgram& decoded) {
    FragmentSpec spec;
    spec.program = &decoded;
    spec.precision = ps11::Precision::Float;
    spec.native = true;
    spec.shaderDepth = decoded.writesDepth;
    for (int s = 0; s < 8; ++s) spec.stages[size_t(s)].bound = ((decoded.stagesUsed >> s) & 1) != 0;
    return spec;
}

const char* const kSmall = "ps_1_1\ntex t0\nmad r0, t0, v0, v0_bias\n";
const char* const kTexkillBem = "ps_1_1\ntex t0\ntexbem t1, t0\ntexkill t2\nmul_sat r0, t1, v1\n";
const char* const kDepth = "ps_1_3\ntex t0\ntexm3x2pad t1, t0_bx2\ntexm3x2depth t2, t0_bx2\nmov r0, v0\n";

// Compiles and links the native vertex shader with `fragment`; 0 and the logs on failure.
GLuint link(const GlFunctions& gl, const std::string& fragment, std::string& log) {
    const GLuint vs = compileShader(gl, GL_VERTEX_SHADER, nativeVertexSource(), log);
    if (!vs) return 0;
    const GLuint prog = linkProgram(gl, vs, fragment, log);
    gl.DeleteShader(vs);
    return prog;
}

}  // namespace

TEST_CASE("glsl native: merge state ONE/ONE ADD", "[glsl_native]") {
    MergeState m;
    m.blend = true;
    m.srcBlend = D3DBLEND_ONE;
    m.dstBlend = D3DBLEND_ONE;
    const NativeMerge n = nativeMergeOf(m, false);
    CHECK(n.blend);
    CHECK(n.srcRgb == GL_ONE);
    CHECK(n.dstRgb == GL_ONE);
    CHECK(n.srcAlpha == GL_ONE);
    CHECK(n.dstAlpha == GL_ONE);
    CHECK(n.eqRgb == GL_FUNC_ADD);
    CHECK(n.eqAlpha == GL_FUNC_ADD);
    CHECK(n.exact);
    CHECK(n.colorMask == std::array<bool, 4>{true, true, true, true});
    CHECK_FALSE(n.depthTest);
    CHECK_FALSE(n.depthWrite);
}

TEST_CASE("glsl native: merge state SRCALPHA/INVSRCALPHA, separate alpha, blend factor", "[glsl_native]") {
    MergeState m;
    m.blend = true;
    m.srcBlend = D3DBLEND_SRCALPHA;
    m.dstBlend = D3DBLEND_INVSRCALPHA;
    m.blendOp = D3DBLENDOP_REVSUBTRACT;
    NativeMerge n = nativeMergeOf(m, false);
    CHECK(n.srcRgb == GL_SRC_ALPHA);
    CHECK(n.dstRgb == GL_ONE_MINUS_SRC_ALPHA);
    // Without SEPARATEALPHABLENDENABLE alpha blends as colour.
    CHECK(n.srcAlpha == GL_SRC_ALPHA);
    CHECK(n.dstAlpha == GL_ONE_MINUS_SRC_ALPHA);
    CHECK(n.eqRgb == GL_FUNC_REVERSE_SUBTRACT);
    CHECK(n.eqAlpha == GL_FUNC_REVERSE_SUBTRACT);
    CHECK(n.exact);

    m.separateAlpha = true;
    m.srcBlendAlpha = D3DBLEND_BLENDFACTOR;
    m.dstBlendAlpha = D3DBLEND_SRCALPHASAT;
    m.blendOpAlpha = D3DBLENDOP_SUBTRACT;
    m.blendFactor = 0x80ff4000;  // a 0x80, r 0xff, g 0x40, b 0x00
    n = nativeMergeOf(m, false);
    CHECK(n.srcRgb == GL_SRC_ALPHA);
    CHECK(n.srcAlpha == GL_CONSTANT_COLOR);
    CHECK(n.dstAlpha == GL_SRC_ALPHA_SATURATE);
    CHECK(n.eqAlpha == GL_FUNC_SUBTRACT);
    CHECK(n.blendColor[0] == 1.0f);
    CHECK(n.blendColor[1] == 64.0f / 255.0f);
    CHECK(n.blendColor[2] == 0.0f);
    CHECK(n.blendColor[3] == 128.0f / 255.0f);
}

TEST_CASE("glsl native: merge state BOTHSRCALPHA and BOTHINVSRCALPHA", "[glsl_native]") {
    MergeState m;
    m.blend = true;
    m.srcBlend = D3DBLEND_BOTHSRCALPHA;
    m.dstBlend = D3DBLEND_ONE;  // overridden
    NativeMerge n = nativeMergeOf(m, false);
    CHECK(n.srcRgb == GL_SRC_ALPHA);
    CHECK(n.dstRgb == GL_ONE_MINUS_SRC_ALPHA);
    CHECK(n.srcAlpha == GL_SRC_ALPHA);
    CHECK(n.dstAlpha == GL_ONE_MINUS_SRC_ALPHA);
    CHECK_FALSE(n.exact);

    m.srcBlend = D3DBLEND_BOTHINVSRCALPHA;
    n = nativeMergeOf(m, false);
    CHECK(n.srcRgb == GL_ONE_MINUS_SRC_ALPHA);
    CHECK(n.dstRgb == GL_SRC_ALPHA);
    CHECK_FALSE(n.exact);

    // As a destination factor: the destination half of the pair.
    m.srcBlend = D3DBLEND_ONE;
    m.dstBlend = D3DBLEND_BOTHSRCALPHA;
    n = nativeMergeOf(m, false);
    CHECK(n.srcRgb == GL_ONE);
    CHECK(n.dstRgb == GL_ONE_MINUS_SRC_ALPHA);
    CHECK_FALSE(n.exact);

    // An unknown value acts as the default (ONE) and is not exact either.
    m.dstBlend = D3DBLEND(99);
    n = nativeMergeOf(m, false);
    CHECK(n.dstRgb == GL_ZERO);
    CHECK_FALSE(n.exact);
}

TEST_CASE("glsl native: merge state MIN, colour mask, kept channels", "[glsl_native]") {
    MergeState m;
    m.blend = true;
    m.srcBlend = D3DBLEND_SRCCOLOR;
    m.dstBlend = D3DBLEND_DESTCOLOR;
    m.blendOp = D3DBLENDOP_MIN;
    m.colorWrite = 1u | 4u;  // r and b
    NativeMerge n = nativeMergeOf(m, false);
    CHECK(n.eqRgb == GL_MIN);
    CHECK(n.eqAlpha == GL_MIN);
    CHECK(n.colorMask == std::array<bool, 4>{true, false, true, false});
    CHECK(n.exact);

    // Blending off: the mask as set, GL_BLEND off.
    m.blend = false;
    m.colorWrite = 8u;
    n = nativeMergeOf(m, false);
    CHECK_FALSE(n.blend);
    CHECK(n.colorMask == std::array<bool, 4>{false, false, false, true});

    // 0·src + 1·dst on colour only (separate alpha): the colour channels are not written.
    m.blend = true;
    m.colorWrite = 0xf;
    m.srcBlend = D3DBLEND_ZERO;
    m.dstBlend = D3DBLEND_ONE;
    m.blendOp = D3DBLENDOP_ADD;
    m.separateAlpha = true;
    m.srcBlendAlpha = D3DBLEND_ONE;
    m.dstBlendAlpha = D3DBLEND_ZERO;
    n = nativeMergeOf(m, false);
    CHECK(n.colorMask == std::array<bool, 4>{false, false, false, true});
}

TEST_CASE("glsl native: merge state depth LESSEQUAL", "[glsl_native]") {
    MergeState m;
    m.depthTest = true;
    m.depthWrite = true;
    m.depthFunc = D3DCMP_LESSEQUAL;
    NativeMerge n = nativeMergeOf(m, true);
    CHECK(n.depthTest);
    CHECK(n.depthFunc == GL_LEQUAL);
    CHECK(n.depthWrite);
    CHECK(n.depthClamp);
    CHECK_FALSE(n.blend);

    m.depthFunc = D3DCMP_GREATER;
    m.depthWrite = false;
    n = nativeMergeOf(m, true);
    CHECK(n.depthFunc == GL_GREATER);
    CHECK_FALSE(n.depthWrite);

    // No depth surface: no test, no write.
    m.depthWrite = true;
    n = nativeMergeOf(m, false);
    CHECK_FALSE(n.depthTest);
    CHECK_FALSE(n.depthWrite);
}

TEST_CASE("glsl native: shaders have no doubles and no triangle record", "[glsl_native]") {
    for (const char* text : {kSmall, kTexkillBem, kDepth}) {
        const ps11::exec::DecodedProgram decoded = decode(text);
        FragmentSpec spec = nativeSpec(decoded);
        spec.merge.fog = true;
        spec.merge.alphaTest = true;
        spec.merge.alphaMask = cmpMask(D3DCMP_GREATEREQUAL);
        spec.merge.alphaRef = 128;
        const std::string fs = fragmentSource(spec);
        INFO(text << "\n" << fs);
        CHECK(fs.find("double") == std::string::npos);
        CHECK(fs.find("lf") == std::string::npos);
        CHECK(fs.find("int64") == std::string::npos);
        CHECK(fs.find("uTri") == std::string::npos);
        CHECK(fs.find("uDstColor") == std::string::npos);
        CHECK(fs.find("uBorder") == std::string::npos);
        CHECK(fs.find("texture(uT0") != std::string::npos);
        CHECK(fs.find("layout(location = 0) out vec4 oColor;") != std::string::npos);
        CHECK(fs.find("discard") != std::string::npos);
        CHECK((fs.find("gl_FragDepth") != std::string::npos) == decoded.writesDepth);
    }
    const std::string vs = nativeVertexSource();
    CHECK(vs.find("double") == std::string::npos);
    CHECK(vs.find("layout(location = 10) in vec4 aTex7;") != std::string::npos);
    CHECK(vs.find("uniform vec4 uXform;") != std::string::npos);
}

TEST_CASE("glsl native: shaders compile and link, merge state applies, pixel centres", "[glsl_native][gl]") {
    std::string error;
    std::unique_ptr<Context> ctx = createContext(std::nullopt, error);
    INFO(error);
    REQUIRE(ctx);  // as the other GL tests: CI installs OpenGL
    REQUIRE(ctx->makeCurrent());
    const GlFunctions& gl = ctx->gl();
    while (gl.GetError() != GL_NO_ERROR) {
    }

    for (const char* text : {kSmall, kTexkillBem, kDepth}) {
        const ps11::exec::DecodedProgram decoded = decode(text);
        for (int variant = 0; variant < 3; ++variant) {
            FragmentSpec spec = nativeSpec(decoded);
            spec.merge.fog = variant >= 1;
            spec.merge.alphaTest = variant >= 1;
            spec.merge.alphaMask = cmpMask(D3DCMP_LESS);
            spec.merge.alphaRef = 7;
            if (variant == 2) spec.stages[0].bound = false;  // an unbound stage samples (0, 0, 0, 1)
            std::string log;
            const GLuint prog = link(gl, fragmentSource(spec), log);
            INFO(text << " variant " << variant << "\n" << log << "\n" << fragmentSource(spec));
            CHECK(prog != 0);
            if (prog) gl.DeleteProgram(prog);
        }
    }

    // Every merge state maps to values GL accepts (SRCALPHASAT as a destination factor included).
    MergeState m;
    m.blend = true;
    m.srcBlend = D3DBLEND_INVBLENDFACTOR;
    m.dstBlend = D3DBLEND_SRCALPHASAT;
    m.blendOp = D3DBLENDOP_SUBTRACT;
    m.separateAlpha = true;
    m.srcBlendAlpha = D3DBLEND_BOTHINVSRCALPHA;
    m.blendOpAlpha = D3DBLENDOP_MAX;
    m.depthTest = true;
    m.depthFunc = D3DCMP_NOTEQUAL;
    m.colorWrite = 5;
    applyNativeMerge(gl, nativeMergeOf(m, true));
    CHECK(gl.GetError() == GL_NO_ERROR);
    GLint v = 0;
    gl.GetIntegerv(GL_BLEND_DST_RGB, &v);
    CHECK(GLenum(v) == GL_SRC_ALPHA_SATURATE);
    gl.GetIntegerv(GL_BLEND_EQUATION_ALPHA, &v);
    CHECK(GLenum(v) == GL_MAX);
    gl.GetIntegerv(GL_DEPTH_FUNC, &v);
    CHECK(GLenum(v) == GL_NOTEQUAL);
    applyNativeMerge(gl, nativeMergeOf(MergeState{}, false));
    CHECK(gl.GetError() == GL_NO_ERROR);

    // A D3D quad over pixels 1..2 of a 4x4 RGBA8 target (D3D vertices at 0.5 and 2.5: the
    // centres of pixels 1 and 2 lie inside, 0 and 3 outside), diffuse red to the right, with
    // glClipControl(GL_UPPER_LEFT, GL_ZERO_TO_ONE) and uXform = (2/W, -2/H, -1, 1).
    const ps11::exec::DecodedProgram decoded = decode("ps_1_1\nmov r0, v0\n");
    std::string log;
    const GLuint prog = link(gl, fragmentSource(nativeSpec(decoded)), log);
    INFO(log);
    REQUIRE(prog != 0);
    GLuint fbo = 0, rb = 0, vao = 0, vbo = 0;
    gl.GenFramebuffers(1, &fbo);
    gl.GenRenderbuffers(1, &rb);
    gl.BindRenderbuffer(GL_RENDERBUFFER, rb);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 4, 4);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
    REQUIRE(gl.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
    gl.Viewport(0, 0, 4, 4);
    gl.ClearColor(0, 0, 0, 0);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    gl.ClipControl(GL_UPPER_LEFT, GL_ZERO_TO_ONE);
    // x y z rhw, diffuse r g b a: two triangles; the colour is x (1/4 per pixel from 0.5)
    const float x0 = 0.5f, x1 = 2.5f, y0 = 0.5f, y1 = 2.5f;
    auto vert = [&](float x, float y) {
        return std::array<float, 8>{x, y, 0.5f, 1.0f, (x - 0.5f) / 4.0f, y / 4.0f, 0.0f, 1.0f};
    };
    std::vector<std::array<float, 8>> verts = {vert(x0, y0), vert(x1, y0), vert(x0, y1),
                                               vert(x1, y0), vert(x1, y1), vert(x0, y1)};
    gl.GenVertexArrays(1, &vao);
    gl.BindVertexArray(vao);
    gl.GenBuffers(1, &vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, vbo);
    gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(verts.size() * sizeof verts[0]), verts.data(), GL_STATIC_DRAW);
    gl.VertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 32, nullptr);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, 32, reinterpret_cast<const void*>(16));
    gl.EnableVertexAttribArray(1);
    gl.UseProgram(prog);
    gl.Uniform4f(gl.GetUniformLocation(prog, "uXform"), 2.0f / 4.0f, -2.0f / 4.0f, -1.0f, 1.0f);
    applyNativeMerge(gl, nativeMergeOf(MergeState{}, false));
    gl.DrawArrays(GL_TRIANGLES, 0, 6);
    std::vector<uint8_t> px(4 * 4 * 4, 0xEE);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, 4, 4, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
    CHECK(gl.GetError() == GL_NO_ERROR);
    // Row 0 of the read-back is D3D's row 0 (upper-left origin). Covered: pixels (1..2, 1..2),
    // red = (x − 0.5)/4 at the pixel centre x, green = y/4.
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            const uint8_t* p = &px[size_t(4 * (4 * y + x))];
            INFO("pixel " << x << ", " << y);
            const bool in = x >= 1 && x <= 2 && y >= 1 && y <= 2;
            CHECK(int(p[3]) == (in ? 255 : 0));
            if (in) {
                CHECK(std::abs(int(p[0]) - int(std::lround((x - 0.5) / 4.0 * 255.0))) <= 1);
                CHECK(std::abs(int(p[1]) - int(std::lround(y / 4.0 * 255.0))) <= 1);
            }
        }
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteFramebuffers(1, &fbo);
    gl.DeleteRenderbuffers(1, &rb);
    gl.DeleteBuffers(1, &vbo);
    gl.DeleteVertexArrays(1, &vao);
    gl.DeleteProgram(prog);
}
