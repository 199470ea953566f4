// The executor, arithmetic stage: fetch (selector, then modifier) → op → write step (shift,
// round once, _sat, range clamp) for mov add sub mul mad dp3 dp4 lrp cnd cmp bem, over a chunk
// of lanes, exactly as docs/precision.md says, for the fx profiles: int32 grid integers, each
// result formed as an exact integer numerator (int32 or int64 lanes). The float profiles'
// float32 stage is executor_arith_float.inc.
#include <cmath>
#include <cstring>

#include "ps11/executor_internal.h"

namespace ps11::exec {
namespace {

void fetchFx(const Profile& p, const DOp& op, RunState& st) {
    const int n = st.n;
    for (int s = 0; s < op.numSrc; ++s) {
        const uint8_t fm = fetchMask(op, s);
        const DSrc& src = op.src[size_t(s)];
        const SourceAffine af = sourceAffine(src.mod, p.g);
        for (int c = 0; c < 4; ++c) {
            if (!((fm >> c) & 1)) continue;
            int32_t* k = st.k[s][c];
            if (src.kind == SrcKind::Const) {
                const int32_t v = af.a * p.constGrid[src.slot][src.sw[size_t(c)]] + af.b;
                for (int i = 0; i < n; ++i) k[i] = v;
            } else {
                const int32_t* r = st.bi.reg[src.slot][src.sw[size_t(c)]];
                const int32_t a = af.a, b = af.b;
                for (int i = 0; i < n; ++i) k[i] = a * r[i] + b;
            }
        }
    }
}

// round_half_even(num / D) for a constant D > 0 (floor division, then the tie rule), clamped to
// [lo, hi]; the only rounding of an fx instruction (docs/precision.md step 2).
template <class W, int64_t D>
inline int32_t roundClamp(W num, int32_t lo, int32_t hi) {
    W q = num / W(D);
    W r = num - q * W(D);
    const W neg = W(r < 0);
    q -= neg;
    r += neg * W(D);
    const W twice = r * 2;
    q += W(twice > W(D)) | (W(twice == W(D)) & (q & 1));
    q = q < W(lo) ? W(lo) : q;
    q = q > W(hi) ? W(hi) : q;
    return int32_t(q);
}

template <class W, int64_t D, int SH, class F>
void finishLoop(int n, int32_t* __restrict out, const F& f, int32_t lo, int32_t hi) {
    for (int i = 0; i < n; ++i) out[i] = roundClamp<W, D>(W(f(i)) * W(int64_t(1) << SH), lo, hi);
}

// Write step for a numerator over D0 (2 for linear ops, 4G for products): the shift multiplies
// the numerator or the denominator by 2^|s|, so the result stays exact before the one rounding.
template <class W, int64_t D0, class F>
void finish(int shift, int n, int32_t* out, const F& f, int32_t lo, int32_t hi) {
    switch (shift) {
        case 1: finishLoop<W, D0, 1>(n, out, f, lo, hi); break;
        case 2: finishLoop<W, D0, 2>(n, out, f, lo, hi); break;
        case 3: finishLoop<W, D0, 3>(n, out, f, lo, hi); break;
        case -1: finishLoop<W, D0 * 2, 0>(n, out, f, lo, hi); break;
        case -2: finishLoop<W, D0 * 4, 0>(n, out, f, lo, hi); break;
        case -3: finishLoop<W, D0 * 8, 0>(n, out, f, lo, hi); break;
        default: finishLoop<W, D0, 0>(n, out, f, lo, hi); break;
    }
}

template <class W, int32_t G>
void arithFx(const Profile& p, const DOp& op, RunState& st, int32_t (*out)[kChunk]) {
    fetchFx(p, op, st);
    const int n = st.n;
    const int32_t lo = op.sat ? (p.nMax < 0 ? p.nMax : 0) : -p.nMax;
    const int32_t hi = op.sat ? (G < p.nMax ? G : p.nMax) : p.nMax;
    // value = K / (2G) -> n = K·2^s / 2. Linear numerators (mov add sub cnd cmp: at most two
    // terms of |k| <= 4·max(nMax, G) + 2G, nMax <= kMaxGridBound = 2^24, times 2^3: at most
    // 2^30 + 32G) stay below 2^31, so they take int32 lanes in every profile; products take W.
    constexpr int64_t kLin = 2;
    constexpr int64_t kProd = 4 * int64_t(G);  // value = P / (4G²) -> n = P·2^s / (4G)
    const int sh = op.shift;
    auto& k = st.k;
    if (op.op == Opcode::Dp3 || op.op == Opcode::Dp4) {
        // One sum, written to every enabled component (replicated).
        const int32_t *a0 = k[0][0], *a1 = k[0][1], *a2 = k[0][2], *a3 = k[0][3];
        const int32_t *b0 = k[1][0], *b1 = k[1][1], *b2 = k[1][2], *b3 = k[1][3];
        int first = -1;
        for (int c = 0; c < 4; ++c) {
            if (!((op.mask >> c) & 1)) continue;
            if (first >= 0) {
                std::memcpy(out[c], out[first], sizeof(int32_t) * size_t(n));
                continue;
            }
            first = c;
            if (op.op == Opcode::Dp3)
                finish<W, kProd>(sh, n, out[c],
                                 [=](int i) { return W(a0[i]) * b0[i] + W(a1[i]) * b1[i] + W(a2[i]) * b2[i]; }, lo, hi);
            else
                finish<W, kProd>(sh, n, out[c], [=](int i) {
                    return W(a0[i]) * b0[i] + W(a1[i]) * b1[i] + W(a2[i]) * b2[i] + W(a3[i]) * b3[i];
                }, lo, hi);
        }
        return;
    }
    if (op.op == Opcode::Bem) {
        // bem (1_4): d.r = a.r + M00·b.r + M10·b.g, d.g = a.g + M01·b.r + M11·b.g with the bump
        // matrix of the destination's stage (spec §2.2), evaluated in double and rounded once.
        const StageState& ss = p.stages[op.stage];
        const double m00 = ss.bumpMat[0], m01 = ss.bumpMat[1], m10 = ss.bumpMat[2], m11 = ss.bumpMat[3];
        const double scale = std::ldexp(0.5, sh);  // K/(2G)·2^s·G
        for (int c = 0; c < 2; ++c) {
            if (!((op.mask >> c) & 1)) continue;
            const double mr = c == 0 ? m00 : m01, mg = c == 0 ? m10 : m11;
            const int32_t *a = k[0][c], *br = k[1][0], *bg = k[1][1];
            for (int i = 0; i < n; ++i) {
                double v = std::nearbyint((double(a[i]) + mr * br[i] + mg * bg[i]) * scale);
                v = v < lo ? lo : (v > hi ? hi : v);  // NaN cannot occur: finite matrix assumed
                out[c][i] = v == v ? int32_t(v) : 0;
            }
        }
        return;
    }
    for (int c = 0; c < 4; ++c) {
        if (!((op.mask >> c) & 1)) continue;
        const int32_t *s0 = k[0][c], *s1 = k[1][c], *s2 = k[2][c];
        int32_t* o = out[c];
        switch (op.op) {
            case Opcode::Mov: finish<int32_t, kLin>(sh, n, o, [=](int i) { return W(s0[i]); }, lo, hi); break;
            case Opcode::Add: finish<int32_t, kLin>(sh, n, o, [=](int i) { return W(s0[i]) + s1[i]; }, lo, hi); break;
            case Opcode::Sub: finish<int32_t, kLin>(sh, n, o, [=](int i) { return W(s0[i]) - s1[i]; }, lo, hi); break;
            case Opcode::Mul: finish<W, kProd>(sh, n, o, [=](int i) { return W(s0[i]) * s1[i]; }, lo, hi); break;
            case Opcode::Mad:
                finish<W, kProd>(sh, n, o, [=](int i) { return W(s0[i]) * s1[i] + W(2 * G) * s2[i]; }, lo, hi);
                break;
            case Opcode::Lrp:
                // f·a + (1 − f)·b = (kf·(ka − kb) + 2G·kb) / (4G²)
                finish<W, kProd>(sh, n, o, [=](int i) { return W(s0[i]) * (W(s1[i]) - s2[i]) + W(2 * G) * s2[i]; },
                                 lo, hi);
                break;
            case Opcode::Cnd:
                // s0 > 0.5 ⟺ k0 > G (1_1-1_3: s0 is r0.a replicated, see create()).
                finish<int32_t, kLin>(sh, n, o, [=](int i) { return W(s0[i] > G ? s1[i] : s2[i]); }, lo, hi);
                break;
            case Opcode::Cmp:
                finish<int32_t, kLin>(sh, n, o, [=](int i) { return W(s0[i] >= 0 ? s1[i] : s2[i]); }, lo, hi);
                break;
            default: break;
        }
    }
}

}  // namespace

void execArithFx(const Profile& p, const DOp& op, RunState& st, int32_t (*out)[kChunk]) {
    if (p.g == 255) {
        if (p.wide)
            arithFx<int64_t, 255>(p, op, st, out);
        else
            arithFx<int32_t, 255>(p, op, st, out);
    } else if (p.wide) {
        arithFx<int64_t, 4080>(p, op, st, out);
    } else {
        arithFx<int32_t, 4080>(p, op, st, out);
    }
}

}  // namespace ps11::exec
