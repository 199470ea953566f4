// bench_peer_check: is the peer honest? The adaptive glare frame (Sousa, published settings,
// 1920×1080) two ways on Mesa llvmpipe (2 threads), in one process, frames interleaved:
//  - BM_AdaptiveHandGlsl's side: the technique's passes written by hand, as a graphics programmer
//    would write them for a GPU: GLSL 4.50 fragment shaders over a full-screen triangle, RGBA8
//    textures, texture() with GL_LINEAR / GL_NEAREST sampler objects, float math,
//    glBlitFramebuffer for the luminance chain, GL blending for the adaptation blend, the same
//    target sizes, passes and taps as glare/adaptive.cpp builds. Its own context
//    (emu::gl::createContext). Time: wall time of issuing the 15 passes + one glFinish.
//    `hand_sync_ms` is the same frame with a glFinish after every pass (as the pass graph
//    times the native side), which also gives the hand version's per-pass times.
//  - BM_AdaptiveNative's side: the same frame through the project: a glare::Runner whose device
//    renderer is the GL renderer in native mode (runner/gl_backend.h); time =
//    FrameResult::milliseconds (each pass ends with the renderer finished).
// Both benchmarks run one frame of each side per iteration (order alternating); they differ only
// in which side's time is the benchmark's own. Counters: the medians, native/hand ratios, and
// the hand output against the native output on frame 0 (max |d|, 8-bit levels, RGB). Per-pass
// medians of both sides go to stderr. OSMesa by default, EGL with PS11_GL=egl.
// bench/README.md "bench_peer_check".
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "emu/gl/context.h"
#include "emu/gl/shader_program.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "runner/gl_backend.h"

namespace {

constexpr uint32_t kW = 1920, kH = 1080;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

const char* glKind() {
    const char* k = std::getenv("PS11_GL");
    return k ? k : "osmesa";
}

// ---- the hand-written GLSL version ----

const char* const kVertex = R"(#version 450 core
out vec2 uv;
void main() {
    // One triangle over the viewport: uv 0..1 across it, so uv = gl_FragCoord.xy / size.
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    uv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";
// PEER_HAND_QUAD=1 (an attribution knob, not the default): two triangles over the viewport, as
// the D3D quad the native side draws.
const char* const kVertexQuad = R"(#version 450 core
out vec2 uv;
const vec2 corners[6] = vec2[6](vec2(0, 0), vec2(1, 0), vec2(0, 1), vec2(0, 1), vec2(1, 0), vec2(1, 1));
void main() {
    vec2 p = corners[gl_VertexID];
    uv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

bool handQuad() {
    const char* q = std::getenv("PEER_HAND_QUAD");
    return q && *q == '1';
}

// The 2x2 luminance level, four point samples at its texel centres, averaged; 4·avg² as the
// 1.1-class card computes mov_x4/mul_x4 (clamped to 1); luminance; alpha = smoothing.
const char* const kAmount = R"(#version 450 core
layout(binding = 0) uniform sampler2D lum;
uniform vec4 smoothing;
out vec4 o;
void main() {
    vec4 avg = 0.25 * (texture(lum, vec2(0.25, 0.25)) + texture(lum, vec2(0.75, 0.25)) +
                       texture(lum, vec2(0.25, 0.75)) + texture(lum, vec2(0.75, 0.75)));
    vec3 sq = min(4.0 * avg.rgb * avg.rgb, vec3(1.0));
    float l = clamp(dot(sq, vec3(0.30, 0.59, 0.11)), 0.0, 1.0);
    o = vec4(vec3(l), smoothing.a);
}
)";

// W/8 x H/8, the scene point-sampled; b = saturate(c − t)·w, b·min(4b, 1), ·(1 − A), alpha 1.
const char* const kBright = R"(#version 450 core
layout(binding = 0) uniform sampler2D scene;
layout(binding = 1) uniform sampler2D adapted;
uniform vec4 threshold;  // (t, t, t, 0)
uniform vec4 amount;     // (w, w, w, 1)
in vec2 uv;
out vec4 o;
void main() {
    vec3 b = clamp(texture(scene, uv).rgb - threshold.rgb, 0.0, 1.0) * amount.rgb;
    b *= min(4.0 * b, vec3(1.0));
    o = vec4(b * (1.0 - texture(adapted, vec2(0.5)).rgb), amount.a);
}
)";

// Four bilinear taps of ¼ at the pinwheel offsets (in uv, set per pass).
const char* const kBlur = R"(#version 450 core
layout(binding = 0) uniform sampler2D src;
uniform vec4 off01;  // tap 0 xy, tap 1 xy
uniform vec4 off23;
in vec2 uv;
out vec4 o;
void main() {
    o = 0.25 * (texture(src, uv + off01.xy) + texture(src, uv + off01.zw) + texture(src, uv + off23.xy) +
                texture(src, uv + off23.zw));
}
)";

