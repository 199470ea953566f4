// The device's whole-surface calls outside draws (emu/device_blit.cpp, emu/blit.h): Clear
// (viewport, scissor and rects, worker threads, the colour, depth and stencil converted to the
// surface formats), StretchRect POINT and LINEAR (sub-rectangles, format conversion, and LINEAR at
// random scales and rects against the weighted sum written out), and GetRenderTargetData.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "device_test_util.h"
#include "emu/blit.h"
#include "emu/device.h"
#include "ps11/cpu_features.h"

using namespace emu;

using namespace devicetest;

namespace {

uint32_t readPixel(Device& dev, Handle surface, UINT x, UINT y) {
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(surface, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    uint32_t c;
    std::memcpy(&c, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, 4);
    REQUIRE(dev.UnlockRect(surface) == D3D_OK);
    return c;
}

float readFloat(Device& dev, Handle surface, UINT x, UINT y, UINT channel = 0) {
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(surface, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    float f;
    D3DSURFACE_DESC desc;
    REQUIRE(dev.GetDesc(surface, &desc) == D3D_OK);
    const UINT bytes = desc.Format == D3DFMT_R32F ? 4 : 16;
    std::memcpy(&f, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * bytes + 4 * channel, 4);
    REQUIRE(dev.UnlockRect(surface) == D3D_OK);
    return f;
}

// A random source rect of sw×sh and destination rect of dw×dh (each at least one pixel, inside),
// and the tap mapping stretchTaps gives them (fx weights or the float profiles').
struct RandomStretch {
    RECT sr{}, dr{};
    std::vector<StretchTap> tx, ty;
};
RandomStretch randomStretch(std::mt19937& rng, UINT sw, UINT sh, UINT dw, UINT dh, bool fixedPoint) {
    RandomStretch r;
    r.sr = RECT{LONG(rng() % sw), LONG(rng() % sh), 0, 0};
    r.dr = RECT{LONG(rng() % dw), LONG(rng() % dh), 0, 0};
    r.sr.right = r.sr.left + 1 + LONG(rng() % (sw - UINT(r.sr.left)));
    r.sr.bottom = r.sr.top + 1 + LONG(rng() % (sh - UINT(r.sr.top)));
    r.dr.right = r.dr.left + 1 + LONG(rng() % (dw - UINT(r.dr.left)));
    r.dr.bottom = r.dr.top + 1 + LONG(rng() % (dh - UINT(r.dr.top)));
    StretchCall call;
    call.sourceRect = PixelBox{r.sr.left, r.sr.top, r.sr.right, r.sr.bottom};
    call.destRect = PixelBox{r.dr.left, r.dr.top, r.dr.right, r.dr.bottom};
    call.linear = true;
    call.fixedPoint = fixedPoint;
    r.tx = stretchTaps(call, true);
    r.ty = stretchTaps(call, false);
    return r;
}

}  // namespace

TEST_CASE("device: Clear honours viewport, scissor and rects", "[device]") {
    Device dev;
    Handle rt = makeTarget(dev, 4, 4, [](UINT, UINT) { return 0u; });
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    auto count = [&](uint32_t colour) {
        int n = 0;
        for (UINT y = 0; y < 4; ++y)
            for (UINT x = 0; x < 4; ++x) n += readPixel(dev, rt, x, y) == colour;
        return n;
    };

    CHECK(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF102030u, 1.0f, 0) == D3D_OK);
    CHECK(count(0xFF102030u) == 16);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(rt, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    const uint8_t* b = static_cast<const uint8_t*>(lr.pBits);
    CHECK((b[0] == 0x30 && b[1] == 0x20 && b[2] == 0x10 && b[3] == 0xFF));  // B G R A in memory
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);

    // Two rects, one inverted (clears nothing).
    D3DRECT rects[2] = {{1, 1, 3, 2}, {3, 3, 1, 1}};
    CHECK(dev.Clear(2, rects, D3DCLEAR_TARGET, 0x00000001u, 1.0f, 0) == D3D_OK);
    CHECK(count(1u) == 2);
    CHECK(readPixel(dev, rt, 1, 1) == 1u);
    CHECK(readPixel(dev, rt, 2, 1) == 1u);

    // A count with NULL rects clears nothing (Wine's d3d9 behaviour); rects with count 0 are
    // ignored (the whole viewport).
    CHECK(dev.Clear(1, nullptr, D3DCLEAR_TARGET, 0x00000002u, 1.0f, 0) == D3D_OK);
    CHECK(count(2u) == 0);
    CHECK(dev.Clear(0, rects, D3DCLEAR_TARGET, 0x00000002u, 1.0f, 0) == D3D_OK);
    CHECK(count(2u) == 16);

    // Scissor (when enabled) ∩ rect.
    RECT sc{0, 0, 2, 2};
    REQUIRE(dev.SetScissorRect(&sc) == D3D_OK);
    D3DRECT big{1, 1, 4, 4};
    CHECK(dev.Clear(1, &big, D3DCLEAR_TARGET, 0x00000003u, 1.0f, 0) == D3D_OK);
    CHECK(count(3u) == 9);  // scissor test off: the rect alone
    REQUIRE(dev.SetRenderState(D3DRS_SCISSORTESTENABLE, 1) == D3D_OK);
    CHECK(dev.Clear(1, &big, D3DCLEAR_TARGET, 0x00000004u, 1.0f, 0) == D3D_OK);
    CHECK(count(4u) == 1);
    CHECK(readPixel(dev, rt, 1, 1) == 4u);
    REQUIRE(dev.SetRenderState(D3DRS_SCISSORTESTENABLE, 0) == D3D_OK);

    // The viewport bounds every clear; COLORWRITEENABLE does not mask it.
    D3DVIEWPORT9 vp{2, 0, 2, 4, 0, 1};
    REQUIRE(dev.SetViewport(&vp) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_COLORWRITEENABLE, 0) == D3D_OK);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x00000005u, 1.0f, 0) == D3D_OK);
    CHECK(count(5u) == 8);
    CHECK(readPixel(dev, rt, 1, 0) != 5u);
    CHECK(readPixel(dev, rt, 2, 0) == 5u);

    // Errors.
    CHECK(dev.Clear(0, nullptr, 0, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.Clear(0, nullptr, 8, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4109");
    Device empty;
    CHECK(empty.Clear(0, nullptr, D3DCLEAR_TARGET, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    D3DLOCKED_RECT held;
    REQUIRE(dev.LockRect(rt, &held, nullptr, 0) == D3D_OK);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0, 1.0f, 0) == D3DERR_INVALIDCALL);
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);
}

TEST_CASE("device: Clear shared by worker threads writes exactly its rects", "[device]") {
    // 320×240: enough texels for up to 4 workers, whose row bands cut through the rects.
    for (int threads : {1, 2, 3, 4}) {
        DeviceOptions o;
        o.software.threads = threads;
        Device dev(o);
        Handle rt = makeTarget(dev, 320, 240, [](UINT x, UINT y) { return 0xFF000000u | (y << 9) | x; });
        REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
        const D3DRECT rects[3] = {{0, 0, 320, 61}, {17, 50, 300, 239}, {5, 119, 6, 121}};
        REQUIRE(dev.Clear(3, rects, D3DCLEAR_TARGET, 0x80402010u, 1.0f, 0) == D3D_OK);
        int wrong = 0;
        for (UINT y = 0; y < 240; ++y)
            for (UINT x = 0; x < 320; ++x) {
                bool in = false;
                for (const D3DRECT& r : rects) in = in || (LONG(x) >= r.x1 && LONG(x) < r.x2 && LONG(y) >= r.y1 && LONG(y) < r.y2);
                wrong += readPixel(dev, rt, x, y) != (in ? 0x80402010u : 0xFF000000u | (y << 9) | x);
            }
        CHECK(wrong == 0);
    }
}

TEST_CASE("device: Clear of a target past half the last cache level writes exactly its rects", "[device]") {
    // Targets of 32 MB (8-bit and float texels): on a machine whose last cache level holds at most
    // 64 MB their rows are stored around the caches (emu/blit.cpp), in 16-byte blocks from the
    // first aligned byte of each row. Rects start on odd columns; every byte is checked.
    INFO("last cache level: " << ps11::cpuFeatures().lastLevelCacheBytes << " bytes");
    for (D3DFORMAT fmt : {D3DFMT_A8R8G8B8, D3DFMT_A32B32G32R32F}) {
        const UINT w = fmt == D3DFMT_A8R8G8B8 ? 4096 : 2048, h = 2048, bpp = fmt == D3DFMT_A8R8G8B8 ? 4 : 16;
        Device dev;
        Handle rt{};
        REQUIRE(dev.CreateRenderTarget(w, h, fmt, 1, &rt) == D3D_OK);
        REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x00000000u, 1.0f, 0) == D3D_OK);
        const D3DRECT rects[2] = {{3, 1, LONG(w) - 5, 900}, {1, 1500, 2, 2047}};
        REQUIRE(dev.Clear(2, rects, D3DCLEAR_TARGET, 0x80402010u, 1.0f, 0) == D3D_OK);
        std::vector<uint8_t> cleared(bpp), zero(bpp, 0);
        if (fmt == D3DFMT_A8R8G8B8) {
            const uint32_t c = 0x80402010u;
            std::memcpy(cleared.data(), &c, 4);
        } else {
            const float v[4] = {float(0x40 / 255.0), float(0x20 / 255.0), float(0x10 / 255.0), float(0x80 / 255.0)};
            std::memcpy(cleared.data(), v, 16);
        }
        size_t wrong = 0;
        REQUIRE(dev.readSurface(rt, [&](const D3DLOCKED_RECT& lr) {
            for (UINT y = 0; y < h; ++y) {
                const uint8_t* row = static_cast<const uint8_t*>(lr.pBits) + size_t(y) * UINT(lr.Pitch);
                for (UINT x = 0; x < w; ++x) {
                    bool in = false;
                    for (const D3DRECT& r : rects)
                        in = in || (LONG(x) >= r.x1 && LONG(x) < r.x2 && LONG(y) >= r.y1 && LONG(y) < r.y2);
                    wrong += std::memcmp(row + size_t(x) * bpp, in ? cleared.data() : zero.data(), bpp) != 0;
                }
            }
        }) == D3D_OK);
        INFO((fmt == D3DFMT_A8R8G8B8 ? "A8R8G8B8" : "A32B32G32R32F"));
        CHECK(wrong == 0);
    }
}

