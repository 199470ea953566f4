#include "glare/runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>


#include "emu/format.h"
#include "emu/fullscreen.h"
#include "emu/thread_pool.h"
#include "glare/scene.h"
#include "glare/sensors_kernels.h"
#include "glare/shader_library.h"

namespace glare {

using emu::Handle;

const std::string_view* shaderText(std::string_view file) {
    for (const EmbeddedShader& s : embeddedShaders())
        if (s.name == file) return &s.text;
    return nullptr;
}

TextureId FrameBuild::persistent(const std::string& name, const TextureDesc& desc, D3DCOLOR initial) {
    std::string error;
    const Handle h = runner.persistent(name, desc, initial, error);
    return graph.import(name, desc, h, true);
}

Runner::Runner(const RunnerOptions& options) : m_options(options) {
    emu::DeviceOptions device = options.device;
    if (!options.skip) device.software.skipTiles = false;
    m_device = std::make_unique<emu::Device>(device);
    m_pool = std::make_unique<TexturePool>(*m_device);
    m_device->CreateTexture(options.width, options.height, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT,
                            &m_scene8);
    if (intermediateFormat() != D3DFMT_A8R8G8B8)
        m_device->CreateTexture(options.width, options.height, 1, D3DUSAGE_RENDERTARGET, intermediateFormat(),
                                D3DPOOL_DEFAULT, &m_sceneFloat);
    m_scene = m_scene8;
    m_device->CreateTexture(options.width, options.height, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT,
                            &m_output);
}

Runner::~Runner() = default;

D3DFORMAT Runner::intermediateFormat() const {
    return m_device->hardware().precision == ps11::Precision::Ideal ? D3DFMT_A32B32G32R32F : D3DFMT_A8R8G8B8;
}

bool Runner::setImage(const emu::RgbaImage& image, std::string& error) {
    emu::FloatImage f;
    f.width = image.width;
    f.height = image.height;
    f.rgba.resize(image.rgba.size());
    for (size_t i = 0; i < image.rgba.size(); ++i) f.rgba[i] = float(image.rgba[i]) / 255.0f;
    return writeScene(f, m_scene8, error);  // (n/255 rounds back to n)
}

bool Runner::setImage(const emu::FloatImage& image, std::string& error) {
    return writeScene(image, m_sceneFloat != Handle::Null ? m_sceneFloat : m_scene8, error);
}

bool Runner::writeScene(const emu::FloatImage& image, Handle scene, std::string& error) {
    if (image.width != m_options.width || image.height != m_options.height) {
        error = "the image is " + std::to_string(image.width) + "x" + std::to_string(image.height) + ", the run " +
                std::to_string(m_options.width) + "x" + std::to_string(m_options.height);
        return false;
    }
    D3DSURFACE_DESC desc{};
    Handle surface{};
    if (m_device->GetLevelDesc(scene, 0, &desc) != D3D_OK || m_device->GetSurfaceLevel(scene, 0, &surface) != D3D_OK) {
        error = m_device->lastError().message;
        return false;
    }
    if (!emu::writeSurface(*m_device, surface, emu::surfacePixels(image, desc.Format), error)) return false;
    m_scene = scene;
    return true;
}

D3DFORMAT Runner::sceneFormat() const {
    return m_scene == m_sceneFloat && m_sceneFloat != Handle::Null ? intermediateFormat() : D3DFMT_A8R8G8B8;
}

bool Runner::renderScene(Scene& scene, int frame, int frameCount, double& milliseconds, std::string& error) {
    const auto start = std::chrono::steady_clock::now();
    // Scenes draw into an A8R8G8B8 target (the back buffer), which is the scene in every profile.
    Handle target{};
    if (m_device->GetSurfaceLevel(m_scene8, 0, &target) != D3D_OK) {
        error = m_device->lastError().message;
        return false;
    }
    if (!scene.render(*m_device, target, frame, frameCount, error)) return false;
    m_scene = m_scene8;
    milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return true;
}

FrameDependence Runner::buildFrame(const Technique& technique, const Settings& settings, int frame, int frameCount,
                                   PassGraph& graph) {
    const TextureId scene = graph.import("scene", {m_options.width, m_options.height, sceneFormat()}, m_scene, false);
    const TextureId output = graph.import("output", {m_options.width, m_options.height, D3DFMT_A8R8G8B8}, m_output, true);
    FrameBuild fb{graph, *this, settings, scene, output, frame, frameCount, intermediateFormat(),
                  m_device->hardware().precision};
    technique.build(fb);
    graph.compile();
    return fb.dependence();
}

bool Runner::runFrame(const Technique& technique, const Settings& settings, int frame, int frameCount,
                      FrameResult& result, std::string& error, const PassGraph::Hook& hook,
                      const std::function<void(PassGraph&)>& built, bool hookObserves) {
    const auto start = std::chrono::steady_clock::now();
    // A still input: the last frame reused every pass, its build read no frame index (or only
    // whether the frame is the first, and this one is as first as that one was), and the
    // technique, its settings and the contents of the scene and the output are the same. This
    // frame would build the same graph and reuse every pass again (the memo, the persistent
    // textures and what the technique keeps are as that frame left them): nothing is built or
    // run. Hooks and `built` look at a frame's passes as they run, so they get a whole frame.
    const StillFrame& still = m_still;
    if (reuses() && !hook && !built && still.valid && (!still.askedFirst || still.first == (frame == 0)) &&
        still.technique == &technique &&
        still.techniqueName == technique.name() && still.settings == settings && still.scene == m_scene &&
        m_device->contentGeneration(m_scene) == still.sceneGeneration &&
        m_device->contentGeneration(m_output) == still.outputGeneration) {
        result.passes = still.passes;
        result.still = true;
        result.buildMilliseconds = 0;
        result.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        return true;
    }
    m_still.valid = false;
    result.still = false;
    PassGraph graph;
    const FrameDependence dependence = buildFrame(technique, settings, frame, frameCount, graph);
    result.buildMilliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!m_persistentError.empty()) {
        error = m_persistentError;
        return false;
    }
    if (built) built(graph);
    result.passes.clear();
    const bool ok = graph.run(*m_pool, result.passes, error, hook, reuses() ? &m_memo : nullptr, hookObserves);
    // The passes' own time: what the hooks (dumps, captures) take is not the technique's.
    result.milliseconds = result.buildMilliseconds;
    for (const PassStats& s : result.passes) result.milliseconds += s.milliseconds;
    if (ok && built) built(graph);  // again, with the aliasing filled in
    if (ok && m_options.graphviz) m_lastGraphviz = graph.graphviz(std::string(technique.name()));
    if (ok && reuses() && dependence != FrameDependence::Index && !result.passes.empty() &&
        std::all_of(result.passes.begin(), result.passes.end(), [](const PassStats& p) { return p.reused; })) {
        m_still = StillFrame{true,
                             dependence == FrameDependence::First,
                             frame == 0,
                             &technique,
                             std::string(technique.name()),
                             settings,
                             m_scene,
                             m_device->contentGeneration(m_scene),
                             m_device->contentGeneration(m_output),
                             result.passes};
        for (PassStats& p : m_still.passes) p.milliseconds = 0;
    }
    return ok;
}

