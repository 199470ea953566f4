// Device stage: resource calls. CreateTexture / CreateVolumeTexture / CreateRenderTarget /
// CreateDepthStencilSurface / CreateOffscreenPlainSurface with D3D9's usage, pool and format
// rules, sizes refused before allocating, surfaces of levels, LockRect/LockBox in D3D's memory
// layout, automatic mip generation and the sampler's view of a texture.
#include <algorithm>
#include <cstring>
#include <new>

#include "emu/device.h"

namespace emu {

namespace {

std::string num(uint64_t v) { return std::to_string(v); }
std::string handleText(Handle h) { return num(uint32_t(h)); }

constexpr DWORD kKnownUsage = D3DUSAGE_RENDERTARGET | D3DUSAGE_DEPTHSTENCIL | D3DUSAGE_WRITEONLY |
                              0x10 /* SOFTWAREPROCESSING */ | D3DUSAGE_DYNAMIC | D3DUSAGE_AUTOGENMIPMAP;

}  // namespace

HRESULT Device::checkNewSize(const char* call, UINT width, UINT height, UINT depth, uint32_t maxSide) {
    if (width == 0 || height == 0 || depth == 0)
        return fail(D3DERR_INVALIDCALL, "E4105",
                    std::string(call) + ": size " + num(width) + "x" + num(height) +
                        (depth != 1 ? "x" + num(depth) : "") + " has a zero side");
    if (width > maxSide || height > maxSide || depth > maxSide)
        return fail(D3DERR_INVALIDCALL, "E4105",
                    std::string(call) + ": size " + num(width) + "x" + num(height) +
                        (depth != 1 ? "x" + num(depth) : "") + " beyond " + num(maxSide) + " per side");
    return D3D_OK;
}

HRESULT Device::createResource(const char* call, Resource&& r, UINT width, UINT height, UINT depth, UINT levels,
                               Handle* out) {
    const uint64_t bytes = resourceBytes(*r.format, width, height, depth, levels);
    if (bytes > m_options.maxResourceBytes)
        return fail(D3DERR_OUTOFVIDEOMEMORY, "E4105",
                    std::string(call) + ": " + num(bytes) + " bytes of " + r.format->name + " beyond the limit of " +
                        num(m_options.maxResourceBytes) + " per resource");
    try {
        allocateLevels(r, width, height, depth, levels);
        if (r.kind != ResourceKind::Surface) r.surfaces.assign(r.exposedLevels, Handle::Null);
        const Handle h = newHandle();
        r.handle = h;
        if (r.kind == ResourceKind::Surface) m_surfaces.emplace(uint32_t(h), SurfaceRef{h, 0});
        m_resources.emplace(uint32_t(h), std::move(r));
        *out = h;
    } catch (const std::bad_alloc&) {
        return fail(E_OUTOFMEMORY, "E4111", std::string(call) + ": out of memory for " + num(bytes) + " bytes");
    }
    return ok();
}

HRESULT Device::CreateTexture(UINT width, UINT height, UINT levels, DWORD usage, D3DFORMAT format, D3DPOOL pool,
                              Handle* texture) {
    ok();
    const char* call = "CreateTexture";
    if (!texture) return fail(D3DERR_INVALIDCALL, "E4103", "CreateTexture: texture pointer is null");
    if (checkNewSize(call, width, height, 1, kMaxTextureSide) != D3D_OK) return m_error.hr;
    const FormatInfo* f = formatInfo(format);
    if (!f || !f->texture)
        return fail(D3DERR_INVALIDCALL, "E4104",
                    std::string("CreateTexture: format ") + formatName(format) + " not taken for textures");
    if (usage & ~kKnownUsage)
        return fail(D3DERR_INVALIDCALL, "E4112", "CreateTexture: unknown usage bits " + num(usage & ~kKnownUsage));
    if (pool > D3DPOOL_SCRATCH) return fail(D3DERR_INVALIDCALL, "E4112", "CreateTexture: unknown pool " + num(pool));
    if (usage & D3DUSAGE_DEPTHSTENCIL)
        return fail(D3DERR_INVALIDCALL, "E4104", "CreateTexture: depth textures are not supported");
    if ((usage & D3DUSAGE_RENDERTARGET) && !f->renderTarget)
        return fail(D3DERR_INVALIDCALL, "E4104",
                    std::string("CreateTexture: format ") + f->name + " cannot be a render target (" +
                        renderTargetFormatList() + ")");
    // D3D9: render targets and DYNAMIC resources live in D3DPOOL_DEFAULT; DYNAMIC and MANAGED
    // exclude each other; AUTOGENMIPMAP is not allowed in SYSTEMMEM (D3DUSAGE reference page).
    if ((usage & D3DUSAGE_RENDERTARGET) && pool != D3DPOOL_DEFAULT)
        return fail(D3DERR_INVALIDCALL, "E4112", "CreateTexture: D3DUSAGE_RENDERTARGET needs D3DPOOL_DEFAULT");
    if ((usage & D3DUSAGE_DYNAMIC) && (usage & D3DUSAGE_RENDERTARGET))
        return fail(D3DERR_INVALIDCALL, "E4112",
                    "CreateTexture: D3DUSAGE_DYNAMIC and D3DUSAGE_RENDERTARGET exclude each other");
    if ((usage & D3DUSAGE_DYNAMIC) && pool == D3DPOOL_MANAGED)
        return fail(D3DERR_INVALIDCALL, "E4112", "CreateTexture: D3DUSAGE_DYNAMIC cannot be used with D3DPOOL_MANAGED");
    const uint32_t full = ps11::fullMipCount(width, height, 1);
    Resource r;
    r.kind = ResourceKind::Texture;
    r.format = f;
    r.usage = usage;
    r.pool = pool;
    // D3D9 locks: every pool except DEFAULT, and DEFAULT only with DYNAMIC.
    r.lockable = pool != D3DPOOL_DEFAULT || (usage & D3DUSAGE_DYNAMIC);
    uint32_t count = levels == 0 ? full : levels;
    if (usage & D3DUSAGE_AUTOGENMIPMAP) {
        if (pool == D3DPOOL_SYSTEMMEM || pool == D3DPOOL_SCRATCH)
            return fail(D3DERR_INVALIDCALL, "E4112",
                        "CreateTexture: D3DUSAGE_AUTOGENMIPMAP needs D3DPOOL_DEFAULT or MANAGED");
        if (levels > 1)
            return fail(D3DERR_INVALIDCALL, "E4105",
                        "CreateTexture: D3DUSAGE_AUTOGENMIPMAP takes Levels 0 or 1, not " + num(levels));
        count = full;
        r.exposedLevels = 1;
    } else {
        if (count > full)
            return fail(D3DERR_INVALIDCALL, "E4105",
                        "CreateTexture: " + num(levels) + " levels, a " + num(width) + "x" + num(height) +
                            " texture has at most " + num(full));
        r.exposedLevels = count;
    }
    return createResource(call, std::move(r), width, height, 1, count, texture);
}

HRESULT Device::CreateVolumeTexture(UINT width, UINT height, UINT depth, UINT levels, DWORD usage, D3DFORMAT format,
                                    D3DPOOL pool, Handle* volumeTexture) {
    ok();
    const char* call = "CreateVolumeTexture";
    if (!volumeTexture) return fail(D3DERR_INVALIDCALL, "E4103", "CreateVolumeTexture: texture pointer is null");
    if (checkNewSize(call, width, height, depth, kMaxVolumeSide) != D3D_OK) return m_error.hr;
    const FormatInfo* f = formatInfo(format);
    if (!f || !f->texture)
        return fail(
            D3DERR_INVALIDCALL, "E4104",
            std::string("CreateVolumeTexture: format ") + formatName(format) + " not taken for volume textures");
    if (usage & ~kKnownUsage)
        return fail(D3DERR_INVALIDCALL, "E4112",
                    "CreateVolumeTexture: unknown usage bits " + num(usage & ~kKnownUsage));
    if (pool > D3DPOOL_SCRATCH)
        return fail(D3DERR_INVALIDCALL, "E4112", "CreateVolumeTexture: unknown pool " + num(pool));
    // D3D9 volume textures cannot be render targets or depth buffers, nor generate their mips.
    if (usage & (D3DUSAGE_RENDERTARGET | D3DUSAGE_DEPTHSTENCIL | D3DUSAGE_AUTOGENMIPMAP))
        return fail(D3DERR_INVALIDCALL, "E4112",
                    "CreateVolumeTexture: usage " + num(usage) +
                        " not allowed (no RENDERTARGET, DEPTHSTENCIL or AUTOGENMIPMAP for volumes)");
    if ((usage & D3DUSAGE_DYNAMIC) && pool == D3DPOOL_MANAGED)
        return fail(D3DERR_INVALIDCALL, "E4112",
                    "CreateVolumeTexture: D3DUSAGE_DYNAMIC cannot be used with D3DPOOL_MANAGED");
    const uint32_t full = ps11::fullMipCount(width, height, depth);
    const uint32_t count = levels == 0 ? full : levels;
    if (count > full)
        return fail(D3DERR_INVALIDCALL, "E4105",
                    "CreateVolumeTexture: " + num(levels) + " levels, the volume has at most " + num(full));
    Resource r;
    r.kind = ResourceKind::VolumeTexture;
    r.format = f;
    r.usage = usage;
    r.pool = pool;
    r.lockable = pool != D3DPOOL_DEFAULT || (usage & D3DUSAGE_DYNAMIC);
    r.exposedLevels = count;
    return createResource(call, std::move(r), width, height, depth, count, volumeTexture);
}

HRESULT Device::CreateRenderTarget(UINT width, UINT height, D3DFORMAT format, BOOL lockable, Handle* surface) {
    ok();
    const char* call = "CreateRenderTarget";
    if (!surface) return fail(D3DERR_INVALIDCALL, "E4103", "CreateRenderTarget: surface pointer is null");
    if (checkNewSize(call, width, height, 1, kMaxTextureSide) != D3D_OK) return m_error.hr;
    const FormatInfo* f = formatInfo(format);
    if (!f || !f->renderTarget)
        return fail(D3DERR_INVALIDCALL, "E4104",
                    std::string("CreateRenderTarget: format ") + formatName(format) + " cannot be a render target (" +
                        renderTargetFormatList() + ")");
    Resource r;
    r.kind = ResourceKind::Surface;
    r.format = f;
    r.usage = D3DUSAGE_RENDERTARGET;
    r.pool = D3DPOOL_DEFAULT;
    r.lockable = lockable != 0;
    return createResource(call, std::move(r), width, height, 1, 1, surface);
}

HRESULT Device::CreateDepthStencilSurface(UINT width, UINT height, D3DFORMAT format, Handle* surface) {
    ok();
    const char* call = "CreateDepthStencilSurface";
    if (!surface) return fail(D3DERR_INVALIDCALL, "E4103", "CreateDepthStencilSurface: surface pointer is null");
    if (checkNewSize(call, width, height, 1, kMaxTextureSide) != D3D_OK) return m_error.hr;
    const FormatInfo* f = formatInfo(format);
    if (!f || f->cls != FormatClass::Depth)
        return fail(D3DERR_INVALIDCALL, "E4104",
                    std::string("CreateDepthStencilSurface: format ") + formatName(format) +
                        " is not a depth format (" + depthFormatList() + ")");
    Resource r;
    r.kind = ResourceKind::Surface;
    r.format = f;
    r.usage = D3DUSAGE_DEPTHSTENCIL;
    r.pool = D3DPOOL_DEFAULT;
    r.lockable = f->lockableDepth;  // only the _LOCKABLE formats can be locked (D3DFORMAT page)
    return createResource(call, std::move(r), width, height, 1, 1, surface);
}

HRESULT Device::CreateOffscreenPlainSurface(UINT width, UINT height, D3DFORMAT format, D3DPOOL pool, Handle* surface) {
    ok();
    const char* call = "CreateOffscreenPlainSurface";
    if (!surface) return fail(D3DERR_INVALIDCALL, "E4103", "CreateOffscreenPlainSurface: surface pointer is null");
    if (checkNewSize(call, width, height, 1, kMaxTextureSide) != D3D_OK) return m_error.hr;
    const FormatInfo* f = formatInfo(format);
    if (!f || f->cls == FormatClass::Depth)
        return fail(
            D3DERR_INVALIDCALL, "E4104",
            std::string("CreateOffscreenPlainSurface: format ") + formatName(format) + " not taken for surfaces");
    // D3D9: offscreen plain surfaces cannot be MANAGED.
    if (pool == D3DPOOL_MANAGED || pool > D3DPOOL_SCRATCH)
        return fail(D3DERR_INVALIDCALL, "E4112",
                    "CreateOffscreenPlainSurface: pool " + num(pool) + " not allowed (DEFAULT, SYSTEMMEM or SCRATCH)");
    Resource r;
    r.kind = ResourceKind::Surface;
    r.format = f;
    r.usage = 0;
    r.pool = pool;
    r.lockable = true;  // offscreen plain surfaces are lockable in every pool
    r.offscreenPlain = true;
    return createResource(call, std::move(r), width, height, 1, 1, surface);
}

HRESULT Device::Release(Handle object) {
    ok();
    const uint32_t id = uint32_t(object);
    if (m_shaders.erase(id)) {
        if (m_state.pixelShader == object) m_state.pixelShader = Handle::Null;
        return D3D_OK;
    }
    auto unbind = [this](Handle h) {
        for (Handle& t : m_state.textures)
            if (t == h) t = Handle::Null;
        if (m_state.renderTarget == h) m_state.renderTarget = Handle::Null;
        if (m_state.depthStencil == h) m_state.depthStencil = Handle::Null;
    };
    Resource* r = findResource(object);
    if (!r) {
        if (m_surfaces.count(id))
            return fail(D3DERR_INVALIDCALL, "E4102",
                        "Release: surface " + handleText(object) + " belongs to a texture; release the texture");
        return fail(D3DERR_INVALIDCALL, "E4102",
                    "Release: handle " + handleText(object) + " is not an object of this device");
    }
    for (Handle s : r->surfaces)
        if (s != Handle::Null) {
            unbind(s);
            m_surfaces.erase(uint32_t(s));
        }
    unbind(object);
    m_renderer->release(id);  // while its images are there (a copy put off may read them)
    m_surfaces.erase(id);
    m_resources.erase(id);
    return D3D_OK;
}

Image* Device::findSurface(Handle h, const char* what, CallError& error, Resource** owner, SurfaceRef* ref) {
    auto it = m_surfaces.find(uint32_t(h));
    if (it == m_surfaces.end()) {
        const bool other = m_resources.count(uint32_t(h)) || m_shaders.count(uint32_t(h));
        error = CallError{D3DERR_INVALIDCALL, "E4102",
                          std::string(what) + " " + handleText(h) +
                              (other ? " is not a surface (use GetSurfaceLevel for a texture level)"
                                     : " is not an object of this device")};
        return nullptr;
    }
    Resource* r = findResource(it->second.owner);
    if (!r) {
        error = CallError{D3DERR_INVALIDCALL, "E4102", std::string(what) + " " + handleText(h) + " was released"};
        return nullptr;
    }
    if (owner) *owner = r;
    if (ref) *ref = it->second;
    return &r->levels[it->second.level];
}

Image* Device::surfaceImage(Handle h, const char* call, const char* what, Resource** owner, SurfaceRef* ref) {
    CallError error;
    Image* image = findSurface(h, what, error, owner, ref);
    if (!image) fail(error.hr, error.code.c_str(), std::string(call) + ": " + error.message);
    return image;
}

DWORD Device::GetLevelCount(Handle texture) {
    ok();
    Resource* r = findResource(texture);
    if (!r || r->kind == ResourceKind::Surface) {
        fail(D3DERR_INVALIDCALL, "E4102", "GetLevelCount: handle " + handleText(texture) + " is not a texture");
        return 0;
    }
    return r->exposedLevels;
}

namespace {
void describe(const Resource& r, const Image& im, D3DSURFACE_DESC* desc) {
    desc->Format = r.format->format;
    desc->Type = D3DRTYPE_SURFACE;
    desc->Usage = r.usage;
    desc->Pool = r.pool;
    desc->Width = im.width;
    desc->Height = im.height;
}
}  // namespace

HRESULT Device::GetLevelDesc(Handle texture, UINT level, D3DSURFACE_DESC* desc) {
    ok();
    if (!desc) return fail(D3DERR_INVALIDCALL, "E4103", "GetLevelDesc: desc pointer is null");
    Resource* r = findResource(texture);
    if (!r || r->kind != ResourceKind::Texture)
        return fail(D3DERR_INVALIDCALL, "E4102", "GetLevelDesc: handle " + handleText(texture) + " is not a texture");
    if (level >= r->exposedLevels)
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "GetLevelDesc: level " + num(level) + " out of range 0.." + num(r->exposedLevels - 1));
    describe(*r, r->levels[level], desc);
    return D3D_OK;
}

