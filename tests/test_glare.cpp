// The glare techniques (glare/): shaders, the pass graph, every technique on both renderers, and
// GLARE.md's behaviours with thresholds derived from its formulas.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>

#include "emu/fullscreen.h"
#include "glare/compare.h"
#include "glare/glow.h"
#include "glare/passes.h"
#include "glare/report.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "glare/shader_library.h"
#include "emu/thread_pool.h"
#include "glare/sprites.h"
#include "glare/stress.h"
#include "ps11/assembler.h"
#include "ps11/validator.h"
#include "runner/gl_backend.h"
#include "simd_levels.h"

using namespace glare;

namespace {

emu::FloatImage uniform(uint32_t w, uint32_t h, float r, float g, float b, float a = 1) {
    emu::FloatImage img{w, h, {}};
    for (size_t i = 0; i < size_t(w) * h; ++i) img.rgba.insert(img.rgba.end(), {r, g, b, a});
    return img;
}

// The value of a 1x1 (or the first texel of a) texture, as stored: floats read exactly.
std::array<double, 4> texel(Runner& r, emu::Handle texture) {
    emu::Handle s{};
    REQUIRE(r.device().GetSurfaceLevel(texture, 0, &s) == D3D_OK);
    std::string err;
    std::optional<emu::SurfacePixels> px = emu::readSurface(r.device(), s, err);
    REQUIRE(px);
    std::array<double, 4> v{};
    if (px->format == D3DFMT_A8R8G8B8) {
        v = {px->bytes[2] / 255.0, px->bytes[1] / 255.0, px->bytes[0] / 255.0, px->bytes[3] / 255.0};
    } else {
        float f[4];
        std::memcpy(f, px->bytes.data(), 16);
        v = {f[0], f[1], f[2], f[3]};
    }
    return v;
}

RunnerOptions options(uint32_t w, uint32_t h, std::optional<ps11::Precision> p = std::nullopt) {
    RunnerOptions ro;
    ro.width = w;
    ro.height = h;
    ro.device.precision = p;
    return ro;
}

Settings preset(const char* technique, const char* name = "published") {
    return *presetSettings(*findTechnique(technique), name);
}

}  // namespace

TEST_CASE("every glare shader assembles and validates as ps_1_1", "[glare]") {
    REQUIRE(embeddedShaders().size() >= 10);
    for (const EmbeddedShader& s : embeddedShaders()) {
        INFO(s.name);
        ps11::Diagnostics diags;
        std::optional<ps11::Program> p = ps11::parseAssembly(s.text, std::string(s.name), {}, diags);
        REQUIRE(p);
        ps11::ShaderStats stats;
        CHECK(ps11::validate(*p, diags, &stats));
        CHECK(stats.version.minor == 1);
        CHECK(stats.texSlots <= stats.texLimit);
        CHECK(stats.arithSlots <= stats.arithLimit);
    }
}

TEST_CASE("the embedded shaders are the files in glare/shaders", "[glare]") {
    for (const EmbeddedShader& s : embeddedShaders()) {
        std::ifstream f(std::string(PS11_SOURCE_DIR) + "/glare/shaders/" + std::string(s.name), std::ios::binary);
        REQUIRE(f);
        std::stringstream text;
        text << f.rdbuf();
        CHECK(text.str() == s.text);
    }
}

TEST_CASE("pass graph: culling, order, lifetimes and aliasing", "[glare][graph]") {
    emu::Device device;
    TexturePool pool(device);
    emu::Handle out{};
    REQUIRE(device.CreateTexture(16, 16, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &out) == D3D_OK);
    PassGraph g;
    const TextureId output = g.import("output", {16, 16}, out, true);
    const TextureDesc small{8, 8};
    const TextureId a = g.create("a", small), b = g.create("b", small), c = g.create("c", small),
                    unused = g.create("unused", small);
    std::vector<std::string> ran;
    auto clearPass = [&](const char* name, std::vector<TextureId> reads, TextureId write) {
        g.addPass(
            PassInfo{name, PassKind::Clear, "", ""},
            [&](PassBuilder& pb) {
                for (TextureId r : reads) pb.read(r);
                pb.write(write);
            },
            [&ran, name, write](PassContext& ctx) {
                ran.push_back(name);
                return ctx.clear(write, 0xff102030);
            });
    };
    clearPass("make_a", {}, a);
    clearPass("make_unused", {a}, unused);  // nobody reads it: culled
    clearPass("a_to_b", {a}, b);
    clearPass("b_to_c", {b}, c);  // a is dead from here: c may take a's device texture
    clearPass("overwritten", {}, output);  // the next pass overwrites output without reading: culled
    clearPass("c_to_output", {c}, output);
    g.compile();
    CHECK(g.livePassNames() == std::vector<std::string>{"make_a", "a_to_b", "b_to_c", "c_to_output"});
    std::vector<PassStats> stats;
    std::string err;
    REQUIRE(g.run(pool, stats, err));
    CHECK(ran == std::vector<std::string>{"make_a", "a_to_b", "b_to_c", "c_to_output"});
    CHECK(stats.size() == 4);
    CHECK(g.texture(a).firstUse == 0);
    CHECK(g.texture(a).lastUse == 2);
    CHECK(g.texture(unused).firstUse == -1);
    // a and b live together (a_to_b); c starts after a's last use, so it reuses a's texture.
    CHECK(g.texture(a).physical != g.texture(b).physical);
    CHECK(g.texture(c).physical == g.texture(a).physical);
    CHECK(pool.created() == 2);
    const std::string dot = g.graphviz("test");
    CHECK(dot.find("make_unused") != std::string::npos);
    CHECK(dot.find("style=dashed, fontcolor=gray") != std::string::npos);
    // Running again takes the same pooled textures: nothing new is made.
    stats.clear();
    REQUIRE(g.run(pool, stats, err));
    CHECK(pool.created() == 2);
}

