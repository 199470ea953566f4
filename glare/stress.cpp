// The stress suite, GLARE.md §7: each 8-bit pitfall measured on the emulated 1.1-class card by the
// techniques' own ps_1_1 passes, beside its prediction (the §7 formula in double) and a fix that
// still fits ps_1_1 (docs/stress.md). §6's metrics and the robustness checks are in
// glare/stress_metrics.cpp.
#include "glare/stress.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "glare/glow.h"
#include "glare/passes.h"
#include "ps11/hardware.h"

namespace glare {

double stressGet(const StressValue& v, const std::string& key) {
    for (const auto& [k, x] : v)
        if (k == key) return x;
    return NAN;
}

RunnerOptions stressRunnerOptions(const StressOptions& o, uint32_t w, uint32_t h) {
    RunnerOptions ro;
    ro.width = w;
    ro.height = h;
    ro.device.hardware = o.hardware ? o.hardware : &ps11::defaultHardware(1);
    ro.skip = false;
    ro.device.software.skipTiles = false;
    return ro;
}

namespace {

emu::FloatImage uniformImage(uint32_t w, uint32_t h, float v, float a = 1) {
    emu::FloatImage img{w, h, {}};
    img.rgba.reserve(size_t(w) * h * 4);
    for (size_t i = 0; i < size_t(w) * h; ++i) img.rgba.insert(img.rgba.end(), {v, v, v, a});
    return img;
}

void setPixel(emu::FloatImage& img, uint32_t x, uint32_t y, float v) {
    float* p = &img.rgba[(size_t(y) * img.width + x) * 4];
    p[0] = p[1] = p[2] = v;
}

Settings published(const char* technique) { return *presetSettings(*findTechnique(technique), "published"); }

// The red channel of a texture's level 0, in levels.
bool redLevels(Runner& run, emu::Handle texture, std::vector<int>& out, std::string& error) {
    std::optional<emu::RgbaImage> img = run.readTexture(texture, error);
    if (!img) return false;
    out.resize(size_t(img->width) * img->height);
    for (size_t i = 0; i < out.size(); ++i) out[i] = img->rgba[i * 4];
    return true;
}

long sum(const std::vector<int>& v) { return std::accumulate(v.begin(), v.end(), 0L); }

// Runs one frame and reads the red levels of the textures the named passes wrote, right after
// they ran (a graph's transient textures are reused later in the frame).
bool runAndRead(Runner& run, const Technique& t, const Settings& s, int frame, int frames,
                const std::vector<std::string>& passNames, std::vector<std::vector<int>>& read, std::string& error) {
    PassGraph* graph = nullptr;
    read.assign(passNames.size(), {});
    FrameResult r;
    std::string hookError;
    const bool ok = run.runFrame(
        t, s, frame, frames, r, error,
        [&](uint32_t pass, bool after, std::string& e) {
            if (!after) return true;
            for (size_t i = 0; i < passNames.size(); ++i)
                if (graph->passes()[pass].info.name == passNames[i] &&
                    !redLevels(run, graph->texture(graph->passes()[pass].writes[0]).device, read[i], e))
                    return false;
            return true;
        },
        [&](PassGraph& g) { graph = &g; });
    return ok;
}

// One direction of a separable convolution with the weights given (as constants: the device
// rounds them to its grid), 4 point taps per pass of weighted4.psh, passes after the first added
// (ONE, ONE): the glow's ps_1_1 path (glare/glow.cpp) with the weights left to the caller.
class WeightRow final : public Technique {
public:
    explicit WeightRow(std::vector<double> w) : m_weights(std::move(w)) {}
    std::string_view name() const override { return "weight_row"; }
    std::string_view title() const override { return "one 1D convolution pass set (stress suite)"; }
    std::string_view summary() const override { return "weighted4.psh passes, point taps, weights as given"; }
    std::string_view scene() const override { return ""; }
    const std::vector<ParamInfo>& params() const override {
        static const std::vector<ParamInfo> none;
        return none;
    }
    void build(FrameBuild& fb) const override {
        const int r = int(m_weights.size() / 2);
        for (size_t first = 0, pass = 0; first < m_weights.size(); first += 4, ++pass) {
            QuadPass qp{"weighted4.psh", fb.output, {}, {}, pass == 0 ? Blend::None : Blend::Add};
            for (size_t i = 0; i < 4; ++i) {
                const size_t k = first + i;
                const float w = k < m_weights.size() ? float(m_weights[k]) : 0.0f;
                if (k < m_weights.size()) qp.taps.push_back(texelTap(fb, fb.scene, float(int(k) - r), 0, D3DTEXF_POINT));
                qp.constants.push_back({int(i), {w, w, w, w}});
            }
            addQuadPass(fb, "row_" + std::to_string(pass), "", qp);
        }
    }

private:
    std::vector<double> m_weights;
};

// Σ of the impulse response of one WeightRow pass set: a texel of level 255 in a black row, the
// output summed, over 255: the kernel's sum as the card holds it.
bool measureWeightSum(const StressOptions& o, const std::vector<double>& weights, double& gain, std::string& error) {
    const uint32_t w = 64, h = 4;
    Runner run(stressRunnerOptions(o, w, h));
    emu::FloatImage img = uniformImage(w, h, 0);
    for (uint32_t y = 0; y < h; ++y) setPixel(img, w / 2, y, 1);
    if (!run.setImage(img, error)) return false;
    const WeightRow t(weights);
    FrameResult r;
    std::vector<int> out;
    if (!run.runFrame(t, {}, 0, 1, r, error) || !redLevels(run, run.outputTexture(), out, error)) return false;
    gain = double(sum(out)) / (255.0 * h);
    return true;
}

}  // namespace

bool adaptationLevels(const StressOptions& o, const Settings& settings, const std::vector<emu::FloatImage>& images,
                      const std::vector<int>& imageOfFrame, std::vector<int>& levels, std::string& error) {
    const Technique& t = *findTechnique("adaptive");
    Runner run(stressRunnerOptions(o, images.at(0).width, images.at(0).height));
    const emu::Handle adapted = run.persistent("adapted glare amount", {1, 1, run.intermediateFormat()}, 0, error);
    if (adapted == emu::Handle::Null) return false;
    levels.clear();
    int shown = -1;
    const int frames = int(imageOfFrame.size());
    for (int f = 0; f < frames; ++f) {
        if (imageOfFrame[size_t(f)] != shown) {
            shown = imageOfFrame[size_t(f)];
            if (!run.setImage(images.at(size_t(shown)), error)) return false;
        }
        FrameResult r;
        std::vector<int> a;
        if (!run.runFrame(t, settings, f, frames, r, error) || !redLevels(run, adapted, a, error)) return false;
        levels.push_back(a.at(0));
    }
    return true;
}

std::vector<int> predictSmoothingLevels(double a, int target, int start, int frames) {
    const double a8 = std::nearbyint(a * 255);
    std::vector<int> out;
    double level = start;
    for (int f = 0; f < frames; ++f) {
        level = std::nearbyint((a8 * target + level * (255 - a8)) / 255);
        out.push_back(int(level));
    }
    return out;
}

std::vector<int> predictFeedbackLevels(const Settings& glowSettings, int y0, int frames) {
    const std::vector<double> q = quantiseWeights(glowKernel(glowSettings), ps11::Precision::Fx8);
    auto blur = [&](double y) {
        double total = 0;
        for (size_t first = 0; first < q.size(); first += 4) {
            double r = 0;
            for (size_t i = first; i < std::min(first + 4, q.size()); ++i)
                r = std::nearbyint(y * std::nearbyint(q[i] * 255) / 255 + r);
            total += r;
        }
        return std::min(total, 255.0);
    };
    const double k8 = std::nearbyint(glowSettings.at("decay") * 255);
    std::vector<int> out;
    double y = y0;
    for (int f = 0; f < frames; ++f) {
        y = blur(blur(std::nearbyint(y * k8 / 255)));
        out.push_back(int(y));
    }
    return out;
}

// --- smoothing_dead_band --------------------------------------------------------------------

bool stressSmoothingDeadBand(const StressOptions& o, StressItem& item, std::string& error) {
    // A uniform grey whose adapted amount L sits mid-scale (the dither's offsets are clipped near 0
    // and 255), approached from black (start=black) and from white (a converged white frame first).
    const uint32_t n = 16;
    const std::vector<emu::FloatImage> images = {uniformImage(n, n, 0.35f), uniformImage(n, n, 1.0f)};
    Settings s = published("adaptive");
    const double a = s.at("smoothing");
    const int frames = 400;
    // The target: one frame with smoothing 1 writes L itself.
    Settings once = s;
    once["smoothing"] = 1;
    once["start"] = 1;
    std::vector<int> levels;
    if (!adaptationLevels(o, once, images, {0}, levels, error)) return false;
    const int target = levels.at(0);

    std::vector<int> below(size_t(frames), 0), above(size_t(frames), 0);
    above[0] = 1;  // frame 0 white (converged start), then the grey
    std::vector<int> lb, la;  // the last run's levels from below and from above
    auto run = [&](const Settings& st, double& fromBelow, double& fromAbove, bool meanOfTail) {
        Settings sb = st, sa = st;
        sb["start"] = 1;  // black
        sa["start"] = 0;  // converged on frame 0's white
        if (!adaptationLevels(o, sb, images, below, lb, error) || !adaptationLevels(o, sa, images, above, la, error))
            return false;
        auto settled = [&](const std::vector<int>& v) {
            if (!meanOfTail) return double(v.back());
            double m = 0;
            for (size_t i = v.size() / 2; i < v.size(); ++i) m += v[i];
            return m / double(v.size() - v.size() / 2);
        };
        fromBelow = double(target) - settled(lb);
        fromAbove = settled(la) - double(target);
        return true;
    };
    double mb = 0, ma = 0, fb = 0, fa = 0;
    if (!run(s, mb, ma, false)) return false;
    const std::vector<int> plainBelow = lb;
    Settings dithered = s;
    dithered["dither"] = 1;
    if (!run(dithered, fb, fa, true)) return false;
    auto curve = [](const std::vector<int>& v) { return std::vector<double>(v.begin(), v.end()); };
    std::vector<double> unrounded(static_cast<size_t>(frames));
    for (int f = 0; f < frames; ++f) unrounded[size_t(f)] = target * (1 - std::pow(1 - a, f + 1));
    item.series = {{"published (8-bit blend)", curve(plainBelow)},
                   {"dither=temporal", curve(lb)},
                   {"exact a·L + (1 − a)·A", unrounded}};
    item.seriesUnit = "adapted amount A (levels) per frame, from black towards L = " + std::to_string(target);

    // GLARE.md §7: with round-to-nearest the step a·(L − A) is lost once under half a level, so the
    // smoothing stops 0.5/a levels away, from either side; the card holds a as round(255a)/255.
    const double aCard = std::nearbyint(a * 255) / 255;
    item.name = "smoothing_dead_band";
    item.unit = "levels short of the target L (from below: L − A; from above: A − L)";
    item.setup = "adaptive, smoothing " + std::to_string(a).substr(0, 5) + " (the card holds " +
                 std::to_string(int(std::nearbyint(a * 255))) + "/255), uniform grey 0.35 (L = " + std::to_string(target) +
                 "), 16x16, " + std::to_string(frames) + " frames from black and from a converged white";
    const std::vector<int> pb = predictSmoothingLevels(a, target, 0, frames),
                           pa = predictSmoothingLevels(a, target, 255, frames - 1);
    item.predicted = {{"from_below", 0.5 / aCard},
                      {"from_above", 0.5 / aCard},
                      {"from_below_recurrence", double(target - pb.back())},
                      {"from_above_recurrence", double(pa.back() - target)}};
    item.measured = {{"from_below", mb}, {"from_above", ma}};
    item.fix = "dither=temporal: adaptive_amount_dither.psh adds a per-frame offset over ±0.5/a levels before the "
               "blend (mean |A − L| over the last 200 frames)";
    item.measuredWithFix = {{"from_below", std::fabs(fb)}, {"from_above", std::fabs(fa)}};
    item.note = "0.5/a = " + std::to_string(0.5 / a).substr(0, 5) + " levels at a = 0.025 itself; the stop is the last "
                "whole level inside 0.5/a' (ties to even)";
    return true;
}

// --- blur_energy_drift ----------------------------------------------------------------------

double predictPinwheelEnergy(int passes, bool truncate, int side) {
    auto q = [&](double x) { return truncate ? std::floor(x + 1e-9) : std::nearbyint(x); };
    std::vector<double> img(size_t(side) * side, 0.0);
    img[size_t(side / 2) * side + size_t(side / 2)] = 255;
    const double w = std::nearbyint(0.25 * 255);  // c0 = 0.25 on the grid: 64/255
    auto at = [&](int x, int y) {
        x = std::clamp(x, 0, side - 1);
        y = std::clamp(y, 0, side - 1);
        return img[size_t(y) * side + size_t(x)];
    };
    // A bilinear tap at texel-space (x, y), texel centres at integers: 8-bit sub-texel weights,
    // the weighted sum exact, then one rounding to a level.
    auto tap = [&](double x, double y) {
        const double x0 = std::floor(x), y0 = std::floor(y);
        const double fx = std::nearbyint((x - x0) * 256), fy = std::nearbyint((y - y0) * 256);
        const int i = int(x0), j = int(y0);
        const double s = at(i, j) * (256 - fx) * (256 - fy) + at(i + 1, j) * fx * (256 - fy) +
                         at(i, j + 1) * (256 - fx) * fy + at(i + 1, j + 1) * fx * fy;
        return q(s / 65536.0);
    };
    const double before = 255;
    for (int k = 0; k < passes; ++k) {
        const double s = 0.5 * k + 0.5, l = k + 0.5;
        const double off[4][2] = {{+s, +l}, {-l, +s}, {-s, -l}, {+l, -s}};
        std::vector<double> next(img.size());
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                double r = 0;
                for (int t = 0; t < 4; ++t) r = q(tap(x + off[t][0], y + off[t][1]) * w / 255 + r);
                next[size_t(y) * side + size_t(x)] = std::clamp(r, 0.0, 255.0);
            }
        img = std::move(next);
    }
    return std::accumulate(img.begin(), img.end(), 0.0) / before;
}

