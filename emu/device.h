// The emulated Direct3D 9-style device (docs/device.md): D3D9 names and return codes at the
// edge, plain C++ inside. It has resources (textures, volume textures, render targets,
// depth surfaces, offscreen plain surfaces; Lock/Unlock in D3D's memory layout, mip generation,
// GetRenderTargetData), every state setter, state blocks, pixel shaders, Clear, StretchRect and
// DrawPrimitiveUP (vertex processing, rasteriser, executor, output merger; docs/device.md
// "Drawing").
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>

#include "emu/call_error.h"
#include "emu/d3d9types.h"
#include "emu/resources.h"
#include "emu/software_renderer.h"
#include "emu/state.h"
#include "ps11/hardware.h"
#include "ps11/precision.h"
#include "ps11/texture.h"

namespace emu {

struct DeviceOptions {
    // The emulated GPU (ps11/hardware.h): highest ps_1_x version, profile, MaxValue, signed-texel
    // decode, co-issued cnd, filter weights. Null: the default 1.1-class card.
    const ps11::HardwareClass* hardware = nullptr;
    std::optional<ps11::Precision> precision;  // overrides the class's profile (draws, StretchRect weights)
    float maxValue = 0;                        // overrides the class's PixelShader1xMaxValue (0 = the class's)
    uint64_t maxResourceBytes = kMaxResourceBytes;  // per resource, checked before allocating
    // The software renderer's own options (threads, aligned passes, tile skipping).
    SoftwareRendererOptions software;
    // Another renderer (emu/renderer.h), made when the device is: the GL renderer
    // (emu/gl/gl_renderer.h) comes this way. Empty: the software renderer.
    std::function<std::unique_ptr<Renderer>()> renderer;
};

// What the last call reported. Every call resets it; a failed call sets hr, an E41xx code and
// a message naming the call and the argument.
struct DeviceError {
    HRESULT hr = D3D_OK;
    std::string code;     // "E4101" …, empty on success
    std::string message;  // "E4101 SetTextureStageState: stage 9 out of range 0..7"
};

struct DrawContext;  // emu/device_draw.cpp: the front's lowered fixed-function programs
struct DrawSetup;    // emu/device_draw.cpp: one DrawPrimitiveUP call as its stages resolve it

class Device {
public:
    explicit Device(const DeviceOptions& options = {});
    ~Device();
    Device(const Device&) = delete;
    Device& operator=(const Device&) = delete;

    const DeviceOptions& options() const { return m_options; }
    // The class, profile and MaxValue every draw uses (DeviceOptions resolved).
    const ps11::HardwareConfig& hardware() const { return m_hardware; }
    // Everything the Set* calls have set; a copy is a captured state block (applyState).
    const DeviceState& state() const { return m_state; }
    const DeviceError& lastError() const { return m_error; }

    // ---- resources ----
    // Levels 0 = the full chain. AUTOGENMIPMAP: Levels 0 or 1, the chain is kept hidden and
    // GetLevelCount returns 1 (D3D9).
    HRESULT CreateTexture(UINT width, UINT height, UINT levels, DWORD usage, D3DFORMAT format, D3DPOOL pool,
                          Handle* texture);
    HRESULT CreateVolumeTexture(UINT width, UINT height, UINT depth, UINT levels, DWORD usage, D3DFORMAT format,
                                D3DPOOL pool, Handle* volumeTexture);
    HRESULT CreateRenderTarget(UINT width, UINT height, D3DFORMAT format, BOOL lockable, Handle* surface);
    HRESULT CreateDepthStencilSurface(UINT width, UINT height, D3DFORMAT format, Handle* surface);
    HRESULT CreateOffscreenPlainSurface(UINT width, UINT height, D3DFORMAT format, D3DPOOL pool, Handle* surface);
    // Frees an object. Bindings to it (SetTexture, render target, depth, pixel shader) are reset
    // to NULL; its surface handles die with it.
    HRESULT Release(Handle object);