TEST_CASE("pass graph: a technique's transient textures share device textures where their lives allow", "[glare][graph]") {
    // glow (published, no after-image): sources → h blur → v blur → composite. "glow h" lives from
    // the first h pass to the last v pass, with "glow sources" until the last h pass; "glow" starts at
    // the first v pass, after the sources' last use, so it takes their texture. Aliasing is the
    // run without reuse (with it every transient keeps a texture of its own between frames).
    RunnerOptions ro = options(96, 64);
    ro.skip = false;
    Runner run(ro);
    std::string err;
    REQUIRE(run.setImage(uniform(96, 64, 0.5f, 0.5f, 0.5f), err));
    const Technique& t = *findTechnique("glow");
    const Settings s = preset("glow");
    std::vector<PassGraph::TextureNode> nodes;
    std::vector<std::string> live;
    FrameResult r;
    REQUIRE(run.runFrame(t, s, 0, 1, r, err, {}, [&](PassGraph& g) {
        nodes = g.textures();
        live = g.livePassNames();
    }));
    auto node = [&](const std::string& name) {
        for (const auto& n : nodes)
            if (n.name == name) return n;
        FAIL("no texture " << name);
        return nodes.front();
    };
    CHECK(node("glow sources").physical == node("glow").physical);
    CHECK(node("glow h").physical != node("glow").physical);
    CHECK(node("glow h").physical != node("glow sources").physical);
    CHECK(live.front() == "glow_source");
    CHECK(live.back() == "composite");
    CHECK(r.passes.size() == live.size());
    // Two textures of the glow buffer's size serve three transient textures.
    CHECK(run.pool().created() == 2);
    // The traffic floor: copy_scene reads and writes one 96x64 A8R8G8B8 frame.
    for (const PassStats& p : r.passes)
        if (p.pass == "copy_scene") CHECK(p.bytes == 2u * 96 * 64 * 4);
}

namespace {

// A pass graph over a device with one imported 8x8 output, for the self-containment tests.
struct SmallGraph {
    emu::Device device;
    TexturePool pool{device};
    emu::Handle out{};
    PassGraph graph;
    TextureId output;
    SmallGraph() {
        REQUIRE(device.CreateTexture(8, 8, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &out) == D3D_OK);
        output = graph.import("output", {8, 8}, out, true);
    }
    bool run(std::string& error) {
        std::vector<PassStats> stats;
        return graph.run(pool, stats, error);
    }
    uint32_t pixel() {
        emu::Handle s{};
        REQUIRE(device.GetSurfaceLevel(out, 0, &s) == D3D_OK);
        std::string err;
        std::optional<emu::SurfacePixels> px = emu::readSurface(device, s, err);
        REQUIRE(px);
        uint32_t v = 0;
        std::memcpy(&v, px->bytes.data(), 4);
        return v;
    }
};

// Fixed function: the vertex colour, as it is (stage 0 selects the diffuse colour and alpha).
bool drawDiffuse(PassContext& c, D3DCOLOR colour) {
    emu::Device& d = c.device;
    return c.check(d.SetPixelShader(emu::Handle::Null)) &&
           c.check(d.SetTextureStageState(0, D3DTSS_COLOROP, D3DTOP_SELECTARG1)) &&
           c.check(d.SetTextureStageState(0, D3DTSS_COLORARG1, D3DTA_DIFFUSE)) &&
           c.check(d.SetTextureStageState(0, D3DTSS_ALPHAOP, D3DTOP_SELECTARG1)) &&
           c.check(d.SetTextureStageState(0, D3DTSS_ALPHAARG1, D3DTA_DIFFUSE)) && c.drawQuad({}, colour);
}

}  // namespace

TEST_CASE("pass graph: every pass starts from the state run() found, and run() leaves it behind", "[glare][graph]") {
    SmallGraph g;
    emu::Handle tex{};
    REQUIRE(g.device.CreateTexture(4, 4, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    // The caller's state: not D3D9's defaults everywhere.
    REQUIRE(g.device.SetRenderState(D3DRS_TEXTUREFACTOR, 0x12345678) == D3D_OK);
    REQUIRE(g.device.SetTextureStageState(3, D3DTSS_COLOROP, D3DTOP_ADD) == D3D_OK);
    const emu::DeviceState initial = g.device.state();
    const TextureId scratch = g.graph.create("scratch", {8, 8});
    std::vector<emu::DeviceState> seen;
    // The first pass turns additive blending on and binds a texture, and does not turn them off.
    g.graph.addPass(
        PassInfo{"leaky", PassKind::FixedFunction, "", ""}, [&](PassBuilder& b) { b.write(scratch); },
        [&](PassContext& c) {
            seen.push_back(c.device.state());
            emu::Device& d = c.device;
            return c.clear(scratch, 0xff000000) && c.check(d.SetRenderState(D3DRS_ALPHABLENDENABLE, 1)) &&
                   c.check(d.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE)) &&
                   c.check(d.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE)) && c.check(d.SetTexture(1, tex)) &&
                   drawDiffuse(c, 0xff101010);
        });
    // The second clears the output to 0x40 grey and draws 0x20 grey over it: 0x20 when blending
    // is off, 0x60 had the first pass's blending leaked into it.
    g.graph.addPass(
        PassInfo{"after", PassKind::FixedFunction, "", ""},
        [&](PassBuilder& b) {
            b.read(scratch);
            b.write(g.output);
        },
        [&](PassContext& c) {
            seen.push_back(c.device.state());
            return c.clear(g.output, 0xff404040) && drawDiffuse(c, 0xff202020);
        });
    std::string err;
    REQUIRE(g.run(err));
    REQUIRE(seen.size() == 2);
    CHECK(seen[0] == initial);
    CHECK(seen[1] == initial);
    CHECK(g.pixel() == 0xff202020u);
    CHECK(g.device.state() == initial);

    // After a failing pass too.
    g.graph.addPass(
        PassInfo{"fails", PassKind::FixedFunction, "", ""}, [&](PassBuilder& b) { b.readWrite(g.output); },
        [&](PassContext& c) {
            c.device.SetRenderState(D3DRS_ZENABLE, D3DZB_TRUE);
            c.device.SetTexture(0, tex);
            c.error = "pass fails: on purpose";
            return false;
        });
    CHECK_FALSE(g.run(err));
    CHECK(err == "pass fails: on purpose");
    CHECK(g.device.state() == initial);

    // A state that can no longer be put back (a texture released in a pass) fails the run, naming it.
    PassGraph released;
    const TextureId out = released.import("output", {8, 8}, g.out, true);
    released.addPass(
        PassInfo{"release", PassKind::Clear, "", ""}, [&](PassBuilder& b) { b.write(out); },
        [&](PassContext& c) { return c.check(c.device.Release(tex)) && c.clear(out, 0); });
    REQUIRE(g.device.SetTexture(2, tex) == D3D_OK);
    std::vector<PassStats> stats;
    CHECK_FALSE(released.run(g.pool, stats, err));
    CHECK(err == "after the passes: E4102 applyState: SetTexture: handle " + std::to_string(uint32_t(tex)) +
                     " is not an object of this device (the block's texture of stage 2)");
}

