// The GL renderer (docs/gl-backend.md "Renderer"): the device front's calls (emu/renderer.h)
// carried out with OpenGL 4.5 core through an emu::gl::Context. One GlRenderer per context holds
// what every device shares (the context, the program and texture caches); each device draws
// through its own DeviceRenderer (GlRenderer::forDevice), which keeps the device's surfaces
// resident on the GL side: uploaded when the front's contents change (by generation), read back
// only when the front asks. Two modes translate the same calls:
// - exact: bit for bit with the emulator. Surfaces are raw words, each fragment evaluates the
//   rasteriser's planes, filters by hand and merges in the shader (emu/gl/glsl.h); Clear and
//   StretchRect write the emulator's texels. The cross-check.
// - native: what a GPU driver runs. Surfaces in GL's own formats (RGBA8, RGBA16F, DEPTH24_STENCIL8
//   ...), GL's interpolation and filtering, float arithmetic, GL's blend and depth state,
//   glBlitFramebuffer for StretchRect. The speed peer; not bit-exact by design.
// What it cannot draw is refused with E4122, never drawn differently.
#pragma once

#include <memory>
#include <string>

#include "emu/gl/context.h"
#include "emu/renderer.h"

namespace emu::gl {

enum class GlMode : uint8_t { Exact, Native };
const char* glModeName(GlMode mode);  // "exact", "native"
// "exact" or "native"; false for anything else.
bool parseGlMode(const std::string& text, GlMode& mode);

struct GlRendererOptions {
    ContextOptions context;  // which context (OSMesa first, then EGL, by default)
    // Exact mode, float and ideal profiles: filter with GL's texture unit
    // (FragmentSpec::hardwareFiltering), not the emulator's formulas: measures a GPU's filtering,
    // no longer a bit-exact renderer.
    bool hardwareFiltering = false;
};

struct GlState;  // programs, textures, buffers and resident surfaces (gl_internal.h)
struct GlSpace;  // one device's resident surfaces

class GlRenderer {
public:
    // Makes the context and checks what the shaders need (OpenGL 4.5, ARB_gpu_shader_int64);
    // null with `error` naming what is missing.
    static std::unique_ptr<GlRenderer> create(const GlRendererOptions& options, std::string& error);
    ~GlRenderer();

    // A device's renderer in `mode`; it keeps `shared` alive.
    static std::unique_ptr<Renderer> forDevice(std::shared_ptr<GlRenderer> shared, GlMode mode);

    const Context& context() const { return *m_context; }

    // The operations of a device renderer, on that device's space.
    bool draw(GlSpace& space, const DrawCall& call, DrawStats& stats, CallError& error);
    bool clear(GlSpace& space, const ClearCall& call);
    bool stretchRect(GlSpace& space, const StretchCall& call);
    void readBack(GlSpace& space, const SurfaceDesc& surface);
    void release(GlSpace& space, uint32_t resource);
    void releaseAll(GlSpace& space);
    // glFinish: every GL call so far has completed.
    void finish();

private:
    GlRenderer() = default;
    bool drawExact(GlSpace& space, const DrawCall& call, DrawStats& stats, CallError& error);
    bool drawNative(GlSpace& space, const DrawCall& call, DrawStats& stats, CallError& error);
    std::unique_ptr<Context> m_context;
    std::unique_ptr<GlState> m_state;
    bool m_hardwareFiltering = false;
};

}  // namespace emu::gl
