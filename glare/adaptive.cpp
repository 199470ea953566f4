// Adaptive glare (Tiago Sousa, ShaderX3 4.2, CryEngine / Far Cry): GLARE.md §1,
// docs/glare/adaptive.md.
#include <algorithm>
#include <cmath>

#include "glare/adaptive.h"
#include "glare/passes.h"
#include "glare/runner.h"

namespace glare {
namespace {

class Adaptive final : public Technique {
public:
    std::string_view name() const override { return "adaptive"; }
    std::string_view title() const override { return "Adaptive glare (Sousa, ShaderX3 4.2)"; }
    std::string_view scene() const override { return "box"; }
    std::string_view summary() const override {
        return "eye-adapted glare amount, W/8 point-sampled bright pass, 5-pass pinwheel blur, screen composite";
    }
    const std::vector<ParamInfo>& params() const override {
        static const std::vector<ParamInfo> p = {
            {"luminance", "", "scene luminance: 128x128 and its mip chain down to 2x2, or StretchRect straight to 2x2",
             0, 1, {1, 0, 0, 0}, {"mip", "plain"}, false},
            {"threshold", "", "bright-pass threshold on [0,1] colour", 0, 1, {0.4, 0.4, 0.4, 0.4}, {}, false},
            {"glare_amount", "", "w, the largest glare amount", 0, 1, {1, 1, 1, 1}, {}, false},
            {"smoothing", "per frame", "alpha of the temporal smoothing blend (A = a·L + (1 − a)·A)", 0, 1,
             {0.025, 0.025, 0.025, 0.025}, {}, false},
            {"start", "", "the adapted amount before the first frame: converged (frame 0 is not blended) or black",
             0, 1, {0, 0, 0, 0}, {"converged", "black"}, false},
            {"divisor", "", "the bright pass is (W/divisor) x (H/divisor)", 2, 32, {16, 8, 4, 8}, {}, true},
            {"blur_passes", "", "pinwheel blur passes (pass k: taps at (±(0.5k + 0.5), ±(k + 0.5)) texels)", 0, 5, {3, 4, 5, 5},
             {}, true},
            {"composite", "", "screen S+G(1-S), add S+G, or luminance lerp(S+G, S, lum S)", 0, 2, {0, 0, 0, 0},
             {"screen", "add", "luminance"}, false},
            {"dither", "", "off, or temporal: a per-frame offset over ±0.5/smoothing levels added before the smoothing "
             "blend, so the 8-bit adaptation reaches its target (docs/stress.md)",
             0, 1, {0, 0, 0, 0}, {"off", "temporal"}, false},
            {"square", "", "the glare amount's square: as the shipped sample (Cg 1.2's mov_x4 then mul, "
             "avg·min(4·avg, 1) on the card) or mul_x4 (min(4·avg², 1), glare gone from avg 0.5; docs/glare/adaptive.md)",
             0, 1, {0, 0, 0, 0}, {"sample", "mul_x4"}, false},
            {"blur_sum", "", "the blur's four taps summed with mad by 0.25 (64/255 on the 8-bit grid, as published) or "
             "by halving adds (exactly 1/4 each, docs/stress.md)",
             0, 1, {0, 0, 0, 0}, {"mad", "halving"}, false},
        };
        return p;
    }

