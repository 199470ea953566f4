// Pyramid bloom (Sylphis3D, Kalogirou 2006): GLARE.md §3, docs/glare/pyramid.md.
#include <algorithm>

#include "glare/passes.h"
#include "glare/runner.h"

namespace glare {
namespace {

class Pyramid final : public Technique {
public:
    std::string_view name() const override { return "pyramid"; }
    std::string_view title() const override { return "Pyramid bloom (Sylphis3D, Kalogirou 2006)"; }
    std::string_view scene() const override { return "sky"; }
    std::string_view summary() const override {
        return "bright pass at 128, 128→64→32→16, 5x5 Gaussian per level, four levels summed in one pass";
    }
    const std::vector<ParamInfo>& params() const override {
        static const std::vector<ParamInfo> p = {
            {"size", "texels", "the top level is size x size (then /2, /4, /8)", 32, 512, {64, 128, 256, 128}, {}, true},
            {"threshold", "", "bright pass: (c − t)/(1 − t), saturated; t <= 0.75 (the scale 1/(1 − t) must fit 4·c1)",
             0, 0.75, {0.6, 0.6, 0.6, 0.6}, {}, false},
            {"sum", "", "plain (DC gain 4, as published) or energy-normalised (each level 1/4)", 0, 1, {0, 0, 1, 0},
             {"plain", "normalised"}, false},
            {"strength", "", "scale of the bloom added to the scene", 0, 1, {1, 1, 1, 1}, {}, false},
        };
        return p;
    }

    void build(FrameBuild& fb) const override {
        PassGraph& g = fb.graph;
        const uint32_t top = uint32_t(fb.get("size"));
        const TextureId scaled = g.create("scene " + std::to_string(top), {top, top, fb.format});
        addStretchPass(fb, "downsample_" + std::to_string(top), fb.scene, scaled, D3DTEXF_LINEAR);
        const float t = float(fb.get("threshold")), s4 = float(0.25 / (1.0 - fb.get("threshold")));
        std::array<TextureId, 4> level;
        level[0] = g.create("bright " + std::to_string(top), {top, top, fb.format});
        addQuadPass(fb, "bright_pass", "saturate(c − t)·(1/(1 − t)) as mul_x4 with c1 = 1/(4(1 − t))",
                    QuadPass{"bright_threshold.psh", level[0], {texelTap(fb, scaled, 0, 0, D3DTEXF_POINT)},
                             {{0, {t, t, t, 0}}, {1, {s4, s4, s4, 1}}}});
        for (size_t i = 1; i < 4; ++i) {
            const uint32_t size = top >> i;
            level[i] = g.create("level " + std::to_string(size), {size, size, fb.format});
            addStretchPass(fb, "downsample_" + std::to_string(size), level[i - 1], level[i], D3DTEXF_LINEAR);
        }
        // The 5x5 binomial per level, separable: 3 bilinear taps per direction.
        const std::vector<double> w = quantiseWeights({5.0 / 16, 6.0 / 16, 5.0 / 16}, fb.precision);
        const std::vector<std::pair<int, std::array<float, 4>>> wc = {
            {0, {float(w[0]), float(w[0]), float(w[0]), float(w[0])}},
            {1, {float(w[1]), float(w[1]), float(w[1]), float(w[1])}},
            {2, {float(w[2]), float(w[2]), float(w[2]), float(w[2])}}};
        std::array<TextureId, 4> blurred;
        for (size_t i = 0; i < 4; ++i) {
            const uint32_t size = top >> i;
            const std::string n = std::to_string(size);
            const TextureId h = g.create("gauss h " + n, {size, size, fb.format});
            blurred[i] = g.create("gauss " + n, {size, size, fb.format});
            addQuadPass(fb, "gauss_h_" + n, "[1 4 6 4 1]/16 horizontally: taps at −1.2, 0, +1.2 texels",
                        QuadPass{"weighted3.psh", h,
                                 {texelTap(fb, level[i], -1.2f, 0), texelTap(fb, level[i], 0, 0),
                                  texelTap(fb, level[i], +1.2f, 0)},
                                 wc});
            addQuadPass(fb, "gauss_v_" + n, "[1 4 6 4 1]/16 vertically",
                        QuadPass{"weighted3.psh", blurred[i],
                                 {texelTap(fb, h, 0, -1.2f), texelTap(fb, h, 0, 0), texelTap(fb, h, 0, +1.2f)}, wc});
        }
        const float lw = fb.choice("sum") == 0 ? 1.0f : 0.25f;
        const TextureId bloom = g.create("bloom", {top, top, fb.format});
        addQuadPass(fb, "sum_levels", fb.choice("sum") == 0 ? "4 levels bilinear-upsampled and added (DC gain 4)"
                                                             : "4 levels bilinear-upsampled, each 1/4 (DC gain 1)",
                    QuadPass{"weighted4.psh", bloom,
                             {texelTap(fb, blurred[0], 0, 0), texelTap(fb, blurred[1], 0, 0),
                              texelTap(fb, blurred[2], 0, 0), texelTap(fb, blurred[3], 0, 0)},
                             {{0, {lw, lw, lw, lw}}, {1, {lw, lw, lw, lw}}, {2, {lw, lw, lw, lw}}, {3, {lw, lw, lw, lw}}}});
        addStretchPass(fb, "copy_scene", fb.scene, fb.output, D3DTEXF_POINT);
        const float s = float(fb.get("strength"));
        addQuadPass(fb, "composite", "additive blend (ONE, ONE) of the bilinear-upsampled bloom",
                    QuadPass{"scale.psh", fb.output, {texelTap(fb, bloom, 0, 0)}, {{0, {s, s, s, 0}}}, Blend::Add});
    }
};

}  // namespace

const Technique& pyramidTechnique() {
    static const Pyramid t;
    return t;
}

}  // namespace glare