    // IDirect3DTexture9 / IDirect3DVolumeTexture9: levels, surfaces, locks.
    DWORD GetLevelCount(Handle texture);  // 0 (and an error) for a bad handle
    HRESULT GetLevelDesc(Handle texture, UINT level, D3DSURFACE_DESC* desc);
    HRESULT GetSurfaceLevel(Handle texture, UINT level, Handle* surface);
    HRESULT LockRect(Handle texture, UINT level, D3DLOCKED_RECT* locked, const RECT* rect, DWORD flags);
    HRESULT UnlockRect(Handle texture, UINT level);
    HRESULT LockBox(Handle volumeTexture, UINT level, D3DLOCKED_BOX* locked, const D3DBOX* box, DWORD flags);
    HRESULT UnlockBox(Handle volumeTexture, UINT level);
    // D3D9 regenerates AUTOGENMIPMAP sublevels from level 0; no effect on other textures.
    HRESULT GenerateMipSubLevels(Handle texture);

    // IDirect3DSurface9
    HRESULT GetDesc(Handle surface, D3DSURFACE_DESC* desc);
    HRESULT LockRect(Handle surface, D3DLOCKED_RECT* locked, const RECT* rect, DWORD flags);
    HRESULT UnlockRect(Handle surface);

    // Copies a render target into a SYSTEMMEM surface of the same size and format.
    HRESULT GetRenderTargetData(Handle renderTarget, Handle destSurface);
    // Copies a rectangle between DEFAULT-pool colour surfaces, scaling with POINT or LINEAR
    // filtering (docs/device.md "StretchRect").
    HRESULT StretchRect(Handle source, const RECT* sourceRect, Handle dest, const RECT* destRect,
                        D3DTEXTUREFILTERTYPE filter);
    // Clears the viewport (∩ scissor when enabled ∩ the rects) of the render target, depth and
    // stencil (docs/device.md "Clear").
    HRESULT Clear(DWORD count, const D3DRECT* rects, DWORD flags, D3DCOLOR color, float z, DWORD stencil);

    // ---- state ----
    HRESULT SetTexture(DWORD stage, Handle texture);
    HRESULT GetTexture(DWORD stage, Handle* texture);
    HRESULT SetSamplerState(DWORD sampler, D3DSAMPLERSTATETYPE type, DWORD value);
    HRESULT GetSamplerState(DWORD sampler, D3DSAMPLERSTATETYPE type, DWORD* value);
    // Float states (BUMPENVMAT*, BUMPENVLSCALE/LOFFSET) are passed as their bit pattern.
    HRESULT SetTextureStageState(DWORD stage, D3DTEXTURESTAGESTATETYPE type, DWORD value);
    HRESULT GetTextureStageState(DWORD stage, D3DTEXTURESTAGESTATETYPE type, DWORD* value);
    HRESULT SetRenderState(D3DRENDERSTATETYPE state, DWORD value);
    HRESULT GetRenderState(D3DRENDERSTATETYPE state, DWORD* value);
    // Index 0 only (one render target). Resets the viewport and scissor rect to the whole target.
    HRESULT SetRenderTarget(DWORD index, Handle surface);
    HRESULT GetRenderTarget(DWORD index, Handle* surface);
    HRESULT SetDepthStencilSurface(Handle surface);
    HRESULT GetDepthStencilSurface(Handle* surface);
    HRESULT SetTransform(D3DTRANSFORMSTATETYPE state, const D3DMATRIX* matrix);
    HRESULT GetTransform(D3DTRANSFORMSTATETYPE state, D3DMATRIX* matrix);
    HRESULT SetViewport(const D3DVIEWPORT9* viewport);
    HRESULT GetViewport(D3DVIEWPORT9* viewport);
    HRESULT SetScissorRect(const RECT* rect);
    HRESULT GetScissorRect(RECT* rect);
    HRESULT SetFVF(DWORD fvf);
    // Not D3D9 API: a state block of D3DSBT_ALL as a value (docs/device.md "State blocks").
    // state() captures; applyState sets every field of `state` through its Set* call, with that
    // call's checks. A refused field (a handle released since the capture, a state slot no Set*
    // call takes) changes nothing and names the Set* call and the field in lastError().
    HRESULT applyState(const DeviceState& state);

    // ---- pixel shaders ----
    // Tokens up to and including the end token (D3D9 has no length: the stream is scanned).
    HRESULT CreatePixelShader(const DWORD* function, Handle* shader);
    HRESULT CreatePixelShader(std::span<const DWORD> function, Handle* shader);
    // Convenience: assembles ps_1_x text (preprocessor included) and validates it.
    HRESULT CreatePixelShaderFromText(std::string_view source, Handle* shader);
    HRESULT SetPixelShader(Handle shader);
    HRESULT SetPixelShaderConstantF(UINT startRegister, const float* data, UINT vector4fCount);
    HRESULT GetPixelShaderConstantF(UINT startRegister, float* data, UINT vector4fCount);

