// The intended math of the pyramid and the glow (glare/intended.h, docs/bench.md "Intended math"):
// float images on the CPU, separable convolutions with clamped edges; the reference `ps11 bench`
// measures how far a technique's shortcuts (small buffers, few taps, 8-bit passes) land from.
#include "glare/intended.h"

#include <algorithm>
#include <cmath>

#include "glare/glow.h"

namespace glare {

namespace {

constexpr double kPi = 3.14159265358979323846;

// One row or column: out[i] = Σ_k kernel[k]·in[clamp(i + k − r)], over `n` values `stride` apart.
void convolveLine(const float* in, float* out, size_t n, size_t stride, const std::vector<double>& kernel) {
    const int r = int(kernel.size() / 2);
    for (size_t i = 0; i < n; ++i) {
        double sum = 0;
        for (int k = -r; k <= r; ++k) {
            const long j = std::clamp(long(i) + k, 0L, long(n) - 1);
            sum += kernel[size_t(k + r)] * in[size_t(j) * stride];
        }
        out[i * stride] = float(sum);
    }
}

// Area resampling of one axis: destination texel i covers source [i·n/m, (i+1)·n/m), each source
// pixel weighted by how much of it falls inside.
std::vector<std::vector<std::pair<uint32_t, double>>> areaWeights(uint32_t n, uint32_t m) {
    std::vector<std::vector<std::pair<uint32_t, double>>> w(m);
    const double scale = double(n) / double(m);
    for (uint32_t i = 0; i < m; ++i) {
        const double a = i * scale, b = (i + 1) * scale;
        for (uint32_t s = uint32_t(std::floor(a)); s < n && double(s) < b; ++s) {
            const double cover = std::min(b, double(s + 1)) - std::max(a, double(s));
            if (cover > 0) w[i].push_back({s, cover / scale});
        }
    }
    return w;
}

emu::FloatImage areaResize(const emu::FloatImage& in, uint32_t w, uint32_t h) {
    const auto wx = areaWeights(in.width, w), wy = areaWeights(in.height, h);
    emu::FloatImage rows;  // in.height x w
    rows.width = w, rows.height = in.height;
    rows.rgba.assign(size_t(w) * in.height * 4, 0.0f);
    for (uint32_t y = 0; y < in.height; ++y)
        for (uint32_t x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c) {
                double sum = 0;
                for (const auto& [s, f] : wx[x]) sum += f * in.rgba[(size_t(y) * in.width + s) * 4 + c];
                rows.rgba[(size_t(y) * w + x) * 4 + c] = float(sum);
            }
    emu::FloatImage out;
    out.width = w, out.height = h;
    out.rgba.assign(size_t(w) * h * 4, 0.0f);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c) {
                double sum = 0;
                for (const auto& [s, f] : wy[y]) sum += f * rows.rgba[(size_t(s) * w + x) * 4 + c];
                out.rgba[(size_t(y) * w + x) * 4 + c] = float(sum);
            }
    return out;
}

// Bilinear sample of `img` (RGB) at texel-space (u, v) with texel centres at integers, clamped.
void bilinear(const emu::FloatImage& img, double u, double v, float rgb[3]) {
    u = std::clamp(u, 0.0, double(img.width - 1));
    v = std::clamp(v, 0.0, double(img.height - 1));
    const uint32_t x0 = uint32_t(u), y0 = uint32_t(v);
    const uint32_t x1 = std::min(x0 + 1, img.width - 1), y1 = std::min(y0 + 1, img.height - 1);
    const double fx = u - x0, fy = v - y0;
    for (int c = 0; c < 3; ++c) {
        auto at = [&](uint32_t x, uint32_t y) { return double(img.rgba[(size_t(y) * img.width + x) * 4 + c]); };
        rgb[c] = float((1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1)));
    }
}

// The frame: input + `bloom` (RGB, bilinearly stretched over the frame when smaller) × strength,
// clamped to [0, 1] as the 8-bit output clamps it; alpha 1.
emu::FloatImage addToScene(const emu::FloatImage& input, const emu::FloatImage& bloom, double strength) {
    emu::FloatImage out = input;
    const bool same = bloom.width == input.width && bloom.height == input.height;
    for (uint32_t y = 0; y < input.height; ++y)
        for (uint32_t x = 0; x < input.width; ++x) {
            float g[3];
            if (same) {
                for (int c = 0; c < 3; ++c) g[c] = bloom.rgba[(size_t(y) * input.width + x) * 4 + c];
            } else {
                // D3D's mapping of a stretched texture: pixel centre x + ½ over the frame.
                bilinear(bloom, (x + 0.5) * bloom.width / input.width - 0.5, (y + 0.5) * bloom.height / input.height - 0.5, g);
            }
            float* p = &out.rgba[(size_t(y) * input.width + x) * 4];
            for (int c = 0; c < 3; ++c) p[c] = std::clamp(float(p[c] + strength * g[c]), 0.0f, 1.0f);
            p[3] = 1.0f;
        }
    return out;
}

