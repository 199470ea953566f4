// ps_1_x → GLSL, the program and sampler part (emu/gl/glsl.h): the triangle record and the
// attribute planes, v# loading, every arithmetic and texture-address instruction of the
// executor's op list (ps11/executor_arith.cpp, ps11/executor_texture.cpp) in the profile's
// terms, and one sampling function per stage (ps11/texture_sampler.cpp: level selection,
// addressing, the exact weighted sums). The merge is in glsl_merge.cpp.
#include "emu/gl/glsl.h"

#include <cmath>
#include <cstring>
#include <sstream>

#include "emu/vertex.h"

namespace emu::gl {

using ps11::Opcode;
using ps11::Precision;
using ps11::SrcMod;
using ps11::exec::DOp;
using ps11::exec::DSrc;
using ps11::exec::SrcKind;

std::string mergeSource(const FragmentSpec& spec);  // glsl_merge.cpp

namespace {

const char* const kComp = "xyzw";

std::string num(double v) {
    std::ostringstream o;
    o.precision(17);
    o << v;
    std::string s = o.str();
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
    return s;
}
// A float literal that reads back as exactly `v` (hex bits, no decimal rounding).
std::string flit(float v) {
    uint32_t b;
    std::memcpy(&b, &v, 4);
    return "uintBitsToFloat(" + std::to_string(b) + "u)";
}

// Helper functions every shader has.
const char* kCommon = R"(
// floor(n / d) for d > 0 without a 64-bit division (Mesa's lowering of it is not reliable): a
// double estimate, corrected by the exact remainder.
int64_t floorDiv64(int64_t n, int64_t d) {
    int64_t q = int64_t(floor(double(n) / double(d)));
    int64_t r = n - q * d;
    if (r < 0l) q -= 1l;
    else if (r >= d) q += 1l;
    return q;
}
// round_half_even(n / d) clamped to [lo, hi] (d > 0): the one rounding of an fx instruction.
int rc64(int64_t n, int64_t d, int lo, int hi) {
    int64_t q = floorDiv64(n, d);
    int64_t t = (n - q * d) * 2l;
    if (t > d || (t == d && (q & 1l) != 0l)) q += 1l;
    // (no 64-bit clamp: llvmpipe's compiler crashes on it)
    return q < int64_t(lo) ? lo : q > int64_t(hi) ? hi : int(q);
}
int floorDiv32(int n, int d) { return n >= 0 ? n / d : -((-n + d - 1) / d); }
int rc32(int n, int d, int lo, int hi) {
    int q = floorDiv32(n, d);
    int t = (n - q * d) * 2;
    if (t > d || (t == d && (q & 1) != 0)) q += 1;
    return clamp(q, lo, hi);
}
// Correctly rounded float32 division (through double: 53 >= 2 * 24 + 2).
float fdiv(float a, float b) { return float(double(a) / double(b)); }
// round_half_even(v * g) with NaN -> lo, clamped to [lo, hi] (the executor's writeFloat).
int gridOf(float v, double g, double lo, double hi) {
    double x = roundEven(double(v) * g);
    x = x > lo ? x : lo;
    x = x < hi ? x : hi;
    return int(x);
}
)";

// The sampling helpers, in shaders that sample a texture.
const char* kSampling = R"(
// log2 in double: frexp, then 2·atanh((m − 1)/(m + 1)) / ln 2 with m in [√½, √2).
double log2d(double x) {
    int e;
    double m = frexp(x, e);
    if (m < 0.70710678118654752lf) { m *= 2.0lf; e -= 1; }
    precise double s = (m - 1.0lf) / (m + 1.0lf);
    precise double s2 = s * s;
    precise double t = 0.0lf;
    for (int k = 39; k >= 1; k -= 2) t = t * s2 + 1.0lf / double(k);
    return double(e) + 2.0lf * s * t * 1.4426950408889634074lf;
}
// The values of v at the quad's top-left, top-right and bottom-left pixels, exactly: v's four
// bytes as floats go through fine derivatives (differences of small integers are exact), each
// pixel undoes its own offset in the quad. The signs of dFdx/dFdy are measured, not assumed.
uint packBytes(vec4 b) { return uint(b.x) | (uint(b.y) << 8) | (uint(b.z) << 16) | (uint(b.w) << 24); }
vec3 quadValues(float v) {
    uint u = floatBitsToUint(v);
    vec4 by = vec4(float(u & 255u), float((u >> 8) & 255u), float((u >> 16) & 255u), float(u >> 24));
    float sx = dFdxFine(gl_FragCoord.x), sy = dFdyFine(gl_FragCoord.y);
    bool right = (int(gl_FragCoord.x) & 1) != 0, bottom = (int(gl_FragCoord.y) & 1) != 0;
    vec4 dx = sx * dFdxFine(by);
    vec4 left = right ? by - dx : by, rightv = right ? by : by + dx;
    vec4 dyL = sy * dFdyFine(left), dyR = sy * dFdyFine(rightv);
    vec4 tl = bottom ? left - dyL : left, tr = bottom ? rightv - dyR : rightv, bl = bottom ? left : left + dyL;
    return vec3(uintBitsToFloat(packBytes(tl)), uintBitsToFloat(packBytes(tr)), uintBitsToFloat(packBytes(bl)));
}
// The level of detail 0.5·log2(rho2) as the sampler takes it: NaN counts as 0, +inf (an
// overflowed derivative) as far beyond every level, 0 as magnified. No isinf/frexp on
// infinities, which llvmpipe does not evaluate reliably for doubles.
double lodOf(double rho2) {
    if (isnan(rho2)) return 0.0lf;
    if (rho2 > 1.7976931348623157e308lf) return 1e300lf;
    if (!(rho2 > 0.0lf)) return -1e300lf;
    return 0.5lf * log2d(rho2);
}
// The 8-bit sub-texel weight round_half_even(f · 256).
int weight8(double f) { return int(roundEven(f * 256.0lf)); }
// Texel-space position of one coordinate (ps11/texture_sampler_internal.h texelPosition): NaN
// samples as 0, infinities as a far texel.
void texelPos(float u, int n, bool linear, out double fl, out double fr) {
    precise double x = double(u) * double(n) - (linear ? 0.5lf : 0.0lf);
    // (comparisons, not isnan/isinf: llvmpipe does not evaluate those reliably for doubles)
    if (!(x == x)) { fl = 0.0lf; fr = 0.0lf; return; }
    if (abs(x) > 1.7976931348623157e308lf) { fl = x > 0.0lf ? 1e18lf : -1e18lf; fr = 0.0lf; return; }
    fl = floor(x);
    fr = x - fl;
}
int64_t posMod(int64_t k, int64_t n) { return k - floorDiv64(k, n) * n; }
// fl mod n in [0, n) for an integer-valued fl of any size, exactly (fl = m·2^e: m mod n times
// 2^e mod n); the sampler takes std::fmod beyond 1e15.
int64_t posModBig(double fl, int64_t n) {
    if (abs(fl) < 1e15lf) return posMod(int64_t(fl), n);
    int e;
    double m = frexp(abs(fl), e);
    int64_t r = posMod(int64_t(m * 9007199254740992.0lf), n);
    e -= 53;
    int64_t b = posMod(2l, n);
    for (int i = 0; i < 11 && e > 0; ++i) {
        if ((e & 1) != 0) r = posMod(r * b, n);
        b = posMod(b * b, n);
        e >>= 1;
    }
    return fl < 0.0lf ? posMod(-r, n) : r;
}
int mirrorIndex(int64_t k, int64_t n) { return int(k < n ? k : 2l * n - 1l - k); }
// The two texel indices of an axis under an address mode (-1: border).
ivec2 address(int mode, double fl, int n) {
    int64_t nn = int64_t(n);
    if (mode == 2) {  // mirror
        int64_t p = 2l * nn;
        int64_t k = posModBig(fl, p);
        return ivec2(mirrorIndex(k, nn), mirrorIndex(k + 1l == p ? 0l : k + 1l, nn));
    }
    if (mode == 3) {  // clamp
        int k = int(clamp(fl, -1.0lf, double(n)));
        return ivec2(clamp(k, 0, n - 1), clamp(k + 1, 0, n - 1));
    }
    if (mode == 4) {  // border
        int64_t k = int64_t(clamp(fl, -2.0lf, double(n + 1)));
        return ivec2(k >= 0l && k < nn ? int(k) : -1, k + 1l >= 0l && k + 1l < nn ? int(k + 1l) : -1);
    }
    if (mode == 5) {  // mirror once
        int k = int(clamp(fl, -double(n) - 2.0lf, double(n + 1)));
        int a = k < 0 ? -k - 1 : k, b = k + 1 < 0 ? -k - 2 : k + 1;
        return ivec2(clamp(a, 0, n - 1), clamp(b, 0, n - 1));
    }
    int64_t k = posModBig(fl, nn);  // wrap
    return ivec2(int(k), k + 1l == nn ? 0 : int(k + 1l));
}
// round_half_even(v / 2^32) (the sampler's roundShift).
int roundShift32(int64_t v) { return int((v + 2147483647l + ((v >> 32) & 1l)) >> 32); }
float lerpf(float a, float b, float f) { precise float r = (1.0 - f) * a + f * b; return r; }
)";

