// The device's objects: textures, volume textures and surfaces kept in D3D9's memory layout
// (what LockRect hands out), and pixel shaders. Internal to the device (emu/device*.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "emu/d3d9types.h"
#include "emu/format.h"
#include "emu/state.h"
#include "ps11/caps.h"
#include "ps11/ir.h"
#include "ps11/texture.h"

namespace emu {

// The bytes of one image. A standalone image owns them (assign; a copy is a deep copy); a
// resource's levels are views into the resource's one buffer (allocateLevels), which a sampled
// texture may share (makeSampledTexture reads A8R8G8B8 levels in place).
class ImageBytes {
public:
    ImageBytes() = default;
    ImageBytes(const ImageBytes& o) { copyFrom(o); }
    ImageBytes& operator=(const ImageBytes& o) {
        if (this != &o) copyFrom(o);
        return *this;
    }
    ImageBytes(ImageBytes&& o) noexcept { *this = std::move(o); }
    ImageBytes& operator=(ImageBytes&& o) noexcept {
        m_store = std::move(o.m_store);
        m_data = o.m_data, m_size = o.m_size;
        o.m_data = nullptr, o.m_size = 0;
        return *this;
    }

    // Owns n fresh bytes of value v.
    void assign(size_t n, uint8_t v);
    // Views n bytes at `offset` of a shared buffer.
    void view(std::shared_ptr<uint8_t[]> store, size_t offset, size_t n) {
        m_store = std::move(store);
        m_data = m_store.get() + offset, m_size = n;
    }
    const std::shared_ptr<uint8_t[]>& store() const { return m_store; }

    uint8_t* data() { return m_data; }
    const uint8_t* data() const { return m_data; }
    size_t size() const { return m_size; }
    uint8_t* begin() { return m_data; }
    uint8_t* end() { return m_data + m_size; }
    const uint8_t* begin() const { return m_data; }
    const uint8_t* end() const { return m_data + m_size; }
    uint8_t& operator[](size_t i) { return m_data[i]; }
    const uint8_t& operator[](size_t i) const { return m_data[i]; }

private:
    void copyFrom(const ImageBytes& o);
    std::shared_ptr<uint8_t[]> m_store;
    uint8_t* m_data = nullptr;
    size_t m_size = 0;
};

// One mip level or one standalone surface: texels in the format's D3D layout, rows `rowPitch`
// bytes apart, slices `slicePitch` bytes apart.
struct Image {
    const FormatInfo* format = nullptr;
    uint32_t width = 0, height = 0, depth = 1;
    uint32_t rowPitch = 0;
    uint64_t slicePitch = 0;
    ImageBytes bytes;

    uint8_t* texel(uint32_t x, uint32_t y, uint32_t z = 0) {
        return bytes.data() + z * slicePitch + size_t(y) * rowPitch + size_t(x) * format->bytes;
    }
    const uint8_t* texel(uint32_t x, uint32_t y, uint32_t z = 0) const {
        return bytes.data() + z * slicePitch + size_t(y) * rowPitch + size_t(x) * format->bytes;
    }
};

enum class ResourceKind : uint8_t { Texture, VolumeTexture, Surface };

// A texture, volume texture or standalone surface (render target, depth stencil, offscreen
// plain surface).
struct Resource {
    Handle handle = Handle::Null;  // its own handle (what renderers know it by)
    ResourceKind kind = ResourceKind::Texture;
    const FormatInfo* format = nullptr;
    DWORD usage = 0;
    D3DPOOL pool = D3DPOOL_DEFAULT;
    bool lockable = false;
    bool offscreenPlain = false;  // CreateOffscreenPlainSurface
    std::vector<Image> levels;    // every level, including the hidden ones of AUTOGENMIPMAP
    uint32_t exposedLevels = 1;   // GetLevelCount: 1 for AUTOGENMIPMAP (D3D9)
    std::vector<uint8_t> locked;  // per level: LockRect/LockBox outstanding
    std::vector<uint8_t> lockedReadOnly;
    std::vector<Handle> surfaces;  // per exposed level: GetSurfaceLevel's handle, Null until asked
    bool mipsDirty = false;        // AUTOGENMIPMAP: level 0 changed since the last generation
    uint64_t generation = 0;       // bumped by every write that changes a byte; the sampler's copy follows it
    // A small resource's bytes before the write under way (Device::prepareWrite): a write that
    // leaves them equal keeps the generation (docs/device.md "Generations").
    std::vector<uint8_t> bytesBefore;
    // Per level: the generation of its last write (a renderer's copy follows it), and whether
    // the renderer holds newer contents than `levels` (its write, not yet read back).
    std::vector<uint64_t> levelGeneration;
    std::vector<uint8_t> rendererNewer;
    uint64_t sampledGeneration = ~uint64_t(0);
    std::shared_ptr<const ps11::Texture> sampled;  // the sampler's view (see Device::sampledTexture)
    // Level 0's tile facts known without a scan (docs/device.md "Tile facts from clears"): set
    // when a clear wrote one value to every texel, then a byte per tile of its tile grid
    // (ps11::texelTileSide) that draws may have written since; null after any other write.
    // Handed to each sampled view (ps11::Texture::setUniformTiles).
    std::shared_ptr<const std::vector<uint8_t>> uniformStale;
    // Every texel's pad bits (the X byte of X8R8G8B8) are 1s, so the sampler, which reads them as
    // alpha 1, can read the level where it lies (ps11::Texture::fromLevels' `padOnes`). Set by a
    // clear of the whole of a one-level resource (its texels encoded with the pad set); kept by
    // draws and clears, whose stores set the pad (the merger's X8 or-mask, encodeUnorm8); cleared
    // by every other write (a lock, a copy of bytes as given, StretchRect, mip generation).
    bool padOnes = false;