std::optional<emu::RgbaImage> Runner::readTexture(Handle texture, std::string& error) {
    emu::RgbaImage img;
    if (!readTexture(texture, img, error)) return std::nullopt;
    return img;
}

bool Runner::readTexture(Handle texture, emu::RgbaImage& img, std::string& error) {
    return readPixels(
        texture,
        [&](const Pixels& px) {
            const emu::FormatInfo* info = emu::formatInfo(px.format);
            if (!info) {
                error = std::string("readTexture: the texture's format ") + emu::formatName(px.format) + " is unknown";
                return false;
            }
            img.width = px.width;
            img.height = px.height;
            img.rgba.resize(size_t(px.width) * px.height * 4);  // keeps the buffer of an image read before
            const bool floats = px.format == D3DFMT_A32B32G32R32F;  // four floats r g b a (ps11/formats.cpp)
            std::vector<float> v(floats ? size_t(px.width) * 4 : 0);   // a row (its bytes need not be aligned)
            for (uint32_t y = 0; y < px.height; ++y) {
                const uint8_t* row = px.data + size_t(y) * px.pitch;
                uint8_t* d = &img.rgba[size_t(y) * px.width * 4];
                if (px.format == D3DFMT_A8R8G8B8) {  // b g r a words: swap bytes 0 and 2
                    for (uint32_t x = 0; x < px.width; ++x) {
                        uint32_t w;
                        std::memcpy(&w, row + 4 * size_t(x), 4);
                        w = (w & 0xff00ff00u) | ((w >> 16) & 0xffu) | ((w & 0xffu) << 16);
                        std::memcpy(d + 4 * size_t(x), &w, 4);
                    }
                } else if (floats) {
                    std::memcpy(v.data(), row, v.size() * sizeof(float));
                    frameBytes(v.data(), v.size(), d);
                } else {
                    for (uint32_t x = 0; x < px.width; ++x) {
                        const uint8_t* p = row + size_t(x) * info->bytes;
                        if (info->cls == emu::FormatClass::Unorm8) {
                            const auto rgba = emu::decodeUnorm8(*info, p);
                            std::memcpy(d + 4 * size_t(x), rgba.data(), 4);
                        } else {
                            const auto v = emu::decodeTexel(*info, p, ps11::SignedDecode{});
                            for (int c = 0; c < 4; ++c) d[4 * size_t(x) + size_t(c)] = frameByte(v[size_t(c)]);
                        }
                    }
                }
            }
            return true;
        },
        error);
}