    void build(FrameBuild& fb) const override {
        PassGraph& g = fb.graph;
        const TextureDesc sd = fb.sceneDesc();
        const D3DFORMAT f = fb.format;

        // Luminance: 128x128 and its chain down to 2x2 (each level a bilinear 2:1 StretchRect,
        // i.e. a 2x2 box), or the scene straight to 2x2.
        TextureId lum = fb.scene;
        for (uint32_t size = fb.choice("luminance") == 0 ? 128 : 2; size >= 2; size /= 2) {
            const TextureId next = g.create("luminance " + std::to_string(size), {size, size, f});
            addStretchPass(fb, "luminance_" + std::to_string(size), lum, next, D3DTEXF_LINEAR);
            lum = next;
        }

        // The glare amount, smoothed over frames in a 1x1 target by alpha blending.
        const TextureId adapted = fb.persistent("adapted glare amount", {1, 1, f}, 0);
        const bool blend = !(fb.firstFrame() && fb.choice("start") == 0);
        const float a = float(fb.get("smoothing"));
        const bool dither = fb.choice("dither") == 1;
        const bool mulx4 = fb.choice("square") == 1;
        QuadPass amount{std::string("adaptive_amount") + (dither ? "_dither" : "") + (mulx4 ? "_mulx4" : "") + ".psh",
                        adapted,
                        {pointTap(lum, 0.25f, 0.25f), pointTap(lum, 0.75f, 0.25f), pointTap(lum, 0.25f, 0.75f),
                         pointTap(lum, 0.75f, 0.75f)},
                        {{2, {0, 0, 0, a}}},
                        blend ? Blend::Alpha : Blend::None};
        if (dither) {
            const float d = blend ? float(adaptationDither(fb.frame(), a)) : 0.0f;
            amount.constants.push_back({3, {d, d, d, 0}});
        }
        addQuadPass(fb, "glare_amount",
                    std::string(mulx4 ? "min(4·avg², 1)" : "avg·min(4·avg, 1)") +
                        (blend ? " of the 2x2 luminance → luminance, blended into 1x1 with alpha = smoothing"
                               : " of the 2x2 luminance → luminance, written (the converged start)") +
                        (dither ? ", plus this frame's dither offset" : ""),
                    amount);

        // The bright pass: W/d x H/d, point-sampling the scene.
        const uint32_t d = uint32_t(fb.get("divisor"));
        const TextureDesc bd{std::max(sd.width / d, 1u), std::max(sd.height / d, 1u), f};
        const TextureId bright = g.create("bright", bd);
        const float t = float(fb.get("threshold")), w = float(fb.get("glare_amount"));
        addQuadPass(fb, "bright_pass", "saturate(c − threshold)·w, b·min(4b,1), ·(1 − A)",
                    QuadPass{"adaptive_bright.psh",
                             bright,
                             {texelTap(fb, fb.scene, 0, 0, D3DTEXF_POINT), pointTap(adapted, 0.5f, 0.5f)},
                             {{0, {t, t, t, 0}}, {1, {w, w, w, 1}}}});

        // The pinwheel blur: pass k samples at (±(0.5k+0.5), ±(k+0.5)) texels, rotating.
        TextureId src = bright;
        const int passes = int(fb.get("blur_passes"));
        for (int k = 0; k < passes; ++k) {
            const TextureId dst = g.create("blur " + std::to_string(k), bd);
            const float s = 0.5f * float(k) + 0.5f, l = float(k) + 0.5f;
            addQuadPass(fb, "blur_" + std::to_string(k),
                        "4 bilinear taps, weight 0.25, at (±" + std::to_string(s).substr(0, 4) + ", ±" +
                            std::to_string(l).substr(0, 4) + ") texels, rotating",
                        QuadPass{fb.choice("blur_sum") == 1 ? "blur4_halve.psh" : "blur4.psh",
                                 dst,
                                 {texelTap(fb, src, +s, +l), texelTap(fb, src, -l, +s), texelTap(fb, src, -s, -l),
                                  texelTap(fb, src, +l, -s)}});
            src = dst;
        }

        static const char* composites[] = {"composite_screen.psh", "composite_add.psh", "composite_luminance.psh"};
        addQuadPass(fb, "composite", "scene + glare (bilinear upsample)",
                    QuadPass{composites[fb.choice("composite")],
                             fb.output,
                             {texelTap(fb, fb.scene, 0, 0, D3DTEXF_POINT), texelTap(fb, src, 0, 0)}});
    }
};

}  // namespace

double adaptationDither(int frame, double smoothing) {
    // The 8-bit step a·(L + d − A) rounds once: d spread evenly over one level of the step
    // (±0.5/a levels of the output) makes its rounding right on average. The offsets follow the
    // golden-ratio sequence (evenly spread over any run of frames) and sit on the grid.
    if (smoothing <= 0) return 0;
    const double a8 = std::max(1.0, std::nearbyint(smoothing * 255));  // the constant as the card holds it
    const double span = 255.0 / a8;                                     // levels of output per level of step
    const double u = std::fmod(double(frame) * 0.6180339887498949, 1.0) - 0.5;
    return std::clamp(std::nearbyint(u * span), -255.0, 255.0) / 255.0;
}

const Technique& adaptiveTechnique() {
    static const Adaptive t;
    return t;
}

}  // namespace glare
