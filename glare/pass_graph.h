// The pass graph (docs/glare/README.md "Pass graph"), in the style of Filament's FrameGraph: a
// pass is a name, a setup that declares the textures it reads and writes, and an execute step
// that draws through emu::Device only, so one graph runs on the software and the GL renderer.
// compile() culls the passes whose output nobody reads, gives every transient texture a
// lifetime (first to last use) and refuses a read of a transient texture nothing wrote; run()
// takes device textures from a TexturePool when a texture's life starts and gives them back when
// it ends, so textures of the same description that are never alive together share one device
// texture (aliasing). Passes are self-contained: each starts from the device state run() found
// and reaches only the textures it declared.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "emu/d3d9types.h"
#include "emu/device.h"
#include "emu/fullscreen.h"

namespace glare {

// The techniques are D3D9 programs: the device's D3D9 names (D3DFORMAT, D3DFMT_*, D3DTEXF_*, …)
// are used unqualified, as a D3D9 program would.
using namespace emu;

// A texture's description: what a pool matches on.
struct TextureDesc {
    uint32_t width = 1, height = 1;
    D3DFORMAT format = D3DFMT_A8R8G8B8;
    bool operator==(const TextureDesc&) const = default;
    auto operator<=>(const TextureDesc&) const = default;
};

// A virtual texture of one graph.
struct TextureId {
    uint32_t index = ~0u;
    bool valid() const { return index != ~0u; }
    bool operator==(const TextureId&) const = default;
};

// What a pass is, for the fits-ps_1_1 report (glare/report.h).
enum class PassKind : uint8_t {
    Shader,          // a ps_1_x pixel shader over a quad: `shader` names glare/shaders/<shader>
    FixedFunction,   // texture stages only (the D3D7 path): 1.1-class hardware runs it
    StretchRect,     // a device blit (filtered copy), no shader
    Clear,           // a device clear
    DeviceSide,      // work the CPU does on the device side: not 1.1 hardware (`note` says why)
};
const char* passKindName(PassKind kind);

// Per-pass statistics of one run: device draws (their pixels, texels, instructions), blits and
// clears (the pixels they write; a LINEAR blit reads 4 texels per pixel, POINT 1), wall time.
struct PassStats {
    std::string pass;
    double milliseconds = 0;
    uint64_t draws = 0, pixels = 0, texels = 0, instructions = 0;
    // Surfaces that crossed between the device front and a renderer that keeps copies (the GL
    // renderer): uploaded to it, read back from it.
    uint64_t uploads = 0, readBacks = 0;
    // The memory traffic the pass cannot avoid: each texture it reads, once (no more than its
    // texels fetched), and each texture it writes, once (no more than its pixels). Time over
    // this shows a pass far above its share.
    uint64_t bytes = 0;
    // The software renderer's tiles of the pass's draws (docs/device.md "Tile skipping"): shaded,
    // filled with a constant, copied from one tap, skipped. Zero on the GL renderer.
    uint64_t tilesShaded = 0, tilesFilled = 0, tilesCopied = 0, tilesSkipped = 0;
    // Run with a PassMemo: the pass's fingerprint and outputs were last frame's, so its outputs
    // were kept and nothing ran (milliseconds is the dry run's).
    bool reused = false;
    // A copy the renderer put off (Device::lastStretchPutOff): made by the pass that next reads
    // or writes its destination, in whose time it is.
    bool putOff = false;
};

// Device textures by description, kept between frames and runs: a graph takes one when a
// transient texture's life starts and returns it when the life ends. Render-target textures,
// D3DPOOL_DEFAULT, one level.
class TexturePool {
public:
    explicit TexturePool(emu::Device& device) : m_device(device) {}
    ~TexturePool();
    TexturePool(const TexturePool&) = delete;
    TexturePool& operator=(const TexturePool&) = delete;
    // A free texture of `desc` (made when none is free); Null with `error` set on failure.
    emu::Handle acquire(const TextureDesc& desc, std::string& error);
    void release(emu::Handle texture);
    size_t created() const { return m_all.size(); }
    emu::Device& device() { return m_device; }

private:
    emu::Device& m_device;
    std::multimap<TextureDesc, emu::Handle> m_free;
    std::map<uint32_t, TextureDesc> m_all;
};

// What PassGraph::run keeps from frame to frame to run a pass only when something it depends on
// changed (docs/glare/README.md "Reuse"): per pass, its device fingerprint (emu::Device::
// beginFingerprint: the calls it makes, with every state, constant and vertex, and the
// generations of what it reads) and the generations its outputs had when it ran; and a device
// texture of its own for every transient texture, kept between frames (no aliasing: a pass's
// outputs stay as it left them unless something writes them).
class PassMemo {
public:
    PassMemo() = default;
    PassMemo(const PassMemo&) = delete;
    PassMemo& operator=(const PassMemo&) = delete;
    // Gives the textures back to `pool` and forgets every pass.
    void clear(TexturePool& pool);
    size_t passes() const { return m_entries.size(); }

private:
    friend class PassGraph;
    // Per group of passes (PassGraph::run), at its first pass's index.
    struct Entry {
        std::string name;  // the group's pass names
        bool valid = false;
        std::vector<uint32_t> words;
        std::vector<emu::Handle> writes;
        std::vector<std::pair<emu::Handle, uint64_t>> outputs;
    };
    std::vector<Entry> m_entries;  // by pass index
    std::map<std::pair<std::string, TextureDesc>, emu::Handle> m_textures;
};

class PassGraph;
struct PassContext;

// Declares a pass's reads and writes during setup. A pass that needs a texture's earlier
// contents reads it; one that overwrites it all (a clear first, then blending onto it, included)
// only writes it.
class PassBuilder {
public:
    TextureId create(const std::string& name, const TextureDesc& desc);  // a transient texture
    TextureId read(TextureId texture);
    TextureId write(TextureId texture);
    // Reads and writes (blending onto it, or drawing only part of it): the texture must hold
    // contents an earlier live pass wrote (or be imported).
    TextureId readWrite(TextureId texture) { return write(read(texture)); }

private:
    friend class PassGraph;
    PassBuilder(PassGraph& graph, uint32_t pass) : m_graph(graph), m_pass(pass) {}
    PassGraph& m_graph;
    uint32_t m_pass;
};

// How a quad pass writes its target.
enum class Blend : uint8_t {
    None,
    Add,    // ONE / ONE: additive multipass, composites
    Alpha,  // SRCALPHA / INVSRCALPHA: exponential smoothing
};

// One texture stage of a shader pass as drawn: its texture, where the quad's corners sample it,
// its filter (clamp addressing, no mips: glare/passes.h bindTap).
struct PassStage {
    TextureId texture;
    emu::QuadCoords coords;
    D3DTEXTUREFILTERTYPE filter = D3DTEXF_LINEAR;
};

struct PassInfo {
    std::string name;
    PassKind kind = PassKind::Shader;
    std::string shader;  // Shader: the .psh file name
    std::string note;    // what the pass does, or why it is not 1.1
    // Shader: the constants it sets (c#, value) and the stages it samples with POINT, for the
    // range proof of the fits report (glare/report.h).
    std::vector<std::pair<int, std::array<float, 4>>> constants = {};
    uint8_t pointStages = 0;
    // Shader: its stages (stage i = stages[i]) and blend, one full-target quad; StretchRect:
    // the source and filter (stages[0]). What `ps11 debug --technique` follows a pixel back
    // through and retraces it with (glare/frame_debug.h).
    std::vector<PassStage> stages = {};
    Blend blend = Blend::None;
};

// What a pass's execute step sees. It starts from the device state run() found (every pass
// sets the states it relies on) and reaches only the textures its setup declared.
struct PassContext {
    emu::Device& device;
    PassStats& stats;
    std::string& error;
    const PassGraph& graph;
    uint32_t pass;  // the pass's index in the graph
    // The device texture and its level-0 surface behind a virtual texture (valid while it lives),
    // and its description. A texture the pass did not declare (read or write) gives Null and
    // (for desc) an empty description, sets `error` and fails the pass.
    emu::Handle texture(TextureId id) const;
    emu::Handle surface(TextureId id) const;
    const TextureDesc& desc(TextureId id) const;