TEST_CASE("pass graph: a pass reaches only the textures it declared", "[glare][graph]") {
    SmallGraph g;
    const TextureId other = g.graph.create("other", {8, 8});
    g.graph.addPass(
        PassInfo{"make_other", PassKind::Clear, "", ""}, [&](PassBuilder& b) { b.write(other); },
        [&](PassContext& c) { return c.clear(other, 0); });
    // What the pass's execute does with `other`, which it does not declare.
    std::function<bool(PassContext&)> peek;
    g.graph.addPass(
        PassInfo{"peek", PassKind::Clear, "", ""}, [&](PassBuilder& b) { b.readWrite(g.output); },
        [&](PassContext& c) { return peek(c); });
    const std::string undeclared =
        "pass peek: texture other was not declared by the pass (declare it with read() or write() in setup)";
    auto fails = [&](const std::function<bool(PassContext&)>& f, const std::string& message) {
        peek = f;
        std::string err;
        CHECK_FALSE(g.run(err));
        CHECK(err == message);
        CHECK(g.device.state() == emu::DeviceState{});
    };
    emu::Handle seenTexture{emu::Handle(1234)}, seenSurface{emu::Handle(1234)};
    TextureDesc seenDesc;
    // Even an execute step that goes on and reports success fails the pass.
    fails(
        [&](PassContext& c) {
            seenTexture = c.texture(other);
            seenSurface = c.surface(other);
            seenDesc = c.desc(other);
            return true;
        },
        undeclared);
    CHECK(seenTexture == emu::Handle::Null);
    CHECK(seenSurface == emu::Handle::Null);
    CHECK(seenDesc.width == 0);
    CHECK(seenDesc.format == D3DFMT_UNKNOWN);
    fails([&](PassContext& c) { return c.setTarget(other); }, undeclared);
    fails([&](PassContext& c) { return c.clear(other, 0); }, undeclared);
    fails([&](PassContext& c) { return c.stretch(other, g.output, D3DTEXF_POINT); }, undeclared);
    fails([&](PassContext& c) { return c.stretch(g.output, other, D3DTEXF_POINT); }, undeclared);
    fails([&](PassContext& c) { return c.texture(TextureId{99}) != emu::Handle::Null; },
          "pass peek: texture #99 is not a texture of this graph");
    fails([&](PassContext& c) { return c.texture(TextureId{}) != emu::Handle::Null; },
          "pass peek: texture (invalid id) is not a texture of this graph");
    // The declared texture is there.
    peek = [&](PassContext& c) { return c.texture(g.output) == g.out && c.desc(g.output).width == 8; };
    std::string err;
    CHECK(g.run(err));

    // A target must be declared written, a StretchRect source read.
    PassGraph h;
    const TextureId out = h.import("output", {8, 8}, g.out, true);
    const TextureId in = h.create("in", {8, 8});
    h.addPass(
        PassInfo{"make_in", PassKind::Clear, "", ""}, [&](PassBuilder& b) { b.write(in); },
        [&](PassContext& c) { return c.clear(in, 0xff00ff00); });
    h.addPass(
        PassInfo{"copy", PassKind::StretchRect, "", ""},
        [&](PassBuilder& b) {
            b.read(in);
            b.write(out);
        },
        [&](PassContext& c) { return peek(c); });
    std::vector<PassStats> stats;
    auto hFails = [&](const std::function<bool(PassContext&)>& f, const std::string& message) {
        peek = f;
        CHECK_FALSE(h.run(g.pool, stats, err));
        CHECK(err == message);
    };
    hFails([&](PassContext& c) { return c.setTarget(in); },
           "pass copy: texture in is written but was declared read only (declare it with write() or readWrite() in "
           "setup)");
    hFails([&](PassContext& c) { return c.stretch(out, in, D3DTEXF_POINT); },
           "pass copy: texture output is read but was declared write only (declare it with read() or readWrite() in "
           "setup)");
    peek = [&](PassContext& c) { return c.stretch(in, out, D3DTEXF_POINT); };
    REQUIRE(h.run(g.pool, stats, err));
    CHECK(g.pixel() == 0xff00ff00u);
}

TEST_CASE("pass graph: a transient texture read before any live pass wrote it is an error", "[glare][graph]") {
    auto clearPass = [](PassGraph& graph, const char* name, std::vector<TextureId> reads, std::vector<TextureId> writes,
                        bool* ran = nullptr) {
        graph.addPass(
            PassInfo{name, PassKind::Clear, "", ""},
            [&](PassBuilder& b) {
                for (TextureId r : reads) b.read(r);
                for (TextureId w : writes) b.write(w);
            },
            [ran, target = writes.front()](PassContext& c) {
                if (ran) *ran = true;
                return c.clear(target, 0);
            });
    };
    std::string err;
    {
        SmallGraph g;
        const TextureId a = g.graph.create("a", {8, 8});
        bool ran = false;
        clearPass(g.graph, "use_a", {a}, {g.output}, &ran);
        const std::string message =
            "pass use_a reads transient texture a, which no earlier live pass wrote: its contents are undefined";
        CHECK_FALSE(g.graph.compile());
        CHECK(g.graph.compileError() == message);
        CHECK_FALSE(g.run(err));
        CHECK(err == message);
        CHECK_FALSE(ran);
        // A writer after the reader does not help (and is culled).
        clearPass(g.graph, "make_a_late", {}, {a});
        CHECK_FALSE(g.graph.compile());
        CHECK(g.graph.compileError() == message);
    }
    {
        // Blending onto a fresh texture reads undefined contents: a pass's own write does not count.
        SmallGraph g;
        const TextureId a = g.graph.create("a", {8, 8});
        clearPass(g.graph, "blend_onto_a", {a}, {a});
        clearPass(g.graph, "use_a", {a}, {g.output});
        CHECK_FALSE(g.run(err));
        CHECK(err ==
              "pass blend_onto_a reads and writes transient texture a, which no earlier live pass wrote: it would "
              "keep or blend onto undefined contents (a pass that clears it first declares it write() only)");
    }
    {
        // CPU data too.
        SmallGraph g;
        const TextureId list = g.graph.createData("list");
        clearPass(g.graph, "use_list", {list}, {g.output});
        CHECK_FALSE(g.run(err));
        CHECK(err == "pass use_list reads CPU data list, which no earlier live pass wrote: its contents are undefined");
    }
    {
        // What is fine: blending onto an import, onto a texture an earlier pass wrote, and a pass
        // that clears a fresh texture and then blends onto it (declared written only).
        SmallGraph g;
        const TextureId a = g.graph.create("a", {8, 8}), b = g.graph.create("b", {8, 8});
        clearPass(g.graph, "clear_then_blend_a", {}, {a});
        clearPass(g.graph, "blend_onto_a", {a}, {a});
        clearPass(g.graph, "a_to_b", {a}, {b});
        clearPass(g.graph, "blend_b_onto_output", {b}, {g.output});
        clearPass(g.graph, "blend_onto_output", {g.output}, {g.output});
        CHECK(g.graph.compile());
        CHECK(g.graph.compileError().empty());
        CHECK(g.run(err));
    }
    {
        // A TextureId that is no texture of the graph, declared in a setup.
        SmallGraph g;
        clearPass(g.graph, "stray", {TextureId{42}}, {g.output});
        CHECK_FALSE(g.graph.compile());
        CHECK(g.graph.compileError() == "pass stray: setup declares texture #42, which is not a texture of this graph");
        CHECK_FALSE(g.run(err));
    }
}

