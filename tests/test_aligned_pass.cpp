// The aligned-pass path of DrawPrimitiveUP (emu/aligned_pass.h) against the quad path: random
// screen-aligned draws (target and texture sizes, texel formats, filters, every address mode,
// border colours, 1:1 / offset / scaled / downsampling coordinates, colour gradients, programs of
// ps_1_1–1_4, blending, alpha test, write masks, scissor) drawn by two devices, one with
// DeviceOptions::alignedPasses off, the aligned one at every SIMD level this CPU runs; the render
// targets must be identical byte for byte, and the aligned device must really have taken the row
// path (no helper lanes shaded).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "emu/aligned_float.h"
#include "emu/aligned_pass.h"
#include "emu/aligned_pass_kernels.h"
#include "emu/device.h"
#include "emu/format.h"
#include "ps11/assembler.h"
#include "ps11/validator.h"
#include "simd_levels.h"

using namespace emu;

namespace {

struct Vtx {
    float x, y, z, rhw;
    DWORD diffuse;
    DWORD specular = 0xff000000u;  // its alpha is the vertex fog factor
    float uv[4][2];
};
constexpr DWORD kFvf = D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_SPECULAR | D3DFVF_TEX4;

const char* const kPrograms[] = {
    "ps_1_1\ntex t0\nmov r0, t0\n",
    "ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\nmad r0, t1, c0, r0\nmad r0, t2, c0, r0\nmad r0, t3, c0, "
    "r0\n",
    "ps_1_1\ntex t0\nsub_sat r0, t0, c1\nmul_x4 r0, r0, c2\nmul r0, r0, v0\n",
    "ps_1_1\ntex t0\ntex t1\nmul r1, t1, c0\nmad r0, 1-t0, r1, t0\nlrp r0, c3, r0, v0\n",
    "ps_1_1\ntex t0\ntex t1\ndp3_sat r0.rgb, t0_bx2, t1_bx2\n+mov r0.a, t0.a\n",
    "ps_1_2\ntex t0\ntex t2\nmov r0, t0\ncnd r1, r0.a, t0, t2\nadd_d2 r0.rgb, r1, v0\n",
    "ps_1_3\ntex t1\ntex t3\nmad_x2 r1, t1, v0, -t3\ncmp r0, r1, r1, c1\n",
    "ps_1_4\ntexld r0, t0\ntexld r1, t2\nmul r0, r0, r1\nphase\ntexld r2, t1\nadd_sat r0.rgb, r0, r2\n+mov r0.a, "
    "r2.a\n",
    "ps_1_4\ntexld r3, t3\nmov_x4 r0, r3\nmad r0, r0, c0, -r3\n",
    "ps_1_1\nmov r0, v0\n",
    "ps_1_1\ntex t0\nmul r0.rgb, t0, v0\n",  // r0.a never written: reads 0
    // 1 − n factors of known non-negative values (the 16-bit product kernel's complement).
    "ps_1_1\ntex t0\ntex t1\nmad r0, t1, 1-t0, t0\n",
    "ps_1_1\ntex t0\ntex t1\nmul r1, 1-t0, 1-t1\nmad r0, 1-r1, t0, -t1\n",
};

const D3DFORMAT kTexFormats[] = {D3DFMT_A8R8G8B8, D3DFMT_X8R8G8B8, D3DFMT_L8, D3DFMT_A8, D3DFMT_A8L8};
// The float row path also reads decoded textures: float, half and signed formats.
const D3DFORMAT kFloatTexFormats[] = {D3DFMT_A8R8G8B8,      D3DFMT_L8,   D3DFMT_A32B32G32R32F,
                                      D3DFMT_A16B16G16R16F, D3DFMT_R32F, D3DFMT_V8U8};

uint32_t texelBytes(D3DFORMAT f) {
    switch (f) {
        case D3DFMT_A32B32G32R32F:
            return 16;
        case D3DFMT_A16B16G16R16F:
            return 8;
        case D3DFMT_V8U8:
            return 2;
        case D3DFMT_L8:
        case D3DFMT_A8:
            return 1;
        case D3DFMT_A8L8:
            return 2;
        default:
            return 4;
    }
}

// Everything one random case sets, applied identically to both devices.
struct Case {
    UINT w = 1, h = 1;
    D3DFORMAT rtFormat = D3DFMT_A8R8G8B8;
    std::vector<uint8_t> rtInit;
    struct Tex {
        UINT w = 1, h = 1;
        D3DFORMAT format = D3DFMT_A8R8G8B8;
        std::vector<uint8_t> bytes;
        DWORD filter = D3DTEXF_POINT, addressU = D3DTADDRESS_CLAMP, addressV = D3DTADDRESS_CLAMP, border = 0;
        bool bound = true;
        // Levels 1.. of a mip chain (each max(1, size >> level)), the min filter where it is not
        // `filter` (0: the same) and the MIP filter.
        std::vector<std::vector<uint8_t>> mips;
        DWORD minFilter = 0, mipFilter = D3DTEXF_NONE;
    };
    std::vector<Tex> tex;  // 4 stages
    // Every stage reads stage 0's texture (each with its own sampler states and coordinates):
    // a blur's taps, whose row paths share texel rows between taps.
    bool oneTexture = false;
    std::string program;
    float consts[4][4] = {};
    std::vector<Vtx> verts;
    DWORD blend = 0;  // 0 off, 1 ONE/ONE, 2 SRCALPHA/INVSRCALPHA, 3 BLENDFACTOR/ONE
    DWORD blendFactor = 0;
    bool alphaTest = false;
    DWORD alphaRef = 0;
    DWORD writeMask = 0xf;
    bool scissor = false;
    RECT scissorRect{};
    // Vertex fog toward fogColor by each vertex's specular alpha (the triangles' own planes).
    bool fog = false;
    DWORD fogColor = 0;
    // A D24X8 depth buffer cleared to zClear, tested with zFunc and written where zWrite; the
    // vertices' z differ per triangle (a quad's halves are not one plane), and `depthVerts`,
    // drawn after with the same states, tests what the first draw wrote.
    bool depth = false;
    DWORD zFunc = D3DCMP_LESSEQUAL;
    bool zWrite = true;
    float zClear = 1.0f;
    std::vector<Vtx> depthVerts;
};

// Depth and fog on a quarter of the cases each, from their own generator seeded by `rng`.
void depthAndFog(std::mt19937& rng, Case& c) {
    std::mt19937 more(rng());
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(more); };
    c.fog = uni(0, 3) == 0;
    c.fogColor = DWORD(more());
    for (Vtx& v : c.verts) v.specular = DWORD(more());
    c.depth = uni(0, 3) == 0;
    if (!c.depth) return;
    const DWORD funcs[6] = {D3DCMP_LESS,  D3DCMP_LESSEQUAL, D3DCMP_GREATER,
                            D3DCMP_EQUAL, D3DCMP_NOTEQUAL,  D3DCMP_ALWAYS};
    c.zFunc = funcs[uni(0, 5)];
    c.zWrite = uni(0, 3) != 0;
    c.zClear = float(uni(0, 4)) * 0.25f;
    c.depthVerts = c.verts;
    for (Vtx& v : c.depthVerts) v.z = float(uni(0, 1000)) / 1000.0f, v.diffuse = DWORD(more());
}

// Every NaN of float or half texels replaced by the infinity of its sign.
void withoutNaNs(std::vector<uint8_t>& bytes, D3DFORMAT f) {
    if (f == D3DFMT_A32B32G32R32F || f == D3DFMT_R32F) {
        for (size_t i = 0; i + 4 <= bytes.size(); i += 4) {
            uint32_t v;
            std::memcpy(&v, &bytes[i], 4);
            if ((v & 0x7f800000u) == 0x7f800000u && (v & 0x007fffffu)) v &= 0xff800000u;
            std::memcpy(&bytes[i], &v, 4);
        }
    } else if (f == D3DFMT_A16B16G16R16F) {
        for (size_t i = 0; i + 2 <= bytes.size(); i += 2) {
            uint16_t v;
            std::memcpy(&v, &bytes[i], 2);
            if ((v & 0x7c00u) == 0x7c00u && (v & 0x03ffu)) v = uint16_t(v & 0xfc00u);
            std::memcpy(&bytes[i], &v, 2);
        }
    }
}

Case randomCase(std::mt19937& rng, bool floatFormats = false) {
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    Case c;
    c.w = UINT(uni(1, 300));
    c.h = UINT(uni(1, 24));
    c.rtFormat = uni(0, 3) ? D3DFMT_A8R8G8B8 : D3DFMT_X8R8G8B8;
    c.rtInit.resize(size_t(c.w) * c.h * 4);
    for (uint8_t& b : c.rtInit) b = uint8_t(rng());
    c.tex.resize(4);
    for (Case::Tex& t : c.tex) {
        t.w = UINT(uni(0, 2) ? uni(1, 320) : c.w);
        t.h = UINT(uni(0, 2) ? uni(1, 40) : c.h);
        t.format = floatFormats ? kFloatTexFormats[uni(0, 5)] : kTexFormats[uni(0, 4)];
        t.bytes.resize(size_t(t.w) * t.h * texelBytes(t.format));
        for (uint8_t& b : t.bytes) b = uint8_t(uni(0, 3) ? rng() : (uni(0, 1) ? 0 : 255));
        t.filter = uni(0, 2) ? D3DTEXF_LINEAR : D3DTEXF_POINT;
        t.addressU = DWORD(uni(1, 5));
        t.addressV = DWORD(uni(1, 5));
        t.border = DWORD(rng());
        t.bound = uni(0, 9) != 0;
    }
    c.program = kPrograms[uni(0, int(std::size(kPrograms)) - 1)];
    for (auto& k : c.consts)
        for (float& v : k) v = uni(0, 3) ? real(-1.2f, 1.2f) : float(uni(0, 4)) * 0.25f;
    // A rectangle in pixels (corners anywhere, often on the half-pixel grid) and per set a
    // texture-coordinate rectangle: 1:1 with a texel offset, a 2:1 reduction, or anything.
    auto corner = [&](int n) { return uni(0, 1) ? float(uni(-3, n + 3)) - 0.5f : real(-3.0f, float(n) + 3.0f); };
    float x0 = corner(int(c.w)), x1 = corner(int(c.w)), y0 = corner(int(c.h)), y1 = corner(int(c.h));
    // Half the cases are post-processing passes: the whole target through the half-pixel corners,
    // textures of the target's size (1:1) or 2, 3 or 4 times it (integer-ratio reductions).
    const bool post = uni(0, 1);
    if (post) {
        x0 = -0.5f, x1 = float(c.w) - 0.5f, y0 = -0.5f, y1 = float(c.h) - 0.5f;
        const UINT scales[5] = {1, 1, 2, 3, 4};  // 1:1 and integer-ratio reductions
        const UINT scale = scales[uni(0, 4)];
        for (Case::Tex& t : c.tex) {
            t.w = c.w * scale, t.h = c.h * scale;
            t.bytes.resize(size_t(t.w) * t.h * texelBytes(t.format));
            for (uint8_t& b : t.bytes) b = uint8_t(uni(0, 3) ? rng() : (uni(0, 1) ? 0 : 255));
        }
    }
    // One texture on every stage, or (as often) textures that differ only in their texels: the
    // row paths must share rows between the taps of the first and never of the second.
    c.oneTexture = uni(0, 3) == 0;
    const bool sameShape = !c.oneTexture && uni(0, 2) == 0;
    if (c.oneTexture || sameShape)
        for (size_t s = 1; s < 4; ++s) {
            const Case::Tex own = c.tex[s];
            c.tex[s] = c.tex[0];
            if (uni(0, 2) == 0) c.tex[s].filter = own.filter, c.tex[s].addressV = own.addressV;
            if (sameShape)
                for (uint8_t& b : c.tex[s].bytes) b = uint8_t(rng());
        }
    float u[4][2], v[4][2];
    for (int s = 0; s < 4; ++s) {
        const Case::Tex& t = c.tex[size_t(s)];
        const int kind = post ? 0 : uni(0, 3);
        if (kind == 0) {
            // Offsets in eighths of a texel: fixed 8-bit weights 0, 32, ..., 224 along whole rows.
            const float ox = float(uni(-16, 16)) * 0.125f / float(t.w), oy = float(uni(-16, 16)) * 0.125f / float(t.h);
            u[s][0] = ox, u[s][1] = 1 + ox, v[s][0] = oy, v[s][1] = 1 + oy;
        } else if (kind == 1) {
            u[s][0] = 0, u[s][1] = 2, v[s][0] = 0, v[s][1] = 2;
        } else {
            u[s][0] = real(-1.5f, 1.5f), u[s][1] = real(-1.5f, 2.5f), v[s][0] = real(-1.5f, 1.5f),
            v[s][1] = real(-1.5f, 2.5f);
        }
        // Mostly stage 0's columns with other rows (a vertical blur).
        if ((c.oneTexture || sameShape) && s > 0 && uni(0, 3) != 0) u[s][0] = u[0][0], u[s][1] = u[0][1];
    }
    // Or pairs of taps on the same rows, columns a whole or part of a texel apart (the half-texel
    // blur's taps at (±½, ±½)): one tap's vertical blends serve the other's (VerticalMemo).
    if (c.oneTexture && uni(0, 2) == 0)
        for (int s = 1; s < 4; s += 2) {
            const float d = float(std::array<int, 6>{8, -8, 16, 4, 1, 0}[size_t(uni(0, 5))]) * 0.125f / float(c.tex[0].w);
            v[s][0] = v[s - 1][0], v[s][1] = v[s - 1][1];
            u[s][0] = u[s - 1][0] + d, u[s][1] = u[s - 1][1] + d;
        }
    DWORD dif[4];
    const bool gradient = uni(0, 1);
    for (DWORD& d : dif) d = gradient ? DWORD(rng()) : 0;
    if (!gradient) {
        const DWORD one = DWORD(rng());
        for (DWORD& d : dif) d = one;
    }
    const float xs[4] = {x0, x1, x1, x0}, ys[4] = {y0, y0, y1, y1};
    const int order[2][6] = {{0, 1, 2, 0, 2, 3}, {1, 2, 3, 1, 3, 0}};
    const int split = uni(0, 1);
    for (int k : order[split]) {
        Vtx q{xs[k], ys[k], real(0, 1), 1.0f, dif[k], 0xff000000u, {}};
        for (int s = 0; s < 4; ++s) {
            q.uv[s][0] = (k == 1 || k == 2) ? u[s][1] : u[s][0];
            q.uv[s][1] = (k >= 2) ? v[s][1] : v[s][0];
        }
        c.verts.push_back(q);
    }
    c.blend = DWORD(uni(0, 4) < 3 ? 0 : uni(1, 2));
    c.alphaTest = uni(0, 5) == 0;
    c.alphaRef = DWORD(uni(0, 255));
    c.writeMask = uni(0, 5) == 0 ? DWORD(uni(0, 15)) : 0xf;
    c.scissor = uni(0, 5) == 0;
    c.scissorRect = RECT{uni(0, int(c.w)), uni(0, int(c.h)), uni(0, int(c.w)), uni(0, int(c.h))};
    depthAndFog(rng, c);
    return c;
}