// Screen composite: S + G·(1 − S), S point-sampled 1:1, G bilinear (the upsample).
const char* const kComposite = R"(#version 450 core
layout(binding = 0) uniform sampler2D scene;
layout(binding = 1) uniform sampler2D glare;
in vec2 uv;
out vec4 o;
void main() {
    vec4 s = texture(scene, uv);
    o = texture(glare, uv) * (1.0 - s) + s;
}
)";

class HandAdaptive {
public:
    static constexpr int kPasses = 15;
    static const char* passName(int i) {
        static const char* const names[kPasses] = {"luminance_128", "luminance_64", "luminance_32", "luminance_16",
                                                   "luminance_8",   "luminance_4",  "luminance_2",  "glare_amount",
                                                   "bright_pass",   "blur_0",       "blur_1",       "blur_2",
                                                   "blur_3",        "blur_4",       "composite"};
        return names[i];
    }

    // threshold t, glare amount w, smoothing a, divisor d, blur passes n: the published settings.
    bool init(const emu::RgbaImage& scene, float t, float w, float a, uint32_t d, int n, std::string& err) {
        m_t = t, m_w = w, m_a = a, m_blurs = n;
        auto kind = emu::gl::parseContextKind(glKind());
        m_ctx = emu::gl::createContext(kind, err);
        if (!m_ctx) return false;
        const auto& gl = m_ctx->gl();
        gl.GenVertexArrays(1, &m_vao);
        gl.BindVertexArray(m_vao);
        GLuint samplers[2];
        gl.GenSamplers(2, samplers);
        m_point = samplers[0], m_linear = samplers[1];
        for (GLuint s : samplers) {
            const GLint f = s == m_point ? GL_NEAREST : GL_LINEAR;
            gl.SamplerParameteri(s, GL_TEXTURE_MIN_FILTER, f);
            gl.SamplerParameteri(s, GL_TEXTURE_MAG_FILTER, f);
            gl.SamplerParameteri(s, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
            gl.SamplerParameteri(s, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        }
        // Targets: scene, output, luminance 128..2, adapted 1x1, bright, blur 0..n−1.
        m_scene = target(kW, kH);
        m_output = target(kW, kH);
        for (uint32_t s = 128; s >= 2; s /= 2) m_lum.push_back(target(s, s));
        m_adapted = target(1, 1);
        m_bw = std::max(kW / d, 1u), m_bh = std::max(kH / d, 1u);
        m_bright = target(m_bw, m_bh);
        for (int k = 0; k < n; ++k) m_blur.push_back(target(m_bw, m_bh));
        gl.BindTexture(GL_TEXTURE_2D, m_scene.tex);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, GLsizei(kW), GLsizei(kH), GL_RGBA, GL_UNSIGNED_BYTE, scene.rgba.data());
        const GLubyte zero[4] = {0, 0, 0, 0};
        gl.ClearTexSubImage(m_adapted.tex, 0, 0, 0, 0, 1, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, zero);
        if (!(m_pAmount = program(kAmount, err)) || !(m_pBright = program(kBright, err)) ||
            !(m_pBlur = program(kBlur, err)) || !(m_pComposite = program(kComposite, err)))
            return false;
        gl.UseProgram(m_pBright);
        gl.Uniform4f(gl.GetUniformLocation(m_pBright, "threshold"), t, t, t, 0);
        gl.Uniform4f(gl.GetUniformLocation(m_pBright, "amount"), w, w, w, 1);
        gl.UseProgram(m_pAmount);
        gl.Uniform4f(gl.GetUniformLocation(m_pAmount, "smoothing"), 0, 0, 0, a);
        m_off01 = gl.GetUniformLocation(m_pBlur, "off01");
        m_off23 = gl.GetUniformLocation(m_pBlur, "off23");
        gl.Finish();
        if (GLenum e = gl.GetError(); e != GL_NO_ERROR) {
            err = "GL error " + std::to_string(e) + " in setup";
            return false;
        }
        return true;
    }

    // One frame; `blend`: the adaptation blend (off on frame 0: the converged start). With
    // `perPass` a glFinish after each pass and its time in passMs. Returns the frame's ms.
    double frame(bool blend, bool perPass, std::vector<double>* passMs = nullptr) {
        m_ctx->makeCurrent();
        const auto& gl = m_ctx->gl();
        gl.BindVertexArray(m_vao);
        gl.Disable(GL_SCISSOR_TEST);
        gl.Disable(GL_DEPTH_TEST);
        gl.Disable(GL_BLEND);
        int pass = 0;
        auto start = Clock::now(), passStart = start;
        auto endPass = [&] {
            if (!perPass) return;
            gl.Finish();
            if (passMs) passMs->at(size_t(pass)) = msSince(passStart);
            ++pass;
            passStart = Clock::now();
        };
        // Luminance: scene → 128x128 → … → 2x2, bilinear blits.
        const Target* src = &m_scene;
        for (const Target& l : m_lum) {
            gl.BindFramebuffer(GL_READ_FRAMEBUFFER, src->fbo);
            gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, l.fbo);
            gl.BlitFramebuffer(0, 0, GLint(src->w), GLint(src->h), 0, 0, GLint(l.w), GLint(l.h), GL_COLOR_BUFFER_BIT,
                               GL_LINEAR);
            src = &l;
            endPass();
        }
        // Glare amount into the 1x1, blended SRCALPHA / INVSRCALPHA.
        bindTarget(m_adapted);
        gl.UseProgram(m_pAmount);
        bindTexture(0, m_lum.back(), m_point);
        if (blend) {
            gl.Enable(GL_BLEND);
            gl.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
            gl.BlendEquationSeparate(GL_FUNC_ADD, GL_FUNC_ADD);
        }
        gl.DrawArrays(GL_TRIANGLES, 0, m_vertices);
        gl.Disable(GL_BLEND);
        endPass();
        // Bright pass at W/d x H/d.
        bindTarget(m_bright);
        gl.UseProgram(m_pBright);
        bindTexture(0, m_scene, m_point);
        bindTexture(1, m_adapted, m_point);
        gl.DrawArrays(GL_TRIANGLES, 0, m_vertices);
        endPass();
        // Pinwheel blur.
        src = &m_bright;
        gl.UseProgram(m_pBlur);
        for (int k = 0; k < m_blurs; ++k) {
            const float s = 0.5f * float(k) + 0.5f, l = float(k) + 0.5f;
            const float du = 1.0f / float(m_bw), dv = 1.0f / float(m_bh);
            bindTarget(m_blur[size_t(k)]);
            bindTexture(0, *src, m_linear);
            gl.Uniform4f(m_off01, +s * du, +l * dv, -l * du, +s * dv);
            gl.Uniform4f(m_off23, -s * du, -l * dv, +l * du, -s * dv);
            gl.DrawArrays(GL_TRIANGLES, 0, m_vertices);
            src = &m_blur[size_t(k)];
            endPass();
        }
        // Composite at full size.
        bindTarget(m_output);
        gl.UseProgram(m_pComposite);
        bindTexture(0, m_scene, m_point);
        bindTexture(1, *src, m_linear);
        gl.DrawArrays(GL_TRIANGLES, 0, m_vertices);
        if (perPass) endPass();
        else gl.Finish();
        return msSince(start);
    }

