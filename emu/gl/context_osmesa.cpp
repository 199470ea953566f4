// GL backend, OSMesa contexts: Mesa's off-screen library (Debian 12: libosmesa6-dev, gallium
// llvmpipe inside libOSMesa). OSMesaCreateContextAttribs asks for a 3.3 core profile; the
// context renders into a small RGBA8 buffer this object owns (real rendering goes to FBOs).
// OSMesa was removed in Mesa 25.1; context_egl.cpp covers newer systems.
#include <GL/osmesa.h>

#include <cstdint>
#include <vector>

#include "emu/gl/context.h"

namespace emu::gl {

namespace {

// The default framebuffer's size: only needs to exist (OSMesaMakeCurrent wants a buffer).
constexpr int kBufferSide = 16;

class OSMesaContextImpl final : public Context {
public:
    explicit OSMesaContextImpl(OSMesaContext ctx) : m_ctx(ctx), m_buffer(kBufferSide * kBufferSide, 0) {}
    ~OSMesaContextImpl() override {
        if (OSMesaGetCurrentContext() == m_ctx) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
        OSMesaDestroyContext(m_ctx);
    }

    ContextKind kind() const override { return ContextKind::OSMesa; }
    std::string platform() const override { return "OSMesa"; }
    GlProc getProcAddress(const char* name) const override { return OSMesaGetProcAddress(name); }
    bool makeCurrent() override {
        // The buffer is 4-byte aligned (uint32_t), as OSMesaMakeCurrent requires for RGBA.
        return OSMesaMakeCurrent(m_ctx, m_buffer.data(), GL_UNSIGNED_BYTE, kBufferSide, kBufferSide) == GL_TRUE;
    }
    bool setup(std::string& error) {
        if (!makeCurrent()) {
            error = "OSMesa: OSMesaMakeCurrent failed";
            return false;
        }
        return finishSetup("OSMesa: ", error);
    }

private:
    OSMesaContext m_ctx;
    std::vector<uint32_t> m_buffer;  // RGBA8, bottom row first
};

}  // namespace

std::unique_ptr<Context> createOSMesaContext(std::string& error) {
    // clang-format off
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA,
                           OSMESA_DEPTH_BITS, 0,
                           OSMESA_STENCIL_BITS, 0,
                           OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 3,
                           OSMESA_CONTEXT_MINOR_VERSION, 3,
                           0};
    // clang-format on
    OSMesaContext ctx = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!ctx) {
        error = "OSMesa: OSMesaCreateContextAttribs refused an OpenGL 3.3 core profile context";
        return nullptr;
    }
    auto context = std::make_unique<OSMesaContextImpl>(ctx);
    if (!context->setup(error)) return nullptr;
    return context;
}

}  // namespace emu::gl
