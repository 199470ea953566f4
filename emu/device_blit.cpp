// Device front: whole-surface operations outside draws. Clear (viewport ∩ scissor ∩ rects,
// colour converted to the target's format, depth and stencil) and StretchRect checked and
// resolved into calls for the renderer (emu/renderer.h; done in the front's images by
// emu/blit.h when the renderer leaves them), and GetRenderTargetData. docs/device.md.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "emu/blit.h"
#include "emu/device.h"
#include "emu/tile_facts.h"
#include "ps11/precision.h"

namespace emu {

namespace {

std::string num(uint64_t v) { return std::to_string(v); }
std::string handleText(Handle h) { return num(uint32_t(h)); }
std::string rectText(const RECT& r) {
    return "(" + std::to_string(r.left) + ", " + std::to_string(r.top) + ")-(" + std::to_string(r.right) + ", " +
           std::to_string(r.bottom) + ")";
}

struct Box {
    int64_t x0, y0, x1, y1;  // x1, y1 exclusive
    bool empty() const { return x0 >= x1 || y0 >= y1; }
    Box meet(const Box& o) const {
        return {std::max(x0, o.x0), std::max(y0, o.y0), std::min(x1, o.x1), std::min(y1, o.y1)};
    }
};

}  // namespace

HRESULT Device::GetRenderTargetData(Handle renderTarget, Handle destSurface) {
    ok();
    if (m_fingerprint.active) return fingerprintRefuse("GetRenderTargetData");
    Resource* src = nullptr;
    Resource* dst = nullptr;
    SurfaceRef srcRef, dstRef;
    Image* s = surfaceImage(renderTarget, "GetRenderTargetData", "render target", &src, &srcRef);
    if (!s) return m_error.hr;
    Image* d = surfaceImage(destSurface, "GetRenderTargetData", "destination", &dst, &dstRef);
    if (!d) return m_error.hr;
    if (!src->isRenderTarget())
        return fail(D3DERR_INVALIDCALL, "E4108",
                    "GetRenderTargetData: surface " + handleText(renderTarget) + " is not a render target");
    // D3D9: the destination is a D3DPOOL_SYSTEMMEM surface of the same size and format.
    if (dst->pool != D3DPOOL_SYSTEMMEM)
        return fail(D3DERR_INVALIDCALL, "E4108",
                    "GetRenderTargetData: destination " + handleText(destSurface) + " is not in D3DPOOL_SYSTEMMEM");
    if (s->format != d->format || s->width != d->width || s->height != d->height)
        return fail(D3DERR_INVALIDCALL, "E4108",
                    std::string("GetRenderTargetData: destination is ") + num(d->width) + "x" + num(d->height) + " " +
                        d->format->name + ", the render target " + num(s->width) + "x" + num(s->height) + " " +
                        s->format->name);
    if (src->locked[srcRef.level] || dst->locked[dstRef.level])
        return fail(D3DERR_INVALIDCALL, "E4106", "GetRenderTargetData: a surface is locked");
    syncLevel(*src, srcRef.level);  // the read-back of a renderer that keeps copies
    prepareWrite(*dst);
    // A renderer that draws into the front's images moves the rows itself, as an unscaled
    // StretchRect (the software renderer over its workers: a 1080p read-back is an 8 MB copy);
    // otherwise the front copies the image brought back.
    if (!m_renderer->keepsCopies()) {
        StretchCall sc;
        sc.source = surfaceDesc(srcRef, *src);
        sc.dest = surfaceDesc(dstRef, *dst);
        sc.sourceRect = sc.destRect = PixelBox{0, 0, int64_t(s->width), int64_t(s->height)};
        sc.fixedPoint = ps11::isFixedPoint(m_hardware.precision);
        sc.decode = m_hardware.hardware->signedDecode;
        if (m_renderer->stretchRect(sc)) {
            markWritten(*dst, dstRef.level);
            return D3D_OK;
        }
    }
    const size_t row = size_t(s->width) * s->format->bytes;
    for (uint32_t y = 0; y < s->height; ++y) std::copy_n(s->texel(0, y), row, d->texel(0, y));
    markWritten(*dst, dstRef.level);
    return D3D_OK;
}

HRESULT Device::StretchRect(Handle source, const RECT* sourceRect, Handle dest, const RECT* destRect,
                            D3DTEXTUREFILTERTYPE filter) {
    ok();
    const char* call = "StretchRect";
    Resource* src = nullptr;
    Resource* dst = nullptr;
    SurfaceRef srcRef, dstRef;
    Image* s = surfaceImage(source, call, "source", &src, &srcRef);
    if (!s) return m_error.hr;
    Image* d = surfaceImage(dest, call, "destination", &dst, &dstRef);
    if (!d) return m_error.hr;
    if (source == dest)
        return fail(D3DERR_INVALIDCALL, "E4108", "StretchRect: source and destination are the same surface");
    if (filter != D3DTEXF_NONE && filter != D3DTEXF_POINT && filter != D3DTEXF_LINEAR)
        return fail(D3DERR_INVALIDCALL, "E4112",
                    "StretchRect: filter " + num(filter) + " not taken (NONE, POINT, LINEAR)");
    // D3D9: both surfaces in D3DPOOL_DEFAULT; the destination a render target or an offscreen
    // plain surface; depth surfaces only whole and unscaled (not supported here).
    if (src->pool != D3DPOOL_DEFAULT || dst->pool != D3DPOOL_DEFAULT)
        return fail(D3DERR_INVALIDCALL, "E4108", "StretchRect: both surfaces must be in D3DPOOL_DEFAULT");
    if (!dst->isRenderTarget() && !dst->offscreenPlain)
        return fail(D3DERR_INVALIDCALL, "E4108",
                    "StretchRect: destination " + handleText(dest) +
                        " is neither a render target nor an offscreen plain surface");
    if (!s->format->renderTarget || !d->format->renderTarget)
        return fail(D3DERR_INVALIDCALL, "E4104",
                    std::string("StretchRect: formats ") + s->format->name + " -> " + d->format->name + " not taken (" +
                        renderTargetFormatList() + ")");
    if (src->locked[srcRef.level] || dst->locked[dstRef.level])
        return fail(D3DERR_INVALIDCALL, "E4106", "StretchRect: a surface is locked");
    const RECT sr = sourceRect ? *sourceRect : RECT{0, 0, LONG(s->width), LONG(s->height)};
    const RECT dr = destRect ? *destRect : RECT{0, 0, LONG(d->width), LONG(d->height)};
    auto inside = [](const RECT& r, const Image& im) {
        return r.left >= 0 && r.top >= 0 && r.left < r.right && r.top < r.bottom && uint32_t(r.right) <= im.width &&
               uint32_t(r.bottom) <= im.height;
    };
    if (!inside(sr, *s))
        return fail(D3DERR_INVALIDCALL, "E4108",
                    "StretchRect: source rect " + rectText(sr) + " is empty or outside the " + num(s->width) + "x" +
                        num(s->height) + " source");
    if (!inside(dr, *d))
        return fail(D3DERR_INVALIDCALL, "E4108",
                    "StretchRect: destination rect " + rectText(dr) + " is empty or outside the " + num(d->width) +
                        "x" + num(d->height) + " destination");

    if (m_fingerprint.active) {
        const uint32_t words[] = {0x53545245u,  // "STRE"
                                  uint32_t(srcRef.owner), srcRef.level, uint32_t(sr.left), uint32_t(sr.top),
                                  uint32_t(sr.right), uint32_t(sr.bottom), uint32_t(dstRef.owner), dstRef.level,
                                  uint32_t(dr.left), uint32_t(dr.top), uint32_t(dr.right), uint32_t(dr.bottom),
                                  uint32_t(filter)};
        fingerprintWords(words, sizeof words);
        fingerprintRead(srcRef.owner);
        const bool whole = dst->levels.size() == 1 && dr.left == 0 && dr.top == 0 && uint32_t(dr.right) == d->width &&
                           uint32_t(dr.bottom) == d->height;
        fingerprintWrite(dstRef.owner, whole);
        return D3D_OK;
    }
    StretchCall sc;
    sc.source = surfaceDesc(srcRef, *src);
    sc.dest = surfaceDesc(dstRef, *dst);
    sc.sourceRect = PixelBox{sr.left, sr.top, sr.right, sr.bottom};
    sc.destRect = PixelBox{dr.left, dr.top, dr.right, dr.bottom};
    sc.linear = filter == D3DTEXF_LINEAR;
    sc.fixedPoint = ps11::isFixedPoint(m_hardware.precision);
    sc.decode = m_hardware.hardware->signedDecode;
    // Not where the front compares a small destination's bytes before and after (prepareWrite):
    // a copy put off has written none of them yet.
    sc.mayPutOff = resourceLevelBytes(*dst) > kComparedResourceBytes;
    prepareWrite(*dst);
    m_lastStretchPutOff = false;
    if (m_renderer->stretchRect(sc)) {
        rendererWrote(*dst, dstRef.level);
        // A renderer that draws into the front's images and holds the level newer put it off.
        m_lastStretchPutOff = !m_renderer->keepsCopies() && dst->rendererNewer[dstRef.level];
        return D3D_OK;
    }
    // The renderer left it to the front: in the front's images, brought up to date first.
    syncLevel(*src, srcRef.level);
    syncLevel(*dst, dstRef.level);
    stretchImages(sc);
    markWritten(*dst, dstRef.level);
    return D3D_OK;
}

HRESULT Device::Clear(DWORD count, const D3DRECT* rects, DWORD flags, D3DCOLOR color, float z, DWORD stencil) {
    ok();
    const DWORD known = D3DCLEAR_TARGET | D3DCLEAR_ZBUFFER | D3DCLEAR_STENCIL;
    if (flags == 0 || (flags & ~known))
        return fail(
            D3DERR_INVALIDCALL, "E4112",
            "Clear: flags " + num(flags) + " must be a non-empty mix of D3DCLEAR_TARGET (1), ZBUFFER (2), STENCIL (4)");
    Resource* rt = nullptr;
    Resource* ds = nullptr;
    SurfaceRef rtRef, dsRef;
    Image* target = nullptr;
    Image* depth = nullptr;
    if (flags & D3DCLEAR_TARGET) {
        if (m_state.renderTarget == Handle::Null)
            return fail(D3DERR_INVALIDCALL, "E4109", "Clear: D3DCLEAR_TARGET without a render target");
        target = surfaceImage(m_state.renderTarget, "Clear", "render target", &rt, &rtRef);
        if (!target) return m_error.hr;
        if (rt->locked[rtRef.level]) return fail(D3DERR_INVALIDCALL, "E4106", "Clear: the render target is locked");
    }
    if (flags & (D3DCLEAR_ZBUFFER | D3DCLEAR_STENCIL)) {
        // D3D9: clearing depth or stencil without a depth stencil surface is an invalid call.
        if (m_state.depthStencil == Handle::Null)
            return fail(D3DERR_INVALIDCALL, "E4109", "Clear: D3DCLEAR_ZBUFFER/STENCIL without a depth stencil surface");
        depth = surfaceImage(m_state.depthStencil, "Clear", "depth stencil surface", &ds, &dsRef);
        if (!depth) return m_error.hr;
        if ((flags & D3DCLEAR_STENCIL) && depth->format->stencilBits == 0)
            return fail(D3DERR_INVALIDCALL, "E4104",
                        std::string("Clear: D3DCLEAR_STENCIL on ") + depth->format->name + ", which has no stencil");
        if (ds->locked[dsRef.level])
            return fail(D3DERR_INVALIDCALL, "E4106", "Clear: the depth stencil surface is locked");
        if ((flags & D3DCLEAR_ZBUFFER) && !(z >= 0.0f && z <= 1.0f))
            return fail(D3DERR_INVALIDCALL, "E4105", "Clear: z " + std::to_string(z) + " outside [0, 1]");
    }
    // The region: the viewport, ∩ the scissor rect when D3DRS_SCISSORTESTENABLE is set, ∩ each
    // rect. D3D9 clears the viewport, not the whole target, and honours the scissor test (Wine's
    // d3d9 visual tests); D3DRS_COLORWRITEENABLE does not mask clears (wined3d's clear path).
    const D3DVIEWPORT9& vp = m_state.viewport;
    Box region{int64_t(vp.X), int64_t(vp.Y), int64_t(vp.X) + vp.Width, int64_t(vp.Y) + vp.Height};
    // Without a render target (D3D9 always has one) a depth-only clear covers the depth surface.
    if (m_state.renderTarget == Handle::Null && depth) region = Box{0, 0, depth->width, depth->height};
    if (m_state.renderStates[D3DRS_SCISSORTESTENABLE]) {
        const RECT& sc = m_state.scissor;
        region = region.meet(Box{sc.left, sc.top, sc.right, sc.bottom});
    }
    std::vector<Box> boxes;
    if (count == 0 || !rects) {
        // D3D9 (as Wine implements it): a count with NULL rects clears nothing and succeeds; rects
        // with a zero count are ignored and the whole region is cleared.
        if (count == 0) boxes.push_back(region);
    } else {
        for (DWORD i = 0; i < count; ++i) {
            const Box b = region.meet(Box{rects[i].x1, rects[i].y1, rects[i].x2, rects[i].y2});
            if (!b.empty()) boxes.push_back(b);  // inverted or outside rects clear nothing
        }
    }
    // Whether the boxes are one that covers the whole of `im`.
    auto coversAll = [&](const Image& im) {
        return boxes.size() == 1 && boxes[0].x0 <= 0 && boxes[0].y0 <= 0 && boxes[0].x1 >= int64_t(im.width) &&
               boxes[0].y1 >= int64_t(im.height);
    };
    if (m_fingerprint.active) {
        uint32_t zBits;
        std::memcpy(&zBits, &z, 4);
        const uint32_t words[] = {0x434c4541u, flags, color, zBits, stencil, uint32_t(boxes.size())};  // "CLEA"
        fingerprintWords(words, sizeof words);
        for (const Box& b : boxes) {
            const int64_t box[4] = {b.x0, b.y0, b.x1, b.y1};
            fingerprintWords(box, sizeof box);
        }
        auto whole = [&](const Resource* r, const Image* im) { return r->levels.size() == 1 && coversAll(*im); };
        // A depth surface cleared of depth but not of its stencil keeps the stencil bits.
        const bool depthWhole = depth && (flags & D3DCLEAR_ZBUFFER) &&
                                ((flags & D3DCLEAR_STENCIL) || depth->format->stencilBits == 0) && whole(ds, depth);
        if (depth && !depthWhole) fingerprintRead(dsRef.owner);
        if (target) fingerprintWrite(rtRef.owner, whole(rt, target));
        if (depth) fingerprintWrite(dsRef.owner, depthWhole);
        return D3D_OK;
    }
    ClearCall cc;
    for (const Box& b : boxes) cc.boxes.push_back(PixelBox{b.x0, b.y0, b.x1, b.y1});
    if (target) {
        const FormatInfo& f = *target->format;
        const std::array<uint8_t, 4> rgba{uint8_t(color >> 16), uint8_t(color >> 8), uint8_t(color),
                                          uint8_t(color >> 24)};
        if (f.cls == FormatClass::Unorm8) {
            encodeUnorm8(f, rgba, cc.colorTexel.data());
        } else {
            std::array<float, 4> v;
            for (size_t c = 0; c < 4; ++c) v[c] = float(rgba[c] / 255.0);
            encodeFloat(f, v, cc.colorTexel.data());
        }
        cc.color = surfaceDesc(rtRef, *rt);
    }
    if (depth) {
        const FormatInfo& f = *depth->format;
        // The stored word is (old & keep) | set, computed once: depth as the nearest of 2^bits − 1
        // steps (a float depth format: the float), stencil in the low 8 bits of D24S8.
        uint32_t keep = 0xffffffffu, set = 0;
        if (flags & D3DCLEAR_ZBUFFER) {
            uint32_t zw;
            if (f.depthFloat) {
                std::memcpy(&zw, &z, 4);
                keep = 0, set = zw;
            } else if (f.depthBits == 16) {
                keep = 0, set = uint32_t(std::nearbyint(double(z) * 65535.0));
            } else if (f.depthBits == 24) {
                keep = 0xffu, set = uint32_t(std::nearbyint(double(z) * 16777215.0)) << 8;
            } else {
                keep = 0, set = uint32_t(std::nearbyint(double(z) * 4294967295.0));
            }
        }
        if ((flags & D3DCLEAR_STENCIL) && f.stencilBits == 8) keep &= ~0xffu, set = (set & ~0xffu) | (stencil & 0xffu);
        cc.depthKeep = keep, cc.depthSet = set;
        cc.depth = surfaceDesc(dsRef, *ds);
    }
    if (boxes.empty()) return D3D_OK;
    if (target) prepareWrite(*rt);
    if (depth) prepareWrite(*ds);
    // (The cleared texels are cc.colorTexel, its pad bits set by encodeUnorm8.)
    if (m_renderer->clear(cc)) {
        if (target) rendererWrote(*rt, rtRef.level, /*setsPad=*/true);
        if (depth) rendererWrote(*ds, dsRef.level);
    } else {
        if (target) syncLevel(*rt, rtRef.level);
        if (depth) syncLevel(*ds, dsRef.level);
        clearImages(cc);
        if (target) markWritten(*rt, rtRef.level, /*setsPad=*/true);
        if (depth) markWritten(*ds, dsRef.level);
    }
    if (target && rt->levels.size() == 1 && coversAll(*target)) rt->padOnes = true;
    // Level 0 of a texture cleared whole holds one value: its tile facts need no scan until drawn into.
    if (target && rtRef.level == 0 && coversAll(*target))
        rt->uniformStale = std::make_shared<const std::vector<uint8_t>>(uniformTileCount(*target), uint8_t(0));
    return D3D_OK;
}

}  // namespace emu
