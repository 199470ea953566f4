// The process's GL renderer (runner/gl_backend.h).
#include "runner/gl_backend.h"

#ifdef PS11_HAVE_GL
#include "emu/gl/gl_renderer.h"
#endif

namespace ps11test {

using namespace ps11;

#ifdef PS11_HAVE_GL
namespace {

struct Shared {
    std::shared_ptr<emu::gl::GlRenderer> renderer;
    std::string error;
    bool tried = false;
};
// Never destroyed: at exit, libOSMesa's own state may already be gone when a static
// destructor would release the context (it crashed there).
Shared& shared() {
    static Shared* s = new Shared;
    return *s;
}

}  // namespace

RendererFactory glRendererFactory(const std::string& kind, std::string& error, bool native, bool hardwareFiltering) {
    Shared& s = shared();
    if (!s.tried) {
        s.tried = true;
        emu::gl::GlRendererOptions options;
        options.context.kind = emu::gl::parseContextKind(kind);
        options.hardwareFiltering = hardwareFiltering;
        s.renderer = emu::gl::GlRenderer::create(options, s.error);
    }
    if (!s.renderer) {
        error = "no GL renderer: " + s.error;
        return {};
    }
    std::shared_ptr<emu::gl::GlRenderer> r = s.renderer;
    const emu::gl::GlMode mode = native ? emu::gl::GlMode::Native : emu::gl::GlMode::Exact;
    return [r, mode] { return emu::gl::GlRenderer::forDevice(r, mode); };
}

std::string glRendererDescription() {
    const Shared& s = shared();
    if (!s.renderer) return "";
    return s.renderer->context().renderer() + ", OpenGL " + s.renderer->context().version() + " (" +
           s.renderer->context().platform() + ")";
}
#else
RendererFactory glRendererFactory(const std::string&, std::string& error, bool, bool) {
    error = "no GL renderer: the OpenGL backend is not in this build (configured with PS11_GL=OFF)";
    return {};
}
std::string glRendererDescription() { return ""; }
#endif

}  // namespace ps11test
