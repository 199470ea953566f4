// GL backend, context creation: the part both kinds share — choosing a kind, loading the entry
// points, and refusing a context that is not OpenGL 3.3+ core. The kinds themselves live in
// context_osmesa.cpp and context_egl.cpp.
#include "emu/gl/context.h"

namespace emu::gl {

std::string_view contextKindName(ContextKind kind) { return kind == ContextKind::OSMesa ? "osmesa" : "egl"; }

std::optional<ContextKind> parseContextKind(std::string_view name) {
    if (name == "osmesa") return ContextKind::OSMesa;
    if (name == "egl") return ContextKind::Egl;
    return std::nullopt;
}

bool contextKindBuilt(ContextKind kind) {
#ifdef PS11_GL_HAVE_OSMESA
    (void)kind;
    return true;
#else
    return kind == ContextKind::Egl;
#endif
}

#ifndef PS11_GL_HAVE_OSMESA
std::unique_ptr<Context> createOSMesaContext(std::string& error) {
    error = "OSMesa: not in this build (configured with PS11_GL_OSMESA=OFF)";
    return nullptr;
}
#endif

bool Context::finishSetup(const std::string& prefix, std::string& error) {
    std::string missing;
    auto getProc = [this](const char* name) { return getProcAddress(name); };
    if (!loadGlFunctions(m_gl, getProc, missing)) {
        error = prefix + "the context has no " + missing;
        return false;
    }
    auto text = [this](GLenum what) {
        const GLubyte* s = m_gl.GetString(what);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
    };
    m_renderer = text(GL_RENDERER);
    m_version = text(GL_VERSION);
    m_glsl = text(GL_SHADING_LANGUAGE_VERSION);
    while (m_gl.GetError() != GL_NO_ERROR) {
    }
    GLint major = 0, minor = 0, profile = 0;
    m_gl.GetIntegerv(GL_MAJOR_VERSION, &major);
    m_gl.GetIntegerv(GL_MINOR_VERSION, &minor);
    // GL_CONTEXT_PROFILE_MASK exists from 3.2 on; a 3.0/3.1 context reports an error and 0.
    m_gl.GetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    bool queried = m_gl.GetError() == GL_NO_ERROR;
    m_versionNumber = 10 * major + minor;
    if (!queried || m_versionNumber < 33 || !(profile & GL_CONTEXT_CORE_PROFILE_BIT)) {
        error = prefix + "asked for OpenGL 3.3 core, got \"" + m_version + "\" (" + std::to_string(major) + "." +
                std::to_string(minor) + ((profile & GL_CONTEXT_CORE_PROFILE_BIT) ? " core" : " not core") + ")";
        return false;
    }
    return true;
}

std::unique_ptr<Context> createContext(const ContextOptions& options, std::string& error) {
    error.clear();
    if (options.kind == ContextKind::OSMesa) return createOSMesaContext(error);
    if (options.kind == ContextKind::Egl) return createEglContext(options, error);
    // No kind asked for: what works, OSMesa first (the reference llvmpipe of DESIGN.md), then EGL.
    std::string osmesaError, eglError;
    if (std::unique_ptr<Context> c = createOSMesaContext(osmesaError)) return c;
    if (std::unique_ptr<Context> c = createEglContext(options, eglError)) return c;
    error = osmesaError + "; " + eglError;
    return nullptr;
}

std::unique_ptr<Context> createContext(std::optional<ContextKind> kind, std::string& error) {
    ContextOptions options;
    options.kind = kind;
    return createContext(options, error);
}

}  // namespace emu::gl
