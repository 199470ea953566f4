// StretchRect put off (SoftwareRendererOptions::putOffCopies, docs/device.md "StretchRect"): the
// software renderer makes a whole-surface copy when something reads or writes its destination or
// writes its source, and a draw into the destination copies each band of rows just before it
// draws them, or (the fx row path, tile by tile) makes the copy as it draws. Every sequence here
// runs on a device that puts copies off and on one that makes them at once, and everything read
// back must be byte for byte the same.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "emu/device.h"
#include "emu/fullscreen.h"
#include "runner/random_composite.h"

using namespace emu;

namespace {

// Above kComparedResourceBytes (64 KB): the device lets the renderer put copies into it off.
constexpr UINT kW = 160, kH = 120;

// The surface's kW × kH pixels, row after row.
std::vector<uint8_t> surfaceBytes(Device& dev, Handle h) {
    std::vector<uint8_t> out;
    REQUIRE(dev.readSurface(h, [&](const D3DLOCKED_RECT& lr) {
        for (UINT y = 0; y < kH; ++y) {
            const uint8_t* row = static_cast<const uint8_t*>(lr.pBits) + y * UINT(lr.Pitch);
            out.insert(out.end(), row, row + kW * 4);
        }
    }) == D3D_OK);
    return out;
}

struct Script {
    Device dev;
    Handle a{}, b{}, c{}, x{}, tex{}, texLevel{}, constant{}, sample{};
    std::vector<std::vector<uint8_t>> seen;  // every read, in order

    explicit Script(bool putOff) : dev([&] {
        DeviceOptions o;
        o.software.threads = 2;
        o.software.putOffCopies = putOff;
        return o;
    }()) {
        for (Handle* h : {&a, &b, &c, &x}) REQUIRE(dev.CreateRenderTarget(kW, kH, D3DFMT_A8R8G8B8, 1, h) == D3D_OK);
        REQUIRE(dev.CreateTexture(kW, kH, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &texLevel) == D3D_OK);
        std::mt19937 rng(3);
        for (Handle h : {a, b, c, x}) fill(h, rng);
        REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ndef c0, 0.2, 0.1, 0.3, 0.4\nmov r0, c0\n", &constant) == D3D_OK);
        REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\nmov r0, t0\n", &sample) == D3D_OK);
    }
    void fill(Handle h, std::mt19937& rng) {
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(h, &lr, nullptr, 0) == D3D_OK);
        for (UINT y = 0; y < kH; ++y)
            for (UINT i = 0; i < kW * 4; ++i) static_cast<uint8_t*>(lr.pBits)[y * UINT(lr.Pitch) + i] = uint8_t(rng());
        REQUIRE(dev.UnlockRect(h) == D3D_OK);
    }
    std::vector<uint8_t> read(Handle h) {
        seen.push_back(surfaceBytes(dev, h));
        return seen.back();
    }
    std::vector<uint8_t> lockRead(Handle h) {
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(h, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
        std::vector<uint8_t> out;
        for (UINT y = 0; y < kH; ++y) {
            const uint8_t* row = static_cast<const uint8_t*>(lr.pBits) + y * UINT(lr.Pitch);
            out.insert(out.end(), row, row + kW * 4);
        }
        REQUIRE(dev.UnlockRect(h) == D3D_OK);
        seen.push_back(out);
        return out;
    }
    void copy(Handle from, Handle to) { REQUIRE(dev.StretchRect(from, nullptr, to, nullptr, D3DTEXF_POINT) == D3D_OK); }
    // Rows [y0, y1) of `target`: the constant, added (ONE, ONE) or replacing.
    void drawConstant(Handle target, float y0, float y1, bool add) {
        REQUIRE(dev.SetRenderTarget(0, target) == D3D_OK);
        REQUIRE(dev.SetTexture(0, Handle::Null) == D3D_OK);
        REQUIRE(dev.SetPixelShader(constant) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, add ? 1 : 0) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE) == D3D_OK);
        REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
        const auto q = halfPixelQuad(0, y0, float(kW), y1, {});
        REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, q.data(), sizeof(QuadVertex)) == D3D_OK);
    }
    // The texture drawn 1:1 into `target`.
    void drawTexture(Handle target) {
        REQUIRE(dev.SetRenderTarget(0, target) == D3D_OK);
        REQUIRE(dev.SetPixelShader(sample) == D3D_OK);
        REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 0) == D3D_OK);
        REQUIRE(drawFullscreenQuad(dev, {}) == D3D_OK);
        REQUIRE(dev.SetTexture(0, Handle::Null) == D3D_OK);
    }
};