HRESULT Device::GetDesc(Handle surface, D3DSURFACE_DESC* desc) {
    ok();
    if (!desc) return fail(D3DERR_INVALIDCALL, "E4103", "GetDesc: desc pointer is null");
    Resource* r = nullptr;
    Image* im = surfaceImage(surface, "GetDesc", "surface", &r, nullptr);
    if (!im) return m_error.hr;
    describe(*r, *im, desc);
    return D3D_OK;
}

HRESULT Device::GetSurfaceLevel(Handle texture, UINT level, Handle* surface) {
    ok();
    if (!surface) return fail(D3DERR_INVALIDCALL, "E4103", "GetSurfaceLevel: surface pointer is null");
    Resource* r = findResource(texture);
    if (!r || r->kind != ResourceKind::Texture)
        return fail(D3DERR_INVALIDCALL, "E4102",
                    "GetSurfaceLevel: handle " + handleText(texture) + " is not a texture");
    if (level >= r->exposedLevels)
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "GetSurfaceLevel: level " + num(level) + " out of range 0.." + num(r->exposedLevels - 1));
    if (r->surfaces[level] == Handle::Null) {
        const Handle h = newHandle();
        m_surfaces.emplace(uint32_t(h), SurfaceRef{texture, level});
        r->surfaces[level] = h;
    }
    *surface = r->surfaces[level];
    return D3D_OK;
}