TEST_CASE("device: Clear converts the colour, depth and stencil to the surface formats", "[device]") {
    Device dev;
    Handle f32{}, f16{}, x8{};
    REQUIRE(dev.CreateRenderTarget(2, 2, D3DFMT_A32B32G32R32F, 1, &f32) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, f32) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x33804000u, 1.0f, 0) == D3D_OK);
    CHECK(readFloat(dev, f32, 1, 1, 0) == float(128.0 / 255));
    CHECK(readFloat(dev, f32, 1, 1, 1) == float(64.0 / 255));
    CHECK(readFloat(dev, f32, 1, 1, 2) == 0.0f);
    CHECK(readFloat(dev, f32, 1, 1, 3) == float(51.0 / 255));
    REQUIRE(dev.CreateRenderTarget(2, 2, D3DFMT_A16B16G16R16F, 1, &f16) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, f16) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFFFF0000u, 1.0f, 0) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(f16, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    const uint8_t* p = static_cast<const uint8_t*>(lr.pBits);
    CHECK((p[0] == 0x00 && p[1] == 0x3C));  // R = 1.0 = 0x3C00
    CHECK((p[2] == 0x00 && p[3] == 0x00));  // G = 0
    CHECK((p[6] == 0x00 && p[7] == 0x3C));  // A = 1.0
    REQUIRE(dev.UnlockRect(f16) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(2, 2, D3DFMT_X8R8G8B8, 1, &x8) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, x8) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x00123456u, 1.0f, 0) == D3D_OK);
    CHECK(readPixel(dev, x8, 0, 0) == 0xFF123456u);  // X written as 0xFF

    Handle ds{}, d16{};
    REQUIRE(dev.CreateDepthStencilSurface(2, 2, D3DFMT_D24S8, &ds) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(2, 2, D3DFMT_D16_LOCKABLE, &d16) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(d16) == D3D_OK);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_STENCIL, 0, 1.0f, 7) == D3DERR_INVALIDCALL);  // D16 has no stencil
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, 1.5f, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, std::nanf(""), 0) == D3DERR_INVALIDCALL);
    // z = 0.5 on 16 bits: 0.5 * 65535 = 32767.5 -> 32768 (nearest, ties to even).
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, 0.5f, 0) == D3D_OK);
    REQUIRE(dev.LockRect(d16, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    p = static_cast<const uint8_t*>(lr.pBits);
    CHECK((p[lr.Pitch + 2] | (p[lr.Pitch + 3] << 8)) == 32768);
    REQUIRE(dev.UnlockRect(d16) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(ds) == D3D_OK);
    CHECK(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER | D3DCLEAR_STENCIL | D3DCLEAR_TARGET, 0, 0.25f, 0x1A5) == D3D_OK);
}