// The half-pixel quad over the whole target, every set's coordinates 0..1 (a 1:1 pass when the
// textures have the target's size).
void fullTargetQuad(Case& c) {
    c.verts.clear();
    const float xs[4] = {-0.5f, float(c.w) - 0.5f, float(c.w) - 0.5f, -0.5f};
    const float ys[4] = {-0.5f, -0.5f, float(c.h) - 0.5f, float(c.h) - 0.5f};
    for (int k : {0, 1, 2, 0, 2, 3}) {
        Vtx q{xs[k], ys[k], 0.5f, 1.0f, 0xffffffffu, 0xff000000u, {}};
        for (int s = 0; s < 4; ++s) q.uv[s][0] = (k == 1 || k == 2) ? 1.0f : 0.0f, q.uv[s][1] = k >= 2 ? 1.0f : 0.0f;
        c.verts.push_back(q);
    }
}

std::vector<uint8_t> drawCase(Device& dev, const Case& c, DrawStats& stats) {
    Handle rt{};
    REQUIRE(dev.CreateRenderTarget(c.w, c.h, c.rtFormat, 1, &rt) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    D3DLOCKED_RECT lr;
    const size_t rtRow = size_t(c.w) * texelBytes(c.rtFormat);
    REQUIRE(c.rtInit.size() == rtRow * c.h);
    REQUIRE(dev.LockRect(rt, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < c.h; ++y)
        std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &c.rtInit[y * rtRow], rtRow);
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);
    Handle first{};
    for (DWORD s = 0; s < 4; ++s) {
        const Case::Tex& t = c.tex[s];
        Handle tex{};
        REQUIRE(dev.CreateTexture(t.w, t.h, UINT(1 + t.mips.size()), 0, t.format, D3DPOOL_MANAGED, &tex) == D3D_OK);
        for (UINT level = 0; level <= t.mips.size(); ++level) {
            const UINT lw = std::max(1u, t.w >> level), lh = std::max(1u, t.h >> level);
            const std::vector<uint8_t>& bytes = level == 0 ? t.bytes : t.mips[level - 1];
            REQUIRE(dev.LockRect(tex, level, &lr, nullptr, 0) == D3D_OK);
            const size_t row = size_t(lw) * texelBytes(t.format);
            REQUIRE(bytes.size() == row * lh);
            for (UINT y = 0; y < lh; ++y)
                std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &bytes[y * row], row);
            REQUIRE(dev.UnlockRect(tex, level) == D3D_OK);
        }
        if (s == 0) first = tex;
        REQUIRE(dev.SetTexture(s, !t.bound ? Handle::Null : c.oneTexture ? first : tex) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_MINFILTER, t.minFilter ? t.minFilter : t.filter) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_MIPFILTER, t.mipFilter) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_MAGFILTER, t.filter) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_ADDRESSU, t.addressU) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_ADDRESSV, t.addressV) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_BORDERCOLOR, t.border) == D3D_OK);
    }
    Handle ps{};
    REQUIRE(dev.CreatePixelShaderFromText(c.program.c_str(), &ps) == D3D_OK);
    REQUIRE(dev.SetPixelShader(ps) == D3D_OK);
    REQUIRE(dev.SetPixelShaderConstantF(0, &c.consts[0][0], 4) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_CULLMODE, D3DCULL_NONE) == D3D_OK);
    // Every state the cases vary is set, on or off: a device may have drawn another case before.
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, c.blend ? 1 : 0) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ALPHATESTENABLE, c.alphaTest ? 1 : 0) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_SCISSORTESTENABLE, c.scissor ? 1 : 0) == D3D_OK);
    if (c.blend) {
        REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
        const DWORD src = c.blend == 1 ? D3DBLEND_ONE : c.blend == 3 ? D3DBLEND_BLENDFACTOR : D3DBLEND_SRCALPHA;
        const DWORD dst = c.blend == 2 ? D3DBLEND_INVSRCALPHA : D3DBLEND_ONE;
        REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, src) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, dst) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_BLENDFACTOR, c.blendFactor) == D3D_OK);
    }
    if (c.alphaTest) {
        REQUIRE(dev.SetRenderState(D3DRS_ALPHATESTENABLE, 1) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ALPHAFUNC, D3DCMP_GREATEREQUAL) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ALPHAREF, c.alphaRef) == D3D_OK);
    }
    REQUIRE(dev.SetRenderState(D3DRS_COLORWRITEENABLE, c.writeMask) == D3D_OK);
    if (c.scissor) {
        REQUIRE(dev.SetScissorRect(&c.scissorRect) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_SCISSORTESTENABLE, 1) == D3D_OK);
    }
    REQUIRE(dev.SetRenderState(D3DRS_FOGENABLE, c.fog ? 1 : 0) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_FOGCOLOR, c.fogColor) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_ZENABLE, c.depth ? 1 : 0) == D3D_OK);
    Handle ds{};
    if (c.depth) {
        REQUIRE(dev.CreateDepthStencilSurface(c.w, c.h, D3DFMT_D24X8, &ds) == D3D_OK);
        REQUIRE(dev.SetDepthStencilSurface(ds) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, c.zClear, 0) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ZFUNC, c.zFunc) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ZWRITEENABLE, c.zWrite ? 1 : 0) == D3D_OK);
    }
    REQUIRE(dev.SetFVF(kFvf) == D3D_OK);
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(c.verts.size() / 3), c.verts.data(), sizeof(Vtx)) == D3D_OK);
    stats = dev.lastDrawStats();
    if (c.depth) {
        // The second draw's pixels pass or fail against what the first wrote.
        REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(c.depthVerts.size() / 3), c.depthVerts.data(),
                                    sizeof(Vtx)) == D3D_OK);
        const DrawStats& second = dev.lastDrawStats();
        stats.pixelsCovered += second.pixelsCovered;
        stats.pixelsWritten += second.pixelsWritten;
        stats.pixelsShaded += second.pixelsShaded;
        stats.pixelsRowPath += second.pixelsRowPath;
        REQUIRE(dev.SetDepthStencilSurface(Handle::Null) == D3D_OK);
    }
    std::vector<uint8_t> out(rtRow * c.h);
    REQUIRE(dev.LockRect(rt, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    for (UINT y = 0; y < c.h; ++y) std::memcpy(&out[y * rtRow], static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, rtRow);
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);
    return out;
}

// Case c drawn by a device with `rowOpt` must give the quad path's bytes (`expected`) and counts
// (`qs`); a case covering pixels counts in `cases`, and in `rows` where no helper lane was shaded.
void requireRowsEqual(const DeviceOptions& rowOpt, const Case& c, const std::vector<uint8_t>& expected,
                      const DrawStats& qs, int& cases, int& rows) {
    Device rowDev(rowOpt);
    DrawStats rs;
    REQUIRE(drawCase(rowDev, c, rs) == expected);
    CHECK(rs.pixelsCovered == qs.pixelsCovered);
    CHECK(rs.pixelsWritten == qs.pixelsWritten);
    if (qs.pixelsCovered == 0) return;
    ++cases;
    if (rs.pixelsShaded == rs.pixelsCovered) ++rows;
}

// The float row path's profiles for case i: float or ideal (overriding the class's profile:
// float weights), and every eighth case the D3D9 class in its own float profile, whose filter
// weights are 8-bit (the row path's weights8).
void floatProfile(int i, bool ideal, DeviceOptions& a, DeviceOptions& b) {
    a.precision = b.precision = ideal ? ps11::Precision::Ideal : ps11::Precision::Float;
    if (i % 8 == 1) {
        a.hardware = b.hardware = ps11::findHardware("d3d9");
        a.precision = b.precision = std::nullopt;
    }
}

std::string profileName(const DeviceOptions& o) {
    if (o.precision) return ps11::precisionName(*o.precision);
    return o.hardware ? "the " + std::string(o.hardware->name) + " class's own profile" : "the default class's";
}

// Tile skipping (emu/tile_skip.h) changes no byte and no covered pixel: the case drawn by a device
// like `rowOpt` with skipping on must give the quad path's bytes.
void requireSkippingEqual(const DeviceOptions& rowOpt, const Case& c, const std::vector<uint8_t>& expected,
                          const DrawStats& qs) {
    DeviceOptions skipOpt = rowOpt;
    skipOpt.software.skipTiles = true;
    Device skipDev(skipOpt);
    DrawStats ks;
    REQUIRE(drawCase(skipDev, c, ks) == expected);
    CHECK(ks.pixelsCovered == qs.pixelsCovered);
}

// Both devices as the radeon8500 class: fx12 with MaxValue 8 (ps11/hardware.h).
void radeon8500(DeviceOptions& a, DeviceOptions& b) {
    a.hardware = b.hardware = ps11::findHardware("radeon8500");
    REQUIRE(a.hardware);
    a.precision = b.precision = std::nullopt;
}

}  // namespace

TEST_CASE("aligned pass: random screen-aligned draws equal the quad path byte for byte", "[draw][aligned]") {
    std::mt19937 rng(20261125);
    int aligned = 0, cases = 0;
    for (int i = 0; i < 400; ++i) {
        const Case c = randomCase(rng);
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        rowOpt.software.skipTiles = false;  // every pixel shaded: the statistics below hold
        // ps_1_4 programs run on the 1.4-class card, in fx8; every third case on that card in its
        // own fx12 (MaxValue 8: the generic executor's pre-sampled runs).
        if (c.program.rfind("ps_1_4", 0) == 0) {
            quadOpt.hardware = rowOpt.hardware = &ps11::defaultHardware(4);
            quadOpt.precision = rowOpt.precision = ps11::Precision::Fx8;
        }
        if (i % 3 == 2) radeon8500(quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", program:\n" << c.program);
        testutil::forEachSimdLevel([&](ps11::SimdLevel) {
            Device rowDev(rowOpt);
            DrawStats rs;
            REQUIRE(drawCase(rowDev, c, rs) == expected);
            requireSkippingEqual(rowOpt, c, expected, qs);
            CHECK(rs.pixelsCovered == qs.pixelsCovered);
            CHECK(rs.pixelsWritten == qs.pixelsWritten);
            if (qs.pixelsCovered == 0) return;
            ++cases;
            // The row path shades exactly the covered pixels; the quad path adds helper lanes.
            if (rs.pixelsShaded == rs.pixelsCovered) ++aligned;
            CHECK(rs.instructions * qs.pixelsShaded == qs.instructions * rs.pixelsShaded);
        });
    }
    // Every case qualifies (fx8 or fx12, plain texture reads, screen-aligned): all must take the
    // row path, save those whose quads happened to be all covered.
    INFO(aligned << " of " << cases << " cases took the row path");
    CHECK(aligned * 10 >= cases * 9);
}

