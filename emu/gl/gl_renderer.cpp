// Renderer stage: the GL renderer's draws (emu/gl/gl_renderer.h), in stages: the program (decoded
// and translated once per configuration, then found by what determines it), the attributes (exact:
// the software rasteriser's setups as records, so both renderers shade the same values; native:
// the vertices as GL attributes), the bindings (resident surfaces and textures, samplers,
// uniforms) and the draw. Nothing is read back here: the device front asks when it needs to
// (gl_surfaces.cpp). Exact mode draws triangles in batches that do not overlap (a fragment reads
// the pixel it writes: ARB_texture_barrier); native mode draws them in one call with GL's blend.
#include "emu/gl/gl_renderer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include "emu/gl/gl_internal.h"
#include "emu/gl/glsl.h"
#include "emu/gl/native_merge.h"
#include "emu/gl/shader_program.h"
#include "emu/vertex.h"
#include "ps11/diagnostics.h"

namespace emu::gl {

namespace {

constexpr size_t kMaxCachedPrograms = 256;

bool hasExtension(const GlFunctions& gl, const char* name) {
    GLint n = 0;
    gl.GetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; ++i) {
        const char* e = reinterpret_cast<const char*>(gl.GetStringi(GL_EXTENSIONS, GLuint(i)));
        if (e && std::strcmp(e, name) == 0) return true;
    }
    return false;
}

// The triangle (window coordinates) with each edge moved out by `d`: the new corners are where
// neighbouring moved edges meet. False when a corner would move further than `reach` (a sharp
// corner) or the triangle is degenerate.
bool expandTriangle(const double* x, const double* y, double d, double reach, double* ox, double* oy) {
    const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if (!(std::fabs(area) > 0)) return false;
    const double sign = area > 0 ? 1.0 : -1.0;
    // Edge i from corner i to i+1: outward unit normal n and offset c (n·p = c on the moved edge).
    double nx[3], ny[3], c[3];
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3;
        const double dx = x[j] - x[i], dy = y[j] - y[i], len = std::hypot(dx, dy);
        if (!(len > 0)) return false;
        nx[i] = sign * dy / len, ny[i] = -sign * dx / len;
        c[i] = nx[i] * x[i] + ny[i] * y[i] + d;
    }
    for (int k = 0; k < 3; ++k) {
        const int a = (k + 2) % 3, b = k;  // the edges meeting at corner k
        const double det = nx[a] * ny[b] - ny[a] * nx[b];
        if (!(std::fabs(det) > 1e-12)) return false;
        ox[k] = (c[a] * ny[b] - ny[a] * c[b]) / det;
        oy[k] = (nx[a] * c[b] - c[a] * nx[b]) / det;
        if (!(std::hypot(ox[k] - x[k], oy[k] - y[k]) <= reach)) return false;
    }
    return true;
}


// FNV-1a over the values that determine a program's GLSL.
struct KeyHash {
    uint64_t h = 1469598103934665603ull;
    template <class T>
    KeyHash& operator<<(const T& v) {
        static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
        uint64_t x = 0;
        std::memcpy(&x, &v, std::min(sizeof v, sizeof x));
        for (int i = 0; i < 8; ++i) h = (h ^ ((x >> (8 * i)) & 0xff)) * 1099511628211ull;
        return *this;
    }
};

// Everything the GLSL writer reads besides the program itself.
uint64_t programKey(uint64_t space, const DrawProgram& prog, const ps11::HardwareConfig& hw, const FragmentSpec& spec) {
    KeyHash k;
    k << space << prog.key << uintptr_t(hw.hardware) << hw.precision << hw.maxValue << spec.weightBits << spec.usedAttributes
      << spec.shaderDepth << spec.wantZ << spec.hardwareFiltering << spec.native;
    for (const ps11::StageState& s : prog.stages)
        k << s.clampLuminance << s.transformFlags << s.coordComponents << s.textureDimensions;
    for (const StageSpec& s : spec.stages) {
        k << s.bound << s.volume << s.levels << s.unorm8 << s.packedWords << s.borderInRange << s.state.minFilter << s.state.magFilter
          << s.state.mipFilter << s.state.addressU << s.state.addressV << s.state.addressW;
    }
    const Plan& p = spec.merge;
    // Native shaders do only the fog and the alpha test (GL's state does the rest of the merge).
    k << p.fog << p.alphaTest << p.alphaMask << p.alphaRef << p.target << (p.color != nullptr);
    for (uint8_t b : p.fogByte) k << b;
    if (spec.native) return k.h;
    k << p.precision << p.depthTest << p.depthWrite << p.blend << p.depthMask << p.channels << p.depthKind;
    for (uint8_t b : p.bfByte) k << b;
    for (const ChannelPlan& c : p.ch)
        k << c.src.slot << c.src.inv << c.dst.slot << c.dst.inv << c.kind << c.cs << c.cd;
    return k.h;
}