struct Gen {
    const FragmentSpec& spec;
    const ps11::exec::Profile& p;
    bool fx;
    std::ostringstream o;

    explicit Gen(const FragmentSpec& s)
        : spec(s), p(s.program->profile), fx(ps11::isFixedPoint(s.precision)) {}

    std::string G() const { return std::to_string(p.g); }

    // ---- sampling functions ----
    void sampler(int s) {
        const StageSpec& st = spec.stages[size_t(s)];
        const std::string ret = fx ? "ivec4" : "vec4";
        o << ret << " S" << s << "(float u, float v, float w) {\n";
        if (!st.bound) {
            o << (fx ? "    return ivec4(0, 0, 0, " + G() + ");\n}\n" : "    return vec4(0.0, 0.0, 0.0, 1.0);\n}\n");
            return;
        }
        const bool vol = st.volume;
        const int axes = vol ? 3 : 2;
        const std::string tex = "uT" + std::to_string(s);
        if (spec.hardwareFiltering && !fx) {
            o << "    return texture(" << tex << ", " << (vol ? "vec3(u, v, w)" : "vec2(u, v)") << ");\n}\n";
            return;
        }
        auto effLinear = [](ps11::Filter f) { return f == ps11::Filter::Linear; };
        const bool magLin = effLinear(st.state.magFilter), minLin = effLinear(st.state.minFilter);
        const bool weights8 = !fx && spec.weightBits == 8 && spec.precision == Precision::Float;
        const std::string scale = std::to_string(p.g / 255);
        // One texel of level lv as grid integers (8-bit texels scaled to the grid).
        auto texel = [&](const std::string& coord, const std::string& lv) {
            const std::string f = "texelFetch(" + tex + ", " + coord + ", " + lv + ")";
            return st.unorm8 && fx ? "(ivec4(" + f + ") * " + scale + ")" : f;
        };
        if (fx && st.unorm8 && !vol && lodFree(st) && st.borderInRange) {
            // One 2-D level of 8-bit texels: the same taps and weights, summed in 32 bits
            // (255·16 · 2^16 < 2^31) and rounded once: round_half_even(acc / 2^16).
            const std::string b = "uBorderG[" + std::to_string(s) + "]";
            auto tap = [&](const std::string& x, const std::string& y) {
                return "((" + x + " | " + y + ") < 0 ? " + b + " : " + texel("ivec2(" + x + ", " + y + ")", "0") + ")";
            };
            o << "    ivec2 sz = textureSize(" << tex << ", 0);\n    double fl, fr;\n"
              << "    texelPos(u, sz.x, " << (magLin ? "true" : "false") << ", fl, fr); ivec2 ix = address("
              << int(st.state.addressU) << ", fl, sz.x); int wx = weight8(fr);\n"
              << "    texelPos(v, sz.y, " << (magLin ? "true" : "false") << ", fl, fr); ivec2 iy = address("
              << int(st.state.addressV) << ", fl, sz.y); int wy = weight8(fr);\n";
            if (!magLin) {
                o << "    return " << tap("ix.x", "iy.x") << ";\n}\n";
                return;
            }
            o << "    ivec4 acc = " << tap("ix.x", "iy.x") << " * ((256 - wx) * (256 - wy)) + " << tap("ix.y", "iy.x")
              << " * (wx * (256 - wy))\n        + " << tap("ix.x", "iy.y") << " * ((256 - wx) * wy) + "
              << tap("ix.y", "iy.y") << " * (wx * wy);\n"
              << "    return (acc + 32767 + ((acc >> 16) & 1)) >> 16;\n}\n";
            return;
        }
        o << "    float c[3] = float[3](u, v, w);\n";
        if (lodFree(st)) {
            o << "    bool minified = false;\n";
        } else {
        o << "    ivec3 size0 = ivec3(textureSize(" << tex << ", 0)" << (vol ? "" : ", 1") << ");\n";
        // Level selection from the quad (ddx = top-right − top-left, ddy = bottom-left − top-left).
        o << "    double dx2 = 0.0lf, dy2 = 0.0lf;\n";
        o << "    for (int a = 0; a < " << axes << "; ++a) {\n"
          << "        vec3 q = quadValues(c[a]);\n"
          << "        precise double c0 = double(q.x) * double(size0[a]);\n"
          << "        precise double ddx = double(q.y) * double(size0[a]) - c0;\n"
          << "        precise double ddy = double(q.z) * double(size0[a]) - c0;\n"
          << "        dx2 += ddx * ddx; dy2 += ddy * ddy;\n    }\n";
        o << "    double rho2 = dx2 < dy2 ? dy2 : dx2;\n";  // std::max's choice when one is NaN
        o << "    double lod = lodOf(rho2);\n    bool minified = lod > 0.0lf;\n";
        }
        o << "    int level0 = 0, level1 = 0, slots = 1, mipW = 0; float mipF = 0.0;\n";
        if (st.levels > 1 && st.state.mipFilter == ps11::Filter::Point) {
            o << "    if (minified) { double nl = floor(lod + 0.5lf);\n"
              << "        level0 = nl >= " << st.levels - 1 << ".0lf ? " << st.levels - 1 << " : int(nl); }\n";
        } else if (st.levels > 1 && st.state.mipFilter == ps11::Filter::Linear) {
            o << "    if (minified) { double a = floor(lod);\n"
              << "        if (a >= " << st.levels - 1 << ".0lf) level0 = " << st.levels - 1 << ";\n"
              << "        else { level0 = int(a); level1 = level0 + 1; double fr = lod - a;\n";
            if (fx || weights8)
                o << "            mipW = weight8(fr); if (mipW == 256) level0 = level1;\n"
                     "            slots = mipW == 0 || mipW == 256 ? 1 : 2; mipF = float(mipW) / 256.0;\n";
            else
                o << "            mipF = float(fr); slots = mipF == 0.0 ? 1 : 2;\n";
            o << "        } }\n";
        }
        o << "    bool linear = minified ? " << (minLin ? "true" : "false") << " : " << (magLin ? "true" : "false")
          << ";\n";
        const int modes[3] = {int(st.state.addressU), int(st.state.addressV), int(st.state.addressW)};
        if (fx) {
            o << "    i64vec4 acc = i64vec4(0);\n";
        } else {
            o << "    vec4 res[2];\n";
        }
        o << "    for (int sl = 0; sl < slots; ++sl) {\n"
          << "        int lv = sl == 0 ? level0 : level1;\n"
          // Level extents halve from level 0 (a full chain). Not textureSize(tex, lv): llvmpipe
          // answers it with one lane's level for the whole SIMD group when levels differ.
          << "        ivec3 sz = max(ivec3(1), ivec3(textureSize(" << tex << ", 0)" << (vol ? "" : ", 1") << ") >> lv);\n"
          << "        ivec2 ia[3]; int wa[3]; float fa[3];\n"
          << "        for (int a = 0; a < 3; ++a) { ia[a] = ivec2(0); wa[a] = 0; fa[a] = 0.0; }\n";
        for (int a = 0; a < axes; ++a)
            o << "        { double fl, fr; texelPos(c[" << a << "], sz[" << a << "], linear, fl, fr);\n"
              << "          ia[" << a << "] = address(" << modes[a] << ", fl, sz[" << a << "]);\n"
              << "          wa[" << a << "] = linear ? weight8(fr) : 0; fa[" << a << "] = linear ? "
              << (weights8 ? "float(wa[" + std::to_string(a) + "]) / 256.0" : "float(fr)") << " : 0.0; }\n";
        const std::string fetch = vol ? texel("ivec3(X, Y, Z)", "lv") : texel("ivec2(X, Y)", "lv");
        auto tap = [&](const std::string& x, const std::string& y, const std::string& z) {
            std::string f = fetch;
            auto rep = [&](const std::string& k, const std::string& v) { f.replace(f.find(k), k.size(), v); };
            rep("X", x);
            rep("Y", y);
            if (vol) rep("Z", z);
            const std::string cond = "(" + x + " | " + y + (vol ? " | " + z : "") + ") < 0";
            return "(" + cond + " ? " + (fx ? "uBorderG[" : "uBorderF[") + std::to_string(s) + "] : " + f + ")";
        };
        if (fx) {
            o << "        int64_t mw = slots == 1 ? 256l : sl == 0 ? int64_t(256 - mipW) : int64_t(mipW);\n"
              << "        if (!linear) {\n"
              << "            acc += i64vec4(" << tap("ia[0].x", "ia[1].x", "ia[2].x") << ") * (mw << 24);\n"
              << "        } else {\n";
            o << "            for (int z = 0; z < " << (vol ? 2 : 1) << "; ++z) for (int y = 0; y < 2; ++y) for (int x = 0; x < 2; ++x) {\n"
              << "                int X = x == 0 ? ia[0].x : ia[0].y; int Y = y == 0 ? ia[1].x : ia[1].y;\n"
              << "                int Z = z == 0 ? ia[2].x : ia[2].y;\n"
              << "                int64_t wgt = int64_t(x == 0 ? 256 - wa[0] : wa[0]) * int64_t(y == 0 ? 256 - wa[1] : wa[1])"
              << " * int64_t(" << (vol ? "z == 0 ? 256 - wa[2] : wa[2]" : "256") << ") * mw;\n"
              << "                acc += i64vec4(" << tap("X", "Y", "Z") << ") * wgt;\n"
              << "            }\n        }\n    }\n";
            o << "    return ivec4(roundShift32(acc.x), roundShift32(acc.y), roundShift32(acc.z), roundShift32(acc.w));\n}\n";
        } else {
            o << "        if (!linear) { res[sl] = " << tap("ia[0].x", "ia[1].x", "ia[2].x") << "; continue; }\n"
              << "        vec4 plane[2];\n"
              << "        for (int z = 0; z < " << (vol ? 2 : 1) << "; ++z) {\n"
              << "            int Z = z == 0 ? ia[2].x : ia[2].y;\n"
              << "            int X0 = ia[0].x, X1 = ia[0].y, Y0 = ia[1].x, Y1 = ia[1].y;\n"
              << "            vec4 t00, t10, t01, t11;\n"
              << "            { int X = X0, Y = Y0; t00 = " << tap("X", "Y", "Z") << "; }\n"
              << "            { int X = X1, Y = Y0; t10 = " << tap("X", "Y", "Z") << "; }\n"
              << "            { int X = X0, Y = Y1; t01 = " << tap("X", "Y", "Z") << "; }\n"
              << "            { int X = X1, Y = Y1; t11 = " << tap("X", "Y", "Z") << "; }\n"
              << "            for (int k = 0; k < 4; ++k)\n"
              << "                plane[z][k] = lerpf(lerpf(t00[k], t10[k], fa[0]), lerpf(t01[k], t11[k], fa[0]), fa[1]);\n"
              << "        }\n";
            if (vol)
                o << "        for (int k = 0; k < 4; ++k) res[sl][k] = lerpf(plane[0][k], plane[1][k], fa[2]);\n";
            else
                o << "        res[sl] = plane[0];\n";
            o << "    }\n    if (slots == 1) return res[0];\n"
              << "    vec4 r; for (int k = 0; k < 4; ++k) r[k] = lerpf(res[0][k], res[1][k], mipF);\n    return r;\n}\n";
        }
    }

