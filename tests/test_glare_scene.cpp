// The built-in procedural scenes (glare/scene.h, docs/glare/scenes.md): each renders, is
// deterministic and animated, and has the property its technique needs (box: a large change of
// mean luminance; neon: alpha marks exactly the emissive strips; lights: a small bright fraction
// with one-pixel lights; sky: a large bright fraction). The GL renderer draws the same bytes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "emu/device.h"
#include "glare/scene.h"
#include "runner/gl_backend.h"

using namespace emu;

namespace {

struct Frame {
    UINT w = 0, h = 0;
    std::vector<uint32_t> argb;  // 0xAARRGGBB
    uint32_t at(UINT x, UINT y) const { return argb[size_t(y) * w + x]; }
};

double luminance(uint32_t p) {
    return (0.299 * double((p >> 16) & 0xFF) + 0.587 * double((p >> 8) & 0xFF) + 0.114 * double(p & 0xFF)) / 255.0;
}

// Renders frame `frame` of `frameCount` into a fresh w × h target of `dev` and reads it back.
Frame render(Device& dev, glare::Scene& scene, UINT w, UINT h, int frame, int frameCount) {
    Handle rt{}, copy{};
    REQUIRE(dev.CreateRenderTarget(w, h, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);
    REQUIRE(dev.CreateOffscreenPlainSurface(w, h, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &copy) == D3D_OK);
    std::string error;
    const bool ok = scene.render(dev, rt, frame, frameCount, error);
    INFO(error);
    REQUIRE(ok);
    CHECK(error.empty());
    REQUIRE(dev.GetRenderTargetData(rt, copy) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(copy, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    Frame img{w, h, std::vector<uint32_t>(size_t(w) * h)};
    for (UINT y = 0; y < h; ++y)
        std::memcpy(&img.argb[size_t(y) * w], static_cast<const uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch),
                    size_t(w) * 4);
    REQUIRE(dev.UnlockRect(copy) == D3D_OK);
    REQUIRE(dev.Release(copy) == D3D_OK);
    REQUIRE(dev.Release(rt) == D3D_OK);
    return img;
}

Frame render(std::string_view name, UINT w, UINT h, int frame, int frameCount) {
    std::string error;
    std::unique_ptr<glare::Scene> scene = glare::makeScene(name, error);
    REQUIRE(scene);
    DeviceOptions o;
    o.software.threads = 2;
    Device dev(o);
    return render(dev, *scene, w, h, frame, frameCount);
}

double meanLuminance(const Frame& img) {
    double sum = 0;
    for (uint32_t p : img.argb) sum += luminance(p);
    return sum / double(img.argb.size());
}

double fraction(const Frame& img, double threshold) {
    size_t n = 0;
    for (uint32_t p : img.argb) n += luminance(p) > threshold;
    return double(n) / double(img.argb.size());
}

int frameCount(std::string_view name) {
    for (const glare::SceneInfo& s : glare::sceneList())
        if (s.name == name) return s.defaultFrames;
    FAIL("no scene " << name);
    return 0;
}

}  // namespace

TEST_CASE("scene: the list and unknown names", "[scene]") {
    const auto& list = glare::sceneList();
    REQUIRE(list.size() == 6);
    CHECK(list[0].name == "box");
    CHECK(list[1].name == "neon");
    CHECK(list[2].name == "lights");
    CHECK(list[3].name == "sky");
    CHECK(list[4].name == "sparse");
    CHECK(list[5].name == "dense");
    for (const glare::SceneInfo& s : list) {
        CHECK(s.defaultFrames > 1);
        CHECK_FALSE(s.description.empty());
        std::string error;
        CHECK(glare::makeScene(s.name, error));
        CHECK(error.empty());
    }
    std::string error;
    CHECK_FALSE(glare::makeScene("x", error));
    CHECK(error == "unknown scene 'x' (scenes: box, neon, lights, sky, sparse, dense)");
    CHECK_FALSE(glare::makeScene("", error));
    CHECK(error == "unknown scene '' (scenes: box, neon, lights, sky, sparse, dense)");
}

TEST_CASE("scene: every scene renders, deterministically, and moves", "[scene]") {
    for (const glare::SceneInfo& s : glare::sceneList()) {
        INFO(s.name);
        const int n = s.defaultFrames;
        const Frame a = render(s.name, 192, 108, 0, n);
        const Frame b = render(s.name, 192, 108, 0, n);
        CHECK(a.argb == b.argb);
        const Frame last = render(s.name, 192, 108, n - 1, n);
        CHECK(a.argb != last.argb);
        // Alpha is a mask: 0 or 255 only.
        size_t other = 0;
        for (uint32_t p : a.argb) other += (p >> 24) != 0 && (p >> 24) != 255;
        CHECK(other == 0);
        // Something glows in every scene.
        size_t glowing = 0;
        for (uint32_t p : a.argb) glowing += (p >> 24) == 255;
        CHECK(glowing > 0);
    }
}

TEST_CASE("scene: one Scene on one device, frame after frame, with other targets in between", "[scene]") {
    std::string error;
    auto scene = glare::makeScene("box", error);
    REQUIRE(scene);
    Device dev;
    const Frame small = render(dev, *scene, 192, 108, 3, 10);
    const Frame other = render(dev, *scene, 100, 75, 3, 10);  // another size: another depth surface
    CHECK(other.w == 100);
    CHECK(render(dev, *scene, 192, 108, 3, 10).argb == small.argb);
    CHECK(render("box", 192, 108, 3, 10).argb == small.argb);  // same as a fresh device and scene
    // Odd sizes and a 1×1 target work too.
    for (auto [w, h] : {std::pair<UINT, UINT>{1, 1}, {7, 300}, {333, 17}})
        for (const glare::SceneInfo& s : glare::sceneList()) {
            auto sc = glare::makeScene(s.name, error);
            REQUIRE(sc);
            CHECK(render(dev, *sc, w, h, 1, 4).argb.size() == size_t(w) * h);
        }
}

TEST_CASE("scene: the device state is put back", "[scene]") {
    std::string error;
    auto scene = glare::makeScene("neon", error);
    REQUIRE(scene);
    Device dev;
    Handle mine{}, target{}, depth{};
    REQUIRE(dev.CreateRenderTarget(64, 64, D3DFMT_A8R8G8B8, 0, &mine) == D3D_OK);
    REQUIRE(dev.CreateRenderTarget(96, 54, D3DFMT_A8R8G8B8, 0, &target) == D3D_OK);
    REQUIRE(dev.CreateDepthStencilSurface(64, 64, D3DFMT_D16, &depth) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, mine) == D3D_OK);
    REQUIRE(dev.SetDepthStencilSurface(depth) == D3D_OK);
    D3DVIEWPORT9 vp{4, 5, 30, 20, 0.25f, 0.75f};
    REQUIRE(dev.SetViewport(&vp) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ZENABLE, D3DZB_FALSE) == D3D_OK);
    REQUIRE(dev.SetTextureStageState(0, D3DTSS_COLOROP, D3DTOP_ADD) == D3D_OK);
    REQUIRE(dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_TEX1) == D3D_OK);
    const DeviceState before = dev.state();
    REQUIRE(scene->render(dev, target, 0, 2, error));
    CHECK(dev.state() == before);
}