std::string glErrorText(GLenum e) {
    char b[32];
    std::snprintf(b, sizeof b, "OpenGL error 0x%x", unsigned(e));
    return b;
}

}  // namespace

const char* glModeName(GlMode mode) { return mode == GlMode::Native ? "native" : "exact"; }

bool parseGlMode(const std::string& text, GlMode& mode) {
    if (text == "exact") mode = GlMode::Exact;
    else if (text == "native") mode = GlMode::Native;
    else return false;
    return true;
}

// A device's renderer: its own space of resident surfaces on the shared context.
class DeviceRenderer final : public Renderer {
public:
    DeviceRenderer(std::shared_ptr<GlRenderer> gl, GlMode mode) : m_gl(std::move(gl)) {
        static std::atomic<uint64_t> serial{0};
        m_space.mode = mode;
        m_space.serial = ++serial;
    }
    ~DeviceRenderer() override { m_gl->releaseAll(m_space); }
    bool draw(const DrawCall& call, DrawStats& stats, CallError& error) override {
        return m_gl->draw(m_space, call, stats, error);
    }
    bool clear(const ClearCall& call) override { return m_gl->clear(m_space, call); }
    bool stretchRect(const StretchCall& call) override { return m_gl->stretchRect(m_space, call); }
    bool keepsCopies() const override { return true; }
    void readBack(const SurfaceDesc& surface) override { m_gl->readBack(m_space, surface); }
    void release(uint32_t resource) override { m_gl->release(m_space, resource); }
    TransferStats transfers() const override { return m_space.transfers; }
    void finish() override { m_gl->finish(); }
    const char* name() const override { return m_space.mode == GlMode::Native ? "gl-native" : "gl"; }

private:
    std::shared_ptr<GlRenderer> m_gl;
    GlSpace m_space;
};

std::unique_ptr<Renderer> GlRenderer::forDevice(std::shared_ptr<GlRenderer> shared, GlMode mode) {
    return std::make_unique<DeviceRenderer>(std::move(shared), mode);
}

std::unique_ptr<GlRenderer> GlRenderer::create(const GlRendererOptions& options, std::string& error) {
    std::unique_ptr<GlRenderer> r(new GlRenderer);
    r->m_context = createContext(options.context, error);
    if (!r->m_context) return nullptr;
    const GlFunctions& gl = r->m_context->gl();
    if (r->m_context->versionNumber() < 45) {
        error = "the GL renderer needs OpenGL 4.5 (doubles, clip control, texture barrier); the context has " +
                r->m_context->version();
        return nullptr;
    }
    if (!hasExtension(gl, "GL_ARB_gpu_shader_int64")) {
        error = "the GL renderer needs GL_ARB_gpu_shader_int64 (64-bit integers for the exact sums); " +
                r->m_context->renderer() + " lacks it";
        return nullptr;
    }
    r->m_state = std::make_unique<GlState>(gl);
    GlState& st = *r->m_state;
    gl.GenVertexArrays(1, &st.vao);
    gl.GenBuffers(1, &st.vbo);
    gl.GenBuffers(1, &st.triBuffer);
    gl.GenBuffers(1, &st.tapBuffer);
    gl.GenTextures(1, &st.triTexture);
    gl.GenTextures(1, &st.tapTexture);
    gl.GenFramebuffers(1, &st.fbo);
    gl.GenFramebuffers(1, &st.readFbo);
    gl.GenQueries(1, &st.query);
    gl.GenSamplers(ps11::kMaxTextureStages, st.samplers);
    r->m_hardwareFiltering = options.hardwareFiltering;
    return r;
}

void GlRenderer::finish() {
    if (m_context->makeCurrent()) m_context->gl().Finish();
}