    // ---- register access ----
    std::string reg(int slot, int comp) const { return "R[" + std::to_string(slot) + "]." + kComp[comp]; }
    // Register component as float (fx: n / G correctly rounded), with _bx2 when given.
    std::string regFloat(int slot, int comp, SrcMod mod) const {
        std::string v = fx ? "fdiv(float(" + reg(slot, comp) + "), " + G() + ".0)" : reg(slot, comp);
        if (mod == SrcMod::Sign) v = "(2.0 * " + v + " - 1.0)";
        return v;
    }
    std::string tc(int set, int comp) const {
        return set >= 0 && set < 8 ? "TC[" + std::to_string(set) + "]." + kComp[comp] : "0.0";
    }
    std::string srcFloat(const DSrc& s, int comp) const {
        return s.kind == SrcKind::TexCoord ? tc(s.slot, comp) : regFloat(s.slot, comp, s.mod);
    }
    // Writes a float to a register component (the executor's writeFloat).
    void writeFloat(int slot, int comp, const std::string& v, bool sat) {
        if (fx) {
            const std::string lo = sat ? "0.0lf" : num(-double(p.nMax));
            const std::string hi = sat ? num(double(std::min(p.g, p.nMax))) : num(double(p.nMax));
            o << "    " << reg(slot, comp) << " = gridOf(" << v << ", " << num(p.g) << ", " << lo << ", " << hi
              << ");\n";
        } else {
            o << "    { precise float x = " << v << ";";
            if (sat) o << " x = x > 0.0 ? x : 0.0; x = x < 1.0 ? x : 1.0;";
            if (p.clampRange)
                o << " x = x < " << flit(-p.maxValue) << " ? " << flit(-p.maxValue) << " : x; x = x > "
                  << flit(p.maxValue) << " ? " << flit(p.maxValue) << " : x;";
            o << " " << reg(slot, comp) << " = x; }\n";
        }
    }
    void sampleInto(int stage, const std::string& u, const std::string& v, const std::string& w, int slot) {
        o << "    R[" << slot << "] = S" << stage << "(" << u << ", " << v << ", " << w << ");\n";
        if (fx)
            o << "    R[" << slot << "] = clamp(R[" << slot << "], ivec4(" << -p.nMax << "), ivec4(" << p.nMax << "));\n";
        else if (p.clampRange)
            o << "    R[" << slot << "] = clamp(R[" << slot << "], vec4(" << flit(-p.maxValue) << "), vec4("
              << flit(p.maxValue) << "));\n";
    }