void Device::regenerateMips(Resource& r) {
    syncResource(r);
    prepareWrite(r);
    generateMips(r);
    for (uint32_t l = 1; l < r.levels.size(); ++l) markWritten(r, l);
    r.mipsDirty = false;
}


void Device::markWritten(Resource& r, uint32_t level, bool setsPad) {
    if (!setsPad) r.padOnes = false;
    r.levelGeneration.resize(r.levels.size(), 0);
    r.rendererNewer.resize(r.levels.size(), 0);
    if (!r.bytesBefore.empty()) {
        bool same = true;
        size_t at = 0;
        for (const Image& im : r.levels) {
            const size_t n = levelBytes(im);
            same = same && std::memcmp(r.bytesBefore.data() + at, im.bytes.data(), n) == 0;
            at += n;
        }
        r.bytesBefore.clear();
        if (same) return;  // nothing changed: the generation, the mips and the renderer's copy stand
    }
    ++r.generation;
    if (level == 0) r.uniformStale.reset();  // (a clear or a draw that keeps it sets it again)
    r.levelGeneration[level] = r.generation;
    r.rendererNewer[level] = 0;
    if (level == 0 && r.autoGenMips()) r.mipsDirty = true;
}

void Device::rendererWrote(Resource& r, uint32_t level, bool setsPad) {
    markWritten(r, level, setsPad);
    r.rendererNewer[level] = m_renderer->leftNewer(surfaceDesc(SurfaceRef{r.handle, level}, r)) ? 1 : 0;
}

