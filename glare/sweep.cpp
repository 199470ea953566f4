// The run-time-against-error sweep (glare/sweep.h, docs/bench.md): expands techniques × presets ×
// settings × hardware × renderers into rows, runs each row's warm frames interleaved with the
// other rows of its settings, measures the last frame against the cached ideal reference and the
// intended math, and marks the Pareto front.
#include "glare/sweep.h"

#include <algorithm>
#include <cstdio>
#include <map>

#include "glare/intended.h"
#include "glare/scene.h"

namespace glare {

std::vector<SweepHardware> allSweepHardware() {
    std::vector<SweepHardware> all;
    for (const ps11::HardwareClass& h : ps11::hardwareClasses()) all.push_back({std::string(h.name), &h, false});
    all.push_back({"ideal", nullptr, true});
    return all;
}

std::optional<SweepHardware> findSweepHardware(std::string_view name) {
    if (name == "ideal") return SweepHardware{"ideal", nullptr, true};
    const ps11::HardwareClass* h = ps11::findHardware(name);
    if (!h) return std::nullopt;
    return SweepHardware{std::string(h->name), h, false};
}

bool dominates(const SweepRow& a, const SweepRow& b) {
    const bool moreAccurate =
        a.error.mean < b.error.mean || (a.error.mean == b.error.mean && a.error.max < b.error.max);
    return a.msMedian < b.msMedian && moreAccurate;
}

void markPareto(std::vector<SweepRow>& rows) {
    auto group = [](const SweepRow& r) {
        return r.technique + "|" + r.scene + "|" + std::to_string(r.width) + "x" + std::to_string(r.height);
    };
    for (SweepRow& b : rows) {
        b.pareto = true;
        for (const SweepRow& a : rows)
            if (&a != &b && group(a) == group(b) && dominates(a, b)) {
                b.pareto = false;
                break;
            }
    }
}

namespace {

emu::FloatImage toFloat(const emu::RgbaImage& img) {
    emu::FloatImage f;
    f.width = img.width, f.height = img.height;
    f.rgba.resize(img.rgba.size());
    for (size_t i = 0; i < img.rgba.size(); ++i) f.rgba[i] = float(img.rgba[i]) / 255.0f;
    return f;
}

emu::RgbaImage toBytes(const emu::FloatImage& f) {
    emu::RgbaImage img;
    img.width = f.width, img.height = f.height;
    img.rgba.resize(f.rgba.size());
    frameBytes(f.rgba.data(), f.rgba.size(), img.rgba.data());
    return img;
}

std::string settingsKey(const Settings& s) {
    std::string k;
    char buf[48];
    for (const auto& [name, v] : s) {
        std::snprintf(buf, sizeof buf, "=%.17g;", v);
        k += name + buf;
    }
    return k;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

// Every combination of the settings `t` has (the others are for other techniques), as --set
// assignments; one empty combination when none applies.
std::vector<std::vector<std::string>> combinations(const Technique& t, const std::vector<SweepSetting>& settings) {
    std::vector<std::vector<std::string>> out = {{}};
    for (const SweepSetting& s : settings) {
        const bool has = std::any_of(t.params().begin(), t.params().end(), [&](const ParamInfo& p) { return p.name == s.name; });
        if (!has) continue;
        std::vector<std::vector<std::string>> next;
        for (const std::vector<std::string>& prefix : out)
            for (const std::string& v : s.values) {
                next.push_back(prefix);
                next.back().push_back(s.name + "=" + v);
            }
        out = std::move(next);
    }
    return out;
}

class Sweep {
public:
    Sweep(const SweepSpec& spec, const SweepProgress& progress) : m_spec(spec), m_progress(progress) {}

    bool run(std::vector<SweepRow>& rows, std::string& error);

private:
    void say(const std::string& line) const {
        if (m_progress) m_progress(line);
    }
    uint32_t width() const { return m_spec.image ? m_spec.image->width : m_spec.width; }
    uint32_t height() const { return m_spec.image ? m_spec.image->height : m_spec.height; }
    int frameCount() const { return m_spec.frames + 1; }  // one warm-up frame, then the timed ones
    RunnerOptions options(const SweepHardware* hw, bool gl, bool skip) const {
        RunnerOptions ro;
        ro.width = width();
        ro.height = height();
        ro.skip = skip;
        ro.device.software.threads = m_spec.threads;
        if (hw) ro.device.hardware = hw->hardware;
        if (!hw || hw->ideal) ro.device.precision = ps11::Precision::Ideal;
        if (gl) ro.device.renderer = m_spec.glRenderer;
        return ro;
    }
    const emu::FloatImage* input(const Technique& t, const Settings& s, const std::string& scene, std::string& error);
    const emu::RgbaImage* reference(const Technique& t, const Settings& s, const emu::FloatImage& in,
                                    const std::string& inputKey, std::string& error);
    const std::optional<emu::RgbaImage>& intended(const Technique& t, const Settings& s, const emu::FloatImage& in,
                                                  const std::string& inputKey);

    const SweepSpec& m_spec;
    const SweepProgress& m_progress;
    std::map<std::string, emu::FloatImage> m_inputs;
    std::map<std::string, emu::RgbaImage> m_references;
    std::map<std::string, std::optional<emu::RgbaImage>> m_intended;
    std::string m_inputKey;  // the key of the last input()
};

// The input of a row: the image, or frame 0 of the scene drawn on the emulated default card (with
// the technique's glow fog), kept per scene and fog.
const emu::FloatImage* Sweep::input(const Technique& t, const Settings& s, const std::string& scene, std::string& error) {
    if (m_spec.image) {
        m_inputKey = "image";
        return &*m_spec.image;
    }
    const auto [fogStart, fogEnd] = t.sceneGlowFog(s);
    char fog[64];
    std::snprintf(fog, sizeof fog, "|%.9g|%.9g", double(fogStart), double(fogEnd));
    m_inputKey = scene + fog;
    auto it = m_inputs.find(m_inputKey);
    if (it != m_inputs.end()) return &it->second;
    std::unique_ptr<Scene> sc = makeScene(scene, error);
    if (!sc) return nullptr;
    sc->setGlowFog(fogStart, fogEnd);
    int frames = 1;
    for (const SceneInfo& info : sceneList())
        if (info.name == scene) frames = info.defaultFrames;
    RunnerOptions ro = options(nullptr, false, true);
    ro.device.precision.reset();  // scenes draw on the default card, as `ps11 glare` and the benchmark do
    Runner runner(ro);
    double ms = 0;
    std::optional<emu::RgbaImage> img;
    if (!runner.renderScene(*sc, 0, frames, ms, error) || !(img = runner.readTexture(runner.sceneTexture(), error)))
        return nullptr;
    return &m_inputs.emplace(m_inputKey, toFloat(*img)).first->second;
}

// The technique's output on the ideal profile after the same frames as a row (reuse on: the same
// bytes), once per technique, settings and input.
const emu::RgbaImage* Sweep::reference(const Technique& t, const Settings& s, const emu::FloatImage& in,
                                       const std::string& inputKey, std::string& error) {
    const std::string key = std::string(t.name()) + "|" + settingsKey(s) + "|" + inputKey;
    auto it = m_references.find(key);
    if (it != m_references.end()) return &it->second;
    say("ideal reference: " + std::string(t.name()) + " (" + std::to_string(frameCount()) + " frames)");
    Runner runner(options(nullptr, false, true));
    if (!runner.setImage(in, error)) return nullptr;
    for (int f = 0; f < frameCount(); ++f) {
        FrameResult r;
        if (!runner.runFrame(t, s, f, frameCount(), r, error)) return nullptr;
    }
    std::optional<emu::RgbaImage> out = runner.readOutput(error);
    if (!out) return nullptr;
    return &m_references.emplace(key, std::move(*out)).first->second;
}

const std::optional<emu::RgbaImage>& Sweep::intended(const Technique& t, const Settings& s, const emu::FloatImage& in,
                                                     const std::string& inputKey) {
    const std::string key = std::string(t.name()) + "|" + settingsKey(s) + "|" + inputKey;
    auto it = m_intended.find(key);
    if (it != m_intended.end()) return it->second;
    std::string why;
    std::optional<emu::FloatImage> f = intendedResult(t, s, in, frameCount() - 1, why);
    if (f) say("intended math: " + std::string(t.name()));
    return m_intended.emplace(key, f ? std::optional<emu::RgbaImage>(toBytes(*f)) : std::nullopt).first->second;
}

bool Sweep::run(std::vector<SweepRow>& rows, std::string& error) {
    rows.clear();
    if (m_spec.techniques.empty()) {
        error = "no technique to run";
        return false;
    }
    if (m_spec.frames < 1) {
        error = "frames must be at least 1";
        return false;
    }
    if (m_spec.gl && !m_spec.glRenderer) {
        error = "the GL renderer is not available";
        return false;
    }
    if (width() < 8 || height() < 8) {
        error = "the frame is " + std::to_string(width()) + "x" + std::to_string(height()) +
                "; the techniques need at least 8x8";
        return false;
    }
    // A swept setting some selected technique must have.
    for (const SweepSetting& s : m_spec.settings) {
        bool any = false;
        std::string names;
        for (const Technique* t : m_spec.techniques) {
            names += (names.empty() ? "" : ", ") + std::string(t->name());
            for (const ParamInfo& p : t->params()) any = any || p.name == s.name;
        }
        if (!any) {
            error = "--set " + s.name + ": no setting '" + s.name + "' in " + names + " (`ps11 glare --list` lists them)";
            return false;
        }
        if (s.values.empty()) {
            error = "--set " + s.name + ": no values";
            return false;
        }
    }
    std::vector<SweepHardware> hardware = m_spec.hardware;
    if (hardware.empty()) {
        const ps11::HardwareClass& h = ps11::defaultHardware(1);
        hardware.push_back({std::string(h.name), &h, false});
    }
    std::vector<bool> backends;
    if (m_spec.emu) backends.push_back(false);
    if (m_spec.gl) backends.push_back(true);
    if (backends.empty()) {
        error = "no renderer to run";
        return false;
    }

    size_t total = 0;
    for (const Technique* t : m_spec.techniques)
        total += m_spec.qualities.size() * combinations(*t, m_spec.settings).size() * hardware.size() * backends.size();

    for (const Technique* t : m_spec.techniques) {
        const std::string sceneName = m_spec.image ? m_spec.imageName : m_spec.scene.empty() ? std::string(t->scene()) : m_spec.scene;
        for (const std::string& quality : m_spec.qualities) {
            const std::optional<Settings> preset = presetSettings(*t, quality);
            if (!preset) {
                error = "--quality: unknown preset '" + quality + "' (low, medium, high, published)";
                return false;
            }
            for (const std::vector<std::string>& combo : combinations(*t, m_spec.settings)) {
                Settings s = *preset;
                std::vector<std::pair<std::string, std::string>> swept;
                for (const std::string& a : combo) {
                    if (!applySetting(*t, s, a, error)) {
                        error = "--set " + a + ": " + error;
                        return false;
                    }
                    const std::string name = a.substr(0, a.find('='));
                    for (const ParamInfo& p : t->params())
                        if (p.name == name) swept.push_back({name, settingText(p, s.at(name))});
                }
                const emu::FloatImage* in = input(*t, s, sceneName, error);
                if (!in) return false;
                const std::string inputKey = m_inputKey;
                const emu::RgbaImage* ref = reference(*t, s, *in, inputKey, error);
                if (!ref) return false;
                const std::optional<emu::RgbaImage>& want = intended(*t, s, *in, inputKey);

                // The group's runners, their frames interleaved.
                struct Run {
                    SweepRow row;
                    std::unique_ptr<Runner> runner;
                    std::vector<double> ms;
                };
                std::vector<Run> group;
                for (const SweepHardware& hw : hardware)
                    for (bool gl : backends) {
                        Run r;
                        r.row.technique = std::string(t->name());
                        r.row.quality = quality;
                        r.row.settings = s;
                        r.row.swept = swept;
                        r.row.hardware = hw.name;
                        r.row.backend = gl ? "gl" : "emu";
                        r.row.glMode = gl ? (m_spec.glNative ? "native" : "exact") : "";
                        r.row.scene = sceneName;
                        r.row.width = width();
                        r.row.height = height();
                        r.row.frames = m_spec.frames;
                        r.runner = std::make_unique<Runner>(options(&hw, gl, false));
                        r.row.precision = ps11::precisionName(r.runner->device().hardware().precision);
                        if (!r.runner->setImage(*in, error)) {
                            error = r.row.backend + ": " + error;
                            return false;
                        }
                        group.push_back(std::move(r));
                    }
                for (int f = 0; f < frameCount(); ++f)
                    for (Run& r : group) {
                        FrameResult fr;
                        if (!r.runner->runFrame(*t, s, f, frameCount(), fr, error)) {
                            error = r.row.technique + " on " + r.row.hardware + " (" + r.row.backend + "): " + error;
                            return false;
                        }
                        if (f > 0) r.ms.push_back(fr.milliseconds);
                    }
                for (Run& r : group) {
                    std::optional<emu::RgbaImage> out = r.runner->readOutput(error);
                    if (!out) return false;
                    r.runner.reset();
                    r.row.msMedian = median(r.ms);
                    r.row.msMin = *std::min_element(r.ms.begin(), r.ms.end());
                    r.row.msMax = *std::max_element(r.ms.begin(), r.ms.end());
                    r.row.error = imageError(*out, *ref);
                    if (want) r.row.intendedError = imageError(*out, *want);
                    rows.push_back(std::move(r.row));
                    const SweepRow& row = rows.back();
                    std::string settingsText;
                    for (const auto& [n, v] : row.swept) settingsText += " " + n + "=" + v;
                    char buf[160];
                    std::snprintf(buf, sizeof buf, ": %.2f ms, %.3f levels mean, %d max", row.msMedian, row.error.mean,
                                  row.error.max);
                    say("[" + std::to_string(rows.size()) + "/" + std::to_string(total) + "] " + row.technique + " " +
                        row.quality + settingsText + " " + row.hardware + " " + row.backend + buf);
                }
            }
        }
    }
    markPareto(rows);
    return true;
}

}  // namespace

bool runSweep(const SweepSpec& spec, std::vector<SweepRow>& rows, std::string& error, const SweepProgress& progress) {
    Sweep sweep(spec, progress);
    return sweep.run(rows, error);
}

}  // namespace glare