// Runs `steps` on both devices; everything they read must be the same.
template <class F>
void bothWays(F steps) {
    Script on(true), off(false);
    steps(on);
    steps(off);
    REQUIRE(on.seen.size() == off.seen.size());
    for (size_t i = 0; i < on.seen.size(); ++i) {
        INFO("read " << i);
        CHECK(on.seen[i] == off.seen[i]);
    }
}

}  // namespace

TEST_CASE("put-off copies: the destination reads as the copy, however it is read", "[device][putoff]") {
    bothWays([](Script& s) {
        const std::vector<uint8_t> a = s.read(s.a);
        const uint64_t before = s.dev.contentGeneration(s.b);
        s.copy(s.a, s.b);
        CHECK(s.dev.contentGeneration(s.b) != before);  // a new generation at the call, as a copy made
        CHECK(s.read(s.b) == a);                         // readSurface
        s.copy(s.x, s.c);
        s.lockRead(s.c);  // LockRect
        s.copy(s.a, s.texLevel);
        s.drawTexture(s.c);  // sampled by a draw
        s.read(s.c);
        Handle sys{};
        REQUIRE(s.dev.CreateOffscreenPlainSurface(kW, kH, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
        s.copy(s.x, s.b);
        REQUIRE(s.dev.GetRenderTargetData(s.b, sys) == D3D_OK);  // read back
        s.lockRead(sys);
    });
}

TEST_CASE("put-off copies: writing the source first makes the copy of what it held", "[device][putoff]") {
    bothWays([](Script& s) {
        const std::vector<uint8_t> a = s.read(s.a);
        s.copy(s.a, s.b);
        REQUIRE(s.dev.SetRenderTarget(0, s.a) == D3D_OK);
        REQUIRE(s.dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xff102030, 1, 0) == D3D_OK);  // a clear of the source
        CHECK(s.read(s.b) == a);
        s.copy(s.b, s.c);
        s.drawConstant(s.b, 0, float(kH), false);  // a draw into the source
        CHECK(s.read(s.c) == a);
        s.copy(s.c, s.x);
        std::mt19937 rng(9);
        s.fill(s.c, rng);  // a lock of the source
        CHECK(s.read(s.x) == a);
        s.copy(s.x, s.b);
        s.copy(s.c, s.x);  // a copy into the source
        CHECK(s.read(s.b) == a);
        s.copy(s.x, s.b);
        CHECK(s.dev.Release(s.x) == D3D_OK);  // the source released
        s.read(s.b);
    });
}

TEST_CASE("put-off copies: draws into the destination copy their bands first, and the rest after", "[device][putoff]") {
    bothWays([](Script& s) {
        // Added over some rows (the bands the draw reaches and the ones it does not), over all of
        // them, replacing some, and a mesh of more triangles than a chunk (the copy made first).
        s.copy(s.a, s.b);
        s.drawConstant(s.b, 37, 83, true);
        s.read(s.b);
        s.copy(s.a, s.b);
        s.drawConstant(s.b, 0, float(kH), true);
        s.read(s.b);
        s.copy(s.a, s.b);
        s.drawConstant(s.b, 5, 6, false);
        s.read(s.b);
        s.copy(s.a, s.b);
        s.drawConstant(s.b, float(kH) + 10, float(kH) + 20, true);  // nothing drawn: the copy still lands
        s.read(s.b);
        s.copy(s.a, s.b);
        std::vector<QuadVertex> v;
        for (int i = 0; i < 1500; ++i) {
            const float x0 = float(i % 150), y0 = float((i / 150) * 11);
            const auto q = halfPixelQuad(x0, y0, x0 + 3, y0 + 4, {});
            v.insert(v.end(), {q[0], q[1], q[2]});
        }
        REQUIRE(s.dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
        REQUIRE(s.dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 1500, v.data(), sizeof(QuadVertex)) == D3D_OK);
        s.read(s.b);
        // Fewer triangles than a chunk, whose row tables pass the column budget (64 target widths):
        // drawn in parts, each band copied once, before the first part that reaches it.
        s.copy(s.a, s.b);
        std::vector<QuadVertex> w;
        for (int i = 0; i < 480; ++i) {
            const float x0 = float((i * 37) % 120), y0 = float((i * 53) % 110);
            const auto q = halfPixelQuad(x0, y0, x0 + 40, y0 + 9, {});
            for (int k : {0, 1, 2, 2, 1, 3}) w.push_back(q[size_t(k)]);
        }
        REQUIRE(s.dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 960, w.data(), sizeof(QuadVertex)) == D3D_OK);
        s.read(s.b);
        // A partial clear of the destination, a whole copy over a copy put off, then part of one.
        s.copy(s.a, s.b);
        REQUIRE(s.dev.SetRenderTarget(0, s.b) == D3D_OK);
        const D3DRECT r{10, 20, 50, 60};
        REQUIRE(s.dev.Clear(1, &r, D3DCLEAR_TARGET, 0xff0000ff, 1, 0) == D3D_OK);
        s.read(s.b);
        s.copy(s.a, s.b);
        s.copy(s.c, s.b);
        s.read(s.b);
        s.copy(s.a, s.b);
        const RECT part{3, 4, 40, 50};
        REQUIRE(s.dev.StretchRect(s.c, &part, s.b, &part, D3DTEXF_POINT) == D3D_OK);
        s.read(s.b);
        // The destination released with its copy put off.
        s.copy(s.a, s.c);
        CHECK(s.dev.Release(s.c) == D3D_OK);
        s.read(s.a);
    });
}