namespace {

// The red levels of the adaptive bright pass and last blur pass for one white pixel at (x, y),
// threshold 0 (so the bright pass keeps it whole: b·min(4b, 1) = 1) and A held at 0.
bool adaptiveImpulse(const StressOptions& o, uint32_t side, uint32_t x, uint32_t y, const Settings& extra,
                     std::vector<int>& bright, std::vector<int>& blurred, std::string& error) {
    Runner run(stressRunnerOptions(o, side, side));
    emu::FloatImage img = uniformImage(side, side, 0);
    setPixel(img, x, y, 1);
    if (!run.setImage(img, error)) return false;
    Settings s = published("adaptive");
    s["threshold"] = 0;
    s["start"] = 1;
    s["smoothing"] = 0;
    for (const auto& [k, v] : extra) s[k] = v;
    const int passes = int(s.at("blur_passes"));
    std::vector<std::vector<int>> read;
    if (!runAndRead(run, *findTechnique("adaptive"), s, 0, 1, {"bright_pass", "blur_" + std::to_string(passes - 1)},
                    read, error))
        return false;
    bright = read[0];
    blurred = read[1];
    return true;
}

}  // namespace

bool stressCapturedOffset(const StressOptions& o, uint32_t& cx, uint32_t& cy, std::string& error) {
    const uint32_t side = 64;
    for (uint32_t oy = 0; oy < 8; ++oy)
        for (uint32_t ox = 0; ox < 8; ++ox) {
            std::vector<int> bright, blurred;
            if (!adaptiveImpulse(o, side, 24 + ox, 24 + oy, {{"blur_passes", 1}}, bright, blurred, error)) return false;
            if (sum(bright) > 0) {
                cx = ox;
                cy = oy;
                return true;
            }
        }
    error = "the adaptive bright pass read none of the 64 pixels of an 8x8 cell";
    return false;
}

