// Internal to the GL renderer (gl_renderer.cpp: draws; gl_surfaces.cpp: resident surfaces, Clear,
// StretchRect, read-back): the shared GL objects and caches, and one device's resident surfaces.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "emu/gl/functions.h"
#include "emu/gl/gl_renderer.h"
#include "ps11/decoded_program.h"

namespace emu::gl {

constexpr int kUnitTri = 8, kUnitDstColor = 9, kUnitDstDepth = 10, kUnitUpload = 11;

// A surface's copy on the GL side.
struct Resident {
    GLuint tex = 0;       // exact: raw words (R32UI, RG32UI, RGBA32UI); native: GL's own format
    uint64_t generation = ~uint64_t(0);  // the front's level generation this copy holds
    uint32_t width = 0, height = 0;
    const FormatInfo* format = nullptr;
};

// How a D3D format lives on the GL side in native mode: internal format, and the client format
// and type whose memory layout is the D3D texel's (so uploads, read-backs and clears pass the
// front's bytes as they are).
struct NativeFormat {
    GLenum internal = 0, format = 0, type = 0;
    bool depth = false, stencil = false;
};
// False for a format native mode does not keep as a surface.
bool nativeFormatOf(const FormatInfo& f, NativeFormat& out);

struct GlSpace {
    GlMode mode = GlMode::Exact;
    // Unique per device renderer: DrawProgram::key names a program within one device only.
    uint64_t serial = 0;
    std::map<uint64_t, Resident> surfaces;  // by resource << 32 | level
    TransferStats transfers;
    static uint64_t key(uint32_t resource, uint32_t level) { return uint64_t(resource) << 32 | level; }
};

struct ProgramEntry {
    GLuint program = 0;
    uint64_t lastUse = 0;
    std::unique_ptr<ps11::exec::DecodedProgram> decoded;  // constants and defs at draw time
    // Uniform locations (-1: the program does not use it).
    GLint constG = -1, constF = -1, bump = -1, lum = -1, borderG = -1, borderF = -1, stride = -1, tri = -1,
          dstColor = -1, dstDepth = -1, xform = -1, primBase = -1;
    GLint tex[ps11::kMaxTextureStages] = {-1, -1, -1, -1, -1, -1, -1, -1};
};

struct TextureEntry {
    std::shared_ptr<const ps11::Texture> texture;  // kept alive: its address is the key
    bool fx = false;
    ps11::Precision precision = ps11::Precision::Fx8;
    bool hardware = false;  // for GL's texture unit: 8-bit textures as GL_RGBA8
    GLuint name = 0;
    uint64_t lastUse = 0;
};

struct GlState {
    const GlFunctions& gl;
    explicit GlState(const GlFunctions& f) : gl(f) {}
    ~GlState();
    GLuint vao = 0, vbo = 0, triBuffer = 0, triTexture = 0, fbo = 0, readFbo = 0, query = 0;
    GLuint samplers[ps11::kMaxTextureStages] = {};  // GL sampler objects of GL's own filtering
    GLuint sizingTex = 0;     // exact mode without a colour target: sizes the framebuffer
    GLuint vertexShader = 0, nativeVertexShader = 0, stretchProgram = 0, tapBuffer = 0, tapTexture = 0;
    std::unordered_map<uint64_t, ProgramEntry> programs;  // by what determines the GLSL
    std::vector<TextureEntry> textures;
    uint64_t clock = 0;

    // The GL texture of a ps11 texture in the profile's terms (grid integers or float32, or
    // GL_RGBA8 for GL's own filtering).
    GLuint texture(const std::shared_ptr<const ps11::Texture>& tex, ps11::Precision precision, bool hardware);
    // The copy of a surface, created and uploaded from the front's image when it is missing or
    // older than the front's contents.
    Resident& resident(GlSpace& space, const SurfaceDesc& surface);
    // Binds GL's own sampling state for stage `s` (sampler object from the D3D sampler state).
    void bindSampler(int s, const ps11::SamplerState& sm);
};

}  // namespace emu::gl
