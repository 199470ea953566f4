// GLSL shaders and programs on a context (emu/gl/functions.h): compiled and linked once here for
// the GL renderer, its tests and the benchmarks that write their own GLSL.
#pragma once

#include <string>

#include "emu/gl/functions.h"

namespace emu::gl {

// A compiled shader, or 0 with the compiler's log in `log`.
GLuint compileShader(const GlFunctions& gl, GLenum type, const std::string& source, std::string& log);
// `vertex` (kept) linked with `fragment` compiled here; 0 with the log on failure.
GLuint linkProgram(const GlFunctions& gl, GLuint vertex, const std::string& fragment, std::string& log);

}  // namespace emu::gl
