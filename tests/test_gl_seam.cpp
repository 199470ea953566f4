// The renderer seam with a renderer that keeps copies (emu/renderer.h, emu/gl/gl_renderer.h):
// Clear and StretchRect done on the GL side equal the software renderer's byte for byte; the
// front's locks, GetRenderTargetData and sampling see what the GL side drew; surfaces cross only
// when the front's contents are newer or the front asks; a glare frame on GL uploads its input
// once and reads its result back once; native mode draws within reach of the emulated card.
#include <catch2/catch.hpp>

#include <cstring>
#include <random>
#include <vector>

#include "emu/device.h"
#include "emu/fullscreen.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "runner/gl_backend.h"

using namespace emu;

namespace {

DeviceOptions glOptions(bool native, std::optional<ps11::Precision> precision = std::nullopt) {
    std::string error;
    DeviceOptions o;
    o.renderer = ps11test::glRendererFactory("", error, native);
    INFO(error);
    REQUIRE(o.renderer);
    o.precision = precision;
    return o;
}

std::vector<uint8_t> lockedBytes(Device& dev, Handle s) {
    D3DSURFACE_DESC desc{};
    REQUIRE(dev.GetDesc(s, &desc) == D3D_OK);
    const UINT bpp = formatInfo(desc.Format)->bytes;
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(s, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    std::vector<uint8_t> out(size_t(desc.Width) * desc.Height * bpp);
    for (UINT y = 0; y < desc.Height; ++y)
        std::memcpy(&out[y * desc.Width * bpp], static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, desc.Width * bpp);
    REQUIRE(dev.UnlockRect(s) == D3D_OK);
    return out;
}

void fillRandom(Device& dev, Handle s, std::mt19937& rng, bool floats) {
    D3DSURFACE_DESC desc{};
    REQUIRE(dev.GetDesc(s, &desc) == D3D_OK);
    const UINT bpp = formatInfo(desc.Format)->bytes;
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(s, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < desc.Height; ++y) {
        uint8_t* row = static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch;
        if (floats) {
            for (UINT i = 0; i < desc.Width * bpp / 4; ++i) {
                const float v = float(rng() % 1000) / 700.0f;
                std::memcpy(row + 4 * i, &v, 4);
            }
        } else {
            for (UINT i = 0; i < desc.Width * bpp; ++i) row[i] = uint8_t(rng());
        }
    }
    REQUIRE(dev.UnlockRect(s) == D3D_OK);
}

RECT randomRect(std::mt19937& rng, UINT w, UINT h) {
    const LONG x0 = LONG(rng() % w), y0 = LONG(rng() % h);
    const LONG x1 = x0 + 1 + LONG(rng() % (w - UINT(x0))), y1 = y0 + 1 + LONG(rng() % (h - UINT(y0)));
    return RECT{x0, y0, x1, y1};
}

// The same calls on one device: random contents, clears of random rects (some under a scissor),
// stretches of random rects with either filter; returns the destination's bytes.
std::vector<uint8_t> blitSequence(Device& dev, uint32_t seed, D3DFORMAT format) {
    std::mt19937 rng(seed);
    const bool floats = format != D3DFMT_A8R8G8B8 && format != D3DFMT_X8R8G8B8;
    const UINT sw = 5 + rng() % 60, sh = 5 + rng() % 40, dw = 5 + rng() % 60, dh = 5 + rng() % 40;
    Handle a{}, b{}, ds{};
    REQUIRE(dev.CreateRenderTarget(sw, sh, format, 1, &a) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(dw, dh, format, 1, &b) == D3D_OK);
    // A lockable depth format, so its cleared words can be compared too.
    REQUIRE(dev.CreateDepthStencilSurface(dw, dh, D3DFMT_D32F_LOCKABLE, &ds) == D3D_OK);
    fillRandom(dev, a, rng, floats);
    fillRandom(dev, b, rng, floats);
    REQUIRE(dev.SetRenderTarget(0, b) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(ds) == D3D_OK);
    for (int step = 0; step < 6; ++step) {
        if (rng() % 2) {
            const RECT r = randomRect(rng, dw, dh);
            const D3DRECT rect{r.left, r.top, r.right, r.bottom};
            const bool scissor = rng() % 3 == 0;
            dev.SetRenderState(D3DRS_SCISSORTESTENABLE, scissor);
            if (scissor) {
                const RECT sc = randomRect(rng, dw, dh);
                dev.SetScissorRect(&sc);
            }
            const DWORD flags = (rng() % 4 ? D3DCLEAR_TARGET : 0) | (rng() % 2 ? D3DCLEAR_ZBUFFER : 0);
            if (flags == 0) continue;
            REQUIRE(dev.Clear(rng() % 2 ? 1 : 0, &rect, flags, D3DCOLOR(rng()), float(rng() % 100) / 99.0f,
                              DWORD(rng() % 256)) == D3D_OK);
        } else {
            const RECT s = randomRect(rng, sw, sh), d = randomRect(rng, dw, dh);
            const D3DTEXTUREFILTERTYPE filter = rng() % 2 ? D3DTEXF_LINEAR : D3DTEXF_POINT;
            REQUIRE(dev.StretchRect(a, &s, b, &d, filter) == D3D_OK);
        }
    }
    std::vector<uint8_t> out = lockedBytes(dev, b);
    const std::vector<uint8_t> depth = lockedBytes(dev, ds);
    out.insert(out.end(), depth.begin(), depth.end());
    return out;
}

}  // namespace

TEST_CASE("gl renderer: Clear and StretchRect on the GL side equal the software renderer's byte for byte", "[gl]") {
    for (D3DFORMAT format : {D3DFMT_A8R8G8B8, D3DFMT_X8R8G8B8, D3DFMT_A16B16G16R16F, D3DFMT_R32F})
        for (ps11::Precision p : {ps11::Precision::Fx8, ps11::Precision::Float})
            for (uint32_t seed = 1; seed <= 12; ++seed) {
                INFO("format " << formatInfo(format)->name << ", seed " << seed << ", profile " << int(p));
                DeviceOptions so;
                so.precision = p;
                Device soft(so);
                Device gl(glOptions(false, p));
                CHECK(blitSequence(soft, seed, format) == blitSequence(gl, seed, format));
            }
}

TEST_CASE("gl renderer: surfaces stay on the GL side until the front asks, and the front's writes reach it", "[gl]") {
    for (bool native : {false, true}) {
        INFO((native ? "native" : "exact"));
        Device dev(glOptions(native));
        Handle tex{}, level{}, rt{}, ps{};
        REQUIRE(dev.CreateTexture(16, 16, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        REQUIRE(dev.CreateRenderTarget(16, 16, D3DFMT_A8R8G8B8, 1, &rt) == D3D_OK);
        // Draw into the texture, then sample it into the render target: nothing crosses.
        REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xff336699, 0, 0) == D3D_OK);
        REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\nmov r0, t0\n", &ps) == D3D_OK);
        REQUIRE(dev.SetPixelShader(ps) == D3D_OK);
        REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
        REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
        REQUIRE(drawFullscreenQuad(dev, {QuadCoords{0, 0, 1, 1}}, 0xffffffff) == D3D_OK);
        const TransferStats t0 = dev.transfers();
        CHECK(t0.readBacks == 0);
        CHECK(t0.uploads <= 2);  // each surface's first contents, at most
        // readSurface of the texture cleared on the GL side (not lockable): one read-back, the
        // cleared colour; a second read of unchanged contents crosses nothing.
        for (int pass = 0; pass < 2; ++pass) {
            uint32_t cleared = 0;
            REQUIRE(dev.readSurface(level, [&](const D3DLOCKED_RECT& lr) { std::memcpy(&cleared, lr.pBits, 4); }) == D3D_OK);
            CHECK(cleared == 0xff336699u);
            CHECK(dev.transfers().readBacks == 1);
        }
        // The front asks for the render target: one read-back more, the drawn colour.
        const std::vector<uint8_t> px = lockedBytes(dev, rt);
        CHECK(dev.transfers().readBacks == 2);
        CHECK(px[0] == 0x99);
        CHECK(px[1] == 0x66);
        CHECK(px[2] == 0x33);
        CHECK(px[3] == 0xff);
        // A lock that writes (the render target is lockable): the next call that reads it on the GL
        // side sees it (uploaded by generation, once), and a draw sampling the copy sees it too.
        D3DLOCKED_RECT lr;
        REQUIRE(dev.LockRect(rt, &lr, nullptr, 0) == D3D_OK);
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + 4 * x, "\x10\x20\x30\x40", 4);
        REQUIRE(dev.UnlockRect(rt) == D3D_OK);
        const uint64_t uploads = dev.transfers().uploads;
        REQUIRE(dev.StretchRect(rt, nullptr, level, nullptr, D3DTEXF_POINT) == D3D_OK);
        CHECK(dev.transfers().uploads == uploads + 1);
        REQUIRE(drawFullscreenQuad(dev, {QuadCoords{0, 0, 1, 1}}, 0xffffffff) == D3D_OK);
        CHECK(dev.transfers().uploads == uploads + 1);
        const std::vector<uint8_t> again = lockedBytes(dev, rt);
        CHECK(again[0] == 0x10);
        CHECK(again[3] == 0x40);
    }
}

