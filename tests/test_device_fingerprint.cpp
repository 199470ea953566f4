// Fingerprints and generations (Device::beginFingerprint, contentGeneration; docs/device.md
// "Fingerprints", "Generations"): a dry run writes nothing, equal calls give equal words,
// anything the result depends on changes them, reads of contents an earlier call determined
// are not by generation, calls that hand contents back are refused; a small resource written
// with the bytes it had keeps its generation.
#include <catch2/catch.hpp>

#include <cstring>
#include <tuple>
#include <vector>

#include "emu/device.h"
#include "emu/fullscreen.h"

using namespace emu;

namespace {

struct Scene {
    Handle source{}, target{}, targetSurface{}, shader{};
};

Scene makeScene(Device& dev) {
    Scene s;
    REQUIRE(dev.CreateTexture(8, 8, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &s.source) == D3D_OK);
    REQUIRE(dev.CreateTexture(8, 8, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &s.target) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(s.target, 0, &s.targetSurface) == D3D_OK);
    REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\nmul r0, t0, c0\n", &s.shader) == D3D_OK);
    Handle src{};
    REQUIRE(dev.GetSurfaceLevel(s.source, 0, &src) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, src) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xff336699u, 1, 0) == D3D_OK);
    return s;
}

// One pass: clear the target, then draw the source scaled by c0 onto it (optionally blended).
void pass(Device& dev, const Scene& s, float scale, bool blend, const std::array<QuadCoords, 4>& coords = {}) {
    REQUIRE(dev.SetRenderTarget(0, s.targetSurface) == D3D_OK);
    REQUIRE(dev.SetPixelShader(s.shader) == D3D_OK);
    REQUIRE(dev.SetTexture(0, s.source) == D3D_OK);
    const float c0[4] = {scale, scale, scale, 1};
    REQUIRE(dev.SetPixelShaderConstantF(0, c0, 1) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, blend) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE) == D3D_OK);
    if (!blend) REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0, 1, 0) == D3D_OK);
    REQUIRE(drawFullscreenQuad(dev, coords) == D3D_OK);
}

