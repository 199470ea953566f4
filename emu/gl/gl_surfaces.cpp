// Renderer stage: the GL renderer's resident surfaces (emu/gl/gl_internal.h). A device's surfaces
// live on the GL side from their first use: uploaded when the front's contents are newer (by
// generation), read back only when the front asks. Clear and StretchRect work on those copies:
// exact mode writes the emulator's texels (raw words, the stretch taps of emu/blit.h summed in
// the same order), native mode uses glClearTexSubImage and glBlitFramebuffer as a driver would.
#include <algorithm>
#include <cstring>

#include "emu/blit.h"
#include "emu/gl/gl_internal.h"
#include "emu/gl/glsl.h"
#include "emu/gl/shader_program.h"

namespace emu::gl {

namespace {

constexpr size_t kMaxCachedTextures = 64;

// Exact mode: 1, 2 or 4 32-bit words a pixel.
uint32_t wordsOf(const FormatInfo& f) { return (f.bytes + 3) / 4; }
void wordFormats(uint32_t n, GLenum& internal, GLenum& format) {
    internal = n == 1 ? GL_R32UI : n == 2 ? GL_RG32UI : GL_RGBA32UI;
    format = n == 1 ? GL_RED_INTEGER : n == 2 ? GL_RG_INTEGER : GL_RGBA_INTEGER;
}

// The client format and type of a surface's texels: GL's own (native mode, true) or raw words.
bool clientFormatOf(bool native, const FormatInfo& f, GLenum& format, GLenum& type) {
    NativeFormat nf;
    if (native && nativeFormatOf(f, nf)) {
        format = nf.format, type = nf.type;
        return true;
    }
    GLenum internal;
    wordFormats(wordsOf(f), internal, format);
    type = GL_UNSIGNED_INT;
    return false;
}

// `fbo` bound for drawing with `tex` as its only colour target, every channel written.
void drawInto(const GlFunctions& gl, GLuint fbo, GLuint tex) {
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
    gl.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    gl.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, 0, 0);
    gl.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, 0, 0);
    const GLenum buffers[1] = {GL_COLOR_ATTACHMENT0};
    gl.DrawBuffers(1, buffers);
    gl.ColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

const char* kStretchFragment = R"(#version 450 core
// Exact StretchRect of A8R8G8B8: the taps of emu/blit.h, bytes summed in double in its order and
// rounded once (ties to even).
uniform usampler2D uSrc;
uniform usamplerBuffer uTaps;  // dest columns then dest rows: i0, i1, w1 (double as two words)
uniform ivec4 uDst;            // rect x0, y0, width, height
uniform int uLinear;
layout(location = 0) out uvec4 oWord;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    uvec4 tx = texelFetch(uTaps, p.x - uDst.x), ty = texelFetch(uTaps, uDst.z + p.y - uDst.y);
    uint a = texelFetch(uSrc, ivec2(tx.x, ty.x), 0).x;
    if (uLinear == 0) { oWord = uvec4(a, 0u, 0u, 0u); return; }
    uint b = texelFetch(uSrc, ivec2(tx.y, ty.x), 0).x;
    uint c = texelFetch(uSrc, ivec2(tx.x, ty.y), 0).x;
    uint e = texelFetch(uSrc, ivec2(tx.y, ty.y), 0).x;
    double wx = packDouble2x32(tx.zw), wy = packDouble2x32(ty.zw);
    uint word = 0u;
    for (int k = 0; k < 32; k += 8) {
        double A = double((a >> uint(k)) & 255u), B = double((b >> uint(k)) & 255u);
        double C = double((c >> uint(k)) & 255u), E = double((e >> uint(k)) & 255u);
        precise double v = (1.0lf - wy) * ((1.0lf - wx) * A + wx * B) + wy * ((1.0lf - wx) * C + wx * E);
        v = roundEven(v);
        v = v < 0.0lf ? 0.0lf : (v > 255.0lf ? 255.0lf : v);
        word |= uint(v) << uint(k);
    }
    oWord = uvec4(word, 0u, 0u, 0u);
}
)";

}  // namespace