TEST_CASE("every technique and preset runs and matches the GL renderer pass by pass", "[glare][gl]") {
    std::string error;
    const ps11test::RendererFactory gl = ps11test::glRendererFactory("", error);
    REQUIRE(gl);
    for (const Technique* t : techniques())
        for (std::string_view presetName : kPresetNames) {
            INFO(std::string(t->name()) + " " + std::string(presetName));
            Runner emuRun(options(96, 64));
            RunnerOptions glOptions = options(96, 64);
            glOptions.device.renderer = gl;
            Runner glRun(glOptions);
            std::string sceneError;
            std::unique_ptr<Scene> scene = makeScene(t->name() == "sprites" ? "lights" : "box", sceneError);
            REQUIRE(scene);
            double ms = 0;
            REQUIRE(emuRun.renderScene(*scene, 3, 8, ms, error));
            std::optional<emu::RgbaImage> frame = emuRun.readTexture(emuRun.sceneTexture(), error);
            REQUIRE(frame);
            REQUIRE(glRun.setImage(*frame, error));
            std::vector<PassAgreement> agreement;
            FrameResult result;
            const Settings s = *presetSettings(*t, presetName);
            for (int f = 0; f < 2; ++f) REQUIRE(compareFrame(emuRun, glRun, *t, s, f, 2, agreement, result, error));
            REQUIRE(!agreement.empty());
            for (const PassAgreement& a : agreement) {
                INFO(a.pass << ": " << a.overOne << " of " << a.pixels << " pixels past 1 level, max " << a.maxDiff);
                CHECK(a.overOne == 0);
            }
        }
}

TEST_CASE("adaptive: the glare amount follows A_n = a·L + (1 − a)·A_(n−1), and stops short in 8 bits", "[glare]") {
    // A uniform grey 0.5 squared by mul_x4: 4·avg² = 1 per channel, luminance 1.0 (clamped), so
    // L = 1 in both profiles (the published square, avg·min(4·avg, 1), gives 0.5 on the card and
    // 1 under ideal). From black, ideal: A_n = 1 − (1 − a)^n. fx8 with round-to-nearest stops
    // where the step a·(L − A) falls below half a level: about 0.5/a = 20 levels short (GLARE.md §7).
    const Technique& t = *findTechnique("adaptive");
    Settings s = preset("adaptive");
    s["start"] = 1;   // black
    s["square"] = 1;  // mul_x4
    const double a = s.at("smoothing");
    for (auto p : {ps11::Precision::Ideal, ps11::Precision::Fx8}) {
        Runner run(options(16, 16, p));
        std::string err;
        REQUIRE(run.setImage(uniform(16, 16, 0.5f, 0.5f, 0.5f), err));
        std::vector<double> values;
        for (int f = 0; f < 400; ++f) {
            FrameResult r;
            REQUIRE(run.runFrame(t, s, f, 400, r, err));
            values.push_back(texel(run, run.persistent("adapted glare amount", {1, 1, run.intermediateFormat()}, 0, err))[0]);
        }
        if (p == ps11::Precision::Ideal) {
            for (int n : {1, 10, 50, 100, 200}) {
                INFO("frame " << n);
                CHECK(values[size_t(n - 1)] == Approx(1 - std::pow(1 - a, n)).margin(1e-4));
            }
        } else {
            // The 8-bit recurrence, exactly (glare/stress.h, the prediction `ps11 stress` prints): the
            // smoothing constant sits on the grid, the blend rounds once to a level, ties to even.
            const std::vector<int> predicted = predictSmoothingLevels(a, 255, 0, 400);
            for (int f = 0; f < 400; ++f) {
                INFO("frame " << f);
                REQUIRE(values[size_t(f)] * 255 == Approx(predicted[size_t(f)]).margin(1e-6));
            }
            // Stuck below 1.0 by the dead band (the stress suite's smoothing_dead_band measures its size
            // from both sides), and no longer moving.
            CHECK(values.back() < 1.0);
            CHECK(values[399] == values[300]);
        }
    }
}

TEST_CASE("adaptive: the ps_1_1 bright pass computes b·min(4b, 1), ideal computes 4b²", "[glare]") {
    const Technique& t = *findTechnique("adaptive");
    for (float c : {0.5f, 0.6f, 0.8f}) {
        const double b = c - 0.4, intended = std::min(4 * b * b, 1.0), hardware = b * std::min(4 * b, 1.0);
        for (auto p : {ps11::Precision::Ideal, ps11::Precision::Fx8}) {
            Runner run(options(16, 16, p));
            std::string err;
            REQUIRE(run.setImage(uniform(16, 16, c, c, c), err));
            Settings s = preset("adaptive");
            s["glare_amount"] = 1;
            s["blur_passes"] = 0;
            s["start"] = 1;      // black, and
            s["smoothing"] = 0;  // kept black: A = 0, 1 − A = 1
            PassGraph* graph = nullptr;
            double value = -1;
            FrameResult r;
            // Read the bright pass's target right after it ran (A is that frame's amount).
            REQUIRE(run.runFrame(
                t, s, 0, 1, r, err,
                [&](uint32_t pass, bool after, std::string&) {
                    if (after && graph->passes()[pass].info.name == "bright_pass")
                        value = texel(run, graph->texture(graph->passes()[pass].writes[0]).device)[0];
                    return true;
                },
                [&](PassGraph& g) { graph = &g; }));
            INFO("c = " << c << " profile " << int(p));
            if (p == ps11::Precision::Ideal)
                CHECK(value == Approx(intended).margin(0.02));
            else
                CHECK(value == Approx(hardware).margin(0.02));
        }
    }
}