    // ---- texture-address instructions (ps11/executor_texture.cpp) ----
    void staticCoords(int m) {
        const int divisor = ps11::projectionDivisor(p.stages[size_t(m)]);
        if (divisor >= 0) {
            const std::string q = tc(m, divisor);
            o << "    U = fdiv(" << tc(m, 0) << ", " << q << "); V = fdiv(" << tc(m, 1) << ", " << q
              << "); W = fdiv(" << tc(m, 2) << ", " << q << ");\n";
        } else {
            o << "    U = " << tc(m, 0) << "; V = " << tc(m, 1) << "; W = " << tc(m, 2) << ";\n";
        }
    }
    std::string rowDot(int row, const DSrc& s) {
        return "((" + tc(row, 0) + " * " + regFloat(s.slot, 0, s.mod) + " + " + tc(row, 1) + " * " +
               regFloat(s.slot, 1, s.mod) + ") + " + tc(row, 2) + " * " + regFloat(s.slot, 2, s.mod) + ")";
    }
    void coords14(const DSrc& s) {
        o << "    { float raw[4] = float[4](" << srcFloat(s, 0) << ", " << srcFloat(s, 1) << ", " << srcFloat(s, 2)
          << ", " << srcFloat(s, 3) << ");\n";
        o << "      C4 = vec4(raw[" << int(s.sw[0]) << "], raw[" << int(s.sw[1]) << "], raw[" << int(s.sw[2])
          << "], raw[" << int(s.sw[3]) << "]);\n";
        if (s.mod == SrcMod::Dz || s.mod == SrcMod::Dw) {
            const int d = s.mod == SrcMod::Dz ? 2 : 3;
            o << "      float d = raw[" << d << "]; C4.x = d == 0.0 ? 1.0 : fdiv(C4.x, d); C4.y = d == 0.0 ? 1.0 : fdiv(C4.y, d);\n";
        }
        o << "    }\n";
    }
    void texture(const DOp& op) {
        const bool v14 = p.minor >= 4;
        const int dst = op.dstSlot, stage = op.stage;
        switch (op.op) {
            case Opcode::TexCoord:
                if (v14) {
                    coords14(op.src[0]);
                    for (int k = 0; k < 4; ++k)
                        if ((op.mask >> k) & 1) writeFloat(dst, k, std::string("C4.") + kComp[k], op.sat);
                } else {
                    for (int c = 0; c < 3; ++c) writeFloat(dst, c, tc(stage, c), true);
                    writeFloat(dst, 3, "1.0", false);
                }
                break;
            case Opcode::Tex:
                if (v14) {
                    coords14(op.src[0]);
                    sampleInto(stage, "C4.x", "C4.y", "C4.z", dst);
                } else {
                    staticCoords(stage);
                    sampleInto(stage, "U", "V", "W", dst);
                }
                break;
            case Opcode::TexKill:
                for (int c = 0; c < 3; ++c) o << "    if (" << srcFloat(op.src[0], c) << " < 0.0) killed = true;\n";
                break;
            case Opcode::TexBem:
            case Opcode::TexBemL: {
                staticCoords(stage);
                const std::string r = regFloat(op.src[0].slot, 0, op.src[0].mod);
                const std::string g = regFloat(op.src[0].slot, 1, op.src[0].mod);
                const std::string m = "uBump[" + std::to_string(stage) + "]";
                o << "    { precise float uu = (U + " << m << ".x * " << r << ") + " << m << ".z * " << g << ";\n"
                  << "      precise float vv = (V + " << m << ".y * " << r << ") + " << m << ".w * " << g << ";\n"
                  << "      U = uu; V = vv; W = 0.0; }\n";
                sampleInto(stage, "U", "V", "0.0", dst);
                if (op.op == Opcode::TexBemL) {
                    const std::string b = regFloat(op.src[0].slot, 2, op.src[0].mod);
                    const std::string l = "uLum[" + std::to_string(stage) + "]";
                    o << "    { precise float L = " << b << " * " << l << ".x + " << l << ".y;\n";
                    if (p.stages[size_t(stage)].clampLuminance) o << "      L = L < 0.0 ? 0.0 : (L > 1.0 ? 1.0 : L);\n";
                    if (fx) {
                        o << "      for (int k = 0; k < 4; ++k) { double x = roundEven(double(R[" << dst
                          << "][k]) * double(L)); x = x > " << num(-p.nMax) << " ? x : " << num(-p.nMax) << "; x = x < "
                          << num(p.nMax) << " ? x : " << num(p.nMax) << "; R[" << dst << "][k] = int(x); } }\n";
                    } else {
                        o << "      for (int k = 0; k < 4; ++k) { precise float x = R[" << dst << "][k] * L;";
                        if (p.clampRange)
                            o << " x = x < " << flit(-p.maxValue) << " ? " << flit(-p.maxValue) << " : x; x = x > "
                              << flit(p.maxValue) << " ? " << flit(p.maxValue) << " : x;";
                        o << " R[" << dst << "][k] = x; } }\n";
                    }
                }
                break;
            }
            case Opcode::TexReg2AR:
            case Opcode::TexReg2GB:
            case Opcode::TexReg2RGB: {
                static constexpr int kAR[3] = {3, 0, 0}, kGB[3] = {1, 2, 2}, kRGB[3] = {0, 1, 2};
                const int* sel = op.op == Opcode::TexReg2AR ? kAR : op.op == Opcode::TexReg2GB ? kGB : kRGB;
                const DSrc& s = op.src[0];
                o << "    U = " << regFloat(s.slot, sel[0], s.mod) << "; V = " << regFloat(s.slot, sel[1], s.mod)
                  << "; W = " << regFloat(s.slot, sel[2], s.mod) << ";\n";
                sampleInto(stage, "U", "V", "W", dst);
                break;
            }
            case Opcode::TexM3x2Pad:
            case Opcode::TexM3x3Pad:
                o << "    { precise float d = " << rowDot(stage, op.src[0]) << "; P" << int(op.padIndex) << " = d; }\n";
                break;
            case Opcode::TexM3x2Tex:
                o << "    { precise float d = " << rowDot(stage, op.src[0]) << "; V = d; }\n";
                sampleInto(stage, "P0", "V", "0.0", dst);
                break;
            case Opcode::TexM3x2Depth:
                o << "    { precise float wv = " << rowDot(stage, op.src[0]) << ";\n"
                  << "      float d = wv == 0.0 ? 1.0 : fdiv(P0, wv); d = d > 0.0 ? d : 0.0; depthOut = d < 1.0 ? d : 1.0; }\n";
                break;
            case Opcode::TexM3x3Tex:
                o << "    { precise float d = " << rowDot(stage, op.src[0]) << "; W = d; }\n";
                sampleInto(stage, "P0", "P1", "W", dst);
                break;
            case Opcode::TexM3x3:
                o << "    { precise float d = " << rowDot(stage, op.src[0]) << "; W = d; }\n";
                writeFloat(dst, 0, "P0", false);
                writeFloat(dst, 1, "P1", false);
                writeFloat(dst, 2, "W", false);
                writeFloat(dst, 3, "1.0", false);
                break;
            case Opcode::TexM3x3Spec:
            case Opcode::TexM3x3VSpec: {
                o << "    { precise float nz = " << rowDot(stage, op.src[0]) << ";\n";
                if (op.op == Opcode::TexM3x3Spec) {
                    const std::string c = fx ? "uConstF[" + std::to_string(op.src[1].slot) + "]"
                                             : "uConstF[" + std::to_string(op.src[1].slot) + "]";
                    o << "      vec3 E = " << c << ".xyz;\n";
                } else {
                    o << "      vec3 E = vec3(" << tc(op.rowBase, 3) << ", " << tc(op.rowBase + 1, 3) << ", "
                      << tc(op.rowBase + 2, 3) << ");\n";
                }
                o << "      precise float ne = (P0 * E.x + P1 * E.y) + nz * E.z;\n"
                  << "      precise float nn = (P0 * P0 + P1 * P1) + nz * nz;\n"
                  << "      precise float f = nn == 0.0 ? 0.0 : fdiv(2.0 * ne, nn);\n"
                  << "      precise float ru = f * P0 - E.x; precise float rv = f * P1 - E.y; precise float rw = f * nz - E.z;\n"
                  << "      U = ru; V = rv; W = rw; }\n";
                sampleInto(stage, "U", "V", "W", dst);
                break;
            }
            case Opcode::TexDp3Tex:
                o << "    { precise float d = " << rowDot(stage, op.src[0]) << "; U = d; }\n";
                sampleInto(stage, "U", "0.0", "0.0", dst);
                break;
            case Opcode::TexDp3:
                o << "    { precise float d = " << rowDot(stage, op.src[0]) << "; U = d; }\n";
                for (int c = 0; c < 4; ++c) writeFloat(dst, c, "U", false);
                break;
            case Opcode::TexDepth:
                o << "    { float r = " << regFloat(dst, 0, SrcMod::None) << ", g = " << regFloat(dst, 1, SrcMod::None)
                  << ";\n      float d = g == 0.0 ? 1.0 : fdiv(r, g); d = d > 0.0 ? d : 0.0; depthOut = d < 1.0 ? d : 1.0; }\n";
                break;
            default:
                break;
        }
    }

