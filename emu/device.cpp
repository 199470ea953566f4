// Device stage: the API edge for state and shaders. Error reporting (E41xx codes, D3D9 return
// values), handles, every Set*/Get* state call, state blocks (applyState), pixel shader creation
// through ps11's decoder, assembler and validator.
#include "emu/device.h"

#include <cmath>
#include <cstring>

#include "ps11/assembler.h"
#include "ps11/decoder.h"
#include "ps11/diagnostics.h"
#include "ps11/validator.h"

namespace emu {

namespace {

std::string num(uint64_t v) { return std::to_string(v); }

constexpr DWORD kEndToken = 0x0000FFFF;
constexpr DWORD kCommentOpcode = 0xFFFE;
constexpr size_t kMaxShaderTokens = 1u << 16;

}  // namespace

Device::Device(const DeviceOptions& options) : m_options(options) {
    if (m_options.maxResourceBytes == 0 || m_options.maxResourceBytes > kMaxResourceBytes)
        m_options.maxResourceBytes = kMaxResourceBytes;
    m_hardware = ps11::resolveHardware(m_options.hardware, 1, m_options.precision, m_options.maxValue);
    if (m_options.renderer) m_renderer = m_options.renderer();
    if (!m_renderer) m_renderer = std::make_unique<SoftwareRenderer>(m_options.software);
}

Device::~Device() = default;

HRESULT Device::fail(HRESULT hr, const char* code, std::string message) {
    m_error.hr = hr;
    m_error.code = code;
    m_error.message = std::string(code) + " " + message;
    return hr;
}

HRESULT Device::ok() {
    // Every call starts here: only an error left by the last call is cleared.
    if (m_error.hr != D3D_OK || !m_error.code.empty() || !m_error.message.empty()) m_error = DeviceError{};
    return D3D_OK;
}

Handle Device::newHandle() { return Handle(m_nextHandle++); }

Resource* Device::findResource(Handle h) {
    auto it = m_resources.find(uint32_t(h));
    return it == m_resources.end() ? nullptr : &it->second;
}

// ---- states ----

HRESULT Device::SetTexture(DWORD stage, Handle texture) {
    ok();
    if (stage >= DWORD(kMaxSamplers))
        return fail(D3DERR_INVALIDCALL, "E4101", "SetTexture: stage " + num(stage) + " out of range 0..7");
    if (texture != Handle::Null) {
        Resource* r = findResource(texture);
        if (!r)
            return fail(D3DERR_INVALIDCALL, "E4102",
                        "SetTexture: handle " + num(uint32_t(texture)) + " is not an object of this device");
        if (r->kind == ResourceKind::Surface)
            return fail(D3DERR_INVALIDCALL, "E4102",
                        "SetTexture: handle " + num(uint32_t(texture)) + " is a surface, not a texture");
        // D3D9 refuses SCRATCH resources for the pipeline (D3DPOOL reference page).
        if (r->pool == D3DPOOL_SCRATCH)
            return fail(
                D3DERR_INVALIDCALL, "E4112",
                "SetTexture: texture " + num(uint32_t(texture)) + " is in D3DPOOL_SCRATCH, which cannot be bound");
    }
    m_state.textures[stage] = texture;
    return D3D_OK;
}

HRESULT Device::GetTexture(DWORD stage, Handle* texture) {
    ok();
    if (!texture) return fail(D3DERR_INVALIDCALL, "E4103", "GetTexture: texture pointer is null");
    if (stage >= DWORD(kMaxSamplers))
        return fail(D3DERR_INVALIDCALL, "E4101", "GetTexture: stage " + num(stage) + " out of range 0..7");
    *texture = m_state.textures[stage];
    return D3D_OK;
}

HRESULT Device::SetSamplerState(DWORD sampler, D3DSAMPLERSTATETYPE type, DWORD value) {
    ok();
    if (sampler >= DWORD(kMaxSamplers))
        return fail(D3DERR_INVALIDCALL, "E4101", "SetSamplerState: sampler " + num(sampler) + " out of range 0..7");
    if (!isSamplerState(type))
        return fail(D3DERR_INVALIDCALL, "E4101", "SetSamplerState: unknown sampler state " + num(DWORD(type)));
    // Values are stored as given, as D3D9 does; draws check them (ValidateDevice-style).
    m_state.samplerStates[sampler][type] = value;
    return D3D_OK;
}

HRESULT Device::GetSamplerState(DWORD sampler, D3DSAMPLERSTATETYPE type, DWORD* value) {
    ok();
    if (!value) return fail(D3DERR_INVALIDCALL, "E4103", "GetSamplerState: value pointer is null");
    if (sampler >= DWORD(kMaxSamplers))
        return fail(D3DERR_INVALIDCALL, "E4101", "GetSamplerState: sampler " + num(sampler) + " out of range 0..7");
    if (!isSamplerState(type))
        return fail(D3DERR_INVALIDCALL, "E4101", "GetSamplerState: unknown sampler state " + num(DWORD(type)));
    *value = m_state.samplerStates[sampler][type];
    return D3D_OK;
}

HRESULT Device::SetTextureStageState(DWORD stage, D3DTEXTURESTAGESTATETYPE type, DWORD value) {
    ok();
    if (stage >= DWORD(kMaxStages))
        return fail(D3DERR_INVALIDCALL, "E4101", "SetTextureStageState: stage " + num(stage) + " out of range 0..7");
    if (!isStageState(type))
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "SetTextureStageState: unknown texture stage state " + num(DWORD(type)));
    m_state.stageStates[stage][type] = value;
    return D3D_OK;
}