GlRenderer::~GlRenderer() {
    if (m_context) m_context->makeCurrent();
    m_state.reset();
}

namespace {

// The stage's texture as the shader needs it: a resident surface when the renderer holds one it
// can sample as it is, else the front's sampler view uploaded (cached by texture object).
struct Binding {
    GLuint name = 0;
    bool volume = false;
    int levels = 1;
    bool unorm8 = false;
    bool packed = false;  // a resident surface's raw words (StageSpec::packedWords)
};

}  // namespace

bool GlRenderer::draw(GlSpace& space, const DrawCall& call, DrawStats& stats, CallError& error) {
    if (!m_context->makeCurrent()) {
        error = CallError{D3DERR_INVALIDCALL, "E4122", "the GL renderer cannot draw this call: its context could not be made current"};
        return false;
    }
    return space.mode == GlMode::Native ? drawNative(space, call, stats, error) : drawExact(space, call, stats, error);
}

namespace {

// The program stage shared by both modes: the stage specs from the bindings, then the program
// found by its key, or decoded, translated and linked once.
struct ProgramStage {
    FragmentSpec spec;
    std::array<Binding, ps11::kMaxTextureStages> bindings;
    ProgramEntry* entry = nullptr;
};

bool resolveBindings(GlState& st, GlSpace& space, const DrawCall& call, bool native, ProgramStage& ps,
                            std::string& why) {
    const ps11::Precision precision = call.hardware.precision;
    const bool fx = ps11::isFixedPoint(precision) && !native;
    for (int s = 0; s < ps11::kMaxTextureStages; ++s) {
        const TextureRef& ref = call.textureRefs[size_t(s)];
        Binding& b = ps.bindings[size_t(s)];
        StageSpec& ss = ps.spec.stages[size_t(s)];
        if (ref.resource == 0 && !call.textures[size_t(s)]) continue;
        NativeFormat nf;
        const bool single = ref.resource != 0 && ref.levels == 1 && !ref.volume;
        if (single && !native && fx && ref.format->format == D3DFMT_A8R8G8B8) {
            // The resident words, seen as 8-bit texels: no conversion, no read-back.
            b.name = st.resident(space, ref.level0).tex;
            b.unorm8 = b.packed = true;
        } else if (single && native && nativeFormatOf(*ref.format, nf) && !nf.depth) {
            b.name = st.resident(space, ref.level0).tex;
        } else {
            // A texture given as a sampler view (a caller without a front), or the front's view.
            const std::shared_ptr<const ps11::Texture> view =
                ref.resource == 0 ? call.textures[size_t(s)] : call.textureView(s);
            if (!view) {
                why = "texture " + std::to_string(ref.resource) + " on stage " + std::to_string(s) +
                      " has no sampler view";
                return false;
            }
            if (view->levelCount() == 0) continue;
            b.name = st.texture(view, precision, native || ps.spec.hardwareFiltering);
            b.volume = view->isVolume();
            b.levels = view->levelCount();
            b.unorm8 = fx && view->storage() == ps11::TexelStorage::Unorm8;
        }
        if (!b.volume && b.levels == 1 && b.name == 0) continue;
        ss.bound = true;
        ss.volume = b.volume;
        ss.levels = b.levels;
        ss.state = call.samplers[size_t(s)];
        ss.unorm8 = b.unorm8;
        ss.packedWords = b.packed;
        ss.borderInRange = true;
        for (int c = 0; c < 4 && fx; ++c) {
            const int32_t g = ps11::toGrid(double(ss.state.border[size_t(c)]), precision);
            ss.borderInRange = ss.borderInRange && g >= 0 && g <= ps11::gridScale(precision);
        }
    }
    return true;
}

ProgramEntry* findProgram(GlState& st, const GlSpace& space, const DrawCall& call, bool native, ProgramStage& ps,
                                 std::string& why) {
    const GlFunctions& gl = st.gl;
    const DrawProgram& prog = call.program;
    const uint64_t key = programKey(space.serial, prog, call.hardware, ps.spec);
    auto it = st.programs.find(key);
    if (it != st.programs.end()) {
        it->second.lastUse = ++st.clock;
        return &it->second;
    }
    // Native mode runs the program in float32 with the class's MaxValue clamp, whatever the
    // emulated card's profile.
    ps11::HardwareConfig hw = call.hardware;
    if (native) hw.precision = ps11::Precision::Float;
    ps11::Diagnostics diags;
    auto decoded = std::make_unique<ps11::exec::DecodedProgram>();
    if (!ps11::exec::decodeProgram(*prog.program, ps11::executorOptionsFor(hw), diags, *decoded)) {
        why = "the program cannot be run (" + (diags.all().empty() ? std::string("?") : diags.all()[0].message) + ")";
        return nullptr;
    }
    for (int s = 0; s < ps11::kMaxTextureStages; ++s) decoded->profile.stages[size_t(s)] = prog.stages[size_t(s)];
    ps.spec.program = decoded.get();
    ps.spec.shaderDepth = decoded->writesDepth;  // r0's depth from texdepth / texm3x2depth
    const std::string fragment = fragmentSource(ps.spec);
    if (const char* dir = std::getenv("PS11_GL_DUMP_SHADERS")) {
        // Every new fragment shader as DIR/ps11_fs_N.frag, for reading and debugging.
        const std::string path = std::string(dir) + "/ps11_fs_" + std::to_string(st.programs.size()) + ".frag";
        if (FILE* f = std::fopen(path.c_str(), "w")) {
            std::fwrite(fragment.data(), 1, fragment.size(), f);
            std::fclose(f);
        }
    }
    std::string log;
    GLuint& vs = native ? st.nativeVertexShader : st.vertexShader;
    if (!vs && !(vs = compileShader(gl, GL_VERTEX_SHADER, native ? nativeVertexSource() : vertexSource(), log))) {
        why = "its vertex shader did not compile: " + log.substr(0, 400);
        return nullptr;
    }
    const GLuint program = linkProgram(gl, vs, fragment, log);
    if (!program) {
        why = "its shader did not compile: " + log.substr(0, 400);
        return nullptr;
    }
    if (st.programs.size() >= kMaxCachedPrograms) {
        auto oldest = std::min_element(st.programs.begin(), st.programs.end(),
                                       [](const auto& a, const auto& b) { return a.second.lastUse < b.second.lastUse; });
        gl.DeleteProgram(oldest->second.program);
        st.programs.erase(oldest);
    }
    ProgramEntry e;
    e.program = program;
    e.lastUse = ++st.clock;
    e.decoded = std::move(decoded);
    auto loc = [&](const char* n) { return gl.GetUniformLocation(program, n); };
    e.constG = loc("uConstG"), e.constF = loc("uConstF"), e.bump = loc("uBump"), e.lum = loc("uLum");
    e.borderG = loc("uBorderG"), e.borderF = loc("uBorderF"), e.stride = loc("uStride"), e.tri = loc("uTri");
    e.dstColor = loc("uDstColor"), e.dstDepth = loc("uDstDepth"), e.xform = loc("uXform");
    e.primBase = loc("uPrimBase");
    for (int s = 0; s < ps11::kMaxTextureStages; ++s) e.tex[s] = loc(("uT" + std::to_string(s)).c_str());
    return &st.programs.emplace(key, std::move(e)).first->second;
}

// Textures, samplers and the program's uniforms (constants, bump and luminance, borders).
void bindProgram(GlState& st, const DrawCall& call, bool native, const ProgramStage& ps, uint32_t W,
                        uint32_t H) {
    const GlFunctions& gl = st.gl;
    const ProgramEntry& e = *ps.entry;
    const ps11::exec::DecodedProgram& decoded = *e.decoded;
    const ps11::Precision precision = native ? ps11::Precision::Float : call.hardware.precision;
    const bool fx = ps11::isFixedPoint(precision);
    gl.UseProgram(e.program);
    for (int s = 0; s < ps11::kMaxTextureStages; ++s) {
        const StageSpec& ss = ps.spec.stages[size_t(s)];
        if (!ss.bound) continue;
        gl.ActiveTexture(GL_TEXTURE0 + GLenum(s));
        gl.BindTexture(ss.volume ? GL_TEXTURE_3D : GL_TEXTURE_2D, ps.bindings[size_t(s)].name);
        if (native || ps.spec.hardwareFiltering)
            st.bindSampler(s, call.samplers[size_t(s)]);
        else
            gl.BindSampler(GLuint(s), 0);
        if (e.tex[s] >= 0) gl.Uniform1i(e.tex[s], s);
    }
    constexpr int kConsts = ps11::exec::kNumConsts, kStages = ps11::kMaxTextureStages;
    int32_t constG[kConsts][4];
    float constF[kConsts][4], bump[kStages][4], lum[kStages][2], borderF[kStages][4];
    int32_t borderG[kStages][4];
    for (int i = 0; i < kConsts; ++i) {
        const auto& v = (decoded.defMask >> i) & 1 ? decoded.defs[size_t(i)] : call.program.constants[size_t(i)];
        for (int c = 0; c < 4; ++c) ps11::exec::constantOf(precision, v[size_t(c)], constG[i][c], constF[i][c]);
    }
    for (int i = 0; i < kStages; ++i) {
        const ps11::StageState& ss = call.program.stages[size_t(i)];
        for (int c = 0; c < 4; ++c) bump[i][c] = ss.bumpMat[size_t(c)];
        lum[i][0] = ss.lumScale, lum[i][1] = ss.lumOffset;
        const ps11::SamplerState& sm = call.samplers[size_t(i)];
        for (int c = 0; c < 4; ++c) {
            borderF[i][c] = sm.border[size_t(c)];
            // The sampler's border on the grid (ps11::TextureSampler::setSamplerState).
            borderG[i][c] = fx ? std::clamp(ps11::toGrid(double(sm.border[size_t(c)]), precision), -ps11::kMaxTexelGrid,
                                            ps11::kMaxTexelGrid)
                               : 0;
        }
    }
    if (e.constG >= 0) gl.Uniform4iv(e.constG, kConsts, &constG[0][0]);
    if (e.constF >= 0) gl.Uniform4fv(e.constF, kConsts, &constF[0][0]);
    if (e.bump >= 0) gl.Uniform4fv(e.bump, kStages, &bump[0][0]);
    if (e.lum >= 0) gl.Uniform2fv(e.lum, kStages, &lum[0][0]);
    if (e.borderG >= 0) gl.Uniform4iv(e.borderG, kStages, &borderG[0][0]);
    if (e.borderF >= 0) gl.Uniform4fv(e.borderF, kStages, &borderF[0][0]);
    // Window x, y (pixel edges at integers, rows down) to clip space under GL_UPPER_LEFT.
    if (e.xform >= 0) gl.Uniform4f(e.xform, 2.0f / float(W), -2.0f / float(H), -1.0f, 1.0f);
}

}  // namespace