TEST_CASE("error-diffused weights keep the kernel's sum on the grid", "[glare]") {
    // GLARE.md §7: rounding each 8-bit weight of a normalised kernel gives Σw ≈ 1.0039; carrying the
    // remainder keeps the quantised sum equal to the quantised real sum.
    const std::vector<std::vector<double>> kernels = {
        {5.0 / 16, 6.0 / 16, 5.0 / 16}, {0.25, 0.25, 0.25, 0.25}, {1.0 / 3, 1.0 / 3, 1.0 / 3}};
    for (const auto& k : kernels) {
        const double sum = std::accumulate(k.begin(), k.end(), 0.0);
        const std::vector<double> q = quantiseWeights(k, ps11::Precision::Fx8);
        CHECK(std::accumulate(q.begin(), q.end(), 0.0) * 255 == Approx(std::nearbyint(sum * 255)).margin(1e-9));
        for (size_t i = 0; i < q.size(); ++i) {
            CHECK(std::fabs(q[i] * 255 - std::nearbyint(q[i] * 255)) < 1e-9);  // on the grid
            CHECK(std::fabs(q[i] - k[i]) <= 1.0 / 255);                       // within a level of the real weight
        }
    }
    // The pyramid's 5/16, 6/16, 5/16 rounded one by one sum to 256/255: the reason diffusion exists.
    double naive = 0;
    for (double w : kernels[0]) naive += std::nearbyint(w * 255);
    CHECK(naive == 256);
    // Float profiles keep the weights as they are.
    CHECK(quantiseWeights(kernels[0], ps11::Precision::Ideal) == kernels[0]);
}

TEST_CASE("pyramid: DC gain 4 when summed plainly, 1 when energy-normalised", "[glare]") {
    // A uniform 0.1 with threshold 0: the bright pass keeps 0.1; every level stays 0.1; the sum of
    // four levels is 0.4 plainly and 0.1 normalised; the composite adds it to the scene.
    const Technique& t = *findTechnique("pyramid");
    for (int sum : {0, 1})
        for (auto p : {ps11::Precision::Ideal, ps11::Precision::Fx8}) {
            Runner run(options(64, 64, p));
            std::string err;
            REQUIRE(run.setImage(uniform(64, 64, 0.1f, 0.1f, 0.1f), err));
            Settings s = preset("pyramid");
            s["threshold"] = 0;
            s["sum"] = sum;
            s["size"] = 64;
            FrameResult r;
            REQUIRE(run.runFrame(t, s, 0, 1, r, err));
            std::optional<emu::RgbaImage> out = run.readOutput(err);
            REQUIRE(out);
            const double expected = 0.1 + (sum == 0 ? 0.4 : 0.1);
            INFO("sum " << sum << " profile " << ps11::precisionName(p));
            // The output is 8-bit: the scene copy (25.5 levels) and the sum each round by up to half a
            // level; fx8 also rounds the input and every pass (four levels weighted and summed).
            CHECK(int(out->rgba[size_t(32 * 64 + 32) * 4]) == Approx(expected * 255).margin(p == ps11::Precision::Ideal ? 1 : 4));
        }
}

TEST_CASE("glow: feedback decays by k per frame, and 8-bit rounding leaves a residue that never fades", "[glare]") {
    // A uniform source (alpha 1), then black. Uniform images make the blur an identity (the
    // kernel sums to 1), so the glow is y ← s + k·y: y → s/(1 − k), then y ← k·y once s = 0.
    // With rounding, y ← Q(k·y) stops at a residue of about 0.5/(1 − k) levels (GLARE.md §7).
    const Technique& t = *findTechnique("glow");
    Settings s = preset("glow");
    s["afterimage"] = 2;  // feedback
    s["decay"] = 0.8;
    s["radius"] = 2;
    for (auto p : {ps11::Precision::Ideal, ps11::Precision::Fx8}) {
        Runner run(options(32, 32, p));
        std::string err;
        std::vector<double> glow;
        for (int f = 0; f < 60; ++f) {
            REQUIRE(run.setImage(f < 20 ? uniform(32, 32, 0.1f, 0.1f, 0.1f) : uniform(32, 32, 0, 0, 0), err));
            FrameResult r;
            REQUIRE(run.runFrame(t, s, f, 60, r, err));
            glow.push_back(texel(run, run.persistent("previous glow", {8, 8, run.intermediateFormat()}, 0, err))[0]);
        }
        INFO("profile " << int(p));
        // Converged near s/(1 − k) = 0.5 after 20 frames (0.8^20 ≈ 1 %).
        CHECK(glow[19] == Approx(0.5).margin(p == ps11::Precision::Ideal ? 0.01 : 0.03));
        if (p == ps11::Precision::Ideal) {
            for (int f = 21; f < 30; ++f) CHECK(glow[size_t(f)] == Approx(0.8 * glow[size_t(f - 1)]).epsilon(1e-3));
            CHECK(glow[59] * 255 < 0.5);  // fades below half a level
        } else {
            // Once the source is black: y ← B_v(B_h(round(k8·y/255))) (glare/stress.h, predicted frame
            // by frame from frame 19's value): it must match exactly, and stop at a residue that never fades.
            const std::vector<int> predicted = predictFeedbackLevels(s, int(std::nearbyint(glow[19] * 255)), 40);
            for (int f = 20; f < 60; ++f) {
                INFO("frame " << f);
                REQUIRE(glow[size_t(f)] * 255 == Approx(predicted[size_t(f - 20)]).margin(1e-6));
            }
            const int y = predicted.back();
            CHECK(y >= 1);
            CHECK(glow[59] == glow[50]);
        }
    }
}

