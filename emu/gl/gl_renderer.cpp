// Renderer stage: the GL renderer (emu/gl/gl_renderer.h). Per draw: the program decoded as the
// executor decodes it, the fragment shader generated (emu/gl/glsl.h) and cached by its text,
// the triangle setups of the software rasteriser written as records (so both renderers shade
// the same attribute values), textures uploaded as grid integers or float32 and cached per
// texture object, the target and depth surfaces uploaded as raw words, the triangles drawn in
// batches that do not overlap (a fragment reads the pixel it writes: ARB_texture_barrier), and
// the surfaces read back.
#include "emu/gl/gl_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <unordered_map>

#include "emu/gl/glsl.h"
#include "ps11/diagnostics.h"

namespace emu::gl {

namespace {

constexpr size_t kMaxCachedTextures = 64;
constexpr size_t kMaxCachedPrograms = 256;
constexpr int kUnitTri = 8, kUnitDstColor = 9, kUnitDstDepth = 10, kUnitUpload = 11;

struct TextureEntry {
    std::shared_ptr<const ps11::Texture> texture;  // kept alive: its address is the key
    bool fx = false;
    ps11::Precision precision = ps11::Precision::Fx8;
    bool hardware = false;  // for GL's texture unit: 8-bit textures as GL_RGBA8
    GLuint name = 0;
    uint64_t lastUse = 0;
};

struct ProgramEntry {
    GLuint program = 0;
    uint64_t lastUse = 0;
};

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

}  // namespace

struct GlState {
    const GlFunctions& gl;
    explicit GlState(const GlFunctions& f) : gl(f) {}
    GLuint vao = 0, vbo = 0, triBuffer = 0, triTexture = 0, fbo = 0, query = 0;
    GLuint samplers[8] = {};  // GL sampler objects of hardware filtering
    GLuint colorTex = 0, depthTex = 0;
    GLuint vertexShader = 0;
    std::unordered_map<std::string, ProgramEntry> programs;
    std::vector<TextureEntry> textures;
    uint64_t clock = 0;

    ~GlState() {
        for (auto& [k, p] : programs) gl.DeleteProgram(p.program);
        for (auto& t : textures) gl.DeleteTextures(1, &t.name);
        GLuint tex[3] = {triTexture, colorTex, depthTex};
        gl.DeleteTextures(3, tex);
        GLuint buf[2] = {vbo, triBuffer};
        gl.DeleteBuffers(2, buf);
        gl.DeleteVertexArrays(1, &vao);
        gl.DeleteFramebuffers(1, &fbo);
        gl.DeleteQueries(1, &query);
        gl.DeleteSamplers(8, samplers);
        if (vertexShader) gl.DeleteShader(vertexShader);
    }

    GLuint compile(GLenum type, const std::string& src, std::string& log) {
        GLuint s = gl.CreateShader(type);
        const char* text = src.c_str();
        gl.ShaderSource(s, 1, &text, nullptr);
        gl.CompileShader(s);
        GLint ok = 0;
        gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            char buf[2048] = {};
            gl.GetShaderInfoLog(s, sizeof buf - 1, nullptr, buf);
            log = buf;
            gl.DeleteShader(s);
            return 0;
        }
        return s;
    }