TEST_CASE("put-off copies: the device says which copies were put off", "[device][putoff]") {
    for (const bool putOff : {true, false}) {
        INFO("putOffCopies " << putOff);
        Script s(putOff);
        s.copy(s.a, s.b);  // whole, above 64 KB
        CHECK(s.dev.lastStretchPutOff() == putOff);
        const RECT part{0, 0, 40, 40};
        REQUIRE(s.dev.StretchRect(s.a, &part, s.c, &part, D3DTEXF_POINT) == D3D_OK);  // part of the destination
        CHECK_FALSE(s.dev.lastStretchPutOff());
        Handle small{}, small2{};
        REQUIRE(s.dev.CreateRenderTarget(64, 64, D3DFMT_A8R8G8B8, 1, &small) == D3D_OK);  // 16 KB: compared by bytes
        REQUIRE(s.dev.CreateRenderTarget(64, 64, D3DFMT_A8R8G8B8, 1, &small2) == D3D_OK);
        s.copy(small, small2);
        CHECK_FALSE(s.dev.lastStretchPutOff());
        s.copy(s.a, s.x);
        CHECK(s.dev.lastStretchPutOff() == putOff);
    }
}

TEST_CASE("put-off copies: a magnified ONE/ONE composite over one, tiled or not, fx8 and fx12", "[device][putoff]") {
    // The glare composites' case: the scene copied into the target, put off, then a texture a
    // quarter of the size added over every pixel. Its top rows are black: their tiles are
    // skipped, the others shaded; with tile skipping off every one is. Against the same on a
    // device that makes copies at once.
    for (const ps11::Precision p : {ps11::Precision::Fx8, ps11::Precision::Fx12})
        for (const bool skip : {true, false}) {
            INFO(ps11::precisionName(p) << (skip ? "" : ", tiles not skipped"));
            std::vector<std::vector<uint8_t>> seen[2];
            for (const bool putOff : {true, false}) {
                Device dev(ps11test::compositeDeviceOptions(p, skip, putOff));
                Handle scene{}, out{}, glow{}, glowLevel{}, sample{};
                REQUIRE(dev.CreateRenderTarget(kW, kH, D3DFMT_A8R8G8B8, 1, &scene) == D3D_OK);
                REQUIRE(dev.CreateRenderTarget(kW, kH, D3DFMT_A8R8G8B8, 1, &out) == D3D_OK);
                REQUIRE(dev.CreateTexture(kW / 4, kH / 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &glow) == D3D_OK);
                REQUIRE(dev.GetSurfaceLevel(glow, 0, &glowLevel) == D3D_OK);
                REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\nmov r0, t0\n", &sample) == D3D_OK);
                std::mt19937 rng(11);
                for (int frame = 0; frame < 3; ++frame) {
                    for (const Handle h : {scene, glowLevel}) {
                        const bool isGlow = h == glowLevel;
                        const UINT w = isGlow ? kW / 4 : kW, hh = isGlow ? kH / 4 : kH;
                        D3DLOCKED_RECT lr{};
                        REQUIRE(dev.LockRect(h, &lr, nullptr, 0) == D3D_OK);
                        for (UINT y = 0; y < hh; ++y)
                            for (UINT i = 0; i < w * 4; ++i)
                                static_cast<uint8_t*>(lr.pBits)[y * UINT(lr.Pitch) + i] =
                                    isGlow && y < hh / 2 + UINT(frame) ? 0 : uint8_t(rng());
                        REQUIRE(dev.UnlockRect(h) == D3D_OK);
                    }
                    REQUIRE(dev.StretchRect(scene, nullptr, out, nullptr, D3DTEXF_POINT) == D3D_OK);
                    REQUIRE(dev.SetRenderTarget(0, out) == D3D_OK);
                    REQUIRE(dev.SetPixelShader(sample) == D3D_OK);
                    REQUIRE(dev.SetTexture(0, glow) == D3D_OK);
                    REQUIRE(dev.SetSamplerState(0, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR) == D3D_OK);
                    REQUIRE(dev.SetSamplerState(0, D3DSAMP_MINFILTER, D3DTEXF_LINEAR) == D3D_OK);
                    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
                    REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE) == D3D_OK);
                    REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE) == D3D_OK);
                    REQUIRE(drawFullscreenQuad(dev, {}) == D3D_OK);
                    REQUIRE(dev.SetTexture(0, Handle::Null) == D3D_OK);
                    seen[putOff ? 0 : 1].push_back(surfaceBytes(dev, out));
                }
            }
            REQUIRE(seen[0].size() == seen[1].size());
            for (size_t i = 0; i < seen[0].size(); ++i) {
                INFO("frame " << i);
                CHECK(seen[0][i] == seen[1][i]);
            }
        }
}

