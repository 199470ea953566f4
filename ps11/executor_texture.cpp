// The executor, texture-address stage: texcoord/texcrd, tex/texld, texkill, texbem(l),
// texreg2*, the texm3x2*/texm3x3* families, texdp3(tex) and texdepth over a chunk of lanes.
// Coordinates are float32 (from TC and register values n/G); lookups go to the Sampler a whole
// chunk per instruction; results written from coordinates round and clamp like arithmetic.
#include <cmath>
#include <cstring>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include "ps11/executor_internal.h"
#include "ps11/executor_presampled_internal.h"

namespace ps11::exec {
namespace {

using Lanes = float[kChunk];

// Register component as float lanes (fx: n/G, correctly rounded), with _bx2 if given.
void regFloat(const Profile& p, const RunState& st, int slot, int comp, SrcMod mod, float* out) {
    const int n = st.n;
    if (isFixedPoint(p.precision)) {
        const int32_t* r = st.bi.reg[slot][comp];
        const float g = float(p.g);
        for (int i = 0; i < n; ++i) out[i] = float(r[i]) / g;
    } else {
        std::memcpy(out, st.bf.reg[slot][comp], sizeof(float) * size_t(n));
    }
    // Texture instructions accept only _bx2 (spec §2.3), 2x − 1.
    if (mod == SrcMod::Sign)
        for (int i = 0; i < n; ++i) out[i] = 2.0f * out[i] - 1.0f;
}

// Source component c of a texture instruction's operand (register or TC set), after swizzle.
void srcFloat(const Profile& p, const RunState& st, const DSrc& s, int comp, float* out) {
    if (s.kind == SrcKind::TexCoord)
        std::memcpy(out, texcoordLanes(st, s.slot, comp), sizeof(float) * size_t(st.n));
    else
        regFloat(p, st, s.slot, comp, s.mod, out);
}

// Writes float lanes to a register component: fx rounds to the grid (ties to even), then _sat
// and the range clamp, like an arithmetic result (docs/precision.md).
void writeFloat(const Profile& p, RunState& st, int slot, int comp, const float* in, bool sat) {
    const int n = st.n;
    if (isFixedPoint(p.precision)) {
        int32_t* d = st.bi.reg[slot][comp];
        const double g = p.g;
        const double lo = sat ? 0.0 : -double(p.nMax), hi = sat ? double(p.g < p.nMax ? p.g : p.nMax) : p.nMax;
        // Clamped first (lo and hi are integers and rounding is monotonic: the same result), then
        // rounded half to even by roundEvenSmall (|v| <= 2^24 here), a loop the compiler
        // vectorises where nearbyint is a call per lane. v·G is exact (24 + 12 bits).
        for (int i = 0; i < n; ++i) {
            double v = double(in[i]) * g;
            v = v > lo ? v : lo;  // NaN -> lo
            v = v < hi ? v : hi;
            d[i] = int32_t(roundEvenSmall(v));
        }
    } else {
        float* d = st.bf.reg[slot][comp];
        const float lo = p.clampRange ? -p.maxValue : -INFINITY, hi = p.clampRange ? p.maxValue : INFINITY;
        for (int i = 0; i < n; ++i) {
            float v = in[i];
            if (sat) {
                v = v > 0.0f ? v : 0.0f;
                v = v < 1.0f ? v : 1.0f;
            }
            v = v < lo ? lo : v;
            d[i] = v > hi ? hi : v;
        }
    }
}

void writeConst(const Profile& p, RunState& st, int slot, int comp, float value) {
    Lanes t;
    for (int i = 0; i < st.n; ++i) t[i] = value;
    writeFloat(p, st, slot, comp, t, false);
}

// One sampler call for the chunk; the texel lands directly in the destination register, then
// the register range clamp ±M applies (not in ideal).
void sampleInto(const Profile& p, RunState& st, int stage, int dims, const float* u, const float* v, const float* w,
                int slot) {
    SampleRequest req;
    req.stage = stage;
    req.count = st.n;
    req.quads = st.in->quads;
    req.dims = dims;
    req.u = u;
    req.v = v;
    req.w = w;
    req.precision = p.precision;
    req.lane = st.offset;
    req.plainRead = st.plainRead;
    SampleResult res;
    const int n = st.n;
    if (isFixedPoint(p.precision)) {
        for (int c = 0; c < 4; ++c) res.grid[c] = st.bi.reg[slot][c];
        st.sampler->sample(req, res);
        if (st.deferTexelClamp || (res.unitRange && p.nMax >= p.g)) return;
        const int32_t m = p.nMax;
        for (int c = 0; c < 4; ++c) {
            int32_t* d = st.bi.reg[slot][c];
            for (int i = 0; i < n; ++i) d[i] = d[i] < -m ? -m : (d[i] > m ? m : d[i]);
        }
    } else {
        for (int c = 0; c < 4; ++c) res.value[c] = st.bf.reg[slot][c];
        st.sampler->sample(req, res);
        if (p.clampRange && !(res.unitRange && p.maxValue >= 1.0f)) {
            const float m = p.maxValue;
            for (int c = 0; c < 4; ++c) {
                float* d = st.bf.reg[slot][c];
                int i = 0;
#if defined(__SSE2__)
                // Compare and select, so a NaN stays a NaN as in the scalar loop (MINPS/MAXPS
                // would replace it).
                const __m128 hi = _mm_set1_ps(m), lo = _mm_set1_ps(-m);
                for (; i + 4 <= n; i += 4) {
                    const __m128 v = _mm_loadu_ps(d + i);
                    const __m128 below = _mm_cmplt_ps(v, lo), above = _mm_cmpgt_ps(v, hi);
                    const __m128 inside = _mm_andnot_ps(_mm_or_ps(below, above), v);
                    _mm_storeu_ps(d + i, _mm_or_ps(inside, _mm_or_ps(_mm_and_ps(below, lo), _mm_and_ps(above, hi))));
                }
#endif
                for (; i < n; ++i) d[i] = d[i] < -m ? -m : (d[i] > m ? m : d[i]);
            }
        }
    }
}

// Static coordinates of TC[m] for tex/texbem(l), divided by the component projectionDivisor
// names when the stage projects.
void staticCoords(const Profile& p, const RunState& st, int m, float* u, float* v, float* w) {
    const int n = st.n;
    const float* tu = texcoordLanes(st, m, 0);
    const float* tv = texcoordLanes(st, m, 1);
    const float* tw = texcoordLanes(st, m, 2);
    const int divisor = projectionDivisor(p.stages[size_t(m)]);
    if (divisor >= 0) {
        const float* q = texcoordLanes(st, m, divisor);
        for (int i = 0; i < n; ++i) {
            u[i] = projectCoord(tu[i], q[i], false);
            v[i] = projectCoord(tv[i], q[i], false);
            w[i] = projectCoord(tw[i], q[i], false);
        }
    } else {
        std::memcpy(u, tu, sizeof(float) * size_t(n));
        std::memcpy(v, tv, sizeof(float) * size_t(n));
        std::memcpy(w, tw, sizeof(float) * size_t(n));
    }
}

// TC[row].xyz · T[n].rgb (with the source's _bx2), evaluated as ((x·r + y·g) + z·b).
void rowDot(const Profile& p, const RunState& st, int row, const DSrc& s, float* out) {
    Lanes r, g, b;
    regFloat(p, st, s.slot, 0, s.mod, r);
    regFloat(p, st, s.slot, 1, s.mod, g);
    regFloat(p, st, s.slot, 2, s.mod, b);
    const float* x = texcoordLanes(st, row, 0);
    const float* y = texcoordLanes(st, row, 1);
    const float* z = texcoordLanes(st, row, 2);
    for (int i = 0; i < st.n; ++i) out[i] = (x[i] * r[i] + y[i] * g[i]) + z[i] * b[i];
}

// 1_4 texld/texcrd coordinates: swizzled x, y and third component; _dz/_dw divide x and y
// by the raw z/w first, a zero divisor giving 1.0 (spec §2.4, §3.1).
void coords14(const Profile& p, const RunState& st, const DSrc& s, float* c0, float* c1, float* c2, float* c3) {
    // Only the components asked for, each straight into its output (the divisor apart).
    float* outs[4] = {c0, c1, c2, c3};
    for (int c = 0; c < 4; ++c)
        if (outs[c]) srcFloat(p, st, s, s.sw[size_t(c)], outs[c]);
    if (s.mod == SrcMod::Dz || s.mod == SrcMod::Dw) {
        Lanes d;
        srcFloat(p, st, s, s.mod == SrcMod::Dz ? 2 : 3, d);
        for (int i = 0; i < st.n; ++i) {
            c0[i] = projectCoord(c0[i], d[i], true);
            c1[i] = projectCoord(c1[i], d[i], true);
        }
    }
}

void execTexld(const Profile& p, const DOp& op, RunState& st) {
    Lanes u, v, w;
    coords14(p, st, op.src[0], u, v, w, nullptr);
    // D3DTTFF_PROJECTED is ignored in 1_4 (texld page).
    sampleInto(p, st, op.stage, 3, u, v, w, op.dstSlot);
}

void execTexcrd(const Profile& p, const DOp& op, RunState& st) {
    Lanes c[4];
    coords14(p, st, op.src[0], c[0], c[1], c[2], c[3]);
    // Unclamped to [0, 1] (texcrd page), but rounded and clamped to ±M like any result.
    for (int k = 0; k < 4; ++k)
        if ((op.mask >> k) & 1) writeFloat(p, st, op.dstSlot, k, c[k], op.sat);
}

void execTexcoord(const Profile& p, const DOp& op, RunState& st) {
    // (sat(u), sat(v), sat(w), 1): w = 1 (docs, DXVK, nine; spec §7.3).
    for (int c = 0; c < 3; ++c) writeFloat(p, st, op.dstSlot, c, texcoordLanes(st, op.stage, c), true);
    writeConst(p, st, op.dstSlot, 3, 1.0f);
}

void execTexkill(const Profile& p, const DOp& op, RunState& st) {
    // 1_1-1_3: TC[m].u, v, w (q ignored, spec §7.9); 1_4: the named register's x, y, z.
    Lanes t;
    for (int c = 0; c < 3; ++c) {
        srcFloat(p, st, op.src[0], c, t);
        for (int i = 0; i < st.n; ++i) st.killed[i] |= uint8_t(t[i] < 0.0f);
    }
}

void execTex(const Profile& p, const DOp& op, RunState& st) {
    if (projectionDivisor(p.stages[size_t(op.stage)]) < 0) {
        // Not projected: the coordinates are TC[m] as they are, no copy needed.
        sampleInto(p, st, op.stage, 3, texcoordLanes(st, op.stage, 0), texcoordLanes(st, op.stage, 1),
                   texcoordLanes(st, op.stage, 2), op.dstSlot);
        return;
    }
    Lanes u, v, w;
    staticCoords(p, st, op.stage, u, v, w);
    sampleInto(p, st, op.stage, 3, u, v, w, op.dstSlot);
}

void execTexbem(const Profile& p, const DOp& op, RunState& st) {
    // u' = u + M00·r + M10·g, v' = v + M01·r + M11·g with the bump matrix of the sampled stage m;
    // the static coordinate is projected first (Wine, DXVK, nine; spec §7.5).
    Lanes u, v, w, r, g;
    staticCoords(p, st, op.stage, u, v, w);
    regFloat(p, st, op.src[0].slot, 0, op.src[0].mod, r);
    regFloat(p, st, op.src[0].slot, 1, op.src[0].mod, g);
    const StageState& ss = p.stages[op.stage];
    const float m00 = ss.bumpMat[0], m01 = ss.bumpMat[1], m10 = ss.bumpMat[2], m11 = ss.bumpMat[3];
    for (int i = 0; i < st.n; ++i) {
        const float uu = u[i] + m00 * r[i] + m10 * g[i];
        const float vv = v[i] + m01 * r[i] + m11 * g[i];
        u[i] = uu;
        v[i] = vv;
        w[i] = 0.0f;
    }
    sampleInto(p, st, op.stage, 2, u, v, w, op.dstSlot);
}

void execTexbeml(const Profile& p, const DOp& op, RunState& st) {
    execTexbem(p, op, st);
    // L = T[n].b · LSCALE + LOFFSET, not clamped for ps_1_x texbeml (docs, Wine, nine; spec
    // §7.4), clamped to [0, 1] for the fixed-function stage (StageState::clampLuminance); every
    // channel is multiplied and rounded once.
    Lanes b;
    regFloat(p, st, op.src[0].slot, 2, op.src[0].mod, b);
    const StageState& ss = p.stages[op.stage];
    for (int i = 0; i < st.n; ++i) b[i] = b[i] * ss.lumScale + ss.lumOffset;
    if (ss.clampLuminance)
        for (int i = 0; i < st.n; ++i) b[i] = b[i] < 0.0f ? 0.0f : (b[i] > 1.0f ? 1.0f : b[i]);
    const int n = st.n;
    if (isFixedPoint(p.precision)) {
        const double m = p.nMax;
        for (int c = 0; c < 4; ++c) {
            int32_t* d = st.bi.reg[op.dstSlot][c];
            for (int i = 0; i < n; ++i) {
                double x = double(d[i]) * double(b[i]);  // exact: 25 + 24 bits
                x = x > -m ? x : -m;                     // NaN -> −M
                x = x < m ? x : m;
                d[i] = int32_t(roundEvenSmall(x));
            }
        }
    } else {
        const float lo = p.clampRange ? -p.maxValue : -INFINITY, hi = p.clampRange ? p.maxValue : INFINITY;
        for (int c = 0; c < 4; ++c) {
            float* d = st.bf.reg[op.dstSlot][c];
            for (int i = 0; i < n; ++i) {
                float x = d[i] * b[i];
                x = x < lo ? lo : x;
                d[i] = x > hi ? hi : x;
            }
        }
    }
}

void execTexreg2(const Profile& p, const DOp& op, RunState& st) {
    // texreg2ar (a, r, r), texreg2gb (g, b, b), texreg2rgb (r, g, b): the repeated third
    // coordinate follows DXVK and nine (spec §7.7).
    static constexpr int kAR[3] = {3, 0, 0}, kGB[3] = {1, 2, 2}, kRGB[3] = {0, 1, 2};
    const int* sel = op.op == Opcode::TexReg2AR ? kAR : op.op == Opcode::TexReg2GB ? kGB : kRGB;
    Lanes c[3];
    for (int k = 0; k < 3; ++k) regFloat(p, st, op.src[0].slot, sel[k], op.src[0].mod, c[k]);
    sampleInto(p, st, op.stage, 3, c[0], c[1], c[2], op.dstSlot);
}

void execTexm3x2pad(const Profile& p, const DOp& op, RunState& st) {
    rowDot(p, st, op.stage, op.src[0], st.pad[op.padIndex]);
}

void execTexm3x2tex(const Profile& p, const DOp& op, RunState& st) {
    Lanes v;
    rowDot(p, st, op.stage, op.src[0], v);
    sampleInto(p, st, op.stage, 2, st.pad[0], v, kZeroLanes, op.dstSlot);
}

void execTexm3x2depth(const Profile& p, const DOp& op, RunState& st) {
    // depth = (w == 0) ? 1 : z/w, clamped to [0, 1] (docs; the clamp as Wine, spec §7.8).
    Lanes w;
    rowDot(p, st, op.stage, op.src[0], w);
    for (int i = 0; i < st.n; ++i) {
        float d = w[i] == 0.0f ? 1.0f : st.pad[0][i] / w[i];
        d = d > 0.0f ? d : 0.0f;
        st.depth[i] = d < 1.0f ? d : 1.0f;
    }
    st.depthWritten = true;
}

void execTexm3x3tex(const Profile& p, const DOp& op, RunState& st) {
    Lanes w;
    rowDot(p, st, op.stage, op.src[0], w);
    sampleInto(p, st, op.stage, 3, st.pad[0], st.pad[1], w, op.dstSlot);
}

void execTexm3x3(const Profile& p, const DOp& op, RunState& st) {
    Lanes w;
    rowDot(p, st, op.stage, op.src[0], w);
    writeFloat(p, st, op.dstSlot, 0, st.pad[0], false);
    writeFloat(p, st, op.dstSlot, 1, st.pad[1], false);
    writeFloat(p, st, op.dstSlot, 2, w, false);
    writeConst(p, st, op.dstSlot, 3, 1.0f);
}

void execTexm3x3spec(const Profile& p, const DOp& op, RunState& st) {
    // R = 2·(N·E)/(N·N)·N − E, E not normalised (docs, nine; spec §7.6); N·N = 0 gives −E.
    Lanes nz, ex, ey, ez;
    rowDot(p, st, op.stage, op.src[0], nz);
    if (op.op == Opcode::TexM3x3Spec) {
        const auto& c = p.constF[op.src[1].slot];
        for (int i = 0; i < st.n; ++i) ex[i] = c[0], ey[i] = c[1], ez[i] = c[2];
    } else {
        // vspec: E = (TC[m].q, TC[m+1].q, TC[m+2].q).
        std::memcpy(ex, texcoordLanes(st, op.rowBase, 3), sizeof(float) * size_t(st.n));
        std::memcpy(ey, texcoordLanes(st, op.rowBase + 1, 3), sizeof(float) * size_t(st.n));
        std::memcpy(ez, texcoordLanes(st, op.rowBase + 2, 3), sizeof(float) * size_t(st.n));
    }
    Lanes ru, rv, rw;
    const float *nx = st.pad[0], *ny = st.pad[1];
    for (int i = 0; i < st.n; ++i) {
        const float ne = (nx[i] * ex[i] + ny[i] * ey[i]) + nz[i] * ez[i];
        const float nn = (nx[i] * nx[i] + ny[i] * ny[i]) + nz[i] * nz[i];
        const float f = nn == 0.0f ? 0.0f : 2.0f * ne / nn;
        ru[i] = f * nx[i] - ex[i];
        rv[i] = f * ny[i] - ey[i];
        rw[i] = f * nz[i] - ez[i];
    }
    sampleInto(p, st, op.stage, 3, ru, rv, rw, op.dstSlot);
}

void execTexdp3tex(const Profile& p, const DOp& op, RunState& st) {
    Lanes u;
    rowDot(p, st, op.stage, op.src[0], u);
    sampleInto(p, st, op.stage, 3, u, kZeroLanes, kZeroLanes, op.dstSlot);
}

void execTexdp3(const Profile& p, const DOp& op, RunState& st) {
    Lanes d;
    rowDot(p, st, op.stage, op.src[0], d);
    for (int c = 0; c < 4; ++c) writeFloat(p, st, op.dstSlot, c, d, false);
}

void execTexdepth(const Profile& p, const DOp& op, RunState& st) {
    // depth = (r5.g == 0) ? 1 : r5.r / r5.g, clamped to [0, 1] (texdepth page; clamp as Wine).
    Lanes r, g;
    regFloat(p, st, op.dstSlot, 0, SrcMod::None, r);
    regFloat(p, st, op.dstSlot, 1, SrcMod::None, g);
    for (int i = 0; i < st.n; ++i) {
        float d = g[i] == 0.0f ? 1.0f : r[i] / g[i];
        d = d > 0.0f ? d : 0.0f;
        st.depth[i] = d < 1.0f ? d : 1.0f;
    }
    st.depthWritten = true;
}

}  // namespace

void execTexture(const Profile& p, const DOp& op, RunState& st) {
    const bool v14 = p.minor >= 4;
    st.plainRead = op.plainRead;
    switch (op.op) {
        case Opcode::TexCoord: v14 ? execTexcrd(p, op, st) : execTexcoord(p, op, st); break;
        case Opcode::Tex: v14 ? execTexld(p, op, st) : execTex(p, op, st); break;
        case Opcode::TexKill: execTexkill(p, op, st); break;
        case Opcode::TexBem: execTexbem(p, op, st); break;
        case Opcode::TexBemL: execTexbeml(p, op, st); break;
        case Opcode::TexReg2AR:
        case Opcode::TexReg2GB:
        case Opcode::TexReg2RGB: execTexreg2(p, op, st); break;
        case Opcode::TexM3x2Pad:
        case Opcode::TexM3x3Pad: execTexm3x2pad(p, op, st); break;
        case Opcode::TexM3x2Tex: execTexm3x2tex(p, op, st); break;
        case Opcode::TexM3x2Depth: execTexm3x2depth(p, op, st); break;
        case Opcode::TexM3x3Tex: execTexm3x3tex(p, op, st); break;
        case Opcode::TexM3x3: execTexm3x3(p, op, st); break;
        case Opcode::TexM3x3Spec:
        case Opcode::TexM3x3VSpec: execTexm3x3spec(p, op, st); break;
        case Opcode::TexDp3Tex: execTexdp3tex(p, op, st); break;
        case Opcode::TexDp3: execTexdp3(p, op, st); break;
        case Opcode::TexDepth: execTexdepth(p, op, st); break;
        default: break;
    }
}

}  // namespace ps11::exec