TEST_CASE("aligned pass: mip chains and MIN != MAG filters take the row path where every quad picks one level",
          "[draw][aligned]") {
    // The random cases (1:1 passes, 2:1 … 4:1 reductions, magnifications, any rectangle) with mip
    // chains of any length, each MIP filter and a min filter that differs from the mag filter
    // half the time, in fx8, fx12, float and ideal: the level and filter each quad picks must be
    // the quad path's.
    std::mt19937 rng(20261130);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    int cases = 0, rows = 0, mipRows = 0;
    std::array<int, 4> profileRows{};
    for (int i = 0; i < 400; ++i) {
        const int profile = i % 4;  // fx8, fx12 (the radeon8500 class), float, ideal
        Case c = randomCase(rng, profile >= 2);
        bool chains = false;
        for (Case::Tex& t : c.tex) {
            int chain = 1;
            while ((t.w >> chain) > 0 || (t.h >> chain) > 0) ++chain;
            const int levels = uni(1, chain);
            chains |= levels > 1;
            for (int level = 1; level < levels; ++level) {
                std::vector<uint8_t>& bytes = t.mips.emplace_back(size_t(std::max(1u, t.w >> level)) *
                                                                  std::max(1u, t.h >> level) * texelBytes(t.format));
                for (uint8_t& b : bytes) b = uint8_t(rng());
            }
            const DWORD mipFilters[3] = {D3DTEXF_NONE, D3DTEXF_POINT, D3DTEXF_LINEAR};
            t.mipFilter = mipFilters[uni(0, 2)];
            if (uni(0, 1)) t.minFilter = t.filter == D3DTEXF_LINEAR ? D3DTEXF_POINT : D3DTEXF_LINEAR;
        }
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        if (c.program.rfind("ps_1_4", 0) == 0) {
            quadOpt.hardware = rowOpt.hardware = &ps11::defaultHardware(4);
            quadOpt.precision = rowOpt.precision = ps11::Precision::Fx8;
        }
        if (profile == 1) radeon8500(quadOpt, rowOpt);
        if (profile >= 2) floatProfile(i, profile == 3, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", program:\n" << c.program);
        const int before = rows;
        requireRowsEqual(rowOpt, c, expected, qs, cases, rows);
        if (chains && rows > before) ++mipRows;
        profileRows[size_t(profile)] += rows - before;
    }
    // Where a quad's level and filter cannot differ from its neighbours' (reductions by 2 and 4
    // pick one level; magnifications level 0), the row path draws; the rest go to quads.
    INFO(rows << " of " << cases << " cases took the row path, " << mipRows << " with a mip chain; fx8 "
              << profileRows[0] << ", fx12 " << profileRows[1] << ", float " << profileRows[2] << ", ideal "
              << profileRows[3]);
    CHECK(rows * 3 >= cases);
    CHECK(mipRows * 5 >= cases);
    for (int n : profileRows) CHECK(n * 20 >= cases);
}

TEST_CASE("aligned pass: triangles of one draw whose quads pick different levels equal the quad path",
          "[draw][aligned]") {
    // Three rectangles side by side over one mip-mapped texture: 2:1, 4:1 and 1:1 across, 2:1
    // down (levels 1, 2 and 1). The row path draws the triangles that pick the level of the
    // first; the others must still get their own level.
    Case c;
    c.w = 96, c.h = 16;
    c.rtInit.assign(size_t(c.w) * c.h * 4, 0x40);
    c.tex.resize(4);
    std::mt19937 rng(7);
    for (Case::Tex& t : c.tex) {
        t.w = 128, t.h = 32;
        t.bytes.resize(size_t(t.w) * t.h * 4);
        for (uint8_t& b : t.bytes) b = uint8_t(rng());
        for (int level = 1; level < 8; ++level) {
            std::vector<uint8_t>& bytes =
                t.mips.emplace_back(size_t(std::max(1u, t.w >> level)) * std::max(1u, t.h >> level) * 4);
            for (uint8_t& b : bytes) b = uint8_t(rng());
        }
        t.filter = D3DTEXF_LINEAR;
        t.mipFilter = D3DTEXF_POINT;
        t.addressU = t.addressV = D3DTADDRESS_WRAP;
    }
    c.program = kPrograms[0];
    const float spans[3][2] = {{0.0f, 0.5f}, {0.5f, 1.5f}, {1.5f, 1.75f}};
    for (int r = 0; r < 3; ++r) {
        const float x0 = float(32 * r) - 0.5f, x1 = x0 + 32.0f;
        const float xs[4] = {x0, x1, x1, x0}, ys[4] = {-0.5f, -0.5f, 15.5f, 15.5f};
        for (int k : {0, 1, 2, 0, 2, 3}) {
            Vtx q{xs[k], ys[k], 0.5f, 1.0f, 0xffffffffu, 0xff000000u, {}};
            q.uv[0][0] = (k == 1 || k == 2) ? spans[r][1] : spans[r][0];
            q.uv[0][1] = k >= 2 ? 1.0f : 0.0f;
            c.verts.push_back(q);
        }
    }
    DeviceOptions quadOpt, rowOpt;
    quadOpt.software.alignedPasses = false;
    Device quadDev(quadOpt);
    DrawStats qs;
    const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
    Device rowDev(rowOpt);
    DrawStats rs;
    REQUIRE(drawCase(rowDev, c, rs) == expected);
    // The first and third rectangles (level 1) on the row path, the second in quads.
    CHECK(rs.pixelsRowPath == 2 * 32 * 16);
}

TEST_CASE("aligned pass: fogged and depth-tested passes take the row paths and equal the quad path",
          "[draw][aligned]") {
    // Full-target quads (whose halves share every tap's planes, so their runs of a row join) and
    // random ones, each vertex with its own fog factor (specular alpha) and z, so the two halves'
    // fog and z planes differ: a run must take each pixel's own triangle's. fx8, fx12, float and
    // ideal; a second draw tests what the first wrote to the depth buffer.
    std::mt19937 rng(20261130);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    int rowPath = 0, cases = 0, fogged = 0, depthTested = 0;
    for (int i = 0; i < 160; ++i) {
        const int profile = i % 4;  // fx8, fx12 (the radeon8500 class), float, ideal
        Case c = randomCase(rng, profile >= 2);
        if (uni(0, 2)) {
            fullTargetQuad(c);
            for (Case::Tex& t : c.tex) {
                t.w = c.w, t.h = c.h;
                t.bytes.resize(size_t(t.w) * t.h * texelBytes(t.format));
                for (uint8_t& b : t.bytes) b = uint8_t(rng());
            }
        }
        c.fog = uni(0, 3) != 0;
        c.depth = !c.fog || uni(0, 1);
        c.fogColor = DWORD(rng());
        for (Vtx& v : c.verts) v.specular = DWORD(rng()), v.z = c.depth ? float(uni(0, 1000)) / 1000.0f : v.z;
        c.zFunc =
            std::array<DWORD, 4>{D3DCMP_LESS, D3DCMP_LESSEQUAL, D3DCMP_GREATER, D3DCMP_NOTEQUAL}[size_t(uni(0, 3))];
        c.zWrite = uni(0, 3) != 0;
        c.zClear = float(uni(1, 3)) * 0.25f;
        c.depthVerts = c.verts;
        for (Vtx& v : c.depthVerts) v.z = float(uni(0, 1000)) / 1000.0f;
        c.program = "ps_1_1\ntex t0\ntex t1\nmad r0, t1, c0, t0\n";
        c.alphaTest = false;
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        rowOpt.software.skipTiles = uni(0, 1) == 0;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        if (profile == 1) radeon8500(quadOpt, rowOpt);
        if (profile >= 2) floatProfile(i, profile == 3, quadOpt, rowOpt);
        Device quadDev(quadOpt), rowDev(rowOpt);
        DrawStats qs, rs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", fog " << c.fog
                     << ", depth " << c.depth);
        REQUIRE(drawCase(rowDev, c, rs) == expected);
        CHECK(rs.pixelsCovered == qs.pixelsCovered);
        CHECK(rs.pixelsWritten == qs.pixelsWritten);
        if (rs.pixelsCovered == 0) continue;
        ++cases;
        if (rs.pixelsRowPath == rs.pixelsCovered) ++rowPath;
        fogged += c.fog, depthTested += c.depth;
    }
    INFO(rowPath << " of " << cases << " drawn by a row path; " << fogged << " fogged, " << depthTested
                 << " depth-tested");
    CHECK(rowPath * 10 >= cases * 9);
    CHECK(fogged > 80);
    CHECK(depthTested > 60);
}

TEST_CASE("float row path: random screen-aligned draws in float and ideal equal the quad path byte for byte",
          "[draw][aligned]") {
    std::mt19937 rng(20261127);
    int rowPath = 0, cases = 0;
    for (int i = 0; i < 300; ++i) {
        // Float, half and signed textures with random bits (NaN and infinities included).
        Case c = randomCase(rng, true);
        // Every third case into a float target (ideal's and float's intermediate textures),
        // blended with constant factors or per pixel.
        // A float target shows a NaN's sign and payload, and which of two NaN operands a sum or
        // product passes on depends on the order the compiler gave them (it commutes them freely,
        // differently in the two paths' code): those cases read and blend over no NaN. Infinities
        // stay, and the NaNs they make (∞ − ∞, 0 · ∞) are the one default NaN whatever the order.
        if (i % 3 == 2) {
            std::mt19937 extra{uint32_t(i)};
            c.rtFormat = i % 2 ? D3DFMT_A32B32G32R32F : D3DFMT_A16B16G16R16F;
            c.rtInit.resize(size_t(c.w) * c.h * texelBytes(c.rtFormat));
            for (uint8_t& b : c.rtInit) b = uint8_t(extra());
            c.blend = DWORD(extra() % 4);
            c.blendFactor = DWORD(extra());
            withoutNaNs(c.rtInit, c.rtFormat);
            for (Case::Tex& t : c.tex) withoutNaNs(t.bytes, t.format);
        }
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        if (c.program.rfind("ps_1_4", 0) == 0) quadOpt.hardware = rowOpt.hardware = &ps11::defaultHardware(4);
        floatProfile(i, (i / 2) % 2 != 0, quadOpt, rowOpt);
        rowOpt.software.skipTiles = false;  // every pixel shaded: the statistics below hold
        Device quadDev(quadOpt), rowDev(rowOpt);
        DrawStats qs, rs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", program:\n" << c.program);
        // Every SIMD level the CPU runs (the float row kernels, emu/aligned_float_kernels.h).
        testutil::forEachSimdLevel([&](ps11::SimdLevel) {
            Device levelDev(rowOpt);
            DrawStats ls;
            CHECK(drawCase(levelDev, c, ls) == expected);
        });
        const std::vector<uint8_t> got = drawCase(rowDev, c, rs);
        size_t firstDiff = 0;
        while (firstDiff < got.size() && got[firstDiff] == expected[firstDiff]) ++firstDiff;
        INFO("first difference at byte " << firstDiff << " (pixel " << firstDiff / 4 % c.w << ", "
                                         << firstDiff / 4 / c.w << "), tex0 format " << c.tex[0].format << " filter "
                                         << c.tex[0].filter << " got "
                                         << (firstDiff < got.size() ? int(got[firstDiff]) : -1) << " want "
                                         << (firstDiff < got.size() ? int(expected[firstDiff]) : -1) << " tex "
                                         << c.tex[0].w << "x" << c.tex[0].h << " addr " << c.tex[0].addressU << ","
                                         << c.tex[0].addressV << " bound " << c.tex[0].bound << " blend " << c.blend
                                         << " mask " << c.writeMask << " alphatest " << c.alphaTest << " scissor "
                                         << c.scissor);
        REQUIRE(firstDiff == got.size());
        requireSkippingEqual(rowOpt, c, expected, qs);
        CHECK(rs.pixelsCovered == qs.pixelsCovered);
        CHECK(rs.pixelsWritten == qs.pixelsWritten);
        if (qs.pixelsCovered == 0) continue;
        ++cases;
        if (rs.pixelsShaded == rs.pixelsCovered) ++rowPath;
    }
    INFO(rowPath << " of " << cases << " cases took the row path");
    CHECK(rowPath * 10 >= cases * 9);
}

