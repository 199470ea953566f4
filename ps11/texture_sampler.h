// The software sampler: textures bound to stages 0..7 with D3D9 sampler state (filters,
// address modes, border colour), answering the executor's span requests exactly as
// docs/precision.md "Sampling" and docs/textures.md say. Used by the executor's test runs and
// by the emu device.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>

#include "ps11/caps.h"
#include "ps11/sampler.h"
#include "ps11/texture.h"

namespace ps11 {

// Sampler stages the device has (D3D9 ps 1.x: 8).
constexpr int kMaxSamplerStages = kMaxTextureStages;  // ps11/caps.h


// D3DSAMP_* state of one stage. Filter::None as min/mag filter acts as point.
struct SamplerState {
    Filter minFilter = Filter::Point;
    Filter magFilter = Filter::Point;
    Filter mipFilter = Filter::None;
    TextureAddress addressU = TextureAddress::Wrap;
    TextureAddress addressV = TextureAddress::Wrap;
    TextureAddress addressW = TextureAddress::Wrap;
    std::array<float, 4> border{0, 0, 0, 0};  // r g b a
};

// Whether a lookup of `tex` under `state` is the same with or without quads: one level in use (one
// level, or mip filter none) and one filter for minification and magnification, so the level of
// detail the quads give cannot change a texel (docs/textures.md "Level of detail"). The device
// then shades rows instead of 2×2 quads (docs/device.md "Rasterisation").
bool lodFree(const Texture& tex, const SamplerState& state);

// The level and filter of one 2×2 quad's lookup (docs/textures.md "Level of detail"), from the
// squared lengths of its screen derivatives at level 0: dx2 = Σ (∂c/∂x · size)², dy2 likewise
// (the sampler's own rule for quads; the device's row paths apply it to quads they tabulate).
// `fixed`: an fx profile; `weights8`: the float profile with 8-bit weights (the mip blend's weight
// then is 8-bit too).
struct LevelChoice {
    int level0 = 0, level1 = 0;
    int slots = 1;        // 2: a mip blend of level0 and level1
    bool linear = false;  // the filter: the min filter where minified, else the mag filter
    int32_t mipW = 0;     // fx (and 8-bit weights): level1's weight, 0..256
    float mipF = 0.0f;    // level1's weight
    bool operator==(const LevelChoice&) const = default;
};
LevelChoice chooseLevel(const Texture& tex, const SamplerState& state, double dx2, double dy2, bool fixed,
                        bool weights8);
// A quad's choice from the coordinates (u, v, and w for a volume) of its top-left, top-right and
// bottom-left lanes: the derivatives ∂c/∂x = c(tr) − c(tl) and ∂c/∂y = c(bl) − c(tl) in level-0
// texels, computed in double, then chooseLevel (what sample() does per quad of its lanes).
LevelChoice quadLevel(const Texture& tex, const SamplerState& state, const float tl[3], const float tr[3],
                      const float bl[3], bool fixed, bool weights8);

class TextureSampler final : public Sampler {
public:
    // `fastPath` false forces the reference path for every lookup (tests and benchmarks compare
    // the two; the results are bit-identical).
    explicit TextureSampler(bool fastPath = true);
    // Binds (or with nullptr unbinds) a texture; false for a stage outside 0..7.
    bool bind(int stage, std::shared_ptr<const Texture> texture);
    // Sets a stage's sampler state; false for a stage outside 0..7.
    bool setSamplerState(int stage, const SamplerState& state);
    const SamplerState& samplerState(int stage) const { return m_stages[size_t(stage)].state; }
    // The texture bound to a stage (null: none, or a stage outside 0..7).
    const Texture* texture(int stage) const {
        return stage >= 0 && stage < kMaxSamplerStages ? m_stages[size_t(stage)].texture.get() : nullptr;
    }

    void sample(const SampleRequest& req, SampleResult& out) override;
    bool hasTexture(int stage) const override;
    uint64_t texelsFetched() const override { return m_fetched.load(std::memory_order_relaxed); }

    // The fast kernels for 8-bit 2-D textures in fx profiles (point and bilinear, one level per
    // quad, every address mode; on by default). Off: the reference path only.
    void setFastPath(bool enabled) { m_fastPath = enabled; }
    // Sub-texel weight bits of bilinear and mip filtering in the float profile: 8 (a hardware
    // class's texture unit, w = round_half_even(f·256)/256) or 0 (float32 weights). fx profiles
    // always weigh with 8 bits, ideal never quantises (docs/precision.md "Sampling").
    void setWeightBits(int bits) { m_weightBits = bits; }
    int weightBits() const { return m_weightBits; }
    // Lanes answered by the fast kernels so far (statistics; tests check the fast path ran).
    uint64_t fastLanes() const { return m_fastLanes.load(std::memory_order_relaxed); }

private:
    struct Stage {
        std::shared_ptr<const Texture> texture;
        SamplerState state;
        std::array<int32_t, 4> borderGrid8{}, borderGrid12{};  // border colour on the fx grids
    };
    std::array<Stage, kMaxSamplerStages> m_stages;
    std::atomic<uint64_t> m_fetched{0};
    std::atomic<uint64_t> m_fastLanes{0};
    bool m_fastPath = true;
    int m_weightBits = 0;
};

// One axis of the reference sampler's float-profile addressing, for row paths that tabulate it
// per column or row (emu/aligned_float.cpp): for each coordinate, the texel pair after the
// address mode (-1 = border) and the weight of i1 as float/ideal lerp with it (w/256 of the
// 8-bit weight when `weights8`, the class's weights in the float profile; 0 for point). The same
// values sample() computes per lane for a 2-D level of `extent` texels.
void floatAxisTaps(TextureAddress mode, bool linear, bool weights8, int count, const float* coord, uint32_t extent,
                   int32_t* i0, int32_t* i1, float* f);

}  // namespace ps11