// From the format's row (ps11/formats.cpp): D3D's 32-bit b g r a word is GL_BGRA of
// GL_UNSIGNED_BYTE (X8R8G8B8's X byte rides along as alpha); float formats whose first n channels
// are halves or floats laid one after another (the rest missing) are GL's R, RG, RGB or RGBA of
// GL_HALF_FLOAT or GL_FLOAT, sampled as GL samples them (native mode); depth by its bits and
// float-ness (D3D's 24-bit word is depth << 8 | stencil or X: GL_UNSIGNED_INT_24_8's layout).
bool nativeFormatOf(const FormatInfo& f, NativeFormat& out) {
    if (f.cls == FormatClass::Unorm8) {
        if (f.bytes != 4) return false;
        for (size_t c = 0; c < 3; ++c)
            if (f.rgba[c].kind != ps11::ChannelKind::Unorm || f.rgba[c].shift != 8 * ps11::kUnorm8Byte[c]) return false;
        out = {GL_RGBA8, GL_BGRA, GL_UNSIGNED_BYTE};
        return true;
    }
    if (f.cls == FormatClass::Float) {
        const ps11::ChannelKind kind = f.rgba[0].kind;
        const uint32_t size = kind == ps11::ChannelKind::Half ? 16 : 32;
        size_t n = 0;
        while (n < 4 && f.rgba[n].kind == kind && f.rgba[n].shift == n * size) ++n;
        for (size_t c = n; c < 4; ++c)
            if (f.rgba[c].kind != ps11::ChannelKind::One) return false;
        if (n == 0) return false;
        static const GLenum halves[4] = {GL_R16F, GL_RG16F, GL_RGB16F, GL_RGBA16F};
        static const GLenum floats[4] = {GL_R32F, GL_RG32F, GL_RGB32F, GL_RGBA32F};
        static const GLenum formats[4] = {GL_RED, GL_RG, GL_RGB, GL_RGBA};
        const bool half = kind == ps11::ChannelKind::Half;
        out = {half ? halves[n - 1] : floats[n - 1], formats[n - 1], GLenum(half ? GL_HALF_FLOAT : GL_FLOAT)};
        return true;
    }
    if (f.cls != FormatClass::Depth) return false;
    if (f.depthFloat) {
        out = {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, true, false};
        return true;
    }
    switch (f.depthBits) {
        case 16:
            out = {GL_DEPTH_COMPONENT16, GL_DEPTH_COMPONENT, GL_UNSIGNED_SHORT, true, false};
            return true;
        case 24:  // D24X8 too: its X byte is GL's stencil
            out = {GL_DEPTH24_STENCIL8, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, true, true};
            return true;
        case 32:
            out = {GL_DEPTH_COMPONENT32, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, true, false};
            return true;
        default:
            return false;
    }
}

GlState::~GlState() {
    for (auto& [k, p] : programs) gl.DeleteProgram(p.program);
    for (auto& t : textures) gl.DeleteTextures(1, &t.name);
    GLuint tex[3] = {triTexture, sizingTex, tapTexture};
    gl.DeleteTextures(3, tex);
    GLuint buf[3] = {vbo, triBuffer, tapBuffer};
    gl.DeleteBuffers(3, buf);
    gl.DeleteVertexArrays(1, &vao);
    gl.DeleteFramebuffers(1, &fbo);
    gl.DeleteFramebuffers(1, &readFbo);
    gl.DeleteQueries(1, &query);
    gl.DeleteSamplers(8, samplers);
    if (stretchProgram) gl.DeleteProgram(stretchProgram);
    if (vertexShader) gl.DeleteShader(vertexShader);
    if (nativeVertexShader) gl.DeleteShader(nativeVertexShader);
}

