// OpenGL 3.3+ core contexts for the GL backend (docs/gl-backend.md "Contexts"): one small
// interface, two implementations (OSMesa, EGL), chosen at run time. Rendering goes to FBOs, so a
// context needs no window and no default framebuffer of a useful size.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "emu/gl/functions.h"

namespace emu::gl {

enum class ContextKind {
    OSMesa,  // Mesa's off-screen library (libOSMesa, llvmpipe); removed from Mesa 25.1
    Egl,     // EGL without a window: Mesa's surfaceless platform or a driver's device platform
};

// "osmesa" / "egl": the names `ps11 info --gl` takes.
std::string_view contextKindName(ContextKind kind);
std::optional<ContextKind> parseContextKind(std::string_view name);

// Which EGL platform an EGL context is made on.
enum class EglPlatform {
    Auto,         // surfaceless (EGL_MESA_platform_surfaceless), then each device in turn
    Surfaceless,  // only EGL_PLATFORM_SURFACELESS_MESA
    Device,       // only EGL_PLATFORM_DEVICE_EXT (a GPU driver, or Mesa's software device)
};

struct ContextOptions {
    std::optional<ContextKind> kind;  // none: OSMesa, then EGL
    EglPlatform eglPlatform = EglPlatform::Auto;
    int eglDevice = -1;  // Device: the index in eglQueryDevicesEXT's list; -1 = the first that works
};

// A current-able OpenGL 3.3+ core profile context. Not copyable; destroying it releases the
// context (and makes nothing current on this thread if it was current).
class Context {
public:
    Context() = default;
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
    virtual ~Context() = default;

    virtual ContextKind kind() const = 0;
    // How it was made, for reports: "OSMesa", "EGL surfaceless", "EGL device 0 (EGL_MESA_device_software)".
    virtual std::string platform() const = 0;
    // A GL (or window-system) entry point of this context's library, or null.
    virtual GlProc getProcAddress(const char* name) const = 0;
    // Makes this context current on the calling thread; false if the library refused.
    virtual bool makeCurrent() = 0;

    // The entry points of functions.h, loaded through getProcAddress when the context was made.
    const GlFunctions& gl() const { return m_gl; }
    // GL_RENDERER, GL_VERSION, GL_SHADING_LANGUAGE_VERSION, read when the context was made.
    const std::string& renderer() const { return m_renderer; }
    const std::string& version() const { return m_version; }
    const std::string& shadingLanguageVersion() const { return m_glsl; }
    // GL_MAJOR_VERSION.GL_MINOR_VERSION as 10·major + minor (33 for 3.3).
    int versionNumber() const { return m_versionNumber; }

protected:
    // Called by the implementations once the context is current: loads gl() and reads the strings;
    // refuses (with `error`) a context that is not 3.3+ core. `prefix` starts every error ("EGL: ").
    bool finishSetup(const std::string& prefix, std::string& error);

private:
    GlFunctions m_gl;
    std::string m_renderer, m_version, m_glsl;
    int m_versionNumber = 0;
};

// Makes a context of the kind asked for, or with no kind the first that works: OSMesa, then EGL.
// On failure returns null and sets `error` to what failed, each kind tried named and joined by
// "; " ("OSMesa: ...; EGL: no surfaceless platform (EGL_MESA_platform_surfaceless missing)").
// Never throws for a missing library or driver. Leaves the new context current on this thread.
std::unique_ptr<Context> createContext(const ContextOptions& options, std::string& error);
std::unique_ptr<Context> createContext(std::optional<ContextKind> kind, std::string& error);

// Whether the build has each kind (PS11_GL_OSMESA can leave OSMesa out on Mesa 25.1+).
bool contextKindBuilt(ContextKind kind);

// The implementations (context_osmesa.cpp, context_egl.cpp); use createContext.
std::unique_ptr<Context> createOSMesaContext(std::string& error);
std::unique_ptr<Context> createEglContext(const ContextOptions& options, std::string& error);

}  // namespace emu::gl
