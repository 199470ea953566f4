// Interval evaluator internals (ps11/intervals.h): the abstract value of one register channel
// and the bound arithmetic of both families, shared by intervals.cpp (driver, inputs, texture
// instructions) and intervals_arith.cpp (arithmetic). Not part of the public API.
//
// fx: a register channel is a range of grid integers; an instruction's exact numerator is bounded
// in int64 and rounded with the executor's roundHalfEven, which is monotone, so the bounds are
// exact for independent sources. float/ideal: a range of floats [lo, hi] plus "may be NaN" and
// "may be −0.0"; every bound is computed with the very float32 operation the executor performs
// (this family is compiled with -ffp-contract=off, like the executor's): IEEE operations round
// monotonically, so the extremes of one operation over a box of float inputs are the operation at
// the box's corners, rounded the same way.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "ps11/decoded_program.h"
#include "ps11/intervals.h"

namespace ps11::intervals {

constexpr float kInf = std::numeric_limits<float>::infinity();

// ---- float family ----
struct FI {
    float lo = -kInf, hi = kInf;
    bool nan = true;  // NaN may occur
    bool nz = true;   // −0.0 may occur (meaningful when lo <= 0 <= hi)
};
constexpr FI fTop() { return {}; }
inline FI fPoint(float v) { return {v, v, false, v == 0.0f && std::signbit(v)}; }
// May be ±0.0: every range holding 0 may hold +0.0.
inline bool has0(const FI& a) { return a.lo <= 0.0f && a.hi >= 0.0f; }
inline bool finite(const FI& a) { return !a.nan && a.lo > -kInf && a.hi < kInf; }
inline bool isPoint(const FI& a, float v) { return !a.nan && a.lo == v && a.hi == v; }
// A bound computed as NaN (∞ − ∞, 0·∞) means anything; −0.0 only where 0 is in range.
inline FI norm(FI a) {
    if (a.lo != a.lo || a.hi != a.hi) return fTop();
    a.nz = a.nz && has0(a);
    return a;
}
inline FI fHull(const FI& a, const FI& b) {
    return norm({a.lo < b.lo ? a.lo : b.lo, a.hi > b.hi ? a.hi : b.hi, a.nan || b.nan, a.nz || b.nz});
}
// −x: −0.0 from +0.0.
inline FI fNeg(const FI& a) { return norm({-a.hi, -a.lo, a.nan, has0(a)}); }
// a + b: −0.0 only from −0.0 + −0.0 (an exact zero sum of other values is +0.0, round to nearest).
inline FI fAdd(const FI& a, const FI& b) {
    FI r{a.lo + b.lo, a.hi + b.hi, a.nan || b.nan, a.nz && b.nz};
    if ((a.hi == kInf && b.lo == -kInf) || (a.lo == -kInf && b.hi == kInf)) r.nan = true;  // ∞ − ∞
    return norm(r);
}
// a − b: −0.0 only from −0.0 − (+0.0).
inline FI fSub(const FI& a, const FI& b) {
    FI r{a.lo - b.hi, a.hi - b.lo, a.nan || b.nan, a.nz && has0(b)};
    if ((a.hi == kInf && b.hi == kInf) || (a.lo == -kInf && b.lo == -kInf)) r.nan = true;
    return norm(r);
}
// Whether x·y or x/y may be −0.0: a zero (or an underflow, which the rounded corners show as a
// bound reaching 0) of differing signs, −0.0 counting as negative and +0.0 as positive.
inline bool signedZeroProduct(const FI& a, const FI& b, const FI& r) {
    const bool aNeg = a.lo < 0.0f || (a.nz && has0(a)), aPos = a.hi > 0.0f || has0(a);
    const bool bNeg = b.lo < 0.0f || (b.nz && has0(b)), bPos = b.hi > 0.0f || has0(b);
    return ((aNeg && bPos) || (aPos && bNeg)) && has0(r);
}
template <class Op>
inline FI fCorners(const FI& a, const FI& b, Op op) {
    const float c[4] = {op(a.lo, b.lo), op(a.lo, b.hi), op(a.hi, b.lo), op(a.hi, b.hi)};
    FI r{c[0], c[0], a.nan || b.nan, false};
    for (float v : c) {
        if (v != v) return fTop();  // 0·∞, ∞/∞: NaN inside the box
        r.lo = v < r.lo ? v : r.lo;
        r.hi = v > r.hi ? v : r.hi;
    }
    r.nz = signedZeroProduct(a, b, r);
    return norm(r);
}
inline FI fMul(const FI& a, const FI& b) {
    return fCorners(a, b, [](float x, float y) { return x * y; });
}
// a / d for a d whose range excludes 0.
inline FI fDiv(const FI& a, const FI& d) {
    return fCorners(a, d, [](float x, float y) { return x / y; });
}
// The smallest float >= d and the largest float <= d: a float inside [lo, hi] lies inside
// [ceilToFloat(lo), floorToFloat(hi)].
inline float ceilToFloat(double d) {
    float f = float(d);
    if (double(f) < d) f = std::nextafter(f, kInf);
    return f;
}
inline float floorToFloat(double d) {
    float f = float(d);
    if (double(f) > d) f = std::nextafter(f, -kInf);
    return f;
}
// An input range as floats (the executor's inputs are float32).
FI fromRange(const ValueRange& r);

// ---- fx family ----
struct KI {  // an exact numerator (source k or product sum), int64
    int64_t lo = 0, hi = 0;
};
inline KI kPoint(int64_t v) { return {v, v}; }
inline KI kAdd(KI a, KI b) { return {a.lo + b.lo, a.hi + b.hi}; }
inline KI kSub(KI a, KI b) { return {a.lo - b.hi, a.hi - b.lo}; }
inline KI kMul(KI a, KI b) {
    const int64_t c[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
    KI r{c[0], c[0]};
    for (int64_t v : c) r.lo = v < r.lo ? v : r.lo, r.hi = v > r.hi ? v : r.hi;
    return r;
}
inline KI kIntersect(KI a, KI b) { return {a.lo > b.lo ? a.lo : b.lo, a.hi < b.hi ? a.hi : b.hi}; }
inline bool isPoint(KI a, int64_t v) { return a.lo == v && a.hi == v; }

// ---- one register channel ----
struct AV {
    int32_t nlo = 0, nhi = 0;  // fx: grid integers
    FI f{};                    // float, ideal
    // Copy tag: this channel is bit for bit channel `ch` of what the plain lookup of op `tap`
    // returned (-1: none).
    int8_t tap = -1;
    uint8_t ch = 0;
};

// The register file of one evaluation: slots as ps11/decoded_program.h lays them out.
// Left uninitialised on construction (an evaluation is a few hundred nanoseconds, and
// constructing every channel was a fifth of it): IntervalEvaluator::run sets every slot its
// program names before the first instruction, and no other slot is read.
struct Regs {
    Regs() {}
    union {
        AV reg[exec::kNumSlots][4];
    };
};

// The whole range of a profile's register (what an unknown value can be after the write step).
AV wholeRange(const exec::Profile& p);

// What the write step of one instruction did to its channels (bit per channel): the range clamp
// to ±MaxValue acted on a value past it (without _sat), _sat cut a value outside [0, 1], or an
// fx profile rounded a value off its grid.
struct WriteFindings {
    uint8_t clamp = 0, saturate = 0, round = 0;
};

// An arithmetic instruction (mov … bem) into out[c] for the channels of op.mask; `findings`, when
// given, receives where the write step can act.
void evalArith(const exec::Profile& p, bool stagesKnown, const exec::DOp& op, const Regs& regs, AV out[4],
               WriteFindings* findings = nullptr);

}  // namespace ps11::intervals