TEST_CASE("scene: bad arguments give errors", "[scene]") {
    std::string error;
    auto scene = glare::makeScene("sky", error);
    REQUIRE(scene);
    Device dev;
    Handle rt{}, tex{}, x8{};
    REQUIRE(dev.CreateRenderTarget(32, 32, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK);
    CHECK_FALSE(scene->render(dev, rt, 0, 0, error));
    CHECK(error == "scene sky: frameCount must be at least 1 (got 0)");
    CHECK_FALSE(scene->render(dev, rt, 4, 4, error));
    CHECK(error == "scene sky: frame 4 out of range 0..3");
    CHECK_FALSE(scene->render(dev, rt, -1, 4, error));
    CHECK(error == "scene sky: frame -1 out of range 0..3");
    CHECK_FALSE(scene->render(dev, Handle(uint32_t(999)), 0, 4, error));
    CHECK(error.rfind("scene sky: Device::GetDesc failed: E41", 0) == 0);
    REQUIRE(dev.CreateTexture(8, 8, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    CHECK_FALSE(scene->render(dev, tex, 0, 4, error));
    CHECK(error.rfind("scene sky: Device::GetDesc failed: ", 0) == 0);
    REQUIRE(dev.CreateRenderTarget(32, 32, D3DFMT_X8R8G8B8, 0, &x8) == D3D_OK);
    CHECK_FALSE(scene->render(dev, x8, 0, 4, error));
    CHECK(error.rfind("scene sky: the target must be an A8R8G8B8 render target", 0) == 0);
    // The device's refusal of a draw is reported with its message: a locked target.
    D3DLOCKED_RECT lr;
    Handle lockable{};
    REQUIRE(dev.CreateRenderTarget(32, 32, D3DFMT_A8R8G8B8, 1, &lockable) == D3D_OK);
    REQUIRE(dev.LockRect(lockable, &lr, nullptr, 0) == D3D_OK);
    CHECK_FALSE(scene->render(dev, lockable, 0, 4, error));
    CHECK(error == "scene sky: Device::Clear failed: E4106 Clear: the render target is locked");
    REQUIRE(dev.UnlockRect(lockable) == D3D_OK);
    CHECK(scene->render(dev, lockable, 0, 4, error));
}

TEST_CASE("scene box: the mean luminance changes strongly from inside to outside", "[scene]") {
    const int n = frameCount("box");
    const double first = meanLuminance(render("box", 192, 108, 0, n));
    const double last = meanLuminance(render("box", 192, 108, n - 1, n));
    INFO("first " << first << " last " << last);
    CHECK(first < 0.3);
    CHECK(last > 0.5);
    CHECK(last > 2.5 * first);
    // Inside, the emissive objects are a good part of the view; outside, a small one.
    const Frame in = render("box", 192, 108, 0, n), out = render("box", 192, 108, n - 1, n);
    auto glow = [](const Frame& img) {
        size_t k = 0;
        for (uint32_t p : img.argb) k += (p >> 24) == 255;
        return double(k) / double(img.argb.size());
    };
    CHECK(glow(in) > 0.08);
    CHECK(glow(out) < 0.02);
    CHECK(glow(out) > 0.0);
}

TEST_CASE("scene neon: alpha marks exactly the bright saturated strips", "[scene]") {
    const int n = frameCount("neon");
    for (int frame : {0, n / 3, n - 1}) {
        const Frame img = render("neon", 192, 108, frame, n);
        size_t glow = 0, brightNoGlow = 0, bright = 0;
        for (uint32_t p : img.argb) {
            const int r = int((p >> 16) & 0xFF), g = int((p >> 8) & 0xFF), b = int(p & 0xFF);
            const int hi = std::max({r, g, b}), lo = std::min({r, g, b});
            if ((p >> 24) == 255) {
                ++glow;
                // Every glowing pixel is a strip: bright and strongly coloured.
                CHECK(hi >= 180);
                CHECK(hi - lo >= hi / 2);
            }
            if (luminance(p) > 0.6) {
                ++bright;
                brightNoGlow += (p >> 24) == 0;
            }
        }
        INFO("frame " << frame << " glow " << glow << " bright " << bright << " bright without glow " << brightNoGlow);
        CHECK(glow > img.argb.size() / 200);
        CHECK(glow < img.argb.size() / 10);
        // The bright diffuse objects are bright too but do not glow: most bright pixels.
        CHECK(brightNoGlow > bright / 2);
    }
}

TEST_CASE("scene lights: a small bright fraction with single-pixel lights", "[scene]") {
    const int n = frameCount("lights");
    for (int frame : {0, n - 1}) {
        const Frame img = render("lights", 192, 108, frame, n);
        const double f = fraction(img, 0.5);
        INFO("frame " << frame << " bright fraction " << f);
        CHECK(f > 0.0);
        CHECK(f < 0.02);
        // Every bright pixel glows, and the dark city does not.
        for (uint32_t p : img.argb)
            if (luminance(p) > 0.5) CHECK((p >> 24) == 255);
    }
    // At 1080p some lights are exactly one pixel: a bright pixel with no bright neighbour.
    const Frame hd = render("lights", 1920, 1080, 0, n);
    CHECK(fraction(hd, 0.5) < 0.02);
    int single = 0;
    for (UINT y = 1; y + 1 < hd.h; ++y)
        for (UINT x = 1; x + 1 < hd.w; ++x) {
            if ((hd.at(x, y) >> 24) != 255) continue;
            bool alone = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if ((dx || dy) && (hd.at(UINT(int(x) + dx), UINT(int(y) + dy)) >> 24) == 255) alone = false;
            single += alone;
        }
    CHECK(single >= 10);
    // The camera moves by less than a pixel a frame: consecutive frames differ in few pixels.
    const Frame f1 = render("lights", 192, 108, 1, n);
    const Frame f0 = render("lights", 192, 108, 0, n);
    size_t changed = 0;
    for (size_t i = 0; i < f0.argb.size(); ++i) changed += f0.argb[i] != f1.argb[i];
    CHECK(changed < f0.argb.size() / 20);
}

TEST_CASE("scene sky: a large bright area", "[scene]") {
    const int n = frameCount("sky");
    for (int frame : {0, n / 2}) {
        const Frame img = render("sky", 192, 108, frame, n);
        const double f = fraction(img, 0.8);
        INFO("frame " << frame << " bright fraction " << f);
        CHECK(f > 0.25);
        CHECK(f < 0.9);  // the ground is darker
        // The sun's core glows and is saturated white.
        size_t sun = 0;
        for (uint32_t p : img.argb)
            if ((p >> 24) == 255) {
                ++sun;
                CHECK((p & 0xFFFFFF) == 0xFFFFFF);
            }
        CHECK(sun > 0);
    }
}

TEST_CASE("scene: the GL renderer draws the same bytes", "[scene][gl]") {
    std::string error;
    const ps11test::RendererFactory factory = ps11test::glRendererFactory("", error);
    INFO(error);
    REQUIRE(factory);
    for (const glare::SceneInfo& s : glare::sceneList()) {
        const int n = s.defaultFrames;
        for (int frame : {0, n / 2, n - 1}) {
            INFO(s.name << " frame " << frame);
            auto scene = glare::makeScene(s.name, error);
            REQUIRE(scene);
            DeviceOptions o;
            o.renderer = factory;
            Device gl(o);
            const Frame a = render(gl, *scene, 192, 108, frame, n);
            const Frame b = render(s.name, 192, 108, frame, n);
            size_t differ = 0, maxDelta = 0;
            for (size_t i = 0; i < a.argb.size(); ++i)
                if (a.argb[i] != b.argb[i]) {
                    ++differ;
                    for (int shift : {0, 8, 16, 24})
                        maxDelta = std::max<size_t>(
                            maxDelta, size_t(std::abs(int((a.argb[i] >> shift) & 0xFF) - int((b.argb[i] >> shift) & 0xFF))));
                }
            INFO(differ << " pixels differ, by at most " << maxDelta << " levels");
            CHECK(differ == 0);
        }
    }
}

TEST_CASE("glow-only black fog fades the glow masks with distance and leaves the colours", "[scene]") {
    Device dev;
    std::string error;
    std::unique_ptr<glare::Scene> plain = glare::makeScene("neon", error), fogged = glare::makeScene("neon", error);
    REQUIRE(plain);
    REQUIRE(fogged);
    fogged->setGlowFog(4.0f, 9.0f);  // the neon wall stands about 6 to 9 units from the camera
    const Frame a = render(dev, *plain, 192, 108, 2, 8);
    const Frame b = render(dev, *fogged, 192, 108, 2, 8);
    uint64_t alphaA = 0, alphaB = 0, partial = 0;
    for (size_t i = 0; i < a.argb.size(); ++i) {
        CHECK((a.argb[i] & 0xffffff) == (b.argb[i] & 0xffffff));  // colours unchanged
        const uint32_t x = a.argb[i] >> 24, y = b.argb[i] >> 24;
        CHECK(y <= x);
        alphaA += x;
        alphaB += y;
        partial += y > 0 && y < 255;
    }
    CHECK(alphaB < alphaA);
    CHECK(alphaB > 0);
    CHECK(partial > 0);
    // end <= start turns it off again.
    fogged->setGlowFog(5.0f, 5.0f);
    CHECK(render(dev, *fogged, 192, 108, 2, 8).argb == a.argb);
}

TEST_CASE("scene: sparse has about 1 % of its pixels above the thresholds, dense all of them", "[scene]") {
    // The thresholds the techniques publish: adaptive 0.4, pyramid 0.6, the sprites' sensors 0.8
    // (luminance); glow reads the mask (alpha 255).
    for (int frame : {0, 17, 59}) {
        INFO("frame " << frame);
        const Frame sparse = render("sparse", 1920, 1080, frame, 60), dense = render("dense", 1920, 1080, frame, 60);
        const double bright = fraction(sparse, 0.4);
        CHECK(bright > 0.008);
        CHECK(bright < 0.013);
        CHECK(fraction(sparse, 0.8) > 0.008);
        size_t black = 0, masked = 0;
        for (uint32_t p : sparse.argb) black += (p & 0xFFFFFFu) == 0, masked += (p >> 24) == 0xFF;
        CHECK(black == 0);  // dark, never black
        CHECK(double(masked) / double(sparse.argb.size()) < 0.013);
        CHECK(fraction(dense, 0.8) == 1.0);
        size_t unmasked = 0;
        for (uint32_t p : dense.argb) unmasked += (p >> 24) != 0xFF;
        CHECK(unmasked == 0);
    }
    // The view moves.
    CHECK(render("sparse", 192, 108, 0, 60).argb != render("sparse", 192, 108, 1, 60).argb);
}