TEST_CASE("frameBytes is frameByte for every float", "[glare]") {
    // Specials, the ends of [0, 1], every value near a rounding boundary, random bits; lengths
    // around the vector block.
    std::vector<float> v = {NAN, -NAN, INFINITY, -INFINITY, 0.0f, -0.0f, 1.0f, 1.0001f, -1e-30f, 1e30f};
    for (int k = 0; k < 256; ++k) {
        const float b = (float(k) + 0.5f) / 255.0f;
        v.insert(v.end(), {b, std::nextafter(b, 0.0f), std::nextafter(b, 1.0f)});
    }
    std::mt19937 rng(5);
    for (int i = 0; i < 3000; ++i) {
        uint32_t bits = rng();
        float f;
        std::memcpy(&f, &bits, 4);
        v.push_back(i % 2 ? f : float(rng() % 70000) / 65536.0f);
    }
    for (size_t n : {size_t(0), size_t(5), size_t(16), size_t(17), size_t(31), v.size()}) {
        std::vector<uint8_t> got(n + 1, 0xAB);
        glare::frameBytes(v.data(), n, got.data());
        size_t bad = 0;
        for (size_t i = 0; i < n; ++i) bad += got[i] != glare::frameByte(v[i]);
        INFO("length " << n);
        CHECK(bad == 0);
        CHECK(got[n] == 0xAB);
    }
}