    // The one buffer all levels view (allocateLevels).
    const std::shared_ptr<uint8_t[]>& store() const { return levels.front().bytes.store(); }
    // Whether something besides the levels holds the buffer (a texture reading it in place).
    bool storeShared() const { return !levels.empty() && store().use_count() > long(levels.size()); }

    bool autoGenMips() const { return (usage & D3DUSAGE_AUTOGENMIPMAP) != 0; }
    bool isRenderTarget() const { return (usage & D3DUSAGE_RENDERTARGET) != 0; }
    bool isDepthStencil() const { return (usage & D3DUSAGE_DEPTHSTENCIL) != 0; }
};

// A surface handle: a level of a texture (owner = the texture) or a standalone surface (owner =
// the surface itself, level 0).
struct SurfaceRef {
    Handle owner = Handle::Null;
    uint32_t level = 0;
};

struct PixelShaderObject {
    ps11::Program program;
    std::vector<DWORD> tokens;  // as given (empty for a shader assembled from text)
};

// Refusals before any allocation (docs/device.md "Limits").
using ps11::kMaxResourceBytes;  // ps11/caps.h
using ps11::kMaxTextureSide;
using ps11::kMaxVolumeSide;

// Resources of at most this many bytes are told unchanged by their bytes (a 1×1 adaptation state
// that has converged, a glare sprite image uploaded every frame): on the software renderer a write
// that leaves them equal keeps the generation; on a renderer that keeps copies, whose writes the
// front does not see, a fingerprint reads their bytes instead of their generation
// (docs/device.md "Generations", "Fingerprints"). Larger ones cost a copy and a compare too many.
constexpr size_t kComparedResourceBytes = 65536;

// Bytes of one level's image (all its slices).
inline size_t levelBytes(const Image& im) { return size_t(im.slicePitch) * im.depth; }
// Bytes of every level of a resource.
inline size_t resourceLevelBytes(const Resource& r) {
    size_t total = 0;
    for (const Image& im : r.levels) total += levelBytes(im);
    return total;
}

// Row pitch of a level in bytes: width * texel size rounded up to 4 bytes (D3D9 pitches are
// DWORD aligned; callers must use the pitch, never width * size).
uint32_t rowPitchOf(const FormatInfo& f, uint32_t width);
// Bytes of a whole resource (all levels) without allocating anything.
uint64_t resourceBytes(const FormatInfo& f, uint32_t width, uint32_t height, uint32_t depth, uint32_t levels);
// Allocates the levels (zero-filled), one buffer viewed by every level. May throw std::bad_alloc.
void allocateLevels(Resource& r, uint32_t width, uint32_t height, uint32_t depth, uint32_t levels);
// Regenerates levels 1.. from level 0 with a 2x2 (2x2x2) box filter rounded half-even in the
// stored representation, the rule ps11/texture.cpp uses for generated chains.
void generateMips(Resource& r);
// Gives the levels a private copy of their buffer (before a write while a texture reads it).
void detachStore(Resource& r);
// Builds the sampler's immutable texture from the stored levels; nullptr and `error` on failure.
// A8R8G8B8 and A32B32G32R32F textures read the levels in place, sharing the buffer (unless `copy`);
// X8R8G8B8 ones too with `padOnes` (every texel's pad bits set: Resource::padOnes).
std::shared_ptr<const ps11::Texture> makeSampledTexture(const Resource& r, ps11::SignedDecode decode, bool copy,
                                                       bool padOnes, std::string& error);

}  // namespace emu