    // Device calls that also count into `stats` and set `error` ("pass NAME: message") on failure.
    // A target (setTarget, clear, the destination of stretch) must be declared written, the
    // source of stretch declared read.
    bool check(HRESULT hr);
    bool setTarget(TextureId target);  // render target = the texture's surface, viewport = all of it
    bool clear(TextureId target, D3DCOLOR colour);
    bool stretch(TextureId source, TextureId dest, D3DTEXTUREFILTERTYPE filter);
    // One draw of the half-pixel full-screen quad (emu/fullscreen.h) on the current target, counted.
    bool drawQuad(const std::array<emu::QuadCoords, 4>& coords = {}, DWORD diffuse = 0xffffffff);
    // DrawPrimitiveUP, counted.
    bool draw(D3DPRIMITIVETYPE type, UINT count, const void* vertices, UINT stride);

    // The first refusal of a texture the pass did not declare (also put in `error`): run() fails
    // the pass with it even if its execute step goes on and returns true or fails otherwise.
    mutable std::string refusal;

private:
    enum class Access : uint8_t { Any, Read, Write };
    // True when the pass declared the texture for `access`; else false with `error` set.
    bool declared(TextureId id, Access access) const;
};

class PassGraph {
public:
    using Execute = std::function<bool(PassContext&)>;