TEST_CASE("runner: readTexture gives each texel as r g b a, into an image it reuses", "[glare]") {
    // An odd size (rows of any length), random bytes in fx8's A8R8G8B8 and random floats (below
    // 0, above 1, NaN) in ideal's A32B32G32R32F: the bytes read are the texels' own, the floats'
    // frameByte; reading into an image that held something else gives the same.
    std::mt19937 rng(11);
    const uint32_t w = 37, h = 5;
    emu::RgbaImage bytes{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
    for (uint8_t& b : bytes.rgba) b = uint8_t(rng());
    emu::FloatImage floats{w, h, std::vector<float>(size_t(w) * h * 4)};
    for (size_t i = 0; i < floats.rgba.size(); ++i)
        floats.rgba[i] = i == 7 ? NAN : float(int(rng() % 4000) - 1000) / 2000.0f;
    std::vector<uint8_t> floatBytes;
    for (float f : floats.rgba) floatBytes.push_back(glare::frameByte(f));
    for (const bool ideal : {false, true}) {
        INFO((ideal ? "ideal" : "fx8"));
        glare::RunnerOptions o;
        o.width = w;
        o.height = h;
        if (ideal) o.device.precision = ps11::Precision::Ideal;
        glare::Runner run(o);
        std::string err;
        REQUIRE((ideal ? run.setImage(floats, err) : run.setImage(bytes, err)));
        const std::vector<uint8_t>& want = ideal ? floatBytes : bytes.rgba;
        const std::optional<emu::RgbaImage> once = run.readTexture(run.sceneTexture(), err);
        REQUIRE(once);
        CHECK(once->width == w);
        CHECK(once->height == h);
        CHECK(once->rgba == want);
        emu::RgbaImage reused{3, 2, std::vector<uint8_t>(size_t(64) * 64 * 4, 0x5A)};
        REQUIRE(run.readTexture(run.sceneTexture(), reused, err));
        CHECK(reused.width == w);
        CHECK(reused.height == h);
        CHECK(reused.rgba == want);
        CHECK_FALSE(run.readTexture(emu::Handle{}, reused, err));
        CHECK_FALSE(err.empty());
    }
}

TEST_CASE("sprites: grouping keeps the total glare energy", "[glare]") {
    // Scattered bright pixels (some adjacent) on black.
    const uint32_t w = 64, h = 48;
    std::vector<uint8_t> img(size_t(w) * h * 4, 0);
    auto set = [&](uint32_t x, uint32_t y, uint8_t r, uint8_t g, uint8_t b) {
        uint8_t* p = &img[(size_t(y) * w + x) * 4];
        p[0] = r, p[1] = g, p[2] = b, p[3] = 255;
    };
    for (uint32_t i = 0; i < 40; ++i) set((i * 37) % w, (i * 23 + i / 3) % h, 255, 240, uint8_t(200 + i));
    set(10, 10, 255, 255, 255);
    set(11, 10, 255, 255, 255);
    set(10, 11, 255, 255, 255);
    for (uint32_t y = 24; y < 32; ++y)
        for (uint32_t x = 40; x < 48; ++x) set(x, y, 255, 255, 255);  // an 8x8 block: a cluster
    SensorSettings base;
    base.strength = 0.1f;
    auto energy = [&](const std::vector<Sprite>& sprites) {
        std::array<double, 3> e{};
        for (const Sprite& s : sprites)
            for (int c = 0; c < 3; ++c) e[size_t(c)] += s.energy[c];
        return e;
    };
    base.group = 1;
    const auto single = senseSprites(img.data(), w, h, base);
    const auto e1 = energy(single);
    size_t clusters = 0;
    for (const Sprite& s : single) clusters += s.cluster;
    CHECK(clusters == 1);
    for (int n : {2, 3, 4, 5, 8}) {  // 3 and 5: groups straddle the cluster block
        SensorSettings s = base;
        s.group = n;
        const auto grouped = senseSprites(img.data(), w, h, s);
        CHECK(grouped.size() < single.size());
        const auto e = energy(grouped);
        for (int c = 0; c < 3; ++c) CHECK(e[size_t(c)] == Approx(e1[size_t(c)]).epsilon(1e-5));
    }
    // Without clusters, the 64 block pixels give 64 sprites with the same energy as the cluster.
    SensorSettings noClusters = base;
    noClusters.clusters = false;
    const auto e0 = energy(senseSprites(img.data(), w, h, noClusters));
    for (int c = 0; c < 3; ++c) CHECK(e0[size_t(c)] == Approx(e1[size_t(c)]).epsilon(1e-5));
}

namespace {

// The sensor step as one pass in raster order, written plainly: what the threaded senseSprites
// must reproduce sprite for sprite, bit for bit.
std::vector<Sprite> senseSpritesReference(const uint8_t* rgba, uint32_t width, uint32_t height,
                                          const SensorSettings& s) {
    auto luminance = [](const uint8_t* p) { return (0.30f * p[0] + 0.59f * p[1] + 0.11f * p[2]) / 255.0f; };
    std::vector<Sprite> out;
    const uint32_t n = uint32_t(std::max(s.group, 1));
    const uint32_t cw = (width + 7) / 8, ch = (height + 7) / 8;
    std::vector<uint8_t> clustered(size_t(cw) * ch, 0);
    auto addSprite = [&](uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1, bool cluster) {
        double sl = 0, sx = 0, sy = 0, e[3] = {0, 0, 0};
        for (uint32_t y = y0; y < y1; ++y)
            for (uint32_t x = x0; x < x1; ++x) {
                if (!cluster && s.clusters && clustered[size_t(y / 8) * cw + x / 8]) continue;
                const uint8_t* p = &rgba[(size_t(y) * width + x) * 4];
                const float l = luminance(p);
                if (l < s.threshold) continue;
                sl += l;
                sx += double(l) * x;
                sy += double(l) * y;
                for (int c = 0; c < 3; ++c) e[c] += p[c] / 255.0;
            }
        if (sl <= 0) return;
        Sprite sp;
        sp.x = float(sx / sl);
        sp.y = float(sy / sl);
        for (int c = 0; c < 3; ++c) sp.energy[c] = float(e[c] * s.strength);
        sp.radius = cluster ? 2 * s.radius : s.radius;
        sp.cluster = cluster;
        out.push_back(sp);
    };
    if (s.clusters)
        for (uint32_t by = 0; by < ch; ++by)
            for (uint32_t bx = 0; bx < cw; ++bx) {
                const uint32_t x0 = bx * 8, y0 = by * 8, x1 = std::min(x0 + 8, width), y1 = std::min(y0 + 8, height);
                uint32_t bright = 0;
                for (uint32_t y = y0; y < y1; ++y)
                    for (uint32_t x = x0; x < x1; ++x) bright += luminance(&rgba[(size_t(y) * width + x) * 4]) >= s.threshold;
                if (bright * 10 >= 9 * (x1 - x0) * (y1 - y0)) {
                    clustered[size_t(by) * cw + bx] = 1;
                    addSprite(x0, y0, x1, y1, true);
                }
            }
    for (uint32_t y0 = 0; y0 < height; y0 += n)
        for (uint32_t x0 = 0; x0 < width; x0 += n) addSprite(x0, y0, std::min(x0 + n, width), std::min(y0 + n, height), false);
    return out;
}

// Bit for bit the same sprites, in the same order.
void sameSprites(const std::vector<Sprite>& got, const std::vector<Sprite>& want) {
    REQUIRE(got.size() == want.size());
    for (size_t i = 0; i < want.size(); ++i) {
        CHECK(std::memcmp(&got[i].x, &want[i].x, sizeof(float) * 2) == 0);
        CHECK(std::memcmp(got[i].energy, want[i].energy, sizeof want[i].energy) == 0);
        CHECK(got[i].radius == want[i].radius);
        CHECK(got[i].cluster == want[i].cluster);
    }
}

}  // namespace

TEST_CASE("sprites: the threaded sensor step gives the one-pass sensors' sprites exactly", "[glare]") {
    emu::ThreadPool one(1), three(3), eight(8);
    std::mt19937 rng(7);
    for (int round = 0; round < 24; ++round) {
        const uint32_t w = 1 + rng() % 300, h = 1 + rng() % 260;
        std::vector<uint8_t> img(size_t(w) * h * 4);
        const unsigned bright = rng() % 60;  // % of bright pixels, some in 8x8 blocks
        for (size_t i = 0; i < img.size(); ++i) img[i] = rng() % 100 < bright ? uint8_t(200 + rng() % 56) : uint8_t(rng() % 256);
        for (int b = 0; b < 4 && w >= 16 && h >= 16; ++b) {
            const uint32_t bx = rng() % (w - 8), by = rng() % (h - 8);
            for (uint32_t y = by; y < by + 8; ++y)
                for (uint32_t x = bx; x < bx + 8; ++x) std::memset(&img[(size_t(y) * w + x) * 4], 255, 4);
        }
        SensorSettings s;
        s.group = 1 + int(rng() % 6);
        s.clusters = rng() % 3 != 0;
        s.threshold = 0.3f + float(rng() % 60) / 100.0f;
        INFO(w << "x" << h << ", group " << s.group << ", clusters " << s.clusters << ", threshold " << s.threshold);
        const std::vector<Sprite> ref = senseSpritesReference(img.data(), w, h, s);
        // The same frame as D3D's b g r a words in rows with padding (what the read-back hands over).
        const size_t pitch = size_t(w) * 4 + 4 * (rng() % 5);
        std::vector<uint8_t> bgra(pitch * h, 0xEE);
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                const uint8_t* p = &img[(size_t(y) * w + x) * 4];
                uint8_t* q = &bgra[y * pitch + size_t(x) * 4];
                q[0] = p[2], q[1] = p[1], q[2] = p[0], q[3] = p[3];
            }
        // On the calling thread and on pools of 1, 3 and 8 (the frame's bands split differently),
        // at every SIMD level (the sensor row's kernels).
        testutil::forEachSimdLevel([&](ps11::SimdLevel) {
            for (const std::vector<Sprite>& fast :
                 {senseSprites(img.data(), w, h, s), senseSprites(SensorFrame{bgra.data(), w, h, pitch, true}, s),
                  senseSprites(SensorFrame{bgra.data(), w, h, pitch, true, &one}, s),
                  senseSprites(SensorFrame{img.data(), w, h, size_t(w) * 4, false, &three}, s),
                  senseSprites(SensorFrame{bgra.data(), w, h, pitch, true, &eight}, s)}) {
                sameSprites(fast, ref);
            }
        });
        // The same frame as floats (a float render target), in rows with padding: byte i as
        // i/255 give or take 0.45/255, 255 as values past 1 or +inf, 0 as values below 0 or NaN.
        // The sensors see glare::frameBytes of it (the 8-bit frame readTexture gives).
        const size_t fpitch = (size_t(w) * 4 + 4 * (rng() % 3)) * sizeof(float);
        std::vector<float> values(fpitch / sizeof(float) * h, -7.0f);
        std::vector<uint8_t> seen(img.size());
        std::uniform_real_distribution<float> jitter(-0.45f, 0.45f);
        for (uint32_t y = 0; y < h; ++y) {
            float* row = values.data() + y * (fpitch / sizeof(float));
            for (size_t i = 0; i < size_t(w) * 4; ++i) {
                const uint8_t b = img[size_t(y) * w * 4 + i];
                float v = (float(b) + jitter(rng)) / 255.0f;
                if (b == 255 && rng() % 2) v = rng() % 2 ? 1.5f : std::numeric_limits<float>::infinity();
                if (b == 0 && rng() % 2) v = rng() % 2 ? -0.25f : std::numeric_limits<float>::quiet_NaN();
                row[i] = v;
            }
            frameBytes(row, size_t(w) * 4, &seen[size_t(y) * w * 4]);
        }
        REQUIRE(seen == img);  // the values say the frame's bytes
        for (emu::ThreadPool* pool : {static_cast<emu::ThreadPool*>(nullptr), &three}) {
            SensorFrame sf{nullptr, w, h, fpitch, true, pool};
            sf.values = values.data();
            sameSprites(senseSprites(sf, s), ref);
        }
    }
}