HRESULT Device::GetTextureStageState(DWORD stage, D3DTEXTURESTAGESTATETYPE type, DWORD* value) {
    ok();
    if (!value) return fail(D3DERR_INVALIDCALL, "E4103", "GetTextureStageState: value pointer is null");
    if (stage >= DWORD(kMaxStages))
        return fail(D3DERR_INVALIDCALL, "E4101", "GetTextureStageState: stage " + num(stage) + " out of range 0..7");
    if (!isStageState(type))
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "GetTextureStageState: unknown texture stage state " + num(DWORD(type)));
    *value = m_state.stageStates[stage][type];
    return D3D_OK;
}

HRESULT Device::SetRenderState(D3DRENDERSTATETYPE state, DWORD value) {
    ok();
    if (!isRenderState(state))
        return fail(D3DERR_INVALIDCALL, "E4101", "SetRenderState: unknown render state " + num(DWORD(state)));
    m_state.renderStates[state] = value;
    return D3D_OK;
}

HRESULT Device::GetRenderState(D3DRENDERSTATETYPE state, DWORD* value) {
    ok();
    if (!value) return fail(D3DERR_INVALIDCALL, "E4103", "GetRenderState: value pointer is null");
    if (!isRenderState(state))
        return fail(D3DERR_INVALIDCALL, "E4101", "GetRenderState: unknown render state " + num(DWORD(state)));
    *value = m_state.renderStates[state];
    return D3D_OK;
}

HRESULT Device::SetRenderTarget(DWORD index, Handle surface) {
    ok();
    // ps 1.x-class hardware: D3DCAPS9 NumSimultaneousRTs = 1.
    if (index != 0)
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "SetRenderTarget: index " + num(index) + " out of range 0..0 (one render target)");
    // D3D9: render target 0 cannot be NULL.
    if (surface == Handle::Null)
        return fail(D3DERR_INVALIDCALL, "E4103", "SetRenderTarget: render target 0 cannot be NULL");
    Resource* owner = nullptr;
    Image* im = surfaceImage(surface, "SetRenderTarget", "surface", &owner, nullptr);
    if (!im) return m_error.hr;
    if (!owner->isRenderTarget())
        return fail(
            D3DERR_INVALIDCALL, "E4104",
            "SetRenderTarget: surface " + num(uint32_t(surface)) + " was not created with D3DUSAGE_RENDERTARGET");
    m_state.renderTarget = surface;
    // D3D9 SetRenderTarget: the viewport and the scissor rect become the whole new target.
    m_state.viewport = D3DVIEWPORT9{0, 0, im->width, im->height, 0.0f, 1.0f};
    m_state.scissor = RECT{0, 0, LONG(im->width), LONG(im->height)};
    return D3D_OK;
}

HRESULT Device::GetRenderTarget(DWORD index, Handle* surface) {
    ok();
    if (!surface) return fail(D3DERR_INVALIDCALL, "E4103", "GetRenderTarget: surface pointer is null");
    if (index != 0)
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "GetRenderTarget: index " + num(index) + " out of range 0..0 (one render target)");
    // D3D9 returns D3DERR_NOTFOUND when no render target is set.
    if (m_state.renderTarget == Handle::Null)
        return fail(D3DERR_NOTFOUND, "E4109", "GetRenderTarget: no render target is set");
    *surface = m_state.renderTarget;
    return D3D_OK;
}

