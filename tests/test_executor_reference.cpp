// An independent reference for the executor's arithmetic (docs/precision.md), written from the
// document only, and a random-program differential test against ps11::Executor.
//
// fx8/fx12: every source component becomes an exact k/(2G) (modifier table), every instruction
// an exact rational R (op table) that is shifted, rounded ONCE with round_half_even in 64-bit
// integers, saturated, clamped to ±round(M·G) and masked. float/ideal: the float32 formulas of
// the document in the same operation order (every product and sum forced through a volatile
// float so the compiler cannot contract or widen). Programs are generated as TEXT from a small
// structured form that this file evaluates itself; ps11::validate filters out invalid ones.
// Nothing here includes or calls executor internals: only parseAssembly, validate and the public
// Executor interface.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "executor_random_programs.h"
#include "ps11/assembler.h"
#include "ps11/executor.h"
#include "ps11/validator.h"
#include "simd_levels.h"

namespace {

using i64 = int64_t;

// ---------------------------------------------------------------- exact helpers
i64 rheDiv(i64 num, i64 den) {  // round_half_even(num / den), den > 0
    i64 q = num / den, r = num % den;
    if (r < 0) r += den, q -= 1;
    i64 twice = 2 * r;
    if (twice > den || (twice == den && (q & 1))) ++q;
    return q;
}
// round_half_even(v * G) for a double v, exact: v is a float (24 bits) and G < 2^13.
i64 gridOf(double v, i64 G) {
    double x = v * double(G);  // exact
    double f = std::floor(x);
    double d = x - f;
    i64 n = i64(f);
    if (d > 0.5 || (d == 0.5 && (n & 1))) ++n;
    return n;
}

float fmulv(float a, float b) {
    volatile float r = a * b;
    return r;
}
float faddv(float a, float b) {
    volatile float r = a + b;
    return r;
}
float fsubv(float a, float b) {
    volatile float r = a - b;
    return r;
}

using namespace execrand;

// ---------------------------------------------------------------- fx reference
struct FxRef {
    i64 G;
    i64 bound;  // round(M·G)
    int minor;
    i64 r[6][4] = {}, c[8][4] = {}, v[2][4] = {}, t[8][4] = {};

    i64 (*regs(RegT t_))[4] {
        switch (t_) {
            case R: return r;
            case C: return c;
            case V: return v;
            default: return t;
        }
    }
    i64 k(const Src& s, int comp) {
        i64 n = regs(s.type)[s.index][s.sel >= 0 ? s.sel : comp];
        switch (s.mod) {
            case 0: return 2 * n;
            case 1: return -2 * n;
            case 2: return 2 * n - G;
            case 3: return G - 2 * n;
            case 4: return 4 * n - 2 * G;
            case 5: return 2 * G - 4 * n;
            case 6: return 2 * G - 2 * n;
            case 7: return 4 * n;
            default: return -4 * n;
        }
    }
    // Write step 1-4 for an exact numerator over den (2G or 4G²).
    i64 finish(i64 num, i64 den, const Ins& in) {
        // n = round_half_even(num/den · 2^s · G)
        i64 nume = num * G, dene = den;
        if (in.shift > 0) nume *= (i64(1) << in.shift);
        if (in.shift < 0) dene *= (i64(1) << -in.shift);
        i64 n = rheDiv(nume, dene);
        if (in.sat) n = std::clamp<i64>(n, 0, G);
        return std::clamp<i64>(n, -bound, bound);
    }
    std::array<i64, 4> eval(const Ins& in) {
        std::array<i64, 4> out{};
        const i64 d1 = 2 * G, d2 = 4 * G * G;
        i64 dot = 0;
        if (in.op == DP3 || in.op == DP4)
            for (int cc = 0; cc < (in.op == DP3 ? 3 : 4); ++cc) dot += k(in.s[0], cc) * k(in.s[1], cc);
        for (int cc = 0; cc < 4; ++cc) {
            i64 num = 0, den = d1;
            switch (in.op) {
                case MOV: num = k(in.s[0], cc); break;
                case ADD: num = k(in.s[0], cc) + k(in.s[1], cc); break;
                case SUB: num = k(in.s[0], cc) - k(in.s[1], cc); break;
                case MUL: num = k(in.s[0], cc) * k(in.s[1], cc), den = d2; break;
                case MAD: num = k(in.s[0], cc) * k(in.s[1], cc) + 2 * G * k(in.s[2], cc), den = d2; break;
                case DP3:
                case DP4: num = dot, den = d2; break;
                case LRP: {
                    i64 kf = k(in.s[0], cc), ka = k(in.s[1], cc), kb = k(in.s[2], cc);
                    num = kf * (ka - kb) + 2 * G * kb, den = d2;
                    break;
                }
                case CND: num = k(in.s[0], cc) > G ? k(in.s[1], cc) : k(in.s[2], cc); break;
                case CMP: num = k(in.s[0], cc) >= 0 ? k(in.s[1], cc) : k(in.s[2], cc); break;
                default: break;
            }
            out[cc] = finish(num, den, in);
        }
        return out;
    }
    void write(const Ins& in, const std::array<i64, 4>& val) {
        for (int cc = 0; cc < 4; ++cc)
            if (in.mask & (1 << cc)) regs(in.dtype)[in.dindex][cc] = val[cc];
    }
};

// ---------------------------------------------------------------- float reference
struct FloatRef {
    bool ideal;
    float M;
    int minor;
    float r[6][4] = {}, c[8][4] = {}, v[2][4] = {}, t[8][4] = {};