    // ---- arithmetic (ps11/executor_arith.cpp) ----
    // fx: source s, output channel c as k = a·n + b (k / 2G is the value).
    std::string k(const DOp& op, int s, int c) const {
        const DSrc& src = op.src[size_t(s)];
        int a = 2, b = 0;
        const int g = p.g;
        switch (src.mod) {
            case SrcMod::Neg: a = -2; break;
            case SrcMod::Bias: b = -g; break;
            case SrcMod::BiasNeg: a = -2, b = g; break;
            case SrcMod::Sign: a = 4, b = -2 * g; break;
            case SrcMod::SignNeg: a = -4, b = 2 * g; break;
            case SrcMod::Comp: a = -2, b = 2 * g; break;
            case SrcMod::X2: a = 4; break;
            case SrcMod::X2Neg: a = -4; break;
            default: break;
        }
        const int comp = src.sw[size_t(c)];
        const std::string v = src.kind == SrcKind::Const ? "uConstG[" + std::to_string(src.slot) + "]." + kComp[comp]
                                                         : reg(src.slot, comp);
        return "(" + std::to_string(a) + " * " + v + " + " + std::to_string(b) + ")";
    }
    std::string x(const DOp& op, int s, int c) const {
        const DSrc& src = op.src[size_t(s)];
        const int comp = src.sw[size_t(c)];
        const std::string r = src.kind == SrcKind::Const ? "uConstF[" + std::to_string(src.slot) + "]." + kComp[comp]
                                                         : reg(src.slot, comp);
        switch (src.mod) {
            case SrcMod::Neg: return "(-" + r + ")";
            case SrcMod::Bias: return "(" + r + " - 0.5)";
            case SrcMod::BiasNeg: return "(-(" + r + " - 0.5))";
            case SrcMod::Sign: return "(2.0 * " + r + " - 1.0)";
            case SrcMod::SignNeg: return "(-(2.0 * " + r + " - 1.0))";
            case SrcMod::Comp: return "(1.0 - " + r + ")";
            case SrcMod::X2: return "(2.0 * " + r + ")";
            case SrcMod::X2Neg: return "(-(2.0 * " + r + "))";
            default: return r;
        }
    }
    void arith(const DOp& op) {
        const uint8_t fm = op.op == Opcode::Dp3 ? 7 : op.op == Opcode::Dp4 ? 15 : op.op == Opcode::Bem ? 3 : op.mask;
        const std::string T = fx ? "ivec4" : "vec4";
        o << "    { " << (fx ? "" : "precise ") << T << " t = " << (op.hold ? "H" : "R[" + std::to_string(op.dstSlot) + "]")
          << ";\n";
        if (fx)
            arithFx(op, fm);
        else
            arithFloat(op, fm);
        if (op.hold) {
            o << "      H = t; }\n";
        } else {
            for (int c = 0; c < 4; ++c)
                if ((op.mask >> c) & 1) o << "      R[" << int(op.dstSlot) << "]." << kComp[c] << " = t." << kComp[c] << ";\n";
            o << "    }\n";
        }
    }
    void arithFx(const DOp& op, uint8_t) {
        const int g = p.g;
        const int lo = op.sat ? (p.nMax < 0 ? p.nMax : 0) : -p.nMax;
        const int hi = op.sat ? std::min(g, p.nMax) : p.nMax;
        const bool wide = p.wide;
        const std::string W = wide ? "int64_t" : "int";
        const std::string rc = wide ? "rc64" : "rc32";
        const int sh = op.shift;
        auto finish = [&](const std::string& numer, int64_t d0) {
            int64_t d = d0;
            std::string n = numer;
            if (sh > 0) n = "(" + n + ") * " + W + "(" + std::to_string(1 << sh) + ")";
            if (sh < 0) d = d0 << -sh;
            return rc + "(" + n + ", " + W + "(" + std::to_string(d) + "), " + std::to_string(lo) + ", " +
                   std::to_string(hi) + ")";
        };
        const int64_t kLin = 2, kProd = 4 * int64_t(g);
        auto K = [&](int s, int c) { return W + k(op, s, c); };
        if (op.op == Opcode::Dp3 || op.op == Opcode::Dp4) {
            std::string sum;
            for (int c = 0; c < (op.op == Opcode::Dp3 ? 3 : 4); ++c)
                sum += (c ? " + " : "") + K(0, c) + " * " + K(1, c);
            o << "      int d = " << finish(sum, kProd) << ";\n";
            for (int c = 0; c < 4; ++c)
                if ((op.mask >> c) & 1) o << "      t." << kComp[c] << " = d;\n";
            return;
        }
        if (op.op == Opcode::Bem) {
            // d.r = a.r + M00·b.r + M10·b.g, d.g = a.g + M01·b.r + M11·b.g in double, rounded once.
            const std::string m = "uBump[" + std::to_string(op.stage) + "]";
            const double scale = std::ldexp(0.5, sh);
            for (int c = 0; c < 2; ++c) {
                if (!((op.mask >> c) & 1)) continue;
                const std::string mr = c == 0 ? m + ".x" : m + ".y", mg = c == 0 ? m + ".z" : m + ".w";
                o << "      { precise double v = roundEven((double(" << k(op, 0, c) << ") + double(" << mr << ") * double("
                  << k(op, 1, 0) << ") + double(" << mg << ") * double(" << k(op, 1, 1) << ")) * " << num(scale)
                  << "lf);\n        v = v < " << lo << ".0lf ? " << lo << ".0lf : (v > " << hi << ".0lf ? " << hi
                  << ".0lf : v); t." << kComp[c] << " = int(v); }\n";
            }
            return;
        }
        for (int c = 0; c < 4; ++c) {
            if (!((op.mask >> c) & 1)) continue;
            std::string e;
            switch (op.op) {
                case Opcode::Mov: e = finish(K(0, c), kLin); break;
                case Opcode::Add: e = finish(K(0, c) + " + " + K(1, c), kLin); break;
                case Opcode::Sub: e = finish(K(0, c) + " - " + K(1, c), kLin); break;
                case Opcode::Mul: e = finish(K(0, c) + " * " + K(1, c), kProd); break;
                case Opcode::Mad:
                    e = finish(K(0, c) + " * " + K(1, c) + " + " + W + "(" + std::to_string(2 * g) + ") * " + K(2, c), kProd);
                    break;
                case Opcode::Lrp:
                    e = finish(K(0, c) + " * (" + K(1, c) + " - " + K(2, c) + ") + " + W + "(" + std::to_string(2 * g) +
                                   ") * " + K(2, c),
                               kProd);
                    break;
                case Opcode::Cnd:
                    e = finish("(" + k(op, 0, c) + " > " + std::to_string(g) + " ? " + K(1, c) + " : " + K(2, c) + ")", kLin);
                    break;
                case Opcode::Cmp:
                    e = finish("(" + k(op, 0, c) + " >= 0 ? " + K(1, c) + " : " + K(2, c) + ")", kLin);
                    break;
                default: continue;
            }
            o << "      t." << kComp[c] << " = " << e << ";\n";
        }
    }
    void arithFloat(const DOp& op, uint8_t) {
        const float scale = std::ldexp(1.0f, op.shift);
        auto finish = [&](const std::string& e) {
            std::string s = "{ precise float v = (" + e + ") * " + flit(scale) + ";";
            if (op.sat) s += " v = v > 0.0 ? v : 0.0; v = v < 1.0 ? v : 1.0;";
            if (p.clampRange)
                s += " v = v < " + flit(-p.maxValue) + " ? " + flit(-p.maxValue) + " : v; v = v > " + flit(p.maxValue) +
                     " ? " + flit(p.maxValue) + " : v;";
            return s;
        };
        if (op.op == Opcode::Dp3 || op.op == Opcode::Dp4) {
            std::string e = "(" + x(op, 0, 0) + " * " + x(op, 1, 0) + " + " + x(op, 0, 1) + " * " + x(op, 1, 1) + ") + " +
                            x(op, 0, 2) + " * " + x(op, 1, 2);
            if (op.op == Opcode::Dp4) e = "(" + e + ") + " + x(op, 0, 3) + " * " + x(op, 1, 3);
            o << "      " << finish(e) << " t = vec4(v); }\n";
            return;
        }
        if (op.op == Opcode::Bem) {
            const std::string m = "uBump[" + std::to_string(op.stage) + "]";
            for (int c = 0; c < 2; ++c) {
                if (!((op.mask >> c) & 1)) continue;
                const std::string mr = c == 0 ? m + ".x" : m + ".y", mg = c == 0 ? m + ".z" : m + ".w";
                o << "      " << finish(x(op, 0, c) + " + (" + mr + " * " + x(op, 1, 0) + " + " + mg + " * " + x(op, 1, 1) + ")")
                  << " t." << kComp[c] << " = v; }\n";
            }
            return;
        }
        for (int c = 0; c < 4; ++c) {
            if (!((op.mask >> c) & 1)) continue;
            std::string e;
            switch (op.op) {
                case Opcode::Mov: e = x(op, 0, c); break;
                case Opcode::Add: e = x(op, 0, c) + " + " + x(op, 1, c); break;
                case Opcode::Sub: e = x(op, 0, c) + " - " + x(op, 1, c); break;
                case Opcode::Mul: e = x(op, 0, c) + " * " + x(op, 1, c); break;
                case Opcode::Mad: e = x(op, 0, c) + " * " + x(op, 1, c) + " + " + x(op, 2, c); break;
                case Opcode::Lrp: e = x(op, 2, c) + " + " + x(op, 0, c) + " * (" + x(op, 1, c) + " - " + x(op, 2, c) + ")"; break;
                case Opcode::Cnd: e = x(op, 0, c) + " > 0.5 ? " + x(op, 1, c) + " : " + x(op, 2, c); break;
                case Opcode::Cmp: e = x(op, 0, c) + " >= 0.0 ? " + x(op, 1, c) + " : " + x(op, 2, c); break;
                default: continue;
            }
            o << "      " << finish(e) << " t." << kComp[c] << " = v; }\n";
        }
    }

