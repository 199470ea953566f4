// ps_1_x → GLSL, the program part (emu/gl/glsl.h): the triangle record, coverage and the
// attribute planes, v# loading, and every arithmetic and texture-address instruction of the
// executor's op list (ps11/executor_arith_fx.inc, ps11/executor_texture.cpp) in the profile's
// terms. The sampling functions are in glsl_sampler.cpp, the merge in glsl_merge.cpp.
#include "emu/gl/glsl.h"

#include "emu/gl/glsl_internal.h"

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
using ps11::kMaxTexCoordSets;
using ps11::kMaxTextureStages;
using ps11::exec::kNumConsts;
using ps11::exec::kNumRegV;
using ps11::exec::kNumSlots;
using ps11::exec::kSlotV;
using namespace detail;

namespace detail {

std::string num(double v) {
    std::ostringstream o;
    o.precision(17);
    o << v;
    std::string s = o.str();
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
    return s;
}

std::string flit(float v) {
    uint32_t b;
    std::memcpy(&b, &v, 4);
    return "uintBitsToFloat(" + std::to_string(b) + "u)";
}

}  // namespace detail

namespace {

const char* const kComp = "xyzw";

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
struct Gen {
    const FragmentSpec& spec;
    const ps11::exec::Profile& p;
    bool fx;
    std::ostringstream o;
    GlslContext ctx{spec, p, fx, o};

    // Native mode is float arithmetic whatever the spec's precision says (the caller decodes
    // the program with a float profile).
    explicit Gen(const FragmentSpec& s)
        : spec(s), p(s.program->profile), fx(!s.native && ps11::isFixedPoint(s.precision)) {}

    std::string G() const { return std::to_string(p.g); }

    // ---- register access ----
    std::string reg(int slot, int comp) const { return regSlot(slot) + "." + kComp[comp]; }
    // Register component as float (fx: n / G correctly rounded), with _bx2 when given.
    std::string regFloat(int slot, int comp, SrcMod mod) const {
        std::string v = fx ? "fdiv(float(" + reg(slot, comp) + "), " + G() + ".0)" : reg(slot, comp);
        if (mod == SrcMod::Sign) v = "(2.0 * " + v + " - 1.0)";
        return v;
    }
    std::string tc(int set, int comp) const {
        return set >= 0 && set < kMaxTexCoordSets ? "TC[" + std::to_string(set) + "]." + kComp[comp] : "0.0";
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
        const std::string r = regSlot(slot);
        o << "    " << r << " = S" << stage << "(" << u << ", " << v << ", " << w << ");\n";
        if (fx)
            o << "    " << r << " = clamp(" << r << ", ivec4(" << -p.nMax << "), ivec4(" << p.nMax << "));\n";
        else if (p.clampRange)
            o << "    " << r << " = clamp(" << r << ", vec4(" << flit(-p.maxValue) << "), vec4(" << flit(p.maxValue)
              << "));\n";
    }

    // ---- texture-address instructions (ps11/executor_texture.cpp) ----
    void staticCoords(int m) {
        const int divisor = ps11::projectionDivisor(p.stages[size_t(m)]);
        if (divisor >= 0) {
            const std::string q = tc(m, divisor);
            o << "    U = fdiv(" << tc(m, 0) << ", " << q << "); V = fdiv(" << tc(m, 1) << ", " << q << "); W = fdiv("
              << tc(m, 2) << ", " << q << ");\n";
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
            o << "      float d = raw[" << d
              << "]; C4.x = d == 0.0 ? 1.0 : fdiv(C4.x, d); C4.y = d == 0.0 ? 1.0 : fdiv(C4.y, d);\n";
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
                        o << "      for (int k = 0; k < 4; ++k) { double x = roundEven(double(" << regSlot(dst)
                          << "[k]) * double(L)); x = x > " << num(-p.nMax) << " ? x : " << num(-p.nMax) << "; x = x < "
                          << num(p.nMax) << " ? x : " << num(p.nMax) << "; " << regSlot(dst) << "[k] = int(x); } }\n";
                    } else {
                        o << "      for (int k = 0; k < 4; ++k) { precise float x = " << regSlot(dst) << "[k] * L;";
                        if (p.clampRange)
                            o << " x = x < " << flit(-p.maxValue) << " ? " << flit(-p.maxValue) << " : x; x = x > "
                              << flit(p.maxValue) << " ? " << flit(p.maxValue) << " : x;";
                        o << " " << regSlot(dst) << "[k] = x; } }\n";
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
                  << "      float d = wv == 0.0 ? 1.0 : fdiv(P0, wv); d = d > 0.0 ? d : 0.0; depthOut = d < 1.0 ? d : "
                     "1.0; }\n";
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
                  << "      precise float ru = f * P0 - E.x; precise float rv = f * P1 - E.y; precise float rw = f * "
                     "nz - E.z;\n"
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
                  << ";\n      float d = g == 0.0 ? 1.0 : fdiv(r, g); d = d > 0.0 ? d : 0.0; depthOut = d < 1.0 ? d : "
                     "1.0; }\n";
                break;
            default:
                break;
        }
    }