    float (*regs(RegT t_))[4] {
        switch (t_) {
            case R: return r;
            case C: return c;
            case V: return v;
            default: return t;
        }
    }
    float x(const Src& s, int comp) {
        float a = regs(s.type)[s.index][s.sel >= 0 ? s.sel : comp];
        switch (s.mod) {
            case 0: return a;
            case 1: return -a;
            case 2: return fsubv(a, 0.5f);
            case 3: return -fsubv(a, 0.5f);
            case 4: return fsubv(fmulv(2.0f, a), 1.0f);
            case 5: return -fsubv(fmulv(2.0f, a), 1.0f);
            case 6: return fsubv(1.0f, a);
            case 7: return fmulv(2.0f, a);
            default: return -fmulv(2.0f, a);
        }
    }
    std::array<float, 4> eval(const Ins& in) {
        std::array<float, 4> out{};
        float dot = 0;
        if (in.op == DP3 || in.op == DP4) {
            dot = faddv(fmulv(x(in.s[0], 0), x(in.s[1], 0)), fmulv(x(in.s[0], 1), x(in.s[1], 1)));
            dot = faddv(dot, fmulv(x(in.s[0], 2), x(in.s[1], 2)));
            if (in.op == DP4) dot = faddv(dot, fmulv(x(in.s[0], 3), x(in.s[1], 3)));
        }
        for (int cc = 0; cc < 4; ++cc) {
            float res = 0;
            switch (in.op) {
                case MOV: res = x(in.s[0], cc); break;
                case ADD: res = faddv(x(in.s[0], cc), x(in.s[1], cc)); break;
                case SUB: res = fsubv(x(in.s[0], cc), x(in.s[1], cc)); break;
                case MUL: res = fmulv(x(in.s[0], cc), x(in.s[1], cc)); break;
                case MAD: res = faddv(fmulv(x(in.s[0], cc), x(in.s[1], cc)), x(in.s[2], cc)); break;
                case DP3:
                case DP4: res = dot; break;
                case LRP: {
                    float f = x(in.s[0], cc), a = x(in.s[1], cc), b = x(in.s[2], cc);
                    res = faddv(b, fmulv(f, fsubv(a, b)));
                    break;
                }
                case CND: res = x(in.s[0], cc) > 0.5f ? x(in.s[1], cc) : x(in.s[2], cc); break;
                case CMP: res = x(in.s[0], cc) >= 0.0f ? x(in.s[1], cc) : x(in.s[2], cc); break;
                default: break;
            }
            res = fmulv(res, std::ldexp(1.0f, in.shift));
            if (in.sat) res = std::clamp(res, 0.0f, 1.0f);
            if (!ideal) res = std::clamp(res, -M, M);
            out[cc] = res;
        }
        return out;
    }
    void write(const Ins& in, const std::array<float, 4>& val) {
        for (int cc = 0; cc < 4; ++cc)
            if (in.mask & (1 << cc)) regs(in.dtype)[in.dindex][cc] = val[cc];
    }
};

// Runs the reference on one pixel. fx: grid integers of r0; float: r0 values.
std::array<i64, 4> runFx(const Prog& p, const Inputs& in, ps11::Precision prec, float M) {
    FxRef ref;
    ref.G = ps11::gridScale(prec);
    ref.bound = gridOf(M, ref.G);
    ref.minor = p.minor;
    for (int i = 0; i < 8; ++i)
        for (int cc = 0; cc < 4; ++cc) ref.c[i][cc] = gridOf(std::clamp(in.consts[i][cc], -1.0f, 1.0f), ref.G);
    for (size_t d = 0; d < p.defs.size(); ++d)
        for (int cc = 0; cc < 4; ++cc)
            ref.c[p.defIndex[d]][cc] = gridOf(std::clamp(p.defs[d][cc], -1.0f, 1.0f), ref.G);
    for (int i = 0; i < 2; ++i)
        for (int cc = 0; cc < 4; ++cc) ref.v[i][cc] = gridOf(std::clamp(in.color[i][cc], 0.0f, 1.0f), ref.G);
    for (const TexIns& t : p.tex) {
        if (p.minor < 4) {  // texcoord: (sat u, sat v, sat w, 1)
            for (int cc = 0; cc < 3; ++cc) ref.t[t.tindex][cc] = gridOf(std::clamp(in.tc[t.tindex][cc], 0.0f, 1.0f), ref.G);
            ref.t[t.tindex][3] = ref.G;
        } else {  // texcrd: (x, y, z|w), rounded and clamped like an arithmetic result
            const int srcComp[3] = {0, 1, t.xyw ? 3 : 2};
            for (int cc = 0; cc < 3; ++cc)
                if (t.mask & (1 << cc))
                    ref.r[t.dindex][cc] =
                        std::clamp<i64>(gridOf(in.tc[t.tindex][srcComp[cc]], ref.G), -ref.bound, ref.bound);
        }
    }
    for (size_t i = 0; i < p.ins.size(); ++i) {
        if (i + 1 < p.ins.size() && p.ins[i + 1].coissue) {  // parallel read
            auto a = ref.eval(p.ins[i]);
            auto b = ref.eval(p.ins[i + 1]);
            ref.write(p.ins[i], a);
            ref.write(p.ins[i + 1], b);
            ++i;
        } else {
            ref.write(p.ins[i], ref.eval(p.ins[i]));
        }
    }
    return {ref.r[0][0], ref.r[0][1], ref.r[0][2], ref.r[0][3]};
}

std::array<float, 4> runFloat(const Prog& p, const Inputs& in, bool ideal, float M) {
    FloatRef ref;
    ref.ideal = ideal;
    ref.M = M;
    ref.minor = p.minor;
    for (int i = 0; i < 8; ++i)
        for (int cc = 0; cc < 4; ++cc) ref.c[i][cc] = std::clamp(in.consts[i][cc], -1.0f, 1.0f);
    for (size_t d = 0; d < p.defs.size(); ++d)
        for (int cc = 0; cc < 4; ++cc) ref.c[p.defIndex[d]][cc] = std::clamp(p.defs[d][cc], -1.0f, 1.0f);
    for (int i = 0; i < 2; ++i)
        for (int cc = 0; cc < 4; ++cc) ref.v[i][cc] = std::clamp(in.color[i][cc], 0.0f, 1.0f);
    for (const TexIns& t : p.tex) {
        if (p.minor < 4) {
            for (int cc = 0; cc < 3; ++cc) ref.t[t.tindex][cc] = std::clamp(in.tc[t.tindex][cc], 0.0f, 1.0f);
            ref.t[t.tindex][3] = 1.0f;
        } else {
            const int srcComp[3] = {0, 1, t.xyw ? 3 : 2};
            for (int cc = 0; cc < 3; ++cc)
                if (t.mask & (1 << cc)) {
                    float val = in.tc[t.tindex][srcComp[cc]];
                    ref.r[t.dindex][cc] = ideal ? val : std::clamp(val, -M, M);
                }
        }
    }
    for (size_t i = 0; i < p.ins.size(); ++i) {
        if (i + 1 < p.ins.size() && p.ins[i + 1].coissue) {
            auto a = ref.eval(p.ins[i]);
            auto b = ref.eval(p.ins[i + 1]);
            ref.write(p.ins[i], a);
            ref.write(p.ins[i + 1], b);
            ++i;
        } else {
            ref.write(p.ins[i], ref.eval(p.ins[i]));
        }
    }
    return {ref.r[0][0], ref.r[0][1], ref.r[0][2], ref.r[0][3]};
}

std::string inputsText(const Inputs& in, const Prog& p, const std::vector<int>& rd) {
    std::ostringstream o;
    (void)p;
    auto four = [&](const std::array<float, 4>& a) {
        std::string s;
        for (float f : a) s += " " + floatText(f);
        return s;
    };
    for (int i : rd) o << "c" << i << four(in.consts[i]) << "\n";
    o << "v0" << four(in.color[0]) << "\nv1" << four(in.color[1]) << "\n";
    for (int i = 0; i < 4; ++i) o << "t" << i << four(in.tc[i]) << "\n";
    return o.str();
}

struct Compiled {
    std::unique_ptr<ps11::Executor> exec;
    std::string error;
};


constexpr int kLanes = 8;

struct DiffStats {
    int generated = 0, valid = 0, compared = 0, mismatches = 0;
};

// Runs one program over `lanes` random pixels (kLanes unless told) in one profile and compares
// with the reference.
bool diffOne(const Prog& p, const ps11::Program& prog, Gen& g, ps11::Precision prec, float M, bool overrideM,
             DiffStats& st, int lanes = kLanes) {
    ps11::ExecutorOptions opt;
    opt.precision = prec;
    opt.maxValue = overrideM ? M : 0.0f;
    ps11::Diagnostics diags;
    auto exec = ps11::Executor::create(prog, opt, diags);
    if (!exec) {
        FAIL_CHECK("Executor::create failed for a valid program:\n" << progText(p) << diags.formatAll());
        return false;
    }
    std::vector<Inputs> ins(static_cast<size_t>(lanes));
    for (auto& i : ins) i = g.inputs();
    // constants are per draw: lane 0's constants for all lanes
    for (int i = 0; i < 8; ++i) exec->setConstant(i, ins[0].consts[i]);
    for (auto& i : ins)
        for (int c = 0; c < 8; ++c) i.consts[c] = ins[0].consts[c];
    // Per register and channel, the lanes (plane k of 4 for colours, of 32 for coordinates).
    std::vector<std::vector<float>> col(8, std::vector<float>(size_t(lanes))), tc(32, std::vector<float>(size_t(lanes)));
    ps11::PixelInputs pin;
    pin.count = lanes;
    for (int l = 0; l < lanes; ++l) {
        for (int i = 0; i < 2; ++i)
            for (int c = 0; c < 4; ++c) col[size_t(4 * i + c)][size_t(l)] = ins[size_t(l)].color[i][c];
        for (int i = 0; i < 8; ++i)
            for (int c = 0; c < 4; ++c) tc[size_t(4 * i + c)][size_t(l)] = ins[size_t(l)].tc[i][c];
    }
    for (int i = 0; i < 2; ++i)
        for (int c = 0; c < 4; ++c) pin.color[i][c] = col[size_t(4 * i + c)].data();
    for (int i = 0; i < 8; ++i)
        for (int c = 0; c < 4; ++c) pin.texcoord[i][c] = tc[size_t(4 * i + c)].data();
    std::vector<std::vector<float>> outc(4, std::vector<float>(size_t(lanes)));
    std::vector<std::vector<int32_t>> outg(4, std::vector<int32_t>(size_t(lanes)));
    ps11::PixelOutputs pout;
    for (int c = 0; c < 4; ++c) pout.color[c] = outc[size_t(c)].data(), pout.grid[c] = outg[size_t(c)].data();
    ps11::NullSampler sampler;
    exec->run(pin, sampler, pout);
    const int mask = r0WrittenMask(p);
    std::vector<int> consts;
    for (int i = 0; i < 8; ++i) consts.push_back(i);
    bool ok = true;
    for (int l = 0; l < lanes && ok; ++l) {
        ++st.compared;
        std::ostringstream diff;
        if (ps11::isFixedPoint(prec)) {
            auto want = runFx(p, ins[size_t(l)], prec, M);
            for (int c = 0; c < 4; ++c)
                if ((mask & (1 << c)) && want[c] != outg[size_t(c)][size_t(l)]) {
                    ok = false;
                    diff << "r0." << "rgba"[c] << ": reference " << want[c] << ", executor " << outg[size_t(c)][size_t(l)]
                         << "\n";
                }
        } else {
            auto want = runFloat(p, ins[size_t(l)], prec == ps11::Precision::Ideal, M);
            for (int c = 0; c < 4; ++c)
                if ((mask & (1 << c)) && !(want[c] == outc[size_t(c)][size_t(l)])) {  // bit-identical but ±0
                    ok = false;
                    diff << "r0." << "rgba"[c] << ": reference " << floatText(want[c]) << ", executor "
                         << floatText(outc[size_t(c)][size_t(l)]) << "\n";
                }
        }
        if (!ok) {
            ++st.mismatches;
            FAIL_CHECK("mismatch at " << ps11::precisionName(prec) << " maxValue " << M << "\n"
                                      << progText(p) << "inputs:\n"
                                      << inputsText(ins[size_t(l)], p, consts) << diff.str());
        }
    }
    return ok;
}

void differential(uint32_t seed, int minor, int programs, DiffStats& st) {
    Gen g(seed);
    int reported = 0;
    while (st.valid < programs && st.generated < programs * 40) {
        ++st.generated;
        Prog p = g.program(minor);
        std::string err;
        auto prog = assemble(progText(p), err);
        if (!prog) continue;
        ++st.valid;
        if (r0WrittenMask(p) == 0) continue;
        bool overrideM = g.coin(0.15);
        // (4112: the largest MaxValue fx12 takes, round(M·4080) <= 2^24: the widest numerators.)
        float M = overrideM ? (minor == 4 ? std::array<float, 4>{1, 2, 4, 4112}[g.uni(0, 3)] : 2.0f)
                            : ps11::defaultHardware(minor).maxValue;
        for (ps11::Precision prec :
             {ps11::Precision::Fx8, ps11::Precision::Fx12, ps11::Precision::Float, ps11::Precision::Ideal}) {
            if (!diffOne(p, *prog, g, prec, M, overrideM, st) && ++reported >= 10) return;
        }
    }
}

// A filter's weighted sum, the shape of the glare techniques' blur programs: texcoord t0..t3,
// then a mul of a register by a constant into r0 and mads adding r0, each with its own shift and
// saturation; now and then something else in the sequence (a register's modifier or component,
// another mask, a co-issued pair, r1).
Prog weightedSumProgram(Gen& g, int minor) {
    Prog p;
    p.minor = minor;
    if (g.coin(0.5)) {
        p.defIndex.push_back(g.uni(0, 7));
        std::array<float, 4> v;
        for (float& f : v) f = g.value(-1.0f, 1.0f);
        p.defs.push_back(v);
    }
    const int ntex = g.uni(1, 4);
    for (int i = 0; i < ntex; ++i) {
        TexIns t;
        t.tindex = i;
        p.tex.push_back(t);
    }
    auto reg = [&] {
        Src r;
        if (g.coin(0.8)) {
            r.type = T, r.index = g.uni(0, ntex - 1);
        } else {
            r.type = V, r.index = g.uni(0, 1);
        }
        return r;
    };
    auto constant = [&] {
        Src c;
        c.type = C, c.index = g.uni(0, 7);
        if (g.coin(0.3)) c.mod = std::array<int, 5>{1, 4, 6, 7, 2}[size_t(g.uni(0, 4))];
        return c;
    };
    const int mask = std::array<int, 3>{15, 15, 7}[size_t(g.uni(0, 2))];
    const int length = g.uni(2, 8);
    for (int k = 0; k < length; ++k) {
        Ins in;
        in.op = k == 0 ? MUL : MAD;
        in.mask = mask;
        in.shift = g.coin(0.25) ? std::array<int, 3>{-1, 1, 2}[size_t(g.uni(0, 2))] : 0;
        in.sat = g.coin(0.3);
        Src r = reg(), c = constant();
        if (g.coin(0.06)) r.mod = std::array<int, 3>{1, 4, 6}[size_t(g.uni(0, 2))];
        if (g.coin(0.06)) r.sel = 3;
        const bool constFirst = g.coin(0.4);
        in.s[0] = constFirst ? c : r;
        in.s[1] = constFirst ? r : c;
        in.s[2].type = R, in.s[2].index = 0;
        if (k > 0 && g.coin(0.05)) in.mask = 7;
        if (k > 0 && g.coin(0.04)) in.dindex = 1, in.op = MUL;  // r1
        p.ins.push_back(in);
        if (k > 0 && mask == 7 && g.coin(0.1)) {
            // A co-issued alpha op.
            Ins a = in;
            a.coissue = true;
            a.mask = 8;
            a.op = MUL;
            p.ins.push_back(a);
        }
    }
    return p;
}

// ---------------------------------------------------------------- hand cases for the reference
Ins mk(Op op, int mask, int shift, bool sat, std::initializer_list<Src> srcs) {
    Ins in;
    in.op = op, in.mask = mask, in.shift = shift, in.sat = sat;
    int i = 0;
    for (const Src& s : srcs) in.s[i++] = s;
    return in;
}
Src S(RegT t, int idx, int mod = 0, int sel = -1) {
    Src s;
    s.type = t, s.index = idx, s.mod = mod, s.sel = sel;
    return s;
}

}  // namespace

