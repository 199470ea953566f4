// The GL renderer for the command line and the .ps11test runner: one OpenGL context and one
// emu::gl::GlRenderer per process (its shader and texture caches serve every device), handed
// to each emu::Device through DeviceOptions::renderer.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "emu/renderer.h"

namespace ps11 {

using RendererFactory = std::function<std::unique_ptr<emu::Renderer>()>;

// A factory of devices' renderers that all draw through the process's GL renderer, made on the
// first call; an empty function with `error` set when there is none (no context, no OpenGL 4.5,
// or a build without the GL backend).
RendererFactory glRendererFactory(std::string& error);

// The GL renderer's description for reports ("llvmpipe (LLVM 15.0.6, 256 bits), OpenGL 4.5 …"),
// or "" before glRendererFactory succeeded.
std::string glRendererDescription();

}  // namespace ps11
