// The pass shapes every technique uses, built on PassGraph: a ps_1_1 shader over the half-pixel
// full-screen quad with its taps, a StretchRect, a Clear.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "glare/pass_graph.h"
#include "glare/technique.h"

namespace glare {

// One texture stage of a quad pass: which texture, where the quad's corners sample it, filter.
struct Tap {
    TextureId texture;
    emu::QuadCoords coords;
    D3DTEXTUREFILTERTYPE filter = D3DTEXF_LINEAR;
};
// A tap covering the whole texture moved by (dx, dy) of its texels.
Tap texelTap(const FrameBuild& fb, TextureId texture, float dx, float dy, D3DTEXTUREFILTERTYPE filter = D3DTEXF_LINEAR);
// A tap that reads one point (u, v) of the texture at every pixel.
Tap pointTap(TextureId texture, float u, float v, D3DTEXTUREFILTERTYPE filter = D3DTEXF_POINT);

struct QuadPass {
    std::string shader = {};  // glare/shaders/<shader>
    TextureId target = {};
    std::vector<Tap> taps = {};  // stage i = taps[i], at most 4
    std::vector<std::pair<int, std::array<float, 4>>> constants = {};
    Blend blend = Blend::None;
};

// Kernel weights as the hardware holds them: on the fx profiles' grid (fx8: n/255, fx12: n/4080)
// with error diffusion (each rounding remainder carried into the next weight, so the quantised
// weights sum to the quantised sum: GLARE.md §2, §7), as they are under float and ideal.
std::vector<double> quantiseWeights(const std::vector<double>& weights, ps11::Precision precision);
// The same with 255 steps whatever the profile (vertex colours, D3DCOLOR bytes).
std::vector<double> quantiseWeights8(const std::vector<double>& weights);

// Adds a pass drawing `q` (reads the taps, and the target when blending; writes the target).
void addQuadPass(FrameBuild& fb, const std::string& name, const std::string& note, const QuadPass& q);
// Draws `q` now (for passes that draw several quads).
bool drawQuadPass(PassContext& c, Runner& runner, const QuadPass& q);
void addStretchPass(FrameBuild& fb, const std::string& name, TextureId source, TextureId dest,
                    D3DTEXTUREFILTERTYPE filter);
void addClearPass(FrameBuild& fb, const std::string& name, TextureId target, D3DCOLOR colour);
// Blending for the next draws (None: off).
bool setBlend(PassContext& c, Blend blend);
// Binds the tap's texture to `stage` with its filter for minification and magnification, clamp
// addressing and no mip filtering (what every pass of the techniques samples with).
bool bindTap(PassContext& c, DWORD stage, const Tap& tap);

}  // namespace glare