bool stressBlurEnergyDrift(const StressOptions& o, StressItem& item, std::string& error) {
    uint32_t cx = 0, cy = 0;
    if (!stressCapturedOffset(o, cx, cy, error)) return false;
    const uint32_t side = 256, cell = side / 2 / 8 * 8;  // the bright target is 32x32: its centre texel
    std::vector<int> bright, blurred, brightFix, blurredFix;
    if (!adaptiveImpulse(o, side, cell + cx, cell + cy, {}, bright, blurred, error) ||
        !adaptiveImpulse(o, side, cell + cx, cell + cy, {{"blur_sum", 1}}, brightFix, blurredFix, error))
        return false;
    if (sum(bright) == 0 || sum(brightFix) == 0) {
        error = "blur_energy_drift: the bright pass missed the white texel";
        return false;
    }
    item.name = "blur_energy_drift";
    item.unit = "energy after / before Sousa's 5-pass blur of one saturated texel";
    item.setup = "adaptive (threshold 0, A = 0), one white pixel of a 256x256 scene: one texel of 255 in the 32x32 "
                 "bright target, blur_0 … blur_4";
    item.predicted = {{"rounding", predictPinwheelEnergy(5, false)}, {"truncation", predictPinwheelEnergy(5, true)}};
    item.measured = {{"rounding", double(sum(blurred)) / double(sum(bright))}};
    item.fix = "blur_sum=halving: blur4_halve.psh sums the taps by add_d2 (weights exactly 1/4; blur4's 0.25 is "
               "64/255 on the grid)";
    item.measuredWithFix = {{"rounding", double(sum(blurredFix)) / double(sum(brightFix))}};
    item.note = "GLARE.md §7: +5 % with rounding, 0 with truncation; the emulated card rounds to nearest (docs/precision.md), "
                "so truncation is predicted only";
    return true;
}

