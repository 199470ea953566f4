// The device's textures and surfaces as memory: LockRect's layout of every format and the value
// the sampler then reads, the TextureSampler over a device texture, the lock rules, volume
// textures locked as boxes, readSurface, automatic mip generation, and the sampler's views of
// A8R8G8B8 textures read in place (a held view never changes).
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "device_test_util.h"
#include "emu/device.h"
#include "ps11/testfile.h"
#include "ps11/texture_sampler.h"

using namespace emu;

using namespace devicetest;

namespace {

struct FormatCase {
    D3DFORMAT format;
    UINT bytes;
    std::vector<uint8_t> texel;  // in D3D memory order
    std::array<float, 4> value;  // what the sampler reads (r g b a)
};

std::vector<uint8_t> wordBytes(uint32_t w, UINT n) {
    std::vector<uint8_t> b;
    for (UINT i = 0; i < n; ++i) b.push_back(uint8_t(w >> (8 * i)));
    return b;
}

std::vector<uint8_t> floatBytes(std::initializer_list<float> fs) {
    std::vector<uint8_t> b;
    for (float f : fs) {
        uint8_t t[4];
        std::memcpy(t, &f, 4);
        b.insert(b.end(), t, t + 4);
    }
    return b;
}

}  // namespace

TEST_CASE("device: LockRect hands out D3D's memory layout for every format", "[device]") {
    // Each texel written as D3D lays it out (little-endian words, d3d9types.h channel order from
    // the most significant bit) and the value the sampler must then read (ps1x-spec §6.4:
    // missing channels 1, A8's rgb 0; signed channels b/den clamped to [-1, 1]).
    const std::vector<FormatCase> cases = {
        // 0x80FF4000: A 0x80, R 0xFF, G 0x40, B 0x00.
        {D3DFMT_A8R8G8B8, 4, wordBytes(0x80FF4000u, 4), {1.0f, float(64 / 255.0), 0.0f, float(128 / 255.0)}},
        {D3DFMT_X8R8G8B8,
         4,
         wordBytes(0x00102030u, 4),
         {float(16 / 255.0), float(32 / 255.0), float(48 / 255.0), 1.0f}},
        {D3DFMT_A8, 1, {0x7F}, {0, 0, 0, float(127 / 255.0)}},
        {D3DFMT_L8, 1, {0x33}, {float(51 / 255.0), float(51 / 255.0), float(51 / 255.0), 1.0f}},
        // A8L8 0x8040: L low byte 0x40, A high byte 0x80.
        {D3DFMT_A8L8,
         2,
         wordBytes(0x8040u, 2),
         {float(64 / 255.0), float(64 / 255.0), float(64 / 255.0), float(128 / 255.0)}},
        // V8U8 0x7F81: U = 0x81 = -127 -> -1, V = 127 -> 1.
        {D3DFMT_V8U8, 2, wordBytes(0x7F81u, 2), {-1.0f, 1.0f, 1.0f, 1.0f}},
        // L6V5U5: U = 3 (3/15), V = 0b11011 = -5 (-5/15), L = 21 (21/63): 21<<10 | 27<<5 | 3.
        {D3DFMT_L6V5U5,
         2,
         wordBytes((21u << 10) | (27u << 5) | 3u, 2),
         {float(3.0 / 15), float(-5.0 / 15), float(21.0 / 63), 1.0f}},
        // X8L8V8U8 0xFF8040C0: U = 0xC0 = -64, V = 64, L = 128 (unsigned), X ignored.
        {D3DFMT_X8L8V8U8,
         4,
         wordBytes(0xFF8040C0u, 4),
         {float(-64.0 / 127), float(64.0 / 127), float(128.0 / 255), 1.0f}},
        // Q8W8V8U8 0x7F8001FF: U = -1, V = 1, W = -128 (clamped to -1), Q = 127.
        {D3DFMT_Q8W8V8U8, 4, wordBytes(0x7F8001FFu, 4), {float(-1.0 / 127), float(1.0 / 127), -1.0f, 1.0f}},
        // V16U16 0x80017FFF: U = 32767 -> 1, V = -32767 -> -1.
        {D3DFMT_V16U16, 4, wordBytes(0x80017FFFu, 4), {1.0f, -1.0f, 1.0f, 1.0f}},
        {D3DFMT_R32F, 4, floatBytes({0.25f}), {0.25f, 1.0f, 1.0f, 1.0f}},
        // A16B16G16R16F: halves in memory order R G B A: 0.5 = 0x3800, -2 = 0xC000, 1 = 0x3C00,
        // 0.25 = 0x3400.
        {D3DFMT_A16B16G16R16F, 8, {0x00, 0x38, 0x00, 0xC0, 0x00, 0x3C, 0x00, 0x34}, {0.5f, -2.0f, 1.0f, 0.25f}},
        {D3DFMT_A32B32G32R32F, 16, floatBytes({0.1f, 2.0f, -3.0f, 0.5f}), {0.1f, 2.0f, -3.0f, 0.5f}},
    };
    for (const FormatCase& fc : cases) {
        INFO("format " << formatName(fc.format));
        Device dev;
        Handle tex{};
        REQUIRE(dev.CreateTexture(3, 2, 1, 0, fc.format, D3DPOOL_MANAGED, &tex) == D3D_OK);
        D3DLOCKED_RECT lr;
        REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
        // Pitch: 3 texels rounded up to a DWORD multiple.
        CHECK(lr.Pitch == int32_t((3 * fc.bytes + 3) / 4 * 4));
        auto* base = static_cast<uint8_t*>(lr.pBits);
        std::memcpy(base + 1 * lr.Pitch + 2 * fc.bytes, fc.texel.data(), fc.bytes);
        REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
        std::shared_ptr<const ps11::Texture> t = dev.sampledTexture(tex);
        REQUIRE(t);
        const ps11::Vec4 v = t->texelValue(0, 2, 1);
        for (size_t c = 0; c < 4; ++c) CHECK(v[c] == fc.value[c]);
        // A sub-rectangle lock points at its first texel.
        RECT r{2, 1, 3, 2};
        REQUIRE(dev.LockRect(tex, 0, &lr, &r, D3DLOCK_READONLY) == D3D_OK);
        CHECK(std::memcmp(lr.pBits, fc.texel.data(), fc.bytes) == 0);
        REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    }
    // fx8 grid of a signed texel: round_half_even(b * 255 / 127) (docs/precision.md "Inputs").
    Device dev;
    Handle tex{};
    REQUIRE(dev.CreateTexture(1, 1, 1, 0, D3DFMT_V8U8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    static_cast<uint8_t*>(lr.pBits)[0] = 0x81;  // U = -127
    static_cast<uint8_t*>(lr.pBits)[1] = 0x20;  // V = 32 -> 32 * 255 / 127 = 64.25 -> 64
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    auto g = dev.sampledTexture(tex)->texelGrid(0, 0, 0, 0, ps11::Precision::Fx8);
    CHECK(g[0] == -255);
    CHECK(g[1] == 64);
}

TEST_CASE("device: the TextureSampler reads a device texture as bound", "[device]") {
    Device dev;
    Handle tex{};
    REQUIRE(dev.CreateTexture(4, 2, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < 2; ++y)
        for (UINT x = 0; x < 4; ++x) {
            const uint32_t c = 0xFF000000u | (40 * x + 100 * y) << 16 | 7u;
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, &c, 4);
        }
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    ps11::TextureSampler sampler;
    REQUIRE(sampler.bind(0, dev.sampledTexture(tex)));
    // Point sampling at the centre of texel (2, 1): u = 2.5/4, v = 1.5/2 (ps1x-spec §6.2).
    const float u = 2.5f / 4, v = 1.5f / 2;
    int32_t r = 0, g = 0, b = 0, a = 0;
    ps11::SampleRequest req;
    req.count = 1;
    req.u = &u;
    req.v = &v;
    ps11::SampleResult out;
    out.grid[0] = &r, out.grid[1] = &g, out.grid[2] = &b, out.grid[3] = &a;
    sampler.sample(req, out);
    CHECK(r == 180);  // 40 * 2 + 100
    CHECK(g == 0);
    CHECK(b == 7);
    CHECK(a == 255);
}

TEST_CASE("device: lock rules", "[device]") {
    Device dev;
    Handle def{}, man{}, dyn{}, rt{}, rtLock{}, ds{}, dsLock{}, level{};
    REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &def) == D3D_OK);
    REQUIRE(dev.CreateTexture(4, 4, 2, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &man) == D3D_OK);
    REQUIRE(dev.CreateTexture(4, 4, 1, D3DUSAGE_DYNAMIC, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &dyn) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(4, 4, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(4, 4, D3DFMT_A8R8G8B8, 1, &rtLock) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(4, 4, D3DFMT_D24S8, &ds) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(4, 4, D3DFMT_D16_LOCKABLE, &dsLock) == D3D_OK);
    D3DLOCKED_RECT lr;
    // D3D9: DEFAULT-pool resources lock only with DYNAMIC; render targets only if created lockable;
    // depth only in the _LOCKABLE formats.
    CHECK(dev.LockRect(def, 0, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4106");
    CHECK(dev.LockRect(dyn, 0, &lr, nullptr, 0) == D3D_OK);
    CHECK(dev.UnlockRect(dyn, 0) == D3D_OK);
    CHECK(dev.LockRect(rt, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.LockRect(rtLock, &lr, nullptr, 0) == D3D_OK);
    CHECK(dev.UnlockRect(rtLock) == D3D_OK);
    CHECK(dev.LockRect(ds, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.LockRect(dsLock, &lr, nullptr, 0) == D3D_OK);
    CHECK(lr.Pitch == 8);
    CHECK(dev.UnlockRect(dsLock) == D3D_OK);
    // Twice, unlock without lock, bad level, bad rect, null out.
    CHECK(dev.LockRect(man, 1, &lr, nullptr, 0) == D3D_OK);
    CHECK(lr.Pitch == 8);
    CHECK(dev.LockRect(man, 1, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "already locked"));
    CHECK(dev.UnlockRect(man, 1) == D3D_OK);
    CHECK(dev.UnlockRect(man, 1) == D3DERR_INVALIDCALL);
    CHECK(dev.LockRect(man, 2, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    RECT out{2, 2, 5, 3};
    CHECK(dev.LockRect(man, 0, &lr, &out, 0) == D3DERR_INVALIDCALL);
    RECT empty{2, 2, 2, 3};
    CHECK(dev.LockRect(man, 0, &lr, &empty, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.LockRect(man, 0, nullptr, nullptr, 0) == D3DERR_INVALIDCALL);
    RECT r{1, 2, 3, 4};
    D3DLOCKED_RECT whole;
    REQUIRE(dev.LockRect(man, 0, &whole, nullptr, D3DLOCK_READONLY) == D3D_OK);
    REQUIRE(dev.UnlockRect(man, 0) == D3D_OK);
    REQUIRE(dev.LockRect(man, 0, &lr, &r, 0) == D3D_OK);
    CHECK(static_cast<uint8_t*>(lr.pBits) - static_cast<uint8_t*>(whole.pBits) == 2 * 16 + 1 * 4);
    REQUIRE(dev.UnlockRect(man, 0) == D3D_OK);
    // A level's surface shares the level's lock.
    REQUIRE(dev.GetSurfaceLevel(man, 0, &level) == D3D_OK);
    REQUIRE(dev.LockRect(level, &lr, nullptr, 0) == D3D_OK);
    CHECK(dev.LockRect(man, 0, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.UnlockRect(man, 0) == D3D_OK);
    CHECK(dev.LockRect(man, &lr, nullptr, 0) == D3DERR_INVALIDCALL);  // a texture handle is not a surface
    CHECK(dev.LockBox(man, 0, nullptr, nullptr, 0) == D3DERR_INVALIDCALL);
}

TEST_CASE("device: volume textures lock as boxes", "[device]") {
    Device dev;
    Handle vol{};
    REQUIRE(dev.CreateVolumeTexture(3, 2, 4, 0, 0, D3DFMT_L8, D3DPOOL_MANAGED, &vol) == D3D_OK);
    CHECK(dev.GetLevelCount(vol) == 3);  // 3x2x4, 1x1x2, 1x1x1
    D3DLOCKED_BOX lb;
    REQUIRE(dev.LockBox(vol, 0, &lb, nullptr, 0) == D3D_OK);
    CHECK(lb.RowPitch == 4);
    CHECK(lb.SlicePitch == 8);
    auto* p = static_cast<uint8_t*>(lb.pBits);
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 3; ++x) p[z * 8 + y * 4 + x] = uint8_t(100 * z + 10 * y + x);
    REQUIRE(dev.UnlockBox(vol, 0) == D3D_OK);
    D3DBOX box{1, 1, 3, 2, 2, 4};
    REQUIRE(dev.LockBox(vol, 0, &lb, &box, D3DLOCK_READONLY) == D3D_OK);
    CHECK(static_cast<uint8_t*>(lb.pBits)[0] == 211);
    CHECK(static_cast<uint8_t*>(lb.pBits)[lb.SlicePitch] == uint8_t(311));  // 100 * 3 + 11, wrapped to a byte
    REQUIRE(dev.UnlockBox(vol, 0) == D3D_OK);
    D3DBOX bad{0, 0, 3, 2, 0, 5};
    CHECK(dev.LockBox(vol, 0, &lb, &bad, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.LockBox(vol, 3, &lb, nullptr, 0) == D3DERR_INVALIDCALL);
    CHECK(dev.UnlockBox(vol, 1) == D3DERR_INVALIDCALL);
    D3DLOCKED_RECT lr;
    CHECK(dev.LockRect(vol, 0, &lr, nullptr, 0) == D3DERR_INVALIDCALL);  // not a 2D texture
    Handle s{};
    CHECK(dev.GetSurfaceLevel(vol, 0, &s) == D3DERR_INVALIDCALL);
    // Levels 1 and 2 hold zeros (not written); level 0 reaches the sampler as a volume.
    auto t = dev.sampledTexture(vol);
    REQUIRE(t);
    CHECK(t->isVolume());
    CHECK(t->texelValue(0, 2, 1, 3)[0] == float((312 & 0xff) / 255.0));
    CHECK(dev.SetTexture(2, vol) == D3D_OK);
}

TEST_CASE("device: readSurface hands the newest bytes in place, and nothing writes them meanwhile", "[device]") {
    Device dev;
    Handle rt{}, tex{}, level{};
    REQUIRE(dev.CreateRenderTarget(3, 2, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);  // not lockable
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    const D3DRECT r{1, 0, 3, 1};
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF000080u, 1.0f, 0) == D3D_OK);
    REQUIRE(dev.Clear(1, &r, D3DCLEAR_TARGET, 0x80FF0000u, 1.0f, 0) == D3D_OK);
    int calls = 0;
    const auto pixel = [](const D3DLOCKED_RECT& lr, UINT x, UINT y) {
        uint32_t c;
        std::memcpy(&c, static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, 4);
        return c;
    };
    REQUIRE(dev.readSurface(rt, [&](const D3DLOCKED_RECT& lr) {
        ++calls;
        CHECK(lr.Pitch >= 12);
        CHECK(pixel(lr, 0, 0) == 0xFF000080u);
        CHECK(pixel(lr, 2, 0) == 0x80FF0000u);
        CHECK(pixel(lr, 2, 1) == 0xFF000080u);
        // Held like a lock: a write to it is refused while `read` runs.
        CHECK(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0u, 1.0f, 0) == D3DERR_INVALIDCALL);
        CHECK(dev.lastError().code == "E4106");
        CHECK(dev.readSurface(rt, [](const D3DLOCKED_RECT&) {}) == D3DERR_INVALIDCALL);
    }) == D3D_OK);
    CHECK(calls == 1);
    // Released afterwards: writes go through and the next read sees them.
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x01020304u, 1.0f, 0) == D3D_OK);
    REQUIRE(dev.readSurface(rt, [&](const D3DLOCKED_RECT& lr) { CHECK(pixel(lr, 1, 1) == 0x01020304u); }) == D3D_OK);
    // A texture's level, and a level locked by LockRect (refused, the callback never runs).
    REQUIRE(dev.CreateTexture(2, 2, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
    D3DLOCKED_RECT lr{};
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    std::memcpy(lr.pBits, "\x11\x22\x33\x44", 4);
    calls = 0;
    CHECK(dev.readSurface(level, [&](const D3DLOCKED_RECT&) { ++calls; }) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "is locked"));
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    REQUIRE(dev.readSurface(level, [&](const D3DLOCKED_RECT& l) {
        ++calls;
        CHECK(pixel(l, 0, 0) == 0x44332211u);
    }) == D3D_OK);
    CHECK(calls == 1);
    // A handle that is no surface, and a fingerprint (which cannot hand contents back).
    CHECK(dev.readSurface(Handle(4242), [](const D3DLOCKED_RECT&) {}) == D3DERR_INVALIDCALL);
    CHECK(contains(dev.lastError().message, "readSurface"));
    dev.beginFingerprint();
    CHECK(dev.readSurface(rt, [](const D3DLOCKED_RECT&) {}) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4125");
    CHECK_FALSE(dev.endFingerprint().complete);
    // The callback may release the surface's owner: the hold is dropped by handle.
    REQUIRE(dev.readSurface(level, [&](const D3DLOCKED_RECT&) { CHECK(dev.Release(tex) == D3D_OK); }) == D3D_OK);
}

TEST_CASE("device: automatic mip generation", "[device]") {
    Device dev;
    Handle tex{};
    REQUIRE(dev.CreateTexture(4, 4, 0, D3DUSAGE_AUTOGENMIPMAP, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    CHECK(dev.GetLevelCount(tex) == 1);  // D3D9: the sublevels are not exposed
    D3DLOCKED_RECT lr;
    CHECK(dev.LockRect(tex, 1, &lr, nullptr, 0) == D3DERR_INVALIDCALL);
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    // Blue channel = 10 * (x + 4y) + (x & 1); alpha 255.
    for (UINT y = 0; y < 4; ++y)
        for (UINT x = 0; x < 4; ++x) {
            uint8_t* p = static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4;
            p[0] = uint8_t(10 * (x + 4 * y) + (x & 1)), p[1] = 0, p[2] = 0, p[3] = 255;
        }
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    auto t = dev.sampledTexture(tex);
    REQUIRE(t);
    REQUIRE(t->levelCount() == 3);
    // Level 1 texel (0, 0): (0 + 11 + 40 + 51) / 4 = 25.5 -> 26 (ties to even). Texel (1, 0):
    // (20 + 31 + 60 + 71) / 4 = 45.5 -> 46. Texel (0, 1): (80 + 91 + 120 + 131) / 4 = 105.5 -> 106.
    // Texel (1, 1): (100 + 111 + 140 + 151) / 4 = 125.5 -> 126. Level 2: (26+46+106+126)/4 = 76.
    CHECK(t->texelGrid(1, 0, 0, 0, ps11::Precision::Fx8)[2] == 26);
    CHECK(t->texelGrid(1, 1, 0, 0, ps11::Precision::Fx8)[2] == 46);
    CHECK(t->texelGrid(1, 0, 1, 0, ps11::Precision::Fx8)[2] == 106);
    CHECK(t->texelGrid(1, 1, 1, 0, ps11::Precision::Fx8)[2] == 126);
    CHECK(t->texelGrid(2, 0, 0, 0, ps11::Precision::Fx8)[2] == 76);
    CHECK(t->texelGrid(2, 0, 0, 0, ps11::Precision::Fx8)[3] == 255);
    CHECK(dev.GenerateMipSubLevels(tex) == D3D_OK);
    CHECK(dev.sampledTexture(tex) == t);  // nothing changed since
    CHECK(dev.GenerateMipSubLevels(Handle(999)) == D3DERR_INVALIDCALL);

    // Signed formats average their signed fields: U {-1, -2, 3, 5} -> 5/4 = 1.25 -> 1.
    Handle bump{};
    REQUIRE(dev.CreateTexture(2, 2, 0, D3DUSAGE_AUTOGENMIPMAP, D3DFMT_V8U8, D3DPOOL_MANAGED, &bump) == D3D_OK);
    REQUIRE(dev.LockRect(bump, 0, &lr, nullptr, 0) == D3D_OK);
    const int8_t u[4] = {-1, -2, 3, 5};
    for (int i = 0; i < 4; ++i) {
        uint8_t* p = static_cast<uint8_t*>(lr.pBits) + (i / 2) * lr.Pitch + (i % 2) * 2;
        p[0] = uint8_t(u[i]), p[1] = uint8_t(-8);
    }
    REQUIRE(dev.UnlockRect(bump, 0) == D3D_OK);
    REQUIRE(dev.GenerateMipSubLevels(bump) == D3D_OK);
    auto b = dev.sampledTexture(bump);
    REQUIRE(b);
    CHECK(b->texelValue(1, 0, 0)[0] == float(1.0 / 127));
    CHECK(b->texelValue(1, 0, 0)[1] == float(-8.0 / 127));

    // A float chain: R32F {0.5, 1.5, 2.5, 4.0} -> 2.125.
    Handle fl{};
    REQUIRE(dev.CreateTexture(2, 2, 0, D3DUSAGE_AUTOGENMIPMAP, D3DFMT_R32F, D3DPOOL_MANAGED, &fl) == D3D_OK);
    REQUIRE(dev.LockRect(fl, 0, &lr, nullptr, 0) == D3D_OK);
    const float v[4] = {0.5f, 1.5f, 2.5f, 4.0f};
    for (int i = 0; i < 4; ++i)
        std::memcpy(static_cast<uint8_t*>(lr.pBits) + (i / 2) * lr.Pitch + (i % 2) * 4, &v[i], 4);
    REQUIRE(dev.UnlockRect(fl, 0) == D3D_OK);
    auto f = dev.sampledTexture(fl);
    REQUIRE(f);
    CHECK(f->texelValue(1, 0, 0)[0] == 2.125f);

    // A textures without AUTOGENMIPMAP keeps its levels as written (D3D9: no effect).
    Handle plain{};
    REQUIRE(dev.CreateTexture(2, 2, 2, 0, D3DFMT_L8, D3DPOOL_MANAGED, &plain) == D3D_OK);
    REQUIRE(dev.LockRect(plain, 0, &lr, nullptr, 0) == D3D_OK);
    std::memset(lr.pBits, 200, 2);
    REQUIRE(dev.UnlockRect(plain, 0) == D3D_OK);
    REQUIRE(dev.GenerateMipSubLevels(plain) == D3D_OK);
    CHECK(dev.sampledTexture(plain)->texelValue(1, 0, 0)[0] == 0.0f);
}

TEST_CASE("device: A8R8G8B8 textures are sampled in place, and a held view never changes", "[device]") {
    Device dev;
    auto fill = [&](Handle tex, UINT level, uint32_t word) {
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(tex, level, &lr, nullptr, 0) == D3D_OK);
        D3DSURFACE_DESC desc{};
        REQUIRE(dev.GetLevelDesc(tex, level, &desc) == D3D_OK);
        for (UINT y = 0; y < desc.Height; ++y)
            for (UINT x = 0; x < desc.Width; ++x)
                std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, &word, 4);
        REQUIRE(dev.UnlockRect(tex, level) == D3D_OK);
    };
    auto red = [](const std::shared_ptr<const ps11::Texture>& t, int level) {
        return int(std::lround(t->texelValue(level, 0, 0)[0] * 255.0f));
    };
    // A quad of one diffuse colour (alpha too) over pixels [0, w) × [0, h) of the render target,
    // through the fixed function.
    auto drawFlat = [&](UINT w, UINT h, DWORD colour) {
        struct V { float x, y, z, rhw; DWORD c; };
        const float r = float(w) - 0.5f, b = float(h) - 0.5f;
        const V quad[4] = {{-0.5f, -0.5f, 0, 1, colour}, {r, -0.5f, 0, 1, colour}, {-0.5f, b, 0, 1, colour},
                           {r, b, 0, 1, colour}};
        REQUIRE(dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_DIFFUSE) == D3D_OK);
        REQUIRE(dev.SetTextureStageState(0, D3DTSS_COLOROP, D3DTOP_SELECTARG1) == D3D_OK);
        REQUIRE(dev.SetTextureStageState(0, D3DTSS_COLORARG1, D3DTA_DIFFUSE) == D3D_OK);
        REQUIRE(dev.SetTextureStageState(0, D3DTSS_ALPHAOP, D3DTOP_SELECTARG1) == D3D_OK);
        REQUIRE(dev.SetTextureStageState(0, D3DTSS_ALPHAARG1, D3DTA_DIFFUSE) == D3D_OK);
        REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, quad, sizeof(V)) == D3D_OK);
    };

    SECTION("a mip chain is read where it is; X8R8G8B8 and A8 are copied") {
        Handle tex{}, x8{}, a8{};
        REQUIRE(dev.CreateTexture(8, 4, 0, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
        for (UINT l = 0; l < 4; ++l) fill(tex, l, 0xFF000000u | ((10u + l) << 16));
        auto t = dev.sampledTexture(tex);
        REQUIRE(t);
        CHECK(t->readsInPlace());
        for (int l = 0; l < 4; ++l) CHECK(red(t, l) == 10 + l);
        REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_X8R8G8B8, D3DPOOL_MANAGED, &x8) == D3D_OK);
        fill(x8, 0, 0x00FF0000u);  // alpha byte 0: the sampler must read 1
        auto tx = dev.sampledTexture(x8);
        REQUIRE(tx);
        CHECK_FALSE(tx->readsInPlace());
        CHECK(tx->texelValue(0, 0, 0)[3] == 1.0f);
        REQUIRE(dev.CreateTexture(4, 4, 1, 0, D3DFMT_A8, D3DPOOL_MANAGED, &a8) == D3D_OK);
        CHECK_FALSE(dev.sampledTexture(a8)->readsInPlace());
        // Every float format is read in place: A32B32G32R32F as the values the sampler keeps, the
        // others through their rows (ps11::Texture::floatTexels).
        for (const D3DFORMAT f : {D3DFMT_A32B32G32R32F, D3DFMT_A16B16G16R16F, D3DFMT_R32F}) {
            Handle ft{};
            REQUIRE(dev.CreateTexture(4, 4, 1, 0, f, D3DPOOL_MANAGED, &ft) == D3D_OK);
            auto sampled = dev.sampledTexture(ft);
            REQUIRE(sampled);
            CHECK(sampled->readsInPlace());
            CHECK((sampled->values() != nullptr) == (f == D3DFMT_A32B32G32R32F));
        }
    }

    SECTION("every write leaves a view someone holds as it was") {
        Handle tex{}, level{}, src{};
        REQUIRE(dev.CreateTexture(4, 4, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        src = makeTarget(dev, 4, 4, [](UINT, UINT) { return 0xFF330000u; });
        REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF010000u, 1.0f, 0) == D3D_OK);
        auto v1 = dev.sampledTexture(tex);
        REQUIRE(v1);
        CHECK(v1->readsInPlace());
        CHECK(red(v1, 0) == 1);
        // Clear, StretchRect and a lock each write the level while v1 is held.
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF020000u, 1.0f, 0) == D3D_OK);
        CHECK(red(v1, 0) == 1);
        auto v2 = dev.sampledTexture(tex);
        CHECK(red(v2, 0) == 2);
        REQUIRE(dev.StretchRect(src, nullptr, level, nullptr, D3DTEXF_POINT) == D3D_OK);
        CHECK(red(v1, 0) == 1);
        CHECK(red(v2, 0) == 2);
        auto v3 = dev.sampledTexture(tex);
        CHECK(red(v3, 0) == 0x33);
        drawFlat(4, 4, 0xFF440000u);  // a draw into the level
        CHECK(red(v3, 0) == 0x33);
        CHECK(red(dev.sampledTexture(tex), 0) == 0x44);
    }

    SECTION("float targets are read in place, and a view held across a draw keeps its values") {
        for (const D3DFORMAT f : {D3DFMT_A16B16G16R16F, D3DFMT_R32F}) {
            INFO("format " << f);
            Handle tex{}, level{};
            REQUIRE(dev.CreateTexture(4, 4, 1, D3DUSAGE_RENDERTARGET, f, D3DPOOL_DEFAULT, &tex) == D3D_OK);
            REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
            REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
            REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x80110000u, 1.0f, 0) == D3D_OK);
            auto v1 = dev.sampledTexture(tex);
            REQUIRE(v1);
            CHECK(v1->readsInPlace());
            CHECK(red(v1, 0) == 0x11);
            // R32F has no alpha: it reads 1; A16B16G16R16F's is the cleared 0x80 / 255, half-rounded.
            CHECK(v1->texelValue(0, 1, 2)[3] == (f == D3DFMT_R32F ? 1.0f : ps11::roundToHalf(128.0f / 255.0f)));
            drawFlat(2, 2, 0xFF440000u);
            auto v2 = dev.sampledTexture(tex);
            CHECK(v2->readsInPlace());
            CHECK(red(v2, 0) == 0x44);
            CHECK(red(v1, 0) == 0x11);  // the view held before the draw is as it was
            CHECK(int(std::lround(v2->texelValue(0, 3, 3)[0] * 255.0f)) == 0x11);
        }
    }

    SECTION("an X8R8G8B8 target is read in place while every X byte is known to be 0xff") {
        Handle tex{}, level{}, src{};
        REQUIRE(dev.CreateTexture(4, 4, 1, D3DUSAGE_RENDERTARGET, D3DFMT_X8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        auto alpha = [](const std::shared_ptr<const ps11::Texture>& t) {
            bool one = true;
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 4; ++x) one = one && t->texelValue(0, x, y)[3] == 1.0f;
            return one;
        };
        // Fresh (zero-filled, X bytes 0): copied, alpha forced to 1.
        CHECK_FALSE(dev.sampledTexture(tex)->readsInPlace());
        CHECK(alpha(dev.sampledTexture(tex)));
        REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
        // A clear of part of it writes 0xff X bytes there only: still copied.
        const D3DRECT part{0, 0, 2, 2};
        REQUIRE(dev.Clear(1, &part, D3DCLEAR_TARGET, 0x00070000u, 1.0f, 0) == D3D_OK);
        CHECK_FALSE(dev.sampledTexture(tex)->readsInPlace());
        // A clear of the whole of it (alpha 0 in the colour: X8 stores no alpha).
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x00080000u, 1.0f, 0) == D3D_OK);
        auto v1 = dev.sampledTexture(tex);
        CHECK(v1->readsInPlace());
        CHECK(red(v1, 0) == 8);
        CHECK(alpha(v1));
        drawFlat(3, 3, 0x00440000u);  // alpha 0 keeps it in place: every store sets the X byte
        auto v2 = dev.sampledTexture(tex);
        CHECK(v2->readsInPlace());
        CHECK(red(v2, 0) == 0x44);
        CHECK(int(std::lround(v2->texelValue(0, 3, 3)[0] * 255.0f)) == 8);
        CHECK(alpha(v2));
        CHECK(red(v1, 0) == 8);  // the view held before the draw is as it was
        // A StretchRect copies bytes it was given: copied again until the next whole clear.
        src = makeTarget(dev, 4, 4, [](UINT, UINT) { return 0x00330000u; });
        REQUIRE(dev.StretchRect(src, nullptr, level, nullptr, D3DTEXF_POINT) == D3D_OK);
        auto v3 = dev.sampledTexture(tex);
        CHECK_FALSE(v3->readsInPlace());
        CHECK(red(v3, 0) == 0x33);
        CHECK(alpha(v3));
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x00090000u, 1.0f, 0) == D3D_OK);
        CHECK(dev.sampledTexture(tex)->readsInPlace());
    }

    SECTION("a texture a draw sampled is written in place afterwards (nothing keeps the view)") {
        Handle tex{}, level{}, out{};
        REQUIRE(dev.CreateTexture(8, 8, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        out = makeTarget(dev, 8, 8, [](UINT, UINT) { return 0u; });
        struct V { float x, y, z, rhw, u, v; };
        const V quad[4] = {{-0.5f, -0.5f, 0, 1, 0, 0}, {7.5f, -0.5f, 0, 1, 1, 0}, {-0.5f, 7.5f, 0, 1, 0, 1}, {7.5f, 7.5f, 0, 1, 1, 1}};
        REQUIRE(dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_TEX1) == D3D_OK);
        auto drawFrom = [&] {
            REQUIRE(dev.SetRenderTarget(0, out) == D3D_OK);
            REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
            REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, quad, sizeof(V)) == D3D_OK);
            REQUIRE(dev.SetTexture(0, Handle::Null) == D3D_OK);
            REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
            REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0xFF102030u, 1.0f, 0) == D3D_OK);
        };
        drawFrom();
        const void* before = dev.sampledTexture(tex)->unorm8();
        drawFrom();
        CHECK(dev.sampledTexture(tex)->unorm8() == before);  // the clear wrote the same buffer
        CHECK(red(dev.sampledTexture(tex), 0) == 0x10);
    }

    SECTION("a lock after the view was made, then a write to another level") {
        Handle tex{};
        REQUIRE(dev.CreateTexture(4, 4, 2, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
        fill(tex, 0, 0xFF050000u);
        fill(tex, 1, 0xFF060000u);
        auto v = dev.sampledTexture(tex);
        D3DLOCKED_RECT lr{};
        REQUIRE(dev.LockRect(tex, 1, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
        fill(tex, 0, 0xFF070000u);  // level 0 written while level 1 stays locked
        CHECK(static_cast<const uint8_t*>(lr.pBits)[2] == 6);
        REQUIRE(dev.UnlockRect(tex, 1) == D3D_OK);
        CHECK(red(v, 0) == 5);
        auto w = dev.sampledTexture(tex);
        CHECK(red(w, 0) == 7);
        CHECK(red(w, 1) == 6);
        // Released while held: the view keeps its bytes alive.
        REQUIRE(dev.Release(tex) == D3D_OK);
        CHECK(red(w, 0) == 7);
    }
}