    // ---- the whole shader ----
    std::string run() {
        o << "#version " << kGlslVersion << " core\n#extension GL_ARB_gpu_shader_int64 : require\n";
        o << "uniform usamplerBuffer uTri;\nuniform int uStride;\nuniform int uPrimBase;\n";
        o << "uniform ivec4 uConstG[8];\nuniform vec4 uConstF[8];\nuniform vec4 uBump[8];\nuniform vec2 uLum[8];\n";
        o << "uniform ivec4 uBorderG[8];\nuniform vec4 uBorderF[8];\n";
        o << "uniform usampler2D uDstColor;\nuniform usampler2D uDstDepth;\n";
        for (int s = 0; s < 8; ++s) {
            const StageSpec& st = spec.stages[size_t(s)];
            if (!st.bound) continue;
            o << "uniform " << (fx ? (st.unorm8 ? "usampler" : "isampler") : "sampler") << (st.volume ? "3D" : "2D")
              << " uT" << s << ";\n";
        }
        o << "layout(location = 0) out uvec4 oColor;\nlayout(location = 1) out uint oDepth;\n";
        o << kCommon;
        bool samples = false;
        for (int s = 0; s < 8; ++s)
            samples = samples || (((spec.program->stagesUsed >> s) & 1) && spec.stages[size_t(s)].bound);
        if (samples) o << kSampling;
        o << "int gBase;\n"
             "double recD(int i) { uvec4 t = texelFetch(uTri, gBase + 6 + (i >> 1)); return packDouble2x32((i & 1) == 0 ? t.xy : t.zw); }\n"
             "int64_t recE(int i) { uvec4 t = texelFetch(uTri, gBase + 1 + (i >> 1)); return int64_t(packUint2x32((i & 1) == 0 ? t.xy : t.zw)); }\n"
             "// The rasteriser's plane value at pixel p (emu/raster.h planeValue).\n"
             "float planeAt(int i, ivec2 p, double ox, double oy) {\n"
             "    precise double row = recD(i) + recD(i + 1) * (0.0lf - ox) + recD(i + 2) * (double(p.y) - oy);\n"
             "    precise float r = float(row) + float(recD(i + 1)) * float(p.x);\n"
             "    return r;\n}\n";
        for (int s = 0; s < 8; ++s)
            if ((spec.program->stagesUsed >> s) & 1) sampler(s);
        mergeFunctions();
        o << "void main() {\n";
        o << "    ivec2 P = ivec2(gl_FragCoord.xy);\n    gBase = (uPrimBase + (gl_PrimitiveID >> 1)) * uStride;\n";
        o << "    uvec4 head = texelFetch(uTri, gBase);\n    bool persp = head.x != 0u;\n"
             "    uint64_t cmask = packUint2x32(head.yz);\n";
        // Coverage exactly as the rasteriser decides it (emu/raster.h: edge functions in 1/256
        // pixel, the top-left rule): GL draws each triangle's bounding rectangle.
        o << "    bool covered = true;\n"
             "    for (int e = 0; e < 3; ++e) {\n"
             "        int64_t E = recE(e) * int64_t(P.x * 256) + recE(3 + e) * int64_t(P.y * 256) + recE(6 + e);\n"
             "        if (E < int64_t((head.w >> uint(e)) & 1u)) covered = false;\n    }\n";
        // Without derivatives (no stage's level or filter depends on them) an uncovered pixel
        // has nothing to contribute to its quad: it leaves at once.
        bool early = true;
        for (int s = 0; s < 8; ++s)
            if ((spec.program->stagesUsed >> s) & 1 && spec.stages[size_t(s)].bound && !lodFree(spec.stages[size_t(s)]) &&
                !(spec.hardwareFiltering && !fx))
                early = false;
        if (early) o << "    if (!covered) discard;\n";
        o << "    double ox = recD(0), oy = recD(1);\n";
        o << "    float inv = 1.0;\n    if (persp) { float r = planeAt(2, P, ox, oy); r = r < 1e-30 ? 1e-30 : r; inv = fdiv(1.0, r); }\n";
        // Attributes: v0, v1 (diffuse, specular), TC[0..7].
        o << "    vec4 VC[2] = vec4[2](vec4(0.0), vec4(0.0));\n    vec4 TC[8];\n"
             "    for (int i = 0; i < 8; ++i) TC[i] = vec4(0.0);\n";
        int idx = 8;
        for (int a = 0; a < kAttrCount; ++a) {
            if (!((spec.usedAttributes >> a) & 1)) continue;
            std::string dst;
            if (a < kAttrSpecular) dst = std::string("VC[0].") + kComp[a];
            else if (a < kAttrTex) dst = std::string("VC[1].") + kComp[a - kAttrSpecular];
            else dst = "TC[" + std::to_string((a - kAttrTex) / 4) + "]." + kComp[(a - kAttrTex) % 4];
            o << "    if (((cmask >> " << a << "u) & uint64_t(1)) != uint64_t(0)) " << dst << " = float(recD(" << idx << "));\n"
              << "    else { precise float v = planeAt(" << idx << ", P, ox, oy); if (persp) v = v * inv; " << dst
              << " = v; }\n";
            idx += 3;
        }
        o << "    float zPlane = " << (spec.wantZ ? "planeAt(5, P, ox, oy)" : "0.0") << ";\n";
        o << "    bool killed = false;\n    float depthOut = 0.0;\n";
        o << "    float U = 0.0, V = 0.0, W = 0.0, P0 = 0.0, P1 = 0.0;\n    vec4 C4 = vec4(0.0);\n";
        // Registers: r0..r5, t0..t5, v0, v1 (the executor's slots).
        if (fx) {
            o << "    ivec4 R[14];\n    for (int i = 0; i < 14; ++i) R[i] = ivec4(0);\n    ivec4 H = ivec4(0);\n";
            for (int v = 0; v < 2; ++v)
                if ((spec.program->vUsed >> v) & 1)
                    o << "    for (int c = 0; c < 4; ++c) { float s = VC[" << v << "][c]; s = s > 0.0 ? (s < 1.0 ? s : 1.0) : 0.0;"
                      << " R[" << 12 + v << "][c] = int(roundEven(double(s) * " << num(p.g) << ")); }\n";
        } else {
            o << "    vec4 R[14];\n    for (int i = 0; i < 14; ++i) R[i] = vec4(0.0);\n    vec4 H = vec4(0.0);\n";
            for (int v = 0; v < 2; ++v)
                if ((spec.program->vUsed >> v) & 1)
                    o << "    for (int c = 0; c < 4; ++c) { float s = VC[" << v << "][c]; R[" << 12 + v
                      << "][c] = s > 0.0 ? (s < 1.0 ? s : 1.0) : 0.0; }\n";
        }
        const auto& ops = spec.program->ops;
        for (size_t i = 0; i < ops.size(); ++i) {
            const DOp& op = ops[i];
            if (op.op == Opcode::Phase) continue;
            if (op.texture)
                texture(op);
            else
                arith(op);
            if (!op.hold && i > 0 && ops[i - 1].hold) {
                const DOp& first = ops[i - 1];
                for (int c = 0; c < 4; ++c)
                    if ((first.mask >> c) & 1) o << "    R[" << int(first.dstSlot) << "]." << kComp[c] << " = H." << kComp[c] << ";\n";
            }
        }
        o << "    if (killed || !covered) discard;\n";
        mergeMain();
        o << "}\n";
        return o.str();
    }