    emu::RgbaImage readOutput() {
        m_ctx->makeCurrent();
        const auto& gl = m_ctx->gl();
        emu::RgbaImage img{kW, kH, std::vector<uint8_t>(size_t(kW) * kH * 4)};
        gl.BindTexture(GL_TEXTURE_2D, m_output.tex);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
        gl.GetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, img.rgba.data());
        return img;
    }
    std::string description() const { return m_ctx ? m_ctx->renderer() + " (" + m_ctx->platform() + ")" : ""; }

private:
    struct Target {
        GLuint tex = 0, fbo = 0;
        uint32_t w = 0, h = 0;
    };
    Target target(uint32_t w, uint32_t h) {
        const auto& gl = m_ctx->gl();
        Target t{0, 0, w, h};
        gl.GenTextures(1, &t.tex);
        gl.BindTexture(GL_TEXTURE_2D, t.tex);
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, GLsizei(w), GLsizei(h));
        gl.GenFramebuffers(1, &t.fbo);
        gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t.tex, 0);
        const GLenum buffers[1] = {GL_COLOR_ATTACHMENT0};
        gl.DrawBuffers(1, buffers);
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        return t;
    }
    void bindTarget(const Target& t) {
        const auto& gl = m_ctx->gl();
        gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
        gl.Viewport(0, 0, GLsizei(t.w), GLsizei(t.h));
    }
    void bindTexture(GLuint unit, const Target& t, GLuint sampler) {
        const auto& gl = m_ctx->gl();
        gl.ActiveTexture(GL_TEXTURE0 + unit);
        gl.BindTexture(GL_TEXTURE_2D, t.tex);
        gl.BindSampler(unit, sampler);
    }
    GLuint program(const char* fragment, std::string& err) {
        const auto& gl = m_ctx->gl();
        std::string log;
        const GLuint vs = emu::gl::compileShader(gl, GL_VERTEX_SHADER, handQuad() ? kVertexQuad : kVertex, log);
        const GLuint p = vs ? emu::gl::linkProgram(gl, vs, fragment, log) : 0;
        if (vs) gl.DeleteShader(vs);
        if (!p) {
            err = "shader: " + log;
            return 0;
        }
        return p;
    }

    std::unique_ptr<emu::gl::Context> m_ctx;
    GLsizei m_vertices = handQuad() ? 6 : 3;
    GLuint m_vao = 0, m_point = 0, m_linear = 0;
    GLuint m_pAmount = 0, m_pBright = 0, m_pBlur = 0, m_pComposite = 0;
    GLint m_off01 = -1, m_off23 = -1;
    Target m_scene, m_output, m_adapted, m_bright;
    std::vector<Target> m_lum, m_blur;
    uint32_t m_bw = 0, m_bh = 0;
    float m_t = 0, m_w = 0, m_a = 0;
    int m_blurs = 0;
};

