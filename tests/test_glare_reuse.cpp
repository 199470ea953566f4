// Glare reuse and tile skipping (glare/runner.h RunnerOptions::skip, docs/glare/README.md "Reuse"):
// frames byte-identical with skipping on and off, moving and held still, on both renderers and
// every hardware class; the sprites' glare image uploaded again only when it changed; a still
// frame skipped whole until anything it depends on changes.
#include <catch2/catch.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "glare/runner.h"
#include "glare/scene.h"
#include "glare/technique.h"
#include "ps11/hardware.h"
#include "runner/gl_backend.h"

using namespace glare;

namespace {

// Every technique with reuse on and off (RunnerOptions::skip) on one renderer and profile: three
// frames of its moving scene, then the last scene frame set as an image and held for three
// frames (nothing changes: passes are reused), then a different image (what depends on it runs
// again), then the first image again. Every frame's output must be byte-identical.
void checkReuse(const emu::DeviceOptions& device) {
    for (const glare::Technique* t : glare::techniques()) {
        INFO(t->name());
        const glare::Settings settings = *glare::presetSettings(*t, "published");
        glare::RunnerOptions on, off;
        on.width = off.width = 160;
        on.height = off.height = 96;
        on.device = off.device = device;
        off.skip = false;
        off.device.software.putOffCopies = false;  // and every copy made at once (the float targets' are put off)
        glare::Runner a(on), b(off);
        std::string err;
        std::unique_ptr<glare::Scene> sa = glare::makeScene(t->scene(), err), sb = glare::makeScene(t->scene(), err);
        REQUIRE(sa);
        const int frames = 9;
        size_t reusedWhileStill = 0, passesWhileStill = 0, reusedAfterChange = 0;
        std::optional<emu::RgbaImage> held;
        for (int f = 0; f < frames; ++f) {
            INFO("frame " << f);
            double ms = 0;
            if (f < 3) {
                REQUIRE(a.renderScene(*sa, f, frames, ms, err));
                REQUIRE(b.renderScene(*sb, f, frames, ms, err));
                if (f == 2) held = a.readTexture(a.sceneTexture(), err);
            } else if (f == 3 || f == 7) {
                REQUIRE(held);
                REQUIRE(a.setImage(*held, err));
                REQUIRE(b.setImage(*held, err));
            } else if (f == 6) {
                emu::RgbaImage other = *held;
                for (size_t i = 0; i < other.rgba.size(); i += 97) other.rgba[i] = uint8_t(255 - other.rgba[i]);
                REQUIRE(a.setImage(other, err));
                REQUIRE(b.setImage(other, err));
            }
            glare::FrameResult ra, rb;
            REQUIRE(a.runFrame(*t, settings, f, frames, ra, err));
            REQUIRE(b.runFrame(*t, settings, f, frames, rb, err));
            const std::optional<emu::RgbaImage> oa = a.readOutput(err), ob = b.readOutput(err);
            REQUIRE(oa);
            REQUIRE(ob);
            REQUIRE(oa->rgba == ob->rgba);
            size_t reused = 0;
            for (const glare::PassStats& st : ra.passes) reused += st.reused;
            for (const glare::PassStats& st : rb.passes) CHECK(!st.reused);
            if (f == 4 || f == 5) reusedWhileStill += reused, passesWhileStill += ra.passes.size();
            if (f == 6) reusedAfterChange = reused;
        }
        // Held still, passes are reused in every technique, on both renderers (not all: a
        // read-back step, what writes CPU data, and passes whose outputs later passes of the frame
        // blend onto run every frame; docs/glare/README.md "Reuse"); after the image changed,
        // fewer. On GL the adaptation's 1×1 state is read by its bytes (docs/device.md "Fingerprints").
        CHECK(reusedWhileStill >= 2);
        CHECK(reusedWhileStill <= passesWhileStill);
        CHECK(reusedAfterChange * 2 < reusedWhileStill + 2);
    }
}

}  // namespace

TEST_CASE("reuse: frames are byte-identical with skipping on and off, moving and still", "[glare][reuse]") {
    checkReuse({});  // the 1.1-class card
    emu::DeviceOptions ideal;
    ideal.precision = ps11::Precision::Ideal;
    checkReuse(ideal);
}