TEST_CASE("reference: rounding helpers", "[reference]") {
    CHECK(rheDiv(1, 2) == 0);
    CHECK(rheDiv(3, 2) == 2);
    CHECK(rheDiv(-1, 2) == 0);
    CHECK(rheDiv(-3, 2) == -2);
    CHECK(rheDiv(5, 4) == 1);
    CHECK(rheDiv(-5, 4) == -1);
    CHECK(rheDiv(7, 4) == 2);
    CHECK(gridOf(0.5, 255) == 128);   // 127.5 → even 128
    CHECK(gridOf(0.5, 4080) == 2040);
    CHECK(gridOf(-0.5, 255) == -128);  // -127.5 → -128
    CHECK(gridOf(0.25, 255) == 64);    // 63.75
}

TEST_CASE("reference: hand-computed fx8 and fx12 cases", "[reference]") {
    FxRef f8;
    f8.G = 255, f8.bound = 255, f8.minor = 1;
    // mul 128/255 · 1/255: k = 256, 2 → 512/(4·255²) · 255 = 512/1020 = 0.50196 → 1/255 (rounds up, > ½)
    f8.r[0][0] = 128, f8.r[1][0] = 1;
    CHECK(f8.eval(mk(MUL, 15, 0, false, {S(R, 0), S(R, 1)}))[0] == 1);
    // mul 255/255 · 1/255 _d2: 1/2 step exactly → tie → 0 (even)
    f8.r[0][0] = 255;
    CHECK(f8.eval(mk(MUL, 15, -1, false, {S(R, 0), S(R, 1)}))[0] == 0);
    // mov 3/255 _d2 = 1.5 → 2 (even); 5/255 _d2 = 2.5 → 2
    f8.r[0][0] = 3;
    CHECK(f8.eval(mk(MOV, 15, -1, false, {S(R, 0)}))[0] == 2);
    f8.r[0][0] = 5;
    CHECK(f8.eval(mk(MOV, 15, -1, false, {S(R, 0)}))[0] == 2);
    // bias of 0: -0.5 → -127.5 → -128 (even)
    f8.r[0][0] = 0;
    CHECK(f8.eval(mk(MOV, 15, 0, false, {S(R, 0, 2)}))[0] == -128);
    // bias of 1/255: 1 − 127.5 = −126.5 → −126
    f8.r[0][0] = 1;
    CHECK(f8.eval(mk(MOV, 15, 0, false, {S(R, 0, 2)}))[0] == -126);
    // bx2 of 128: 2·128 − 255 = 1 → 1; 1-: 255 − 128 = 127
    f8.r[0][0] = 128;
    CHECK(f8.eval(mk(MOV, 15, 0, false, {S(R, 0, 4)}))[0] == 1);
    CHECK(f8.eval(mk(MOV, 15, 0, false, {S(R, 0, 6)}))[0] == 127);
    // add_x4 200 + 200 → clamp to 255; _sat on negative → 0
    f8.r[0][0] = 200, f8.r[1][0] = 200;
    CHECK(f8.eval(mk(ADD, 15, 2, false, {S(R, 0), S(R, 1)}))[0] == 255);
    CHECK(f8.eval(mk(SUB, 15, 0, true, {S(R, 1), S(R, 0, 6)}))[0] == 145);
    f8.r[1][0] = 10;
    CHECK(f8.eval(mk(SUB, 15, 0, true, {S(R, 1), S(R, 0)}))[0] == 0);
    // cnd 1_1: r0.a = 128 (> ½ since 256 > 255) picks a; 127 picks b
    f8.r[0][3] = 128, f8.c[0][1] = 7, f8.c[1][1] = 9;
    CHECK(f8.eval(mk(CND, 15, 0, false, {S(R, 0, 0, 3), S(C, 0), S(C, 1)}))[1] == 7);
    f8.r[0][3] = 127;
    CHECK(f8.eval(mk(CND, 15, 0, false, {S(R, 0, 0, 3), S(C, 0), S(C, 1)}))[1] == 9);
    // lrp f=128, a=255, b=0: 256·510/(4·255²)·255 = 128 exactly (1 − f is exact)
    f8.r[0][2] = 128, f8.r[1][2] = 255, f8.c[2][2] = 0;
    CHECK(f8.eval(mk(LRP, 15, 0, false, {S(R, 0), S(R, 1), S(C, 2)}))[2] == 128);
    // dp3 of (255,255,255)·(128,128,128)/255² ·255 = 384 → clamp 255
    for (int c = 0; c < 3; ++c) f8.r[0][c] = 255, f8.r[1][c] = 128;
    CHECK(f8.eval(mk(DP3, 7, 0, false, {S(R, 0), S(R, 1)}))[0] == 255);
    CHECK(f8.eval(mk(DP3, 7, -2 + 1, false, {S(R, 0), S(R, 1)}))[0] == 192);

    FxRef f12;
    f12.G = 4080, f12.bound = 4080, f12.minor = 1;
    // mul 2040·1/4080² ·4080 = 0.5 → 0 (even); 2040·3 → 1.5 → 2
    f12.r[0][0] = 2040, f12.r[1][0] = 1;
    CHECK(f12.eval(mk(MUL, 15, 0, false, {S(R, 0), S(R, 1)}))[0] == 0);
    f12.r[1][0] = 3;
    CHECK(f12.eval(mk(MUL, 15, 0, false, {S(R, 0), S(R, 1)}))[0] == 2);
    // mad 2040·2040/4080 + 1 = 1020 + 1
    f12.r[1][0] = 2040, f12.c[0][0] = 1;
    CHECK(f12.eval(mk(MAD, 15, 0, false, {S(R, 0), S(R, 1), S(C, 0)}))[0] == 1021);

    // ps_1_4 range ±8: add_x4 of 1 + 1 → 8·255 = 2040 exactly; _x8 of 1 + 1 → 16 → clamp 2040
    FxRef f14;
    f14.G = 255, f14.bound = 8 * 255, f14.minor = 4;
    f14.r[0][0] = 255, f14.r[1][0] = 255;
    CHECK(f14.eval(mk(ADD, 15, 2, false, {S(R, 0), S(R, 1)}))[0] == 2040);
    CHECK(f14.eval(mk(ADD, 15, 3, false, {S(R, 0), S(R, 1)}))[0] == 2040);
    CHECK(f14.eval(mk(ADD, 15, 1, false, {S(R, 0), S(R, 1, 8)}))[0] == -510);  // (1 − 2)·2
    CHECK(f14.eval(mk(CND, 15, 0, false, {S(R, 0, 2), S(R, 0), S(R, 1, 1)}))[0] == -255);  // 0.5 > 0.5 false

    FloatRef fl;
    fl.ideal = false, fl.M = 1, fl.minor = 1;
    fl.r[0][0] = 0.75f, fl.r[1][0] = 0.75f;
    CHECK(fl.eval(mk(ADD, 15, 1, false, {S(R, 0), S(R, 1)}))[0] == 1.0f);
    fl.ideal = true;
    CHECK(fl.eval(mk(ADD, 15, 1, false, {S(R, 0), S(R, 1)}))[0] == 3.0f);
    CHECK(fl.eval(mk(MAD, 15, 0, false, {S(R, 0, 4), S(R, 1), S(R, 1, 6)}))[0] == 0.75f * 0.5f + 0.25f);
}

