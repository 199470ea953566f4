// Random draws for the row-path tests (test_aligned_pass.cpp, test_aligned_rows.cpp, test_aligned_kernels.cpp,
// test_tile_skip.cpp): one Case — target, four textures with their sampler states, program,
// constants, vertices, blending, alpha test, write mask, scissor, fog and depth — drawn by a device,
// and the checks that compare a row-path device with the quad path.
#pragma once

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "emu/device.h"
#include "ps11/hardware.h"
#include "ps11/precision.h"

namespace alignedcases {

using namespace emu;

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

inline uint32_t texelBytes(D3DFORMAT f) {
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
        // Above 1: a volume texture of this depth (one level; `bytes` its slices in order, the
        // W address as U's).
        UINT d = 1;
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
    // Projected reads: each stage's D3DTSS_TEXTURETRANSFORMFLAGS, and per vertex of `verts` each
    // set's third and fourth components (r, q). With `rq` the vertices carry four-component
    // coordinates (depthVerts' r, q are 0 and 1).
    std::array<DWORD, 4> transformFlags{};
    std::vector<std::array<std::array<float, 2>, 4>> rq;
    // Each stage's bump matrix (00 01 10 11), luminance scale and offset (texbem, texbeml).
    std::array<std::array<float, 6>, 4> bump{};
};

// A vertex with four-component coordinates (Case::rq).
struct Vtx4 {
    float x, y, z, rhw;
    DWORD diffuse, specular;
    float uvrq[4][4];
};
constexpr DWORD kFvf4 = D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_SPECULAR | D3DFVF_TEX4 | D3DFVF_TEXCOORDSIZE4(0) |
                        D3DFVF_TEXCOORDSIZE4(1) | D3DFVF_TEXCOORDSIZE4(2) | D3DFVF_TEXCOORDSIZE4(3);

// `verts` with four-component coordinates: rq[i] for vertex i, or (0, 1) without rq.
inline std::vector<Vtx4> withRq(const std::vector<Vtx>& verts, const std::vector<std::array<std::array<float, 2>, 4>>* rq) {
    std::vector<Vtx4> out;
    for (size_t i = 0; i < verts.size(); ++i) {
        const Vtx& v = verts[i];
        Vtx4 w{v.x, v.y, v.z, v.rhw, v.diffuse, v.specular, {}};
        for (int s = 0; s < 4; ++s) {
            w.uvrq[s][0] = v.uv[s][0], w.uvrq[s][1] = v.uv[s][1];
            w.uvrq[s][2] = rq ? (*rq)[i][size_t(s)][0] : 0.0f;
            w.uvrq[s][3] = rq ? (*rq)[i][size_t(s)][1] : 1.0f;
        }
        out.push_back(w);
    }
    return out;
}

// Depth and fog on a quarter of the cases each, from their own generator seeded by `rng`.
inline void depthAndFog(std::mt19937& rng, Case& c) {
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
inline void withoutNaNs(std::vector<uint8_t>& bytes, D3DFORMAT f) {
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

// Every texture of case c, every level, without NaNs.
inline void withoutNaNs(Case& c) {
    for (Case::Tex& t : c.tex) {
        withoutNaNs(t.bytes, t.format);
        for (std::vector<uint8_t>& level : t.mips) withoutNaNs(level, t.format);
    }
}

// The two devices of a differential case i: the quad path (row paths off) and the row paths,
// both on one thread or (odd i) two.
inline void quadAndRowOptions(int i, DeviceOptions& quad, DeviceOptions& rows) {
    quad.software.alignedPasses = false;
    quad.software.threads = rows.software.threads = 1 + (i & 1);
}

// A case of a w × h target, A8R8G8B8 or (a quarter of the time) X8R8G8B8, of random bytes.
inline Case randomTarget(std::mt19937& rng, UINT w, UINT h) {
    Case c;
    c.w = w, c.h = h;
    c.rtFormat = std::uniform_int_distribution<int>(0, 3)(rng) ? D3DFMT_A8R8G8B8 : D3DFMT_X8R8G8B8;
    c.rtInit.resize(size_t(c.w) * c.h * 4);
    for (uint8_t& b : c.rtInit) b = uint8_t(rng());
    return c;
}

inline Case randomCase(std::mt19937& rng, bool floatFormats = false) {
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    const UINT w = UINT(uni(1, 300));
    const UINT h = UINT(uni(1, 24));
    Case c = randomTarget(rng, w, h);
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
inline void fullTargetQuad(Case& c) {
    c.verts.clear();
    const float xs[4] = {-0.5f, float(c.w) - 0.5f, float(c.w) - 0.5f, -0.5f};
    const float ys[4] = {-0.5f, -0.5f, float(c.h) - 0.5f, float(c.h) - 0.5f};
    for (int k : {0, 1, 2, 0, 2, 3}) {
        Vtx q{xs[k], ys[k], 0.5f, 1.0f, 0xffffffffu, 0xff000000u, {}};
        for (int s = 0; s < 4; ++s) q.uv[s][0] = (k == 1 || k == 2) ? 1.0f : 0.0f, q.uv[s][1] = k >= 2 ? 1.0f : 0.0f;
        c.verts.push_back(q);
    }
}

inline std::vector<uint8_t> drawCase(Device& dev, const Case& c, DrawStats& stats) {
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
        if (t.d > 1) {
            REQUIRE(dev.CreateVolumeTexture(t.w, t.h, t.d, 1, 0, t.format, D3DPOOL_MANAGED, &tex) == D3D_OK);
            D3DLOCKED_BOX box{};
            REQUIRE(dev.LockBox(tex, 0, &box, nullptr, 0) == D3D_OK);
            const size_t row = size_t(t.w) * texelBytes(t.format);
            REQUIRE(t.bytes.size() == row * t.h * t.d);
            for (UINT z = 0; z < t.d; ++z)
                for (UINT y = 0; y < t.h; ++y)
                    std::memcpy(static_cast<uint8_t*>(box.pBits) + z * box.SlicePitch + y * box.RowPitch,
                                &t.bytes[(size_t(z) * t.h + y) * row], row);
            REQUIRE(dev.UnlockBox(tex, 0) == D3D_OK);
            REQUIRE(dev.SetSamplerState(s, D3DSAMP_ADDRESSW, t.addressU) == D3D_OK);
        }
        if (t.d <= 1) REQUIRE(dev.CreateTexture(t.w, t.h, UINT(1 + t.mips.size()), 0, t.format, D3DPOOL_MANAGED, &tex) == D3D_OK);
        for (UINT level = 0; t.d <= 1 && level <= t.mips.size(); ++level) {
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
        REQUIRE(dev.SetTextureStageState(s, D3DTSS_TEXTURETRANSFORMFLAGS, c.transformFlags[s]) == D3D_OK);
        const D3DTEXTURESTAGESTATETYPE bumpStates[6] = {D3DTSS_BUMPENVMAT00, D3DTSS_BUMPENVMAT01,
                                                        D3DTSS_BUMPENVMAT10, D3DTSS_BUMPENVMAT11,
                                                        D3DTSS_BUMPENVLSCALE, D3DTSS_BUMPENVLOFFSET};
        for (int k = 0; k < 6; ++k) {
            DWORD bits = 0;
            std::memcpy(&bits, &c.bump[s][size_t(k)], 4);
            REQUIRE(dev.SetTextureStageState(s, bumpStates[k], bits) == D3D_OK);
        }
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
    const bool four = !c.rq.empty();
    REQUIRE((!four || c.rq.size() == c.verts.size()));
    auto draw = [&](const std::vector<Vtx>& verts, bool withCoords) {
        if (!four)
            return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(verts.size() / 3), verts.data(), sizeof(Vtx));
        const std::vector<Vtx4> v4 = withRq(verts, withCoords ? &c.rq : nullptr);
        return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(v4.size() / 3), v4.data(), sizeof(Vtx4));
    };
    REQUIRE(dev.SetFVF(four ? kFvf4 : kFvf) == D3D_OK);
    REQUIRE(draw(c.verts, true) == D3D_OK);
    stats = dev.lastDrawStats();
    if (c.depth) {
        // The second draw's pixels pass or fail against what the first wrote.
        REQUIRE(draw(c.depthVerts, false) == D3D_OK);
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
inline void requireRowsEqual(const DeviceOptions& rowOpt, const Case& c, const std::vector<uint8_t>& expected,
                      const DrawStats& qs, int& cases, int& rows) {
    Device rowDev(rowOpt);
    DrawStats rs;
    REQUIRE(drawCase(rowDev, c, rs) == expected);
    CHECK(rs.pixelsCovered == qs.pixelsCovered);
    CHECK(rs.pixelsWritten == qs.pixelsWritten);
    if (qs.pixelsCovered == 0) return;
    ++cases;
    if (rs.pixelsRowPath == rs.pixelsCovered && rs.pixelsShaded <= rs.pixelsCovered) ++rows;
}

// The float row path's profiles for case i: float or ideal (overriding the class's profile:
// float weights), and every eighth case the D3D9 class in its own float profile, whose filter
// weights are 8-bit (the row path's weights8).
inline void floatProfile(int i, bool ideal, DeviceOptions& a, DeviceOptions& b) {
    a.precision = b.precision = ideal ? ps11::Precision::Ideal : ps11::Precision::Float;
    if (i % 8 == 1) {
        a.hardware = b.hardware = ps11::findHardware("d3d9");
        a.precision = b.precision = std::nullopt;
    }
}

// The same for case c: its ps_1_4 programs on the 1.4-class card.
inline void floatProfile(const Case& c, int i, bool ideal, DeviceOptions& a, DeviceOptions& b) {
    if (c.program.rfind("ps_1_4", 0) == 0) a.hardware = b.hardware = &ps11::defaultHardware(4);
    floatProfile(i, ideal, a, b);
}

inline std::string profileName(const DeviceOptions& o) {
    if (o.precision) return ps11::precisionName(*o.precision);
    return o.hardware ? "the " + std::string(o.hardware->name) + " class's own profile" : "the default class's";
}

// Tile skipping (emu/tile_skip.h) changes no byte and no covered pixel: the case drawn by a device
// like `rowOpt` with skipping on must give the quad path's bytes.
inline void requireSkippingEqual(const DeviceOptions& rowOpt, const Case& c, const std::vector<uint8_t>& expected,
                          const DrawStats& qs) {
    DeviceOptions skipOpt = rowOpt;
    skipOpt.software.skipTiles = true;
    Device skipDev(skipOpt);
    DrawStats ks;
    REQUIRE(drawCase(skipDev, c, ks) == expected);
    CHECK(ks.pixelsCovered == qs.pixelsCovered);
}

// Both devices as the radeon8500 class: fx12 with MaxValue 8 (ps11/hardware.h).
inline void radeon8500(DeviceOptions& a, DeviceOptions& b) {
    a.hardware = b.hardware = ps11::findHardware("radeon8500");
    REQUIRE(a.hardware);
    a.precision = b.precision = std::nullopt;
}

// The fx profiles of case c on both devices: ps_1_4 programs on the 1.4-class card in fx8, and
// with `radeon` the radeon8500 class in its own fx12 (MaxValue 8: the generic executor's
// pre-sampled runs) instead.
inline void fxProfile(const Case& c, bool radeon, DeviceOptions& a, DeviceOptions& b) {
    if (c.program.rfind("ps_1_4", 0) == 0) {
        a.hardware = b.hardware = &ps11::defaultHardware(4);
        a.precision = b.precision = ps11::Precision::Fx8;
    }
    if (radeon) radeon8500(a, b);
}

}  // namespace alignedcases