    GLuint program(const std::string& fragment, std::string& log) {
        auto it = programs.find(fragment);
        if (it != programs.end()) {
            it->second.lastUse = ++clock;
            return it->second.program;
        }
        if (const char* dir = std::getenv("PS11_GL_DUMP_SHADERS")) {
            // Every new fragment shader as DIR/ps11_fs_N.frag, for reading and debugging.
            const std::string path = std::string(dir) + "/ps11_fs_" + std::to_string(programs.size()) + ".frag";
            if (FILE* f = std::fopen(path.c_str(), "w")) {
                std::fwrite(fragment.data(), 1, fragment.size(), f);
                std::fclose(f);
            }
        }
        if (!vertexShader && !(vertexShader = compile(GL_VERTEX_SHADER, vertexSource(), log))) return 0;
        GLuint fs = compile(GL_FRAGMENT_SHADER, fragment, log);
        if (!fs) return 0;
        GLuint p = gl.CreateProgram();
        gl.AttachShader(p, vertexShader);
        gl.AttachShader(p, fs);
        gl.LinkProgram(p);
        gl.DeleteShader(fs);
        GLint ok = 0;
        gl.GetProgramiv(p, GL_LINK_STATUS, &ok);
        if (!ok) {
            char buf[2048] = {};
            gl.GetProgramInfoLog(p, sizeof buf - 1, nullptr, buf);
            log = buf;
            gl.DeleteProgram(p);
            return 0;
        }
        if (programs.size() >= kMaxCachedPrograms) {
            auto oldest = std::min_element(programs.begin(), programs.end(), [](const auto& a, const auto& b) {
                return a.second.lastUse < b.second.lastUse;
            });
            gl.DeleteProgram(oldest->second.program);
            programs.erase(oldest);
        }
        programs.emplace(fragment, ProgramEntry{p, ++clock});
        return p;
    }

    // The GL texture of a ps11 texture in the profile's terms (grid integers or float32).
    GLuint texture(const std::shared_ptr<const ps11::Texture>& tex, ps11::Precision precision, bool hardware) {
        const bool fx = ps11::isFixedPoint(precision);
        for (TextureEntry& e : textures)
            if (e.texture == tex && e.fx == fx && e.hardware == hardware && (!fx || e.precision == precision)) {
                e.lastUse = ++clock;
                return e.name;
            }
        if (textures.size() >= kMaxCachedTextures) {
            auto oldest = std::min_element(textures.begin(), textures.end(),
                                           [](const auto& a, const auto& b) { return a.lastUse < b.lastUse; });
            gl.DeleteTextures(1, &oldest->name);
            textures.erase(oldest);
        }
        GLuint name = 0;
        gl.GenTextures(1, &name);
        const GLenum target = tex->isVolume() ? GL_TEXTURE_3D : GL_TEXTURE_2D;
        gl.ActiveTexture(GL_TEXTURE0 + kUnitUpload);  // not a unit a draw samples
        gl.BindTexture(target, name);
        gl.TexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        gl.TexParameteri(target, GL_TEXTURE_BASE_LEVEL, 0);
        gl.TexParameteri(target, GL_TEXTURE_MAX_LEVEL, tex->levelCount() - 1);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        for (int l = 0; l < tex->levelCount(); ++l) {
            const ps11::TextureLevelInfo& li = tex->level(l);
            const size_t n = size_t(li.width) * li.height * li.depth;
            if (hardware && !fx && tex->storage() == ps11::TexelStorage::Unorm8) {
                // b g r a bytes: GL_BGRA with GL_UNSIGNED_BYTE reads them as they are.
                const uint8_t* bytes = tex->unorm8() + li.offset * 4;
                if (tex->isVolume())
                    gl.TexImage3D(target, l, GL_RGBA8, GLsizei(li.width), GLsizei(li.height), GLsizei(li.depth), 0,
                                  GL_BGRA, GL_UNSIGNED_BYTE, bytes);
                else
                    gl.TexImage2D(target, l, GL_RGBA8, GLsizei(li.width), GLsizei(li.height), 0, GL_BGRA,
                                  GL_UNSIGNED_BYTE, bytes);
            } else if (fx && tex->storage() == ps11::TexelStorage::Unorm8) {
                // The bytes as they are (b g r a: GL_BGRA_INTEGER); the shader scales them to the grid.
                const uint8_t* bytes = tex->unorm8() + li.offset * 4;
                if (tex->isVolume())
                    gl.TexImage3D(target, l, GL_RGBA8UI, GLsizei(li.width), GLsizei(li.height), GLsizei(li.depth), 0,
                                  GL_BGRA_INTEGER, GL_UNSIGNED_BYTE, bytes);
                else
                    gl.TexImage2D(target, l, GL_RGBA8UI, GLsizei(li.width), GLsizei(li.height), 0, GL_BGRA_INTEGER,
                                  GL_UNSIGNED_BYTE, bytes);
            } else if (fx) {
                std::vector<int32_t> data(n * 4);
                size_t i = 0;
                for (uint32_t z = 0; z < li.depth; ++z)
                    for (uint32_t y = 0; y < li.height; ++y)
                        for (uint32_t x = 0; x < li.width; ++x, ++i) {
                            const auto g = tex->texelGrid(l, x, y, z, precision);
                            std::memcpy(&data[i * 4], g.data(), 16);
                        }
                if (tex->isVolume())
                    gl.TexImage3D(target, l, GL_RGBA32I, GLsizei(li.width), GLsizei(li.height), GLsizei(li.depth), 0,
                                  GL_RGBA_INTEGER, GL_INT, data.data());
                else
                    gl.TexImage2D(target, l, GL_RGBA32I, GLsizei(li.width), GLsizei(li.height), 0, GL_RGBA_INTEGER,
                                  GL_INT, data.data());
            } else {
                std::vector<float> data(n * 4);
                size_t i = 0;
                for (uint32_t z = 0; z < li.depth; ++z)
                    for (uint32_t y = 0; y < li.height; ++y)
                        for (uint32_t x = 0; x < li.width; ++x, ++i) {
                            const ps11::Vec4 v = tex->texelValue(l, x, y, z);
                            for (int c = 0; c < 4; ++c) data[i * 4 + size_t(c)] = v[size_t(c)];
                        }
                if (tex->isVolume())
                    gl.TexImage3D(target, l, GL_RGBA32F, GLsizei(li.width), GLsizei(li.height), GLsizei(li.depth), 0,
                                  GL_RGBA, GL_FLOAT, data.data());
                else
                    gl.TexImage2D(target, l, GL_RGBA32F, GLsizei(li.width), GLsizei(li.height), 0, GL_RGBA, GL_FLOAT,
                                  data.data());
            }
        }
        textures.push_back(TextureEntry{tex, fx, precision, hardware, name, ++clock});
        return name;
    }
};

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
    gl.GenTextures(1, &st.triTexture);
    gl.GenTextures(1, &st.colorTex);
    gl.GenTextures(1, &st.depthTex);
    gl.GenFramebuffers(1, &st.fbo);
    gl.GenQueries(1, &st.query);
    gl.GenSamplers(8, st.samplers);
    r->m_hardwareFiltering = options.hardwareFiltering;
    // D3D's window convention: y down, pixel rows from the top (the fill rule follows it).
    gl.ClipControl(GL_UPPER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    return r;
}