    // ---- the output merger (emu/output_merger.cpp, from its plan) ----
    void mergeFunctions() {
        o << R"(
bool cmpPass(uint mask, bool less, bool equal, bool greater) {
    uint outcome = less ? 0u : equal ? 1u : greater ? 2u : 3u;
    return ((mask >> outcome) & 1u) != 0u;
}
float satf(float v) { return v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0; }
uint byteOfUnit(float v) { return uint(roundEven(double(v) * 255.0lf)); }
// float32 -> IEEE half bits, ties to even (emu/output_merger.cpp halfOf).
uint halfOf(float f) {
    uint bits = floatBitsToUint(f);
    uint sign = (bits >> 16) & 0x8000u;
    uint x = bits & 0x7fffffffu;
    if (x > 0x7f800000u) return sign | 0x7e00u;
    if (x >= 0x477ff000u) return sign | 0x7c00u;
    if (x < 0x38800000u) {
        precise float v = uintBitsToFloat(x) * 16777216.0;
        precise float r = (v + 8388608.0) - 8388608.0;
        return sign | uint(r);
    }
    uint h = (x - 0x38000000u) >> 13;
    uint rest = x & 0x1fffu;
    h += (rest + (h & 1u) > 0x1000u) ? 1u : 0u;
    return sign | h;
}
float floatOfHalf(uint h) {
    uint sign = (h & 0x8000u) << 16;
    uint e = (h >> 10) & 31u, m = h & 1023u;
    if (e == 0u) { float v = float(m) * 5.9604644775390625e-8; return sign != 0u ? -v : v; }
    if (e == 31u) return uintBitsToFloat(sign | 0x7f800000u | (m != 0u ? 0x400000u | (m << 13) : 0u));
    return uintBitsToFloat(sign | ((e + 112u) << 23) | (m << 13));
}
)";
        const int g = p.g;
        if (fx) {
            o << "uint byteOfGrid(int n) { return " << (g == 255 ? "uint(n)" : "uint(n + 7 + ((n >> 4) & 1)) >> 4") << "; }\n";
            o << "uint blendByte(int num) { num = clamp(num, 0, " << g * g << ");\n";
            if (g == 255)
                o << "    return uint(num + 127) / 255u; }\n";
            else
                o << "    uint D = 65280u; uint u = uint(num), q = u / D, r = u - q * D;\n"
                     "    return q + ((2u * r > D || (2u * r == D && (q & 1u) != 0u)) ? 1u : 0u); }\n";
        }
    }
    // A factor value on the plan's scale (slots of emu/merge_plan.h).
    std::string factor(const Factor& f, const std::string& one) const {
        std::string v;
        switch (f.slot) {
            case kZero: v = "ZERO"; break;
            case kOne: v = one; break;
            case kSat: v = "vsat"; break;
            default:
                if (f.slot >= kSrc && f.slot < kSrc + 4) v = std::string("s[") + char('0' + f.slot - kSrc) + "]";
                else if (f.slot >= kDst && f.slot < kDst + 4) v = std::string("d[") + char('0' + f.slot - kDst) + "]";
                else v = std::string("bf[") + char('0' + f.slot - kBf) + "]";
        }
        if (v == "ZERO") v = fx ? "0" : "0.0";
        return f.inv ? "(" + one + " - " + v + ")" : v;
    }
    void depthTest() {
        const Plan& m = spec.merge;
        if (!m.depthTest) return;
        o << "    { float z = " << (spec.shaderDepth ? "depthOut" : "zPlane") << "; z = z > 0.0 ? (z < 1.0 ? z : 1.0) : 0.0;\n"
          << "      uint old = texelFetch(uDstDepth, P, 0).x; bool pass; uint neu = old;\n";
        switch (m.depthKind) {
            case DepthKind::D16:
            case DepthKind::D24:
            case DepthKind::D32: {
                const char* scale = m.depthKind == DepthKind::D16 ? "65535.0lf" : m.depthKind == DepthKind::D24 ? "16777215.0lf" : "4294967295.0lf";
                o << "      uint code = uint(roundEven(double(z) * " << scale << "));\n";
                const char* stored = m.depthKind == DepthKind::D16 ? "(old & 0xffffu)" : m.depthKind == DepthKind::D24 ? "(old >> 8)" : "old";
                o << "      uint st = " << stored << "; pass = cmpPass(" << m.depthMask << "u, code < st, code == st, code > st);\n";
                o << "      neu = " << (m.depthKind == DepthKind::D24 ? "(old & 0xffu) | (code << 8)" : "code") << ";\n";
                break;
            }
            case DepthKind::D32F:
                o << "      float st = uintBitsToFloat(old); pass = cmpPass(" << m.depthMask << "u, z < st, z == st, z > st);\n"
                  << "      neu = floatBitsToUint(z);\n";
                break;
        }
        o << "      if (!pass) discard;\n      oDepth = neu; }\n";
    }
    void mergeMain() {
        const Plan& m = spec.merge;
        const int g = p.g;
        const bool hasColor = m.color != nullptr;
        const bool unorm = !hasColor || m.target == TargetKind::Argb8 || m.target == TargetKind::Xrgb8;
        const bool x8 = hasColor && m.target == TargetKind::Xrgb8;
        o << "    oColor = uvec4(0u); oDepth = 0u;\n";
        if (fx && unorm) {
            // mergeFxUnorm8: integers on the grid.
            o << "    int s[4]; for (int c = 0; c < 4; ++c) s[c] = clamp(R[0][c], 0, " << g << ");\n";
            if (m.fog) {
                o << "    { int fq = int(roundEven(double(satf(VC[1].w)) * " << num(g) << "));\n";
                for (int c = 0; c < 3; ++c)
                    o << "      s[" << c << "] = rc64(int64_t(fq) * int64_t(s[" << c << "]) + int64_t(" << g << " - fq) * "
                      << int(m.fogByte[c]) * (g / 255) << "l, " << g << "l, -2147483647, 2147483647);\n";
                o << "    }\n";
            }
            if (m.alphaTest)
                o << "    { uint a = byteOfGrid(s[3]); if (!cmpPass(" << m.alphaMask << "u, a < " << m.alphaRef << "u, a == "
                  << m.alphaRef << "u, a > " << m.alphaRef << "u)) discard; }\n";
            depthTest();
            if (!hasColor) return;
            o << "    uint outb[4];\n";
            if (!m.blend) {
                o << "    for (int c = 0; c < 4; ++c) outb[c] = byteOfGrid(s[c]);\n";
            } else {
                const int S = g / 255;
                o << "    uint old = texelFetch(uDstColor, P, 0).x;\n"
                  << "    int d[4] = int[4](int((old >> 16) & 0xffu) * " << S << ", int((old >> 8) & 0xffu) * " << S
                  << ", int(old & 0xffu) * " << S << ", " << (x8 ? std::to_string(g) : "int(old >> 24) * " + std::to_string(S)) << ");\n"
                  << "    int bf[4] = int[4](" << int(m.bfByte[0]) * S << ", " << int(m.bfByte[1]) * S << ", "
                  << int(m.bfByte[2]) * S << ", " << int(m.bfByte[3]) * S << ");\n"
                  << "    int vsat = min(s[3], " << g << " - d[3]);\n";
                for (int c = 0; c < 4; ++c) {
                    const ChannelPlan& cp = m.ch[c];
                    if (cp.kind == OpKind::Linear)
                        o << "    outb[" << c << "] = blendByte(" << cp.cs << " * s[" << c << "] * " << factor(cp.src, std::to_string(g))
                          << " + " << cp.cd << " * d[" << c << "] * " << factor(cp.dst, std::to_string(g)) << ");\n";
                    else
                        o << "    outb[" << c << "] = byteOfGrid(" << (cp.kind == OpKind::Min ? "min" : "max") << "(s[" << c
                          << "], d[" << c << "]));\n";
                }
            }
            storeUnorm(x8);
            return;
        }
        // mergeFloat: float32 arithmetic (fx profiles: grid values, exact fog and alpha test).
        o << "    float s[4];\n";
        if (fx) {
            o << "    int gn[4]; for (int c = 0; c < 4; ++c) gn[c] = R[0][c];\n";
            if (m.fog) {
                o << "    { int fq = int(roundEven(double(satf(VC[1].w)) * " << num(g) << "));\n";
                for (int c = 0; c < 3; ++c)
                    o << "      gn[" << c << "] = rc64(int64_t(fq) * int64_t(gn[" << c << "]) + int64_t(" << g << " - fq) * "
                      << int(m.fogByte[c]) * (g / 255) << "l, " << g << "l, -2147483647, 2147483647);\n";
                o << "    }\n";
            }
            o << "    for (int c = 0; c < 4; ++c) s[c] = fdiv(float(gn[c]), " << g << ".0);\n";
            if (m.alphaTest)
                o << "    { int64_t a = int64_t(gn[3]) * 255l, r = int64_t(" << m.alphaRef << ") * " << g << "l;\n"
                  << "      if (!cmpPass(" << m.alphaMask << "u, a < r, a == r, a > r)) discard; }\n";
        } else {
            o << "    for (int c = 0; c < 4; ++c) s[c] = " << (unorm ? "satf(R[0][c])" : "R[0][c]") << ";\n";
            if (m.fog) {
                o << "    { float f = satf(VC[1].w);\n";
                for (int c = 0; c < 3; ++c)
                    o << "      { precise float v = f * s[" << c << "] + (1.0 - f) * " << flit(float(m.fogByte[c]) / 255.0f)
                      << "; s[" << c << "] = v; }\n";
                o << "    }\n";
            }
            if (m.alphaTest) {
                if (unorm)
                    o << "    { uint a = byteOfUnit(s[3]); if (!cmpPass(" << m.alphaMask << "u, a < " << m.alphaRef
                      << "u, a == " << m.alphaRef << "u, a > " << m.alphaRef << "u)) discard; }\n";
                else
                    o << "    { double a = double(s[3]) * 255.0lf, r = " << m.alphaRef << ".0lf;\n"
                      << "      if (!cmpPass(" << m.alphaMask << "u, a < r, a == r, a > r)) discard; }\n";
            }
        }
        depthTest();
        if (!hasColor) return;
        auto blendFloat = [&](int c, const std::string& sv, const std::string& dv) {
            const ChannelPlan& cp = m.ch[c];
            if (cp.kind != OpKind::Linear)
                return std::string(cp.kind == OpKind::Min ? "(" + sv + " < " + dv + " ? " + sv + " : " + dv + ")"
                                                          : "(" + sv + " > " + dv + " ? " + sv + " : " + dv + ")");
            const bool zs = cp.src.slot == kZero && !cp.src.inv, zd = cp.dst.slot == kZero && !cp.dst.inv;
            const std::string ts = "(" + num(cp.cs) + " * (" + sv + " * " + factor(cp.src, "1.0") + "))";
            const std::string td = "(" + num(cp.cd) + " * (" + dv + " * " + factor(cp.dst, "1.0") + "))";
            if (zs) return zd ? std::string("0.0") : td;
            if (zd) return ts;
            return "(" + ts + " + " + td + ")";
        };
        const std::string bfDecl = "    float bf[4] = float[4](" + flit(float(m.bfByte[0]) / 255.0f) + ", " +
                                   flit(float(m.bfByte[1]) / 255.0f) + ", " + flit(float(m.bfByte[2]) / 255.0f) + ", " +
                                   flit(float(m.bfByte[3]) / 255.0f) + ");\n";
        if (unorm) {
            o << "    uint outb[4];\n";
            if (!m.blend) {
                o << "    for (int c = 0; c < 4; ++c) outb[c] = byteOfUnit(satf(s[c]));\n";
            } else {
                o << "    uint old = texelFetch(uDstColor, P, 0).x;\n"
                  << "    float d[4] = float[4](fdiv(float((old >> 16) & 0xffu), 255.0), fdiv(float((old >> 8) & 0xffu), 255.0), "
                     "fdiv(float(old & 0xffu), 255.0), "
                  << (x8 ? "1.0" : "fdiv(float(old >> 24), 255.0)") << ");\n"
                  << bfDecl << "    float vsat = min(s[3], 1.0 - d[3]);\n";
                for (int c = 0; c < 4; ++c)
                    o << "    { precise float v = " << blendFloat(c, "s[" + std::to_string(c) + "]", "d[" + std::to_string(c) + "]")
                      << "; outb[" << c << "] = byteOfUnit(satf(v)); }\n";
            }
            storeUnorm(x8);
            return;
        }
        // Float targets: raw words r g b a (A16B16G16R16F: two words of two halves).
        if (m.blend) {
            o << "    uvec4 oldw = texelFetch(uDstColor, P, 0);\n    float d[4];\n";
            if (m.target == TargetKind::Rgba16F)
                o << "    d[0] = floatOfHalf(oldw.x & 0xffffu); d[1] = floatOfHalf(oldw.x >> 16); d[2] = floatOfHalf(oldw.y & 0xffffu);"
                     " d[3] = floatOfHalf(oldw.y >> 16);\n";
            else if (m.target == TargetKind::Rgba32F)
                o << "    for (int c = 0; c < 4; ++c) d[c] = uintBitsToFloat(oldw[c]);\n";
            else
                o << "    d[0] = uintBitsToFloat(oldw.x); d[1] = 1.0; d[2] = 1.0; d[3] = 1.0;\n";
            o << bfDecl << "    float vsat = min(s[3], 1.0 - d[3]);\n    float b[4];\n";
            for (int c = 0; c < 4; ++c)
                o << "    { precise float v = " << blendFloat(c, "s[" + std::to_string(c) + "]", "d[" + std::to_string(c) + "]")
                  << "; b[" << c << "] = v; }\n";
            o << "    for (int c = 0; c < 4; ++c) s[c] = b[c];\n";
        }
        const bool needOld = m.channels != 15u && m.target != TargetKind::R32F;
        o << "    uvec4 w = " << (needOld ? "texelFetch(uDstColor, P, 0)" : "uvec4(0u)") << ";\n";
        if (m.target == TargetKind::Rgba16F) {
            o << "    uint h[4]; for (int c = 0; c < 4; ++c) h[c] = halfOf(s[c]);\n";
            o << "    uint h0[4] = uint[4](w.x & 0xffffu, w.x >> 16, w.y & 0xffffu, w.y >> 16);\n";
            for (int c = 0; c < 4; ++c)
                if (!((m.channels >> c) & 1u)) o << "    h[" << c << "] = h0[" << c << "];\n";
            o << "    oColor = uvec4(h[0] | (h[1] << 16), h[2] | (h[3] << 16), 0u, 0u);\n";
        } else if (m.target == TargetKind::Rgba32F) {
            for (int c = 0; c < 4; ++c)
                if ((m.channels >> c) & 1u) o << "    w[" << c << "] = floatBitsToUint(s[" << c << "]);\n";
            o << "    oColor = w;\n";
        } else {
            o << "    oColor = uvec4(" << ((m.channels & 1u) ? "floatBitsToUint(s[0])" : "texelFetch(uDstColor, P, 0).x")
              << ", 0u, 0u, 0u);\n";
        }
    }
    void storeUnorm(bool x8) {
        const Plan& m = spec.merge;
        uint32_t mask = 0;
        if (m.channels & 1u) mask |= 0x00ff0000u;
        if (m.channels & 2u) mask |= 0x0000ff00u;
        if (m.channels & 4u) mask |= 0x000000ffu;
        if (m.channels & 8u) mask |= 0xff000000u;
        if (x8 && (m.channels & 7u)) mask |= 0xff000000u;
        o << "    uint word = outb[2] | (outb[1] << 8) | (outb[0] << 16) | (" << (x8 ? "0xffu" : "outb[3]") << " << 24);\n";
        if (mask != 0xffffffffu)
            o << "    word = (word & " << mask << "u) | (texelFetch(uDstColor, P, 0).x & " << ~mask << "u);\n";
        o << "    oColor = uvec4(word, 0u, 0u, 0u);\n";
    }
};

}  // namespace