HRESULT Device::SetDepthStencilSurface(Handle surface) {
    ok();
    if (surface != Handle::Null) {
        Resource* owner = nullptr;
        if (!surfaceImage(surface, "SetDepthStencilSurface", "surface", &owner, nullptr)) return m_error.hr;
        if (!owner->isDepthStencil())
            return fail(
                D3DERR_INVALIDCALL, "E4104",
                "SetDepthStencilSurface: surface " + num(uint32_t(surface)) + " is not a depth stencil surface");
    }
    m_state.depthStencil = surface;
    return D3D_OK;
}

HRESULT Device::GetDepthStencilSurface(Handle* surface) {
    ok();
    if (!surface) return fail(D3DERR_INVALIDCALL, "E4103", "GetDepthStencilSurface: surface pointer is null");
    if (m_state.depthStencil == Handle::Null)
        return fail(D3DERR_NOTFOUND, "E4109", "GetDepthStencilSurface: no depth stencil surface is set");
    *surface = m_state.depthStencil;
    return D3D_OK;
}

namespace {
D3DMATRIX* transformSlot(DeviceState& s, DWORD t) {
    if (t == D3DTS_VIEW) return &s.view;
    if (t == D3DTS_PROJECTION) return &s.projection;
    if (t >= D3DTS_TEXTURE0 && t <= D3DTS_TEXTURE7) return &s.texture[t - D3DTS_TEXTURE0];
    if (t == D3DTS_WORLD) return &s.world;
    return nullptr;
}
}  // namespace

HRESULT Device::SetTransform(D3DTRANSFORMSTATETYPE state, const D3DMATRIX* matrix) {
    ok();
    if (!matrix) return fail(D3DERR_INVALIDCALL, "E4103", "SetTransform: matrix pointer is null");
    D3DMATRIX* slot = transformSlot(m_state, state);
    if (!slot)
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "SetTransform: transform " + num(DWORD(state)) +
                        " not taken (VIEW 2, PROJECTION 3, TEXTURE0..7 16..23, WORLD 256; no vertex blending)");
    *slot = *matrix;
    return D3D_OK;
}

HRESULT Device::GetTransform(D3DTRANSFORMSTATETYPE state, D3DMATRIX* matrix) {
    ok();
    if (!matrix) return fail(D3DERR_INVALIDCALL, "E4103", "GetTransform: matrix pointer is null");
    D3DMATRIX* slot = transformSlot(m_state, state);
    if (!slot) return fail(D3DERR_INVALIDCALL, "E4101", "GetTransform: transform " + num(DWORD(state)) + " not taken");
    *matrix = *slot;
    return D3D_OK;
}

HRESULT Device::SetViewport(const D3DVIEWPORT9* vp) {
    ok();
    if (!vp) return fail(D3DERR_INVALIDCALL, "E4103", "SetViewport: viewport pointer is null");
    if (m_state.renderTarget == Handle::Null)
        return fail(D3DERR_INVALIDCALL, "E4109", "SetViewport: no render target is set");
    Image* rt = surfaceImage(m_state.renderTarget, "SetViewport", "render target", nullptr, nullptr);
    if (!rt) return m_error.hr;
    // D3D9 returns D3DERR_INVALIDCALL for a viewport outside the render target.
    if (uint64_t(vp->X) + vp->Width > rt->width || uint64_t(vp->Y) + vp->Height > rt->height)
        return fail(D3DERR_INVALIDCALL, "E4105",
                    "SetViewport: viewport (" + num(vp->X) + ", " + num(vp->Y) + ") " + num(vp->Width) + "x" +
                        num(vp->Height) + " is outside the " + num(rt->width) + "x" + num(rt->height) +
                        " render target");
    if (!std::isfinite(vp->MinZ) || !std::isfinite(vp->MaxZ) || vp->MinZ < 0.0f || vp->MaxZ > 1.0f ||
        vp->MinZ > vp->MaxZ)
        return fail(D3DERR_INVALIDCALL, "E4105",
                    "SetViewport: MinZ " + std::to_string(vp->MinZ) + ", MaxZ " + std::to_string(vp->MaxZ) +
                        " must satisfy 0 <= MinZ <= MaxZ <= 1");
    m_state.viewport = *vp;
    return D3D_OK;
}