    // ---- arithmetic (ps11/executor_arith_fx.inc) ----
    // fx: source s, output channel c as k = a·n + b (k / 2G is the value).
    std::string k(const DOp& op, int s, int c) const {
        const DSrc& src = op.src[size_t(s)];
        int a = 2, b = 0;
        const int g = p.g;
        switch (src.mod) {
            case SrcMod::Neg:
                a = -2;
                break;
            case SrcMod::Bias:
                b = -g;
                break;
            case SrcMod::BiasNeg:
                a = -2, b = g;
                break;
            case SrcMod::Sign:
                a = 4, b = -2 * g;
                break;
            case SrcMod::SignNeg:
                a = -4, b = 2 * g;
                break;
            case SrcMod::Comp:
                a = -2, b = 2 * g;
                break;
            case SrcMod::X2:
                a = 4;
                break;
            case SrcMod::X2Neg:
                a = -4;
                break;
            default:
                break;
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
            case SrcMod::Neg:
                return "(-" + r + ")";
            case SrcMod::Bias:
                return "(" + r + " - 0.5)";
            case SrcMod::BiasNeg:
                return "(-(" + r + " - 0.5))";
            case SrcMod::Sign:
                return "(2.0 * " + r + " - 1.0)";
            case SrcMod::SignNeg:
                return "(-(2.0 * " + r + " - 1.0))";
            case SrcMod::Comp:
                return "(1.0 - " + r + ")";
            case SrcMod::X2:
                return "(2.0 * " + r + ")";
            case SrcMod::X2Neg:
                return "(-(2.0 * " + r + "))";
            default:
                return r;
        }
    }
    void arith(const DOp& op) {
        const std::string T = fx ? "ivec4" : "vec4";
        o << "    { " << (fx ? "" : "precise ") << T
          << " t = " << (op.hold ? "H" : regSlot(op.dstSlot)) << ";\n";
        if (fx)
            arithFx(op);
        else
            arithFloat(op);
        if (op.hold) {
            o << "      H = t; }\n";
        } else {
            for (int c = 0; c < 4; ++c)
                if ((op.mask >> c) & 1)
                    o << "      " << reg(op.dstSlot, c) << " = t." << kComp[c] << ";\n";
            o << "    }\n";
        }
    }
    void arithFx(const DOp& op) {
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
            // The sum over the components both sources read (dp3 .rgb, dp4 .rgba: the opcode table).
            const uint8_t rd = ps11::componentsRead(*op.info, 0, op.mask) & ps11::componentsRead(*op.info, 1, op.mask);
            std::string sum;
            for (int c = 0; c < 4; ++c)
                if ((rd >> c) & 1) sum += (sum.empty() ? "" : " + ") + K(0, c) + " * " + K(1, c);
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
                o << "      { precise double v = roundEven((double(" << k(op, 0, c) << ") + double(" << mr
                  << ") * double(" << k(op, 1, 0) << ") + double(" << mg << ") * double(" << k(op, 1, 1) << ")) * "
                  << num(scale) << "lf);\n        v = v < " << lo << ".0lf ? " << lo << ".0lf : (v > " << hi
                  << ".0lf ? " << hi << ".0lf : v); t." << kComp[c] << " = int(v); }\n";
            }
            return;
        }
        for (int c = 0; c < 4; ++c) {
            if (!((op.mask >> c) & 1)) continue;
            std::string e;
            switch (op.op) {
                case Opcode::Mov:
                    e = finish(K(0, c), kLin);
                    break;
                case Opcode::Add:
                    e = finish(K(0, c) + " + " + K(1, c), kLin);
                    break;
                case Opcode::Sub:
                    e = finish(K(0, c) + " - " + K(1, c), kLin);
                    break;
                case Opcode::Mul:
                    e = finish(K(0, c) + " * " + K(1, c), kProd);
                    break;
                case Opcode::Mad:
                    e = finish(K(0, c) + " * " + K(1, c) + " + " + W + "(" + std::to_string(2 * g) + ") * " + K(2, c),
                               kProd);
                    break;
                case Opcode::Lrp:
                    e = finish(K(0, c) + " * (" + K(1, c) + " - " + K(2, c) + ") + " + W + "(" + std::to_string(2 * g) +
                                   ") * " + K(2, c),
                               kProd);
                    break;
                case Opcode::Cnd:
                    e = finish("(" + k(op, 0, c) + " > " + std::to_string(g) + " ? " + K(1, c) + " : " + K(2, c) + ")",
                               kLin);
                    break;
                case Opcode::Cmp:
                    e = finish("(" + k(op, 0, c) + " >= 0 ? " + K(1, c) + " : " + K(2, c) + ")", kLin);
                    break;
                default:
                    continue;
            }
            o << "      t." << kComp[c] << " = " << e << ";\n";
        }
    }
    void arithFloat(const DOp& op) {
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
            // ((a.r·b.r + a.g·b.g) + a.b·b.b) (+ a.a·b.a) over the components read, as the executor.
            const uint8_t rd = ps11::componentsRead(*op.info, 0, op.mask) & ps11::componentsRead(*op.info, 1, op.mask);
            std::string e;
            int terms = 0;
            for (int c = 0; c < 4; ++c) {
                if (!((rd >> c) & 1)) continue;
                const std::string t = x(op, 0, c) + " * " + x(op, 1, c);
                e = terms == 0 ? t : (terms == 1 ? e : "(" + e + ")") + " + " + t;  // left to right
                ++terms;
            }
            o << "      " << finish(e) << " t = vec4(v); }\n";
            return;
        }
        if (op.op == Opcode::Bem) {
            const std::string m = "uBump[" + std::to_string(op.stage) + "]";
            for (int c = 0; c < 2; ++c) {
                if (!((op.mask >> c) & 1)) continue;
                const std::string mr = c == 0 ? m + ".x" : m + ".y", mg = c == 0 ? m + ".z" : m + ".w";
                o << "      "
                  << finish(x(op, 0, c) + " + (" + mr + " * " + x(op, 1, 0) + " + " + mg + " * " + x(op, 1, 1) + ")")
                  << " t." << kComp[c] << " = v; }\n";
            }
            return;
        }
        for (int c = 0; c < 4; ++c) {
            if (!((op.mask >> c) & 1)) continue;
            std::string e;
            switch (op.op) {
                case Opcode::Mov:
                    e = x(op, 0, c);
                    break;
                case Opcode::Add:
                    e = x(op, 0, c) + " + " + x(op, 1, c);
                    break;
                case Opcode::Sub:
                    e = x(op, 0, c) + " - " + x(op, 1, c);
                    break;
                case Opcode::Mul:
                    e = x(op, 0, c) + " * " + x(op, 1, c);
                    break;
                case Opcode::Mad:
                    e = x(op, 0, c) + " * " + x(op, 1, c) + " + " + x(op, 2, c);
                    break;
                case Opcode::Lrp:
                    e = x(op, 2, c) + " + " + x(op, 0, c) + " * (" + x(op, 1, c) + " - " + x(op, 2, c) + ")";
                    break;
                case Opcode::Cnd:
                    e = x(op, 0, c) + " > 0.5 ? " + x(op, 1, c) + " : " + x(op, 2, c);
                    break;
                case Opcode::Cmp:
                    e = x(op, 0, c) + " >= 0.0 ? " + x(op, 1, c) + " : " + x(op, 2, c);
                    break;
                default:
                    continue;
            }
            o << "      " << finish(e) << " t." << kComp[c] << " = v; }\n";
        }
    }

    // ---- the op list (both modes) ----
    void ops() {
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
                    if ((first.mask >> c) & 1)
                        o << "    " << reg(first.dstSlot, c) << " = H." << kComp[c] << ";\n";
            }
        }
    }

    // ---- native mode (FragmentSpec::native) ----
    std::string runNative();

    // ---- the whole shader ----
    std::string run() {
        o << "#version " << kGlslVersion << " core\n#extension GL_ARB_gpu_shader_int64 : require\n";
        o << "uniform usamplerBuffer uTri;\nuniform int uStride;\nuniform int uPrimBase;\n";
        o << "uniform ivec4 uConstG[" << kNumConsts << "];\nuniform vec4 uConstF[" << kNumConsts
          << "];\nuniform vec4 uBump[" << kMaxTextureStages << "];\nuniform vec2 uLum[" << kMaxTextureStages << "];\n";
        o << "uniform ivec4 uBorderG[" << kMaxTextureStages << "];\nuniform vec4 uBorderF[" << kMaxTextureStages
          << "];\n";
        o << "uniform usampler2D uDstColor;\nuniform usampler2D uDstDepth;\n";
        for (int s = 0; s < kMaxTextureStages; ++s) {
            const StageSpec& st = spec.stages[size_t(s)];
            if (!st.bound) continue;
            o << "uniform " << (fx ? (st.unorm8 ? "usampler" : "isampler") : "sampler") << (st.volume ? "3D" : "2D")
              << " uT" << s << ";\n";
        }
        o << "layout(location = 0) out uvec4 oColor;\nlayout(location = 1) out uint oDepth;\n";
        o << kCommon;
        bool samples = false;
        for (int s = 0; s < kMaxTextureStages; ++s)
            samples = samples || (((spec.program->stagesUsed >> s) & 1) && spec.stages[size_t(s)].bound);
        if (samples) o << kSampling;
        o << "int gBase;\n"
             "double recD(int i) { uvec4 t = texelFetch(uTri, gBase + 6 + (i >> 1)); return packDouble2x32((i & 1) == "
             "0 ? t.xy : t.zw); }\n"
             "int64_t recE(int i) { uvec4 t = texelFetch(uTri, gBase + 1 + (i >> 1)); return int64_t(packUint2x32((i & "
             "1) == 0 ? t.xy : t.zw)); }\n"
             "// The rasteriser's plane value at pixel p (emu/raster.h planeValue).\n"
             "float planeAt(int i, ivec2 p, double ox, double oy) {\n"
             "    precise double row = recD(i) + recD(i + 1) * (0.0lf - ox) + recD(i + 2) * (double(p.y) - oy);\n"
             "    precise float r = float(row) + float(recD(i + 1)) * float(p.x);\n"
             "    return r;\n}\n";
        for (int s = 0; s < kMaxTextureStages; ++s)
            if ((spec.program->stagesUsed >> s) & 1) writeSampler(ctx, s);
        writeMergeFunctions(ctx);
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
        for (int s = 0; s < kMaxTextureStages; ++s)
            if ((spec.program->stagesUsed >> s) & 1 && spec.stages[size_t(s)].bound &&
                !lodFree(spec.stages[size_t(s)]) && !(spec.hardwareFiltering && !fx))
                early = false;
        if (early) o << "    if (!covered) discard;\n";
        o << "    double ox = recD(0), oy = recD(1);\n";
        o << "    float inv = 1.0;\n    if (persp) { float r = planeAt(2, P, ox, oy); r = r < 1e-30 ? 1e-30 : r; inv = "
             "fdiv(1.0, r); }\n";
        // Attributes: v0, v1 (diffuse, specular), TC[0..7].
        o << "    vec4 VC[2] = vec4[2](vec4(0.0), vec4(0.0));\n    vec4 TC[" << kMaxTexCoordSets
          << "];\n    for (int i = 0; i < " << kMaxTexCoordSets << "; ++i) TC[i] = vec4(0.0);\n";
        int idx = 8;
        for (int a = 0; a < kAttrCount; ++a) {
            if (!((spec.usedAttributes >> a) & 1)) continue;
            std::string dst;
            if (a < kAttrSpecular)
                dst = std::string("VC[0].") + kComp[a];
            else if (a < kAttrTex)
                dst = std::string("VC[1].") + kComp[a - kAttrSpecular];
            else
                dst = "TC[" + std::to_string((a - kAttrTex) / 4) + "]." + kComp[(a - kAttrTex) % 4];
            o << "    if (((cmask >> " << a << "u) & uint64_t(1)) != uint64_t(0)) " << dst << " = float(recD(" << idx
              << "));\n"
              << "    else { precise float v = planeAt(" << idx << ", P, ox, oy); if (persp) v = v * inv; " << dst
              << " = v; }\n";
            idx += 3;
        }
        o << "    float zPlane = " << (spec.wantZ ? "planeAt(5, P, ox, oy)" : "0.0") << ";\n";
        o << "    bool killed = false;\n    float depthOut = 0.0;\n";
        o << "    float U = 0.0, V = 0.0, W = 0.0, P0 = 0.0, P1 = 0.0;\n    vec4 C4 = vec4(0.0);\n";
        // Registers: the executor's register file (r0..r5, t0..t5, v0, v1 in its slots).
        if (fx) {
            o << "    ivec4 R[" << kNumSlots << "];\n    for (int i = 0; i < " << kNumSlots
              << "; ++i) R[i] = ivec4(0);\n    ivec4 H = ivec4(0);\n";
            for (int v = 0; v < kNumRegV; ++v)
                if ((spec.program->vUsed >> v) & 1)
                    o << "    for (int c = 0; c < 4; ++c) { float s = VC[" << v
                      << "][c]; s = s > 0.0 ? (s < 1.0 ? s : 1.0) : 0.0;"
                      << " " << regSlot(kSlotV + v) << "[c] = int(roundEven(double(s) * " << num(p.g) << ")); }\n";
        } else {
            o << "    vec4 R[" << kNumSlots << "];\n    for (int i = 0; i < " << kNumSlots
              << "; ++i) R[i] = vec4(0.0);\n    vec4 H = vec4(0.0);\n";
            for (int v = 0; v < kNumRegV; ++v)
                if ((spec.program->vUsed >> v) & 1)
                    o << "    for (int c = 0; c < 4; ++c) { float s = VC[" << v << "][c]; " << regSlot(kSlotV + v)
                      << "[c] = s > 0.0 ? (s < 1.0 ? s : 1.0) : 0.0; }\n";
        }
        ops();
        o << "    if (killed || !covered) discard;\n";
        writeMerge(ctx);
        o << "}\n";
        return o.str();
    }
};