// --- weight sums ----------------------------------------------------------------------------

std::vector<std::pair<std::string, std::vector<double>>> stressKernels() {
    return {{"pyramid_5_6_5", {5.0 / 16, 6.0 / 16, 5.0 / 16}}, {"glow_published", glowKernel(published("glow"))}};
}

bool stressWeightSumRounded(const StressOptions& o, StressItem& item, std::string& error) {
    item = {};
    item.name = "weight_sum_rounded";
    item.unit = "Σw of a normalised 1D kernel as the card holds it (1 = exact)";
    item.setup = "weighted4.psh passes (4 point taps, added ONE/ONE), the impulse response of a 255 texel summed, 64x4";
    item.fix = "error diffusion: quantiseWeights (glare/passes.h) carries each rounding remainder into the next "
               "weight; the pyramid and the glow use it";
    for (const auto& [name, k] : stressKernels()) {
        double rounded = 0;
        for (double w : k) rounded += std::nearbyint(w * 255);
        double measured = 0, fixed = 0;
        if (!measureWeightSum(o, k, measured, error) ||
            !measureWeightSum(o, quantiseWeights(k, ps11::Precision::Fx8), fixed, error))
            return false;
        item.predicted.push_back({name, rounded / 255});
        item.measured.push_back({name, measured});
        item.measuredWithFix.push_back({name, fixed});
    }
    item.note = "the weights go to the device as they are; constants load rounded to n/255 (docs/precision.md)";
    return true;
}