    // ---- drawing ----
    // Draws triangle lists, strips and fans from a user pointer with the FVF of SetFVF
    // (docs/device.md "Drawing"). Points and lines: D3DERR_NOTAVAILABLE.
    HRESULT DrawPrimitiveUP(D3DPRIMITIVETYPE type, UINT primitiveCount, const void* vertexData, UINT stride);
    // Statistics of the last successful draw and the running total of all draws.
    const DrawStats& lastDrawStats() const { return m_lastDraw; }
    const DrawStats& totalDrawStats() const { return m_totalDraw; }
    // What has crossed between the front's images and the renderer's copies so far (zero for the
    // software renderer, which keeps none).
    TransferStats transfers() const { return m_renderer->transfers(); }
    // Not D3D9 API: returns when the renderer has finished every call so far (timings).
    void finish() { m_renderer->finish(); }
    // The renderer's name ("software", "gl", "gl-native").
    const char* rendererName() const { return m_renderer->name(); }

    // ---- fingerprints (not D3D9 API; docs/device.md "Fingerprints") ----
    // Between beginFingerprint and endFingerprint the calls that write resources (Clear,
    // StretchRect, DrawPrimitiveUP) are checked but not run: each appends to the fingerprint
    // everything its result depends on — the call and its arguments, the whole state, the
    // vertices, and the contents (handle and generation) of every resource it reads whose
    // contents the fingerprint's earlier calls do not determine. Two fingerprints with equal
    // words, taken where those generations are equal, stand for calls that write the same
    // bytes. A call that hands contents back (locks, GetRenderTargetData, GenerateMipSubLevels)
    // cannot wait: it fails with E4125 and the fingerprint is incomplete. Set* and Create*
    // calls run as always.
    struct Fingerprint {
        bool complete = false;
        std::vector<uint32_t> words;
        std::vector<Handle> writes;  // resources the calls write (owners: a texture, not its level's surface)
    };
    void beginFingerprint();
    Fingerprint endFingerprint();
    bool fingerprinting() const { return m_fingerprint.active; }
    // The version of a resource's contents (a texture's, or a surface's owner's): it changes
    // with every write that changes a byte (docs/device.md "Generations"); 0 for a bad handle.
    uint64_t contentGeneration(Handle resourceOrSurface) const;