GLuint GlState::texture(const std::shared_ptr<const ps11::Texture>& tex, ps11::Precision precision, bool hardware) {
    const bool fx = ps11::isFixedPoint(precision) && !hardware;
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
    auto image = [&](int l, const ps11::TextureLevelInfo& li, GLenum internal, GLenum format, GLenum type,
                     const void* data) {
        if (tex->isVolume())
            gl.TexImage3D(target, l, GLint(internal), GLsizei(li.width), GLsizei(li.height), GLsizei(li.depth), 0,
                          format, type, data);
        else
            gl.TexImage2D(target, l, GLint(internal), GLsizei(li.width), GLsizei(li.height), 0, format, type, data);
    };
    for (int l = 0; l < tex->levelCount(); ++l) {
        const ps11::TextureLevelInfo& li = tex->level(l);
        const size_t n = size_t(li.width) * li.height * li.depth;
        if (hardware && tex->storage() == ps11::TexelStorage::Unorm8) {
            // b g r a bytes: GL_BGRA with GL_UNSIGNED_BYTE reads them as they are.
            image(l, li, GL_RGBA8, GL_BGRA, GL_UNSIGNED_BYTE, tex->unorm8() + li.offset * 4);
        } else if (fx && tex->storage() == ps11::TexelStorage::Unorm8) {
            // The bytes as they are (b g r a: GL_BGRA_INTEGER); the shader scales them to the grid.
            image(l, li, GL_RGBA8UI, GL_BGRA_INTEGER, GL_UNSIGNED_BYTE, tex->unorm8() + li.offset * 4);
        } else if (fx) {
            std::vector<int32_t> data(n * 4);
            size_t i = 0;
            for (uint32_t z = 0; z < li.depth; ++z)
                for (uint32_t y = 0; y < li.height; ++y)
                    for (uint32_t x = 0; x < li.width; ++x, ++i) {
                        const auto g = tex->texelGrid(l, x, y, z, precision);
                        std::memcpy(&data[i * 4], g.data(), 16);
                    }
            image(l, li, GL_RGBA32I, GL_RGBA_INTEGER, GL_INT, data.data());
        } else {
            std::vector<float> data(n * 4);
            size_t i = 0;
            for (uint32_t z = 0; z < li.depth; ++z)
                for (uint32_t y = 0; y < li.height; ++y)
                    for (uint32_t x = 0; x < li.width; ++x, ++i) {
                        const std::array<float, 4> v = tex->texelValue(l, x, y, z);
                        for (int c = 0; c < 4; ++c) data[i * 4 + size_t(c)] = v[size_t(c)];
                    }
            image(l, li, GL_RGBA32F, GL_RGBA, GL_FLOAT, data.data());
        }
    }
    textures.push_back(TextureEntry{tex, fx, precision, hardware, name, ++clock});
    return name;
}

void GlState::bindSampler(int s, const ps11::SamplerState& sm) {
    // D3D's sampler state as GL's (D3DTEXF_NONE as a min/mag filter acts as point).
    const GLuint so = samplers[s];
    const bool magLin = sm.magFilter == ps11::Filter::Linear, minLin = sm.minFilter == ps11::Filter::Linear;
    const GLint minf = sm.mipFilter == ps11::Filter::None    ? (minLin ? GL_LINEAR : GL_NEAREST)
                       : sm.mipFilter == ps11::Filter::Point ? (minLin ? GL_LINEAR_MIPMAP_NEAREST : GL_NEAREST_MIPMAP_NEAREST)
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
}