SurfaceDesc Device::surfaceDesc(const SurfaceRef& ref, Resource& r) {
    r.levelGeneration.resize(r.levels.size(), 0);
    r.rendererNewer.resize(r.levels.size(), 0);
    SurfaceDesc d;
    d.resource = uint32_t(ref.owner);
    d.level = ref.level;
    d.image = &r.levels[ref.level];
    d.generation = r.levelGeneration[ref.level];
    d.writeGeneration = r.generation + 1;  // what markWritten makes it
    return d;
}

void Device::prepareWrite(Resource& r) {
    m_renderer->beforeWrite(uint32_t(r.handle));  // a copy put off that reads these levels, made first
    // The sampler's view is stale once the write lands. A texture reading the levels in place
    // that is still held elsewhere keeps the bytes it was made from: the levels move to a copy.
    if (r.sampled && r.sampled->readsInPlace()) r.sampled.reset();
    if (r.storeShared()) detachStore(r);
    // A small resource whose bytes the front holds: kept, to tell an unchanging write.
    r.bytesBefore.clear();
    const size_t total = resourceLevelBytes(r);
    if (total <= kComparedResourceBytes && !m_renderer->keepsCopies() &&
        std::none_of(r.rendererNewer.begin(), r.rendererNewer.end(), [](uint8_t b) { return b != 0; })) {
        r.bytesBefore.reserve(total);
        for (const Image& im : r.levels)
            r.bytesBefore.insert(r.bytesBefore.end(), im.bytes.data(), im.bytes.data() + levelBytes(im));
    }
}

