// The GL renderer (docs/gl-backend.md "Renderer"): draws the device front's DrawCalls
// (emu/renderer.h) with OpenGL 4.5 core through an emu::gl::Context. Each draw uploads the
// render target and depth surface as raw words, draws the triangles with a fragment shader
// generated from the program (emu/gl/glsl.h: exact mode in fx8/fx12, float mode in
// float/ideal), merges in the shader, and reads the surfaces back. What it cannot draw is
// refused with E4122, never drawn differently.
#pragma once

#include <memory>
#include <string>

#include "emu/gl/context.h"
#include "emu/renderer.h"

namespace emu::gl {

struct GlRendererOptions {
    ContextOptions context;  // which context (OSMesa first, then EGL, by default)
    // float and ideal profiles: filter with GL's texture unit (FragmentSpec::hardwareFiltering),
    // not the emulator's formulas: measures a GPU's filtering, no longer a bit-exact renderer.
    bool hardwareFiltering = false;
};

struct GlState;  // programs, textures and buffers of the context (gl_renderer.cpp)

class GlRenderer final : public Renderer {
public:
    // Makes the context and checks what the shaders need (OpenGL 4.5, ARB_gpu_shader_int64);
    // null with `error` naming what is missing.
    static std::unique_ptr<GlRenderer> create(const GlRendererOptions& options, std::string& error);
    ~GlRenderer() override;

    bool draw(const DrawCall& call, DrawStats& stats, RendererError& error) override;
    const char* name() const override { return "gl"; }

    const Context& context() const { return *m_context; }
    // Wall time of the last draw's GL work alone (from the first GL draw call to glFinish),
    // without the uploads and the read-back: what benchmarks compare.
    double lastDrawMilliseconds() const { return m_lastDrawMs; }

private:
    GlRenderer() = default;
    std::unique_ptr<Context> m_context;
    std::unique_ptr<GlState> m_state;
    bool m_hardwareFiltering = false;
    double m_lastDrawMs = 0;
};

}  // namespace emu::gl