TEST_CASE("tiles: sparse and dense frames are byte-identical with skipping on and off, every hardware class",
          "[glare][reuse]") {
    // Skipping's measuring scenes, moving, on every hardware class (fx8, fx12, float) and under
    // ideal: the software renderer fills, copies and skips tiles (docs/device.md "Tile
    // skipping"), reuses passes and puts the scene's copy off into the composite's bands; the
    // frames must be those of every pass run, every tile drawn and every copy made at once.
    uint64_t decided = 0;
    std::vector<emu::DeviceOptions> devices;
    for (const ps11::HardwareClass& h : ps11::hardwareClasses()) {
        emu::DeviceOptions d;
        d.hardware = &h;
        devices.push_back(d);
    }
    devices.emplace_back().precision = ps11::Precision::Ideal;
    for (const emu::DeviceOptions& device : devices) {
        INFO((device.hardware ? std::string(device.hardware->name) : std::string("ideal")));
        for (const glare::Technique* t : glare::techniques()) {
            INFO(t->name());
            const glare::Settings settings = *glare::presetSettings(*t, "published");
            for (const char* sceneName : {"sparse", "dense"}) {
                INFO(sceneName);
                glare::RunnerOptions on, off;
                on.width = off.width = 192;
                on.height = off.height = 108;
                on.device = off.device = device;
                on.device.software.timeTiles = false;  // decided by the share of tiles: the count below holds
                off.skip = false;
                off.device.software.putOffCopies = false;  // copies made at once (docs/device.md "StretchRect")
                glare::Runner a(on), b(off);
                std::string err;
                std::unique_ptr<glare::Scene> sa = glare::makeScene(sceneName, err), sb = glare::makeScene(sceneName, err);
                REQUIRE(sa);
                for (int f = 0; f < 3; ++f) {
                    INFO("frame " << f);
                    double ms = 0;
                    REQUIRE(a.renderScene(*sa, f, 60, ms, err));
                    REQUIRE(b.renderScene(*sb, f, 60, ms, err));
                    glare::FrameResult ra, rb;
                    REQUIRE(a.runFrame(*t, settings, f, 60, ra, err));
                    REQUIRE(b.runFrame(*t, settings, f, 60, rb, err));
                    const std::optional<emu::RgbaImage> oa = a.readOutput(err), ob = b.readOutput(err);
                    REQUIRE(oa);
                    REQUIRE(ob);
                    REQUIRE(oa->rgba == ob->rgba);
                    for (const glare::PassStats& st : ra.passes) decided += st.tilesFilled + st.tilesCopied + st.tilesSkipped;
                    for (const glare::PassStats& st : rb.passes)
                        CHECK(st.tilesFilled + st.tilesCopied + st.tilesSkipped == 0);
                }
            }
        }
    }
    INFO("tiles filled, copied or skipped: " << decided);
    CHECK(decided > 1000);
}

namespace {

// A runner with reuse on and one that runs every pass (RunnerOptions::skip off), w × h, both
// holding the first frame of the technique's own scene as an image.
struct HeldPair {
    std::unique_ptr<glare::Runner> on, off;
    emu::RgbaImage image;
};
HeldPair heldPair(const glare::Technique& t, uint32_t w, uint32_t h) {
    glare::RunnerOptions on, off;
    on.width = off.width = w;
    on.height = off.height = h;
    off.skip = false;
    HeldPair p{std::make_unique<glare::Runner>(on), std::make_unique<glare::Runner>(off), {}};
    std::string err;
    std::unique_ptr<glare::Scene> scene = glare::makeScene(t.scene(), err);
    REQUIRE(scene);
    double ms = 0;
    REQUIRE(p.on->renderScene(*scene, 0, 1, ms, err));
    std::optional<emu::RgbaImage> image = p.on->readTexture(p.on->sceneTexture(), err);
    REQUIRE(image);
    p.image = *image;
    REQUIRE(p.on->setImage(p.image, err));
    REQUIRE(p.off->setImage(p.image, err));
    return p;
}

}  // namespace

TEST_CASE("sprites: the glare image is uploaded again only when its texture or the streaks change", "[glare][reuse]") {
    // One runner with reuse on against one with skipping off, the image held still: the glare
    // image's upload is reused while its texture holds it; changing the streaks mid-run (the
    // image kept on the runner is rebuilt) uploads it again, and every frame's output equals the
    // skip-off runner's.
    const glare::Technique* t = glare::findTechnique("sprites");
    REQUIRE(t);
    glare::Settings settings = *glare::presetSettings(*t, "published");
    HeldPair held = heldPair(*t, 160, 96);
    glare::Runner &a = *held.on, &b = *held.off;
    std::string err;
    const auto imagePass = [](const glare::FrameResult& r) {
        for (const glare::PassStats& st : r.passes)
            if (st.pass == "glare_image") return st;
        FAIL("no glare_image pass");
        return glare::PassStats{};
    };
    for (int f = 0; f < 6; ++f) {
        INFO("frame " << f);
        if (f == 3) settings["streaks"] = settings["streaks"] + 2;
        glare::FrameResult ra, rb;
        REQUIRE(a.runFrame(*t, settings, f, 6, ra, err));
        REQUIRE(b.runFrame(*t, settings, f, 6, rb, err));
        const std::optional<emu::RgbaImage> oa = a.readOutput(err), ob = b.readOutput(err);
        REQUIRE(oa);
        REQUIRE(ob);
        REQUIRE(oa->rgba == ob->rgba);
        CHECK_FALSE(imagePass(rb).reused);
        CHECK(imagePass(ra).reused == (f != 0 && f != 3));
    }
}