bool GlRenderer::drawExact(GlSpace& space, const DrawCall& call, DrawStats& stats, CallError& error) {
    auto refuse = [&](const std::string& why) {
        error.hr = D3DERR_INVALIDCALL;
        error.code = "E4122";
        error.message = "the GL renderer cannot draw this call: " + why;
        return false;
    };
    const GlFunctions& gl = m_context->gl();
    GlState& st = *m_state;
    bool planOk = false;
    const Plan plan = makePlan(call.merge, call.target, planOk);
    if (!planOk) return refuse("the render target or depth surface format is not one the merger stores");
    Image* color = call.target.color;
    const bool useDepth = plan.depthTest && call.target.depth && call.depthSurface.valid();
    if (!color || !call.colorSurface.valid()) return refuse("the draw has no render target");

    // ---- program ----
    ProgramStage ps;
    FragmentSpec& spec = ps.spec;
    spec.precision = call.hardware.precision;
    spec.weightBits = call.hardware.weightBits;
    spec.usedAttributes = call.usedAttributes;
    spec.merge = plan;
    spec.wantZ = call.merge.depthTest || (call.merge.depthWrite && call.target.depth);
    spec.hardwareFiltering = m_hardwareFiltering && !ps11::isFixedPoint(spec.precision);
    std::string why;
    if (!resolveBindings(st, space, call, false, ps, why)) return refuse(why);
    ps.entry = findProgram(st, space, call, false, ps, why);
    if (!ps.entry) return refuse(why);

    // ---- triangles: the software rasteriser's setups as records ----
    const uint64_t used = call.usedAttributes;
    const int stride = recordTexels(used);
    std::vector<uint32_t> records;
    std::vector<float> positions;
    struct Box {
        int x0, y0, x1, y1;
    };
    std::vector<Box> boxes;
    std::vector<ScreenTriangle> tris;
    for (uint32_t first = 0; first < call.primitiveCount; first += 1024) {
        tris.clear();
        call.assemble(first, std::min<uint32_t>(1024, call.primitiveCount - first), tris);
        for (const ScreenTriangle& t : tris) {
            TriangleSetup s;
            if (!setupTriangle(t, used, call.clip, s)) continue;
            const size_t at = records.size();
            records.resize(at + size_t(stride) * 4);
            writeRecord(s, used, records.data() + at);
            // GL draws a superset of the pixels the rasteriser covers: the triangle with every
            // edge pushed out by 3/4 pixel (a pixel centre on or inside the triangle is then
            // strictly inside, whatever GL's fill rule), or, where a sharp corner would reach far,
            // its bounding rectangle. The shader keeps the covered pixels (the edge functions in
            // the record). Two GL triangles a record (gl_PrimitiveID / 2).
            double X[3], Y[3];
            for (int k = 0; k < 3; ++k)
                X[k] = double(std::llround(t.v[size_t(k)].x * 256.0)) / 256.0 + 0.5,
                Y[k] = double(std::llround(t.v[size_t(k)].y * 256.0)) / 256.0 + 0.5;
            double ex[3], ey[3];
            Box box;
            if (expandTriangle(X, Y, 0.75, 6.0, ex, ey)) {
                positions.insert(positions.end(), {float(ex[0]), float(ey[0]), float(ex[1]), float(ey[1]), float(ex[2]),
                                                   float(ey[2]), 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f});
                box = Box{
                    int(std::floor(std::min({ex[0], ex[1], ex[2]}))), int(std::floor(std::min({ey[0], ey[1], ey[2]}))),
                    int(std::ceil(std::max({ex[0], ex[1], ex[2]}))), int(std::ceil(std::max({ey[0], ey[1], ey[2]})))};
            } else {
                const double xl = std::min({X[0], X[1], X[2]}), xh = std::max({X[0], X[1], X[2]});
                const int x0 = std::max(call.clip.x0, int(std::max(-1e9, std::floor(xl)))),
                          x1 = std::min(call.clip.x1, int(std::min(1e9, std::ceil(xh))));
                const float fx0 = float(x0), fx1 = float(x1), fy0 = float(s.yMin), fy1 = float(s.yMax);
                positions.insert(positions.end(), {fx0, fy0, fx1, fy0, fx0, fy1, fx1, fy0, fx1, fy1, fx0, fy1});
                box = Box{x0, s.yMin, x1, s.yMax};
            }
            box.x0 = std::max(box.x0, call.clip.x0), box.x1 = std::min(box.x1, call.clip.x1);
            box.y0 = std::max(box.y0, call.clip.y0), box.y1 = std::min(box.y1, call.clip.y1);
            boxes.push_back(box);
        }
    }
    stats.trianglesDrawn += boxes.size();
    if (boxes.empty()) return true;

    // ---- bindings: the resident target and depth words, textures, uniforms, records ----
    Resident& rc = st.resident(space, call.colorSurface);
    Resident* rd = useDepth ? &st.resident(space, call.depthSurface) : nullptr;
    const uint32_t W = rc.width, H = rc.height;
    bindProgram(st, call, false, ps, W, H);
    const ProgramEntry& e = *ps.entry;
    gl.ActiveTexture(GL_TEXTURE0 + kUnitDstColor);
    gl.BindTexture(GL_TEXTURE_2D, rc.tex);
    gl.ActiveTexture(GL_TEXTURE0 + kUnitDstDepth);
    gl.BindTexture(GL_TEXTURE_2D, rd ? rd->tex : 0);
    if (e.stride >= 0) gl.Uniform1i(e.stride, stride);
    if (e.tri >= 0) gl.Uniform1i(e.tri, kUnitTri);
    if (e.dstColor >= 0) gl.Uniform1i(e.dstColor, kUnitDstColor);
    if (e.dstDepth >= 0) gl.Uniform1i(e.dstDepth, kUnitDstDepth);

    gl.BindBuffer(GL_TEXTURE_BUFFER, st.triBuffer);
    gl.BufferData(GL_TEXTURE_BUFFER, GLsizeiptr(records.size() * 4), records.data(), GL_STREAM_DRAW);
    gl.ActiveTexture(GL_TEXTURE0 + kUnitTri);
    gl.BindTexture(GL_TEXTURE_BUFFER, st.triTexture);
    gl.TexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32UI, st.triBuffer);

    gl.BindVertexArray(st.vao);
    for (GLuint a = 1; a < 11; ++a) gl.DisableVertexAttribArray(a);
    gl.BindBuffer(GL_ARRAY_BUFFER, st.vbo);
    gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(positions.size() * 4), positions.data(), GL_STREAM_DRAW);
    gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 8, nullptr);
    gl.EnableVertexAttribArray(0);

    // ---- the framebuffer: raw colour words, raw depth words; the merge is in the shader ----
    gl.BindFramebuffer(GL_FRAMEBUFFER, st.fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, 0, 0);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, rc.tex, 0);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, rd ? rd->tex : 0, 0);
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, rd ? GLenum(GL_COLOR_ATTACHMENT1) : GLenum(GL_NONE)};
    gl.DrawBuffers(2, buffers);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return refuse("its framebuffer is incomplete");
    const bool writeColor = plan.channels != 0;
    gl.ColorMaski(0, writeColor, writeColor, writeColor, writeColor);
    if (rd) gl.ColorMaski(1, plan.depthWrite, plan.depthWrite, plan.depthWrite, plan.depthWrite);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_DEPTH_TEST);
    gl.ClipControl(GL_UPPER_LEFT, GL_NEGATIVE_ONE_TO_ONE);  // D3D's window convention: rows from the top
    gl.Viewport(0, 0, GLsizei(W), GLsizei(H));
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(call.clip.x0, call.clip.y0, call.clip.x1 - call.clip.x0, call.clip.y1 - call.clip.y0);

    // Batches of triangles whose pixel boxes do not overlap: a fragment that reads its pixel
    // (blending, depth, write masks) must see every earlier triangle's write.
    gl.BeginQuery(GL_SAMPLES_PASSED, st.query);
    size_t begin = 0;
    const size_t n = boxes.size();
    while (begin < n) {
        size_t end = begin + 1;
        while (end < n) {
            const Box& b = boxes[end];
            bool overlap = false;
            for (size_t i = begin; i < end && !overlap; ++i) {
                const Box& a = boxes[i];
                overlap = a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
            }
            if (overlap) break;
            ++end;
        }
        gl.Uniform1i(e.primBase, GLint(begin));
        gl.DrawArrays(GL_TRIANGLES, GLint(begin * 6), GLsizei((end - begin) * 6));
        gl.TextureBarrier();
        begin = end;
    }
    gl.EndQuery(GL_SAMPLES_PASSED);
    GLuint64 passed = 0;
    gl.GetQueryObjectui64v(st.query, GL_QUERY_RESULT, &passed);
    stats.pixelsWritten += passed;
    gl.Disable(GL_SCISSOR_TEST);
    // The copies now hold what the front will count as this draw's write (emu/renderer.h).
    rc.generation = call.colorSurface.writeGeneration;
    if (call.depthSurface.valid() && call.merge.depthWrite) {
        auto it = space.surfaces.find(GlSpace::key(call.depthSurface.resource, call.depthSurface.level));
        if (it != space.surfaces.end()) it->second.generation = call.depthSurface.writeGeneration;
    }
    if (GLenum err = gl.GetError(); err != GL_NO_ERROR) return refuse(glErrorText(err));
    return true;
}