// The case's quad with any mapping: each vertex's position moved by up to two pixels (any
// quadrilateral), its coordinates anywhere (rotated, sheared, mirrored), and in half the cases
// an rhw of its own (perspective). The fx8 row path samples such taps per pixel.
void anyMapping(Case& c, std::mt19937& rng) {
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    const bool perspective = rng() & 1;
    // The six vertices are two triangles over four corners: each corner (by its old position)
    // gets one new vertex, so the two triangles still share their edge.
    std::vector<std::pair<std::array<float, 2>, Vtx>> corners;
    for (Vtx& v : c.verts) {
        const std::array<float, 2> at{v.x, v.y};
        auto it = std::find_if(corners.begin(), corners.end(), [&](const auto& k) { return k.first == at; });
        if (it == corners.end()) {
            Vtx n = v;
            n.x += real(-2.0f, 2.0f), n.y += real(-2.0f, 2.0f);
            for (auto& uv : n.uv) uv[0] = real(-1.5f, 2.5f), uv[1] = real(-1.5f, 2.5f);
            n.rhw = perspective ? real(0.25f, 2.0f) : 1.0f;
            corners.emplace_back(at, n);
            it = corners.end() - 1;
        }
        v = it->second;
    }
}

TEST_CASE("aligned pass: random rotated, sheared and perspective draws equal the quad path byte for byte",
          "[draw][aligned]") {
    std::mt19937 rng(20261129);
    int rowPath = 0, cases = 0;
    for (int i = 0; i < 300; ++i) {
        Case c = randomCase(rng);
        anyMapping(c, rng);
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        rowOpt.software.skipTiles = (i % 3) == 0;  // such triangles' tiles are never decided
        if (c.program.rfind("ps_1_4", 0) == 0) {
            quadOpt.hardware = rowOpt.hardware = &ps11::defaultHardware(4);
            quadOpt.precision = rowOpt.precision = ps11::Precision::Fx8;
        }
        if (i % 4 == 1) radeon8500(quadOpt, rowOpt);  // fx12: taps sampled per pixel at scale 16
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << " rhw " << c.verts[0].rhw << " program:\n" << c.program);
        testutil::forEachSimdLevel([&](ps11::SimdLevel) { requireRowsEqual(rowOpt, c, expected, qs, cases, rowPath); });
    }
    INFO(rowPath << " of " << cases << " cases took the row path");
    CHECK(rowPath * 10 >= cases * 9);
}

TEST_CASE("float row path: random rotated, sheared and perspective draws in float and ideal equal the quad path",
          "[draw][aligned]") {
    std::mt19937 rng(20261130);
    int rowPath = 0, cases = 0;
    for (int i = 0; i < 200; ++i) {
        Case c = randomCase(rng, (i & 2) != 0);
        anyMapping(c, rng);
        for (Case::Tex& t : c.tex) withoutNaNs(t.bytes, t.format);
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        if (c.program.rfind("ps_1_4", 0) == 0) quadOpt.hardware = rowOpt.hardware = &ps11::defaultHardware(4);
        floatProfile(i, (i / 4) % 2 != 0, quadOpt, rowOpt);
        rowOpt.software.skipTiles = (i % 3) == 0;
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", rhw " << c.verts[0].rhw
                     << ", program:\n"
                     << c.program);
        requireRowsEqual(rowOpt, c, expected, qs, cases, rowPath);
    }
    INFO(rowPath << " of " << cases << " cases took the row path");
    CHECK(rowPath * 10 >= cases * 8);
}

TEST_CASE("aligned pass: rotated and perspective draws take the row path, in fx8 and fx12", "[draw][aligned]") {
    std::mt19937 rng(7);
    Case c = randomCase(rng);
    c.program = kPrograms[1];
    c.w = 40, c.h = 20;
    c.rtInit.assign(size_t(c.w) * c.h * 4, 0);
    c.scissor = false;
    c.blend = 0, c.alphaTest = false, c.writeMask = 0xf;
    // Full-target quad with its texture coordinates rotated by 90 degrees: u follows y.
    c.verts.clear();
    const float xs[4] = {-0.5f, 39.5f, 39.5f, -0.5f}, ys[4] = {-0.5f, -0.5f, 19.5f, 19.5f};
    for (int k : {0, 1, 2, 0, 2, 3}) {
        Vtx q{xs[k], ys[k], 0.5f, 1.0f, 0xffffffff, 0xff000000u, {}};
        for (auto& uv : q.uv) uv[0] = k >= 2 ? 1.0f : 0.0f, uv[1] = (k == 1 || k == 2) ? 1.0f : 0.0f;
        c.verts.push_back(q);
    }
    for (Case::Tex& t : c.tex) t.bound = true;
    DeviceOptions quadOpt;
    quadOpt.software.alignedPasses = false;
    auto check = [&](const char* what, const DeviceOptions& opt, bool rows) {
        INFO(what);
        DrawStats a, b;
        Device dev(opt), quadDev(quadOpt);
        CHECK(drawCase(dev, c, a) == drawCase(quadDev, c, b));
        CHECK(a.pixelsCovered == 800);
        // The row path shades the covered pixels only; quads add helper lanes on the diagonal.
        CHECK((a.pixelsShaded == a.pixelsCovered) == rows);
        CHECK(b.pixelsShaded > b.pixelsCovered);
    };
    check("rotated", DeviceOptions{}, true);
    // Perspective (rhw differs), colours too.
    for (size_t k = 0; k < c.verts.size(); ++k) {
        c.verts[k].rhw = c.verts[k].x > 0 ? 0.5f : 1.0f;
        c.verts[k].diffuse = c.verts[k].y > 0 ? 0xff2040c0u : 0x80ff0010u;
    }
    c.program = "ps_1_1\ntex t0\nmul r0, t0, v0\n";
    quadOpt.software.threads = 1;
    check("perspective", DeviceOptions{}, true);

    // fx12 (MaxValue 1 here, the ps_1_1 default class's): the aligned path too, without helper
    // lanes.
    DeviceOptions fx12;
    fx12.precision = ps11::Precision::Fx12;
    quadOpt.precision = ps11::Precision::Fx12;
    check("fx12", fx12, true);
}

TEST_CASE("aligned pass: one device across draws (constants change sign, textures rewritten, ping-pong)",
          "[draw][aligned]") {
    // What the row path may keep between spans or draws (the sign analysis of the constants,
    // filtered texel rows) must follow every change: the same calls on both devices, compared
    // after every draw. In each profile with a row path: fx8 and fx12, and float and ideal (the
    // float row path's H rows and decoded texel rows).
    const ps11::Precision precision =
        GENERATE(ps11::Precision::Fx8, ps11::Precision::Fx12, ps11::Precision::Float, ps11::Precision::Ideal);
    INFO("precision " << ps11::precisionName(precision));
    std::mt19937 rng(4242);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    const UINT w = 203, h = 19;
    DeviceOptions quadOpt, rowOpt;
    quadOpt.precision = rowOpt.precision = precision;
    quadOpt.software.alignedPasses = false;
    quadOpt.software.threads = rowOpt.software.threads = 2;
    Device quadDev(quadOpt), rowDev(rowOpt);
    Device* devs[2] = {&quadDev, &rowDev};
    Handle src[2], ping[2][2], surf[2][2], ps[2];
    for (int d = 0; d < 2; ++d) {
        Device& dev = *devs[d];
        REQUIRE(dev.CreateTexture(w, h, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &src[d]) == D3D_OK);
        for (int k = 0; k < 2; ++k) {
            REQUIRE(dev.CreateTexture(w, h, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &ping[d][k]) ==
                    D3D_OK);
            REQUIRE(dev.GetSurfaceLevel(ping[d][k], 0, &surf[d][k]) == D3D_OK);
        }
        REQUIRE(dev.CreatePixelShaderFromText(
                    "ps_1_1\ntex t0\ntex t1\ntex t2\nmul r0, t0, c0\nmad r0, t1, c1, r0\nmad_sat r0, t2, c2, r0\n",
                    &ps[d]) == D3D_OK);
        REQUIRE(dev.SetPixelShader(ps[d]) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_CULLMODE, D3DCULL_NONE) == D3D_OK);
        REQUIRE(dev.SetFVF(kFvf) == D3D_OK);
        for (DWORD s = 0; s < 3; ++s) {
            REQUIRE(dev.SetSamplerState(s, D3DSAMP_MINFILTER, D3DTEXF_LINEAR) == D3D_OK);
            REQUIRE(dev.SetSamplerState(s, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR) == D3D_OK);
            REQUIRE(dev.SetSamplerState(s, D3DSAMP_ADDRESSU, D3DTADDRESS_CLAMP) == D3D_OK);
            REQUIRE(dev.SetSamplerState(s, D3DSAMP_ADDRESSV, D3DTADDRESS_CLAMP) == D3D_OK);
        }
    }
    // Taps half a texel apart in both directions (the blur footprint) and one at an eighth.
    std::vector<Vtx> quad;
    const float xs[4] = {-0.5f, float(w) - 0.5f, float(w) - 0.5f, -0.5f};
    const float ys[4] = {-0.5f, -0.5f, float(h) - 0.5f, float(h) - 0.5f};
    const float off[3][2] = {{-0.5f, -0.5f}, {0.5f, 0.5f}, {0.125f, -0.375f}};
    for (int k : {0, 1, 2, 0, 2, 3}) {
        Vtx q{xs[k], ys[k], 0.5f, 1.0f, 0xffffffff, 0xff000000u, {}};
        for (int s = 0; s < 3; ++s) {
            q.uv[s][0] = ((k == 1 || k == 2) ? 1.0f : 0.0f) + off[s][0] / float(w);
            q.uv[s][1] = (k >= 2 ? 1.0f : 0.0f) + off[s][1] / float(h);
        }
        quad.push_back(q);
    }
    std::vector<uint8_t> bytes(size_t(w) * h * 4);
    for (int iter = 0; iter < 12; ++iter) {
        // Every third draw rewrites the source texture, every draw flips constant signs.
        if (iter % 3 == 0)
            for (uint8_t& b : bytes) b = uint8_t(rng());
        float consts[3][4];
        for (auto& c : consts)
            for (float& v : c) v = float(uni(-4, 4)) * 0.25f;
        std::vector<uint8_t> result[2];
        for (int d = 0; d < 2; ++d) {
            Device& dev = *devs[d];
            if (iter % 3 == 0) {
                D3DLOCKED_RECT lr;
                REQUIRE(dev.LockRect(src[d], 0, &lr, nullptr, 0) == D3D_OK);
                for (UINT y = 0; y < h; ++y)
                    std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &bytes[size_t(y) * w * 4], 4 * w);
                REQUIRE(dev.UnlockRect(src[d], 0) == D3D_OK);
            }
            REQUIRE(dev.SetPixelShaderConstantF(0, &consts[0][0], 3) == D3D_OK);
            // Draw 0 of each group reads the source, the others the previous target (ping-pong).
            const int to = iter & 1;
            const Handle from = iter % 3 == 0 ? src[d] : ping[d][to ^ 1];
            for (DWORD s = 0; s < 3; ++s) REQUIRE(dev.SetTexture(s, from) == D3D_OK);
            REQUIRE(dev.SetRenderTarget(0, surf[d][to]) == D3D_OK);
            REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, quad.data(), sizeof(Vtx)) == D3D_OK);
            if (d == 1) CHECK(dev.lastDrawStats().pixelsShaded == dev.lastDrawStats().pixelsCovered);
            Handle sys{};
            REQUIRE(dev.CreateOffscreenPlainSurface(w, h, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &sys) == D3D_OK);
            REQUIRE(dev.GetRenderTargetData(surf[d][to], sys) == D3D_OK);
            D3DLOCKED_RECT lr;
            REQUIRE(dev.LockRect(sys, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
            result[d].resize(size_t(w) * h * 4);
            for (UINT y = 0; y < h; ++y)
                std::memcpy(&result[d][size_t(y) * w * 4], static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, 4 * w);
            REQUIRE(dev.UnlockRect(sys) == D3D_OK);
            REQUIRE(dev.Release(sys) == D3D_OK);
        }
        INFO("draw " << iter);
        REQUIRE(result[1] == result[0]);
    }
}