GlRenderer::~GlRenderer() {
    if (m_context) m_context->makeCurrent();
    m_state.reset();
}

bool GlRenderer::draw(const DrawCall& call, DrawStats& stats, RendererError& error) {
    auto refuse = [&](const std::string& why) {
        error.hr = D3DERR_INVALIDCALL;
        error.code = "E4122";
        error.message = "the GL renderer cannot draw this call: " + why;
        return false;
    };
    if (!m_context->makeCurrent()) return refuse("its context could not be made current");
    const GlFunctions& gl = m_context->gl();
    GlState& st = *m_state;
    const DrawProgram& prog = call.program;

    // ---- the program, decoded as the executor decodes it ----
    ps11::Diagnostics diags;
    ps11::exec::DecodedProgram decoded;
    if (!ps11::exec::decodeProgram(*prog.program, ps11::executorOptionsFor(call.hardware), diags, decoded))
        return refuse("the program cannot be run (" +
                      (diags.all().empty() ? std::string("?") : diags.all()[0].message) + ")");
    for (int s = 0; s < 8; ++s) decoded.profile.stages[size_t(s)] = prog.stages[size_t(s)];
    const ps11::Precision precision = call.hardware.precision;
    const bool fx = ps11::isFixedPoint(precision);

    bool planOk = false;
    const Plan plan = makePlan(call.merge, call.target, planOk);
    if (!planOk) return refuse("the render target or depth surface format is not one the merger stores");
    Image* color = call.target.color;
    Image* depth = plan.depthTest ? call.target.depth : nullptr;
    if (!color && !depth) return true;

    FragmentSpec spec;
    spec.program = &decoded;
    spec.precision = precision;
    spec.weightBits = call.hardware.weightBits;
    spec.usedAttributes = call.usedAttributes;
    spec.merge = plan;
    spec.shaderDepth = decoded.writesDepth;
    spec.wantZ = call.merge.depthTest || (call.merge.depthWrite && call.target.depth);
    spec.hardwareFiltering = m_hardwareFiltering && !fx;
    for (int s = 0; s < 8; ++s) {
        if (!((decoded.stagesUsed >> s) & 1)) continue;
        const auto& tex = call.textures[size_t(s)];
        StageSpec& ss = spec.stages[size_t(s)];
        ss.bound = tex && tex->levelCount() > 0;
        if (!ss.bound) continue;
        ss.volume = tex->isVolume();
        ss.levels = tex->levelCount();
        ss.state = call.samplers[size_t(s)];
        ss.unorm8 = fx && tex->storage() == ps11::TexelStorage::Unorm8;
        ss.borderInRange = true;
        for (int c = 0; c < 4 && fx; ++c) {
            const int32_t g = ps11::toGrid(double(ss.state.border[size_t(c)]), precision);
            ss.borderInRange = ss.borderInRange && g >= 0 && g <= ps11::gridScale(precision);
        }
    }
    std::string log;
    const GLuint program = st.program(fragmentSource(spec), log);
    if (!program) return refuse("its shader did not compile: " + log.substr(0, 400));

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

    // ---- surfaces as raw words: 1, 2 or 4 32-bit words a pixel (R32UI, RG32UI, RGBA32UI) ----
    const uint32_t W = color ? color->width : depth->width, H = color ? color->height : depth->height;
    std::vector<uint32_t> words;
    auto wordsOf = [](const Image& img) { return (img.format->bytes + 3) / 4; };
    auto formats = [](uint32_t n, GLenum& internal, GLenum& format) {
        internal = n == 1 ? GL_R32UI : n == 2 ? GL_RG32UI : GL_RGBA32UI;
        format = n == 1 ? GL_RED_INTEGER : n == 2 ? GL_RG_INTEGER : GL_RGBA_INTEGER;
    };
    auto upload = [&](GLuint tex, const Image& img) {
        const uint32_t n = wordsOf(img), bytes = img.format->bytes;
        words.assign(size_t(img.width) * img.height * n, 0);
        for (uint32_t y = 0; y < img.height; ++y) {
            uint8_t* dst = reinterpret_cast<uint8_t*>(&words[size_t(y) * img.width * n]);
            if (bytes == 4 * n)
                std::memcpy(dst, img.texel(0, y), size_t(img.width) * bytes);
            else
                for (uint32_t x = 0; x < img.width; ++x) std::memcpy(dst + size_t(x) * 4 * n, img.texel(x, y), bytes);
        }
        GLenum internal, format;
        formats(n, internal, format);
        gl.BindTexture(GL_TEXTURE_2D, tex);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl.TexImage2D(GL_TEXTURE_2D, 0, GLint(internal), GLsizei(img.width), GLsizei(img.height), 0, format,
                      GL_UNSIGNED_INT, words.data());
    };
    // Without a colour target the colour attachment only sizes the framebuffer (never written).
    emu::Image none;
    if (!color) {
        none.format = depth->format;
        none.width = W, none.height = H;
        none.rowPitch = W * depth->format->bytes;
        none.bytes.assign(size_t(none.rowPitch) * H, 0);
    }
    gl.ActiveTexture(GL_TEXTURE0 + kUnitDstColor);
    upload(st.colorTex, color ? *color : none);
    gl.ActiveTexture(GL_TEXTURE0 + kUnitDstDepth);
    if (depth) upload(st.depthTex, *depth);

    // ---- textures and uniforms ----
    gl.UseProgram(program);
    for (int s = 0; s < 8; ++s) {
        if (!spec.stages[size_t(s)].bound) continue;
        const GLuint name = st.texture(call.textures[size_t(s)], precision, spec.hardwareFiltering);
        gl.ActiveTexture(GL_TEXTURE0 + GLenum(s));
        gl.BindTexture(spec.stages[size_t(s)].volume ? GL_TEXTURE_3D : GL_TEXTURE_2D, name);
        if (spec.hardwareFiltering) {
            // D3D's sampler state as GL's (D3DTEXF_NONE as a min/mag filter acts as point).
            const ps11::SamplerState& sm = call.samplers[size_t(s)];
            const GLuint so = st.samplers[s];
            const bool magLin = sm.magFilter == ps11::Filter::Linear, minLin = sm.minFilter == ps11::Filter::Linear;
            const GLint minf = sm.mipFilter == ps11::Filter::None ? (minLin ? GL_LINEAR : GL_NEAREST)
                               : sm.mipFilter == ps11::Filter::Point
                                   ? (minLin ? GL_LINEAR_MIPMAP_NEAREST : GL_NEAREST_MIPMAP_NEAREST)
                                   : (minLin ? GL_LINEAR_MIPMAP_LINEAR : GL_NEAREST_MIPMAP_LINEAR);
            gl.SamplerParameteri(so, GL_TEXTURE_MIN_FILTER, minf);
            gl.SamplerParameteri(so, GL_TEXTURE_MAG_FILTER, magLin ? GL_LINEAR : GL_NEAREST);
            const ps11::TextureAddress modes[3] = {sm.addressU, sm.addressV, sm.addressW};
            const GLenum names[3] = {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R};
            for (int a = 0; a < 3; ++a) {
                GLint m = GL_REPEAT;
                switch (modes[a]) {
                    case ps11::TextureAddress::Mirror:
                        m = GL_MIRRORED_REPEAT;
                        break;
                    case ps11::TextureAddress::Clamp:
                        m = GL_CLAMP_TO_EDGE;
                        break;
                    case ps11::TextureAddress::Border:
                        m = GL_CLAMP_TO_BORDER;
                        break;
                    case ps11::TextureAddress::MirrorOnce:
                        m = GL_MIRROR_CLAMP_TO_EDGE;
                        break;
                    default:
                        break;
                }
                gl.SamplerParameteri(so, names[a], m);
            }
            gl.SamplerParameterfv(so, GL_TEXTURE_BORDER_COLOR, sm.border.data());
            gl.BindSampler(GLuint(s), so);
        } else {
            gl.BindSampler(GLuint(s), 0);
        }
        gl.Uniform1i(gl.GetUniformLocation(program, ("uT" + std::to_string(s)).c_str()), s);
    }
    int32_t constG[8][4];
    float constF[8][4], bump[8][4], lum[8][2], borderF[8][4];
    int32_t borderG[8][4];
    for (int i = 0; i < 8; ++i) {
        const auto& v = (decoded.defMask >> i) & 1 ? decoded.defs[size_t(i)] : prog.constants[size_t(i)];
        for (int c = 0; c < 4; ++c) ps11::exec::constantOf(precision, v[size_t(c)], constG[i][c], constF[i][c]);
        const ps11::StageState& ss = prog.stages[size_t(i)];
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
    gl.Uniform4iv(gl.GetUniformLocation(program, "uConstG"), 8, &constG[0][0]);
    gl.Uniform4fv(gl.GetUniformLocation(program, "uConstF"), 8, &constF[0][0]);
    gl.Uniform4fv(gl.GetUniformLocation(program, "uBump"), 8, &bump[0][0]);
    gl.Uniform2fv(gl.GetUniformLocation(program, "uLum"), 8, &lum[0][0]);
    gl.Uniform4iv(gl.GetUniformLocation(program, "uBorderG"), 8, &borderG[0][0]);
    gl.Uniform4fv(gl.GetUniformLocation(program, "uBorderF"), 8, &borderF[0][0]);
    gl.Uniform1i(gl.GetUniformLocation(program, "uStride"), stride);
    gl.Uniform1i(gl.GetUniformLocation(program, "uTri"), kUnitTri);
    gl.Uniform1i(gl.GetUniformLocation(program, "uDstColor"), kUnitDstColor);
    gl.Uniform1i(gl.GetUniformLocation(program, "uDstDepth"), kUnitDstDepth);
    // Window x, y (pixel edges at integers, rows down) to clip space under GL_UPPER_LEFT.
    gl.Uniform4f(gl.GetUniformLocation(program, "uXform"), 2.0f / float(W), -2.0f / float(H), -1.0f, 1.0f);
    const GLint primBase = gl.GetUniformLocation(program, "uPrimBase");

    gl.BindBuffer(GL_TEXTURE_BUFFER, st.triBuffer);
    gl.BufferData(GL_TEXTURE_BUFFER, GLsizeiptr(records.size() * 4), records.data(), GL_STREAM_DRAW);
    gl.ActiveTexture(GL_TEXTURE0 + kUnitTri);
    gl.BindTexture(GL_TEXTURE_BUFFER, st.triTexture);
    gl.TexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32UI, st.triBuffer);

    gl.BindVertexArray(st.vao);
    gl.BindBuffer(GL_ARRAY_BUFFER, st.vbo);
    gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(positions.size() * 4), positions.data(), GL_STREAM_DRAW);
    gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 8, nullptr);
    gl.EnableVertexAttribArray(0);

    // ---- the framebuffer: raw colour words, raw depth words ----
    gl.BindFramebuffer(GL_FRAMEBUFFER, st.fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, st.colorTex, 0);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, depth ? st.depthTex : 0, 0);
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, depth ? GLenum(GL_COLOR_ATTACHMENT1) : GLenum(GL_NONE)};
    gl.DrawBuffers(2, buffers);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return refuse("its framebuffer is incomplete");
    const bool writeColor = color && plan.channels != 0;
    gl.ColorMaski(0, writeColor, writeColor, writeColor, writeColor);
    if (depth) gl.ColorMaski(1, plan.depthWrite, plan.depthWrite, plan.depthWrite, plan.depthWrite);
    gl.Viewport(0, 0, GLsizei(W), GLsizei(H));
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(call.clip.x0, call.clip.y0, call.clip.x1 - call.clip.x0, call.clip.y1 - call.clip.y0);

    // Batches of triangles whose pixel boxes do not overlap: a fragment that reads its pixel
    // (blending, depth, write masks) must see every earlier triangle's write.
    const auto start = std::chrono::steady_clock::now();
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
        gl.Uniform1i(primBase, GLint(begin));
        gl.DrawArrays(GL_TRIANGLES, GLint(begin * 6), GLsizei((end - begin) * 6));
        gl.TextureBarrier();
        begin = end;
    }
    gl.EndQuery(GL_SAMPLES_PASSED);
    gl.Finish();
    m_lastDrawMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    GLuint64 passed = 0;
    gl.GetQueryObjectui64v(st.query, GL_QUERY_RESULT, &passed);
    stats.pixelsWritten += passed;
    gl.Disable(GL_SCISSOR_TEST);

    // ---- read back ----
    auto readBack = [&](GLuint tex, Image& img) {
        const uint32_t n = wordsOf(img), bytes = img.format->bytes;
        words.assign(size_t(img.width) * img.height * n, 0);
        GLenum internal, format;
        formats(n, internal, format);
        gl.BindTexture(GL_TEXTURE_2D, tex);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
        gl.GetTexImage(GL_TEXTURE_2D, 0, format, GL_UNSIGNED_INT, words.data());
        for (uint32_t y = 0; y < img.height; ++y) {
            const uint8_t* src = reinterpret_cast<const uint8_t*>(&words[size_t(y) * img.width * n]);
            if (bytes == 4 * n)
                std::memcpy(img.texel(0, y), src, size_t(img.width) * bytes);
            else
                for (uint32_t x = 0; x < img.width; ++x) std::memcpy(img.texel(x, y), src + size_t(x) * 4 * n, bytes);
        }
    };
    gl.ActiveTexture(GL_TEXTURE0 + kUnitDstColor);
    if (writeColor) readBack(st.colorTex, *color);
    gl.ActiveTexture(GL_TEXTURE0 + kUnitDstDepth);
    if (plan.depthWrite) readBack(st.depthTex, *depth);
    if (GLenum e = gl.GetError(); e != GL_NO_ERROR)
        return refuse("OpenGL reported error 0x" + [&] {
            char b[16];
            std::snprintf(b, sizeof b, "%x", unsigned(e));
            return std::string(b);
        }());
    return true;
}

}  // namespace emu::gl