TEST_CASE("gl renderer: a glare frame uploads its input once and reads its result back once", "[gl][glare]") {
    // Without reuse: with it, the passes' dry runs also bring back the small textures GL wrote
    // that they read (their bytes stand for them in fingerprints; docs/gl-backend.md).
    for (bool native : {false, true}) {
        INFO((native ? "native" : "exact"));
        std::string err;
        glare::RunnerOptions ro;
        ro.width = 160, ro.height = 90;
        ro.skip = false;
        ro.device = glOptions(native);
        glare::Runner run(ro);
        const glare::Technique& t = *glare::findTechnique("adaptive");
        const glare::Settings s = *glare::presetSettings(t, "published");
        emu::RgbaImage img;
        img.width = 160, img.height = 90;
        img.rgba.resize(size_t(160) * 90 * 4);
        for (size_t i = 0; i < img.rgba.size(); ++i) img.rgba[i] = uint8_t((i * 37) % 251);
        glare::FrameResult r;
        REQUIRE(run.setImage(img, err));
        REQUIRE(run.runFrame(t, s, 0, 3, r, err));  // the first frame makes the pool's textures
        const TransferStats before = run.device().transfers();
        REQUIRE(run.setImage(img, err));
        REQUIRE(run.runFrame(t, s, 1, 3, r, err));
        REQUIRE(run.readOutput(err));
        const TransferStats after = run.device().transfers();
        CHECK(after.uploads - before.uploads == 1);
        CHECK(after.readBacks - before.readBacks == 1);
        for (const glare::PassStats& p : r.passes) {
            INFO(p.pass);
            CHECK(p.readBacks == 0);
        }
    }
}

