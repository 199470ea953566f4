// Interval evaluator, arithmetic instructions (mov add sub mul mad dp3 dp4 lrp cnd cmp bem): the
// bounds of the executor's fetch → op → write step (executor_arith_fx.inc for the fx profiles,
// executor_arith_float.inc for float and ideal), and the copy tags that pass through the exact
// identities of each profile (docs/intervals.md).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "ps11/intervals_internal.h"
#include "ps11/precision.h"

namespace ps11::intervals {
namespace {

using exec::DOp;
using exec::DSrc;
using exec::Profile;
using exec::SrcKind;

// One fetched source channel (selector, then modifier).
struct SV {
    KI k;             // fx: the exact value is k/(2G)
    FI f;             // float: the value
    int var = -1;     // the register channel read (slot·4 + component); -1 for a constant
    int8_t tap = -1;  // copy tag, kept only without a modifier
    uint8_t ch = 0;
    int32_t nlo = 0, nhi = 0;  // fx: the register's grid range (for the identities' clamp checks)
    SrcMod mod = SrcMod::None;
};

// Two fetched sources are one value in every run: the same register channel under the same
// modifier, or copies of the same lookup channel (copy tags are bit-exact).
bool sameValue(const SV& a, const SV& b) {
    return (a.var >= 0 && a.var == b.var && a.mod == b.mod) || (a.tap >= 0 && a.tap == b.tap && a.ch == b.ch);
}

// A float modifier over a range: the formulas are monotone, so they apply to the bounds.
FI modFloat(SrcMod m, const FI& x) {
    auto up = [&](bool nz) {
        return norm({exec::applySourceModifier(m, x.lo), exec::applySourceModifier(m, x.hi), x.nan, nz});
    };
    switch (m) {
        case SrcMod::Neg:
            return fNeg(x);
        case SrcMod::Bias:
            return up(false);  // x − 0.5 is 0 only as +0.0
        case SrcMod::BiasNeg:
            return fNeg(modFloat(SrcMod::Bias, x));
        case SrcMod::Sign:
            return up(false);
        case SrcMod::SignNeg:
            return fNeg(modFloat(SrcMod::Sign, x));
        case SrcMod::Comp:
            return norm({1.0f - x.hi, 1.0f - x.lo, x.nan, false});
        case SrcMod::X2:
            return up(x.nz);
        case SrcMod::X2Neg:
            return fNeg(modFloat(SrcMod::X2, x));
        default:
            return x;
    }
}

// Fx: fills k; float and ideal: fills f.
template <bool Fx>
SV fetch(const Profile& p, const Regs& regs, const DSrc& src, int c) {
    SV s;
    const int comp = src.sw[size_t(c)];
    if (src.kind == SrcKind::Const) {
        if constexpr (Fx) {
            const exec::SourceAffine af = exec::sourceAffine(src.mod, p.g);
            const int32_t n = p.constGrid[src.slot][size_t(comp)];
            s.k = kPoint(int64_t(af.a) * n + af.b);
            s.nlo = s.nhi = n;
        } else {
            s.f = fPoint(exec::applySourceModifier(src.mod, p.constF[src.slot][size_t(comp)]));
        }
        return s;
    }
    const AV& r = regs.reg[src.slot][comp];
    if constexpr (Fx) {
        const exec::SourceAffine af = exec::sourceAffine(src.mod, p.g);
        const int64_t a = int64_t(af.a) * r.nlo + af.b, b = int64_t(af.a) * r.nhi + af.b;
        s.k = {std::min(a, b), std::max(a, b)};
        s.nlo = r.nlo, s.nhi = r.nhi;
    } else {
        s.f = modFloat(src.mod, r.f);
    }
    s.var = src.slot * 4 + comp;
    s.mod = src.mod;
    if (src.mod == SrcMod::None) s.tap = r.tap, s.ch = r.ch;
    return s;
}

bool independent(const SV* s, int n) {
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j)
            if (s[i].var >= 0 && s[i].var == s[j].var) return false;
    return true;
}

// ---------------------------------------------------------------- fx
// mad whose sources share a register channel outside the product (the screen composite's
// t1·(1 − t0) + t0): each source is k = a·n + b of its channel's grid integer n, so the numerator
// k0·k1 + 2G·k2 is multilinear in the distinct channels and its extremes lie at the corners of
// their ranges (exact, where the independent bound adds the two t0 terms apart).
KI madCorners(const Profile& p, const SV* s) {
    int vars[3], nv = 0, which[3];
    for (int i = 0; i < 3; ++i) {
        which[i] = -1;
        if (s[i].var < 0) continue;
        for (int j = 0; j < nv; ++j)
            if (vars[j] == s[i].var) which[i] = j;
        if (which[i] < 0) which[i] = nv, vars[nv++] = s[i].var;
    }
    KI r{INT64_MAX, INT64_MIN};
    for (int m = 0; m < (1 << nv); ++m) {
        int64_t k[3];
        for (int i = 0; i < 3; ++i) {
            if (which[i] < 0) {
                k[i] = s[i].k.lo;  // a constant: one value
                continue;
            }
            const exec::SourceAffine af = exec::sourceAffine(s[i].mod, p.g);
            const int64_t n = (m >> which[i]) & 1 ? s[i].nhi : s[i].nlo;
            k[i] = int64_t(af.a) * n + af.b;
        }
        const int64_t v = k[0] * k[1] + 2 * int64_t(p.g) * k[2];
        r.lo = std::min(r.lo, v), r.hi = std::max(r.hi, v);
    }
    return r;
}

// The clamp bounds of the write step (executor_arith_fx.inc arithFx).
void fxClamp(const Profile& p, bool sat, int32_t& lo, int32_t& hi) {
    lo = sat ? (p.nMax < 0 ? p.nMax : 0) : -p.nMax;
    hi = sat ? (p.g < p.nMax ? p.g : p.nMax) : p.nMax;
}

// Write step of a numerator over d0 (2 for linear ops, 4G for products): shift, round once
// (roundHalfEven, monotone), _sat, range clamp — applied to both bounds.
void fxWrite(const Profile& p, const DOp& op, KI num, int64_t d0, AV& out, WriteFindings* wf = nullptr,
             uint8_t channels = 0) {
    int64_t den = d0;
    if (op.shift > 0) num.lo *= int64_t(1) << op.shift, num.hi *= int64_t(1) << op.shift;
    if (op.shift < 0) den <<= -op.shift;
    int32_t lo, hi;
    fxClamp(p, op.sat, lo, hi);
    if (wf) {
        const int64_t qlo = roundHalfEven(num.lo, den), qhi = roundHalfEven(num.hi, den);
        if (op.sat && (qlo < 0 || qhi > p.g)) wf->saturate |= channels;
        if (!op.sat && (qlo < -p.nMax || qhi > p.nMax)) wf->clamp |= channels;
        if (num.lo != num.hi || num.lo % den != 0) wf->round |= channels;
    }
    auto step = [&](int64_t v) {
        int64_t q = roundHalfEven(v, den);
        q = q < lo ? lo : q;
        return int32_t(q > hi ? hi : q);
    };
    out.nlo = step(num.lo);
    out.nhi = num.hi == num.lo ? out.nlo : step(num.hi);
}

// A per-component op passes source `pass` through exactly when k = 2n reaches the write step
// whole: adding k = 0, multiplying by k = 2G (1.0), lrp by 0 or 1, a decided cnd/cmp.
void arithFx(const Profile& p, const DOp& op, const Regs& regs, AV out[4], WriteFindings* wf) {
    const int64_t G = p.g, kOne = 2 * G, kLin = 2, kProd = 4 * G;
    if (op.op == Opcode::Dp3 || op.op == Opcode::Dp4) {
        // One sum of products (each bounded at its corners), written to every enabled channel.
        KI sum{0, 0};
        const uint8_t reads = componentsRead(*op.info, 0, op.mask);  // dp3 .rgb, dp4 .rgba
        for (int c = 0; c < 4; ++c)
            if ((reads >> c) & 1)
                sum = kAdd(sum, kMul(fetch<true>(p, regs, op.src[0], c).k, fetch<true>(p, regs, op.src[1], c).k));
        AV r;
        fxWrite(p, op, sum, kProd, r, wf, op.mask);
        for (int c = 0; c < 4; ++c)
            if ((op.mask >> c) & 1) out[c] = r;
        return;
    }
    for (int c = 0; c < 4; ++c) {
        if (!((op.mask >> c) & 1)) continue;
        SV s[3];
        for (int i = 0; i < op.numSrc; ++i) s[i] = fetch<true>(p, regs, op.src[size_t(i)], c);
        KI num{0, 0};
        int64_t d0 = kLin;
        int pass = -1;  // the source passed through exactly, if any
        switch (op.op) {
            case Opcode::Mov:
                num = s[0].k, pass = 0;
                break;
            case Opcode::Add:
                num = kAdd(s[0].k, s[1].k);
                pass = isPoint(s[1].k, 0) ? 0 : isPoint(s[0].k, 0) ? 1 : -1;
                break;
            case Opcode::Sub:
                num = kSub(s[0].k, s[1].k);
                pass = isPoint(s[1].k, 0) ? 0 : -1;
                break;
            case Opcode::Mul:
                num = kMul(s[0].k, s[1].k), d0 = kProd;
                pass = isPoint(s[1].k, kOne) ? 0 : isPoint(s[0].k, kOne) ? 1 : -1;
                break;
            case Opcode::Mad:
                num = kAdd(kMul(s[0].k, s[1].k), kMul(kPoint(2 * G), s[2].k)), d0 = kProd;
                if (!independent(s, 3) && !(s[0].var >= 0 && s[0].var == s[1].var))
                    num = kIntersect(num, madCorners(p, s));
                if (isPoint(s[0].k, 0) || isPoint(s[1].k, 0))
                    pass = 2;
                else if (isPoint(s[2].k, 0))
                    pass = isPoint(s[1].k, kOne) ? 0 : isPoint(s[0].k, kOne) ? 1 : -1;
                break;
            case Opcode::Lrp: {
                // (kf·(ka − kb) + 2G·kb) / (4G²): multilinear in kf, ka, kb, so over independent
                // sources its extremes are at the corners; otherwise two sound forms intersected.
                d0 = kProd;
                auto f = [&](int64_t kf, int64_t ka, int64_t kb) { return kf * (ka - kb) + 2 * G * kb; };
                if (sameValue(s[1], s[2])) {  // f·a + (1 − f)·a = a exactly
                    num = kMul(kPoint(2 * G), s[2].k), pass = 2;
                    break;
                }
                if (independent(s, 3)) {
                    num = kPoint(f(s[0].k.lo, s[1].k.lo, s[2].k.lo));
                    for (int m = 0; m < 8; ++m) {
                        const int64_t v = f(m & 1 ? s[0].k.hi : s[0].k.lo, m & 2 ? s[1].k.hi : s[1].k.lo,
                                            m & 4 ? s[2].k.hi : s[2].k.lo);
                        num.lo = std::min(num.lo, v), num.hi = std::max(num.hi, v);
                    }
                } else {
                    const KI a = kAdd(kMul(s[0].k, kSub(s[1].k, s[2].k)), kMul(kPoint(2 * G), s[2].k));
                    const KI b = kAdd(kMul(s[0].k, s[1].k), kMul(kSub(kPoint(2 * G), s[0].k), s[2].k));
                    num = kIntersect(a, b);
                }
                pass = isPoint(s[0].k, kOne) ? 1 : isPoint(s[0].k, 0) ? 2 : -1;
                break;
            }
            case Opcode::Cnd:
            case Opcode::Cmp: {
                // cnd: s0 > 0.5 ⟺ k0 > G; cmp: s0 >= 0 ⟺ k0 >= 0.
                const bool isCnd = op.op == Opcode::Cnd;
                const bool allTrue = isCnd ? s[0].k.lo > G : s[0].k.lo >= 0;
                const bool allFalse = isCnd ? s[0].k.hi <= G : s[0].k.hi < 0;
                if (allTrue || sameValue(s[1], s[2]))
                    num = s[1].k, pass = 1;
                else if (allFalse)
                    num = s[2].k, pass = 2;
                else
                    num = {std::min(s[1].k.lo, s[2].k.lo), std::max(s[1].k.hi, s[2].k.hi)};
                break;
            }
            default:
                break;
        }
        AV& r = out[c];
        r = AV{};
        fxWrite(p, op, num, d0, r, wf, uint8_t(1u << c));
        // The copy tag survives when the source is the register unmodified (k = 2n), nothing is
        // shifted, and the clamps of the write step cannot act on its range.
        if (pass >= 0 && s[pass].tap >= 0 && op.shift == 0) {
            int32_t lo, hi;
            fxClamp(p, op.sat, lo, hi);
            if (s[pass].nlo >= lo && s[pass].nhi <= hi) r.tap = s[pass].tap, r.ch = s[pass].ch;
        }
    }
}

// bem (1_4): d.r = a.r + M00·b.r + M10·b.g, d.g = a.g + M01·b.r + M11·b.g in double, rounded
// once with nearbyint (executor_arith_fx.inc). Every step is monotone in each input (the matrix
// fixed), so the extremes are at the corners of the box.
void bemFx(const Profile& p, bool stagesKnown, const DOp& op, const Regs& regs, AV out[4], WriteFindings* wf) {
    int32_t lo, hi;
    fxClamp(p, op.sat, lo, hi);
    const StageState& ss = p.stages[op.stage];
    bool finiteMatrix = stagesKnown;
    for (float m : ss.bumpMat) finiteMatrix = finiteMatrix && std::isfinite(m);
    const double scale = std::ldexp(0.5, op.shift);
    const SV br = fetch<true>(p, regs, op.src[1], 0), bg = fetch<true>(p, regs, op.src[1], 1);
    for (int c = 0; c < 2; ++c) {
        if (!((op.mask >> c) & 1)) continue;
        AV& r = out[c];
        r = AV{};
        if (!finiteMatrix) {  // any matrix: any value the clamps leave
            r.nlo = lo, r.nhi = hi;
            if (wf) (op.sat ? wf->saturate : wf->clamp) |= uint8_t(1u << c);
            continue;
        }
        const SV a = fetch<true>(p, regs, op.src[0], c);
        const double mr = c == 0 ? ss.bumpMat[0] : ss.bumpMat[1], mg = c == 0 ? ss.bumpMat[2] : ss.bumpMat[3];
        double vlo = INFINITY, vhi = -INFINITY;
        for (int m = 0; m < 8; ++m) {
            const int64_t ka = m & 1 ? a.k.hi : a.k.lo, kr = m & 2 ? br.k.hi : br.k.lo, kg = m & 4 ? bg.k.hi : bg.k.lo;
            const double exact = (double(ka) + mr * double(kr) + mg * double(kg)) * scale;
            double v = std::nearbyint(exact);
            if (wf && (v < lo || v > hi)) (op.sat ? wf->saturate : wf->clamp) |= uint8_t(1u << c);
            if (wf && v != exact) wf->round |= uint8_t(1u << c);
            v = v < lo ? lo : (v > hi ? hi : v);
            vlo = std::min(vlo, v), vhi = std::max(vhi, v);
        }
        r.nlo = int32_t(vlo), r.nhi = int32_t(vhi);
    }
}

// ---------------------------------------------------------------- float, ideal
// Write step (executor_arith_float.inc finishFloat): ·2^shift, _sat, range clamp; each monotone,
// NaN becomes 0 under _sat and stays NaN otherwise.
FI floatWrite(const Profile& p, const DOp& op, FI v, WriteFindings* wf = nullptr, uint8_t channels = 0) {
    static constexpr float kScale[7] = {0.125f, 0.25f, 0.5f, 1.0f, 2.0f, 4.0f, 8.0f};  // 2^shift, exact
    const float scale = kScale[op.shift + 3];
    const float lo = p.clampRange ? -p.maxValue : -kInf, hi = p.clampRange ? p.maxValue : kInf;
    FI s{v.lo * scale, v.hi * scale, v.nan, v.nz};
    // A negative value too small for the down-shift becomes −0.0.
    if (scale < 1.0f && v.lo < 0.0f &&
        (v.hi < -std::numeric_limits<float>::denorm_min() ? v.hi : -std::numeric_limits<float>::denorm_min()) * scale ==
            0.0f)
        s.nz = true;
    if (wf) {
        if (op.sat && (s.nan || s.lo < 0.0f || s.hi > 1.0f)) wf->saturate |= channels;
        if (!op.sat && (s.lo < lo || s.hi > hi)) wf->clamp |= channels;
    }
    if (op.sat) {
        auto f = [&](float x) {
            x = x > 0.0f ? x : 0.0f;
            x = x < 1.0f ? x : 1.0f;
            x = x < lo ? lo : x;
            return x > hi ? hi : x;
        };
        FI r{f(s.lo), f(s.hi), false, false};
        if (s.nan) r.lo = std::min(r.lo, f(0.0f)), r.hi = std::max(r.hi, f(0.0f));
        return r;
    }
    auto f = [&](float x) {
        x = x < lo ? lo : x;
        return x > hi ? hi : x;
    };
    return norm({f(s.lo), f(s.hi), s.nan, s.nz});
}

// b + f·(a − b) over independent sources: the real lerp is multilinear (extremes at the corners)
// and the float one is within E of it: |fl(b + fl(f·fl(a − b))) − L| <= 3u·|f(a − b)| + u·|b| plus
// an underflow, u = 2^-24; E below is larger (2^-21, covering the double corners too).
FI lrpRefine(const SV* s, FI steps) {
    // Finite steps also mean no operation overflowed for any input of the box.
    if (!finite(s[0].f) || !finite(s[1].f) || !finite(s[2].f) || !finite(steps) || !independent(s, 3)) return steps;
    double lo = INFINITY, hi = -INFINITY;
    for (int m = 0; m < 8; ++m) {
        const double f = m & 1 ? s[0].f.hi : s[0].f.lo, a = m & 2 ? s[1].f.hi : s[1].f.lo,
                     b = m & 4 ? s[2].f.hi : s[2].f.lo;
        const double v = b + f * (a - b);
        lo = std::min(lo, v), hi = std::max(hi, v);
    }
    auto mag = [](const FI& x) { return std::max(std::fabs(double(x.lo)), std::fabs(double(x.hi))); };
    const double e = (mag(s[2].f) + mag(s[0].f) * (mag(s[1].f) + mag(s[2].f))) * 0x1p-21 + 0x1p-140;
    steps.lo = std::max(steps.lo, ceilToFloat(lo - e));
    steps.hi = std::min(steps.hi, floorToFloat(hi + e));
    return norm(steps);
}

void arithFloat(const Profile& p, bool stagesKnown, const DOp& op, const Regs& regs, AV out[4], WriteFindings* wf) {
    if (op.op == Opcode::Dp3 || op.op == Opcode::Dp4) {
        // ((a.r·b.r + a.g·b.g) + a.b·b.b) (+ a.a·b.a), as the executor evaluates it.
        auto term = [&](int c) {
            return fMul(fetch<false>(p, regs, op.src[0], c).f, fetch<false>(p, regs, op.src[1], c).f);
        };
        FI sum = fAdd(fAdd(term(0), term(1)), term(2));
        if (op.op == Opcode::Dp4) sum = fAdd(sum, term(3));
        AV r;
        r.f = floatWrite(p, op, sum, wf, op.mask);
        for (int c = 0; c < 4; ++c)
            if ((op.mask >> c) & 1) out[c] = r;
        return;
    }
    if (op.op == Opcode::Bem) {
        // a + (Mr·b.r + Mg·b.g) in float32; an unknown matrix gives anything.
        const StageState& ss = p.stages[op.stage];
        const FI br = fetch<false>(p, regs, op.src[1], 0).f, bg = fetch<false>(p, regs, op.src[1], 1).f;
        for (int c = 0; c < 2; ++c) {
            if (!((op.mask >> c) & 1)) continue;
            const float mr = c == 0 ? ss.bumpMat[0] : ss.bumpMat[1], mg = c == 0 ? ss.bumpMat[2] : ss.bumpMat[3];
            const FI v = stagesKnown ? fAdd(fetch<false>(p, regs, op.src[0], c).f,
                                            fAdd(fMul(fPoint(mr), br), fMul(fPoint(mg), bg)))
                                     : fTop();
            out[c] = AV{};
            out[c].f = floatWrite(p, op, v, wf, uint8_t(1u << c));
        }
        return;
    }
    for (int c = 0; c < 4; ++c) {
        if (!((op.mask >> c) & 1)) continue;
        SV s[3];
        for (int i = 0; i < op.numSrc; ++i) s[i] = fetch<false>(p, regs, op.src[size_t(i)], c);
        const FI &x = s[0].f, &y = s[1].f, &z = s[2].f;
        // An exact zero of either sign: a + ±0 is a unless a is −0.0 (−0 + +0 = +0).
        auto zero = [](const FI& v) { return isPoint(v, 0.0f); };
        FI v;
        int pass = -1;
        switch (op.op) {
            case Opcode::Mov:
                v = x, pass = 0;
                break;
            case Opcode::Add:
                v = fAdd(x, y);
                pass = zero(y) && !x.nz ? 0 : zero(x) && !y.nz ? 1 : -1;
                break;
            case Opcode::Sub:
                // a − (+0) = a + (−0) = a always; a − (−0) = a + (+0) needs a not −0.0.
                v = fSub(x, y);
                pass = zero(y) && (!y.nz || !x.nz) ? 0 : -1;
                break;
            case Opcode::Mul:
                v = fMul(x, y);
                pass = isPoint(y, 1.0f) ? 0 : isPoint(x, 1.0f) ? 1 : -1;  // a·1 = a, −0.0 included
                break;
            case Opcode::Mad:
                v = fAdd(fMul(x, y), z);
                if (((zero(x) && finite(y)) || (zero(y) && finite(x))) && !z.nz)
                    pass = 2;  // ±0 + c
                else if (zero(z) && isPoint(y, 1.0f) && !x.nz)
                    pass = 0;
                else if (zero(z) && isPoint(x, 1.0f) && !y.nz)
                    pass = 1;
                break;
            case Opcode::Lrp: {
                // b + (±0) is b when b is never −0.0: f exactly 0 with a − b finite, or a and b
                // one finite value (a − a = +0) with f finite. f = 1 is not exact in float.
                const FI d = fSub(y, z);
                if ((zero(x) && finite(d) && !z.nz) || (sameValue(s[1], s[2]) && finite(z) && finite(x) && !z.nz)) {
                    v = z, pass = 2;
                    break;
                }
                v = lrpRefine(s, fAdd(z, fMul(x, d)));
                break;
            }
            case Opcode::Cnd:
            case Opcode::Cmp: {
                // cnd: s0 > 0.5; cmp: s0 >= 0 (−0.0 >= 0); a NaN condition takes the second source.
                const bool isCnd = op.op == Opcode::Cnd;
                const bool allTrue = !x.nan && (isCnd ? x.lo > 0.5f : x.lo >= 0.0f);
                const bool allFalse = isCnd ? x.hi <= 0.5f : x.hi < 0.0f;
                if (allTrue || sameValue(s[1], s[2]))
                    v = y, pass = 1;
                else if (allFalse)
                    v = z, pass = 2;
                else
                    v = fHull(y, z);
                break;
            }
            default:
                v = fTop();
                break;
        }
        AV& r = out[c];
        r = AV{};
        r.f = floatWrite(p, op, v, wf, uint8_t(1u << c));
        // The copy tag survives an exact identity when nothing is shifted and the write step
        // leaves the value alone: _sat turns −0.0 into +0.0, the clamp acts outside [−M, M].
        if (pass >= 0 && s[pass].tap >= 0 && op.shift == 0) {
            const FI& t = s[pass].f;
            const float lo = p.clampRange ? -p.maxValue : -kInf, hi = p.clampRange ? p.maxValue : kInf;
            bool keeps = !t.nan && t.lo >= lo && t.hi <= hi;
            if (op.sat) keeps = keeps && t.lo >= 0.0f && t.hi <= 1.0f && !t.nz;
            if (keeps) r.tap = s[pass].tap, r.ch = s[pass].ch;
        }
    }
}

}  // namespace

void evalArith(const Profile& p, bool stagesKnown, const DOp& op, const Regs& regs, AV out[4], WriteFindings* wf) {
    if (isFixedPoint(p.precision)) {
        if (op.op == Opcode::Bem)
            bemFx(p, stagesKnown, op, regs, out, wf);
        else
            arithFx(p, op, regs, out, wf);
    } else {
        arithFloat(p, stagesKnown, op, regs, out, wf);
    }
}

}  // namespace ps11::intervals