Resident& GlState::resident(GlSpace& space, const SurfaceDesc& surface) {
    Resident& r = space.surfaces[GlSpace::key(surface.resource, surface.level)];
    const Image& img = *surface.image;
    if (r.tex && (r.width != img.width || r.height != img.height || r.format != img.format)) {
        // A handle reused for another surface (never within one device; kept safe).
        gl.DeleteTextures(1, &r.tex);
        r = Resident{};
    }
    const bool native = space.mode == GlMode::Native;
    NativeFormat nf;
    if (!r.tex) {
        r.width = img.width, r.height = img.height, r.format = img.format;
        gl.GenTextures(1, &r.tex);
        gl.ActiveTexture(GL_TEXTURE0 + kUnitUpload);
        gl.BindTexture(GL_TEXTURE_2D, r.tex);
        if (native && nativeFormatOf(*img.format, nf)) {
            gl.TexStorage2D(GL_TEXTURE_2D, 1, nf.internal, GLsizei(img.width), GLsizei(img.height));
            // D3D9 samples X8R8G8B8 with alpha 1 and R32F as (r, 1, 1, 1).
            if (img.format->format == D3DFMT_X8R8G8B8) gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_A, GL_ONE);
            if (img.format->format == D3DFMT_R32F)
                for (GLenum c : {GL_TEXTURE_SWIZZLE_G, GL_TEXTURE_SWIZZLE_B, GL_TEXTURE_SWIZZLE_A})
                    gl.TexParameteri(GL_TEXTURE_2D, c, GL_ONE);
        } else {
            GLenum internal, format;
            wordFormats(wordsOf(*img.format), internal, format);
            gl.TexStorage2D(GL_TEXTURE_2D, 1, internal, GLsizei(img.width), GLsizei(img.height));
        }
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    if (r.generation == surface.generation) return r;
    if (surface.generation == 0) {
        // Never written since it was made: the front's zero-filled bytes, cleared here instead of
        // uploaded (zero words in either mode's format).
        const uint32_t zero[4] = {};
        GLenum format = 0, type = 0;
        clientFormatOf(native, *img.format, format, type);
        gl.ClearTexSubImage(r.tex, 0, 0, 0, 0, GLsizei(img.width), GLsizei(img.height), 1, format, type, zero);
        r.generation = 0;
        return r;
    }
    // The front's contents are newer: upload them.
    gl.ActiveTexture(GL_TEXTURE0 + kUnitUpload);
    gl.BindTexture(GL_TEXTURE_2D, r.tex);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);  // D3D9 pitches are DWORD aligned, as GL's rows here
    if (native && nativeFormatOf(*img.format, nf)) {
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, GLsizei(img.width), GLsizei(img.height), nf.format, nf.type,
                         img.bytes.data());
    } else {
        const uint32_t n = wordsOf(*img.format), bytes = img.format->bytes;
        GLenum internal, format;
        wordFormats(n, internal, format);
        if (bytes == 4 * n) {
            gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, GLsizei(img.width), GLsizei(img.height), format, GL_UNSIGNED_INT,
                             img.bytes.data());
        } else {
            std::vector<uint32_t> words(size_t(img.width) * img.height * n, 0);
            for (uint32_t y = 0; y < img.height; ++y) {
                uint8_t* dst = reinterpret_cast<uint8_t*>(&words[size_t(y) * img.width * n]);
                for (uint32_t x = 0; x < img.width; ++x) std::memcpy(dst + size_t(x) * 4 * n, img.texel(x, y), bytes);
            }
            gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, GLsizei(img.width), GLsizei(img.height), format, GL_UNSIGNED_INT,
                             words.data());
        }
    }
    space.transfers.uploads += 1;
    space.transfers.uploadBytes += img.bytes.size();
    r.generation = surface.generation;
    return r;
}

void GlRenderer::readBack(GlSpace& space, const SurfaceDesc& surface) {
    m_context->makeCurrent();
    auto it = space.surfaces.find(GlSpace::key(surface.resource, surface.level));
    if (it == space.surfaces.end()) return;  // never handed to this renderer: the front is current
    const GlFunctions& gl = m_context->gl();
    Resident& r = it->second;
    Image& img = *surface.image;
    gl.ActiveTexture(GL_TEXTURE0 + kUnitUpload);
    gl.BindTexture(GL_TEXTURE_2D, r.tex);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    NativeFormat nf;
    if (space.mode == GlMode::Native && nativeFormatOf(*img.format, nf)) {
        gl.GetTexImage(GL_TEXTURE_2D, 0, nf.format, nf.type, img.bytes.data());
        // X8R8G8B8 stores 0xff in the unused byte (the merger's and Clear's rule).
        if (img.format->format == D3DFMT_X8R8G8B8)
            for (uint32_t y = 0; y < img.height; ++y)
                for (uint32_t x = 0; x < img.width; ++x) img.texel(x, y)[3] = 0xff;
    } else {
        const uint32_t n = wordsOf(*img.format), bytes = img.format->bytes;
        GLenum internal, format;
        wordFormats(n, internal, format);
        if (bytes == 4 * n) {
            gl.GetTexImage(GL_TEXTURE_2D, 0, format, GL_UNSIGNED_INT, img.bytes.data());
        } else {
            std::vector<uint32_t> words(size_t(img.width) * img.height * n, 0);
            gl.GetTexImage(GL_TEXTURE_2D, 0, format, GL_UNSIGNED_INT, words.data());
            for (uint32_t y = 0; y < img.height; ++y) {
                const uint8_t* src = reinterpret_cast<const uint8_t*>(&words[size_t(y) * img.width * n]);
                for (uint32_t x = 0; x < img.width; ++x) std::memcpy(img.texel(x, y), src + size_t(x) * 4 * n, bytes);
            }
        }
    }
    space.transfers.readBacks += 1;
    space.transfers.readBackBytes += img.bytes.size();
}