TEST_CASE("put-off copies: a draw that makes the copy as it draws equals the copy made first", "[device][putoff]") {
    // A whole copy of one 8-bit format put off into the target of a draw the row path draws tile
    // by tile: the draw makes the copy itself (RowSource) — its direct stores of copied and filled
    // windows read the source's words where nothing is drawn yet, every other write copies its
    // columns first, and the rest of each row is copied after. 100 random cases
    // (runner/random_composite.h: sizes that end bands and groups anywhere, A8R8G8B8 and X8R8G8B8,
    // the scene now and then in the other one, a texture of zero, constant and random blocks at
    // 1× to 8× magnification, programs that copy, fill, shade or add zero, ONE/ONE, none or
    // SRCALPHA/INVSRCALPHA, fx8 and fx12, tiles skipped or not, one quad, a part of the target or
    // two overlapping ones), each then drawn again without a copy (the copy landed). Against a
    // device that makes copies at once, and one that draws 2×2 quads with the reference sampler.
    std::mt19937 rng(20261204);
    const std::function<uint32_t()> next = [&] { return uint32_t(rng()); };
    for (int i = 0; i < 100; ++i) {
        const ps11test::CompositeCase c = ps11test::randomComposite(next);
        INFO("case " << i << ": " << c.describe());
        std::vector<uint8_t> seen[3];
        std::string error;
        bool putOff = false;
        REQUIRE(ps11test::drawComposite(c, ps11test::compositeDeviceOptions(c, true), seen[0], error, &putOff));
        REQUIRE(putOff);
        REQUIRE(ps11test::drawComposite(c, ps11test::compositeDeviceOptions(c, false), seen[1], error));
        REQUIRE(ps11test::drawComposite(c, ps11test::compositeDeviceOptions(c, true, false), seen[2], error));
        REQUIRE(seen[0] == seen[1]);
        REQUIRE(seen[0] == seen[2]);
    }
}
