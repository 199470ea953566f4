// GL backend, EGL contexts: OpenGL 3.3 core without a window, made current with EGL_NO_SURFACE
// (EGL_KHR_surfaceless_context; rendering goes to FBOs). Two platforms: Mesa's surfaceless one
// (EGL_MESA_platform_surfaceless: llvmpipe, or the GPU Mesa finds) and the device platform
// (EGL_EXT_platform_device over eglQueryDevicesEXT: a GPU driver such as NVIDIA's, and Mesa's
// software device). This is the kind that still works on Mesa 25.1+, which has no OSMesa.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <dlfcn.h>
#include <link.h>

#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <vector>

#include "emu/gl/context.h"

namespace emu::gl {

namespace {

// Keeps Mesa's EGL vendor library and DRI driver loaded for the rest of the process (dlopen with
// RTLD_NODELETE on the objects already loaded). eglTerminate otherwise unloads them, and the
// driver's one-time allocations (128 bytes with Mesa 22.3.6-1+deb12u2) are then left where no
// loaded module refers to them, which LeakSanitizer reports with no module to suppress by.
void pinMesaDriver() {
    dl_iterate_phdr(
        [](dl_phdr_info* info, size_t, void*) {
            const char* name = info->dlpi_name;
            if (name && (std::strstr(name, "/dri/") || std::strstr(name, "libEGL_mesa") ||
                         std::strstr(name, "libgallium")))
                dlopen(name, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
            return 0;
        },
        nullptr);
}

// Whether a space-separated extension list holds `name` as a whole word.
bool hasExtension(const char* list, const char* name) {
    if (!list) return false;
    size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

std::string eglErrorText(EGLint code) {
    static const struct {
        EGLint code;
        const char* name;
    } kNames[] = {
        {EGL_SUCCESS, "EGL_SUCCESS"},
        {EGL_NOT_INITIALIZED, "EGL_NOT_INITIALIZED"},
        {EGL_BAD_ACCESS, "EGL_BAD_ACCESS"},
        {EGL_BAD_ALLOC, "EGL_BAD_ALLOC"},
        {EGL_BAD_ATTRIBUTE, "EGL_BAD_ATTRIBUTE"},
        {EGL_BAD_CONFIG, "EGL_BAD_CONFIG"},
        {EGL_BAD_CONTEXT, "EGL_BAD_CONTEXT"},
        {EGL_BAD_CURRENT_SURFACE, "EGL_BAD_CURRENT_SURFACE"},
        {EGL_BAD_DISPLAY, "EGL_BAD_DISPLAY"},
        {EGL_BAD_MATCH, "EGL_BAD_MATCH"},
        {EGL_BAD_NATIVE_PIXMAP, "EGL_BAD_NATIVE_PIXMAP"},
        {EGL_BAD_NATIVE_WINDOW, "EGL_BAD_NATIVE_WINDOW"},
        {EGL_BAD_PARAMETER, "EGL_BAD_PARAMETER"},
        {EGL_BAD_SURFACE, "EGL_BAD_SURFACE"},
        {EGL_CONTEXT_LOST, "EGL_CONTEXT_LOST"},
    };
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%04x", unsigned(code));
    for (const auto& e : kNames)
        if (e.code == code) return std::string(e.name) + " " + hex;
    return hex;
}

std::string lastEglError() { return eglErrorText(eglGetError()); }

// EGL displays are shared per (platform, native display) within a process, and eglTerminate ends
// every context on one: so contexts count their display's users and the last one terminates it.
class DisplayRef {
public:
    DisplayRef() = default;
    DisplayRef(const DisplayRef&) = delete;
    DisplayRef& operator=(const DisplayRef&) = delete;
    ~DisplayRef() { reset(); }

    // eglInitialize for the first user; false (EGL's error in `why`) if it fails.
    bool acquire(EGLDisplay dpy, EGLint& major, EGLint& minor, std::string& why) {
        std::lock_guard<std::mutex> lock(mutex());
        int& users = counts()[dpy];
        if (!eglInitialize(dpy, &major, &minor)) {
            why = lastEglError();
            if (users == 0) counts().erase(dpy);
            return false;
        }
        ++users;
        m_dpy = dpy;
        pinMesaDriver();
        return true;
    }
    void reset() {
        if (m_dpy == EGL_NO_DISPLAY) return;
        std::lock_guard<std::mutex> lock(mutex());
        auto it = counts().find(m_dpy);
        if (it != counts().end() && --it->second == 0) {
            counts().erase(it);
            eglTerminate(m_dpy);
        }
        m_dpy = EGL_NO_DISPLAY;
    }
    EGLDisplay get() const { return m_dpy; }

private:
    static std::mutex& mutex() {
        static std::mutex m;
        return m;
    }
    static std::map<EGLDisplay, int>& counts() {
        static std::map<EGLDisplay, int> c;
        return c;
    }
    EGLDisplay m_dpy = EGL_NO_DISPLAY;
};

class EglContextImpl final : public Context {
public:
    explicit EglContextImpl(std::string label) : m_label(std::move(label)) {}
    ~EglContextImpl() override {
        if (m_ctx == EGL_NO_CONTEXT) return;
        if (eglGetCurrentContext() == m_ctx)
            eglMakeCurrent(m_display.get(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(m_display.get(), m_ctx);
    }

    ContextKind kind() const override { return ContextKind::Egl; }
    std::string platform() const override { return "EGL " + m_label; }
    GlProc getProcAddress(const char* name) const override { return eglGetProcAddress(name); }
    bool makeCurrent() override {
        return eglBindAPI(EGL_OPENGL_API) && eglMakeCurrent(m_display.get(), EGL_NO_SURFACE, EGL_NO_SURFACE, m_ctx);
    }

    // Initialises `dpy` and makes a 3.3 core context on it, current; `error` names what failed.
    bool create(EGLDisplay dpy, std::string& error) {
        const std::string prefix = "EGL: " + m_label + ": ";
        EGLint major = 0, minor = 0;
        std::string why;
        if (!m_display.acquire(dpy, major, minor, why)) {
            error = prefix + "eglInitialize failed (" + why + ")";
            return false;
        }
        const char* extensions = eglQueryString(dpy, EGL_EXTENSIONS);
        bool egl15 = major > 1 || (major == 1 && minor >= 5);
        if (!egl15 && !hasExtension(extensions, "EGL_KHR_create_context")) {
            error = prefix + "EGL " + std::to_string(major) + "." + std::to_string(minor) +
                    " without EGL_KHR_create_context cannot ask for a core profile";
            return false;
        }
        if (!hasExtension(extensions, "EGL_KHR_surfaceless_context")) {
            error = prefix + "no EGL_KHR_surfaceless_context (a context without a surface)";
            return false;
        }
        const char* apis = eglQueryString(dpy, EGL_CLIENT_APIS);
        if (!hasExtension(apis, "OpenGL") || !eglBindAPI(EGL_OPENGL_API)) {
            error = prefix + "no desktop OpenGL (EGL_CLIENT_APIS: " + (apis ? apis : "none") + ")";
            return false;
        }
        // Rendering goes to FBOs, so no config is needed where the driver allows that.
        EGLConfig config = EGL_NO_CONFIG_KHR;
        if (!hasExtension(extensions, "EGL_KHR_no_config_context")) {
            const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
            EGLint count = 0;
            if (!eglChooseConfig(dpy, want, &config, 1, &count) || count < 1) {
                error = prefix + "no config renders desktop OpenGL";
                return false;
            }
        }
        // OpenGL 3.3 core, the least the backend takes; where the driver gives exactly that and no
        // more (NVIDIA's does; Mesa gives the highest it has), 4.5 core once more, which the GL
        // renderer's shaders need.
        auto create = [&](EGLint major, EGLint minor) {
            // clang-format off
            const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, major,
                                      EGL_CONTEXT_MINOR_VERSION, minor,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_NONE};
            // clang-format on
            return eglCreateContext(dpy, config, EGL_NO_CONTEXT, attribs);
        };
        m_ctx = create(3, 3);
        if (m_ctx == EGL_NO_CONTEXT) {
            error = prefix + "eglCreateContext refused OpenGL 3.3 core (" + lastEglError() + ")";
            return false;
        }
        if (!makeCurrent()) {
            error = prefix + "eglMakeCurrent with EGL_NO_SURFACE failed (" + lastEglError() + ")";
            return false;
        }
        auto getIntegerv = reinterpret_cast<PFNGLGETINTEGERVPROC>(eglGetProcAddress("glGetIntegerv"));
        GLint glMajor = 0, glMinor = 0;
        if (getIntegerv) {
            getIntegerv(GL_MAJOR_VERSION, &glMajor);
            getIntegerv(GL_MINOR_VERSION, &glMinor);
        }
        if (glMajor * 10 + glMinor < 45) {
            const EGLContext higher = create(4, 5);
            if (higher != EGL_NO_CONTEXT) {
                eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
                eglDestroyContext(dpy, m_ctx);
                m_ctx = higher;
                if (!makeCurrent()) {
                    error = prefix + "eglMakeCurrent with EGL_NO_SURFACE failed (" + lastEglError() + ")";
                    return false;
                }
            }
        }
        return finishSetup(prefix, error);
    }

private:
    std::string m_label;
    DisplayRef m_display;  // released after the destructor body has destroyed m_ctx
    EGLContext m_ctx = EGL_NO_CONTEXT;
};

// The client extensions and the entry points of EGL_EXT_platform_base / device enumeration.
struct EglClient {
    const char* extensions = nullptr;
    PFNEGLGETPLATFORMDISPLAYEXTPROC getPlatformDisplay = nullptr;
    PFNEGLQUERYDEVICESEXTPROC queryDevices = nullptr;
    PFNEGLQUERYDEVICESTRINGEXTPROC queryDeviceString = nullptr;

    // False (with `error`) when EGL has no client extensions or no platform displays at all.
    bool load(std::string& error) {
        // Null when EGL_EXT_client_extensions is missing (EGL_BAD_DISPLAY).
        extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
        if (!extensions) {
            eglGetError();
            error = "EGL: no client extensions (EGL_EXT_client_extensions missing, or no EGL vendor library)";
            return false;
        }
        if (!hasExtension(extensions, "EGL_EXT_platform_base")) {
            error = "EGL: no platform displays (EGL_EXT_platform_base missing)";
            return false;
        }
        getPlatformDisplay =
            reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        queryDeviceString =
            reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
        if (!getPlatformDisplay) {
            error = "EGL: eglGetPlatformDisplayEXT not found";
            return false;
        }
        return true;
    }
};

std::unique_ptr<Context> createSurfaceless(const EglClient& egl, std::string& error) {
    if (!hasExtension(egl.extensions, "EGL_MESA_platform_surfaceless")) {
        error = "EGL: no surfaceless platform (EGL_MESA_platform_surfaceless missing)";
        return nullptr;
    }
    EGLDisplay dpy = egl.getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (dpy == EGL_NO_DISPLAY) {
        error = "EGL: surfaceless: no display (" + lastEglError() + ")";
        return nullptr;
    }
    auto context = std::make_unique<EglContextImpl>("surfaceless");
    if (!context->create(dpy, error)) return nullptr;
    return context;
}

// "EGL_MESA_device_software" or the DRM device file: what a device is, for reports.
std::string deviceName(const EglClient& egl, EGLDeviceEXT device) {
    if (!egl.queryDeviceString) return "?";
    const char* exts = egl.queryDeviceString(device, EGL_EXTENSIONS);
    if (hasExtension(exts, "EGL_EXT_device_drm")) {
        if (const char* file = egl.queryDeviceString(device, EGL_DRM_DEVICE_FILE_EXT)) return file;
    }
    if (hasExtension(exts, "EGL_MESA_device_software")) return "EGL_MESA_device_software";
    eglGetError();
    return exts && *exts ? exts : "?";
}

// The device asked for (index >= 0), or each device in turn until one makes a context.
std::unique_ptr<Context> createOnDevice(const EglClient& egl, int index, std::string& error) {
    if (!hasExtension(egl.extensions, "EGL_EXT_platform_device") || !egl.queryDevices ||
        !(hasExtension(egl.extensions, "EGL_EXT_device_enumeration") ||
          hasExtension(egl.extensions, "EGL_EXT_device_base"))) {
        error = "EGL: no device platform (EGL_EXT_platform_device or EGL_EXT_device_enumeration missing)";
        return nullptr;
    }
    EGLint count = 0;
    if (!egl.queryDevices(0, nullptr, &count)) {
        error = "EGL: eglQueryDevicesEXT failed (" + lastEglError() + ")";
        return nullptr;
    }
    std::vector<EGLDeviceEXT> devices(size_t(count > 0 ? count : 0));
    if (count > 0 && !egl.queryDevices(count, devices.data(), &count)) {
        error = "EGL: eglQueryDevicesEXT failed (" + lastEglError() + ")";
        return nullptr;
    }
    devices.resize(size_t(count > 0 ? count : 0));
    if (devices.empty()) {
        error = "EGL: eglQueryDevicesEXT lists no devices";
        return nullptr;
    }
    if (index >= int(devices.size())) {
        error = "EGL: device " + std::to_string(index) + " asked for, but eglQueryDevicesEXT lists " +
                std::to_string(devices.size()) + " (0.." + std::to_string(devices.size() - 1) + ")";
        return nullptr;
    }
    std::string errors;
    for (size_t i = index >= 0 ? size_t(index) : 0; i < devices.size(); ++i) {
        std::string label = "device " + std::to_string(i) + " (" + deviceName(egl, devices[i]) + ")";
        std::string why;
        EGLDisplay dpy = egl.getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (dpy == EGL_NO_DISPLAY) {
            why = "EGL: " + label + ": no display (" + lastEglError() + ")";
        } else {
            auto context = std::make_unique<EglContextImpl>(label);
            if (context->create(dpy, why)) return context;
        }
        errors += (errors.empty() ? "" : "; ") + why;
        if (index >= 0) break;
    }
    error = errors;
    return nullptr;
}

}  // namespace

std::unique_ptr<Context> createEglContext(const ContextOptions& options, std::string& error) {
    EglClient egl;
    if (!egl.load(error)) return nullptr;
    if (options.eglPlatform == EglPlatform::Surfaceless) return createSurfaceless(egl, error);
    if (options.eglPlatform == EglPlatform::Device) return createOnDevice(egl, options.eglDevice, error);
    // Auto: surfaceless first (Mesa picks llvmpipe or the GPU it finds), then each device.
    std::string surfacelessError, deviceError;
    if (std::unique_ptr<Context> c = createSurfaceless(egl, surfacelessError)) return c;
    if (std::unique_ptr<Context> c = createOnDevice(egl, -1, deviceError)) return c;
    error = surfacelessError + "; " + deviceError;
    return nullptr;
}

}  // namespace emu::gl
