// The fx8 fast path of the executor: registers as int16 lanes (16 per AVX2 register, 32 per
// AVX-512 one), sources fetched as k = a·n + b in int16, products and sums of products formed
// exactly in int32 by pmaddwd, then the one round-half-even of docs/precision.md done with
// integer and float operations whose exactness is proven over the whole input range
// (tests/test_executor_fast.cpp). It gives results bit-identical to the generic int32/int64 path
// (executor_arith_fx.inc), which stays the reference and runs whatever the fast path does not
// cover. The kernels (executor_fast_kernels.inc) are compiled once per SIMD level
// (executor_fast_sse2.cpp for any x86-64, executor_fast_avx2.cpp, executor_fast_avx512.cpp) and
// fetched per run from fastKernels(simdLevel()) (ps11/simd_dispatch.h). Not part of the public API.
#pragma once

#include <array>
#include <cstdint>

#include "ps11/executor_internal.h"
#include "ps11/executor_presampled_internal.h"
#include "ps11/simd_dispatch.h"

namespace ps11::exec {

// Applies when: fx8 (G = 255) and round(M·G) <= kFastMaxGrid. Then every grid value n and every
// source k = a·n + b fits int16 (|k| <= 4·2040 + 510 = 8670, lrp's ka − kb <= 17340) and every
// product numerator (dp4: 4·8670² ≈ 3.0e8, doubled for _x8) fits int32.
constexpr int32_t kFastMaxGrid = 2040;

enum class FastKind : uint8_t { Mov, Add, Sub, Mul, Mad, Dp3, Dp4, Lrp, Cnd, Cmp };

// Slots of the int16 bank: the register slots (ps11/decoded_program.h), then c0..c7 as lanes.
constexpr int kFastConstSlot = kNumSlots;
constexpr int kFastSlots = kNumSlots + kNumConsts;

struct FastSrc {
    uint8_t slot = 0;
    std::array<uint8_t, 4> sw{0, 1, 2, 3};
    int16_t a = 2, b = 0;  // k = a·n + b (docs/precision.md modifier table, G = 255)
};

struct FastOp {
    FastKind kind = FastKind::Mov;
    bool hold = false;     // write into the hold buffer (first member of a co-issued pair)
    bool viaTemp = false;  // write into tmp, then copy (the destination is also a swizzled source)
    bool half = false;     // products: every source k is even, formed halved (see the kernels)
    bool small = false;    // mul/mad, shift 0, sources ±n, |n| <= 255: the 16-bit kernel (productSmall)
    bool nonNegative = false;  // small, and both factors unnegated and >= 0 in every lane (set per run)
    uint8_t complement = 0;    // nonNegative only: bit s, factor s is 1 − n (255 − n, n known in [0, 255])
    // nonNegative only: the result is >= 0 in every lane and lo <= 0 (a mul, or a mad whose third
    // source is unnegated and known >= 0), so productSmall leaves out the lower clamp.
    bool lean = false;
    uint8_t dst = 0;
    uint8_t mask = kMaskAll;
    int8_t shift = 0;
    int16_t lo = -255, hi = 255;  // _sat and range clamp, as the generic path computes them
    uint8_t numSrc = 0;
    std::array<FastSrc, 3> src{};
    // Pre-sampled runs (presampledOps): this op heads a chain of `chain` consecutive products run
    // as one (FastKernels::chain), and the ops after it in the chain have `inChain` set.
    uint8_t chain = 0;
    bool inChain = false;
};

struct FastBank {
    alignas(64) int16_t reg[kFastSlots][4][kChunk];
    alignas(64) int16_t hold[4][kChunk];
    alignas(64) int16_t tmp[4][kChunk];
};

// Runs one arithmetic op over lanes [0, nv) (nv a multiple of FastKernels::lanes, <= kChunk).
using FastArithFn = void (*)(const FastOp& op, FastBank& bank, int nv);
// Runs a chain of `count` ops (FastOp::chain) over lanes [0, nv): a small non-negative mul into
// register R, then small non-negative mads each adding R as it stands; each op's result rounded
// and clamped as arith() would, R kept in a vector register between them and stored once.
using FastChainFn = void (*)(const FastOp* ops, int count, FastBank& bank, int nv);
// The longest chain.
constexpr int kMaxFastChain = 8;

// A program that runs as chain rows (ps11/executor_presampled_internal.h, chainRows): `count`
// small non-negative products into r0 (productSmall's formulas, FastOp::nonNegative), ops2[head]
// and the ops after it: one mul or mad on its own, or a chain (FastOp::chain) whose ops after the
// first add r0. Each op's two factors are a tap (its index in the TapPlan, >= 0) or a constant
// (−1 − k), the first always a tap (the factors are swapped where the program has the constant
// first); `complement` bit s: factor s is 1 − n (255 − n; taps only). The first op's addend (a
// mad's third source): a tap, a constant known >= 0 in every channel, or kNoAddend. Every op's
// clamp holds 0 (lo <= 0 <= hi): a sum of non-negative terms needs its upper clamp only. Constant k's
// grid integers in b g r a byte order. `flat`: the taps read other than as an uncomplemented
// first factor (a tap halfway between two texels is formed into a row of its own first).
struct ChainRowPlan {
    static constexpr int8_t kNoAddend = -128;
    bool ready = false;
    int head = 0, count = 0;
    int taps = 0;  // the program's texture reads
    std::array<std::array<int8_t, 2>, kMaxFastChain> factor{};
    std::array<uint8_t, kMaxFastChain> complement{};
    int8_t addend = kNoAddend;
    uint8_t flat = 0;
    std::array<std::array<int16_t, 4>, kNumConsts> pattern{};
};
// Runs a ChainRowPlan over `bytes` (a multiple of the kernels' lanes) lanes of row bytes: lane
// l of tap t is its filtered texel byte (ChainRowTap) at l, r0's lanes go to out saturated to
// [0, 255], each word or-ed with orMask, with `additive` added to out's bytes with saturation.
// Reads and writes whole steps of lanes (the caller pads); the taps in plan.flat are not
// halfway ones.
using FastChainRowFn = void (*)(const FastOp* ops, const ChainRowPlan& plan, const ChainRowTap* taps, int bytes,
                                uint8_t* out, uint32_t orMask, bool additive);

// Test hooks: the rounding steps of the kernels on their own, over count lanes (any count).
// Products: n = round_half_even(P·2^s / (4G)) (half: round_half_even(P·2^s / G)), clamped to
// [lo, hi]. Linear: n = round_half_even(K·2^s / 2), clamped.
using FastRoundProductFn = void (*)(const int32_t* p, int16_t* out, int count, int shift, bool half, int16_t lo,
                                    int16_t hi);
using FastRoundLinearFn = void (*)(const int16_t* k, int16_t* out, int count, int shift, int16_t lo, int16_t hi);

// v# input: saturate to [0, 1] (NaN -> 0) and round_half_even(s·255) computed in double, n lanes.
using FastLoadColorFn = void (*)(const float* src, int16_t* dst, int n);
// int32 register lanes (texture stage results) to int16, clamped to [-m, m].
using FastNarrowFn = void (*)(const int32_t* src, int16_t* dst, int n, int16_t m);
// r0 output: color = float(n) / 255 (correctly rounded division), grid = n; either may be null.
using FastStoreFn = void (*)(const int16_t* r, float* color, int32_t* grid, int n);

struct FastKernels {
    const char* name;  // what Executor::pathName() says: "fast-sse2", "fast-avx2" or "fast-avx512"
    int lanes;         // int16 lanes a step: 16 (SSE2 pairs, AVX2) or 32 (AVX-512)
    FastArithFn arith;
    FastChainFn chain;
    FastLoadColorFn loadColor;
    FastStoreFn store;
    FastNarrowFn narrow;
    FastRoundProductFn roundProduct;
    FastRoundLinearFn roundLinear;
    FastChainRowFn chainRow;
};

// The kernels of a SIMD level: SSE2 at Baseline, AVX2 + FMA at Avx2, AVX-512 BW at Avx512.
// Null off x86-64 (no kernels at any level: the generic path runs every program).
const FastKernels* fastKernels(SimdLevel level);
// The tables (x86-64 builds), defined by executor_fast_kernels.inc; use fastKernels().
namespace sse2 {
extern const FastKernels kKernels;
}
namespace avx2 {
extern const FastKernels kKernels;
}
namespace avx512 {
extern const FastKernels kKernels;
}

}  // namespace ps11::exec