TEST_CASE("device: a depth-only Clear without a render target covers the depth surface", "[device]") {
    Device dev;
    Handle ds{};
    REQUIRE(dev.CreateDepthStencilSurface(3, 2, D3DFMT_D16_LOCKABLE, &ds) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(ds) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, 1.0f, 0) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(ds, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    const uint8_t* p = static_cast<const uint8_t*>(lr.pBits);
    CHECK((p[lr.Pitch + 4] == 0xFF && p[lr.Pitch + 5] == 0xFF));  // z = 1 -> 65535
    REQUIRE(dev.UnlockRect(ds) == D3D_OK);
}

TEST_CASE("device: StretchRect point and linear", "[device]") {
    Device dev;  // fx8

    SECTION("4x4 -> 2x2 linear averages 2x2 blocks, rounded once (ties to even)") {
        // Red channel per block: {10, 20, 31, 40} -> 25.25 -> 25; {1, 2, 2, 2} -> 1.75 -> 2;
        // {0, 1, 0, 1} -> 0.5 -> 0; {1, 2, 1, 2} -> 1.5 -> 2. Other channels constant.
        const uint8_t red[4][4] = {{10, 20, 1, 2}, {31, 40, 2, 2}, {0, 1, 1, 2}, {0, 1, 1, 2}};
        Handle src = makeTarget(dev, 4, 4, [&](UINT x, UINT y) { return 0xFF004080u | (uint32_t(red[y][x]) << 16); });
        Handle dst = makeTarget(dev, 2, 2, [](UINT, UINT) { return 0u; });
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst, 0, 0) == 0xFF194080u);  // 25
        CHECK(readPixel(dev, dst, 1, 0) == 0xFF024080u);  // 2
        CHECK(readPixel(dev, dst, 0, 1) == 0xFF004080u);  // 0
        CHECK(readPixel(dev, dst, 1, 1) == 0xFF024080u);  // 2
        // POINT: destination pixel i maps to source floor((i + 1/2) * 2) = 2i + 1.
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_POINT) == D3D_OK);
        CHECK(readPixel(dev, dst, 0, 0) >> 16 == (0xFF00u | red[1][1]));
        CHECK(readPixel(dev, dst, 1, 1) >> 16 == (0xFF00u | red[3][3]));
        CHECK(readPixel(dev, dst, 1, 0) >> 16 == (0xFF00u | red[1][3]));
    }

    SECTION("1:1 copies are exact with either filter") {
        auto colour = [](UINT x, UINT y) { return (x * 2654435761u) ^ (y * 40503u) ^ 0x5A5A5A5Au; };
        Handle src = makeTarget(dev, 5, 3, colour);
        Handle dst = makeTarget(dev, 5, 3, [](UINT, UINT) { return 0u; });
        for (D3DTEXTUREFILTERTYPE f : {D3DTEXF_NONE, D3DTEXF_POINT, D3DTEXF_LINEAR}) {
            REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, f) == D3D_OK);
            for (UINT y = 0; y < 3; ++y)
                for (UINT x = 0; x < 5; ++x) CHECK(readPixel(dev, dst, x, y) == colour(x, y));
        }
    }

    SECTION("2:1 reductions of random data: every byte is the 2x2 block's mean, ties to even") {
        auto colour = [](UINT x, UINT y) { return (x * 2654435761u + 7) ^ (y * 2246822519u) ^ (x * y * 374761393u); };
        for (D3DFORMAT fmt : {D3DFMT_A8R8G8B8, D3DFMT_X8R8G8B8}) {
            Handle src = makeTarget(dev, 10, 6, colour);
            Handle dst{};
            REQUIRE(dev.CreateRenderTarget(7, 5, fmt, 1, &dst) == D3D_OK);
            Handle srcFmt{};
            REQUIRE(dev.CreateRenderTarget(10, 6, fmt, 1, &srcFmt) == D3D_OK);
            REQUIRE(dev.StretchRect(src, nullptr, srcFmt, nullptr, D3DTEXF_POINT) == D3D_OK);  // 1:1 copy
            RECT sr{2, 0, 10, 6}, dr{1, 1, 5, 4};
            REQUIRE(dev.StretchRect(srcFmt, &sr, dst, &dr, D3DTEXF_LINEAR) == D3D_OK);
            for (UINT j = 0; j < 3; ++j)
                for (UINT i = 0; i < 4; ++i) {
                    uint32_t expect = 0;
                    for (int b = 0; b < 4; ++b) {
                        int sum = 0;
                        for (UINT dy = 0; dy < 2; ++dy)
                            for (UINT dx = 0; dx < 2; ++dx) {
                                uint32_t c = colour(2 + 2 * i + dx, 2 * j + dy);
                                if (fmt == D3DFMT_X8R8G8B8 && b == 3) c |= 0xFF000000u;
                                sum += int((c >> (8 * b)) & 0xFF);
                            }
                        const int q = sum / 4, r = sum % 4;
                        const int rounded = r < 2 ? q : r > 2 ? q + 1 : q + (q & 1);
                        expect |= uint32_t(rounded) << (8 * b);
                    }
                    INFO("format " << formatName(fmt) << " pixel " << i << ", " << j);
                    CHECK(readPixel(dev, dst, 1 + i, 1 + j) == expect);
                }
            CHECK(readPixel(dev, dst, 0, 0) == 0u);  // outside the rect
        }
    }

    SECTION("sub-rectangles, upscaling and edge clamping") {
        // Source row [0, 255] (red); 2 -> 4 linear: x = (i + 1/2)/2 - 1/2 = -0.25, 0.25, 0.75,
        // 1.25; taps clamp to the rect, so 0, 0.25 * 255 = 63.75 -> 64, 191.25 -> 191, 255.
        Handle src = makeTarget(dev, 4, 1, [](UINT x, UINT) { return x == 2 ? 0xFFFF0000u : 0xFF000000u; });
        Handle dst = makeTarget(dev, 6, 2, [](UINT, UINT) { return 0x11111111u; });
        RECT sr{1, 0, 3, 1}, dr{1, 1, 5, 2};
        REQUIRE(dev.StretchRect(src, &sr, dst, &dr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst, 1, 1) == 0xFF000000u);
        CHECK(readPixel(dev, dst, 2, 1) == 0xFF400000u);
        CHECK(readPixel(dev, dst, 3, 1) == 0xFFBF0000u);
        CHECK(readPixel(dev, dst, 4, 1) == 0xFFFF0000u);
        CHECK(readPixel(dev, dst, 0, 1) == 0x11111111u);  // outside the rect: untouched
        CHECK(readPixel(dev, dst, 5, 1) == 0x11111111u);
        CHECK(readPixel(dev, dst, 2, 0) == 0x11111111u);
    }

    SECTION("3 -> 2 and 8-bit weights") {
        // 3 -> 2: x = (i + 1/2) * 3/2 - 1/2 = 0.25, 1.75. Red [0, 100, 200]: 25, 175 exactly.
        Handle src = makeTarget(dev, 3, 1, [](UINT x, UINT) { return 0xFF000000u | (100u * x) << 16; });
        Handle dst = makeTarget(dev, 2, 1, [](UINT, UINT) { return 0u; });
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst, 0, 0) == 0xFF190000u);
        CHECK(readPixel(dev, dst, 1, 0) == 0xFFAF0000u);
        // 2 -> 7: pixel 1 has x = 1.5 * 2/7 - 1/2 = 3/7 - 1/2 < 0 -> pixel 2: x = 2.5*2/7 - 0.5 =
        // 3/14 = 0.2142857: fx8 weight round(0.2142857 * 256) = round(54.857) = 55, so red
        // 255 * 55/256 = 54.785 -> 55; exact (ideal) 255 * 3/14 = 54.643 -> 55 too. Pixel 3:
        // x = 3.5 * 2/7 - 0.5 = 0.5 exactly: 127.5 -> 128 (ties to even). Pixel 4: x = 11/14:
        // fx8 weight round(201.14) = 201, 255 * 201/256 = 200.21 -> 200; ideal 200.36 -> 200.
        Handle src2 = makeTarget(dev, 2, 1, [](UINT x, UINT) { return x ? 0xFFFF0000u : 0xFF000000u; });
        Handle dst2 = makeTarget(dev, 7, 1, [](UINT, UINT) { return 0u; });
        REQUIRE(dev.StretchRect(src2, nullptr, dst2, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst2, 0, 0) == 0xFF000000u);
        CHECK(readPixel(dev, dst2, 1, 0) == 0xFF000000u);
        CHECK(readPixel(dev, dst2, 2, 0) == 0xFF370000u);
        CHECK(readPixel(dev, dst2, 3, 0) == 0xFF800000u);
        CHECK(readPixel(dev, dst2, 4, 0) == 0xFFC80000u);
        CHECK(readPixel(dev, dst2, 6, 0) == 0xFFFF0000u);
        // Where 8-bit weights change the result: 3 -> 7 red [0, 0, 255], pixel 4: x = 4.5 * 3/7 -
        // 0.5 = 1.4285714 -> f = 3/7: fx8 weight round(109.714) = 110, 255 * 110/256 = 109.57 ->
        // 110; ideal 255 * 3/7 = 109.286 -> 109.
        Handle src3 = makeTarget(dev, 3, 1, [](UINT x, UINT) { return x == 2 ? 0xFFFF0000u : 0xFF000000u; });
        Handle dst3 = makeTarget(dev, 7, 1, [](UINT, UINT) { return 0u; });
        REQUIRE(dev.StretchRect(src3, nullptr, dst3, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(dev, dst3, 4, 0) == 0xFF6E0000u);
        DeviceOptions o;
        o.precision = ps11::Precision::Ideal;
        Device ideal(o);
        Handle s4 = makeTarget(ideal, 3, 1, [](UINT x, UINT) { return x == 2 ? 0xFFFF0000u : 0xFF000000u; });
        Handle d4 = makeTarget(ideal, 7, 1, [](UINT, UINT) { return 0u; });
        REQUIRE(ideal.StretchRect(s4, nullptr, d4, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        CHECK(readPixel(ideal, d4, 4, 0) == 0xFF6D0000u);
    }

    SECTION("format conversion into a float target") {
        Handle src = makeTarget(dev, 2, 2, [](UINT x, UINT y) { return 0xFF000000u | ((x + 2 * y) * 51u) << 16; });
        Handle dst{};
        REQUIRE(dev.CreateRenderTarget(1, 1, D3DFMT_R32F, 1, &dst) == D3D_OK);
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_LINEAR) == D3D_OK);
        // (0 + 51 + 102 + 153) / 4 = 76.5 bytes -> 76.5 / 255 = 0.3 exactly representable? as float
        CHECK(readFloat(dev, dst, 0, 0) == float(76.5 / 255.0));
        REQUIRE(dev.StretchRect(src, nullptr, dst, nullptr, D3DTEXF_POINT) == D3D_OK);
        CHECK(readFloat(dev, dst, 0, 0) == float(153.0 / 255.0));  // point picks (1, 1)
        // Unscaled into A32B32G32R32F (a fast path): every byte value, each channel, X8's alpha 1.
        for (D3DFORMAT from : {D3DFMT_A8R8G8B8, D3DFMT_X8R8G8B8}) {
            Handle bytes = makeTarget(
                dev, 16, 16, [](UINT x, UINT y) { const uint32_t b = y * 16 + x; return (b << 24) | ((255 - b) << 16) | (b << 8) | (b ^ 0x5a); },
                from);
            Handle f32{};
            REQUIRE(dev.CreateRenderTarget(16, 16, D3DFMT_A32B32G32R32F, 1, &f32) == D3D_OK);
            REQUIRE(dev.StretchRect(bytes, nullptr, f32, nullptr, D3DTEXF_LINEAR) == D3D_OK);
            int wrong = 0;
            for (UINT y = 0; y < 16; ++y)
                for (UINT x = 0; x < 16; ++x) {
                    const uint32_t b = y * 16 + x;
                    const double want[4] = {double(255 - b), double(b), double(b ^ 0x5a), from == D3DFMT_X8R8G8B8 ? 255.0 : double(b)};
                    for (UINT c = 0; c < 4; ++c) wrong += readFloat(dev, f32, x, y, c) != float(want[c] / 255.0);
                }
            CHECK(wrong == 0);
        }
        // And back (another fast path): nearest byte, ties to even, clamped, NaN 0.
        const float values[] = {0.0f, 1.0f, -0.5f, 2.0f, 0.5f / 255, 1.5f / 255, 2.5f / 255, 254.5f / 255,
                                 0.3f, 0.7f, float(NAN), float(INFINITY), -float(INFINITY), 1e-30f, 0.999f, 0.0019607f};
        const size_t nv = sizeof values / sizeof values[0];
        for (D3DFORMAT to : {D3DFMT_A8R8G8B8, D3DFMT_X8R8G8B8}) {
            Handle f32{}, bytes{};
            REQUIRE(dev.CreateRenderTarget(UINT(nv), 1, D3DFMT_A32B32G32R32F, 1, &f32) == D3D_OK);
            REQUIRE(dev.CreateRenderTarget(UINT(nv), 1, to, 1, &bytes) == D3D_OK);
            D3DLOCKED_RECT lr{};
            REQUIRE(dev.LockRect(f32, &lr, nullptr, 0) == D3D_OK);
            for (size_t i = 0; i < nv; ++i) {
                const float px[4] = {values[i], values[(i + 1) % nv], values[(i + 2) % nv], values[(i + 3) % nv]};
                std::memcpy(static_cast<uint8_t*>(lr.pBits) + i * 16, px, 16);
            }
            REQUIRE(dev.UnlockRect(f32) == D3D_OK);
            REQUIRE(dev.StretchRect(f32, nullptr, bytes, nullptr, D3DTEXF_POINT) == D3D_OK);
            auto byteOf = [](float v) {
                return std::isnan(v) ? 0u : uint32_t(std::nearbyint(std::clamp(double(v), 0.0, 1.0) * 255.0));
            };
            for (size_t i = 0; i < nv; ++i) {
                const uint32_t a = to == D3DFMT_X8R8G8B8 ? 255u : byteOf(values[(i + 3) % nv]);
                const uint32_t want = a << 24 | byteOf(values[i]) << 16 | byteOf(values[(i + 1) % nv]) << 8 | byteOf(values[(i + 2) % nv]);
                CHECK(readPixel(dev, bytes, UINT(i), 0) == want);
            }
        }
    }

    SECTION("into a render-target texture, which its sampler view then shows") {
        Handle src = makeTarget(dev, 2, 2, [](UINT, UINT) { return 0xFF336699u; });
        Handle tex{}, level{};
        REQUIRE(dev.CreateTexture(2, 2, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        auto before = dev.sampledTexture(tex);
        REQUIRE(before);
        CHECK(before->texelValue(0, 1, 1)[0] == 0.0f);
        REQUIRE(dev.StretchRect(src, nullptr, level, nullptr, D3DTEXF_POINT) == D3D_OK);
        auto after = dev.sampledTexture(tex);
        REQUIRE(after);
        CHECK(after != before);
        CHECK(after->texelValue(0, 1, 1)[0] == float(0x33 / 255.0));
        CHECK(dev.sampledTexture(tex) == after);  // cached until the next write
    }

    SECTION("errors") {
        Handle rt = makeTarget(dev, 4, 4, [](UINT, UINT) { return 0u; });
        Handle rt2 = makeTarget(dev, 4, 4, [](UINT, UINT) { return 0u; });
        Handle sys{}, a8{}, tex{}, level{};
        REQUIRE(dev.CreateOffscreenPlainSurface(4, 4, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
        REQUIRE(dev.CreateOffscreenPlainSurface(4, 4, D3DFMT_A8, D3DPOOL_DEFAULT, &a8) == D3D_OK);
        REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        CHECK(dev.StretchRect(rt, nullptr, rt, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(rt, nullptr, rt2, nullptr, D3DTEXF_ANISOTROPIC) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(rt, nullptr, sys, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(level, nullptr, rt2, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(rt, nullptr, a8, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.lastError().code == "E4104");
        RECT outside{0, 0, 5, 4};
        CHECK(dev.StretchRect(rt, &outside, rt2, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(contains(dev.lastError().message, "source rect (0, 0)-(5, 4)"));
        RECT inverted{2, 0, 1, 4};
        CHECK(dev.StretchRect(rt, nullptr, rt2, &inverted, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(tex, nullptr, rt2, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
        CHECK(dev.StretchRect(Handle(4242), nullptr, rt2, nullptr, D3DTEXF_POINT) == D3DERR_INVALIDCALL);
    }
}

TEST_CASE("device: GetRenderTargetData of a large target over two workers copies every byte", "[device]") {
    // 301x217: more rows than the workers' share and an odd width (the software renderer moves the
    // rows as an unscaled StretchRect over its workers).
    DeviceOptions o;
    o.software.threads = 2;
    Device dev(o);
    const UINT w = 301, h = 217;
    Handle rt{}, sys{};
    REQUIRE(dev.CreateRenderTarget(w, h, D3DFMT_A8R8G8B8, 1, &rt) == D3D_OK);
    std::mt19937 rng(5);
    std::vector<uint8_t> bytes(size_t(w) * h * 4);
    for (uint8_t& b : bytes) b = uint8_t(rng());
    D3DLOCKED_RECT lr{};
    REQUIRE(dev.LockRect(rt, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < h; ++y) std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &bytes[size_t(y) * w * 4], w * 4);
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);
    REQUIRE(dev.CreateOffscreenPlainSurface(w, h, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
    REQUIRE(dev.GetRenderTargetData(rt, sys) == D3D_OK);
    REQUIRE(dev.LockRect(sys, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    size_t wrong = 0;
    for (UINT y = 0; y < h; ++y)
        wrong += std::memcmp(static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch, &bytes[size_t(y) * w * 4], w * 4) != 0;
    REQUIRE(dev.UnlockRect(sys) == D3D_OK);
    CHECK(wrong == 0);
}

TEST_CASE("device: GetRenderTargetData copies into SYSTEMMEM", "[device]") {
    Device dev;
    Handle rt{}, sys{}, sysSmall{}, def{}, sysTex{}, sysLevel{};
    REQUIRE(dev.CreateRenderTarget(3, 2, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);  // not lockable
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    D3DRECT r{1, 0, 3, 1};
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF000080u, 1.0f, 0) == D3D_OK);
    REQUIRE(dev.Clear(1, &r, D3DCLEAR_TARGET, 0x80FF0000u, 1.0f, 0) == D3D_OK);
    REQUIRE(dev.CreateOffscreenPlainSurface(3, 2, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
    REQUIRE(dev.GetRenderTargetData(rt, sys) == D3D_OK);
    CHECK(readPixel(dev, sys, 0, 0) == 0xFF000080u);
    CHECK(readPixel(dev, sys, 2, 0) == 0x80FF0000u);
    CHECK(readPixel(dev, sys, 2, 1) == 0xFF000080u);
    REQUIRE(dev.CreateTexture(3, 2, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sysTex) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(sysTex, 0, &sysLevel) == D3D_OK);
    REQUIRE(dev.GetRenderTargetData(rt, sysLevel) == D3D_OK);
    CHECK(readPixel(dev, sysLevel, 1, 0) == 0x80FF0000u);

    REQUIRE(dev.CreateOffscreenPlainSurface(2, 2, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sysSmall) == D3D_OK);
    REQUIRE(dev.CreateOffscreenPlainSurface(3, 2, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &def) == D3D_OK);
    CHECK(dev.GetRenderTargetData(rt, sysSmall) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "destination is 2x2 A8R8G8B8, the render target 3x2 A8R8G8B8"));
    CHECK(dev.GetRenderTargetData(rt, def) == D3DERR_INVALIDCALL);
    CHECK(dev.GetRenderTargetData(sys, sysLevel) == D3DERR_INVALIDCALL);  // source not a render target
    CHECK(dev.GetRenderTargetData(rt, Handle::Null) == D3DERR_INVALIDCALL);
}

TEST_CASE("device: LINEAR StretchRect between 8-bit targets equals the weighted sum, any scale and rect", "[device]") {
    // The filter written out from the one tap mapping (emu/blit.h stretchTaps): fx weights k/256
    // (the double sum exact), the float profiles' weights rem/den; rounded to nearest, ties to
    // even; X8's alpha 255.
    std::mt19937 rng(11);
    for (int round = 0; round < 80; ++round) {
        DeviceOptions o;
        o.software.threads = 1 + int(rng() % 2);
        const bool fixedPoint = round % 2 == 0;
        o.precision = fixedPoint ? ps11::Precision::Fx8 : ps11::Precision::Float;
        Device dev(o);
        const D3DFORMAT fmt = rng() % 3 ? D3DFMT_A8R8G8B8 : D3DFMT_X8R8G8B8;
        const UINT sw = 1 + rng() % 70, sh = 1 + rng() % 70, dw = 1 + rng() % 70, dh = 1 + rng() % 90;
        std::vector<uint32_t> texels(size_t(sw) * sh);
        for (uint32_t& t : texels) t = rng();
        Handle src = makeTarget(dev, sw, sh, [&](UINT x, UINT y) { return texels[size_t(y) * sw + x]; }, fmt);
        Handle dst = makeTarget(dev, dw, dh, [](UINT, UINT) { return 0x12345678u; }, fmt);
        const RandomStretch rs = randomStretch(rng, sw, sh, dw, dh, fixedPoint);
        const RECT &sr = rs.sr, &dr = rs.dr;
        const std::vector<StretchTap>&tx = rs.tx, &ty = rs.ty;
        INFO("round " << round << ": " << sw << "x" << sh << " -> " << dw << "x" << dh);
        REQUIRE(dev.StretchRect(src, &sr, dst, &dr, D3DTEXF_LINEAR) == D3D_OK);
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(dst, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
        int wrong = 0;
        for (UINT y = 0; y < dh; ++y)
            for (UINT x = 0; x < dw; ++x) {
                uint32_t got;
                std::memcpy(&got, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, 4);
                const bool inside = LONG(x) >= dr.left && LONG(x) < dr.right && LONG(y) >= dr.top && LONG(y) < dr.bottom;
                uint32_t want = 0x12345678u;  // outside the rect: as written
                if (inside) {
                    const StretchTap& a = tx[size_t(LONG(x) - dr.left)];
                    const StretchTap& b = ty[size_t(LONG(y) - dr.top)];
                    want = 0;
                    for (int k = 0; k < 4; ++k) {
                        auto byte = [&](int64_t sx, int64_t sy) { return double((texels[size_t(sy) * sw + size_t(sx)] >> (8 * k)) & 0xFF); };
                        const double v = (1 - b.w1) * ((1 - a.w1) * byte(a.i0, b.i0) + a.w1 * byte(a.i1, b.i0)) +
                                         b.w1 * ((1 - a.w1) * byte(a.i0, b.i1) + a.w1 * byte(a.i1, b.i1));
                        const uint32_t r = k == 3 && fmt == D3DFMT_X8R8G8B8 ? 255u : uint32_t(std::nearbyint(v));
                        want |= r << (8 * k);
                    }
                }
                wrong += got != want;
            }
        REQUIRE(dev.UnlockRect(dst) == D3D_OK);
        CHECK(wrong == 0);
    }
}

TEST_CASE("device: StretchRect from 8-bit words into A32B32G32R32F is the sum over bytes, over 255, as float", "[device]") {
    // The ideal profile's reductions of an 8-bit scene: A8R8G8B8 or X8R8G8B8 into a float target at
    // any scale and rect, LINEAR (the tap mapping's weights, fx ones too, the sum over the bytes in
    // the documented order, X8's alpha the byte 255) and POINT, each value float(v / 255).
    std::mt19937 rng(13);
    for (int round = 0; round < 60; ++round) {
        DeviceOptions o;
        o.software.threads = 1 + int(rng() % 2);
        const bool fixedPoint = round % 4 == 0;
        o.precision = fixedPoint ? ps11::Precision::Fx8 : ps11::Precision::Ideal;
        Device dev(o);
        const D3DFORMAT fmt = rng() % 2 ? D3DFMT_A8R8G8B8 : D3DFMT_X8R8G8B8;
        const bool linear = round % 3 != 2;
        const UINT sw = 1 + rng() % 70, sh = 1 + rng() % 70, dw = 1 + rng() % 70, dh = 1 + rng() % 90;
        std::vector<uint32_t> texels(size_t(sw) * sh);
        for (uint32_t& t : texels) t = rng();
        Handle src = makeTarget(dev, sw, sh, [&](UINT x, UINT y) { return texels[size_t(y) * sw + x]; }, fmt);
        Handle dst{};
        REQUIRE(dev.CreateRenderTarget(dw, dh, D3DFMT_A32B32G32R32F, 1, &dst) == D3D_OK);
        RandomStretch rs = randomStretch(rng, sw, sh, dw, dh, fixedPoint);
        if (!linear) {
            StretchCall call;
            call.sourceRect = PixelBox{rs.sr.left, rs.sr.top, rs.sr.right, rs.sr.bottom};
            call.destRect = PixelBox{rs.dr.left, rs.dr.top, rs.dr.right, rs.dr.bottom};
            rs.tx = stretchTaps(call, true);
            rs.ty = stretchTaps(call, false);
        }
        const RECT &sr = rs.sr, &dr = rs.dr;
        INFO("round " << round << ": " << sw << "x" << sh << " -> " << dw << "x" << dh << (linear ? " LINEAR" : " POINT"));
        REQUIRE(dev.StretchRect(src, &sr, dst, &dr, linear ? D3DTEXF_LINEAR : D3DTEXF_POINT) == D3D_OK);
        int wrong = 0, inside = 0;
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(dst, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
        for (UINT y = UINT(dr.top); y < UINT(dr.bottom); ++y)
            for (UINT x = UINT(dr.left); x < UINT(dr.right); ++x) {
                const StretchTap& a = rs.tx[size_t(LONG(x) - dr.left)];
                const StretchTap& b = rs.ty[size_t(LONG(y) - dr.top)];
                for (UINT k = 0; k < 4; ++k) {  // r g b a: bytes 2 1 0 3 of the word
                    auto at = [&](int64_t sx, int64_t sy) {
                        if (k == 3 && fmt == D3DFMT_X8R8G8B8) return 255.0;
                        return double((texels[size_t(sy) * sw + size_t(sx)] >> (8 * (k == 3 ? 3 : 2 - k))) & 0xFF);
                    };
                    const double v = !linear ? at(a.i0, b.i0)
                                             : (1 - b.w1) * ((1 - a.w1) * at(a.i0, b.i0) + a.w1 * at(a.i1, b.i0)) +
                                                   b.w1 * ((1 - a.w1) * at(a.i0, b.i1) + a.w1 * at(a.i1, b.i1));
                    const float want = float(v / 255.0);
                    float got;
                    std::memcpy(&got, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * 16 + 4 * k, 4);
                    wrong += std::memcmp(&got, &want, 4) != 0;
                    ++inside;
                }
            }
        REQUIRE(dev.UnlockRect(dst) == D3D_OK);
        CHECK(inside > 0);
        CHECK(wrong == 0);
    }
}

TEST_CASE("device: LINEAR StretchRect between A32B32G32R32F targets is the double sum rounded to float", "[device]") {
    // The ideal profile's reductions: the tap mapping's weights (fx ones too), the sum in double
    // in the documented order, stored as float; values of any sign and size, infinities, NaN.
    std::mt19937 rng(12);
    const float specials[] = {0.0f, -0.0f, 1.0f, 1e30f, -3e38f, 1e-40f, float(INFINITY), float(NAN)};
    for (int round = 0; round < 40; ++round) {
        DeviceOptions o;
        o.software.threads = 1 + int(rng() % 2);
        const bool fixedPoint = round % 4 == 0;
        o.precision = fixedPoint ? ps11::Precision::Fx8 : ps11::Precision::Ideal;
        Device dev(o);
        const UINT sw = 1 + rng() % 70, sh = 1 + rng() % 70, dw = 1 + rng() % 70, dh = 1 + rng() % 90;
        std::vector<float> texels(size_t(sw) * sh * 4);
        std::uniform_real_distribution<float> value(-2.0f, 2.0f);
        for (float& t : texels) t = rng() % 16 ? value(rng) : specials[rng() % 8];
        Handle src{}, dst{};
        REQUIRE(dev.CreateRenderTarget(sw, sh, D3DFMT_A32B32G32R32F, 1, &src) == D3D_OK);
        REQUIRE(dev.CreateRenderTarget(dw, dh, D3DFMT_A32B32G32R32F, 1, &dst) == D3D_OK);
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(src, &lr, nullptr, 0) == D3D_OK);
        for (UINT y = 0; y < sh; ++y)
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &texels[size_t(y) * sw * 4], size_t(sw) * 16);
        REQUIRE(dev.UnlockRect(src) == D3D_OK);
        const RandomStretch rs = randomStretch(rng, sw, sh, dw, dh, fixedPoint);
        const RECT &sr = rs.sr, &dr = rs.dr;
        const std::vector<StretchTap>&tx = rs.tx, &ty = rs.ty;
        INFO("round " << round << ": " << sw << "x" << sh << " -> " << dw << "x" << dh);
        REQUIRE(dev.StretchRect(src, &sr, dst, &dr, D3DTEXF_LINEAR) == D3D_OK);
        int wrong = 0, inside = 0;
        REQUIRE(dev.LockRect(dst, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
        for (UINT y = UINT(dr.top); y < UINT(dr.bottom); ++y)
            for (UINT x = UINT(dr.left); x < UINT(dr.right); ++x) {
                const StretchTap& a = tx[size_t(LONG(x) - dr.left)];
                const StretchTap& b = ty[size_t(LONG(y) - dr.top)];
                for (UINT k = 0; k < 4; ++k) {
                    auto at = [&](int64_t sx, int64_t sy) {
                        return double(texels[(size_t(sy) * sw + size_t(sx)) * 4 + k]);
                    };
                    const float want = float((1 - b.w1) * ((1 - a.w1) * at(a.i0, b.i0) + a.w1 * at(a.i1, b.i0)) +
                                             b.w1 * ((1 - a.w1) * at(a.i0, b.i1) + a.w1 * at(a.i1, b.i1)));
                    float got;
                    std::memcpy(&got, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * 16 + 4 * k, 4);
                    // (A NaN's payload follows the operands' order, which the compiler may swap.)
                    wrong += std::memcmp(&got, &want, 4) != 0 && !(std::isnan(got) && std::isnan(want));
                    ++inside;
                }
            }
        REQUIRE(dev.UnlockRect(dst) == D3D_OK);
        CHECK(inside > 0);
        CHECK(wrong == 0);
    }
}
