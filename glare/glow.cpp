// Real-time glow (Greg James & John O'Rorke, GPU Gems ch. 21, Tron 2.0): GLARE.md §2,
// docs/glare/glow.md.
#include <algorithm>
#include <cmath>

#include "glare/glow.h"
#include "glare/passes.h"
#include "glare/runner.h"

namespace glare {

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

// The normalised 1D kernel over −radius … +radius.
std::vector<double> glowKernel(const Settings& s) {
    const int r = int(s.at("radius"));
    std::vector<double> w;
    double sum = 0;
    for (int x = -r; x <= r; ++x) {
        double v = 0;
        const double ax = std::abs(double(x));
        switch (int(s.at("profile"))) {
            case 0: {
                const double sb = s.at("sigma_broad"), sn = s.at("sigma_narrow"), m = s.at("narrow_share");
                // Each Gaussian normalised on its own, then mixed: the narrow one carries `m` of the sum.
                v = (1 - m) * std::exp(-ax * ax / (2 * sb * sb)) / (sb * std::sqrt(2 * kPi)) +
                    m * std::exp(-ax * ax / (2 * sn * sn)) / (sn * std::sqrt(2 * kPi));
                break;
            }
            case 1: {
                const double sb = s.at("sigma_broad");
                v = std::exp(-ax * ax / (2 * sb * sb));
                break;
            }
            default: {
                const double p = s.at("period");
                v = (1 - std::fmod(ax, p) / p) * (1 - ax / double(r + 1));
                break;
            }
        }
        w.push_back(v);
        sum += v;
    }
    for (double& v : w) v /= sum;
    return w;
}


namespace {

class Glow final : public Technique {
public:
    std::string_view name() const override { return "glow"; }
    std::string_view title() const override { return "Real-time glow (James & O'Rorke, GPU Gems 21)"; }
    std::string_view scene() const override { return "neon"; }
    std::string_view summary() const override {
        return "glow sources RGB×alpha at 1/4 size, separable 4-tap multipass convolution (or the D3D7 2-texture path), additive";
    }
    const std::vector<ParamInfo>& params() const override {
        static const std::vector<ParamInfo> p = {
            {"divisor", "", "glow buffer is (W/divisor) x (H/divisor): 3 or 4 in the chapter", 2, 8, {4, 4, 3, 4}, {}, true},
            {"radius", "texels", "kernel half-width in glow-buffer texels (2·radius + 1 taps per direction)", 1, 32,
             {4, 8, 12, 8}, {}, true},
            {"profile", "", "1D kernel: a broad plus a narrow Gaussian, one Gaussian, or a periodic sawtooth", 0, 2,
             {0, 0, 0, 0}, {"two_gaussians", "gaussian", "sawtooth"}, false},
            {"sigma_broad", "texels", "σ of the broad Gaussian (the smooth base)", 0.5, 32, {2.5, 4, 6, 4}, {}, false},
            {"sigma_narrow", "texels", "σ of the narrow Gaussian (the bright spike)", 0.25, 8, {1, 1, 1, 1}, {}, false},
            {"narrow_share", "", "the narrow Gaussian's share of the kernel's sum", 0, 1, {0.3, 0.3, 0.3, 0.3}, {}, false},
            {"period", "texels", "sawtooth period", 1, 16, {3, 3, 3, 3}, {}, false},
            {"path", "", "ps_1_1: 4 taps per pass, weights in constants; ffp: the D3D7 fixed-function fallback, 2 textures "
                         "per pass, weights in the vertex colour",
             0, 1, {0, 0, 0, 0}, {"ps_1_1", "ffp"}, false},
            {"afterimage", "", "off; source: the previous frame's glow sources, dimmed, added to this frame's; feedback: the "
                               "previous blurred glow added (can bleed to white)",
             0, 2, {0, 0, 0, 0}, {"off", "source", "feedback"}, false},
            {"decay", "", "k, the after-image's dimming per frame", 0, 1, {0.6, 0.6, 0.6, 0.6}, {}, false},
            {"strength", "", "scale of the glow added to the scene", 0, 1, {1, 1, 1, 1}, {}, false},
            {"ramp", "", "ramping: the strength pulses by this fraction over `ramp_period` frames (0: steady)", 0, 1,
             {0, 0, 0, 0}, {}, false},
            {"ramp_period", "frames", "period of the ramp", 2, 1000, {60, 60, 60, 60}, {}, true},
            {"fog_start", "scene units", "glow-only black fog on built-in scenes: glow masks fade linearly from this "
                                         "distance from the camera…",
             0, 10000, {0, 0, 0, 0}, {}, false},
            {"fog_end", "scene units", "…to none at this one (fog_end <= fog_start: no fog)", 0, 10000, {0, 0, 0, 0},
             {}, false},
        };
        return p;
    }

public:
    // One direction of the separable convolution: additive passes of 4 (ps_1_1) or 2 (ffp) taps.
    static void convolve(FrameBuild& fb, TextureId src, TextureId dst, bool horizontal, const std::vector<double>& k) {
        const int r = int(k.size() / 2);
        const bool ffp = fb.choice("path") == 1;
        const size_t per = ffp ? 2 : 4;
        const std::vector<double> q = ffp ? quantiseWeights8(k) : quantiseWeights(k, fb.precision);
        const std::string dir = horizontal ? "h" : "v";
        for (size_t first = 0, pass = 0; first < q.size(); first += per, ++pass) {
            std::vector<Tap> taps;
            std::vector<float> weights;
            for (size_t i = first; i < std::min(first + per, q.size()); ++i) {
                const float o = float(int(i) - r);
                taps.push_back(texelTap(fb, src, horizontal ? o : 0, horizontal ? 0 : o, D3DTEXF_POINT));
                weights.push_back(float(q[i]));
            }
            const Blend blend = pass == 0 ? Blend::None : Blend::Add;
            const std::string name = "blur_" + dir + "_" + std::to_string(pass);
            if (!ffp) {
                QuadPass qp{"weighted4.psh", dst, taps, {}, blend};
                // A last pass with fewer taps: the unused stages sample nothing ((0, 0, 0, 1)) and
                // get weight 0, so they add nothing, alpha included.
                for (size_t i = 0; i < 4; ++i) {
                    const float w = i < weights.size() ? weights[i] : 0.0f;
                    qp.constants.push_back({int(i), {w, w, w, w}});
                }
                addQuadPass(fb, name, std::to_string(taps.size()) + " taps" + (pass ? ", added (ONE, ONE)" : ""), qp);
            } else {
                addFixedFunctionPass(fb, name, dst, taps, weights, blend);
            }
        }
    }

