// ps_1_x → GLSL for the GL renderer (docs/gl-backend.md "Shaders"). One fragment shader per
// draw configuration: the decoded program (ps11/decoded_program.h, the op list the executor
// runs), the precision profile, the sampled stages' texture kinds and sampler states, and the
// output merger's plan (emu/merge_plan.h). Two modes follow from the profile:
// - exact (fx8, fx12): registers are grid integers, every instruction forms the executor's exact
//   numerator and rounds once (ties to even), bilinear and mip filtering by hand with
//   texelFetch and 8-bit weights, the merge on the grid;
// - float (float, ideal): float32 registers evaluated in the executor's order without
//   contraction (`precise`), the same filtering formulas in float32.
// Attributes are not interpolated by GL: each fragment evaluates the rasteriser's planes
// (emu/raster.h) from a per-triangle record, so both renderers shade the same inputs.
// A third mode, native (FragmentSpec::native), is what a GPU driver would run for the draw: GL
// interpolates the attributes (nativeVertexSource), GL's texture unit filters, float32
// arithmetic with the hardware class's clamps, and the merge left to GL's fixed-function blend
// and depth state (emu/gl/native_merge.h) except vertex fog and the alpha test.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "emu/merge_plan.h"
#include "emu/raster.h"
#include "ps11/decoded_program.h"
#include "ps11/texture_sampler.h"

namespace emu::gl {

// A sampled stage as the shader sees it.
struct StageSpec {
    bool bound = false;   // a texture is bound; otherwise the stage samples (0, 0, 0, 1)
    bool volume = false;  // sampler3D / isampler3D
    int levels = 1;
    ps11::SamplerState state;  // filters and address modes (the border colour is a uniform)
    // fx profiles: 8-bit texels (ps11::TexelStorage::Unorm8), uploaded as GL_RGBA8UI and scaled
    // to the grid in the shader; others are GL_RGBA32I grid integers.
    bool unorm8 = false;
    // unorm8, sampled from a resident A8R8G8B8 surface's raw words (GL_R32UI) and unpacked in
    // the shader: no conversion of a texture the renderer drew.
    bool packedWords = false;
    // The border colour's grid values are within [0, G] (what a D3DCOLOR gives): 32-bit sums
    // suffice for a one-level 2-D bilinear tap.
    bool borderInRange = false;
};

// The level and filter of a stage do not depend on the quad's derivatives: one level (or no
// mip filter) and the same filter for minification and magnification.
inline bool lodFree(const StageSpec& s) {
    const bool magLin = s.state.magFilter == ps11::Filter::Linear, minLin = s.state.minFilter == ps11::Filter::Linear;
    return (s.levels == 1 || s.state.mipFilter == ps11::Filter::None) && magLin == minLin;
}

struct FragmentSpec {
    const ps11::exec::DecodedProgram* program = nullptr;
    ps11::Precision precision = ps11::Precision::Fx8;
    int weightBits = 8;  // float profile: 8-bit sub-texel weights (0: float32 weights)
    std::array<StageSpec, ps11::kMaxTextureStages> stages{};
    uint64_t usedAttributes = 0;  // attributes in the triangle record (emu/vertex.h indices)
    Plan merge;                   // the output merger's plan (colour/depth pointers unused)
    bool shaderDepth = false;     // r0's depth comes from texdepth / texm3x2depth
    bool wantZ = false;           // the depth plane is evaluated (depth test or write)
    // float profiles: sample with GL's own texture unit (texture(), the sampler state as a GL
    // sampler object, 8-bit textures as GL_RGBA8) instead of the emulator's filtering formulas:
    // the experiment that measures a GPU's filtering against the emulator's model.
    bool hardwareFiltering = false;
    // Native mode (a float profile's program; `fx` never applies): GL's interpolation of the
    // varyings of nativeVertexSource() for v0, v1 and TC0..7, texture() for every bound stage
    // (hardwareFiltering implied; an unbound stage samples (0, 0, 0, 1)), float32 registers
    // clamped to [-maxValue, maxValue] after each write, `discard` for texkill, gl_FragDepth
    // only when shaderDepth, then vertex fog and the alpha test from `merge` (fog, fogByte,
    // alphaTest, alphaMask, alphaRef, and the colour target's kind) and r0 out as a vec4.
    // Blending, the colour mask and the depth test are GL state (nativeMergeOf). No doubles, no
    // record: usedAttributes, weightBits, wantZ and the stages' border colours are unused.
    bool native = false;
};

// The GLSL version and extensions the shaders need (checked by the renderer).
constexpr int kGlslVersion = 450;

std::string vertexSource();
std::string fragmentSource(const FragmentSpec& spec);

// The vertex shader of native mode. Attributes: location 0 `vec4 aPos` = (x, y, z, rhw): x, y
// in D3D screen pixels (pixel centres at integers, rows down), z in [0, 1] after the viewport,
// rhw = 1/w (1 when not perspective); 1 `vec4 aDiffuse`, 2 `vec4 aSpecular` (alpha: the vertex
// fog factor); 3..10 `vec4 aTex0` … `aTex7`, the texture-coordinate sets u v w q. Uniform
// `vec4 uXform` = (2/W, −2/H, −1, 1) maps window x, y (pixel edges at integers) to NDC, for
// glClipControl(GL_UPPER_LEFT, GL_ZERO_TO_ONE). Position (x + 0.5, y + 0.5) (GL's pixel
// centres are at +0.5), clip = (ndc·w, z·w, w) with w = 1/rhw (rhw below 1e-30, or NaN, taken
// as 1e-30), so GL interpolates perspective-correctly as D3D does. Outputs (smooth):
// vDiffuse, vSpecular, vTex[8].
std::string nativeVertexSource();

// The triangle record (a usamplerBuffer of RGBA32UI texels): texel 0 = (perspective,
// constant-mask low, high, top-left bits), texels 1..5 = the edge functions a0 a1 a2 b0 b1 b2 c0
// c1 c2 (int64, two a texel), then doubles two per texel: ox, oy, the rhw plane, the z plane
// and, for each attribute of `used` in ascending order, its plane (base, dx, dy) or, when the
// attribute is constant over the triangle, (value, 0, 0).
int recordTexels(uint64_t used);
void writeRecord(const TriangleSetup& setup, uint64_t used, uint32_t* out);

}  // namespace emu::gl