emu::ThreadPool& Runner::cpuPool() {
    if (emu::ThreadPool* w = m_device->rendererWorkers()) return *w;
    if (!m_cpuPool) m_cpuPool = emu::ThreadPool::shared(cpuThreads());
    return *m_cpuPool;
}

Runner::CopySpeed Runner::copySpeed() {
    const size_t bytes = std::max<size_t>(size_t(m_options.width) * m_options.height * 4, 64);
    // The cold ring: four pairs, at least 64 MiB together (a smaller frame's surfaces are copied
    // from further into a larger ring: every copy still reads and writes `bytes`).
    constexpr size_t kPairs = 4, kRing = size_t(64) << 20;
    const size_t stride = std::max(bytes, kRing / (2 * kPairs));
    std::vector<uint8_t> ring(2 * kPairs * stride, 1);  // every page touched here
    emu::ThreadPool& pool = cpuPool();
    auto speed = [&](auto&& pair) {
        std::vector<double> ms;
        for (int i = 0; i < 6; ++i) {
            const auto [to, from] = pair(i);
            const auto t0 = std::chrono::steady_clock::now();
            emu::parallelCopy(pool, to, from, bytes);
            if (i > 0)  // (the first untimed)
                ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        }
        std::sort(ms.begin(), ms.end());
        const double median = ms[ms.size() / 2];
        return median > 0 ? 2.0 * double(bytes) / 1e6 / median : 0.0;
    };
    CopySpeed s;
    s.warm = speed([&](int) { return std::pair{ring.data() + stride, ring.data()}; });
    s.cold = speed([&](int i) {
        uint8_t* from = ring.data() + 2 * size_t(i % int(kPairs)) * stride;
        return std::pair{from + stride, static_cast<const uint8_t*>(from)};
    });
    return s;
}

bool Runner::readPixels(Handle texture, const std::function<bool(const Pixels&)>& use, std::string& error) {
    emu::Device& d = *m_device;
    Handle surface{};
    D3DSURFACE_DESC desc{};
    bool ok = false;
    if (d.GetSurfaceLevel(texture, 0, &surface) != D3D_OK || d.GetDesc(surface, &desc) != D3D_OK ||
        d.readSurface(surface, [&](const D3DLOCKED_RECT& lr) {
            ok = use(Pixels{static_cast<const uint8_t*>(lr.pBits), desc.Width, desc.Height, size_t(lr.Pitch), desc.Format});
        }) != D3D_OK) {
        error = d.lastError().message;
        return false;
    }
    return ok;
}

std::optional<emu::RgbaImage> Runner::readOutput(std::string& error) { return readTexture(m_output, error); }
bool Runner::readOutput(emu::RgbaImage& image, std::string& error) { return readTexture(m_output, image, error); }