    // ---- for the renderers, the glare layer and tests (not D3D9 API) ----
    // The sampler's view of a texture or volume texture, rebuilt after writes (mips regenerated
    // first for AUTOGENMIPMAP); nullptr with lastError() set on failure.
    std::shared_ptr<const ps11::Texture> sampledTexture(Handle texture);
    // The decoded, validated program of a pixel shader; nullptr for a bad handle.
    const ps11::Program* pixelShaderProgram(Handle shader) const;
    // The renderer's worker threads for CPU work between calls (Renderer::workers), or null.
    ThreadPool* rendererWorkers() { return m_renderer->workers(); }
    // A surface's newest bytes where the front keeps them, for reading: D3D9 reads a render
    // target through GetRenderTargetData into a SYSTEMMEM copy, which for a 1080p frame moves
    // 8 MB (32 MB in float) only to look at it. `read` gets the level's pitch and bits; while it
    // runs the level counts as locked, so nothing may write it (a write fails with E4106) and the
    // bytes cannot move. Any surface, lockable or not; refused while fingerprinting (E4125) and
    // for a level already locked (E4106).
    HRESULT readSurface(Handle surface, const std::function<void(const D3DLOCKED_RECT&)>& read);
    // Whether the renderer put the last StretchRect's copy off (SoftwareRendererOptions::putOffCopies):
    // its time then lands on the call that next reads or writes the destination.
    bool lastStretchPutOff() const { return m_lastStretchPutOff; }

private:
    HRESULT fail(HRESULT hr, const char* code, std::string message);
    HRESULT ok();
    Handle newHandle();
    Resource* findResource(Handle h);
    // The surface's image and owner, or null (with lastError set, naming `call` and `what`).
    Image* surfaceImage(Handle h, const char* call, const char* what, Resource** owner, SurfaceRef* ref);
    // The same, or null with `error` set (its message names `what`, not the call); lastError untouched.
    Image* findSurface(Handle h, const char* what, CallError& error, Resource** owner, SurfaceRef* ref);
    // sampledTexture's work, or null with `error` set ("sampledTexture: …"); lastError untouched.
    std::shared_ptr<const ps11::Texture> makeSampled(Handle texture, CallError& error);
    HRESULT checkNewSize(const char* call, UINT width, UINT height, UINT depth, uint32_t maxSide);
    HRESULT createResource(const char* call, Resource&& r, UINT width, UINT height, UINT depth, UINT levels,
                           Handle* out);
    HRESULT lockLevel(const char* call, Handle owner, Resource& r, uint32_t level, const RECT* rect, const D3DBOX* box,
                      DWORD flags, D3DLOCKED_BOX* out);
    HRESULT unlockLevel(const char* call, Resource& r, uint32_t level);
    HRESULT registerShader(const char* call, PixelShaderObject&& shader, Handle* out);
    // AUTOGENMIPMAP: levels 1.. from level 0, in the front's images.
    void regenerateMips(Resource& r);
    // The front wrote a level in its own image; `setsPad`: every texel it wrote has its pad bits
    // set (Resource::padOnes stands), else padOnes is cleared.
    void markWritten(Resource& r, uint32_t level, bool setsPad = false);
    // The renderer wrote a level in its copy (the front's image is stale until syncLevel).
    void rendererWrote(Resource& r, uint32_t level, bool setsPad = false);
    // Called before anything writes a resource's levels (the front, a renderer, a lock): drops
    // the sampler's view and gives the levels a copy if a texture still reads them in place.
    void prepareWrite(Resource& r);
    // Brings the front's image of a level (or of every level) up to date with the renderer's copy.
    void syncLevel(Resource& r, uint32_t level);
    void syncResource(Resource& r);
    // A level as the renderer sees it (emu/renderer.h SurfaceDesc).
    SurfaceDesc surfaceDesc(const SurfaceRef& ref, Resource& r);
    // DrawPrimitiveUP's stages (emu/device_draw.cpp), in the order the call runs them: each
    // resolves its part of `d` (the DrawCall for the renderer) or says why the draw is refused;
    // submit hands the call to the renderer (which may refuse it too).
    std::optional<CallError> checkCall(DrawSetup& d) const;      // arguments, FVF, stride
    std::optional<CallError> resolveTargets(DrawSetup& d);       // render target, depth
    std::optional<CallError> checkRasterStates() const;          // cull, shade and fill modes
    std::optional<CallError> resolveProgram(DrawSetup& d);       // shader or lowered fixed function
    std::optional<CallError> resolveSamplers(DrawSetup& d);      // sampler states, textures
    std::optional<CallError> resolveStages(DrawSetup& d) const;  // texcoord indices, stage states
    std::optional<CallError> resolveMerge(DrawSetup& d) const;   // merge state, clip rect
    void vertices(DrawSetup& d);                                 // vertex processing on demand
    std::optional<CallError> submit(DrawSetup& d, DrawStats& stats);
    // Records a refused draw as lastError ("E41xx DrawPrimitiveUP: …") and returns its HRESULT.
    HRESULT drawFail(const CallError& error);

    // Fingerprints: the owner of a surface handle (or the resource itself); the calls' parts.
    Handle ownerOf(Handle resourceOrSurface) const;
    void fingerprintWords(const void* data, size_t bytes);
    void fingerprintRead(Handle owner);                   // contents not determined yet: handle, generation
    void fingerprintWrite(Handle owner, bool wholeImage);  // wholeImage: the contents are determined from here on
    HRESULT fingerprintRefuse(const char* call);
    struct FingerprintState {
        bool active = false;
        Fingerprint print;
        std::vector<Handle> determined;
    } m_fingerprint;

    DrawStats m_lastDraw, m_totalDraw;
    bool m_lastStretchPutOff = false;
    std::shared_ptr<DrawContext> m_draw;  // created by the first draw
    std::unique_ptr<Renderer> m_renderer;  // draws what the front resolved (emu/renderer.h)

    DeviceOptions m_options;
    ps11::HardwareConfig m_hardware;
    DeviceState m_state;
    DeviceError m_error;
    uint32_t m_nextHandle = 1;
    std::unordered_map<uint32_t, Resource> m_resources;
    std::unordered_map<uint32_t, SurfaceRef> m_surfaces;
    std::unordered_map<uint32_t, PixelShaderObject> m_shaders;
};

}  // namespace emu
