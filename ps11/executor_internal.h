// Executor internals shared by its stages: the per-run register file in structure-of-arrays
// lanes and the kernels of each family (executor_arith*.cpp, executor_texture.cpp). The decoded op
// list, the profile and the register slot layout they run over are public
// (ps11/decoded_program.h). Not part of the public API.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "ps11/decoded_program.h"
#include "ps11/executor.h"
#include "ps11/executor_presampled_internal.h"
#include "ps11/fill_lanes.h"
#include "ps11/precision.h"
#include "ps11/simd_dispatch.h"

namespace ps11::exec {

// Lanes processed at once inside run(): a span is cut into chunks of this size so the working
// set (registers + scratch) stays in L1 or L2. A whole span (kMaxSpan) at once: the per-chunk
// work of the row paths (a fill per tap, an op dispatch per instruction) is paid once a span.
constexpr int kChunk = 256;

// A chunk of 0.0f lanes: what an absent input (texture coordinate, colour) reads.
alignas(64) inline constexpr float kZeroLanes[kChunk] = {};

// A v# channel as the executor reads it (docs/precision.md "Inputs"): saturated to [0, 1], NaN
// as 0; in fx profiles then its grid integer round_half_even(s·G) (roundEvenSmall: exact below
// 2^51).
inline float saturateColor(float s) { return s > 0.0f ? (s < 1.0f ? s : 1.0f) : 0.0f; }
inline int32_t colorGrid(float s, int32_t g) { return int32_t(roundEvenSmall(double(saturateColor(s)) * double(g))); }

// Whether lanes of v#'s channel c are one value (PixelInputs::uniformColor), and where they start
// for a chunk at `offset` (a null pointer reads as 0).
inline bool uniformColor(const PixelInputs& in, int v, int c) { return (in.uniformColor >> (4 * v + c)) & 1; }
inline const float* colorLanes(const PixelInputs& in, int v, int c, int offset) {
    const float* src = in.color[v][c];
    return !src ? kZeroLanes : uniformColor(in, v, c) ? src : src + offset;
}

// Register storage of one chunk. Only one of the int / float banks is used per profile.
template <class T>
struct Bank {
    alignas(64) T reg[kNumSlots][4][kChunk];
    alignas(64) T hold[4][kChunk];  // held result of a co-issued pair's first member
};

struct RunState {
    int n = 0;  // lanes in this chunk
    int offset = 0;  // lane offset of the chunk inside the span
    const PixelInputs* in = nullptr;
    Sampler* sampler = nullptr;
    Bank<int32_t> bi;
    Bank<float> bf;
    alignas(64) int32_t k[3][4][kChunk];   // fx: fetched sources as k (value k/(2G))
    alignas(64) float x[3][4][kChunk];     // float: fetched sources
    alignas(64) float pad[2][kChunk];      // texm3x2pad / texm3x3pad dot products
    alignas(64) uint8_t killed[kChunk];
    alignas(64) float depth[kChunk];
    bool depthWritten = false;
    // Set by the fx8 fast path around tex/texld: sampleInto then leaves the ±M clamp of the
    // texels to the caller, which clamps while converting to its int16 registers.
    bool deferTexelClamp = false;
    bool plainRead = false;  // the texture instruction running is a plain read (SampleRequest::plainRead)
    // Pre-sampled runs on the generic path (runPresampled, fx profiles): the k-th texture
    // instruction takes tap k's grid integers from `fill` instead of the sampler; null otherwise.
    TapFill fill = nullptr;
    void* fillCtx = nullptr;
    uint8_t executedTaps = 0;  // plain reads sampled here all the same (PresampledRun::executedTaps)
};

// The calling thread's T (a run state of tens of KB), kept between calls so a span costs no
// allocation; taken out of the cache while in use, so a nested call on the same thread allocates
// its own. T is default-initialised: callers set what they read.
template <class T>
class ThreadCached {
public:
    ThreadCached() : m_v(std::move(cache())) {
        if (!m_v) m_v.reset(new T);
    }
    ~ThreadCached() { cache() = std::move(m_v); }
    ThreadCached(const ThreadCached&) = delete;
    ThreadCached& operator=(const ThreadCached&) = delete;
    T& operator*() const { return *m_v; }
    T* operator->() const { return m_v.get(); }

private:
    static std::unique_ptr<T>& cache() {
        thread_local std::unique_ptr<T> c;
        return c;
    }
    std::unique_ptr<T> m_v;
};

// Channels of source s an op reads, as a mask of output channels (the opcode table's
// componentsRead: the write mask, or dp3 .rgb, dp4 .rgba, bem .rg).
inline uint8_t fetchMask(const DOp& op, int s) { return componentsRead(*op.info, s, op.mask); }

// Arithmetic instruction (mov … bem, not nop) into out (the destination or the hold buffer):
// fx profiles (executor_arith_fx.inc), float profiles (executor_arith_float.inc), each a table
// per SIMD level that runGeneric fetches once per run.
using FxArithFn = void (*)(const Profile& p, const DOp& op, RunState& st, int32_t (*out)[kChunk]);
// Pre-sampled runs: a tap's int16 lanes (TapFill) into int32 register lanes, each at most `hi`;
// r0's int32 lanes into the int16 lanes of ResultSink (|n| <= nMax <= 32767 there).
using FxWidenFn = void (*)(const int16_t* src, int32_t* dst, int n, int32_t hi);
using FxNarrowFn = void (*)(const int32_t* src, int16_t* dst, int n);
struct FxArithKernels {
    FxArithFn arith;
    FxWidenFn widen;
    FxNarrowFn narrow;
};
const FxArithKernels& fxArithKernels(SimdLevel level);
// The tables (the Avx2 and Avx512 ones in x86-64 builds only); use fxArithKernels().
namespace baseline {
extern const FxArithKernels kFxArith;
}
namespace avx2 {
extern const FxArithKernels kFxArith;
}
namespace avx512 {
extern const FxArithKernels kFxArith;
}
using FloatArithFn = void (*)(const Profile& p, const DOp& op, RunState& st, float (*out)[kChunk]);
struct FloatArithKernels {
    FloatArithFn arith;
};
const FloatArithKernels& floatArithKernels(SimdLevel level);
// The tables (the Avx2 and Avx512 ones in x86-64 builds only); use floatArithKernels().
namespace baseline {
extern const FloatArithKernels kFloatArith;
}
namespace avx2 {
extern const FloatArithKernels kFloatArith;
}
namespace avx512 {
extern const FloatArithKernels kFloatArith;
}
// Texture-address instruction.
void execTexture(const Profile& p, const DOp& op, RunState& st);

// Pointer to TC[set][comp] lanes of the chunk (zeros when absent).
const float* texcoordLanes(const RunState& st, int set, int comp);

}  // namespace ps11::exec