namespace {

// Below the device: a copy program (`mov r0, t0`) for the profile's executor.
std::unique_ptr<ps11::Executor> copyExecutor(ps11::Precision precision) {
    ps11::Diagnostics diags;
    std::optional<ps11::Program> program = ps11::parseAssembly("ps_1_1\ntex t0\nmov r0, t0\n", "t.psh", {}, diags);
    REQUIRE(program);
    REQUIRE(ps11::validate(*program, diags));
    ps11::ExecutorOptions eo;
    eo.precision = precision;
    std::unique_ptr<ps11::Executor> exec = ps11::Executor::create(*program, eo, diags);
    REQUIRE(exec);
    return exec;
}

// The two triangles of the 1:1 quad over a w×h target, tap 0's coordinates shifted by (du, dv)
// texels; `used` is what they interpolate.
void quadSetups(int w, int h, float du, float dv, TriangleSetup setups[2], uint64_t& used) {
    ScreenTriangle tris[2];
    const double xs[4] = {-0.5, w - 0.5, w - 0.5, -0.5}, ys[4] = {-0.5, -0.5, h - 0.5, h - 0.5};
    const int order[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int t = 0; t < 2; ++t)
        for (int k = 0; k < 3; ++k) {
            ScreenVertex& v = tris[t].v[size_t(k)];
            const int c = order[t][k];
            v.x = xs[c], v.y = ys[c], v.rhw = 1;
            v.attr[size_t(attrTex(0, 0))] = float((c == 1 || c == 2) ? 1.0 : 0.0) + du / float(w);
            v.attr[size_t(attrTex(0, 1))] = (c >= 2 ? 1.0f : 0.0f) + dv / float(h);
        }
    used = (uint64_t(1) << attrTex(0, 0)) | (uint64_t(1) << attrTex(0, 1));
    for (int t = 0; t < 2; ++t) REQUIRE(setupTriangle(tris[t], used, ClipRect{0, 0, w, h}, setups[t]));
}

}  // namespace

TEST_CASE("aligned pass: H rows cached by a worker never outlive their draw", "[draw][aligned]") {
    // The device may place a new texture copy where a freed one was, so two draws can sample the
    // same address with different texels. Driven below the device: the same buffer, rewritten
    // between two draws of the same triangles, must give each draw its own texels.
    const int w = 48, h = 6;
    const std::unique_ptr<ps11::Executor> exec = copyExecutor(ps11::Precision::Fx8);
    std::vector<uint8_t> texels(size_t(w) * h * 4);
    Image target;
    target.format = formatInfo(D3DFMT_A8R8G8B8);
    target.width = w, target.height = h, target.rowPitch = 4 * w;
    target.bytes.assign(size_t(w) * h * 4, 0);
    // The 1:1 quad with the tap a quarter texel right (one weight along whole rows).
    TriangleSetup setups[2];
    uint64_t used = 0;
    quadSetups(w, h, 0.25f, 0.0f, setups, used);
    AlignedScratch* scratch = new AlignedScratch;  // one worker's, kept across the draws
    std::mt19937 rng(99);
    for (int draw = 0; draw < 2; ++draw) {
        for (uint8_t& b : texels) b = uint8_t(rng());
        AlignedDraw d;
        // prepareAlignedDraw gives every draw a new serial; the taps are set by hand here.
        std::array<std::shared_ptr<const ps11::Texture>, 8> none{};
        std::array<ps11::SamplerState, 8> samplers{};
        MergeState merge;
        REQUIRE(prepareAlignedDraw(*exec, ps11::Precision::Fx8, none, samplers, merge, MergeTarget{&target, nullptr},
                                   false, used, d));
        AlignedTap& tap = d.taps[0];
        tap.bound = true;
        d.bound = 1;
        tap.texels = texels.data();
        tap.width = w, tap.height = h;
        tap.linear = true;
        tap.addressU = tap.addressV = ps11::TextureAddress::Clamp;
        AlignedTriangle at[2];
        for (int t = 0; t < 2; ++t) REQUIRE(prepareAlignedTriangle(d, setups[t], at[t]));
        const AlignedTriangle* tp[2] = {&at[0], &at[1]};
        const TriangleSetup* sp[2] = {&setups[0], &setups[1]};
        AlignedStats stats;
        // The second draw covers only the row the first ended on: its cached H row has the
        // same texel address and configuration.
        const int y0 = draw == 0 ? 0 : h - 1;
        drawAlignedRows(d, tp, sp, 2, y0, h, *scratch, stats);
        CHECK(stats.pixels == uint64_t(w) * uint64_t(h - y0));
        // Expected: round_half_even((a·192 + b·64) / 256) of texels x and x + 1 (clamped).
        int wrong = 0;
        for (int y = y0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 4; ++c) {
                    const uint32_t a = texels[(size_t(y) * w + size_t(x)) * 4 + size_t(c)];
                    const uint32_t b = texels[(size_t(y) * w + size_t(std::min(x + 1, w - 1))) * 4 + size_t(c)];
                    const uint32_t t = a * 192 + b * 64;
                    const uint32_t e = (t + 127 + ((t >> 8) & 1)) >> 8;
                    wrong += target.bytes[(size_t(y) * w + size_t(x)) * 4 + size_t(c)] != e;
                }
        INFO("draw " << draw);
        CHECK(wrong == 0);
    }
    // The vector path (where the level has one) really served the second draw from rows it built
    // itself.
    if (alignedKernels(ps11::simdLevel())) CHECK(scratch->hrows.built == uint64_t(h + 1));
    delete scratch;
}

TEST_CASE("float row path: texel rows kept by a worker never outlive their draw", "[draw][aligned]") {
    // As above for the float row path's H rows and decoded texel rows: the same buffer, rewritten
    // between two draws, read by a worker that keeps its scratch; each draw must equal the same
    // draw on a fresh scratch.
    const int w = 48, h = 6;
    const std::unique_ptr<ps11::Executor> exec = copyExecutor(ps11::Precision::Float);
    std::vector<uint8_t> texels(size_t(w) * h * 4);
    auto makeTarget = [&] {
        Image t;
        t.format = formatInfo(D3DFMT_A8R8G8B8);
        t.width = w, t.height = h, t.rowPitch = 4 * w;
        t.bytes.assign(size_t(w) * h * 4, 0);
        return t;
    };
    Image kept = makeTarget(), fresh = makeTarget();
    // The 1:1 quad with the tap a quarter texel right and a quarter texel down (each pixel row
    // reads H rows of two texel rows).
    TriangleSetup setups[2];
    uint64_t used = 0;
    quadSetups(w, h, 0.25f, 0.25f, setups, used);
    auto scratch = std::make_unique<FloatRowScratch>();  // one worker's, kept across the draws
    std::mt19937 rng(99);
    for (int draw = 0; draw < 2; ++draw) {
        for (uint8_t& b : texels) b = uint8_t(rng());
        for (Image* target : {&kept, &fresh}) {
            FloatRowDraw d;
            std::array<std::shared_ptr<const ps11::Texture>, 8> none{};
            std::array<ps11::SamplerState, 8> samplers{};
            MergeState merge;
            merge.precision = ps11::Precision::Float;
            REQUIRE(prepareFloatRowDraw(*exec, ps11::Precision::Float, 0, false, none, samplers, merge,
                                        MergeTarget{target, nullptr}, false, used, d));
            FloatRowTap& tap = d.taps[0];
            tap.bound = true;
            d.bound = 1;
            tap.unorm8 = true;
            tap.bytes = texels.data();
            tap.width = w, tap.height = h;
            tap.linear = true;
            tap.addressU = tap.addressV = ps11::TextureAddress::Clamp;
            tap.nonNegative = true;
            FloatRowTriangle ft[2];
            for (int t = 0; t < 2; ++t) REQUIRE(prepareFloatRowTriangle(d, setups[t], ft[t]));
            const uint8_t prepared[2] = {1, 1};
            const uint32_t tableOf[2] = {0, 1};
            shareFloatRowTables(d, ft, prepared, tableOf, 2);
            const FloatRowTriangle* tp[2] = {&ft[0], &ft[1]};
            const TriangleSetup* sp[2] = {&setups[0], &setups[1]};
            AlignedStats stats;
            // The second draw covers only the rows the first ended on: the kept scratch holds
            // rows of the same texel addresses.
            const int y0 = draw == 0 ? 0 : h - 2;
            FloatRowScratch own;
            drawFloatRows(d, tp, sp, 2, y0, h, target == &kept ? *scratch : own, stats);
            CHECK(stats.pixels == uint64_t(w) * uint64_t(h - y0));
        }
        INFO("draw " << draw);
        CHECK(std::vector<uint8_t>(kept.bytes.begin(), kept.bytes.end()) ==
              std::vector<uint8_t>(fresh.bytes.begin(), fresh.bytes.end()));
    }
}

TEST_CASE("aligned pass: magnified taps (2x, 3x, 8x, non-integer) equal the quad path byte for byte",
          "[draw][aligned]") {
    // A glare composite's blurred tap reads a small texture magnified: consecutive columns share
    // their texels and the weight changes every column (tabulated H rows). Every address mode,
    // border colours, coordinates past [0, 1] (border and wrapped texels inside a row), point
    // and linear filters, one or two threads.
    std::mt19937 rng(20261127);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    const float scales[] = {2.0f, 3.0f, 8.0f, 2.5f, 1.75f, 5.3f, 1.0f / 0.9f};
    int aligned = 0, cases = 0;
    for (int i = 0; i < 280; ++i) {
        Case c = randomCase(rng);
        c.w = UINT(uni(16, 420));
        c.h = UINT(uni(2, 20));
        c.rtInit.resize(size_t(c.w) * c.h * 4);
        for (uint8_t& b : c.rtInit) b = uint8_t(rng());
        const float scale = scales[size_t(i) % std::size(scales)];
        float u[4][2], v[4][2];
        for (int s = 0; s < 4; ++s) {
            Case::Tex& t = c.tex[size_t(s)];
            t.w = std::max(1u, UINT(float(c.w) / scale + 0.5f));
            t.h = std::max(1u, UINT(float(c.h) / scale + 0.5f));
            t.bytes.resize(size_t(t.w) * t.h * texelBytes(t.format));
            for (uint8_t& b : t.bytes) b = uint8_t(uni(0, 3) ? rng() : (uni(0, 1) ? 0 : 255));
            t.filter = uni(0, 4) ? D3DTEXF_LINEAR : D3DTEXF_POINT;
            t.bound = uni(0, 15) != 0;
            const int kind = uni(0, 3);
            if (kind <= 1) {  // the whole texture over the target, maybe offset by a fraction of a texel
                const float ox = kind ? float(uni(-8, 8)) * 0.0625f / float(t.w) : 0.0f;
                u[s][0] = ox, u[s][1] = 1 + ox, v[s][0] = 0, v[s][1] = 1;
            } else {  // past the edges: border, clamped, wrapped and mirrored texels inside rows
                u[s][0] = real(-0.6f, 0.3f), u[s][1] = real(0.7f, 1.6f), v[s][0] = real(-0.4f, 0.2f),
                v[s][1] = real(0.8f, 1.4f);
            }
        }
        // One stage on a 1:1 texture (the scene tap of a composite).
        if (uni(0, 1)) {
            Case::Tex& t = c.tex[0];
            t.w = c.w, t.h = c.h;
            t.bytes.resize(size_t(t.w) * t.h * texelBytes(t.format));
            for (uint8_t& b : t.bytes) b = uint8_t(rng());
            u[0][0] = 0, u[0][1] = 1, v[0][0] = 0, v[0][1] = 1;
        }
        const float xs[4] = {-0.5f, float(c.w) - 0.5f, float(c.w) - 0.5f, -0.5f};
        const float ys[4] = {-0.5f, -0.5f, float(c.h) - 0.5f, float(c.h) - 0.5f};
        c.verts.clear();
        const int order[2][6] = {{0, 1, 2, 0, 2, 3}, {1, 2, 3, 1, 3, 0}};
        const DWORD dif = DWORD(rng());
        for (int k : order[uni(0, 1)]) {
            Vtx q{xs[k], ys[k], 0.5f, 1.0f, dif, 0xff000000u, {}};
            for (int s = 0; s < 4; ++s) {
                q.uv[s][0] = (k == 1 || k == 2) ? u[s][1] : u[s][0];
                q.uv[s][1] = (k >= 2) ? v[s][1] : v[s][0];
            }
            c.verts.push_back(q);
        }
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        rowOpt.software.skipTiles = false;  // every pixel shaded: the row path's count below holds
        if (c.program.rfind("ps_1_4", 0) == 0) {
            quadOpt.hardware = rowOpt.hardware = &ps11::defaultHardware(4);
            quadOpt.precision = rowOpt.precision = ps11::Precision::Fx8;
        }
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << " scale " << scale << " program:\n" << c.program);
        testutil::forEachSimdLevel([&](ps11::SimdLevel) {
            Device rowDev(rowOpt);
            DrawStats rs;
            REQUIRE(drawCase(rowDev, c, rs) == expected);
            requireSkippingEqual(rowOpt, c, expected, qs);
            if (qs.pixelsCovered == 0) return;
            ++cases;
            if (rs.pixelsShaded == rs.pixelsCovered) ++aligned;
        });
    }
    INFO(aligned << " of " << cases << " cases took the row path");
    CHECK(aligned * 10 >= cases * 9);
}

