// Device stage: whole-surface operations outside draws. Clear (viewport ∩ scissor ∩ rects,
// colour converted to the target's format, depth and stencil), StretchRect (POINT and LINEAR
// with texel-centre mapping and 8-bit weights in fx profiles, rounded once) and
// GetRenderTargetData. The exact rules are in docs/device.md.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "emu/device.h"
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

// floor(n / d) for d > 0.
int64_t floorDiv(int64_t n, int64_t d) {
    int64_t q = n / d;
    if ((n % d) != 0 && n < 0) --q;
    return q;
}

uint8_t toUnorm8(double v) {
    // Nearest 8-bit value, ties to even (docs/precision.md "Outputs").
    const double x = std::clamp(v, 0.0, 1.0) * 255.0;
    return uint8_t(std::nearbyint(x));
}

}  // namespace

HRESULT Device::GetRenderTargetData(Handle renderTarget, Handle destSurface) {
    ok();
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
                    std::string("StretchRect: formats ") + s->format->name + " -> " + d->format->name +
                        " not taken (A8R8G8B8, X8R8G8B8, R32F, A16B16G16R16F, A32B32G32R32F)");
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

    const FormatInfo& sf = *s->format;
    const FormatInfo& df = *d->format;
    const int64_t sw = sr.right - sr.left, sh = sr.bottom - sr.top;
    const int64_t dw = dr.right - dr.left, dh = dr.bottom - dr.top;
    const bool fx = ps11::isFixedPoint(m_hardware.precision);
    const bool unormSource = sf.cls == FormatClass::Unorm8;
    // Channel values in source units: bytes for 8-bit sources (exact sums), values otherwise.
    auto fetch = [&](int64_t x, int64_t y) {
        std::array<double, 4> v;
        const uint8_t* p = s->texel(uint32_t(x), uint32_t(y));
        if (unormSource) {
            std::array<uint8_t, 4> b = decodeUnorm8(sf, p);
            for (size_t c = 0; c < 4; ++c) v[c] = b[c];
        } else {
            std::array<float, 4> f = decodeTexel(sf, p, m_hardware.hardware->signedDecode);
            for (size_t c = 0; c < 4; ++c) v[c] = f[c];
        }
        return v;
    };
    auto store = [&](int64_t x, int64_t y, const std::array<double, 4>& v) {
        uint8_t* p = d->texel(uint32_t(x), uint32_t(y));
        if (df.cls == FormatClass::Unorm8) {
            std::array<uint8_t, 4> b;
            for (size_t c = 0; c < 4; ++c)
                b[c] = unormSource ? uint8_t(std::clamp(std::nearbyint(v[c]), 0.0, 255.0)) : toUnorm8(v[c]);
            encodeUnorm8(df, b, p);
        } else {
            std::array<float, 4> f;
            for (size_t c = 0; c < 4; ++c) f[c] = float(unormSource ? v[c] / 255.0 : v[c]);
            encodeFloat(df, f, p);
        }
    };
    // Texel-centre mapping (docs/device.md): destination pixel i of the rect has its centre at
    // i + 1/2, which maps to source position sr.left + (i + 1/2) * sw / dw. As exact fractions
    // over 2*dw: POINT takes floor(position) (a tie goes to the higher texel); LINEAR works in
    // texel space x = position - 1/2 = i0 + f.
    auto axisPoint = [](int64_t i, int64_t s0, int64_t sn, int64_t dn) {
        return s0 + floorDiv((2 * i + 1) * sn, 2 * dn);
    };
    struct Tap {
        int64_t i0, i1;
        double w1;  // weight of i1; i0 gets 1 - w1
    };
    auto axisLinear = [fx](int64_t i, int64_t s0, int64_t sn, int64_t dn) {
        const int64_t num2 = (2 * i + 1) * sn - dn;  // (x - s0) * 2dn
        const int64_t den = 2 * dn;
        const int64_t k = floorDiv(num2, den);
        const int64_t rem = num2 - k * den;  // f = rem / den in [0, 1)
        // fx profiles: 8 bits of sub-texel weight, round_half_even(f * 256) (docs/precision.md).
        const double w1 = fx ? double(ps11::roundHalfEven(rem * 256, den)) / 256.0 : double(rem) / double(den);
        // Taps outside the source rect are clamped to its edge texels.
        return Tap{std::clamp(s0 + k, s0, s0 + sn - 1), std::clamp(s0 + k + 1, s0, s0 + sn - 1), w1};
    };
    const bool linear = filter == D3DTEXF_LINEAR;
    const bool sameFormat = &sf == &df;
    // Fast path: an unscaled copy in one format is a row copy with either filter (LINEAR has
    // f = 0 at every pixel, so it reproduces the texels exactly).
    if (sameFormat && sw == dw && sh == dh) {
        const size_t row = size_t(sw) * sf.bytes;
        for (int64_t j = 0; j < dh; ++j)
            std::memmove(d->texel(uint32_t(dr.left), uint32_t(dr.top + j)),
                         s->texel(uint32_t(sr.left), uint32_t(sr.top + j)), row);
        markWritten(*dst, dstRef.level);
        return D3D_OK;
    }
    // Fast path: an exact 2:1 LINEAR reduction of A8R8G8B8/X8R8G8B8 has f = 1/2 on both axes
    // (weight 128/256 in fx profiles, 1/2 exactly otherwise), so each byte is
    // round_half_even((a + b + c + d) / 4) of a 2x2 block, the general path's result.
    if (linear && sameFormat && sf.bytes == 4 && sf.cls == FormatClass::Unorm8 && sw == 2 * dw && sh == 2 * dh) {
        const bool x8 = sf.format == D3DFMT_X8R8G8B8;
        for (int64_t j = 0; j < dh; ++j) {
            const uint8_t* r0 = s->texel(uint32_t(sr.left), uint32_t(sr.top + 2 * j));
            const uint8_t* r1 = r0 + s->rowPitch;
            uint8_t* out = d->texel(uint32_t(dr.left), uint32_t(dr.top + j));
            for (int64_t i = 0; i < dw; ++i, r0 += 8, r1 += 8, out += 4)
                for (int b = 0; b < 4; ++b) {
                    const int sum = r0[b] + r0[b + 4] + r1[b] + r1[b + 4];
                    // (sum + 1 + ((sum >> 2) & 1)) >> 2 is round_half_even(sum / 4).
                    out[b] = uint8_t((sum + 1 + ((sum >> 2) & 1)) >> 2);
                }
            if (x8)
                for (int64_t i = 0; i < dw; ++i) d->texel(uint32_t(dr.left + i), uint32_t(dr.top + j))[3] = 0xFF;
        }
        markWritten(*dst, dstRef.level);
        return D3D_OK;
    }
    std::vector<int64_t> pointX, pointY;
    std::vector<Tap> tapX, tapY;
    for (int64_t i = 0; i < dw; ++i) {
        pointX.push_back(axisPoint(i, sr.left, sw, dw));
        tapX.push_back(axisLinear(i, sr.left, sw, dw));
    }
    for (int64_t j = 0; j < dh; ++j) {
        pointY.push_back(axisPoint(j, sr.top, sh, dh));
        tapY.push_back(axisLinear(j, sr.top, sh, dh));
    }
    for (int64_t j = 0; j < dh; ++j) {
        for (int64_t i = 0; i < dw; ++i) {
            const int64_t dx = dr.left + i, dy = dr.top + j;
            if (!linear) {
                const int64_t sx = pointX[size_t(i)], sy = pointY[size_t(j)];
                if (sameFormat)
                    std::copy_n(s->texel(uint32_t(sx), uint32_t(sy)), sf.bytes, d->texel(uint32_t(dx), uint32_t(dy)));
                else
                    store(dx, dy, fetch(sx, sy));
                continue;
            }
            const Tap& tx = tapX[size_t(i)];
            const Tap& ty = tapY[size_t(j)];
            const std::array<double, 4> a = fetch(tx.i0, ty.i0), b = fetch(tx.i1, ty.i0);
            const std::array<double, 4> c = fetch(tx.i0, ty.i1), e = fetch(tx.i1, ty.i1);
            std::array<double, 4> v;
            // Exact weighted sum (8-bit weights and 8-bit texels: products of dyadic numbers are
            // exact in double), rounded once in store().
            for (size_t k = 0; k < 4; ++k)
                v[k] = (1 - ty.w1) * ((1 - tx.w1) * a[k] + tx.w1 * b[k]) + ty.w1 * ((1 - tx.w1) * c[k] + tx.w1 * e[k]);
            store(dx, dy, v);
        }
    }
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
    if (target) {
        const FormatInfo& f = *target->format;
        uint8_t texel[16] = {};
        const std::array<uint8_t, 4> rgba{uint8_t(color >> 16), uint8_t(color >> 8), uint8_t(color),
                                          uint8_t(color >> 24)};
        if (f.cls == FormatClass::Unorm8) {
            encodeUnorm8(f, rgba, texel);
        } else {
            std::array<float, 4> v;
            for (size_t c = 0; c < 4; ++c) v[c] = float(rgba[c] / 255.0);
            encodeFloat(f, v, texel);
        }
        for (const Box& b : boxes) {
            const Box c = b.meet(Box{0, 0, target->width, target->height});
            if (c.empty()) continue;
            // Fill the first row, then copy it to the others.
            for (int64_t x = c.x0; x < c.x1; ++x)
                std::copy_n(texel, f.bytes, target->texel(uint32_t(x), uint32_t(c.y0)));
            const size_t row = size_t(c.x1 - c.x0) * f.bytes;
            for (int64_t y = c.y0 + 1; y < c.y1; ++y)
                std::memcpy(target->texel(uint32_t(c.x0), uint32_t(y)), target->texel(uint32_t(c.x0), uint32_t(c.y0)),
                            row);
        }
        if (!boxes.empty()) markWritten(*rt, rtRef.level);
    }
    if (depth) {
        const FormatInfo& f = *depth->format;
        // The stored word is (old & keep) | set, computed once: depth as the nearest of 2^bits − 1
        // steps (D32F_LOCKABLE: the float), stencil in the low 8 bits of D24S8.
        uint32_t keep = 0xffffffffu, set = 0;
        if (flags & D3DCLEAR_ZBUFFER) {
            uint32_t zw;
            if (f.format == D3DFMT_D32F_LOCKABLE) {
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
        for (const Box& b : boxes) {
            const Box c = b.meet(Box{0, 0, depth->width, depth->height});
            for (int64_t y = c.y0; y < c.y1; ++y) {
                uint8_t* p = c.x0 < c.x1 ? depth->texel(uint32_t(c.x0), uint32_t(y)) : nullptr;
                for (int64_t x = c.x0; x < c.x1; ++x, p += f.bytes) {
                    const uint32_t w = (loadWord(p, f.bytes) & keep) | set;
                    for (uint32_t k = 0; k < f.bytes; ++k) p[k] = uint8_t(w >> (8 * k));
                }
            }
        }
        if (!boxes.empty()) markWritten(*ds, dsRef.level);
    }
    return D3D_OK;
}

}  // namespace emu
