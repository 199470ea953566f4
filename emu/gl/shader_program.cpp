// Renderer stage: compiling and linking GLSL (emu/gl/shader_program.h).
#include "emu/gl/shader_program.h"

namespace emu::gl {

GLuint compileShader(const GlFunctions& gl, GLenum type, const std::string& source, std::string& log) {
    const GLuint s = gl.CreateShader(type);
    const char* text = source.c_str();
    gl.ShaderSource(s, 1, &text, nullptr);
    gl.CompileShader(s);
    GLint ok = 0;
    gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char buf[4096] = {};
        gl.GetShaderInfoLog(s, sizeof buf - 1, nullptr, buf);
        log = buf;
        gl.DeleteShader(s);
        return 0;
    }
    return s;
}

GLuint linkProgram(const GlFunctions& gl, GLuint vertex, const std::string& fragment, std::string& log) {
    const GLuint fs = compileShader(gl, GL_FRAGMENT_SHADER, fragment, log);
    if (!fs) return 0;
    const GLuint p = gl.CreateProgram();
    gl.AttachShader(p, vertex);
    gl.AttachShader(p, fs);
    gl.LinkProgram(p);
    gl.DeleteShader(fs);
    GLint ok = 0;
    gl.GetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char buf[4096] = {};
        gl.GetProgramInfoLog(p, sizeof buf - 1, nullptr, buf);
        log = buf;
        gl.DeleteProgram(p);
        return 0;
    }
    return p;
}

}  // namespace emu::gl