// Native mode: GL's varyings and texture units, float32 only (no doubles, no 64-bit integers),
// then only the parts of the merge GL's fixed-function state cannot do: vertex fog and the
// alpha test (docs/output-merger.md). Blending, the colour mask and the depth test are GL state
// (emu/gl/native_merge.h).
std::string Gen::runNative() {
    const Plan& m = spec.merge;
    o << "#version " << kGlslVersion << " core\n";
    o << "uniform vec4 uConstF[" << kNumConsts << "];\nuniform vec4 uBump[" << kMaxTextureStages
      << "];\nuniform vec2 uLum[" << kMaxTextureStages << "];\n";
    for (int s = 0; s < kMaxTextureStages; ++s) {
        const StageSpec& st = spec.stages[size_t(s)];
        if (!st.bound || !((spec.program->stagesUsed >> s) & 1)) continue;
        o << "uniform sampler" << (st.volume ? "3D" : "2D") << " uT" << s << ";\n";
    }
    o << "in vec4 vDiffuse;\nin vec4 vSpecular;\nin vec4 vTex[" << kMaxTexCoordSets << "];\n";
    o << "layout(location = 0) out vec4 oColor;\n";
    // The division of the coordinates (projected texturing, texdepth, texm3x3spec): GL's own.
    o << "float fdiv(float a, float b) { return a / b; }\n"
         "float satf(float v) { return v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0; }\n"
         "bool cmpPass(uint mask, bool less, bool equal, bool greater) {\n"
         "    uint outcome = less ? 0u : equal ? 1u : greater ? 2u : 3u;\n"
         "    return ((mask >> outcome) & 1u) != 0u;\n}\n";
    for (int s = 0; s < kMaxTextureStages; ++s)
        if ((spec.program->stagesUsed >> s) & 1) writeSampler(ctx, s);
    o << "void main() {\n";
    o << "    vec4 VC[2] = vec4[2](vDiffuse, vSpecular);\n    vec4 TC[" << kMaxTexCoordSets
      << "];\n    for (int i = 0; i < " << kMaxTexCoordSets << "; ++i) TC[i] = vTex[i];\n";
    o << "    bool killed = false;\n    float depthOut = 0.0;\n";
    o << "    float U = 0.0, V = 0.0, W = 0.0, P0 = 0.0, P1 = 0.0;\n    vec4 C4 = vec4(0.0);\n";
    o << "    vec4 R[" << kNumSlots << "];\n    for (int i = 0; i < " << kNumSlots
      << "; ++i) R[i] = vec4(0.0);\n    vec4 H = vec4(0.0);\n";
    // v0, v1: the interpolated colours clamped to [0, 1] (NaN: 0), as the float profiles load them.
    for (int v = 0; v < kNumRegV; ++v)
        if ((spec.program->vUsed >> v) & 1)
            o << "    for (int c = 0; c < 4; ++c) " << regSlot(kSlotV + v) << "[c] = satf(VC[" << v << "][c]);\n";
    ops();
    o << "    if (killed) discard;\n";
    if (spec.shaderDepth) o << "    gl_FragDepth = depthOut;\n";
    // 8-bit targets (and depth-only draws) see the saturated colour; float targets r0 as is.
    const bool unorm = m.color == nullptr || m.target == TargetKind::Argb8 || m.target == TargetKind::Xrgb8;
    o << "    vec4 s = " << regR0() << ";\n";
    if (unorm) o << "    for (int c = 0; c < 4; ++c) s[c] = satf(" << regR0() << "[c]);\n";
    if (m.fog) {
        // Vertex fog: rgb = f·rgb + (1 − f)·FOGCOLOR, f the specular alpha clamped to [0, 1].
        o << "    { float f = satf(VC[1].w);\n      vec3 fogc = vec3(" << flit(float(m.fogByte[0]) / 255.0f) << ", "
          << flit(float(m.fogByte[1]) / 255.0f) << ", " << flit(float(m.fogByte[2]) / 255.0f) << ");\n"
          << "      s.rgb = f * s.rgb + (1.0 - f) * fogc; }\n";
    }
    if (m.alphaTest) {
        // 8-bit targets compare the alpha the target stores (round(sat(a)·255)) with ALPHAREF;
        // float targets the alpha itself with ALPHAREF/255 (docs/output-merger.md "Alpha test").
        if (unorm)
            o << "    { float a = roundEven(s.a * 255.0), r = " << m.alphaRef << ".0;\n";
        else
            o << "    { float a = s.a, r = " << flit(float(m.alphaRef) / 255.0f) << ";\n";
        o << "      if (!cmpPass(" << m.alphaMask << "u, a < r, a == r, a > r)) discard; }\n";
    }
    o << "    oColor = s;\n}\n";
    return o.str();
}

}  // namespace