namespace ps11::exec {

// A program prepared for the fast path: one FastOp per DOp (unused for texture ops and phase).
struct FastProgram {
    bool ready = false;  // the fast path applies (buildFastProgram); false: the generic path runs
    std::vector<FastOp> ops;
    uint8_t constsUsed = 0;              // constants the arithmetic ops read (bit per c#)
    uint8_t r0Preset = 0xF;              // r0 channels set to 0 before a run (exec::r0PresetChannels)
    std::vector<uint8_t> syncDstBefore;  // texture ops: convert the destination to int32 first
};

// Fills fp for ops if the fast path applies (fx8, round(M·G) <= kFastMaxGrid, no bem) and this
// build has the kernels; returns false otherwise (the generic path then runs the program).
bool buildFastProgram(const Profile& p, const std::vector<DOp>& ops, FastProgram& fp);

// run() of the fast path, with the kernels of simdLevel(): same inputs, outputs and semantics as
// the generic run.
// constsId names p's constants (a process-wide unique number per executor and constant change;
// 0 = unnamed): a thread's bank keeps them between runs with the same id.
void runFast(const FastProgram& fp, const Profile& p, uint64_t constsId, const std::vector<DOp>& ops, uint8_t vUsed,
             bool writesDepth, const PixelInputs& inputs, Sampler& sampler, PixelOutputs& outputs);

// runPresampled (ps11/executor_presampled_internal.h) on the fast path (the kernels of
// simdLevel()): plain reads (DOp::plainRead) have `fill` write tap i's lanes straight into their
// register (then clamped to ±nMax as sampled texels are) instead of sampling; the other texture
// instructions run as in runFast, with `sampler`; r0's int16 lanes go to `sink` chunk by chunk,
// straight from the register bank, and where run.outputs is given its killed and depth lanes as
// runFast writes them; the plain reads run.executedTaps names are sampled like the others.
// `ops2` is fp.ops with the sign analysis of presampledOps for the current constants (plain
// reads of any sign where some are executed).
void runFastPresampled(const FastProgram& fp, const Profile& p, uint64_t constsId, const std::vector<DOp>& ops,
                       const std::vector<FastOp>& ops2, uint8_t vUsed, bool writesDepth, const PixelInputs& inputs,
                       TapFill fill, ResultSink sink, void* ctx, const PresampledRun& run);

// The chain-row plan of a program (ops2: presampledOps' for the current constants): ready when
// fp is, no v# is read, nMax >= 255 (texels are not clamped), and the arithmetic after the texture
// reads is one small non-negative mul or mad, or one chain, writing all of r0, each of whose
// factors is a plain read's register or a constant, unswizzled (ChainRowPlan).
void chainRowPlan(const FastProgram& fp, const Profile& p, const std::vector<DOp>& ops,
                  const std::vector<FastOp>& ops2, uint8_t vUsed, ChainRowPlan& out);

// runChainRow (ps11/executor_presampled_internal.h) with the kernels of simdLevel(): `taps` holds
// plan.taps taps, `ops2` is what `plan` was made from.
void runChainRow(const ChainRowPlan& plan, const std::vector<FastOp>& ops2, const ChainRowTap* taps, int count,
                 uint8_t* out, const ChainRowStore& store);

// fp.ops for pre-sampled runs: mul/mad whose factors are known >= 0 in every lane (plain reads'
// taps are 8-bit texels where `plainTexels`, v# in [0, 1], constants as they are now, _sat
// results; the other texture instructions' results of any sign) marked nonNegative.
// Depends on the constants: recomputed when one changes, not per run.
void presampledOps(const FastProgram& fp, const Profile& p, const std::vector<DOp>& ops, std::vector<FastOp>& out,
                   bool plainTexels);

}  // namespace ps11::exec