TEST_CASE("gl renderer native mode: a filtered, blended pass lands within a few levels of the emulated card", "[gl]") {
    auto run = [](DeviceOptions o) {
        Device dev(o);
        Handle tex{}, rt{}, ps{};
        REQUIRE(dev.CreateRenderTarget(64, 48, D3DFMT_A8R8G8B8, 1, &rt) == D3D_OK);
        REQUIRE(dev.CreateTexture(32, 24, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
        D3DLOCKED_RECT lr;
        REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 32; ++x) {
                const uint8_t v[4] = {uint8_t(x * 8), uint8_t(y * 10), uint8_t((x ^ y) * 7), 200};
                std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + 4 * x, v, 4);
            }
        REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
        REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xff202020, 0, 0) == D3D_OK);
        REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
        REQUIRE(dev.SetSamplerState(0, D3DSAMP_MINFILTER, D3DTEXF_LINEAR) == D3D_OK);
        REQUIRE(dev.SetSamplerState(0, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR) == D3D_OK);
        REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\nmul_x2 r0, t0, v0\n", &ps) == D3D_OK);
        REQUIRE(dev.SetPixelShader(ps) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_SRCALPHA) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_INVSRCALPHA) == D3D_OK);
        REQUIRE(drawFullscreenQuad(dev, {QuadCoords{0, 0, 1, 1}}, 0xff808080) == D3D_OK);
        return lockedBytes(dev, rt);
    };
    const std::vector<uint8_t> card = run(DeviceOptions{}), native = run(glOptions(true));
    REQUIRE(card.size() == native.size());
    int maxDiff = 0;
    size_t differ = 0;
    for (size_t i = 0; i < card.size(); ++i) {
        const int d = std::abs(int(card[i]) - int(native[i]));
        maxDiff = std::max(maxDiff, d);
        differ += d != 0;
    }
    // Float arithmetic and GL's bilinear weights against the card's 8-bit steps: a few levels.
    CHECK(maxDiff <= 3);
    CHECK(differ > 0);  // and not the emulator's result by accident: native is another computation
}