HRESULT Device::GetViewport(D3DVIEWPORT9* vp) {
    ok();
    if (!vp) return fail(D3DERR_INVALIDCALL, "E4103", "GetViewport: viewport pointer is null");
    *vp = m_state.viewport;
    return D3D_OK;
}

HRESULT Device::SetScissorRect(const RECT* rect) {
    ok();
    if (!rect) return fail(D3DERR_INVALIDCALL, "E4103", "SetScissorRect: rect pointer is null");
    // Stored as given (D3D9 does); it is intersected with the target where it is used.
    m_state.scissor = *rect;
    return D3D_OK;
}

HRESULT Device::GetScissorRect(RECT* rect) {
    ok();
    if (!rect) return fail(D3DERR_INVALIDCALL, "E4103", "GetScissorRect: rect pointer is null");
    *rect = m_state.scissor;
    return D3D_OK;
}

HRESULT Device::SetFVF(DWORD fvf) {
    ok();
    m_state.fvf = fvf;
    return D3D_OK;
}

// ---- state blocks ----

// Every field that differs from the device's goes through its Set* call, so a block is checked
// exactly as the calls are (a slot with no D3D9 state then reaches its Set* call, which refuses
// it; an equal value would pass and change nothing). The render target comes first:
// SetRenderTarget resets the viewport and scissor rect, which follow.
HRESULT Device::applyState(const DeviceState& s) {
    const DeviceState before = m_state;
    std::string field;  // which field of the block the refused call was setting
    auto refused = [&](HRESULT hr, std::string what) {
        if (hr == D3D_OK) return false;
        field = std::move(what);
        return true;
    };
    bool failed = false;
    if (s.renderTarget != Handle::Null) {
        failed = refused(SetRenderTarget(0, s.renderTarget), "render target") ||
                 refused(SetViewport(&s.viewport), "viewport");
    } else {
        // A fresh device's NULL render target (SetRenderTarget refuses NULL); with no target to
        // check it against, the viewport is kept as given.
        m_state.renderTarget = Handle::Null;
        m_state.viewport = s.viewport;
    }
    // A value equal to the current one is not set again: every setter below only validates and
    // stores, and a current handle is a live one (Release unbinds it). A pass graph puts its
    // state back around every pass, so this is most of a still frame's work.
    auto same = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof a) == 0; };
    failed = failed || (!same(s.scissor, m_state.scissor) && refused(SetScissorRect(&s.scissor), "scissor rect")) ||
             (s.depthStencil != m_state.depthStencil &&
              refused(SetDepthStencilSurface(s.depthStencil), "depth stencil surface")) ||
             (s.pixelShader != m_state.pixelShader && refused(SetPixelShader(s.pixelShader), "pixel shader"));
    for (DWORD stage = 0; !failed && stage < DWORD(kMaxSamplers); ++stage)
        if (s.textures[stage] != m_state.textures[stage])
            failed = refused(SetTexture(stage, s.textures[stage]), "texture of stage " + num(stage));
    // The state arrays slot by slot only where they differ at all (a pass changes a few slots).
    if (!failed && !same(s.renderStates, m_state.renderStates))
        for (DWORD i = 0; !failed && i < DWORD(kRenderStateLimit); ++i)
            if (s.renderStates[i] != m_state.renderStates[i])
                failed = refused(SetRenderState(D3DRENDERSTATETYPE(i), s.renderStates[i]), "");
    for (DWORD stage = 0; !failed && stage < DWORD(kMaxStages); ++stage)
        if (!same(s.stageStates[stage], m_state.stageStates[stage]))
            for (DWORD i = 0; !failed && i < DWORD(kStageStateLimit); ++i)
                if (s.stageStates[stage][i] != m_state.stageStates[stage][i])
                    failed = refused(SetTextureStageState(stage, D3DTEXTURESTAGESTATETYPE(i), s.stageStates[stage][i]),
                                     "stage " + num(stage));
    for (DWORD sampler = 0; !failed && sampler < DWORD(kMaxSamplers); ++sampler)
        if (!same(s.samplerStates[sampler], m_state.samplerStates[sampler]))
            for (DWORD i = 0; !failed && i < DWORD(kSamplerStateLimit); ++i)
                if (s.samplerStates[sampler][i] != m_state.samplerStates[sampler][i])
                    failed = refused(SetSamplerState(sampler, D3DSAMPLERSTATETYPE(i), s.samplerStates[sampler][i]),
                                     "sampler " + num(sampler));
    const std::pair<D3DTRANSFORMSTATETYPE, const D3DMATRIX*> transforms[] = {
        {D3DTS_WORLD, &s.world}, {D3DTS_VIEW, &s.view}, {D3DTS_PROJECTION, &s.projection}};
    const D3DMATRIX* current[] = {&m_state.world, &m_state.view, &m_state.projection};
    for (size_t k = 0; k < 3; ++k)
        failed = failed || (!same(*transforms[k].second, *current[k]) &&
                            refused(SetTransform(transforms[k].first, transforms[k].second), ""));
    for (DWORD t = 0; !failed && t < DWORD(s.texture.size()); ++t)
        if (!same(s.texture[t], m_state.texture[t]))
            failed = refused(SetTransform(D3DTRANSFORMSTATETYPE(D3DTS_TEXTURE0 + t), &s.texture[t]), "");
    for (UINT c = 0; !failed && c < UINT(kMaxPsConstants); ++c)
        if (!same(s.psConstants[c], m_state.psConstants[c]))
            failed = refused(SetPixelShaderConstantF(c, s.psConstants[c].data(), 1), "");
    failed = failed || (s.fvf != m_state.fvf && refused(SetFVF(s.fvf), ""));
    if (!failed) return ok();
    // Atomic, as every call is: a refused block changes nothing.
    const DeviceError error = m_error;
    m_state = before;
    return fail(error.hr, error.code.c_str(),
                "applyState: " + error.message.substr(error.code.size() + 1) +
                    (field.empty() ? "" : " (the block's " + field + ")"));
}