TEST_CASE("sprites: the drawn glare buffer keeps its energy when pixels are grouped", "[glare]") {
    // The same scattered lights drawn with N = 1 and N = 2 under the ideal profile (float glare
    // buffer): the buffers' sums agree within the bilinear footprint's rounding.
    const Technique& t = *findTechnique("sprites");
    // Sprites larger than the 128-texel glare image (radius 0.4·192 = 77 px) so bilinear sampling
    // magnifies it and the drawn sum does not depend on sub-pixel position; lights near the centre
    // so no sprite is clipped.
    const uint32_t w = 256, h = 192;
    emu::FloatImage img = uniform(w, h, 0, 0, 0);
    const uint32_t spots[][2] = {{120, 90}, {131, 97}, {100, 84}, {141, 101}};
    for (const auto& p : spots)
        for (uint32_t dy = 0; dy < 2; ++dy)
            for (uint32_t dx = 0; dx < 2; ++dx)
                for (int c = 0; c < 3; ++c) img.rgba[(size_t(p[1] + dy) * w + p[0] + dx) * 4 + size_t(c)] = 1;
    std::array<double, 2> totals{};
    for (int n : {1, 2}) {
        Runner run(options(w, h, ps11::Precision::Ideal));
        std::string err;
        REQUIRE(run.setImage(img, err));
        Settings s = preset("sprites");
        s["group"] = n;
        s["shrink"] = 0;
        s["strength"] = 15.0 / 255;  // vertex colours 15/255 (N = 1) and 60/255 (N = 2): both exact bytes
        s["radius"] = 0.4;
        double total = 0;
        PassGraph* graph = nullptr;
        FrameResult r;
        REQUIRE(run.runFrame(
            t, s, 0, 1, r, err,
            [&](uint32_t pass, bool after, std::string& e) {
                if (!after || graph->passes()[pass].info.name != "draw_sprites") return true;
                emu::Handle surface{};
                run.device().GetSurfaceLevel(graph->texture(graph->passes()[pass].writes[0]).device, 0, &surface);
                std::optional<emu::SurfacePixels> px = emu::readSurface(run.device(), surface, e);
                if (!px) return false;
                for (size_t i = 0; i < size_t(w) * h; ++i) {
                    float v;
                    std::memcpy(&v, &px->bytes[i * 16], 4);
                    total += v;
                }
                return true;
            },
            [&](PassGraph& g) { graph = &g; }));
        totals[size_t(n - 1)] = total;
    }
    CHECK(totals[0] > 0);
    CHECK(totals[1] == Approx(totals[0]).epsilon(0.03));
}

TEST_CASE("docs/fits-ps11.md is what ps11 glare --report --markdown prints", "[glare][docs]") {
    std::ifstream f(std::string(PS11_SOURCE_DIR) + "/docs/fits-ps11.md", std::ios::binary);
    REQUIRE(f);
    std::stringstream text;
    text << f.rdbuf();
    const FitsReport r = fitsReport();
    CHECK(text.str() == fitsReportMarkdown(r));
    // Every shader pass fits; the only step past 1.1 is Ando's sensors.
    for (const PassFit& p : r.passes) {
        INFO(p.technique << " " << p.preset << " " << p.pass);
        if (p.pass == "sensors")
            CHECK_FALSE(p.fits);
        else
            CHECK(p.fits);
    }
}

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
    // frames must be those of every pass run, every tile shaded and every copy made at once.
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
    // textures, a hook: each makes the next frame run. Glow with its strength ramping and
    // adaptive (its dither) read the frame index: never skipped whole. Every output equals the
    // one of a runner that runs every pass.
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
    run("adaptive", *glare::presetSettings(*glare::findTechnique("adaptive"), "published"), nothing,
        std::vector<int>{0, 0, 0, 0, 0});
}

TEST_CASE("reuse: the same on the GL renderer", "[glare][reuse][gl]") {
    std::string error;
    emu::DeviceOptions gl;
    gl.renderer = ps11test::glRendererFactory("", error);
    REQUIRE(gl.renderer);
    checkReuse(gl);
}

TEST_CASE("sprites: comparing the luminance sum with sensorSumThreshold is comparing luminance, for every colour",
          "[glare]") {
    // Every r, g, b byte triple against thresholds on and off the 8-bit grid, past the ends and NaN.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> thresholds = {0.8f, 0.5f, 0.31f, 1.0f / 255.0f, 1.0f, 0.0f, -0.25f, 1.5f, nan};
    // Some colours' own luminances and their float neighbours: the sums right at the threshold.
    std::mt19937 rng(2026);
    for (int k = 0; k < 4; ++k) {
        const float l = (0.30f * float(rng() % 256) + 0.59f * float(rng() % 256) + 0.11f * float(rng() % 256)) / 255.0f;
        for (const float t : {l, std::nextafter(l, 0.0f), std::nextafter(l, 2.0f)}) thresholds.push_back(t);
    }
    for (const float t : thresholds) {
        const float s = sensorSumThreshold(t);
        uint64_t mismatches = 0, fires = 0;
        for (int r = 0; r < 256; ++r)
            for (int g = 0; g < 256; ++g)
                for (int b = 0; b < 256; ++b) {
                    const float sum = 0.30f * float(r) + 0.59f * float(g) + 0.11f * float(b);
                    const bool byLuminance = sum / 255.0f >= t;
                    fires += byLuminance;
                    mismatches += byLuminance != (sum >= s);
                }
        INFO("threshold " << t << ", sum threshold " << s << ", colours firing " << fires);
        CHECK(mismatches == 0);
    }
    // The least such sum for many thresholds (division rounds monotonically, so the least float s
    // with s / 255 >= t is the whole rule): s reaches t, the float below it does not.
    uint64_t notLeast = 0;
    for (int k = 0; k < 200000; ++k) {
        const float l = (0.30f * float(rng() % 256) + 0.59f * float(rng() % 256) + 0.11f * float(rng() % 256)) / 255.0f;
        const float t = k % 3 == 0 ? l : k % 3 == 1 ? std::nextafter(l, 0.0f) : std::nextafter(l, 2.0f);
        const float s = sensorSumThreshold(t);
        notLeast += !(s / 255.0f >= t) || std::nextafter(s, -1.0f) / 255.0f >= t;
    }
    CHECK(notLeast == 0);
}
