// A glare technique: an algorithm (the passes it adds to a PassGraph each frame) plus quality
// settings with named presets (docs/glare/README.md). Techniques are stateless; what lives
// between frames (the adapted luminance, the after-image) is a persistent texture of the Runner.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "glare/pass_graph.h"
#include "ps11/precision.h"

namespace glare {

class Runner;

// One quality setting. Numbers carry GLARE.md's units; `choices` makes it an enumeration whose
// value is the index of the choice.
struct ParamInfo {
    std::string name, unit, description;
    double min = 0, max = 1;
    // low, medium, high, published (the source's own default)
    std::array<double, 4> presets{};
    std::vector<std::string> choices;
    bool integer = false;
};

inline constexpr std::array<std::string_view, 4> kPresetNames = {"low", "medium", "high", "published"};
inline constexpr int kDefaultPreset = 3;

using Settings = std::map<std::string, double>;

// What a technique's build read of the frame it built: nothing, only whether it is the first,
// or its index or count.
enum class FrameDependence : uint8_t { None, First, Index };

// What a technique's build() works with for one frame.
struct FrameBuild {
    FrameBuild(PassGraph& g, Runner& r, const Settings& s, TextureId sceneId, TextureId outputId, int frameIndex,
               int frames, D3DFORMAT intermediate, ps11::Precision profile)
        : graph(g), runner(r), settings(s), scene(sceneId), output(outputId), format(intermediate),
          precision(profile), m_frame(frameIndex), m_frameCount(frames) {}
    PassGraph& graph;
    Runner& runner;
    const Settings& settings;
    TextureId scene;   // the frame (A8R8G8B8, or float under the ideal profile)
    TextureId output;  // the result, scene-sized A8R8G8B8
    // The frame's index and count, or only whether it is the first. A build that reads neither
    // index nor count gives the same graph every frame for the same settings (one that asked
    // only firstFrame(), every frame after the first), which lets a still input skip the whole
    // frame (Runner::runFrame).
    int frame() const {
        m_dependence = FrameDependence::Index;
        return m_frame;
    }
    int frameCount() const {
        m_dependence = FrameDependence::Index;
        return m_frameCount;
    }
    bool firstFrame() const {
        if (m_dependence == FrameDependence::None) m_dependence = FrameDependence::First;
        return m_frame == 0;
    }
    FrameDependence dependence() const { return m_dependence; }
    // The format of intermediate textures: A8R8G8B8, or A32B32G32R32F under the ideal profile
    // (docs/precision.md: ideal keeps intermediates in float render targets).
    D3DFORMAT format = D3DFMT_A8R8G8B8;
    ps11::Precision precision = ps11::Precision::Fx8;  // the device's profile
    double get(const std::string& name) const { return settings.at(name); }
    int choice(const std::string& name) const { return int(settings.at(name)); }
    TextureDesc sceneDesc() const { return graph.texture(scene).desc; }  // a copy: creating textures moves the nodes
    // A texture kept between frames, made (and cleared to `initial`) the first time it is asked
    // for; imported as an output so the passes that update it always run.
    TextureId persistent(const std::string& name, const TextureDesc& desc, D3DCOLOR initial = 0);

private:
    int m_frame = 0, m_frameCount = 1;
    mutable FrameDependence m_dependence = FrameDependence::None;
};

class Technique {
public:
    virtual ~Technique() = default;
    virtual std::string_view name() const = 0;     // "adaptive"
    virtual std::string_view title() const = 0;    // "Adaptive glare (Sousa, ShaderX3 4.2)"
    virtual std::string_view summary() const = 0;  // one line for --list
    // The built-in scene made to show it (docs/glare/scenes.md): the demo, the benchmark and the
    // fits report's accuracy table run it there.
    virtual std::string_view scene() const = 0;
    virtual const std::vector<ParamInfo>& params() const = 0;
    // Adds this frame's passes to fb.graph (scene → … → output).
    virtual void build(FrameBuild& fb) const = 0;
    // What the technique asks of a built-in scene before it is drawn: the glow-only fog's start and
    // end distance (Scene::setGlowFog; end <= start: none). Images have no depth and get none.
    virtual std::pair<float, float> sceneGlowFog(const Settings&) const { return {0.0f, 0.0f}; }
};

const std::vector<const Technique*>& techniques();
const Technique* findTechnique(std::string_view name);
// "unknown technique 'x' (techniques: adaptive, glow, pyramid, quarter, sprites)".
std::string unknownTechniqueMessage(std::string_view name);

// The settings of a preset ("low", "medium", "high", "published"); nullopt for an unknown name.
std::optional<Settings> presetSettings(const Technique& t, std::string_view preset);
// Applies "name=value" (a number, or a choice's name); false with `error` naming the setting and
// the allowed range or choices.
bool applySetting(const Technique& t, Settings& settings, std::string_view assignment, std::string& error);
// "screen" for a choice parameter, the number otherwise.
std::string settingText(const ParamInfo& p, double value);

}  // namespace glare