bool stressWeightSumDiffused(const StressOptions& o, StressItem& item, std::string& error) {
    item = {};
    item.name = "weight_sum_diffused";
    item.unit = "Σw of a normalised 1D kernel with error-diffused 8-bit weights (1 = exact)";
    item.setup = "as weight_sum_rounded, weights from quantiseWeights";
    item.fix = "none needed: error diffusion is itself the fix of weight_sum_rounded";
    for (const auto& [name, k] : stressKernels()) {
        const double real = std::accumulate(k.begin(), k.end(), 0.0);
        double measured = 0;
        if (!measureWeightSum(o, quantiseWeights(k, ps11::Precision::Fx8), measured, error)) return false;
        item.predicted.push_back({name, std::nearbyint(real * 255) / 255});
        item.measured.push_back({name, measured});
    }
    return true;
}

// --- feedback_residue -----------------------------------------------------------------------

namespace {

// The glow with an after-image (afterimage = 1 source, 2 feedback) and decay k: a uniform source
// of `level` for `on` frames, then black for `off` frames; the glow buffer's centre level after
// each frame.
bool glowHistory(const StressOptions& o, int afterimage, double k, int radius, int level, int on, int off,
                 std::vector<int>& glow, std::string& error) {
    const uint32_t n = 32;
    Runner run(stressRunnerOptions(o, n, n));
    Settings s = published("glow");
    s["radius"] = radius;
    s["afterimage"] = afterimage;
    s["decay"] = k;
    const emu::FloatImage lit = uniformImage(n, n, float(level) / 255), dark = uniformImage(n, n, 0);
    glow.clear();
    // The glow texture after its last vertical pass (the passes add into it, ONE/ONE).
    const std::string last = "blur_v_" + std::to_string((glowKernel(s).size() + 3) / 4 - 1);
    for (int f = 0; f < on + off; ++f) {
        if (f == 0 || f == on)
            if (!run.setImage(f < on ? lit : dark, error)) return false;
        std::vector<std::vector<int>> read;
        if (!runAndRead(run, *findTechnique("glow"), s, f, on + off, {last}, read, error)) return false;
        if (read[0].empty()) {
            error = "glow: no pass " + last;
            return false;
        }
        glow.push_back(read[0][read[0].size() / 2 + 4]);  // a texel in the middle of the 8x8 buffer
    }
    return true;
}

// The smallest constant source level whose glow saturates (255) within `frames` frames, searched over [lo, hi].
bool saturationLevel(const StressOptions& o, int afterimage, double k, int radius, int lo, int hi, int frames, int& level,
                     std::string& error) {
    auto saturates = [&](int s, bool& yes) {
        std::vector<int> g;
        if (!glowHistory(o, afterimage, k, radius, s, frames, 0, g, error)) return false;
        yes = g.back() >= 255;
        return true;
    };
    bool yes = false;
    if (!saturates(hi, yes)) return false;
    if (!yes) {
        level = hi + 1;  // beyond the range searched
        return true;
    }
    while (lo < hi) {
        const int mid = (lo + hi) / 2;
        if (!saturates(mid, yes)) return false;
        if (yes)
            hi = mid;
        else
            lo = mid + 1;
    }
    level = lo;
    return true;
}

}  // namespace