// ---- pixel shaders ----

HRESULT Device::CreatePixelShader(const DWORD* function, Handle* shader) {
    ok();
    if (!function) return fail(D3DERR_INVALIDCALL, "E4103", "CreatePixelShader: function pointer is null");
    if (!shader) return fail(D3DERR_INVALIDCALL, "E4103", "CreatePixelShader: shader pointer is null");
    // D3D9 passes no length: scan to the end token, skipping comment payloads.
    size_t n = 1;
    for (;;) {
        if (n >= kMaxShaderTokens)
            return fail(D3DERR_INVALIDCALL, "E4107",
                        "CreatePixelShader: no end token (0x0000ffff) within " + num(kMaxShaderTokens) + " tokens");
        const DWORD t = function[n];
        if (t == kEndToken) {
            ++n;
            break;
        }
        n += (t & 0xFFFF) == kCommentOpcode ? 1 + ((t >> 16) & 0x7FFF) : 1;
    }
    return CreatePixelShader(std::span<const DWORD>(function, n), shader);
}

HRESULT Device::CreatePixelShader(std::span<const DWORD> function, Handle* shader) {
    ok();
    if (!shader) return fail(D3DERR_INVALIDCALL, "E4103", "CreatePixelShader: shader pointer is null");
    if (function.empty()) return fail(D3DERR_INVALIDCALL, "E4107", "CreatePixelShader: no tokens");
    const DWORD version = function[0];
    const DWORD major = (version >> 8) & 0xFF, minor = version & 0xFF;
    if ((version & 0xFFFF0000u) != 0xFFFF0000u) {
        char hex[16];
        std::snprintf(hex, sizeof hex, "0x%08x", unsigned(version));
        return fail(
            D3DERR_INVALIDCALL, "E4107",
            std::string("CreatePixelShader: version token ") + hex +
                ((version & 0xFFFF0000u) == 0xFFFE0000u ? " is a vertex shader" : " is not a pixel shader version"));
    }
    // D3DCAPS9::PixelShaderVersion is the hardware class's: 1.1, 1.3 or 1.4.
    const ps11::HardwareClass& hw = *m_hardware.hardware;
    if (major != 1 || minor < 1 || minor > DWORD(hw.maxMinor))
        return fail(D3DERR_INVALIDCALL, "E4107",
                    "CreatePixelShader: version ps_" + num(major) + "_" + num(minor) + " not taken (hardware " +
                        std::string(hw.name) + " runs ps_1_1 ... ps_1_" + num(uint32_t(hw.maxMinor)) + ")");
    ps11::Diagnostics diags;
    const uint32_t file = diags.addFile("CreatePixelShader");
    std::optional<ps11::Program> program = ps11::decode(function, file, diags);
    if (program) ps11::validate(*program, diags);
    if (!program || diags.hasErrors()) {
        std::string first;
        for (const ps11::Diagnostic& d : diags.all())
            if (d.severity == ps11::Severity::Error) {
                first = diags.format(d);
                break;
            }
        return fail(D3DERR_INVALIDCALL, "E4107", "CreatePixelShader: the shader is invalid: " + first);
    }
    PixelShaderObject obj;
    obj.program = std::move(*program);
    obj.tokens.assign(function.begin(), function.end());
    return registerShader("CreatePixelShader", std::move(obj), shader);
}

