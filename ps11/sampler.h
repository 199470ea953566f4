// The sampler interface between the executor and whoever owns textures (the test sampler
// in ps11/texture_sampler.h today, the emu device later). The executor asks for a span of
// lookups at once; the sampler answers in the profile's representation (grid integers for
// fx profiles, floats otherwise), following docs/precision.md "Sampling".
#pragma once

#include <cstdint>

#include "ps11/precision.h"

namespace ps11 {

// Largest span the executor runs at once (in chunks of kChunk lanes, ps11/executor_internal.h). 512
// rather than 256: the row paths' per-span costs (a tap's runs looked up, the executor's op loop
// entered) over twice the pixels took 4–6 % off the 1080p composites in bench_draw (3 alternations).
constexpr int kMaxSpan = 512;

struct LevelChoice;  // ps11/texture_sampler.h

struct SampleRequest {
    int stage = 0;          // sampler stage 0..7
    int count = 0;          // lanes, <= kMaxSpan
    bool quads = false;     // lanes 4i..4i+3 form a 2x2 pixel quad (top-left, top-right,
                            // bottom-left, bottom-right): use them for the mip LOD;
                            // otherwise sample mip level 0
    // Or, where not null, lane i's level, filter and mip blend as its quad chose them
    // (chooseLevel, by a caller that shades rows and keeps each quad's choice): used instead of
    // quads, with the same results as lanes of quads that chose them.
    const LevelChoice* levels = nullptr;
    int dims = 2;           // coordinates used: 1 (u), 2 (u, v) or 3 (u, v, w)
    const float* u = nullptr;
    const float* v = nullptr;
    const float* w = nullptr;
    Precision precision = Precision::Fx8;
    // Where the executor asks: the request's first lane within the run's PixelInputs (its chunk's
    // offset in the span), and whether the instruction is a plain read (DOp::plainRead). A sampler
    // that serves a row's plain reads by position (emu/aligned_float.h) reads no coordinates for
    // them, and tells them from the other instructions of their stage.
    int lane = 0;
    bool plainRead = false;
};

// Output lanes: fx profiles fill grid[c][lane] (value = grid / G), float profiles fill
// value[c][lane]. c = 0..3 is r, g, b, a.
struct SampleResult {
    int32_t* grid[4] = {nullptr, nullptr, nullptr, nullptr};
    float* value[4] = {nullptr, nullptr, nullptr, nullptr};
    // A sampler may set it when every value it wrote lies in [0, 1] or is −0.0 (8-bit texels, a
    // border colour inside [0, 1], and their lerps, which rounding keeps inside; fx: grid values
    // in [0, G]): the ±MaxValue clamp of the result is then skipped where M >= 1, as it could
    // change nothing.
    bool unitRange = false;
};

class Sampler {
public:
    virtual ~Sampler() = default;
    // Samples `req.count` lanes. A stage without a texture returns (0, 0, 0, 1).
    virtual void sample(const SampleRequest& req, SampleResult& out) = 0;
    // True if a texture is bound to the stage (for diagnostics only).
    virtual bool hasTexture(int stage) const = 0;
    // Texels fetched so far (statistics).
    virtual uint64_t texelsFetched() const { return 0; }
};

// A sampler with nothing bound: every lookup returns (0, 0, 0, 1).
class NullSampler final : public Sampler {
public:
    void sample(const SampleRequest& req, SampleResult& out) override;
    bool hasTexture(int) const override { return false; }
};

}  // namespace ps11