TEST_CASE("reference: random ps_1_x arithmetic programs, executor == reference bit for bit", "[reference]") {
    struct Run {
        uint32_t seed;
        int minor;
        int programs;
    };
    const Run runs[] = {{0x5eed0101u, 1, 1500}, {0x5eed0102u, 2, 400}, {0x5eed0103u, 3, 600}, {0x5eed0104u, 4, 2000}};
    // At every SIMD level this CPU runs: each has its own arithmetic kernels (exec::fxArithKernels,
    // exec::floatArithKernels).
    testutil::forEachSimdLevel([&](ps11::SimdLevel level) {
        for (const Run& r : runs) {
            DiffStats st;
            differential(r.seed, r.minor, r.programs, st);
            INFO(ps11::simdLevelName(level)
                 << ", ps_1_" << r.minor << ": " << st.generated << " generated, " << st.valid << " valid, "
                 << st.compared << " pixel comparisons, " << st.mismatches << " mismatches");
            CHECK(st.mismatches == 0);
            CHECK(st.valid >= r.programs / 2);
        }
    });
}

TEST_CASE("reference: weighted sums (a mul, then mads into one register) equal the reference", "[reference]") {
    // Run over 5 to 300 lanes (vector groups and their tails, two chunks of 256 lanes), in float
    // and ideal, at every SIMD level.
    testutil::forEachSimdLevel([&](ps11::SimdLevel level) {
        Gen g(0xc4a1 + uint32_t(level));
        DiffStats st;
        int reported = 0;
        while (st.valid < 600 && st.generated < 4000 && reported < 10) {
            ++st.generated;
            const Prog p = weightedSumProgram(g, g.uni(1, 3));
            std::string err;
            auto prog = assemble(progText(p), err);
            if (!prog) continue;
            ++st.valid;
            const bool overrideM = g.coin(0.2);
            const float M = overrideM ? 2.0f : ps11::defaultHardware(p.minor).maxValue;
            const int lanes = std::array<int, 4>{5, 16, 37, 300}[size_t(g.uni(0, 3))];
            for (ps11::Precision prec : {ps11::Precision::Float, ps11::Precision::Ideal})
                if (!diffOne(p, *prog, g, prec, M, overrideM, st, lanes)) ++reported;
        }
        INFO(ps11::simdLevelName(level) << ": " << st.generated << " generated, " << st.valid << " valid, "
                                        << st.compared << " pixel comparisons, " << st.mismatches << " mismatches");
        CHECK(st.mismatches == 0);
        CHECK(st.valid >= 400);
    });
}

TEST_CASE("reference: the program generator mostly produces valid programs", "[reference]") {
    for (int minor = 1; minor <= 4; ++minor) {
        Gen g(1234u + uint32_t(minor));
        int valid = 0;
        std::map<std::string, int> codes;
        for (int i = 0; i < 500; ++i) {
            Prog p = g.program(minor);
            ps11::Diagnostics diags;
            auto prog = ps11::parseAssembly(progText(p), "random.psh", {}, diags);
            if (prog && ps11::validate(*prog, diags)) {
                ++valid;
                continue;
            }
            for (const auto& d : diags.all())
                if (d.severity == ps11::Severity::Error) {
                    ++codes[d.code];
                    if (getenv("PS11_REF_VERBOSE") && d.code == std::string(getenv("PS11_REF_VERBOSE")))
                        WARN(progText(p) << diags.format(d));
                }
        }
        std::ostringstream o;
        for (auto& [c, n] : codes) o << c << ":" << n << " ";
        INFO("ps_1_" << minor << ": " << valid << "/500 valid; rejections " << o.str());
        CHECK(valid >= 200);
        if (getenv("PS11_REF_VERBOSE")) WARN("ps_1_" << minor << ": " << valid << "/500 valid; " << o.str());
    }
}