// ---- the shared set-up: both sides, made once per process ----

struct Peers {
    const glare::Technique* technique = nullptr;
    glare::Settings settings;
    std::unique_ptr<glare::Runner> native;
    HandAdaptive hand;
    int frame = 1;  // the next frame number (frame 0 ran in set-up, unblended on both sides)
    int maxDiff = 0;
    double meanDiff = 0, overOnePct = 0;
    std::string label, error;
};

Peers* peers() {
    static Peers* p = [] {
        auto* q = new Peers;
        std::string& err = q->error;
        q->technique = glare::findTechnique("adaptive");
        q->settings = *glare::presetSettings(*q->technique, "published");
        const glare::Settings& s = q->settings;
        // The scene frame the technique gets, rendered on the emulator.
        glare::RunnerOptions eo;
        eo.width = kW, eo.height = kH;
        eo.device.software.threads = 2;
        glare::Runner emuRun(eo);
        std::unique_ptr<glare::Scene> scene = glare::makeScene(q->technique->scene(), err);
        double ms = 0;
        std::optional<emu::RgbaImage> img;
        if (!scene || !emuRun.renderScene(*scene, 0, 8, ms, err) ||
            !(img = emuRun.readTexture(emuRun.sceneTexture(), err)))
            return q;
        // Native mode.
        glare::RunnerOptions no;
        no.width = kW, no.height = kH;
        no.device.renderer = ps11test::glRendererFactory(glKind(), err, /*native=*/true);
        if (!no.device.renderer) return q;
        q->native = std::make_unique<glare::Runner>(no);
        if (!q->native->setImage(*img, err)) return q;
        // By hand, with the preset's values (adaptive.cpp reads the same settings).
        auto get = [&](const char* name) { return s.at(name); };
        if (get("luminance") != 0 || get("composite") != 0 || get("start") != 0) {
            err = "the published preset changed (luminance, composite or start): update the hand version";
            return q;
        }
        if (!q->hand.init(*img, float(get("threshold")), float(get("glare_amount")), float(get("smoothing")),
                          uint32_t(get("divisor")), int(get("blur_passes")), err))
            return q;
        // Frame 0 of each (the converged start), outputs compared outside any timing.
        glare::FrameResult r;
        if (!q->native->runFrame(*q->technique, s, 0, 1, r, err)) return q;
        if (r.passes.size() != HandAdaptive::kPasses) {
            err = "native frame has " + std::to_string(r.passes.size()) + " passes, the hand version 15";
            return q;
        }
        q->hand.frame(false, false);
        std::optional<emu::RgbaImage> a = q->native->readOutput(err);
        if (!a) return q;
        const emu::RgbaImage b = q->hand.readOutput();
        uint64_t sum = 0, over = 0;
        for (size_t i = 0; i < a->rgba.size(); i += 4) {
            int m = 0;
            for (int c = 0; c < 3; ++c) {
                const int d = std::abs(int(a->rgba[i + c]) - int(b.rgba[i + c]));
                m = std::max(m, d);
                sum += uint64_t(d);
            }
            q->maxDiff = std::max(q->maxDiff, m);
            over += m > 1;
        }
        const double px = double(a->rgba.size() / 4);
        q->meanDiff = double(sum) / (3 * px);
        q->overOnePct = 100.0 * double(over) / px;
        // Warm-up (llvmpipe compiles the blended variant of the amount pass on first use).
        for (int f = 1; f <= 2; ++f, ++q->frame) {
            if (!q->native->runFrame(*q->technique, s, f, f + 1, r, err)) return q;
            q->hand.frame(true, false);
        }
        q->label = ps11test::glRendererDescription();
        return q;
    }();
    return p;
}