    // A texture from outside the graph (the scene, the output, state kept between frames).
    // Imports are never culled away from: `output` marks it as a result whose writers must run.
    TextureId import(const std::string& name, const TextureDesc& desc, emu::Handle texture, bool output);
    // A transient texture: a device texture from the pool for the span of passes that use it.
    TextureId create(const std::string& name, const TextureDesc& desc);
    // A CPU-side result (a list the device side computed): an edge in the graph, never a device texture.
    TextureId createData(const std::string& name);
    // Adds a pass; `setup` declares its textures now, `execute` draws when the graph runs.
    void addPass(const PassInfo& info, const std::function<void(PassBuilder&)>& setup, Execute execute);

    // Culls, computes lifetimes and checks the declarations: false (compileError() says why)
    // when a setup declared a TextureId of no texture of this graph, or a live pass reads a
    // transient texture (or CPU data) that no earlier live pass wrote. run() compiles when needed
    // and fails with the same error; compile() may be called again after adding.
    bool compile();
    const std::string& compileError() const { return m_compileError; }
    // Runs the live passes in order on the pool's device. Each pass starts from the device state
    // run() found (Device::applyState before each), and run() leaves that state behind, failed or
    // not. Before and after each pass `hook` (when set) is called with the pass index, to let a
    // comparison capture or replace textures. False with `error` set at the first failure.
    // `stats` gets one entry per live pass.
    // With `memo`, passes are reused in groups: a pass and the passes right after it that write
    // a texture it (or one of them) wrote. A group whose dry run (one fingerprint over its
    // passes, after the first one's before-hook) is last frame's while its outputs still hold
    // what it wrote is not run again (PassStats::reused), and transient textures keep their own
    // device textures between frames (PassMemo). A group that hands device contents back (a
    // read-back: its fingerprint is incomplete) or writes CPU data always runs. A hook that may
    // write textures (`hookObserves` false) keeps every group to one pass, so its dry run comes
    // after the hook; a hook that only looks (progress, dumps) does not.
    using Hook = std::function<bool(uint32_t pass, bool after, std::string& error)>;
    bool run(TexturePool& pool, std::vector<PassStats>& stats, std::string& error, const Hook& hook = {},
             PassMemo* memo = nullptr, bool hookObserves = false);

    // ---- introspection (reports, tests, --graph) ----
    struct TextureNode {
        std::string name;
        TextureDesc desc;
        bool imported = false, output = false;
        bool data = false;  // createData: no device texture
        emu::Handle importedTexture{};
        int firstUse = -1, lastUse = -1;  // live pass indices; -1 when no live pass touches it
        emu::Handle device{};             // while the graph runs (or after, for imports)
        int physical = -1;                // after run(): which device texture it had (aliasing)
    };
    struct PassNode {
        PassInfo info;
        std::vector<TextureId> reads, writes;
        Execute execute;
        bool live = true;
    };
    const std::vector<PassNode>& passes() const { return m_passes; }
    const std::vector<TextureNode>& textures() const { return m_textures; }
    const TextureNode& texture(TextureId id) const { return m_textures.at(id.index); }
    // The live passes' names in run order.
    std::vector<std::string> livePassNames() const;
    // Graphviz: passes as boxes (culled ones dashed), textures as ellipses, reads and writes as edges.
    std::string graphviz(const std::string& title) const;

private:
    friend class PassBuilder;
    friend struct PassContext;
    // Reuse (run with a memo): the last pass of the group starting at `first` (itself when
    // `single`), and one fingerprint over the group's passes.
    size_t reuseGroupEnd(size_t first, bool single) const;
    emu::Device::Fingerprint dryRun(size_t first, size_t last, emu::Device& device,
                                    const std::function<bool(const std::string&)>& putBack);
    // True when `texture` is a texture of this graph; else records the setup error (PassBuilder).
    bool declarable(uint32_t pass, TextureId texture);
    std::vector<PassNode> m_passes;
    std::vector<TextureNode> m_textures;
    bool m_compiled = false;
    std::string m_setupError;    // the first TextureId a setup declared that is no texture here
    std::string m_compileError;  // compile()'s verdict
};

}  // namespace glare