void GlRenderer::release(GlSpace& space, uint32_t resource) {
    m_context->makeCurrent();
    const GlFunctions& gl = m_context->gl();
    auto it = space.surfaces.lower_bound(GlSpace::key(resource, 0));
    while (it != space.surfaces.end() && uint32_t(it->first >> 32) == resource) {
        gl.DeleteTextures(1, &it->second.tex);
        it = space.surfaces.erase(it);
    }
}

void GlRenderer::releaseAll(GlSpace& space) {
    m_context->makeCurrent();
    const GlFunctions& gl = m_context->gl();
    for (auto& [k, r] : space.surfaces) {
        gl.DeleteTextures(1, &r.tex);
    }
    space.surfaces.clear();
}

bool GlRenderer::clear(GlSpace& space, const ClearCall& call) {
    // Depth words that keep part of the old value (stencil-only or depth-only clears of D24S8)
    // are left to the front.
    if (call.depth.valid() && call.depthKeep != 0) return false;
    m_context->makeCurrent();
    const GlFunctions& gl = m_context->gl();
    GlState& st = *m_state;
    const bool native = space.mode == GlMode::Native;
    auto fill = [&](const SurfaceDesc& s, const uint8_t* texel) {
        Resident& r = st.resident(space, s);
        GLenum format = 0, type = 0;
        uint32_t words[4] = {};
        if (!clientFormatOf(native, *s.image->format, format, type)) {
            // Raw words: the texel's bytes, the last word padded with zeros.
            std::memcpy(words, texel, s.image->format->bytes);
            texel = reinterpret_cast<const uint8_t*>(words);
        }
        for (const PixelBox& b0 : call.boxes) {
            const PixelBox b{std::max<int64_t>(b0.x0, 0), std::max<int64_t>(b0.y0, 0),
                             std::min<int64_t>(b0.x1, r.width), std::min<int64_t>(b0.y1, r.height)};
            if (b.empty()) continue;
            gl.ClearTexSubImage(r.tex, 0, GLint(b.x0), GLint(b.y0), 0, GLsizei(b.x1 - b.x0), GLsizei(b.y1 - b.y0), 1,
                                format, type, texel);
        }
        r.generation = s.writeGeneration;
    };
    if (call.color.valid()) fill(call.color, call.colorTexel.data());
    if (call.depth.valid()) {
        uint8_t word[4];
        std::memcpy(word, &call.depthSet, 4);
        fill(call.depth, word);
    }
    return true;
}