void Device::syncLevel(Resource& r, uint32_t level) {
    if (level >= r.rendererNewer.size() || !r.rendererNewer[level]) return;
    prepareWrite(r);
    m_renderer->readBack(surfaceDesc(SurfaceRef{r.handle, level}, r));
    r.rendererNewer[level] = 0;
}

void Device::syncResource(Resource& r) {
    for (uint32_t l = 0; l < r.rendererNewer.size(); ++l) syncLevel(r, l);
}

HRESULT Device::lockLevel(const char* call, Handle owner, Resource& r, uint32_t level, const RECT* rect,
                          const D3DBOX* box, DWORD flags, D3DLOCKED_BOX* out) {
    if (!r.lockable)
        return fail(D3DERR_INVALIDCALL, "E4106",
                    std::string(call) + ": " + handleText(owner) +
                        " is not lockable (D3DPOOL_DEFAULT without D3DUSAGE_DYNAMIC, a render target created "
                        "unlockable, or a non-lockable depth format)");
    if (r.locked[level])
        return fail(D3DERR_INVALIDCALL, "E4106",
                    std::string(call) + ": level " + num(level) + " of " + handleText(owner) + " is already locked");
    Image& im = r.levels[level];
    uint32_t x0 = 0, y0 = 0, z0 = 0;
    if (rect) {
        if (rect->left < 0 || rect->top < 0 || rect->left >= rect->right || rect->top >= rect->bottom ||
            uint32_t(rect->right) > im.width || uint32_t(rect->bottom) > im.height)
            return fail(D3DERR_INVALIDCALL, "E4106",
                        std::string(call) + ": rect (" + std::to_string(rect->left) + ", " + std::to_string(rect->top) +
                            ")-(" + std::to_string(rect->right) + ", " + std::to_string(rect->bottom) +
                            ") is empty or outside the " + num(im.width) + "x" + num(im.height) + " level");
        x0 = uint32_t(rect->left), y0 = uint32_t(rect->top);
    }
    if (box) {
        if (box->Left >= box->Right || box->Top >= box->Bottom || box->Front >= box->Back || box->Right > im.width ||
            box->Bottom > im.height || box->Back > im.depth)
            return fail(D3DERR_INVALIDCALL, "E4106",
                        std::string(call) + ": box is empty or outside the " + num(im.width) + "x" + num(im.height) +
                            "x" + num(im.depth) + " level");
        x0 = box->Left, y0 = box->Top, z0 = box->Front;
    }
    syncLevel(r, level);  // the locked bytes are the newest contents
    // Even a read-only lock: no buffer may move while a pointer into it is handed out.
    prepareWrite(r);
    r.locked[level] = 1;
    r.lockedReadOnly[level] = (flags & D3DLOCK_READONLY) ? 1 : 0;
    out->RowPitch = int32_t(im.rowPitch);
    out->SlicePitch = int32_t(std::min<uint64_t>(im.slicePitch, INT32_MAX));
    out->pBits = im.texel(x0, y0, z0);
    return D3D_OK;
}