void BM_Peer(benchmark::State& state, bool reportNative) {
    Peers& p = *peers();
    if (!p.native || !p.error.empty()) {
        state.SkipWithError(("set-up failed: " + p.error).c_str());
        return;
    }
    std::vector<double> handMs, syncMs, nativeMs;
    std::map<int, std::vector<double>> handPass, nativePass;
    std::vector<std::string> names;
    std::string err;
    int i = 0;
    for (auto _ : state) {
        glare::FrameResult r;
        double hand = 0, sync = 0;
        std::vector<double> perPass(HandAdaptive::kPasses, 0.0);
        auto runNative = [&] {
            p.native->device().finish();  // makes the renderer's context current, outside the timing
            return p.native->runFrame(*p.technique, p.settings, p.frame, p.frame + 1, r, err);
        };
        if (i % 2 == 0) {
            if (!runNative()) break;
            hand = p.hand.frame(true, false);
            sync = p.hand.frame(true, true, &perPass);
        } else {
            sync = p.hand.frame(true, true, &perPass);
            hand = p.hand.frame(true, false);
            if (!runNative()) break;
        }
        ++i, ++p.frame;
        handMs.push_back(hand);
        syncMs.push_back(sync);
        nativeMs.push_back(r.milliseconds);
        names.clear();
        for (size_t k = 0; k < r.passes.size(); ++k) {
            nativePass[int(k)].push_back(r.passes[k].milliseconds);
            names.push_back(r.passes[k].pass);
        }
        for (int k = 0; k < HandAdaptive::kPasses; ++k) handPass[k].push_back(perPass[size_t(k)]);
        state.SetIterationTime((reportNative ? r.milliseconds : hand) / 1000);
    }
    if (!err.empty()) {
        state.SkipWithError(err.c_str());
        return;
    }
    const double hm = median(handMs), sm = median(syncMs), nm = median(nativeMs);
    state.counters["hand_ms"] = hm;
    state.counters["hand_sync_ms"] = sm;
    state.counters["native_ms"] = nm;
    state.counters["native_over_hand"] = nm / hm;
    state.counters["native_over_hand_sync"] = nm / sm;
    state.counters["max_d"] = p.maxDiff;
    state.counters["mean_d"] = p.meanDiff;
    state.counters["pct_d_over_1"] = p.overOnePct;
    state.SetLabel(p.label);
    std::fprintf(stderr, "%s: per-pass medians (ms) over %zu frames\n  %-14s %8s %8s %6s\n",
                 reportNative ? "BM_AdaptiveNative" : "BM_AdaptiveHandGlsl", handMs.size(), "pass", "hand", "native",
                 "ratio");
    for (int k = 0; k < HandAdaptive::kPasses; ++k) {
        const double h = median(handPass[k]), n = median(nativePass[k]);
        std::fprintf(stderr, "  %-14s %8.3f %8.3f %6.2f%s\n", HandAdaptive::passName(k), h, n, h > 0 ? n / h : 0.0,
                     size_t(k) < names.size() && names[size_t(k)] != HandAdaptive::passName(k)
                         ? (" (native: " + names[size_t(k)] + ")").c_str()
                         : "");
    }
}

void BM_AdaptiveHandGlsl(benchmark::State& state) { BM_Peer(state, false); }
void BM_AdaptiveNative(benchmark::State& state) { BM_Peer(state, true); }

}  // namespace

BENCHMARK(BM_AdaptiveHandGlsl)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(15);
BENCHMARK(BM_AdaptiveNative)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(15);

int main(int argc, char** argv) {
    // llvmpipe's thread count is read when the first context is made: 2 unless set already.
    setenv("LP_NUM_THREADS", "2", 0);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
