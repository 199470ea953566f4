// `ps11 debug --technique` (glare/frame_debug.h): the walk from the output pixel reaches the
// scene, and every shader pass it visits is retraced to exactly the pixel the frame stored, on
// the class and under ideal (the trace reproduces what the frame computed).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "glare/frame_debug.h"
#include "glare/technique.h"

using namespace glare;

namespace {

FrameDebug follow(const char* technique, const char* scene, uint32_t x, uint32_t y, int frame = 0) {
    FrameDebugRequest rq;
    rq.technique = findTechnique(technique);
    REQUIRE(rq.technique);
    rq.settings = *presetSettings(*rq.technique, "published");
    rq.scene = scene;
    rq.width = 160, rq.height = 90;
    rq.frame = frame;
    rq.x = x, rq.y = y;
    FrameDebug fd;
    std::string error;
    const bool ok = debugFrame(rq, fd, error);
    INFO(error);
    REQUIRE(ok);
    return fd;
}

uint8_t byte(float v) { return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

// Every shader pass's retrace stores what the frame stored: the grid values on the fx8 class
// (its targets are 8-bit), the floats under ideal.
void checkReproduced(const FrameDebug& fd) {
    REQUIRE(fd.fx);
    size_t shaders = 0;
    for (const DebugPass& p : fd.passes) {
        INFO("pass " << p.pass << " at " << p.x << "," << p.y);
        if (p.kind != "shader") continue;
        ++shaders;
        REQUIRE(p.traced);
        REQUIRE(!p.steps.empty());
        for (size_t c = 0; c < 4; ++c) {
            CHECK(byte(p.tracedEmulated[c]) == byte(p.emulated[c]));
            CHECK(p.tracedEmulated[c] == p.emulated[c]);
            CHECK(p.tracedIdeal[c] == p.ideal[c]);
        }
    }
    CHECK(shaders > 0);
}

}  // namespace

TEST_CASE("frame debug: adaptive from the composite back to the scene, every pass retraced exactly",
          "[glare][frame_debug]") {
    const FrameDebug fd = follow("adaptive", "box", 80, 45);
    REQUIRE(!fd.passes.empty());
    CHECK(fd.passes.back().pass == "composite");
    CHECK(fd.passes.back().x == 80);
    CHECK(fd.passes.back().y == 45);
    std::vector<std::string> names;
    for (const DebugPass& p : fd.passes) names.push_back(p.pass);
    for (const char* n : {"luminance_128", "luminance_2", "glare_amount", "bright_pass", "blur_0", "blur_4", "composite"})
        CHECK(std::find(names.begin(), names.end(), n) != names.end());
    bool reachesScene = false;
    for (const DebugPass& p : fd.passes)
        for (const DebugSource& s : p.sources) {
            reachesScene = reachesScene || s.origin == "scene input";
            if (s.from >= 0) {
                REQUIRE(size_t(s.from) < fd.passes.size());
                CHECK(fd.passes[size_t(s.from)].graphIndex < p.graphIndex);  // run order
            }
        }
    CHECK(reachesScene);
    checkReproduced(fd);
    // The steps end on the pass's r0: the composite writes without blending into an 8-bit
    // target, so its last step is the stored pixel on the class.
    const DebugPass& composite = fd.passes.back();
    for (size_t c = 0; c < 3; ++c) CHECK(composite.steps.back().grid[c] == int(byte(composite.emulated[c])));
    REQUIRE(fd.mostError >= 0);
    for (const DebugPass& p : fd.passes) CHECK(p.added <= fd.passes[size_t(fd.mostError)].added);
}

TEST_CASE("frame debug: blends onto the target (alpha smoothing, ONE/ONE) are retraced too", "[glare][frame_debug]") {
    // Frame 1 of adaptive blends the glare amount into last frame's (SRCALPHA/INVSRCALPHA).
    const FrameDebug a = follow("adaptive", "box", 80, 45, 1);
    const auto amount = std::find_if(a.passes.begin(), a.passes.end(), [](const DebugPass& p) { return p.pass == "glare_amount"; });
    REQUIRE(amount != a.passes.end());
    CHECK(std::any_of(amount->sources.begin(), amount->sources.end(),
                      [](const DebugSource& s) { return s.role == "target" && s.origin == "kept from the previous frame"; }));
    checkReproduced(a);
    // glow adds its blur passes (ONE, ONE) and composites onto the copied scene.
    const FrameDebug g = follow("glow", "neon", 80, 45);
    CHECK(std::any_of(g.passes.begin(), g.passes.end(), [](const DebugPass& p) { return p.pass == "copy_scene"; }));
    checkReproduced(g);
}

TEST_CASE("frame debug: a pixel outside the frame is refused, naming --pixel", "[glare][frame_debug]") {
    FrameDebugRequest rq;
    rq.technique = findTechnique("quarter");
    rq.settings = *presetSettings(*rq.technique, "published");
    rq.scene = "lights";
    rq.width = 64, rq.height = 48;
    rq.x = 64, rq.y = 0;
    FrameDebug fd;
    std::string error;
    CHECK(!debugFrame(rq, fd, error));
    CHECK(error.find("--pixel 64,0") != std::string::npos);
}
