// The GL renderer for the command line and the .ps11test runner: one OpenGL context and one
// emu::gl::GlRenderer per process (its shader and texture caches serve every device), handed
// to each emu::Device through DeviceOptions::renderer.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "emu/renderer.h"

namespace ps11test {

using RendererFactory = std::function<std::unique_ptr<emu::Renderer>()>;

// A factory of devices' renderers that all draw through the process's GL renderer, made on the
// first call on a context of `kind` ("osmesa", "egl"; "" = the first that works, OSMesa then
// EGL); an empty function with `error` set when there is none (no context, no OpenGL 4.5, or a
// build without the GL backend). Later calls return the same renderer whatever kind they name.
// `native`: the devices draw in the GL renderer's native mode (emu/gl/gl_renderer.h), else exact.
// `hardwareFiltering` (exact mode): float profiles filter with GL's texture unit
// (GlRendererOptions); only the first call's value counts.
RendererFactory glRendererFactory(const std::string& kind, std::string& error, bool native = false,
                                  bool hardwareFiltering = false);

// The GL renderer's description for reports ("llvmpipe (LLVM 15.0.6, 256 bits), OpenGL 4.5 …"),
// or "" before glRendererFactory succeeded.
std::string glRendererDescription();

}  // namespace ps11test