Handle Runner::shader(const std::string& file, std::string& error) {
    auto it = m_shaders.find(file);
    if (it != m_shaders.end()) return it->second;
    const std::string_view* text = shaderText(file);
    if (!text) {
        error = "no shader glare/shaders/" + file;
        return Handle::Null;
    }
    Handle h{};
    if (m_device->CreatePixelShaderFromText(*text, &h) != D3D_OK) {
        error = "glare/shaders/" + file + ": " + m_device->lastError().message;
        return Handle::Null;
    }
    m_shaders.emplace(file, h);
    return h;
}

Handle Runner::persistent(const std::string& name, const TextureDesc& desc, D3DCOLOR initial, std::string& error) {
    auto it = m_persistent.find(name);
    if (it != m_persistent.end() && it->second.second == desc) return it->second.first;
    if (it != m_persistent.end()) {
        m_device->Release(it->second.first);
        m_persistent.erase(it);
    }
    Handle h{}, surface{};
    if (m_device->CreateTexture(desc.width, desc.height, 1, D3DUSAGE_RENDERTARGET, desc.format, D3DPOOL_DEFAULT, &h) !=
            D3D_OK ||
        m_device->GetSurfaceLevel(h, 0, &surface) != D3D_OK || m_device->SetRenderTarget(0, surface) != D3D_OK ||
        m_device->Clear(0, nullptr, D3DCLEAR_TARGET, initial, 1, 0) != D3D_OK) {
        error = m_persistentError = "persistent texture " + name + ": " + m_device->lastError().message;
        return Handle::Null;
    }
    m_persistent.emplace(name, std::make_pair(h, desc));
    return h;
}

void Runner::resetPersistent() {
    for (auto& [name, entry] : m_persistent) m_device->Release(entry.first);
    m_persistent.clear();
    m_still.valid = false;
}

SceneRun runOnScene(const Technique& technique, const RunnerOptions& options, int frames, std::string& error) {
    SceneRun run;
    Runner runner(options);
    std::unique_ptr<Scene> scene = makeScene(technique.scene(), error);
    if (!scene) return run;
    const Settings settings = *presetSettings(technique, "published");
    const auto [fogStart, fogEnd] = technique.sceneGlowFog(settings);
    scene->setGlowFog(fogStart, fogEnd);
    std::vector<double> ms;
    double sceneMs = 0;
    frames = std::max(frames, 1);
    for (int f = 0; f < frames; ++f) {
        FrameResult r;
        if (!runner.renderScene(*scene, 0, 8, sceneMs, error) || !runner.runFrame(technique, settings, f, frames, r, error))
            return run;
        ms.push_back(r.milliseconds);
        run.passes = r.passes.size();
    }
    std::sort(ms.begin(), ms.end());
    run.medianMs = ms[ms.size() / 2];
    run.image = runner.readOutput(error);
    if (run.image)
        for (size_t i = 3; i < run.image->rgba.size(); i += 4) run.image->rgba[i] = 255;
    return run;
}

ImageError imageError(const emu::RgbaImage& a, const emu::RgbaImage& b) {
    ImageError e;
    const size_t px = std::min(a.rgba.size(), b.rgba.size()) / 4;
    uint64_t sum = 0, over = 0, squares = 0;
    for (size_t i = 0; i < px; ++i) {
        int worst = 0;
        for (size_t c = 0; c < 3; ++c) {
            const int d = std::abs(int(a.rgba[i * 4 + c]) - int(b.rgba[i * 4 + c]));
            worst = std::max(worst, d);
            sum += uint64_t(d);
            squares += uint64_t(d * d);
        }
        e.max = std::max(e.max, worst);
        over += worst > 1;
    }
    e.mean = px ? double(sum) / double(px * 3) : 0;
    e.overOnePercent = px ? 100.0 * double(over) / double(px) : 0;
    e.psnr = squares ? 10.0 * std::log10(255.0 * 255.0 * double(px * 3) / double(squares))
                     : std::numeric_limits<double>::infinity();
    return e;
}

void frameBytes(const float* in, size_t n, uint8_t* out) { sensorKernels(ps11::simdLevel()).frameBytes(in, n, out); }

}  // namespace glare