// GLARE.md §3: the bright pass saturate(c − t)/(1 − t) of the scene at size x size (an area
// average), and the sum of true Gaussians of 5, 11, 21 and 41 taps (radius 2, 5, 10, 20 texels of
// that square; σ = 1, 2, 4, 8: the [1 4 6 4 1]/16 binomial has σ = 1, and each level is half the
// size of the one before), each weighted 1 (`plain`) or ¼ (`normalised`), stretched over the frame
// and added with `strength`.
emu::FloatImage pyramidIntended(const Settings& s, const emu::FloatImage& input) {
    const uint32_t size = uint32_t(s.at("size"));
    const double t = s.at("threshold"), weight = s.at("sum") == 0 ? 1.0 : 0.25;
    emu::FloatImage bright = areaResize(input, size, size);
    for (size_t i = 0; i < bright.rgba.size(); i += 4)
        for (int c = 0; c < 3; ++c) bright.rgba[i + c] = float(std::clamp(bright.rgba[i + c] - t, 0.0, 1.0) / (1.0 - t));
    emu::FloatImage sum = bright;
    std::fill(sum.rgba.begin(), sum.rgba.end(), 0.0f);
    const int radius[4] = {2, 5, 10, 20};
    for (int n = 0; n < 4; ++n) {
        emu::FloatImage level = bright;
        convolveRgb(level, gaussianKernel(double(1 << n), radius[n]));
        for (size_t i = 0; i < sum.rgba.size(); ++i) sum.rgba[i] += float(weight * level.rgba[i]);
    }
    return addToScene(input, sum, s.at("strength"));
}

// GLARE.md §2, docs/glare/glow.md: the glow sources RGB × alpha at full resolution, convolved
// with the 1D profile stretched by the divisor (the buffer's texel is `divisor` pixels wide: σ,
// radius and period in pixels are the setting × divisor), added with the frame's strength (the
// ramp) and, for the `source` after-image from the second frame on, the previous frame's sources
// × decay (a still input: the same sources).
std::optional<emu::FloatImage> glowIntended(const Settings& s, const emu::FloatImage& input, int frame, std::string& why) {
    const int after = int(s.at("afterimage"));
    if (after == 2) {
        why = "the glow's after-image `feedback` has no stated intended result";
        return std::nullopt;
    }
    const double d = s.at("divisor");
    Settings wide = s;
    for (const char* k : {"radius", "sigma_broad", "sigma_narrow", "period"}) wide[k] = s.at(k) * d;
    const std::vector<double> kernel = glowKernel(wide);
    emu::FloatImage glow = input;
    const double sources = after == 1 && frame > 0 ? 1.0 + s.at("decay") : 1.0;
    for (size_t i = 0; i < glow.rgba.size(); i += 4)
        for (int c = 0; c < 3; ++c) glow.rgba[i + c] = float(sources * glow.rgba[i + c] * glow.rgba[i + 3]);
    convolveRgb(glow, kernel);
    const double ramp = s.at("ramp"), period = s.at("ramp_period");
    const double strength = s.at("strength") * (1 - ramp + ramp * 0.5 * (1 + std::cos(2 * kPi * frame / period)));
    return addToScene(input, glow, strength);
}

}  // namespace

std::vector<double> gaussianKernel(double sigma, int radius) {
    std::vector<double> k;
    double sum = 0;
    for (int x = -radius; x <= radius; ++x) {
        k.push_back(std::exp(-double(x) * x / (2 * sigma * sigma)));
        sum += k.back();
    }
    for (double& v : k) v /= sum;
    return k;
}

void convolveRgb(emu::FloatImage& image, const std::vector<double>& kernel) {
    const uint32_t w = image.width, h = image.height;
    std::vector<float> line(std::max(w, h)), out(std::max(w, h));
    for (int c = 0; c < 3; ++c) {
        for (uint32_t y = 0; y < h; ++y) {
            float* row = &image.rgba[size_t(y) * w * 4 + c];
            for (uint32_t x = 0; x < w; ++x) line[x] = row[size_t(x) * 4];
            convolveLine(line.data(), out.data(), w, 1, kernel);
            for (uint32_t x = 0; x < w; ++x) row[size_t(x) * 4] = out[x];
        }
        for (uint32_t x = 0; x < w; ++x) {
            float* col = &image.rgba[size_t(x) * 4 + c];
            for (uint32_t y = 0; y < h; ++y) line[y] = col[size_t(y) * w * 4];
            convolveLine(line.data(), out.data(), h, 1, kernel);
            for (uint32_t y = 0; y < h; ++y) col[size_t(y) * w * 4] = out[y];
        }
    }
}

std::optional<emu::FloatImage> intendedResult(const Technique& t, const Settings& settings, const emu::FloatImage& input,
                                              int frame, std::string& why) {
    if (t.name() == "pyramid") return pyramidIntended(settings, input);
    if (t.name() == "glow") return glowIntended(settings, input, frame, why);
    why = "technique " + std::string(t.name()) + " states no math it approximates";
    return std::nullopt;
}

}  // namespace glare
