// Pre-sampled runs of an Executor, for the device's row paths that sample screen-aligned rows
// themselves (emu/aligned_pass.h, emu/aligned_float.h). Not part of the public API (not
// installed): the callbacks take a `void*` context and the int16 lanes of the fx8 fast path.
#pragma once

#include <array>
#include <cstdint>

#include "ps11/executor.h"

namespace ps11 {

// The texture reads of a program that can take its texels pre-sampled (tapPlan): tap i is the
// i-th plain read (DOp::plainRead); it samples `stage[i]` at (u, v) = TC[coordSet[i]].xy, or where
// divisor[i] >= 0 (a projected read) at (u, v) divided by that component of the same set
// (projectCoord), with no dependency on other registers.
struct TapPlan {
    int count = 0;
    std::array<uint8_t, 8> stage{};
    std::array<uint8_t, 8> coordSet{};
    std::array<int8_t, 8> divisor{-1, -1, -1, -1, -1, -1, -1, -1};
    uint8_t zeroDivisorIsOne = 0;  // bit i: tap i is ps_1_4's _dz/_dw (projectCoord)
    // Bit s: a texkill tests coordinate set s (TC[s].x, y, z < 0 kills the pixel); the caller
    // tests it, pre-sampled runs skip the instruction.
    uint8_t killSets = 0;
    // With tapPlan(…, executes = true): the texture instructions that are not plain reads
    // (dependent reads, matrix rows, coordinates read as values; DOp::plainRead false), which
    // pre-sampled runs execute with the sampler and the coordinates of PixelInputs. Bit s of
    // executedSets: one of them reads coordinate set s; of executedStages: one of them is stage
    // s's instruction (it may sample stage s).
    bool executes = false;
    uint8_t executedSets = 0, executedStages = 0;
    // With `executes`: ps_1_4's `texkill r#` (a register's value) among them. Pre-sampled runs
    // then report the lanes they kill (PresampledRun::outputs).
    bool registerKills = false;
    // Set by the caller: bit i, plain read i is executed too (sampled by the executor as run()
    // samples it, its texels of any sign), not filled: a texture the caller does not filter
    // itself. Its set and stage count among executedSets and executedStages, and `executes` is
    // set with it. Handed to runPresampled (PresampledRun::executedTaps); the float row path's
    // row sampler hands such reads to the worker's sampler (emu/aligned_float.h).
    uint8_t executedTaps = 0;
    bool projected(int i) const { return divisor[size_t(i)] >= 0; }
};

// A projected read's coordinate c over its divisor d, as the executor divides it: ps_1_1–1_3's
// D3DTTFF_PROJECTED c / d (spec §6.5, §7.5), ps_1_4's _dz/_dw (zeroIsOne) 1.0 where d is 0
// (spec §2.4, §3.1).
inline float projectCoord(float c, float d, bool zeroIsOne) { return zeroIsOne && d == 0.0f ? 1.0f : c / d; }

// Available when the program runs in an fx profile whose register values fit int16 (the fx8
// fast path, or the generic path with round(M·G) <= 32767: fx8 up to M = 128, the radeon8500
// class's fx12 with M = 8) and its only texture instructions are plain or projected reads:
// `tex t#` in ps_1_1–1_3 (D3DTTFF_PROJECTED as set now by setStageState: the divisor
// projectionDivisor names), `texld r#, t#` in ps_1_4 (.xy as written; _dz/_dw divide by the
// set's raw z or w), and texkills of a coordinate set (`texkill t#`, any version: killSets).
// Fills `plan` and returns true, else false. With `executes`, the other texture instructions
// are allowed too, texkills of a register among them, and runPresampled executes them:
// TapPlan::executes.
bool tapPlan(const Executor& executor, TapPlan& plan, bool executes = false);
// The same plan in any profile, without the fx8 fast path: true when every texture instruction
// is a plain read as above, or with `executes` any (the float row path, emu/aligned_float.h,
// samples the plain reads for run() with a sampler of its own and hands the others to the
// worker's).
bool plainTaps(const Executor& executor, TapPlan& plan, bool executes = false);

// fill(ctx, i, first, n, dst) writes the grid integers of tap i (the profile's: fx8 or fx12) for
// lanes [first, first + n) into dst[c][0 .. n) (c = r g b a): 8-bit texels, values in [0, G] (the
// fx8 fast path relies on that), clamped to ±round(M·G) where that is smaller, as sampled texels
// are.
using TapFill = void (*)(void* ctx, int tap, int first, int count, int16_t* const dst[4]);
// sink(ctx, first, n, r0) takes r0's grid integers of lanes [first, first + n): r0[c][0 .. n)
// (c = r g b a), valid during the call only. It is called once per chunk of lanes, in order, as
// soon as the chunk is computed (the caller stores it while it is in cache).
using ResultSink = void (*)(void* ctx, int first, int count, const int16_t* const r0[4]);
// Runs `count` (<= kMaxSpan) pixels whose plain reads take their texels from `fill` instead of
// a sampler. v0/v1 come from inputs.color. r0 goes to `sink`. Same results as Executor::run()
// with a sampler returning those texels. Only valid after tapPlan() returned true. `ctx` is
// handed to both callbacks. Where the plan executes other texture instructions, they run as in
// run(): with run.sampler and inputs.texcoord (inputs.quads off: no level of detail), and so
// do the plain reads run.executedTaps names. Where run.outputs is given, its `killed` and `depth`
// (the others are not written) take what run() writes there: each lane a texkill of a register
// discarded, and the depth a program that writes one (texdepth, texm3x2depth) gives each lane
// (chunk by chunk after the sink took it).
struct PresampledRun {
    Sampler* sampler = nullptr;
    const PixelOutputs* outputs = nullptr;
    uint8_t executedTaps = 0;  // TapPlan::executedTaps
};
void runPresampled(const Executor& executor, const PixelInputs& inputs, TapFill fill, ResultSink sink, void* ctx,
                   ExecutorStats* stats = nullptr, const PresampledRun& run = {});

// Chain rows: a program whose arithmetic is one chain of products (mul, then mads adding it, all
// of whose factors are >= 0: the glow's separable blur) each of a tap and a constant, the same on
// every channel, runs over a row's bytes as they lie (b g r a, 4 lanes a pixel), each tap read
// straight from its texel row, no lanes of r g b a planes made. Tap t of a run of pixels: the
// texel bytes at `row` (pixel p's texel at row + 4p), at vertical weight 0 and horizontal weight
// 0, or with halfX 128 (each with the next texel: round(Σ / 2), the reference filter's exact
// sum).
struct ChainRowTap {
    const uint8_t* row = nullptr;
    bool halfX = false;
};
// `n` bytes of a halfway tap's row: each byte round_half_even((b + the next texel's b) / 2), the
// reference filter's exact sum at weight 128 (src holds n + 4 bytes).
inline void halfwayBytes(const uint8_t* src, int n, uint8_t* dst) {
    for (int i = 0; i < n; ++i) {
        const int sum = src[i] + src[i + 4];
        dst[i] = uint8_t((sum + ((sum >> 1) & 1)) >> 1);
    }
}
// How runChainRow stores r0's words: each or-ed with orMask (X8R8G8B8's X = 0xff), with
// `additive` added to the bytes out holds with saturation (ONE/ONE into an 8-bit target).
struct ChainRowStore {
    uint32_t orMask = 0;
    bool additive = false;
};
// Whether the executor's program (with its constants now) runs as chain rows.
bool chainRows(const Executor& executor);
// r0 of `count` (<= kMaxSpan) pixels as bytes saturated to [0, 255], b g r a, to out[0, 4·count)
// as `store` says: what runPresampled gives for those taps, as an 8-bit target stores it. Reads
// the taps' footprints only; writes out's 4·count bytes only. Only valid after tapPlan() and
// chainRows() returned true.
void runChainRow(const Executor& executor, const ChainRowTap* taps, int count, uint8_t* out,
                 const ChainRowStore& store = {}, ExecutorStats* stats = nullptr);

}  // namespace ps11