HRESULT Device::unlockLevel(const char* call, Resource& r, uint32_t level) {
    if (!r.locked[level])
        return fail(D3DERR_INVALIDCALL, "E4106", std::string(call) + ": level " + num(level) + " is not locked");
    r.locked[level] = 0;
    if (!r.lockedReadOnly[level]) markWritten(r, level);
    return D3D_OK;
}

HRESULT Device::LockRect(Handle texture, UINT level, D3DLOCKED_RECT* locked, const RECT* rect, DWORD flags) {
    ok();
    if (m_fingerprint.active) return fingerprintRefuse("LockRect");
    if (!locked) return fail(D3DERR_INVALIDCALL, "E4103", "LockRect: locked-rect pointer is null");
    Resource* r = findResource(texture);
    if (!r || r->kind != ResourceKind::Texture)
        return fail(D3DERR_INVALIDCALL, "E4102", "LockRect: handle " + handleText(texture) + " is not a texture");
    if (level >= r->exposedLevels)
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "LockRect: level " + num(level) + " out of range 0.." + num(r->exposedLevels - 1));
    D3DLOCKED_BOX b;
    if (lockLevel("LockRect", texture, *r, level, rect, nullptr, flags, &b) != D3D_OK) return m_error.hr;
    locked->Pitch = b.RowPitch;
    locked->pBits = b.pBits;
    return D3D_OK;
}

