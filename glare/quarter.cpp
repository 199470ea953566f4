// Fullscreen glow (2009 blog post): GLARE.md §4, docs/glare/quarter.md.
#include <algorithm>

#include "glare/passes.h"
#include "glare/runner.h"

namespace glare {
namespace {

class Quarter final : public Technique {
public:
    std::string_view name() const override { return "quarter"; }
    std::string_view title() const override { return "Fullscreen glow at quarter size (2009)"; }
    std::string_view scene() const override { return "neon"; }
    std::string_view summary() const override {
        return "1/4-size copy with luminance in alpha, 3x3 Gaussian from 4 bilinear taps, additive composite";
    }
    const std::vector<ParamInfo>& params() const override {
        static const std::vector<ParamInfo> p = {
            {"divisor", "", "the glow buffer is (W/divisor) x (H/divisor); 4 in the post", 2, 8, {8, 4, 2, 4}, {}, true},
            {"blur_passes", "", "3x3 Gaussian passes ([1 2 1]⊗[1 2 1]/16 each)", 1, 4, {1, 1, 2, 1}, {}, true},
            {"composite", "", "add the blurred RGB, or only its luminance (alpha) on every channel", 0, 1,
             {0, 0, 0, 0}, {"rgb", "luminance"}, false},
            {"strength", "", "scale of the added glow", 0, 1, {1, 1, 1, 1}, {}, false},
        };
        return p;
    }

    void build(FrameBuild& fb) const override {
        PassGraph& g = fb.graph;
        const TextureDesc sd = fb.sceneDesc();
        const uint32_t d = uint32_t(fb.get("divisor"));
        const TextureDesc qd{std::max(sd.width / d, 1u), std::max(sd.height / d, 1u), fb.format};
        // Four bilinear taps at ±d/4 source texels from the block centre: each averages a 2x2,
        // together the d x d block when d = 4.
        const float o = float(d) / 4.0f;
        const TextureId small = g.create("quarter", qd);
        addQuadPass(fb, "downsample", "average of each block, luminance (0.30, 0.59, 0.11) in alpha",
                    QuadPass{"quarter_down.psh",
                             small,
                             {texelTap(fb, fb.scene, -o, -o), texelTap(fb, fb.scene, +o, -o),
                              texelTap(fb, fb.scene, -o, +o), texelTap(fb, fb.scene, +o, +o)}});
        TextureId src = small;
        for (int k = 0; k < int(fb.get("blur_passes")); ++k) {
            const TextureId dst = g.create("blurred " + std::to_string(k), qd);
            addQuadPass(fb, "gauss3x3_" + std::to_string(k), "4 bilinear taps at (±0.5, ±0.5) texels = [1 2 1]⊗[1 2 1]/16",
                        QuadPass{"blur4.psh",
                                 dst,
                                 {texelTap(fb, src, -0.5f, -0.5f), texelTap(fb, src, +0.5f, -0.5f),
                                  texelTap(fb, src, -0.5f, +0.5f), texelTap(fb, src, +0.5f, +0.5f)}});
            src = dst;
        }
        addStretchPass(fb, "copy_scene", fb.scene, fb.output, D3DTEXF_POINT);
        const float s = float(fb.get("strength"));
        addQuadPass(fb, "composite", "additive blend (ONE, ONE) of the bilinear-upsampled glow",
                    QuadPass{fb.choice("composite") == 0 ? "scale.psh" : "glow_add_luminance.psh",
                             fb.output,
                             {texelTap(fb, src, 0, 0)},
                             {{0, {s, s, s, 0}}},
                             Blend::Add});
    }
};

}  // namespace

const Technique& quarterTechnique() {
    static const Quarter t;
    return t;
}

}  // namespace glare