TEST_CASE("reuse: a still frame whose every pass was reused is skipped whole, until anything it depends on changes",
          "[glare][reuse]") {
    // Pyramid's build reads no frame index: held still, from its third frame on it is skipped
    // whole (FrameResult::still). A setting, the image, the output's contents, the persistent
    // textures, a hook: each makes the next frame run. Adaptive's build asks only whether the
    // frame is the first (a converged start writes its amount instead of blending it): skipped
    // whole too once its amount stops changing, but not on another first frame. Glow with its
    // strength ramping and adaptive with its temporal dither read the frame index: never skipped
    // whole. Every output equals the one of a runner that runs every pass.
    const auto run = [](const char* name, glare::Settings settings, auto change, std::vector<int> wantStill) {
        INFO(name);
        const glare::Technique* t = glare::findTechnique(name);
        REQUIRE(t);
        HeldPair held = heldPair(*t, 192, 108);
        glare::Runner &a = *held.on, &b = *held.off;
        std::string err;
        for (int f = 0; f < int(wantStill.size()); ++f) {
            INFO("frame " << f);
            change(f, *t, a, b, settings, held.image);
            glare::FrameResult ra, rb;
            REQUIRE(a.runFrame(*t, settings, f, 100, ra, err));
            REQUIRE(b.runFrame(*t, settings, f, 100, rb, err));
            CHECK(ra.still == (wantStill[size_t(f)] != 0));
            CHECK_FALSE(rb.still);
            if (ra.still)
                for (const glare::PassStats& p : ra.passes) CHECK(p.reused);
            const std::optional<emu::RgbaImage> oa = a.readOutput(err), ob = b.readOutput(err);
            REQUIRE(oa);
            REQUIRE(ob);
            REQUIRE(oa->rgba == ob->rgba);
        }
    };
    const auto nothing = [](int, const glare::Technique&, glare::Runner&, glare::Runner&, glare::Settings&,
                            emu::RgbaImage&) {};
    run("pyramid", *glare::presetSettings(*glare::findTechnique("pyramid"), "published"),
        [](int f, const glare::Technique& t, glare::Runner& a, glare::Runner& b, glare::Settings& s,
           emu::RgbaImage& image) {
            std::string err;
            if (f == 4) s["strength"] = 0.5;  // a setting
            if (f == 7) {                     // the image
                image.rgba[400] ^= 0x80;
                REQUIRE(a.setImage(image, err));
                REQUIRE(b.setImage(image, err));
            }
            if (f == 10) {  // the output's contents, written by the application
                emu::Handle out{};
                REQUIRE(a.device().GetSurfaceLevel(a.outputTexture(), 0, &out) == emu::D3D_OK);
                REQUIRE(a.device().SetRenderTarget(0, out) == emu::D3D_OK);
                REQUIRE(a.device().Clear(0, nullptr, D3DCLEAR_TARGET, 0xff00ff00, 1, 0) == emu::D3D_OK);
            }
            if (f == 13) a.resetPersistent(), b.resetPersistent();
            if (f == 16) {  // with a hook every pass runs (reused or not), the frame is not skipped whole
                glare::FrameResult r;
                REQUIRE(a.runFrame(t, s, f, 100, r, err, [](uint32_t, bool, std::string&) { return true; }));
                CHECK_FALSE(r.still);
            }
        },
        // (Pyramid keeps no persistent texture: after their reset the frame reuses every pass. A
        // hook that may write keeps each pass its own group: the next frame finds other groups.)
        std::vector<int>{0, 0, 1, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 1, 1, 0, 0, 1, 1});
    glare::Settings glow = *glare::presetSettings(*glare::findTechnique("glow"), "published");
    glow["ramp"] = 0.5;
    run("glow", glow, nothing, std::vector<int>{0, 0, 0, 0, 0});
    glare::Settings adaptive = *glare::presetSettings(*glare::findTechnique("adaptive"), "published");
    REQUIRE(adaptive["dither"] == 0);
    run("adaptive", adaptive,
        [](int f, const glare::Technique&, glare::Runner& a, glare::Runner& b, glare::Settings& s, emu::RgbaImage&) {
            // Frame 6 runs as frame 0 again (below): the converged start writes the amount.
            if (f == 6) {
                std::string err;
                glare::FrameResult ra, rb;
                REQUIRE(a.runFrame(*glare::findTechnique("adaptive"), s, 0, 100, ra, err));
                REQUIRE(b.runFrame(*glare::findTechnique("adaptive"), s, 0, 100, rb, err));
                CHECK_FALSE(ra.still);
                const std::optional<emu::RgbaImage> oa = a.readOutput(err), ob = b.readOutput(err);
                REQUIRE(oa);
                REQUIRE(ob);
                CHECK(oa->rgba == ob->rgba);
            }
        },
        std::vector<int>{0, 0, 0, 1, 1, 1, 0, 0, 1, 1});
    adaptive["dither"] = 1;
    run("adaptive", adaptive, nothing, std::vector<int>{0, 0, 0, 0, 0});
}

TEST_CASE("reuse: the same on the GL renderer", "[glare][reuse][gl]") {
    std::string error;
    emu::DeviceOptions gl;
    gl.renderer = ps11test::glRendererFactory("", error);
    REQUIRE(gl.renderer);
    checkReuse(gl);
}