bool GlRenderer::stretchRect(GlSpace& space, const StretchCall& call) {
    m_context->makeCurrent();
    const GlFunctions& gl = m_context->gl();
    GlState& st = *m_state;
    const FormatInfo& sf = *call.source.image->format;
    const FormatInfo& df = *call.dest.image->format;
    const PixelBox& sr = call.sourceRect;
    const PixelBox& dr = call.destRect;
    const bool unscaled = sr.x1 - sr.x0 == dr.x1 - dr.x0 && sr.y1 - sr.y0 == dr.y1 - dr.y0;
    if (space.mode == GlMode::Native) {
        NativeFormat a, b;
        if (!nativeFormatOf(sf, a) || !nativeFormatOf(df, b) || a.depth || b.depth) return false;
        Resident& s = st.resident(space, call.source);
        Resident& d = st.resident(space, call.dest);
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, st.readFbo);
        gl.FramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, s.tex, 0);
        drawInto(gl, st.fbo, d.tex);
        gl.Disable(GL_SCISSOR_TEST);
        gl.BlitFramebuffer(GLint(sr.x0), GLint(sr.y0), GLint(sr.x1), GLint(sr.y1), GLint(dr.x0), GLint(dr.y0),
                           GLint(dr.x1), GLint(dr.y1), GL_COLOR_BUFFER_BIT,
                           call.linear && !unscaled ? GL_LINEAR : GL_NEAREST);
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        d.generation = call.dest.writeGeneration;
        return true;
    }
    if (&sf == &df && unscaled) {
        // An unscaled copy in one format is the texels as they are (either filter).
        Resident& s = st.resident(space, call.source);
        Resident& d = st.resident(space, call.dest);
        gl.CopyImageSubData(s.tex, GL_TEXTURE_2D, 0, GLint(sr.x0), GLint(sr.y0), 0, d.tex, GL_TEXTURE_2D, 0,
                            GLint(dr.x0), GLint(dr.y0), 0, GLsizei(sr.x1 - sr.x0), GLsizei(sr.y1 - sr.y0), 1);
        d.generation = call.dest.writeGeneration;
        return true;
    }
    if (sf.format != D3DFMT_A8R8G8B8 || df.format != D3DFMT_A8R8G8B8) return false;
    std::string log;
    if (!st.stretchProgram) {
        if (!st.vertexShader && !(st.vertexShader = compileShader(gl, GL_VERTEX_SHADER, vertexSource(), log))) return false;
        if (!(st.stretchProgram = linkProgram(gl, st.vertexShader, kStretchFragment, log))) return false;
    }
    // The taps of the columns, then of the rows (emu/blit.h: one definition for both renderers).
    std::vector<uint32_t> taps;
    for (bool horizontal : {true, false})
        for (const StretchTap& t : stretchTaps(call, horizontal)) {
            uint32_t w[2];
            std::memcpy(w, &t.w1, 8);
            taps.insert(taps.end(), {uint32_t(t.i0), uint32_t(t.i1), w[0], w[1]});
        }
    Resident& s = st.resident(space, call.source);
    Resident& d = st.resident(space, call.dest);
    gl.BindBuffer(GL_TEXTURE_BUFFER, st.tapBuffer);
    gl.BufferData(GL_TEXTURE_BUFFER, GLsizeiptr(taps.size() * 4), taps.data(), GL_STREAM_DRAW);
    gl.ActiveTexture(GL_TEXTURE0 + kUnitTri);
    gl.BindTexture(GL_TEXTURE_BUFFER, st.tapTexture);
    gl.TexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32UI, st.tapBuffer);
    gl.ActiveTexture(GL_TEXTURE0 + kUnitDstColor);
    gl.BindTexture(GL_TEXTURE_2D, s.tex);
    gl.UseProgram(st.stretchProgram);
    gl.Uniform1i(gl.GetUniformLocation(st.stretchProgram, "uSrc"), kUnitDstColor);
    gl.Uniform1i(gl.GetUniformLocation(st.stretchProgram, "uTaps"), kUnitTri);
    const GLint dst[4] = {GLint(dr.x0), GLint(dr.y0), GLint(dr.x1 - dr.x0), GLint(dr.y1 - dr.y0)};
    gl.Uniform4iv(gl.GetUniformLocation(st.stretchProgram, "uDst"), 1, dst);
    gl.Uniform1i(gl.GetUniformLocation(st.stretchProgram, "uLinear"), call.linear ? 1 : 0);
    gl.Uniform4f(gl.GetUniformLocation(st.stretchProgram, "uXform"), 2.0f / float(d.width), -2.0f / float(d.height),
                 -1.0f, 1.0f);
    drawInto(gl, st.fbo, d.tex);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_DEPTH_TEST);
    gl.ClipControl(GL_UPPER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    gl.Viewport(0, 0, GLsizei(d.width), GLsizei(d.height));
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(dst[0], dst[1], dst[2], dst[3]);
    const float x0 = float(dr.x0), y0 = float(dr.y0), x1 = float(dr.x1), y1 = float(dr.y1);
    const float quad[12] = {x0, y0, x1, y0, x0, y1, x1, y0, x1, y1, x0, y1};
    gl.BindVertexArray(st.vao);
    for (GLuint a = 1; a < 11; ++a) gl.DisableVertexAttribArray(a);
    gl.BindBuffer(GL_ARRAY_BUFFER, st.vbo);
    gl.BufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STREAM_DRAW);
    gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 8, nullptr);
    gl.EnableVertexAttribArray(0);
    gl.DrawArrays(GL_TRIANGLES, 0, 6);
    gl.Disable(GL_SCISSOR_TEST);
    d.generation = call.dest.writeGeneration;
    return true;
}

}  // namespace emu::gl