    // The D3D7 path: stage 0 = texture0 × diffuse.rgb (w0), alpha = diffuse.a (w1); stage 1 =
    // MODULATEALPHA_ADDCOLOR: current.rgb + current.a × texture1.rgb.
    static void addFixedFunctionPass(FrameBuild& fb, const std::string& name, TextureId dst, const std::vector<Tap>& taps,
                                     const std::vector<float>& weights, Blend blend) {
        auto byte = [](float w) { return DWORD(std::lround(std::clamp(w, 0.0f, 1.0f) * 255.0f)); };
        const DWORD w0 = byte(weights[0]), w1 = weights.size() > 1 ? byte(weights[1]) : 0;
        const DWORD diffuse = w1 << 24 | w0 << 16 | w0 << 8 | w0;
        fb.graph.addPass(
            PassInfo{name, PassKind::FixedFunction, "",
                     "D3D7 stages: T0×diffuse.rgb + diffuse.a×T1 (8-bit weights in the vertex colour)"},
            [&](PassBuilder& b) {
                for (const Tap& t : taps) b.read(t.texture);
                if (blend != Blend::None) b.read(dst);
                b.write(dst);
            },
            [=](PassContext& c) {
                emu::Device& d = c.device;
                auto tss = [&](DWORD stage, D3DTEXTURESTAGESTATETYPE s, DWORD v) {
                    return c.check(d.SetTextureStageState(stage, s, v));
                };
                if (!c.setTarget(dst) || !setBlend(c, blend) || !c.check(d.SetPixelShader(emu::Handle::Null))) return false;
                std::array<emu::QuadCoords, 4> coords{};
                for (DWORD s = 0; s < 2; ++s) {
                    const Tap& t = taps[std::min<size_t>(s, taps.size() - 1)];
                    coords[s] = t.coords;
                    if (!bindTap(c, s, t)) return false;
                }
                const bool second = taps.size() > 1;
                if (!tss(0, D3DTSS_COLOROP, D3DTOP_MODULATE) || !tss(0, D3DTSS_COLORARG1, D3DTA_TEXTURE) ||
                    !tss(0, D3DTSS_COLORARG2, D3DTA_DIFFUSE) || !tss(0, D3DTSS_ALPHAOP, D3DTOP_SELECTARG1) ||
                    !tss(0, D3DTSS_ALPHAARG1, D3DTA_DIFFUSE) ||
                    !tss(1, D3DTSS_COLOROP, second ? D3DTOP_MODULATEALPHA_ADDCOLOR : D3DTOP_DISABLE) ||
                    !tss(1, D3DTSS_COLORARG1, D3DTA_CURRENT) || !tss(1, D3DTSS_COLORARG2, D3DTA_TEXTURE) ||
                    !tss(1, D3DTSS_ALPHAOP, second ? D3DTOP_SELECTARG1 : D3DTOP_DISABLE) ||
                    !tss(1, D3DTSS_ALPHAARG1, D3DTA_CURRENT) || !tss(2, D3DTSS_COLOROP, D3DTOP_DISABLE))
                    return false;
                return c.drawQuad(coords, diffuse);
            });
    }