TEST_CASE("gl renderer: a fingerprint reads a small resource by its bytes, a large one by its generation",
          "[gl][fingerprint]") {
    // GL writes where the front cannot compare them, so each one makes a new generation; a 1×1
    // state written again with the value it held must still read as unchanged (docs/device.md
    // "Fingerprints"), while a 256×256 texture counts by generation.
    Device dev(glOptions(true));
    Handle tiny{}, tinySurface{}, big{}, bigSurface{}, out{}, outSurface{}, ps{};
    REQUIRE(dev.CreateTexture(1, 1, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tiny) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(tiny, 0, &tinySurface) == D3D_OK);
    REQUIRE(dev.CreateTexture(256, 256, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &big) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(big, 0, &bigSurface) == D3D_OK);
    REQUIRE(dev.CreateTexture(8, 8, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &out) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(out, 0, &outSurface) == D3D_OK);
    REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\ntex t1\nadd r0, t0, t1\n", &ps) == D3D_OK);
    auto fill = [&](Handle surface, D3DCOLOR c) {
        REQUIRE(dev.SetRenderTarget(0, surface) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, c, 1, 0) == D3D_OK);
    };
    // A draw that reads both textures, dry-run.
    auto print = [&] {
        dev.beginFingerprint();
        REQUIRE(dev.SetRenderTarget(0, outSurface) == D3D_OK);
        REQUIRE(dev.SetPixelShader(ps) == D3D_OK);
        REQUIRE(dev.SetTexture(0, tiny) == D3D_OK);
        REQUIRE(dev.SetTexture(1, big) == D3D_OK);
        REQUIRE(drawFullscreenQuad(dev) == D3D_OK);
        return dev.endFingerprint();
    };
    fill(tinySurface, 0xff102030u);
    fill(bigSurface, 0xff405060u);
    const Device::Fingerprint a = print();
    REQUIRE(a.complete);
    fill(tinySurface, 0xff102030u);  // the same bytes: a new generation on GL, the same fingerprint
    const Device::Fingerprint b = print();
    CHECK(b.words == a.words);
    fill(tinySurface, 0xff102031u);  // one byte differs
    CHECK(print().words != a.words);
    fill(tinySurface, 0xff102030u);
    CHECK(print().words == a.words);
    fill(bigSurface, 0xff405060u);  // the same bytes, but 256 KB: by generation
    CHECK(print().words != a.words);
}
