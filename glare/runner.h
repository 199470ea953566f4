// Runs techniques frame by frame on one emu::Device (either renderer): holds the device, the
// texture pool, the persistent textures, the techniques' pixel shaders and the scene input.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "emu/device.h"
#include "emu/image_file.h"
#include "glare/pass_graph.h"
#include "glare/technique.h"

namespace emu {
class ThreadPool;  // emu/thread_pool.h (internal)
}

namespace glare {

class Scene;

struct RunnerOptions {
    emu::DeviceOptions device;  // hardware class, profile, renderer (software or GL)
    uint32_t width = 0, height = 0;
    // Skip what a frame does not need: a pass whose inputs are last frame's is not run again
    // (docs/glare/README.md "Reuse"), and the software renderer fills, copies or skips the tiles
    // its interval evaluator decides (docs/device.md "Tile skipping"). Off: every pass runs every
    // frame and every tile is shaded (`--no-skip`; device.software.skipTiles is then off).
    bool skip = true;
    // With skip: whether passes are reused from frame to frame (off: every pass runs every frame and
    // only the tiles are decided, what a moving scene gets; benchmarks time whole frames so).
    bool reuse = true;
    // Keep the Graphviz of each frame's graph as it ran (lastGraphviz; --graph).
    bool graphviz = false;
};

// One frame's result.
struct FrameResult {
    std::vector<PassStats> passes;
    // The frame's time: its graph built and compiled (the technique's CPU set-up, every frame)
    // and the passes' times; not the scene, not the hooks.
    double milliseconds = 0;
    double buildMilliseconds = 0;  // the graph's part of it
    double sceneMilliseconds = 0;
    // Nothing was built or run: a still input whose last frame reused every pass (Runner::runFrame);
    // `passes` are that frame's, every one reused, with no time.
    bool still = false;
};

// The 8-bit value a float frame's channel reads back as (Runner::readTexture): clamped to
// [0, 1], x·255 rounded half up; NaN reads 0.
inline uint8_t frameByte(float v) {
    if (!(v == v)) return 0;
    const float x = v < 0 ? 0 : v > 1 ? 1 : v;
    return uint8_t(x * 255.0f + 0.5f);
}
// frameByte of n floats (vector blocks, the same float operations).
void frameBytes(const float* in, size_t n, uint8_t* out);

class Runner {
public:
    explicit Runner(const RunnerOptions& options);
    ~Runner();
    Runner(const Runner&) = delete;
    Runner& operator=(const Runner&) = delete;

    emu::Device& device() { return *m_device; }
    uint32_t width() const { return m_options.width; }
    uint32_t height() const { return m_options.height; }
    // A8R8G8B8 for the fx profiles and `float`; A32B32G32R32F under `ideal`.
    D3DFORMAT intermediateFormat() const;
    // The scene's: A8R8G8B8, or intermediateFormat() where a float image went to the float scene.
    D3DFORMAT sceneFormat() const;

    // The scene input: an 8-bit image, a float image (ideal takes values above 1 as they are;
    // other profiles see them clamped and rounded to 8 bits), or a built-in scene's frame. An
    // 8-bit input (an 8-bit image, a built-in scene) stays in an A8R8G8B8 scene in every profile:
    // its texels read as the same n/255 they would in a float scene, and ideal's frame moves a
    // quarter of the bytes to read it; a float image under ideal takes an A32B32G32R32F scene.
    bool setImage(const emu::RgbaImage& image, std::string& error);
    bool setImage(const emu::FloatImage& image, std::string& error);
    bool renderScene(Scene& scene, int frame, int frameCount, double& milliseconds, std::string& error);

    // Builds the technique's graph for a frame (`build` called before compile, for inspection),
    // and runs it; the output stays in outputTexture(). `hookObserves`: the hook only looks
    // (progress, dumps), never writes a texture (PassGraph::run).
    bool runFrame(const Technique& technique, const Settings& settings, int frame, int frameCount, FrameResult& result,
                  std::string& error, const PassGraph::Hook& hook = {},
                  const std::function<void(PassGraph&)>& built = {}, bool hookObserves = false);
    // Builds (and compiles) without running: for reports and --graph. What the technique's build
    // read of the frame (FrameBuild::frame, firstFrame).
    FrameDependence buildFrame(const Technique& technique, const Settings& settings, int frame, int frameCount,
                               PassGraph& graph);

    // The Graphviz of the last frame's graph as it ran (with the aliasing it got); empty unless
    // RunnerOptions::graphviz.
    const std::string& lastGraphviz() const { return m_lastGraphviz; }
    emu::Handle sceneTexture() const { return m_scene; }  // the current input's (setImage, renderScene)
    emu::Handle outputTexture() const { return m_output; }
    // Level 0 of a texture as 8-bit r g b a (float channels by frameByte), read where the device
    // keeps it (readPixels). The overloads taking an image reuse its buffer: a frame loop that
    // reads every frame allocates once.
    std::optional<emu::RgbaImage> readOutput(std::string& error);
    std::optional<emu::RgbaImage> readTexture(emu::Handle texture, std::string& error);
    bool readOutput(emu::RgbaImage& image, std::string& error);
    bool readTexture(emu::Handle texture, emu::RgbaImage& image, std::string& error);
    // Level 0 of a render-target texture as the application sees it, read where the device keeps
    // it (`Device::readSurface`: no copy) while `use` looks at it (D3D's layout, `pitch` bytes a
    // row). False with `error` if a call fails or `use` returns false.
    struct Pixels {
        const uint8_t* data = nullptr;
        uint32_t width = 0, height = 0;
        size_t pitch = 0;
        D3DFORMAT format = D3DFMT_UNKNOWN;
    };
    bool readPixels(emu::Handle texture, const std::function<bool(const Pixels&)>& use, std::string& error);