HRESULT Device::CreatePixelShaderFromText(std::string_view source, Handle* shader) {
    ok();
    if (!shader) return fail(D3DERR_INVALIDCALL, "E4103", "CreatePixelShaderFromText: shader pointer is null");
    ps11::Diagnostics diags;
    std::optional<ps11::Program> program = ps11::parseAssembly(source, "CreatePixelShaderFromText", {}, diags);
    if (program) ps11::validate(*program, diags);
    const ps11::HardwareClass& hw = *m_hardware.hardware;
    if (program && !diags.hasErrors() && program->version.minor > hw.maxMinor)
        return fail(D3DERR_INVALIDCALL, "E4107",
                    "CreatePixelShaderFromText: version ps_1_" + num(uint32_t(program->version.minor)) +
                        " not taken (hardware " + std::string(hw.name) + " runs ps_1_1 ... ps_1_" +
                        num(uint32_t(hw.maxMinor)) + ")");
    if (!program || diags.hasErrors()) {
        std::string first;
        for (const ps11::Diagnostic& d : diags.all())
            if (d.severity == ps11::Severity::Error) {
                first = diags.format(d);
                break;
            }
        return fail(D3DERR_INVALIDCALL, "E4107", "CreatePixelShaderFromText: the shader is invalid: " + first);
    }
    PixelShaderObject obj;
    obj.program = std::move(*program);
    return registerShader("CreatePixelShaderFromText", std::move(obj), shader);
}

HRESULT Device::registerShader(const char* call, PixelShaderObject&& shader, Handle* out) {
    try {
        const Handle h = newHandle();
        m_shaders.emplace(uint32_t(h), std::move(shader));
        *out = h;
    } catch (const std::bad_alloc&) {
        return fail(E_OUTOFMEMORY, "E4111", std::string(call) + ": out of memory");
    }
    return ok();
}

HRESULT Device::SetPixelShader(Handle shader) {
    ok();
    if (shader != Handle::Null && !m_shaders.count(uint32_t(shader)))
        return fail(D3DERR_INVALIDCALL, "E4102",
                    "SetPixelShader: handle " + num(uint32_t(shader)) + " is not a pixel shader of this device");
    m_state.pixelShader = shader;
    return D3D_OK;
}

HRESULT Device::SetPixelShaderConstantF(UINT start, const float* data, UINT count) {
    ok();
    if (uint64_t(start) + count > uint64_t(kMaxPsConstants))
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "SetPixelShaderConstantF: registers c" + num(start) + " + " + num(count) +
                        " beyond c7 (ps 1.x has c0..c7)");
    if (!data && count > 0) return fail(D3DERR_INVALIDCALL, "E4103", "SetPixelShaderConstantF: data pointer is null");
    // Stored unclamped; the executor clamps to [-1, 1] on load (docs/precision.md "Inputs").
    for (UINT i = 0; i < count; ++i)
        for (size_t c = 0; c < 4; ++c) m_state.psConstants[start + i][c] = data[4 * i + c];
    return D3D_OK;
}

HRESULT Device::GetPixelShaderConstantF(UINT start, float* data, UINT count) {
    ok();
    if (uint64_t(start) + count > uint64_t(kMaxPsConstants))
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "GetPixelShaderConstantF: registers c" + num(start) + " + " + num(count) +
                        " beyond c7 (ps 1.x has c0..c7)");
    if (!data && count > 0) return fail(D3DERR_INVALIDCALL, "E4103", "GetPixelShaderConstantF: data pointer is null");
    for (UINT i = 0; i < count; ++i)
        for (size_t c = 0; c < 4; ++c) data[4 * i + c] = m_state.psConstants[start + i][c];
    return D3D_OK;
}

const ps11::Program* Device::pixelShaderProgram(Handle shader) const {
    auto it = m_shaders.find(uint32_t(shader));
    return it == m_shaders.end() ? nullptr : &it->second.program;
}

}  // namespace emu
