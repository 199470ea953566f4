// The glare pass graph (glare/pass_graph.h): culling, order, lifetimes and aliasing of transient
// textures, device textures shared where their lives allow, every pass starting from the state
// run() found, a pass reaching only the textures it declared, and a transient texture read before
// any live pass wrote it.
#include <catch2/catch.hpp>

#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "emu/fullscreen.h"
#include "glare/pass_graph.h"
#include "glare/passes.h"
#include "glare/runner.h"
#include "glare_test_util.h"

using namespace glare;

using namespace glaretest;

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