TEST_CASE("aligned pass: taps one texel apart on the same rows (the half-texel blur) equal the quad path",
          "[draw][aligned]") {
    // Four taps of one texture at (−½, −½), (+½, −½), (−½, +½), (+½, +½) texels plus a common
    // offset in eighths (weights ½ or any, vertical weight ½ or any), 1:1 or a 2:1 reduction,
    // point or linear, every address mode, over rows wider than a span (whole spans inside the
    // taps' runs, as in a 1080p blur; a scissor now and then starts and ends spans anywhere).
    std::mt19937 rng(20261128);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    for (int i = 0; i < 48; ++i) {
        Case c;
        c.w = UINT(uni(260, 700));
        c.h = UINT(uni(2, 9));
        c.rtInit.resize(size_t(c.w) * c.h * 4);
        for (uint8_t& b : c.rtInit) b = uint8_t(rng());
        const UINT scale = uni(0, 3) ? 1 : 2;
        Case::Tex t;
        t.w = c.w * scale, t.h = c.h * scale;
        t.bytes.resize(size_t(t.w) * t.h * 4);
        for (uint8_t& b : t.bytes) b = uint8_t(uni(0, 5) ? rng() : 255);
        t.filter = uni(0, 5) ? D3DTEXF_LINEAR : D3DTEXF_POINT;
        t.addressU = DWORD(uni(1, 5));
        t.addressV = DWORD(uni(1, 5));
        t.border = DWORD(rng());
        c.tex.assign(4, t);
        c.oneTexture = true;
        c.program = uni(0, 1) ? kPrograms[1]  // the blur (c0), or its weighted form (c0..c3)
                              : "ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\nmad r0, t1, c1, r0\n"
                                "mad r0, t2, c2, r0\nmad r0, t3, c3, r0\n";
        for (auto& k : c.consts)
            for (float& v : k) v = float(uni(0, 8)) / 16.0f;
        const float ox = float(uni(0, 1) ? 0 : uni(-7, 7)) / 8.0f, oy = float(uni(0, 1) ? 0 : uni(-7, 7)) / 8.0f;
        const float dx[4] = {-0.5f, 0.5f, -0.5f, 0.5f}, dy[4] = {-0.5f, -0.5f, 0.5f, 0.5f};
        const float xs[4] = {-0.5f, float(c.w) - 0.5f, float(c.w) - 0.5f, -0.5f};
        const float ys[4] = {-0.5f, -0.5f, float(c.h) - 0.5f, float(c.h) - 0.5f};
        for (int k : {0, 1, 2, 0, 2, 3}) {
            Vtx q{xs[k], ys[k], 0.5f, 1.0f, 0xffffffffu, 0xff000000u, {}};
            for (int s = 0; s < 4; ++s) {
                q.uv[s][0] = ((k == 1 || k == 2) ? 1.0f : 0.0f) + (dx[s] + ox) / float(t.w);
                q.uv[s][1] = (k >= 2 ? 1.0f : 0.0f) + (dy[s] + oy) / float(t.h);
            }
            c.verts.push_back(q);
        }
        c.blend = DWORD(uni(0, 1));
        // A scissor rectangle now and then: spans that start and end anywhere.
        c.scissor = uni(0, 2) == 0;
        c.scissorRect = RECT{uni(0, 40), 0, int(c.w) - uni(0, 40), int(c.h)};
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        rowOpt.software.skipTiles = false;
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", scale " << scale << ", offset " << ox << ", " << oy
                     << (c.scissor ? ", scissor" : ""));
        testutil::forEachSimdLevel([&](ps11::SimdLevel) {
            Device rowDev(rowOpt);
            DrawStats rs;
            REQUIRE(drawCase(rowDev, c, rs) == expected);
            CHECK(rs.pixelsShaded == rs.pixelsCovered);  // the row path drew it
        });
    }
}

TEST_CASE("aligned pass: a magnified tap's columns are tabulated runs", "[draw][aligned]") {
    // 2x, 3x, 8x and 2.5x magnification over a 1:1 quad: with vector kernels (the Avx2 level), all
    // columns but a few at the edges (clamped pairs) belong to runs of the tabulated configuration
    // (weight per column).
    const ps11::ScopedSimdLevel level(ps11::SimdLevel::Avx2);
    if (!alignedKernels(level.level())) return;
    ps11::Diagnostics diags;
    std::optional<ps11::Program> program = ps11::parseAssembly("ps_1_1\ntex t0\nmov r0, t0\n", "t.psh", {}, diags);
    REQUIRE(program);
    REQUIRE(ps11::validate(*program, diags));
    std::unique_ptr<ps11::Executor> exec = ps11::Executor::create(*program, ps11::ExecutorOptions{}, diags);
    REQUIRE(exec);
    const int w = 240, h = 4;
    Image target;
    target.format = formatInfo(D3DFMT_A8R8G8B8);
    target.width = w, target.height = h, target.rowPitch = 4 * w;
    target.bytes.assign(size_t(w) * h * 4, 0);
    for (const double scale : {2.0, 3.0, 8.0, 2.5}) {
        const uint32_t tw = uint32_t(w / scale);
        std::vector<uint8_t> texels(size_t(tw) * h * 4, 7);
        ScreenTriangle tri;
        const double xs[3] = {-0.5, w - 0.5, w - 0.5}, ys[3] = {-0.5, -0.5, h - 0.5};
        for (int k = 0; k < 3; ++k) {
            ScreenVertex& v = tri.v[size_t(k)];
            v.x = xs[k], v.y = ys[k], v.rhw = 1;
            v.attr[size_t(attrTex(0, 0))] = k == 0 ? 0.0f : float(w / scale / tw);
            v.attr[size_t(attrTex(0, 1))] = k == 2 ? 1.0f : 0.0f;
        }
        const uint64_t used = (uint64_t(1) << attrTex(0, 0)) | (uint64_t(1) << attrTex(0, 1));
        TriangleSetup setup;
        REQUIRE(setupTriangle(tri, used, ClipRect{0, 0, w, h}, setup));
        AlignedDraw d;
        std::array<std::shared_ptr<const ps11::Texture>, 8> none{};
        std::array<ps11::SamplerState, 8> samplers{};
        REQUIRE(prepareAlignedDraw(*exec, ps11::Precision::Fx8, none, samplers, MergeState{},
                                   MergeTarget{&target, nullptr}, false, used, d));
        AlignedTap& tap = d.taps[0];
        tap.bound = true;
        d.bound = 1;
        tap.texels = texels.data();
        tap.width = tw, tap.height = h;
        tap.linear = true;
        tap.addressU = tap.addressV = ps11::TextureAddress::Clamp;
        AlignedTriangle at;
        REQUIRE(prepareAlignedTriangle(d, setup, at));
        int tabulated = 0;
        for (const AlignedTriangle::Run& r : at.taps[0].runs)
            if (r.tabulated) tabulated += r.x1 - r.x0;
        INFO("scale " << scale);
        CHECK(tabulated >= w - 2 * int(scale + 1));
    }
}

TEST_CASE("tile skipping: random draws over partly constant textures equal every pixel shaded",
          "[draw][aligned][skip]") {
    // Textures that are zero, one constant texel, zero with a few random blocks (a sparse glare),
    // or stripes of different constants (tiles whose ranges are different single values); programs of glare passes
    // (composites, bright passes, blurs) among the random ones; fx8, float, ideal and fx12; ONE/ONE blending often.
    // Skipping on must give the bytes of skipping off (and of the quad path), and must really fill, copy and skip
    // tiles.
    const char* const programs[] = {
        "ps_1_1\ntex t0\ntex t1\nadd r0, t0, t1\n",
        "ps_1_1\ntex t0\ntex t1\nmad r0, t1, c0, t0\n",
        "ps_1_1\ntex t0\nsub_sat r0, t0, c1\nmul_x4 r0, r0, c2\n",
        "ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\nmad r0, t1, c0, r0\nmad r0, t2, c0, r0\nmad r0, t3, "
        "c0, r0\n",
        "ps_1_4\ntexld r0, t0\ntexld r1, t1\nmad r0, r1, c0, r0\n",
    };
    std::mt19937 rng(20261128);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    uint64_t filled = 0, copied = 0, skipped = 0, shaded = 0;
    for (int i = 0; i < 480; ++i) {
        const int profile = i % 4;  // fx8, float, ideal, fx12 (the radeon8500 class)
        Case c = randomCase(rng, profile == 1 || profile == 2);
        if (uni(0, 1)) c.fog = c.depth = false;  // (depth and fog keep a zero ONE/ONE tile from being skipped)
        if (uni(0, 2)) c.program = programs[uni(0, int(std::size(programs)) - 1)];
        if (uni(0, 1)) c.blend = 1;  // ONE/ONE
        if (uni(0, 1)) c.rtFormat = D3DFMT_A8R8G8B8;
        for (Case::Tex& t : c.tex) {
            const uint32_t tb = texelBytes(t.format);
            const int kind = uni(0, 4);
            if (kind == 0) continue;  // random texels
            std::vector<uint8_t> texel(tb, 0);
            if (kind == 2)
                for (uint8_t& b : texel) b = uint8_t(uni(0, 1) ? rng() : 0);
            for (size_t k = 0; k < t.bytes.size(); ++k) t.bytes[k] = texel[k % tb];
            if (kind == 4) {  // stripes of columns, each one constant (zero or not): tiles of different constants
                const UINT stripe = UINT(uni(8, 96));
                for (UINT x0 = 0; x0 < t.w; x0 += stripe) {
                    for (uint8_t& b : texel) b = uint8_t(uni(0, 2) ? rng() : 0);
                    for (UINT y = 0; y < t.h; ++y)
                        for (UINT x = x0; x < std::min(t.w, x0 + stripe); ++x)
                            for (uint32_t k = 0; k < tb; ++k) t.bytes[(size_t(y) * t.w + x) * tb + k] = texel[k];
                }
            }
            if (kind == 3) {  // a few random blocks on zero
                const int blocks = uni(1, 3);
                for (int b = 0; b < blocks; ++b) {
                    const UINT bx = UINT(uni(0, int(t.w) - 1)), by = UINT(uni(0, int(t.h) - 1));
                    const UINT bw = UINT(uni(1, 12)), bh = UINT(uni(1, 6));
                    for (UINT y = by; y < std::min(t.h, by + bh); ++y)
                        for (UINT x = bx; x < std::min(t.w, bx + bw); ++x)
                            for (uint32_t k = 0; k < tb; ++k) t.bytes[(size_t(y) * t.w + x) * tb + k] = uint8_t(rng());
                }
            }
        }
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        rowOpt.software.skipTiles = false;
        if (c.program.rfind("ps_1_4", 0) == 0) quadOpt.hardware = rowOpt.hardware = &ps11::defaultHardware(4);
        quadOpt.precision = rowOpt.precision = profile == 0   ? ps11::Precision::Fx8
                                               : profile == 1 ? ps11::Precision::Float
                                                              : ps11::Precision::Ideal;
        if (profile == 3) radeon8500(quadOpt, rowOpt);
        DeviceOptions skipOpt = rowOpt;
        skipOpt.software.skipTiles = true;
        Device quadDev(quadOpt), rowDev(rowOpt), skipDev(skipOpt);
        DrawStats qs, rs, ks;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << ps11::precisionName(*quadOpt.precision) << ", blend "
                     << c.blend << ", program:\n"
                     << c.program);
        REQUIRE(drawCase(rowDev, c, rs) == expected);
        const std::vector<uint8_t> got = drawCase(skipDev, c, ks);
        size_t firstDiff = 0;
        while (firstDiff < got.size() && got[firstDiff] == expected[firstDiff]) ++firstDiff;
        INFO("first difference at pixel " << firstDiff / 4 % c.w << ", " << firstDiff / 4 / c.w << "; tiles filled "
                                          << ks.tilesFilled << " copied " << ks.tilesCopied << " skipped "
                                          << ks.tilesSkipped);
        REQUIRE(firstDiff == got.size());
        CHECK(ks.pixelsCovered == qs.pixelsCovered);
        filled += ks.tilesFilled, copied += ks.tilesCopied, skipped += ks.tilesSkipped, shaded += ks.tilesShaded;
    }
    INFO("tiles shaded " << shaded << ", filled " << filled << ", copied " << copied << ", skipped " << skipped);
    CHECK(filled > 20);
    CHECK(copied > 20);
    CHECK(skipped > 5);
}