bool stressFeedbackResidue(const StressOptions& o, StressItem& item, std::string& error) {
    const double k = 0.9;
    // The loop y ← Q(s + k·y) with the narrowest kernel (radius 1: 3 taps, weights near 1/3): wider
    // kernels round each tap's small share of a residue away inside the loop (the published
    // radius is measured beside it).
    const int radius = 1, publishedRadius = int(published("glow").at("radius"));
    Settings loop = published("glow");
    loop["afterimage"] = 2;
    loop["decay"] = k;
    loop["radius"] = radius;
    std::vector<int> fb, src, wide;
    if (!glowHistory(o, 2, k, radius, 26, 60, 120, fb, error) || !glowHistory(o, 1, k, radius, 26, 60, 120, src, error) ||
        !glowHistory(o, 2, k, publishedRadius, 26, 60, 120, wide, error))
        return false;
    int satFb = 0, satSrc = 0;
    if (!saturationLevel(o, 2, k, radius, 1, 80, 80, satFb, error) ||
        !saturationLevel(o, 1, k, radius, 1, 255, 8, satSrc, error))
        return false;
    item.name = "feedback_residue";
    item.unit = "residue: glow levels left 120 frames after the source goes black; saturates_above: the smallest "
                "constant source (levels) whose glow reaches white";
    item.setup = "glow, radius 1 (3 taps), afterimage=feedback, decay k = 0.9, uniform source (alpha 1) of 26 levels "
                 "for 60 frames then black, 32x32 (glow buffer 8x8), centre texel";
    // The formula's residue, and the loop's own (its blur's roundings included), predicted from
    // the measured level of the last lit frame.
    item.predicted = {{"residue", std::floor(0.5 / (1 - k))},
                      {"saturates_above", 255 * (1 - k)},
                      {"residue_loop", double(predictFeedbackLevels(loop, fb.at(59), 120).back())}};
    item.measured = {{"residue", double(fb.back())},
                     {"saturates_above", double(satFb)},
                     {"residue_radius_" + std::to_string(publishedRadius), double(wide.back())}};
    item.fix = "afterimage=source: the chapter's other after-image, the previous frame's sources dimmed by k and added "
               "once (no loop)";
    item.measuredWithFix = {{"residue", double(src.back())}, {"saturates_above", double(satSrc)}};
    auto curve = [](const std::vector<int>& v) { return std::vector<double>(v.begin(), v.end()); };
    std::vector<double> unrounded(fb.size());
    for (size_t f = 0; f < fb.size(); ++f)
        unrounded[f] = f < 60 ? double(fb[f]) : double(fb.at(59)) * std::pow(k, double(f - 59));
    item.series = {{"afterimage=feedback, radius 1", curve(fb)},
                   {"afterimage=feedback, radius " + std::to_string(publishedRadius), curve(wide)},
                   {"afterimage=source (fix)", curve(src)},
                   {"exact decay k^n", unrounded}};
    item.seriesUnit = "glow level at the centre per frame (source lit for 60 frames, then black)";
    item.note = "the card holds k as " + std::to_string(int(std::nearbyint(k * 255))) +
                "/255; the blur's roundings also act inside the loop; the fix's saturation is 255/(1 + k) = " +
                std::to_string(255 / (1 + k)).substr(0, 5) + " predicted";
    return true;
}

// --- decimation_capture ---------------------------------------------------------------------