    std::pair<float, float> sceneGlowFog(const Settings& s) const override {
        return {float(s.at("fog_start")), float(s.at("fog_end"))};
    }

    void build(FrameBuild& fb) const override {
        PassGraph& g = fb.graph;
        const TextureDesc sd = fb.sceneDesc();
        const uint32_t d = uint32_t(fb.get("divisor"));
        const TextureDesc gd{std::max(sd.width / d, 1u), std::max(sd.height / d, 1u), fb.format};
        const float o = float(d) / 4.0f;
        const TextureId raw = g.create("glow sources", gd);
        addQuadPass(fb, "glow_source", "RGB × alpha (the glow mask), 4 bilinear taps per block",
                    QuadPass{"glow_source.psh",
                             raw,
                             {texelTap(fb, fb.scene, -o, -o), texelTap(fb, fb.scene, +o, -o),
                              texelTap(fb, fb.scene, -o, +o), texelTap(fb, fb.scene, +o, +o)}});
        const float k = float(fb.get("decay"));
        TextureId src = raw;
        const int after = fb.choice("afterimage");
        TextureId previousGlow;
        if (after == 1) {
            // This frame's sources plus the previous frame's, dimmed; then this frame's are kept.
            const TextureId previous = fb.persistent("previous glow sources", gd, 0);
            src = g.create("sources with after-image", gd);
            addStretchPass(fb, "copy_sources", raw, src, D3DTEXF_POINT);
            addQuadPass(fb, "afterimage", "previous sources × decay, added (ONE, ONE)",
                        QuadPass{"scale.psh", src, {texelTap(fb, previous, 0, 0, D3DTEXF_POINT)}, {{0, {k, k, k, k}}},
                                 Blend::Add});
            addStretchPass(fb, "keep_sources", raw, previous, D3DTEXF_POINT);
        } else if (after == 2) {
            previousGlow = fb.persistent("previous glow", gd, 0);
            addQuadPass(fb, "feedback", "previous blurred glow × decay, added to the sources (ONE, ONE)",
                        QuadPass{"scale.psh", raw, {texelTap(fb, previousGlow, 0, 0, D3DTEXF_POINT)},
                                 {{0, {k, k, k, k}}}, Blend::Add});
        }
        const std::vector<double> kern = glowKernel(fb.settings);
        const TextureId horizontal = g.create("glow h", gd);
        const TextureId glow = g.create("glow", gd);
        convolve(fb, src, horizontal, true, kern);
        convolve(fb, horizontal, glow, false, kern);
        if (after == 2) addStretchPass(fb, "keep_glow", glow, previousGlow, D3DTEXF_POINT);

        addStretchPass(fb, "copy_scene", fb.scene, fb.output, D3DTEXF_POINT);
        const double ramp = fb.get("ramp"), period = fb.get("ramp_period");
        // (Steady, the strength does not depend on the frame: the frame is not read.)
        const double pulse = ramp == 0 ? 1.0 : 1 - ramp + ramp * 0.5 * (1 + std::cos(2 * kPi * double(fb.frame()) / period));
        const float s = float(fb.get("strength") * pulse);
        addQuadPass(fb, "composite", "additive blend (ONE, ONE) of the bilinear-upsampled glow",
                    QuadPass{"scale.psh", fb.output, {texelTap(fb, glow, 0, 0)}, {{0, {s, s, s, 0}}}, Blend::Add});
    }
};

}  // namespace

const Technique& glowTechnique() {
    static const Glow t;
    return t;
}

}  // namespace glare