TEST_CASE("tile skipping: 1:1 copies stored straight from the texel row, plain and ONE/ONE", "[draw][aligned][skip]") {
    // The sprites' composite (mul r0, t0, c0 with c0 = (1, 1, 1, 0), ONE/ONE) and plain copies: every
    // tile is a copy whatever the texels, and the copy goes from the texture's row to the target
    // (a row copy, or a saturating byte add). Bytes must equal skipping off and the quad path.
    std::mt19937 rng(20261127);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    const char* const programs[] = {"ps_1_1\ntex t0\nmul r0, t0, c0\n", "ps_1_1\ntex t0\nmov r0, t0\n",
                                    "ps_1_1\ntex t0\nmov r0.rgb, t0\n+mov r0.a, c1.a\n"};
    uint64_t copied = 0;
    for (int i = 0; i < 96; ++i) {
        Case c = randomCase(rng);
        c.w = UINT(uni(1, 300)), c.h = UINT(uni(1, 40));
        c.rtFormat = uni(0, 2) ? D3DFMT_A8R8G8B8 : D3DFMT_X8R8G8B8;
        c.rtInit.resize(size_t(c.w) * c.h * 4);
        for (uint8_t& b : c.rtInit) b = uint8_t(rng());
        for (Case::Tex& t : c.tex) {
            t.w = c.w, t.h = c.h;
            t.format = uni(0, 2) ? D3DFMT_A8R8G8B8 : D3DFMT_X8R8G8B8;
            t.bytes.resize(size_t(t.w) * t.h * 4);
            for (uint8_t& b : t.bytes) b = uint8_t(uni(0, 3) ? rng() : 255);
            t.filter = uni(0, 1) ? D3DTEXF_LINEAR : D3DTEXF_POINT;
            t.bound = true;
        }
        c.program = programs[size_t(i) % std::size(programs)];
        for (int k = 0; k < 4; ++k) c.consts[0][k] = k < 3 ? 1.0f : 0.0f;
        c.consts[1][3] = float(uni(0, 4)) * 0.25f;
        fullTargetQuad(c);
        c.blend = DWORD(i % 2);  // plain, ONE/ONE
        c.alphaTest = false, c.writeMask = 0xf, c.scissor = uni(0, 5) == 0;
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        rowOpt.software.skipTiles = false;
        // The second half in fx12: a texel's grid value 16·b stores b, and a constant channel
        // between two bytes rounds with the sum, so it is not copied (c1.a = 0.5: 2040, whose
        // sum with 16·d rounds to the even byte, into a target with alpha).
        if (i >= 48) {
            radeon8500(quadOpt, rowOpt);
            if (i % 3 == 2) c.rtFormat = D3DFMT_A8R8G8B8, c.consts[1][3] = 0.5f;
        }
        DeviceOptions skipOpt = rowOpt;
        skipOpt.software.skipTiles = true;
        Device quadDev(quadOpt), rowDev(rowOpt), skipDev(skipOpt);
        DrawStats qs, rs, ks;
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", blend " << c.blend
                     << ", program:\n"
                     << c.program);
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        REQUIRE(drawCase(rowDev, c, rs) == expected);
        REQUIRE(drawCase(skipDev, c, ks) == expected);
        copied += ks.tilesCopied;
    }
    CHECK(copied > 96);
}

TEST_CASE("tile skipping: tiles over different constants of one texture are decided each for its own",
          "[draw][aligned][skip]") {
    // add r0, t0, t1 over random scene texels t0 and a glare t1 of stripes, each stripe one
    // constant (zero, then not): the renderer decides a tile over its stages' ranges with the
    // varying scene widened to the whole texture's (one evaluation for every tile over a zero
    // glare: a copy of the scene), so a tile over the non-zero stripe must not take the zero
    // stripe's copy. Bytes must equal skipping off; both kinds of tile must occur.
    std::mt19937 rng(20261128);
    for (int i = 0; i < 8; ++i) {
        Case c = randomCase(rng);
        c.w = 1024, c.h = 48;
        c.oneTexture = false;
        c.rtFormat = D3DFMT_A8R8G8B8;
        c.rtInit.assign(size_t(c.w) * c.h * 4, 0);
        c.tex.resize(4);
        for (size_t s = 0; s < c.tex.size(); ++s) {
            Case::Tex& t = c.tex[s];
            t.w = c.w, t.h = c.h;
            t.format = D3DFMT_A8R8G8B8;
            t.filter = i & 1 ? D3DTEXF_LINEAR : D3DTEXF_POINT;
            t.addressU = t.addressV = D3DTADDRESS_CLAMP;  // (wrap would let every tile reach every stripe)
            t.bound = s < 2;
            t.bytes.resize(size_t(t.w) * t.h * 4);
            for (UINT y = 0; y < t.h; ++y)
                for (UINT x = 0; x < t.w; ++x)
                    for (int k = 0; k < 4; ++k) {
                        // Stripes of 256 columns (two whole tiles inside each): zero, then
                        // 40 + 20·stripe, the last one zero again.
                        const UINT stripe = x / 256;
                        const uint8_t glare = stripe == 0 || stripe == 3 ? 0 : uint8_t(40 + 20 * stripe);
                        t.bytes[(size_t(y) * t.w + x) * 4 + size_t(k)] = s == 0 ? uint8_t(rng()) : glare;
                    }
        }
        c.program = i & 2 ? "ps_1_1\ntex t0\ntex t1\nadd r0, t0, t1\n" : "ps_1_1\ntex t0\ntex t1\nadd r0, t1, t0\n";
        fullTargetQuad(c);
        c.blend = DWORD(i >> 2);  // plain, ONE/ONE
        c.alphaTest = false, c.writeMask = 0xf, c.scissor = false;
        DeviceOptions rowOpt;
        rowOpt.software.threads = 1 + (i & 1);
        rowOpt.software.skipTiles = false;
        DeviceOptions skipOpt = rowOpt;
        skipOpt.software.skipTiles = true;
        Device rowDev(rowOpt), skipDev(skipOpt);
        DrawStats rs, ks;
        INFO("case " << i << ", program:\n" << c.program);
        const std::vector<uint8_t> expected = drawCase(rowDev, c, rs);
        REQUIRE(drawCase(skipDev, c, ks) == expected);
        INFO("tiles shaded " << ks.tilesShaded << ", copied " << ks.tilesCopied);
        CHECK(ks.tilesCopied > 0);
        CHECK(ks.tilesShaded > 0);
    }
}

// Overlapping axis-aligned quads at sub-pixel positions over a random target, a random texture
// per stage magnified or minified, blended ONE/ONE or not, some partly outside the target.
Case spriteCase(std::mt19937& rng, int quads, bool twoTaps) {
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    Case c = randomCase(rng);
    c.w = UINT(uni(64, 300)), c.h = UINT(uni(16, 60));
    c.rtInit.resize(size_t(c.w) * c.h * 4);
    for (uint8_t& b : c.rtInit) b = uint8_t(rng());
    for (Case::Tex& t : c.tex) {
        t.w = UINT(uni(4, 40)), t.h = UINT(uni(4, 40));
        t.format = D3DFMT_A8R8G8B8;
        t.bytes.resize(size_t(t.w) * t.h * 4);
        for (uint8_t& b : t.bytes) b = uint8_t(rng());
        t.bound = true;
    }
    c.program = twoTaps ? "ps_1_1\ntex t0\ntex t1\nmad r0, t1, c0, t0\n" : "ps_1_1\ntex t0\nmul r0, t0, c0\n";
    c.blend = DWORD(uni(0, 2) ? 1 : 0);
    c.alphaTest = false, c.writeMask = 0xf, c.scissor = false;
    c.verts.clear();
    for (int q = 0; q < quads; ++q) {
        const float size = real(2.0f, 40.0f);
        const float x0 = real(-10.0f, float(c.w)), y0 = real(-10.0f, float(c.h));
        const float xs[4] = {x0, x0 + size, x0 + size, x0}, ys[4] = {y0, y0, y0 + size, y0 + size};
        const DWORD colour = DWORD(rng());
        for (int k : {0, 1, 2, 0, 2, 3}) {
            Vtx v{xs[k], ys[k], 0.5f, 1.0f, colour, 0xff000000u, {}};
            for (int s = 0; s < 4; ++s)
                v.uv[s][0] = (k == 1 || k == 2) ? 1.0f : 0.0f, v.uv[s][1] = k >= 2 ? 1.0f : 0.0f;
            c.verts.push_back(v);
        }
    }
    return c;
}

TEST_CASE("aligned pass: draws of many small quads (sprites) equal the quad path byte for byte", "[draw][aligned]") {
    // Groups of 16 triangles per band, tables of each triangle's own columns, H rows built without
    // the cache.
    std::mt19937 rng(20261127);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    uint64_t rowShaded = 0, quadShaded = 0;
    // Cases 24 on: float and ideal (groups of 16 triangles row by row, as in fx8).
    for (int i = 0; i < 40; ++i) {
        const bool floatCase = i >= 24;
        const int quads = floatCase && i % 2 ? uni(2, 8) : uni(20, 300);
        const Case c = spriteCase(rng, quads, i % 2 == 0);
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        if (floatCase)
            quadOpt.precision = rowOpt.precision = i % 4 < 2 ? ps11::Precision::Float : ps11::Precision::Ideal;
        Device quadDev(quadOpt), rowDev(rowOpt);
        DrawStats qs, rs;
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << quads << " quads, blend " << c.blend
                     << (floatCase ? ", float/ideal" : ", fx8"));
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        REQUIRE(drawCase(rowDev, c, rs) == expected);
        CHECK(rs.pixelsShaded <= qs.pixelsShaded);
        rowShaded += rs.pixelsShaded, quadShaded += qs.pixelsShaded;
    }
    // The row path shades no helper lanes: fewer pixels than the quad path's 2x2 quads.
    INFO("shaded: row path " << rowShaded << ", quad path " << quadShaded);
    CHECK(rowShaded * 10 < quadShaded * 9);
}

TEST_CASE("aligned pass: one device keeps its row tables between draws (sprites, full-screen passes, chunks)",
          "[draw][aligned]") {
    // The renderer keeps a chunk's setups and tables between draws and fills them anew: a draw of
    // fewer triangles or taps after one of more must read none of the earlier draw's. One device
    // per profile draws random full-screen passes and sprite draws in turn, some of more triangles
    // than a chunk (1024), each against a fresh quad-path device.
    std::mt19937 rng(20261129);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    for (const ps11::Precision precision : {ps11::Precision::Fx8, ps11::Precision::Float, ps11::Precision::Ideal}) {
        DeviceOptions rowOpt;
        rowOpt.precision = precision;
        rowOpt.software.threads = 2;
        Device rowDev(rowOpt);
        for (int i = 0; i < 24; ++i) {
            const int kind = uni(0, 2);  // 0: a full-screen pass, 1: a few sprites, 2: more than a chunk of them
            Case c = kind == 0 ? randomCase(rng) : spriteCase(rng, kind == 1 ? uni(1, 6) : uni(520, 700), uni(0, 1) == 1);
            if (kind == 0 && c.program.rfind("ps_1_4", 0) == 0) continue;  // the 1.4-class card: another device
            DeviceOptions quadOpt = rowOpt;
            quadOpt.software.alignedPasses = false;
            Device quadDev(quadOpt);
            DrawStats qs, rs;
            INFO("precision " << int(precision) << ", draw " << i << ": " << c.verts.size() / 3 << " triangles, "
                              << c.w << "x" << c.h << ", program:\n"
                              << c.program);
            const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
            REQUIRE(drawCase(rowDev, c, rs) == expected);
            // Every triangle took the row path (a chunk whose tables pass the column budget: in parts).
            if (kind != 0) CHECK(rs.pixelsRowPath == rs.pixelsCovered);
        }
    }
}

