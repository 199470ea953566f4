// ps_1_x → GLSL, the output-merger part (emu/gl/glsl.h): the merge of emu/output_merger.cpp
// written from its plan (emu/merge_plan.h) — fog, alpha test, depth test and write, blending,
// the colour write mask and the target's stored words — on the grid in the fx profiles (8-bit
// targets) and in float32 otherwise.
#include "emu/gl/glsl_internal.h"

namespace emu::gl::detail {

namespace {

std::string factor(const GlslContext& cx, const Factor& f, const std::string& one) {
    const bool fx = cx.fx;
    std::string v;
    switch (f.slot) {
        case kZero:
            v = "ZERO";
            break;
        case kOne:
            v = one;
            break;
        case kSat:
            v = "vsat";
            break;
        default:
            if (f.slot >= kSrc && f.slot < kSrc + 4)
                v = std::string("s[") + char('0' + f.slot - kSrc) + "]";
            else if (f.slot >= kDst && f.slot < kDst + 4)
                v = std::string("d[") + char('0' + f.slot - kDst) + "]";
            else
                v = std::string("bf[") + char('0' + f.slot - kBf) + "]";
    }
    if (v == "ZERO") v = fx ? "0" : "0.0";
    return f.inv ? "(" + one + " - " + v + ")" : v;
}

void depthTest(GlslContext& cx) {
    const FragmentSpec& spec = cx.spec;
    std::ostringstream& o = cx.o;
    const Plan& m = spec.merge;
    if (!m.depthTest) return;
    o << "    { float z = " << (spec.shaderDepth ? "depthOut" : "zPlane")
      << "; z = z > 0.0 ? (z < 1.0 ? z : 1.0) : 0.0;\n"
      << "      uint old = texelFetch(uDstDepth, P, 0).x; bool pass; uint neu = old;\n";
    switch (m.depthKind) {
        case DepthKind::D16:
        case DepthKind::D24:
        case DepthKind::D32: {
            const char* scale = m.depthKind == DepthKind::D16   ? "65535.0lf"
                                : m.depthKind == DepthKind::D24 ? "16777215.0lf"
                                                                : "4294967295.0lf";
            o << "      uint code = uint(roundEven(double(z) * " << scale << "));\n";
            const char* stored = m.depthKind == DepthKind::D16   ? "(old & 0xffffu)"
                                 : m.depthKind == DepthKind::D24 ? "(old >> 8)"
                                                                 : "old";
            o << "      uint st = " << stored << "; pass = cmpPass(" << m.depthMask
              << "u, code < st, code == st, code > st);\n";
            o << "      neu = " << (m.depthKind == DepthKind::D24 ? "(old & 0xffu) | (code << 8)" : "code") << ";\n";
            break;
        }
        case DepthKind::D32F:
            o << "      float st = uintBitsToFloat(old); pass = cmpPass(" << m.depthMask
              << "u, z < st, z == st, z > st);\n"
              << "      neu = floatBitsToUint(z);\n";
            break;
    }
    o << "      if (!pass) discard;\n      oDepth = neu; }\n";
}

void storeUnorm(GlslContext& cx, bool x8) {
    const FragmentSpec& spec = cx.spec;
    std::ostringstream& o = cx.o;
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

}  // namespace

void writeMergeFunctions(GlslContext& cx) {
    const ps11::exec::Profile& p = cx.p;
    const bool fx = cx.fx;
    std::ostringstream& o = cx.o;

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
        o << "uint byteOfGrid(int n) { return " << (g == 255 ? "uint(n)" : "uint(n + 7 + ((n >> 4) & 1)) >> 4")
          << "; }\n";
        o << "uint blendByte(int num) { num = clamp(num, 0, " << g * g << ");\n";
        if (g == 255)
            o << "    return uint(num + 127) / 255u; }\n";
        else
            o << "    uint D = 65280u; uint u = uint(num), q = u / D, r = u - q * D;\n"
                 "    return q + ((2u * r > D || (2u * r == D && (q & 1u) != 0u)) ? 1u : 0u); }\n";
    }
}
// A factor value on the plan's scale (slots of emu/merge_plan.h).

void writeMerge(GlslContext& cx) {
    const FragmentSpec& spec = cx.spec;
    const ps11::exec::Profile& p = cx.p;
    const bool fx = cx.fx;
    std::ostringstream& o = cx.o;

    const Plan& m = spec.merge;
    const int g = p.g;
    const bool hasColor = m.color != nullptr;
    const bool unorm = !hasColor || m.target == TargetKind::Argb8 || m.target == TargetKind::Xrgb8;
    const bool x8 = hasColor && m.target == TargetKind::Xrgb8;
    o << "    oColor = uvec4(0u); oDepth = 0u;\n";
    if (fx && unorm) {
        // mergeFxUnorm8: integers on the grid.
        o << "    int s[4]; for (int c = 0; c < 4; ++c) s[c] = clamp(" << regR0() << "[c], 0, " << g << ");\n";
        if (m.fog) {
            o << "    { int fq = int(roundEven(double(satf(VC[1].w)) * " << num(g) << "));\n";
            for (int c = 0; c < 3; ++c)
                o << "      s[" << c << "] = rc64(int64_t(fq) * int64_t(s[" << c << "]) + int64_t(" << g << " - fq) * "
                  << int(m.fogByte[c]) * (g / 255) << "l, " << g << "l, -2147483647, 2147483647);\n";
            o << "    }\n";
        }
        if (m.alphaTest)
            o << "    { uint a = byteOfGrid(s[3]); if (!cmpPass(" << m.alphaMask << "u, a < " << m.alphaRef
              << "u, a == " << m.alphaRef << "u, a > " << m.alphaRef << "u)) discard; }\n";
        depthTest(cx);
        if (!hasColor) return;
        o << "    uint outb[4];\n";
        if (!m.blend) {
            o << "    for (int c = 0; c < 4; ++c) outb[c] = byteOfGrid(s[c]);\n";
        } else {
            const int S = g / 255;
            o << "    uint old = texelFetch(uDstColor, P, 0).x;\n"
              << "    int d[4] = int[4](int((old >> 16) & 0xffu) * " << S << ", int((old >> 8) & 0xffu) * " << S
              << ", int(old & 0xffu) * " << S << ", "
              << (x8 ? std::to_string(g) : "int(old >> 24) * " + std::to_string(S)) << ");\n"
              << "    int bf[4] = int[4](" << int(m.bfByte[0]) * S << ", " << int(m.bfByte[1]) * S << ", "
              << int(m.bfByte[2]) * S << ", " << int(m.bfByte[3]) * S << ");\n"
              << "    int vsat = min(s[3], " << g << " - d[3]);\n";
            for (int c = 0; c < 4; ++c) {
                const ChannelPlan& cp = m.ch[c];
                if (cp.kind == OpKind::Linear)
                    o << "    outb[" << c << "] = blendByte(" << cp.cs << " * s[" << c << "] * "
                      << factor(cx, cp.src, std::to_string(g)) << " + " << cp.cd << " * d[" << c << "] * "
                      << factor(cx, cp.dst, std::to_string(g)) << ");\n";
                else
                    o << "    outb[" << c << "] = byteOfGrid(" << (cp.kind == OpKind::Min ? "min" : "max") << "(s[" << c
                      << "], d[" << c << "]));\n";
            }
        }
        storeUnorm(cx, x8);
        return;
    }
    // mergeFloat: float32 arithmetic (fx profiles: grid values, exact fog and alpha test).
    o << "    float s[4];\n";
    if (fx) {
        o << "    int gn[4]; for (int c = 0; c < 4; ++c) gn[c] = " << regR0() << "[c];\n";
        if (m.fog) {
            o << "    { int fq = int(roundEven(double(satf(VC[1].w)) * " << num(g) << "));\n";
            for (int c = 0; c < 3; ++c)
                o << "      gn[" << c << "] = rc64(int64_t(fq) * int64_t(gn[" << c << "]) + int64_t(" << g
                  << " - fq) * " << int(m.fogByte[c]) * (g / 255) << "l, " << g << "l, -2147483647, 2147483647);\n";
            o << "    }\n";
        }
        o << "    for (int c = 0; c < 4; ++c) s[c] = fdiv(float(gn[c]), " << g << ".0);\n";
        if (m.alphaTest)
            o << "    { int64_t a = int64_t(gn[3]) * 255l, r = int64_t(" << m.alphaRef << ") * " << g << "l;\n"
              << "      if (!cmpPass(" << m.alphaMask << "u, a < r, a == r, a > r)) discard; }\n";
    } else {
        o << "    for (int c = 0; c < 4; ++c) s[c] = " << (unorm ? "satf(" + regR0() + "[c])" : regR0() + "[c]") << ";\n";
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
    depthTest(cx);
    if (!hasColor) return;
    auto blendFloat = [&](int c, const std::string& sv, const std::string& dv) {
        const ChannelPlan& cp = m.ch[c];
        if (cp.kind != OpKind::Linear)
            return std::string(cp.kind == OpKind::Min ? "(" + sv + " < " + dv + " ? " + sv + " : " + dv + ")"
                                                      : "(" + sv + " > " + dv + " ? " + sv + " : " + dv + ")");
        const bool zs = cp.src.slot == kZero && !cp.src.inv, zd = cp.dst.slot == kZero && !cp.dst.inv;
        const std::string ts = "(" + num(cp.cs) + " * (" + sv + " * " + factor(cx, cp.src, "1.0") + "))";
        const std::string td = "(" + num(cp.cd) + " * (" + dv + " * " + factor(cx, cp.dst, "1.0") + "))";
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
              << "    float d[4] = float[4](fdiv(float((old >> 16) & 0xffu), 255.0), fdiv(float((old >> 8) & 0xffu), "
                 "255.0), "
                 "fdiv(float(old & 0xffu), 255.0), "
              << (x8 ? "1.0" : "fdiv(float(old >> 24), 255.0)") << ");\n"
              << bfDecl << "    float vsat = min(s[3], 1.0 - d[3]);\n";
            for (int c = 0; c < 4; ++c)
                o << "    { precise float v = "
                  << blendFloat(c, "s[" + std::to_string(c) + "]", "d[" + std::to_string(c) + "]") << "; outb[" << c
                  << "] = byteOfUnit(satf(v)); }\n";
        }
        storeUnorm(cx, x8);
        return;
    }
    // Float targets: raw words r g b a (A16B16G16R16F: two words of two halves).
    if (m.blend) {
        o << "    uvec4 oldw = texelFetch(uDstColor, P, 0);\n    float d[4];\n";
        if (m.target == TargetKind::Rgba16F)
            o << "    d[0] = floatOfHalf(oldw.x & 0xffffu); d[1] = floatOfHalf(oldw.x >> 16); d[2] = "
                 "floatOfHalf(oldw.y & 0xffffu);"
                 " d[3] = floatOfHalf(oldw.y >> 16);\n";
        else if (m.target == TargetKind::Rgba32F)
            o << "    for (int c = 0; c < 4; ++c) d[c] = uintBitsToFloat(oldw[c]);\n";
        else
            o << "    d[0] = uintBitsToFloat(oldw.x); d[1] = 1.0; d[2] = 1.0; d[3] = 1.0;\n";
        o << bfDecl << "    float vsat = min(s[3], 1.0 - d[3]);\n    float b[4];\n";
        for (int c = 0; c < 4; ++c)
            o << "    { precise float v = "
              << blendFloat(c, "s[" + std::to_string(c) + "]", "d[" + std::to_string(c) + "]") << "; b[" << c
              << "] = v; }\n";
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

}  // namespace emu::gl::detail