bool GlRenderer::drawNative(GlSpace& space, const DrawCall& call, DrawStats& stats, CallError& error) {
    auto refuse = [&](const std::string& why) {
        error.hr = D3DERR_INVALIDCALL;
        error.code = "E4122";
        error.message = "the GL renderer (native mode) cannot draw this call: " + why;
        return false;
    };
    const GlFunctions& gl = m_context->gl();
    GlState& st = *m_state;
    NativeFormat cf, df;
    if (!call.colorSurface.valid() || !nativeFormatOf(*call.colorSurface.image->format, cf) || cf.depth)
        return refuse("the render target format is not one it keeps");
    const bool useDepth = call.depthSurface.valid() && call.merge.depthTest;
    if (useDepth && (!nativeFormatOf(*call.depthSurface.image->format, df) || !df.depth))
        return refuse("the depth surface format is not one it keeps");
    bool planOk = false;
    const Plan plan = makePlan(call.merge, call.target, planOk);
    if (!planOk) return refuse("the render target or depth surface format is not one the merger stores");

    // ---- program ----
    ProgramStage ps;
    FragmentSpec& spec = ps.spec;
    spec.native = true;
    spec.hardwareFiltering = true;
    spec.precision = ps11::Precision::Float;
    spec.weightBits = 0;
    spec.usedAttributes = call.usedAttributes;
    spec.merge = plan;
    spec.wantZ = useDepth;
    std::string why;
    if (!resolveBindings(st, space, call, true, ps, why)) return refuse(why);
    ps.entry = findProgram(st, space, call, true, ps, why);
    if (!ps.entry) return refuse(why);

    // ---- attributes: the vertices as they are; GL interpolates ----
    constexpr int kFloats = 4 + kAttrCount;
    std::vector<float> vertices;
    std::vector<ScreenTriangle> tris;
    for (uint32_t first = 0; first < call.primitiveCount; first += 1024) {
        tris.clear();
        call.assemble(first, std::min<uint32_t>(1024, call.primitiveCount - first), tris);
        for (const ScreenTriangle& t : tris)
            for (const ScreenVertex& v : t.v) {
                vertices.insert(vertices.end(), {float(v.x), float(v.y), v.z, v.rhw});
                vertices.insert(vertices.end(), v.attr.begin(), v.attr.end());
            }
    }
    const size_t count = vertices.size() / kFloats;
    stats.trianglesDrawn += count / 3;
    if (count == 0) return true;

    // ---- bindings ----
    Resident& rc = st.resident(space, call.colorSurface);
    Resident* rd = useDepth ? &st.resident(space, call.depthSurface) : nullptr;
    bindProgram(st, call, true, ps, rc.width, rc.height);
    gl.BindVertexArray(st.vao);
    gl.BindBuffer(GL_ARRAY_BUFFER, st.vbo);
    gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * 4), vertices.data(), GL_STREAM_DRAW);
    // location 0: x y z rhw; 1 diffuse; 2 specular; 3..10 the texture-coordinate slots.
    for (GLuint a = 0; a < 11; ++a) {
        gl.VertexAttribPointer(a, 4, GL_FLOAT, GL_FALSE, kFloats * 4,
                               reinterpret_cast<const void*>(uintptr_t(a == 0 ? 0 : 16 + (a - 1) * 16)));
        gl.EnableVertexAttribArray(a);
    }

    // ---- the framebuffer in GL's formats; the merge in GL's blend and depth state ----
    gl.BindFramebuffer(GL_FRAMEBUFFER, st.fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, rc.tex, 0);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, 0, 0);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, 0, 0);
    if (rd)
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, df.stencil ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT,
                                GL_TEXTURE_2D, rd->tex, 0);
    const GLenum buffers[1] = {GL_COLOR_ATTACHMENT0};
    gl.DrawBuffers(1, buffers);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return refuse("its framebuffer is incomplete");
    NativeMerge merge = nativeMergeOf(call.merge, rd != nullptr);
    // X8R8G8B8 keeps its alpha byte at 0xff (uploaded so): DESTALPHA reads 1, as D3D9 defines.
    if (call.colorSurface.image->format->format == D3DFMT_X8R8G8B8) merge.colorMask[3] = false;
    applyNativeMerge(gl, merge);
    gl.ClipControl(GL_UPPER_LEFT, GL_ZERO_TO_ONE);  // D3D's rows from the top and depth range [0, 1]
    gl.Viewport(0, 0, GLsizei(rc.width), GLsizei(rc.height));
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(call.clip.x0, call.clip.y0, call.clip.x1 - call.clip.x0, call.clip.y1 - call.clip.y0);
    gl.DrawArrays(GL_TRIANGLES, 0, GLsizei(count));
    gl.Disable(GL_SCISSOR_TEST);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_DEPTH_TEST);
    rc.generation = call.colorSurface.writeGeneration;
    if (rd && call.merge.depthWrite) rd->generation = call.depthSurface.writeGeneration;
    if (GLenum err = gl.GetError(); err != GL_NO_ERROR) return refuse(glErrorText(err));
    return true;
}

}  // namespace emu::gl