std::vector<uint8_t> pixels(Device& dev, Handle texture) {
    Handle sys{}, surface{};
    REQUIRE(dev.GetSurfaceLevel(texture, 0, &surface) == D3D_OK);
    REQUIRE(dev.CreateOffscreenPlainSurface(8, 8, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
    REQUIRE(dev.GetRenderTargetData(surface, sys) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(sys, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    std::vector<uint8_t> out(static_cast<const uint8_t*>(lr.pBits), static_cast<const uint8_t*>(lr.pBits) + 8 * 8 * 4);
    REQUIRE(dev.UnlockRect(sys) == D3D_OK);
    REQUIRE(dev.Release(sys) == D3D_OK);
    return out;
}

Device::Fingerprint fingerprint(Device& dev, const Scene& s, float scale, bool blend) {
    dev.beginFingerprint();
    pass(dev, s, scale, blend);
    return dev.endFingerprint();
}

}  // namespace

TEST_CASE("fingerprint: a dry run writes nothing and names what it would write", "[device][fingerprint]") {
    Device dev;
    const Scene s = makeScene(dev);
    pass(dev, s, 0.5f, false);
    const std::vector<uint8_t> before = pixels(dev, s.target);
    const uint64_t gen = dev.contentGeneration(s.target);
    const Device::Fingerprint f = fingerprint(dev, s, 1.0f, false);
    CHECK(f.complete);
    CHECK(!dev.fingerprinting());
    CHECK(f.writes == std::vector<Handle>{s.target});  // the owner, not the level's surface
    CHECK(dev.contentGeneration(s.target) == gen);
    CHECK(dev.contentGeneration(s.targetSurface) == gen);
    CHECK(pixels(dev, s.target) == before);
}

TEST_CASE("fingerprint: equal calls give equal words; what the result depends on changes them",
          "[device][fingerprint]") {
    Device dev;
    const Scene s = makeScene(dev);
    const Device::Fingerprint a = fingerprint(dev, s, 0.5f, false);
    CHECK(a.words == fingerprint(dev, s, 0.5f, false).words);
    // A constant.
    CHECK(a.words != fingerprint(dev, s, 0.75f, false).words);
    // The source's contents (a write to it).
    Handle src{};
    REQUIRE(dev.GetSurfaceLevel(s.source, 0, &src) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, src) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xff000000u, 1, 0) == D3D_OK);
    const Device::Fingerprint b = fingerprint(dev, s, 0.5f, false);
    CHECK(a.words != b.words);
    // Vertices.
    dev.beginFingerprint();
    pass(dev, s, 0.5f, false, {QuadCoords{0.1f, 0.0f, 1.0f, 1.0f}});
    CHECK(dev.endFingerprint().words != b.words);
    // A state the pass does not set itself.
    REQUIRE(dev.SetRenderState(D3DRS_COLORWRITEENABLE, 0x7) == D3D_OK);
    CHECK(fingerprint(dev, s, 0.5f, false).words != b.words);
}

TEST_CASE("fingerprint: a target read before anything in the fingerprint overwrote it counts by generation",
          "[device][fingerprint]") {
    Device dev;
    const Scene s = makeScene(dev);
    // Cleared first: the blend-free draw's target is determined, its old contents do not count.
    pass(dev, s, 0.5f, false);
    const Device::Fingerprint a = fingerprint(dev, s, 0.5f, false);
    pass(dev, s, 0.25f, false);  // the target changes
    CHECK(fingerprint(dev, s, 0.5f, false).words == a.words);
    // Blending onto a target nobody cleared reads it: its generation counts.
    const Device::Fingerprint b1 = fingerprint(dev, s, 0.5f, true);
    pass(dev, s, 0.5f, true);
    const Device::Fingerprint b2 = fingerprint(dev, s, 0.5f, true);
    CHECK(b1.words != b2.words);
}

TEST_CASE("fingerprint: calls that hand contents back are refused and leave it incomplete", "[device][fingerprint]") {
    Device dev;
    const Scene s = makeScene(dev);
    Handle sys{};
    REQUIRE(dev.CreateOffscreenPlainSurface(8, 8, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
    dev.beginFingerprint();
    CHECK(dev.GetRenderTargetData(s.targetSurface, sys) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4125");
    CHECK(dev.lastError().message.find("GetRenderTargetData") != std::string::npos);
    D3DLOCKED_RECT lr;
    CHECK(dev.LockRect(sys, &lr, nullptr, D3DLOCK_READONLY) == D3DERR_INVALIDCALL);
    CHECK(!dev.endFingerprint().complete);
    // Outside a fingerprint both work again.
    CHECK(dev.GetRenderTargetData(s.targetSurface, sys) == D3D_OK);
}

TEST_CASE("generations: a small resource written with the bytes it holds keeps its generation", "[device][fingerprint]") {
    Device dev;
    Handle tiny{}, tinySurface{}, big{}, bigSurface{};
    REQUIRE(dev.CreateTexture(1, 1, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tiny) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(tiny, 0, &tinySurface) == D3D_OK);
    REQUIRE(dev.CreateTexture(256, 256, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &big) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(big, 0, &bigSurface) == D3D_OK);
    for (Handle t : {tinySurface, bigSurface}) {
        REQUIRE(dev.SetRenderTarget(0, t) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xff102030u, 1, 0) == D3D_OK);
    }
    const uint64_t tinyGen = dev.contentGeneration(tiny), bigGen = dev.contentGeneration(big);
    for (Handle t : {tinySurface, bigSurface}) {
        REQUIRE(dev.SetRenderTarget(0, t) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xff102030u, 1, 0) == D3D_OK);  // the same bytes
    }
    CHECK(dev.contentGeneration(tiny) == tinyGen);
    CHECK(dev.contentGeneration(big) > bigGen);  // 256 KB: not compared
    REQUIRE(dev.SetRenderTarget(0, tinySurface) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xff102031u, 1, 0) == D3D_OK);  // one byte differs
    CHECK(dev.contentGeneration(tiny) > tinyGen);
    CHECK(dev.contentGeneration(Handle{999999}) == 0);
}

TEST_CASE("fingerprint: a draw certainly covering its whole target determines it", "[device][fingerprint]") {
    Device dev;
    const Scene s = makeScene(dev);
    Handle killer{};
    REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ntex t0\ntexkill t1\nmov r0, t0\n", &killer) == D3D_OK);
    // A full-screen quad without blending, then an additive one onto what it left.
    auto twoDraws = [&](Handle shader, DWORD colorWrite, bool halfSize) {
        REQUIRE(dev.SetRenderTarget(0, s.targetSurface) == D3D_OK);
        REQUIRE(dev.SetPixelShader(shader) == D3D_OK);
        REQUIRE(dev.SetTexture(0, s.source) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_COLORWRITEENABLE, colorWrite) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 0) == D3D_OK);
        if (halfSize) {
            D3DVIEWPORT9 vp{0, 0, 4, 8, 0, 1};
            REQUIRE(dev.SetViewport(&vp) == D3D_OK);
        }
        REQUIRE(drawFullscreenQuad(dev) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_COLORWRITEENABLE, 0xF) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE) == D3D_OK);
        REQUIRE(drawFullscreenQuad(dev) == D3D_OK);
    };
    auto words = [&](Handle shader, DWORD colorWrite, bool halfSize) {
        const DeviceState saved = dev.state();
        dev.beginFingerprint();
        twoDraws(shader, colorWrite, halfSize);
        Device::Fingerprint f = dev.endFingerprint();
        REQUIRE(f.complete);
        REQUIRE(dev.applyState(saved) == D3D_OK);
        return f.words;
    };
    auto changeTarget = [&] {
        REQUIRE(dev.SetRenderTarget(0, s.targetSurface) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xff000000u + uint32_t(dev.contentGeneration(s.target)), 1, 0) ==
                D3D_OK);
    };
    const auto whole = words(s.shader, 0xF, false);
    changeTarget();
    CHECK(words(s.shader, 0xF, false) == whole);  // the blend reads what the first draw wrote
    for (auto [shader, mask, half] : {std::tuple{killer, DWORD(0xF), false}, std::tuple{s.shader, DWORD(0x7), false},
                                      std::tuple{s.shader, DWORD(0xF), true}}) {
        // texkill, a partial write mask, half the target: the target's old contents show through.
        const auto a = words(shader, mask, half);
        changeTarget();
        CHECK(words(shader, mask, half) != a);
    }
    // And what the fingerprint claims holds: the two draws give the same bytes whatever was there.
    const DeviceState saved = dev.state();
    twoDraws(s.shader, 0xF, false);
    const std::vector<uint8_t> first = pixels(dev, s.target);
    REQUIRE(dev.applyState(saved) == D3D_OK);
    changeTarget();
    twoDraws(s.shader, 0xF, false);
    CHECK(pixels(dev, s.target) == first);
}