HRESULT Device::UnlockRect(Handle texture, UINT level) {
    ok();
    Resource* r = findResource(texture);
    if (!r || r->kind != ResourceKind::Texture)
        return fail(D3DERR_INVALIDCALL, "E4102", "UnlockRect: handle " + handleText(texture) + " is not a texture");
    if (level >= r->exposedLevels)
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "UnlockRect: level " + num(level) + " out of range 0.." + num(r->exposedLevels - 1));
    return unlockLevel("UnlockRect", *r, level);
}

HRESULT Device::LockRect(Handle surface, D3DLOCKED_RECT* locked, const RECT* rect, DWORD flags) {
    ok();
    if (m_fingerprint.active) return fingerprintRefuse("LockRect");
    if (!locked) return fail(D3DERR_INVALIDCALL, "E4103", "LockRect: locked-rect pointer is null");
    Resource* r = nullptr;
    SurfaceRef ref;
    if (!surfaceImage(surface, "LockRect", "surface", &r, &ref)) return m_error.hr;
    D3DLOCKED_BOX b;
    if (lockLevel("LockRect", surface, *r, ref.level, rect, nullptr, flags, &b) != D3D_OK) return m_error.hr;
    locked->Pitch = b.RowPitch;
    locked->pBits = b.pBits;
    return D3D_OK;
}

HRESULT Device::UnlockRect(Handle surface) {
    ok();
    Resource* r = nullptr;
    SurfaceRef ref;
    if (!surfaceImage(surface, "UnlockRect", "surface", &r, &ref)) return m_error.hr;
    return unlockLevel("UnlockRect", *r, ref.level);
}

HRESULT Device::readSurface(Handle surface, const std::function<void(const D3DLOCKED_RECT&)>& read) {
    ok();
    if (m_fingerprint.active) return fingerprintRefuse("readSurface");
    Resource* r = nullptr;
    SurfaceRef ref;
    const Image* im = surfaceImage(surface, "readSurface", "surface", &r, &ref);
    if (!im) return m_error.hr;
    if (r->locked[ref.level])
        return fail(D3DERR_INVALIDCALL, "E4106",
                    "readSurface: level " + num(ref.level) + " of " + handleText(surface) + " is locked");
    syncLevel(*r, ref.level);  // the bytes read are the newest contents
    // Read-only: no prepareWrite (the sampler's view and a shared store stay valid).
    // Unlocked afterwards by handle: `read` may have released the resource.
    struct Hold {
        Device& d;
        Handle owner;
        uint32_t level;
        ~Hold() {
            if (Resource* h = d.findResource(owner)) h->locked[level] = 0;
        }
    } hold{*this, r->handle, ref.level};
    r->locked[ref.level] = 1;
    r->lockedReadOnly[ref.level] = 1;
    D3DLOCKED_RECT lr{};
    lr.Pitch = int32_t(im->rowPitch);
    lr.pBits = const_cast<uint8_t*>(im->texel(0, 0));
    read(lr);
    return D3D_OK;
}