bool stressDecimationCapture(const StressOptions& o, StressItem& item, std::string& error) {
    // One white pixel at each of the 64 positions of an 8x8 cell in the middle of a 256x256 scene,
    // published adaptive (A held at 0): how many positions the W/d point-sampled bright pass sees,
    // and the spread of the total glare energy (output − scene) over the positions.
    const uint32_t side = 256, cell = side / 2;
    std::vector<double> cells;  // the last sweep's energy per position, relative to its largest
    auto sweep = [&](int divisor, double& share, double& flicker) {
        Runner run(stressRunnerOptions(o, side, side));
        Settings s = published("adaptive");
        s["start"] = 1;
        s["smoothing"] = 0;
        s["divisor"] = divisor;
        std::vector<double> energy;
        int seen = 0;
        for (uint32_t oy = 0; oy < 8; ++oy)
            for (uint32_t ox = 0; ox < 8; ++ox) {
                emu::FloatImage img = uniformImage(side, side, 0);
                setPixel(img, cell + ox, cell + oy, 1);
                std::vector<std::vector<int>> read;
                std::vector<int> out;
                if (!run.setImage(img, error) ||
                    !runAndRead(run, *findTechnique("adaptive"), s, 0, 1, {"bright_pass"}, read, error) ||
                    !redLevels(run, run.outputTexture(), out, error))
                    return false;
                if (sum(read[0]) > 0) ++seen;
                out[size_t(cell + oy) * side + cell + ox] -= 255;  // the scene's own pixel
                energy.push_back(double(sum(out)));
            }
        share = seen / 64.0;
        const double top = *std::max_element(energy.begin(), energy.end());
        cells.clear();
        for (double e : energy) cells.push_back(top > 0 ? e / top : 0);
        const double mean = std::accumulate(energy.begin(), energy.end(), 0.0) / double(energy.size());
        flicker = mean > 0 ? (*std::max_element(energy.begin(), energy.end()) -
                              *std::min_element(energy.begin(), energy.end())) / mean
                           : NAN;
        return true;
    };
    double share = 0, flicker = 0, shareFix = 0, flickerFix = 0;
    if (!sweep(8, share, flicker)) return false;
    const std::vector<double> published8 = cells;
    if (!sweep(2, shareFix, flickerFix)) return false;
    item.series = {{"divisor 8 (published)", published8}, {"divisor 2 (fix)", cells}};
    item.seriesUnit = "8x8 grid: the glare energy of a 1-pixel source at each position of a cell, relative to the "
                      "largest";
    item.name = "decimation_capture";
    item.unit = "share: positions of a 1-pixel source the bright pass sees; flicker: (max − min)/mean of the glare "
                "energy over the positions";
    item.setup = "adaptive published (divisor 8, A = 0), one white pixel at each of the 64 positions of an 8x8 cell, "
                 "256x256";
    item.predicted = {{"share", 1.0 / 64}, {"flicker", 64}};
    item.measured = {{"share", share}, {"flicker", flicker}};
    item.fix = "divisor=2: an existing setting (16x the bright-pass pixels); predicted share 1/4, flicker 4";
    item.measuredWithFix = {{"share", shareFix}, {"flicker", flickerFix}};
    item.note = "a point sample reads 1 of d² pixels; captured, the source gives all its glare, missed, none: "
                "(max − min)/mean = d²";
    return true;
}

// --- the whole suite ------------------------------------------------------------------------

bool StressReport::robust() const {
    return std::all_of(robustness.begin(), robustness.end(), [](const RobustnessCheck& c) { return c.pass; });
}

bool runStress(const StressOptions& o, StressReport& report, std::string& error) {
    report = {};
    report.hardware = std::string((o.hardware ? *o.hardware : ps11::defaultHardware(1)).name);
    using Fn = bool (*)(const StressOptions&, StressItem&, std::string&);
    for (Fn f : {stressSmoothingDeadBand, stressBlurEnergyDrift, stressWeightSumRounded, stressWeightSumDiffused,
                 stressFeedbackResidue, stressDecimationCapture}) {
        StressItem item;
        if (!f(o, item, error)) return false;
        report.items.push_back(std::move(item));
    }
    for (const Technique* t : techniques()) {
        TechniqueMetrics m;
        if (!stressMetrics(o, *t, m, error)) return false;
        report.metrics.push_back(m);
    }
    return stressRobustness(o, report.robustness, error);
}

}  // namespace glare