TEST_CASE("aligned pass: triangles of one mapping join on a row only where their runs meet", "[draw][aligned]") {
    // Every triangle maps pixels to texels by the same planes (u = x / 64, v = y / 32, exact in
    // binary), so consecutive triangles pass joinRow's attribute test; added ONE/ONE, any pixel
    // of a run joined across a gap or over an overlap (the same triangle twice in a row) would be
    // drawn the wrong number of times. Against the quad path, in fx8 and ideal.
    std::mt19937 rng(20261129);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    // Cases 12 and up give each vertex an rhw of 0.5, 1 or 2 and its coordinates divided by it:
    // every triangle's planes of attr·rhw are still u = x / 64, v = y / 32 exactly, but their rhw
    // planes differ. Every third case fogs with each vertex's own fog factor, every third after
    // it tests depth with each vertex's own z: those planes differ between triangles too, and a
    // run must not join across them.
    for (int i = 0; i < 24; ++i) {
        const bool perspective = i >= 12;
        Case c = randomCase(rng);
        c.fog = i % 3 == 1, c.depth = i % 3 == 2;
        c.zFunc = D3DCMP_LESSEQUAL, c.zWrite = true, c.zClear = 1.0f;
        c.w = 64, c.h = 32;
        c.rtInit.assign(size_t(c.w) * c.h * 4, 0);
        for (uint8_t& b : c.rtInit) b = uint8_t(uni(0, 40));
        for (Case::Tex& t : c.tex) {
            t.w = 16, t.h = 8, t.format = D3DFMT_A8R8G8B8, t.bound = true;
            t.filter = i % 2 ? D3DTEXF_LINEAR : D3DTEXF_POINT;
            t.bytes.resize(size_t(t.w) * t.h * 4);
            for (uint8_t& b : t.bytes) b = uint8_t(uni(0, 60));
        }
        c.program = "ps_1_1\ntex t0\nmov r0, t0\n";
        c.blend = 1, c.alphaTest = false, c.writeMask = 0xf, c.scissor = false;
        c.verts.clear();
        auto vertex = [&](int x, int y) {
            const float rhw = perspective ? std::array<float, 3>{0.5f, 1.0f, 2.0f}[size_t(uni(0, 2))] : 1.0f;
            Vtx v{float(x), float(y), 0.5f, rhw, 0xffffffff, 0xff000000u, {}};
            for (auto& uv : v.uv) uv[0] = float(x) / 64.0f / rhw, uv[1] = float(y) / 32.0f / rhw;
            if (c.fog) v.specular = DWORD(uni(0, 255)) << 24;
            if (c.depth) v.z = float(uni(0, 100)) / 100.0f;
            return v;
        };
        for (int t = 0; (perspective || c.fog || c.depth) && t < 20; ++t) {
            // Rectangles split on a diagonal, each corner its own rhw (or fog factor, or z): the
            // halves' attr·rhw planes are equal and their runs meet on every row, but the rows
            // must not join where their rhw (fog, z) planes differ.
            const int x0 = uni(-8, 60), y0 = uni(-8, 30), x1 = x0 + uni(2, 40), y1 = y0 + uni(2, 20);
            const Vtx a = vertex(x0, y0), b = vertex(x1, y0), d = vertex(x1, y1), e = vertex(x0, y1);
            // Either diagonal, either half first (the halves' v planes have dx +0 or −0 by the
            // order, and runs join only where those bits agree too).
            switch (uni(0, 3)) {
                case 0:
                    c.verts.insert(c.verts.end(), {a, b, d, a, d, e});
                    break;
                case 1:
                    c.verts.insert(c.verts.end(), {a, d, e, a, b, d});
                    break;
                case 2:
                    c.verts.insert(c.verts.end(), {a, b, e, b, d, e});
                    break;
                default:
                    c.verts.insert(c.verts.end(), {b, d, e, a, b, e});
                    break;
            }
        }
        for (int t = 0; !perspective && t < 60; ++t) {
            // Wide triangles (tables over the whole target: equal for all of them), some twice.
            const Vtx a = vertex(uni(-8, 72), uni(-8, 40)), b = vertex(uni(-8, 72), uni(-8, 40)),
                      d = vertex(uni(-8, 72), uni(-8, 40));
            for (int k = uni(0, 3) == 0 ? 2 : 1; k > 0; --k) c.verts.insert(c.verts.end(), {a, b, d});
        }
        c.depthVerts = c.verts;
        for (Vtx& v : c.depthVerts) v.z = float(uni(0, 100)) / 100.0f;
        for (const ps11::Precision precision : {ps11::Precision::Fx8, ps11::Precision::Ideal}) {
            DeviceOptions quadOpt, rowOpt;
            quadOpt.software.alignedPasses = false;
            quadOpt.precision = rowOpt.precision = precision;
            rowOpt.software.skipTiles = false;
            Device quadDev(quadOpt), rowDev(rowOpt);
            DrawStats qs, rs;
            INFO("case " << i << ", precision " << int(precision));
            const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
            REQUIRE(drawCase(rowDev, c, rs) == expected);
            CHECK(rs.pixelsShaded == rs.pixelsCovered);  // the row path drew them
        }
    }
}

TEST_CASE("aligned pass: a 4:1 reduction's pair sums straight from the texel row equal the staged combine",
          "[draw][aligned]") {
    // pairSums4 against the rule (channel sums of texels 4j, 4j + 1 and 4j + 2, 4j + 3, planes
    // r g b a) and against deinterleave + combine (step 4, weight ½, phases 0 and 2), for lengths
    // around whole groups of 16 and random bytes; nothing past texel 4n is read (the row ends
    // there, in a buffer of its own).
    const ps11::ScopedSimdLevel level(ps11::SimdLevel::Avx2);
    const AlignedKernels* k = alignedKernels(level.level());
    if (!k) return;
    std::mt19937 rng(20261129);
    for (const int n : {1, 5, 15, 16, 17, 31, 32, 48, 63, 64, 100, 480}) {
        std::vector<uint8_t> row(size_t(16) * size_t(n));
        for (uint8_t& b : row) b = uint8_t(rng());
        const size_t stride = size_t((n + kHRowPad + 15) & ~15);
        std::vector<uint16_t> even(stride * 4), odd(stride * 4);
        uint16_t* const e[4] = {&even[0], &even[stride], &even[2 * stride], &even[3 * stride]};
        uint16_t* const o[4] = {&odd[0], &odd[stride], &odd[2 * stride], &odd[3 * stride]};
        k->pairSums4(row.data(), n, e, o);
        // The staged way: 4n texels deinterleaved (with the padding combine reads), then combined.
        const size_t sstride = size_t(4 * n + kStagePad + 16);
        std::vector<uint16_t> staged(sstride * 4);
        uint16_t* const s[4] = {&staged[0], &staged[sstride], &staged[2 * sstride], &staged[3 * sstride]};
        k->deinterleave(row.data(), 4 * n, s);
        std::vector<uint16_t> ce(stride * 4), co(stride * 4);
        uint16_t* const cev[4] = {&ce[0], &ce[stride], &ce[2 * stride], &ce[3 * stride]};
        uint16_t* const cov[4] = {&co[0], &co[stride], &co[2 * stride], &co[3 * stride]};
        const uint16_t* const s0[4] = {s[0], s[1], s[2], s[3]};
        const uint16_t* const s2[4] = {s[0] + 2, s[1] + 2, s[2] + 2, s[3] + 2};
        k->combine(s0, n, 4, 128, cev);
        k->combine(s2, n, 4, 128, cov);
        for (int c = 0; c < 4; ++c)
            for (int j = 0; j < n; ++j) {
                const int b = ps11::kUnorm8Byte[c];
                INFO("n " << n << ", channel " << c << ", element " << j);
                REQUIRE(e[c][j] == row[size_t(16 * j + b)] + row[size_t(16 * j + 4 + b)]);
                REQUIRE(o[c][j] == row[size_t(16 * j + 8 + b)] + row[size_t(16 * j + 12 + b)]);
                REQUIRE(e[c][j] == cev[c][j]);
                REQUIRE(o[c][j] == cov[c][j]);
            }
    }
}

TEST_CASE("aligned pass: 4:1 reductions by weight-½ taps (a glow's sources) equal the quad path", "[draw][aligned]") {
    // The glow's first pass: four bilinear taps one texel either side of each 4x4 block's centre
    // (H rows of pair sums from the texel row, both phases at once), random texels, a target of
    // several groups of 16 and a ragged end, in fx8, plain and ONE/ONE.
    std::mt19937 rng(20261130);
    for (int i = 0; i < 8; ++i) {
        Case c = randomCase(rng);
        c.w = UINT(std::uniform_int_distribution<int>(20, 90)(rng)), c.h = 6;
        c.rtInit.resize(size_t(c.w) * c.h * 4);
        for (uint8_t& b : c.rtInit) b = uint8_t(rng());
        for (Case::Tex& t : c.tex) {
            t.w = 4 * c.w, t.h = 4 * c.h, t.format = D3DFMT_A8R8G8B8, t.bound = true;
            t.filter = D3DTEXF_LINEAR, t.addressU = t.addressV = D3DTADDRESS_CLAMP;
            t.bytes.resize(size_t(t.w) * t.h * 4);
            for (uint8_t& b : t.bytes) b = uint8_t(rng());
        }
        c.oneTexture = true;
        c.program = "ps_1_1\ndef c0, 0.25, 0.25, 0.25, 0.25\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\n"
                    "mad r0, t1, c0, r0\nmad r0, t2, c0, r0\nmad r0, t3, c0, r0\n";
        c.blend = DWORD(i % 2), c.alphaTest = false, c.writeMask = 0xf, c.scissor = false;
        c.verts.clear();
        const float xs[4] = {-0.5f, float(c.w) - 0.5f, float(c.w) - 0.5f, -0.5f};
        const float ys[4] = {-0.5f, -0.5f, float(c.h) - 0.5f, float(c.h) - 0.5f};
        const float off[4][2] = {{-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
        for (int k : {0, 1, 2, 0, 2, 3}) {
            Vtx v{xs[k], ys[k], 0.5f, 1.0f, 0xffffffff, 0xff000000u, {}};
            for (int s = 0; s < 4; ++s) {
                v.uv[s][0] = ((k == 1 || k == 2) ? 1.0f : 0.0f) + off[s][0] / float(4 * c.w);
                v.uv[s][1] = (k >= 2 ? 1.0f : 0.0f) + off[s][1] / float(4 * c.h);
            }
            c.verts.push_back(v);
        }
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        rowOpt.software.skipTiles = false;
        quadOpt.software.threads = rowOpt.software.threads = 1 + (i & 1);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h);
        testutil::forEachSimdLevel([&](ps11::SimdLevel) {
            Device rowDev(rowOpt);
            DrawStats rs;
            REQUIRE(drawCase(rowDev, c, rs) == expected);
            CHECK(rs.pixelsShaded == rs.pixelsCovered);
        });
    }
}

TEST_CASE("aligned pass: chains of products that pass the range's top are clamped after each op", "[draw][aligned]") {
    // The weighted blur's mul and three mads (one kernel for the chain: exec::FastKernels::chain)
    // with weights whose sum passes 1, over bright random texels: the running sum meets hi and
    // is clamped after each op, as the quad path's per-op arithmetic does. POINT taps at whole
    // texels (direct runs) and bilinear ones between texels.
    std::mt19937 rng(20261131);
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    for (int i = 0; i < 8; ++i) {
        Case c = randomCase(rng);
        c.w = 70, c.h = 5;
        c.rtInit.assign(size_t(c.w) * c.h * 4, 0);
        for (Case::Tex& t : c.tex) {
            t.w = c.w, t.h = c.h, t.format = D3DFMT_A8R8G8B8, t.bound = true;
            t.filter = i % 2 ? D3DTEXF_LINEAR : D3DTEXF_POINT;
            t.addressU = t.addressV = D3DTADDRESS_CLAMP;
            t.bytes.resize(size_t(t.w) * t.h * 4);
            for (uint8_t& b : t.bytes) b = uint8_t(std::uniform_int_distribution<int>(100, 255)(rng));
        }
        c.oneTexture = true;
        // (The sub after the chain shows its clamp: the store would clamp an unclamped sum anyway.)
        c.program = "ps_1_1\ndef c4, 0.5, 0.5, 0.5, 0.5\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\n"
                    "mad r0, t1, c1, r0\nmad r0, t2, c2, r0\nmad r0, t3, c3, r0\nsub r0, r0, c4\n";
        for (auto& k : c.consts)
            for (float& v : k) v = real(0.2f, 1.0f);
        c.blend = 0, c.alphaTest = false, c.writeMask = 0xf, c.scissor = false, c.fog = false, c.depth = false;
        c.verts.clear();
        const float xs[4] = {-0.5f, float(c.w) - 0.5f, float(c.w) - 0.5f, -0.5f};
        const float ys[4] = {-0.5f, -0.5f, float(c.h) - 0.5f, float(c.h) - 0.5f};
        const float shift = i % 2 ? 0.5f : 1.0f;
        for (int k : {0, 1, 2, 0, 2, 3}) {
            Vtx v{xs[k], ys[k], 0.5f, 1.0f, 0xffffffff, 0xff000000u, {}};
            for (int s = 0; s < 4; ++s) {
                v.uv[s][0] = ((k == 1 || k == 2) ? 1.0f : 0.0f) + (float(s) - 1.5f) * shift / float(c.w);
                v.uv[s][1] = k >= 2 ? 1.0f : 0.0f;
            }
            c.verts.push_back(v);
        }
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        rowOpt.software.skipTiles = false;
        Device quadDev(quadOpt), rowDev(rowOpt);
        DrawStats qs, rs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i);
        REQUIRE(drawCase(rowDev, c, rs) == expected);
        CHECK(rs.pixelsShaded == rs.pixelsCovered);
        // The clamp mattered: the sum reached 1, less 0.5 (the byte 127 or 128).
        CHECK(std::count_if(expected.begin(), expected.end(), [](uint8_t b) { return b == 127 || b == 128; }) > 100);
    }
}