HRESULT Device::LockBox(Handle volumeTexture, UINT level, D3DLOCKED_BOX* locked, const D3DBOX* box, DWORD flags) {
    ok();
    if (m_fingerprint.active) return fingerprintRefuse("LockBox");
    if (!locked) return fail(D3DERR_INVALIDCALL, "E4103", "LockBox: locked-box pointer is null");
    Resource* r = findResource(volumeTexture);
    if (!r || r->kind != ResourceKind::VolumeTexture)
        return fail(D3DERR_INVALIDCALL, "E4102",
                    "LockBox: handle " + handleText(volumeTexture) + " is not a volume texture");
    if (level >= r->exposedLevels)
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "LockBox: level " + num(level) + " out of range 0.." + num(r->exposedLevels - 1));
    return lockLevel("LockBox", volumeTexture, *r, level, nullptr, box, flags, locked);
}

HRESULT Device::UnlockBox(Handle volumeTexture, UINT level) {
    ok();
    Resource* r = findResource(volumeTexture);
    if (!r || r->kind != ResourceKind::VolumeTexture)
        return fail(D3DERR_INVALIDCALL, "E4102",
                    "UnlockBox: handle " + handleText(volumeTexture) + " is not a volume texture");
    if (level >= r->exposedLevels)
        return fail(D3DERR_INVALIDCALL, "E4101",
                    "UnlockBox: level " + num(level) + " out of range 0.." + num(r->exposedLevels - 1));
    return unlockLevel("UnlockBox", *r, level);
}

HRESULT Device::GenerateMipSubLevels(Handle texture) {
    ok();
    if (m_fingerprint.active) return fingerprintRefuse("GenerateMipSubLevels");
    Resource* r = findResource(texture);
    if (!r || r->kind == ResourceKind::Surface)
        return fail(D3DERR_INVALIDCALL, "E4102",
                    "GenerateMipSubLevels: handle " + handleText(texture) + " is not a texture");
    if (r->autoGenMips() && r->mipsDirty) regenerateMips(*r);
    return D3D_OK;
}

std::shared_ptr<const ps11::Texture> Device::makeSampled(Handle texture, CallError& error) {
    Resource* r = findResource(texture);
    if (!r || r->kind == ResourceKind::Surface) {
        error = CallError{D3DERR_INVALIDCALL, "E4102",
                          "sampledTexture: handle " + handleText(texture) + " is not a texture"};
        return nullptr;
    }
    // D3D9 regenerates AUTOGENMIPMAP sublevels before the texture is next used.
    if (r->autoGenMips() && r->mipsDirty) regenerateMips(*r);
    if (r->sampled && r->sampledGeneration == r->generation) return r->sampled;
    syncResource(*r);
    std::string why;
    // A locked level's bytes may change under the texture: it gets a copy then.
    const bool locked = std::find(r->locked.begin(), r->locked.end(), 1) != r->locked.end();
    try {
        // (Pad bits are known only in the front's own images: not on a renderer that keeps copies.)
        r->sampled = makeSampledTexture(*r, m_hardware.hardware->signedDecode, locked,
                                        r->padOnes && !m_renderer->keepsCopies(), why);
    } catch (const std::bad_alloc&) {
        r->sampled = nullptr;
        why = "out of memory";
    }
    if (!r->sampled) {
        error =
            CallError{D3DERR_OUTOFVIDEOMEMORY, "E4111", "sampledTexture: texture " + handleText(texture) + ": " + why};
        return nullptr;
    }
    r->sampledGeneration = r->generation;
    if (r->uniformStale) r->sampled->setUniformTiles(r->uniformStale);
    return r->sampled;
}

std::shared_ptr<const ps11::Texture> Device::sampledTexture(Handle texture) {
    ok();
    CallError error;
    std::shared_ptr<const ps11::Texture> t = makeSampled(texture, error);
    if (!t) fail(error.hr, error.code.c_str(), error.message);
    return t;
}

}  // namespace emu