std::string vertexSource() {
    return "#version " + std::to_string(kGlslVersion) +
           " core\n"
           "layout(location = 0) in vec2 aPos;\n"
           "uniform vec4 uXform;\n"
           "void main() { gl_Position = vec4(aPos * uXform.xy + uXform.zw, 0.0, 1.0); }\n";
}

std::string nativeVertexSource() {
    std::string s = "#version " + std::to_string(kGlslVersion) +
                    " core\n"
                    "layout(location = 0) in vec4 aPos;\n"
                    "layout(location = 1) in vec4 aDiffuse;\n"
                    "layout(location = 2) in vec4 aSpecular;\n";
    for (int i = 0; i < kMaxTexCoordSets; ++i)
        s += "layout(location = " + std::to_string(3 + i) + ") in vec4 aTex" + std::to_string(i) + ";\n";
    s += "uniform vec4 uXform;\n"
         "out vec4 vDiffuse;\nout vec4 vSpecular;\nout vec4 vTex[" + std::to_string(kMaxTexCoordSets) + "];\n"
         "void main() {\n"
         "    float rhw = aPos.w > 1e-30 ? aPos.w : 1e-30;\n"
         "    float w = 1.0 / rhw;\n"
         // D3D9 puts pixel centres on integers, GL at +1/2. A D3D9 driver on GL shifts by 63/128
         // of a pixel, not 1/2, so an edge through a pixel centre falls the way D3D9's top-left
         // rule says (wined3d's position fixup with WINED3D_PIXEL_CENTER_INTEGER: 63/64 in clip
         // units, half a viewport's width per unit); the rasteriser's subpixel grid is 1/256.
         "    vec2 ndc = (aPos.xy + 0.4921875) * uXform.xy + uXform.zw;\n"
         "    gl_Position = vec4(ndc * w, aPos.z * w, w);\n"
         "    vDiffuse = aDiffuse;\n    vSpecular = aSpecular;\n";
    for (int i = 0; i < kMaxTexCoordSets; ++i) s += "    vTex[" + std::to_string(i) + "] = aTex" + std::to_string(i) + ";\n";
    s += "}\n";
    return s;
}

std::string fragmentSource(const FragmentSpec& spec) {
    Gen g(spec);
    return spec.native ? g.runNative() : g.run();
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
