// ps_1_x → GLSL, the sampling part (emu/gl/glsl.h): one function per sampled stage replicating
// the software sampler (ps11/texture_sampler.cpp): level selection from the quad's exact values,
// per-axis texel positions and address modes, 8-bit weights, the exact weighted sums in the fx
// profiles and the float32 lerps in the float profiles; or GL's texture unit when asked.
#include "emu/gl/glsl_internal.h"

namespace emu::gl::detail {

using ps11::Precision;

const char* const kSampling = R"(
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

void writeSampler(GlslContext& cx, int s) {
    const FragmentSpec& spec = cx.spec;
    const ps11::exec::Profile& p = cx.p;
    const bool fx = cx.fx;
    std::ostringstream& o = cx.o;
    auto G = [&] { return std::to_string(p.g); };
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
    if ((spec.hardwareFiltering || spec.native) && !fx) {
        o << "    return texture(" << tex << ", " << (vol ? "vec3(u, v, w)" : "vec2(u, v)") << ");\n}\n";
        return;
    }
    auto effLinear = [](ps11::Filter f) { return f == ps11::Filter::Linear; };
    const bool magLin = effLinear(st.state.magFilter), minLin = effLinear(st.state.minFilter);
    const bool weights8 = !fx && spec.weightBits == 8 && spec.precision == Precision::Float;
    const std::string scale = std::to_string(p.g / 255);
    // One texel of level lv as grid integers (8-bit texels scaled to the grid).
    auto texel = [&](const std::string& coord, const std::string& lv) {
        std::string f = "texelFetch(" + tex + ", " + coord + ", " + lv + ")";
        // A resident A8R8G8B8 surface: its raw words, b | g << 8 | r << 16 | a << 24.
        if (st.packedWords)
            f = "(uvec4(" + f + ".x) >> uvec4(16u, 8u, 0u, 24u) & uvec4(255u))";
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
        o << "            for (int z = 0; z < " << (vol ? 2 : 1)
          << "; ++z) for (int y = 0; y < 2; ++y) for (int x = 0; x < 2; ++x) {\n"
          << "                int X = x == 0 ? ia[0].x : ia[0].y; int Y = y == 0 ? ia[1].x : ia[1].y;\n"
          << "                int Z = z == 0 ? ia[2].x : ia[2].y;\n"
          << "                int64_t wgt = int64_t(x == 0 ? 256 - wa[0] : wa[0]) * int64_t(y == 0 ? 256 - wa[1] : "
             "wa[1])"
          << " * int64_t(" << (vol ? "z == 0 ? 256 - wa[2] : wa[2]" : "256") << ") * mw;\n"
          << "                acc += i64vec4(" << tap("X", "Y", "Z") << ") * wgt;\n"
          << "            }\n        }\n    }\n";
        o << "    return ivec4(roundShift32(acc.x), roundShift32(acc.y), roundShift32(acc.z), "
             "roundShift32(acc.w));\n}\n";
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

}  // namespace emu::gl::detail