std::string vertexSource() {
    return "#version " + std::to_string(kGlslVersion) +
           " core\n"
           "layout(location = 0) in vec2 aPos;\n"
           "uniform vec4 uXform;\n"
           "void main() { gl_Position = vec4(aPos * uXform.xy + uXform.zw, 0.0, 1.0); }\n";
}

std::string fragmentSource(const FragmentSpec& spec) {
    Gen g(spec);
    return g.run();
}

// Texels before the doubles: the header, then the edge functions' a b c (9 int64, two a texel).
constexpr int kRecordHead = 6;

int recordTexels(uint64_t used) {
    int doubles = 8 + 3 * __builtin_popcountll(used);
    return kRecordHead + (doubles + 1) / 2;
}

void writeRecord(const TriangleSetup& s, uint64_t used, uint32_t* out) {
    const int n = recordTexels(used);
    std::memset(out, 0, sizeof(uint32_t) * 4 * size_t(n));
    out[0] = s.perspective ? 1u : 0u;
    out[1] = uint32_t(s.constMask & used);
    out[2] = uint32_t((s.constMask & used) >> 32);
    out[3] = uint32_t(s.t[0] | (s.t[1] << 1) | (s.t[2] << 2));
    const int64_t edges[9] = {s.a[0], s.a[1], s.a[2], s.b[0], s.b[1], s.b[2], s.c[0], s.c[1], s.c[2]};
    std::memcpy(out + 4, edges, sizeof edges);
    std::vector<double> d = {s.ox, s.oy, s.rhw.base, s.rhw.dx, s.rhw.dy, s.z.base, s.z.dx, s.z.dy};
    for (int a = 0; a < kAttrCount; ++a) {
        if (!((used >> a) & 1)) continue;
        if ((s.constMask >> a) & 1) {
            d.insert(d.end(), {double(s.constValue[size_t(a)]), 0.0, 0.0});
        } else {
            const Plane& pl = s.attr[size_t(a)];
            d.insert(d.end(), {pl.base, pl.dx, pl.dy});
        }
    }
    std::memcpy(out + 4 * kRecordHead, d.data(), d.size() * sizeof(double));
}

}  // namespace emu::gl