    // A pixel shader of glare/shaders by file name, assembled and validated on first use.
    emu::Handle shader(const std::string& file, std::string& error);
    // Persistent textures (FrameBuild::persistent).
    emu::Handle persistent(const std::string& name, const TextureDesc& desc, D3DCOLOR initial, std::string& error);
    void resetPersistent();  // the next frame starts from the initial state (a new sequence)
    // An object of type T a technique keeps on this runner between frames under `name` (made on
    // first use): results of device-side steps that a still input lets it keep (reuse).
    template <typename T>
    T& kept(const std::string& name) {
        std::shared_ptr<void>& slot = m_kept[name];
        if (!slot) slot = std::make_shared<T>();
        return *static_cast<T*>(slot.get());
    }
    // Whether passes are reused from frame to frame (RunnerOptions::skip and reuse).
    bool reuses() const { return m_options.skip && m_options.reuse; }
    // The CPU threads the frame's own CPU work (the sprites' sensors) may take: the software
    // renderer's count (DeviceOptions, 0 = the machine's), whichever renderer draws.
    int cpuThreads() const { return m_options.device.software.threads; }
    // Those threads: the renderer's workers (the software renderer's), else a pool of
    // cpuThreads() the runner starts on first use. No thread is started per frame.
    emu::ThreadPool& cpuPool();
    // The host's memory speed now, in GB/s: an RGBA8 surface of the frame's size copied into
    // another by cpuPool()'s threads (emu::parallelCopy), its bytes read and written counted as
    // PassStats::bytes counts a pass's, the median of five copies after one untimed. `warm`: the
    // same two surfaces each time (within the last-level cache where they fit); `cold`: four pairs
    // in turn, 64 MiB or more in all, so each copy's surfaces were last touched three copies
    // earlier (from memory, unless the cache holds that much). A pass that moved only its bytes
    // would run at about these speeds (ps11 glare's per-pass table; bench/README.md
    // "bench_glare").
    struct CopySpeed {
        double warm = 0, cold = 0;
    };
    CopySpeed copySpeed();
    TexturePool& pool() { return *m_pool; }

private:
    // Writes `image` into `scene` (in its format) and makes it the current scene.
    bool writeScene(const emu::FloatImage& image, emu::Handle scene, std::string& error);

    RunnerOptions m_options;
    std::unique_ptr<emu::Device> m_device;
    std::unique_ptr<TexturePool> m_pool;
    PassMemo m_memo;  // with RunnerOptions::skip: what runFrame keeps between frames
    std::map<std::string, std::shared_ptr<void>> m_kept;  // kept()
    std::shared_ptr<emu::ThreadPool> m_cpuPool;             // cpuPool() where the renderer has no workers
    emu::Handle m_scene8{}, m_sceneFloat{};  // the 8-bit scene; the float one (ideal only)
    emu::Handle m_scene{}, m_output{};       // m_scene: the one the last input went to
    std::map<std::string, emu::Handle> m_shaders;
    std::map<std::string, std::pair<emu::Handle, TextureDesc>> m_persistent;
    std::string m_persistentError;
    std::string m_lastGraphviz;
    // The last frame, when it reused every pass and its build read no frame index, with what it
    // depended on: a frame with all of it the same is skipped whole (runFrame).
    struct StillFrame {
        bool valid = false;
        bool askedFirst = false;  // the build read only whether the frame was the first,
        bool first = false;       // and it was (or not)
        const Technique* technique = nullptr;
        std::string techniqueName;  // (an object made where another was has another name, or is the same technique)
        Settings settings;
        emu::Handle scene{};
        uint64_t sceneGeneration = 0, outputGeneration = 0;
        std::vector<PassStats> passes;
    } m_still;
};

// One technique on its own built-in scene (Technique::scene, the scene's first frame), published
// settings, `frames` frames timed (the state carries over; the first starts converged).
struct SceneRun {
    std::optional<emu::RgbaImage> image;  // the last frame's output, alpha 255
    double medianMs = 0;                  // the technique's passes per frame
    size_t passes = 0;
};
SceneRun runOnScene(const Technique& technique, const RunnerOptions& options, int frames, std::string& error);

// RGB difference of two images of one size, in 8-bit levels.
struct ImageError {
    int max = 0;
    double mean = 0;
    double overOnePercent = 0;  // pixels whose largest channel difference is more than 1 level
    double psnr = 0;            // dB over RGB, peak 255: 10·log10(255² / mean squared difference); +inf when equal
};
ImageError imageError(const emu::RgbaImage& a, const emu::RgbaImage& b);

// The shader text of glare/shaders/<file>, or nullptr.
const std::string_view* shaderText(std::string_view file);

}  // namespace glare
