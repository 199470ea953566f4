// Tile skipping (emu/tile_skip.h) against every pixel shaded: random draws over partly constant
// textures, 1:1 copies stored straight from the texel row, tiles over different constants of one
// texture, programs that copy whatever they read on draws not decided per tile.
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
#include "emu/fullscreen.h"
#include "ps11/assembler.h"
#include "ps11/validator.h"
#include "aligned_cases.h"
#include "simd_levels.h"

using namespace emu;

using namespace alignedcases;

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
        quadAndRowOptions(i, quadOpt, rowOpt);
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
        quadAndRowOptions(i, quadOpt, rowOpt);
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

TEST_CASE("tile skipping: taps of one texture far apart are each bounded by their own texels",
          "[draw][aligned][skip]") {
    // Stages that read one texture with the same addressing take the union of their footprints
    // (TileSkipper::decide): a blur's taps, a texel apart. Here the taps are up to 120 texels
    // apart over a zero texture with a few bright blocks, so a tile's first tap may read only
    // zeros while another reaches a block: a tile bounded by one tap's texels alone would be
    // filled or skipped wrongly. Clamp, border and wrap; point and linear; plain and ONE/ONE;
    // fx8 and the radeon8500 class. Bytes must equal skipping off; tiles must be filled or
    // skipped and shaded.
    std::mt19937 rng(20261202);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    uint64_t saved = 0, shaded = 0;
    for (int i = 0; i < 24; ++i) {
        Case c = randomCase(rng);
        c.w = 512, c.h = 64;
        c.oneTexture = true;
        c.rtFormat = D3DFMT_A8R8G8B8;
        c.rtInit.assign(size_t(c.w) * c.h * 4, 0);
        c.tex.resize(4);
        const DWORD address[] = {D3DTADDRESS_CLAMP, D3DTADDRESS_BORDER, D3DTADDRESS_WRAP};
        for (size_t s = 0; s < c.tex.size(); ++s) {
            Case::Tex& t = c.tex[s];
            t = Case::Tex{};
            t.w = c.w, t.h = c.h;
            t.format = D3DFMT_A8R8G8B8;
            t.filter = i & 1 ? D3DTEXF_LINEAR : D3DTEXF_POINT;
            t.addressU = t.addressV = address[(i / 2) % 3];
            t.border = 0;
            t.bound = s < 2;
            t.bytes.assign(size_t(t.w) * t.h * 4, 0);  // (stage 1 reads stage 0's texture)
            if (s == 0) {
                for (int b = 0; b < 3; ++b) {
                    const int bx = uni(0, int(t.w) - 8), by = uni(0, int(t.h) - 8);
                    for (int y = by; y < by + 8; ++y)
                        for (int x = bx; x < bx + 8; ++x)
                            for (int k = 0; k < 4; ++k) t.bytes[(size_t(y) * t.w + size_t(x)) * 4 + size_t(k)] = 200;
                }
            }
        }
        c.program = "ps_1_1\ntex t0\ntex t1\nadd r0, t0, t1\n";
        fullTargetQuad(c);
        // t1 shifted by up to ±120 texels across and ±20 down.
        const float du = float(uni(-120, 120)) / float(c.w), dv = float(uni(-20, 20)) / float(c.h);
        for (Vtx& v : c.verts) v.uv[1][0] += du, v.uv[1][1] += dv;
        c.blend = DWORD(i >> 2 & 1);  // plain, ONE/ONE
        c.alphaTest = false, c.writeMask = 0xf, c.scissor = false, c.fog = false, c.depth = false;
        DeviceOptions rowOpt, other;
        rowOpt.software.threads = 1 + (i & 1);
        rowOpt.software.skipTiles = false;
        rowOpt.software.timeTiles = false;
        if (i >= 12) radeon8500(rowOpt, other);
        DeviceOptions skipOpt = rowOpt;
        skipOpt.software.skipTiles = true;
        Device rowDev(rowOpt), skipDev(skipOpt);
        DrawStats rs, ks;
        INFO("case " << i << ": shift " << du * float(c.w) << ", " << dv * float(c.h) << " texels");
        const std::vector<uint8_t> expected = drawCase(rowDev, c, rs);
        REQUIRE(drawCase(skipDev, c, ks) == expected);
        saved += ks.tilesFilled + ks.tilesSkipped + ks.tilesCopied;
        shaded += ks.tilesShaded;
    }
    INFO("tiles saved " << saved << ", shaded " << shaded);
    CHECK(saved > 100);
    CHECK(shaded > 20);
}

TEST_CASE("tile skipping: filled runs stored directly equal every lane stored, plain and ONE/ONE, fx8 and fx12",
          "[draw][aligned][skip]") {
    // A program of constants (and a colour constant on the quad) fills every tile: where the draw
    // stores its runs directly, the fill's word is made once and written or added across the
    // run. fx12's ONE/ONE adds the 12-bit value and rounds the sum once, so a constant between
    // two bytes (grid not a multiple of 16) must not be added as a byte. Bytes must equal
    // skipping off and the quad path; tiles must be filled.
    std::mt19937 rng(20261202);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    const char* const programs[] = {"ps_1_1\nmov r0, c0\n", "ps_1_1\nadd r0, v0, c0\n"};
    for (int i = 0; i < 32; ++i) {
        Case c = randomTarget(rng, 200, 40);
        c.tex.assign(4, Case::Tex{});
        for (Case::Tex& t : c.tex) t.bound = false, t.bytes.assign(4, 0);
        c.program = programs[i % 2];
        fullTargetQuad(c);
        const DWORD diffuse = 0xff000000u | uint32_t(uni(0, 0xffffff));
        for (Vtx& v : c.verts) v.diffuse = diffuse;
        for (int k = 0; k < 4; ++k) c.consts[0][k] = float(uni(0, 40)) / 4080.0f;  // often between two bytes in fx12
        c.blend = DWORD(i / 2 % 2);                                                // plain, ONE/ONE
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = false;
        rowOpt.software.timeTiles = false;
        if (i >= 16) radeon8500(quadOpt, rowOpt);
        DeviceOptions skipOpt = rowOpt;
        skipOpt.software.skipTiles = true;
        Device quadDev(quadOpt), rowDev(rowOpt), skipDev(skipOpt);
        DrawStats qs, rs, ks;
        INFO("case " << i << ", blend " << c.blend << ", program:\n" << c.program);
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        REQUIRE(drawCase(rowDev, c, rs) == expected);
        REQUIRE(drawCase(skipDev, c, ks) == expected);
        CHECK(ks.tilesFilled > 0);
    }
}

TEST_CASE("tile skipping: a program that copies one tap whatever it reads is drawn as that copy when not decided per tile",
          "[draw][aligned][skip]") {
    // TileSkipper::anyData: `mul r0, t0, c0` with c0 = (1, 1, 1, 0) and `mov r0, t0` copy their tap
    // for every texel, so a draw that is not decided tile by tile — every draw with skipping off;
    // with it on (untimed), the three after a first decided draw whose copies of one filtered tap
    // saved nothing — runs no program: its windows copy the tap. Each of six draws of one shader, over new texels each
    // time, 1:1 or magnified 4×, plain or ONE/ONE, in fx8, float and ideal, with skipping on and
    // off, must equal the quad path's bytes. Those draws must have shaded no pixel in fx8 and
    // ideal and counted no tile; a program that is no copy (c1) must shade.
    std::mt19937 rng(1201);
    const char* const programs[] = {"ps_1_1\ntex t0\nmul r0, t0, c0\n", "ps_1_1\ntex t0\nmov r0, t0\n",
                                    "ps_1_1\ntex t0\nmul r0, t0, c1\n"};
    const UINT w = 320, h = 240;
    uint64_t copiedDraws = 0;
    for (int i = 0; i < 18; ++i) {
        const int profile = i % 3;  // fx8, float, ideal
        const UINT tw = i % 2 ? w / 4 : w, th = i % 2 ? h / 4 : h;  // 1:1, or magnified 4x (bilinear)
        const size_t program = size_t(i / 3) % std::size(programs);
        const bool add = (i / 6) % 2 == 1;
        DeviceOptions on, off, quads;
        on.software.timeTiles = off.software.timeTiles = false;
        off.software.skipTiles = false;
        quads.software.alignedPasses = false;
        if (profile)
            on.precision = off.precision = quads.precision =
                profile == 1 ? ps11::Precision::Float : ps11::Precision::Ideal;
        Device skipDev(on), plainDev(off), quadDev(quads);
        Device* devs[3] = {&skipDev, &plainDev, &quadDev};
        Handle rt[3], tex[3], ps[3];
        const float c0[8] = {1, 1, 1, 0, 0.5f, 0.25f, 1, 1};  // c1: not a copy
        for (int d = 0; d < 3; ++d) {
            Device& dev = *devs[d];
            REQUIRE(dev.CreateRenderTarget(w, h, D3DFMT_A8R8G8B8, 1, &rt[d]) == D3D_OK);
            REQUIRE(dev.SetRenderTarget(0, rt[d]) == D3D_OK);
            REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x20406080u, 1.0f, 0) == D3D_OK);
            REQUIRE(dev.CreateTexture(tw, th, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex[d]) == D3D_OK);
            REQUIRE(dev.CreatePixelShaderFromText(programs[program], &ps[d]) == D3D_OK);
            REQUIRE(dev.SetPixelShader(ps[d]) == D3D_OK);
            REQUIRE(dev.SetPixelShaderConstantF(0, c0, 2) == D3D_OK);
            REQUIRE(dev.SetTexture(0, tex[d]) == D3D_OK);
            for (D3DSAMPLERSTATETYPE f : {D3DSAMP_MINFILTER, D3DSAMP_MAGFILTER})
                REQUIRE(dev.SetSamplerState(0, f, i % 2 ? D3DTEXF_LINEAR : D3DTEXF_POINT) == D3D_OK);
            REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, add ? 1 : 0) == D3D_OK);
            REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE) == D3D_OK);
            REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE) == D3D_OK);
        }
        for (int draw = 0; draw < 6; ++draw) {
            std::vector<uint8_t> texels(size_t(tw) * th * 4);
            for (uint8_t& b : texels) b = uint8_t(rng() % 3 ? rng() % 64 : rng());
            std::vector<uint8_t> out[3];
            DrawStats stats[3];
            for (int d = 0; d < 3; ++d) {
                Device& dev = *devs[d];
                D3DLOCKED_RECT lr;
                REQUIRE(dev.LockRect(tex[d], 0, &lr, nullptr, 0) == D3D_OK);
                for (UINT y = 0; y < th; ++y)
                    std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &texels[size_t(y) * tw * 4], tw * 4);
                REQUIRE(dev.UnlockRect(tex[d], 0) == D3D_OK);
                REQUIRE(drawFullscreenQuad(dev) == D3D_OK);
                stats[d] = dev.lastDrawStats();
                REQUIRE(dev.LockRect(rt[d], &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
                for (UINT y = 0; y < h; ++y) {
                    const uint8_t* row = static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch;
                    out[d].insert(out[d].end(), row, row + w * 4);
                }
                REQUIRE(dev.UnlockRect(rt[d]) == D3D_OK);
            }
            INFO("case " << i << " (" << programs[program] << "), " << tw << "x" << th << ", profile " << profile
                         << (add ? ", ONE/ONE" : "") << ", draw " << draw);
            REQUIRE(out[0] == out[2]);
            REQUIRE(out[1] == out[2]);
            // (Not in the float profile of this class: its registers clamp at MaxValue 1 and the
            // evaluator's float lookups are widened past their bounds, so a lookup that may reach 1
            // is not proven to pass the clamp unchanged: no copy whatever the data; those draws shade.)
            if (profile == 1) continue;
            const bool copy = program != 2;
            for (int d = 0; d < 2; ++d) {
                const DrawStats& s = stats[d];
                const uint64_t tiles = s.tilesShaded + s.tilesFilled + s.tilesCopied + s.tilesSkipped;
                INFO((d ? "skipping off" : "skipping on"));
                if (d == 1) CHECK(tiles == 0);
                if (tiles) continue;  // (skipping on: decided per tile, as the draw's history said)
                CHECK(s.pixelsCovered == uint64_t(w) * h);
                CHECK((s.pixelsShaded == 0) == copy);
                copiedDraws += copy && s.pixelsShaded == 0 ? (d ? 1 : 1000) : 0;
            }
        }
    }
    // Copied without a program with skipping off, and on draws that waited with it on (the
    // magnified fx8 copies, whose first decided draw saved nothing).
    CHECK(copiedDraws % 1000 > 0);
    CHECK(copiedDraws / 1000 > 0);
}

TEST_CASE("tile skipping: a magnified tap copied as words equals the quad path at every SIMD level",
          "[draw][aligned][skip]") {
    // The glare composites' pass: `mul r0, t0, c0` with c0 = (1, 1, 1, 0) or `mov r0, t0`, a
    // texture magnified 2x, 2.5x, 3x, 4x or 8x (bilinear, or point), added ONE/ONE or stored
    // plainly into an A8R8G8B8 or X8R8G8B8 target of a width that ends groups anywhere, with
    // skipping off: every window copies its tap, and the fx8 copies of ready runs go from the H
    // rows to the target as words (copyTexels' blended route). Each must equal the quad path's
    // bytes at every SIMD level, and shade no pixel.
    std::mt19937 rng(20261203);
    const char* const programs[] = {"ps_1_1\ntex t0\nmul r0, t0, c0\n", "ps_1_1\ntex t0\nmov r0, t0\n"};
    int i = 0;
    for (const double scale : {2.0, 2.5, 3.0, 4.0, 8.0})
        for (const bool add : {false, true}) {
            const UINT w = UINT(97 + rng() % 200), h = UINT(9 + rng() % 20);
            const UINT tw = std::max(2u, UINT(w / scale)), th = std::max(2u, UINT(h / scale));
            const D3DFORMAT format = i % 3 == 2 ? D3DFMT_X8R8G8B8 : D3DFMT_A8R8G8B8;
            const char* const program = programs[i % 2];
            const bool linear = i % 4 != 3;
            ++i;
            std::vector<uint8_t> texels(size_t(tw) * th * 4), init(size_t(w) * h * 4);
            for (uint8_t& b : texels) b = uint8_t(rng() % 3 ? rng() % 64 : rng());
            for (uint8_t& b : init) b = uint8_t(rng());
            auto draw = [&](const DeviceOptions& options, DrawStats& stats) {
                Device dev(options);
                Handle rt{}, tex{}, ps{};
                REQUIRE(dev.CreateRenderTarget(w, h, format, 1, &rt) == D3D_OK);
                REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
                D3DLOCKED_RECT lr;
                REQUIRE(dev.LockRect(rt, &lr, nullptr, 0) == D3D_OK);
                for (UINT y = 0; y < h; ++y)
                    std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &init[size_t(y) * w * 4], w * 4);
                REQUIRE(dev.UnlockRect(rt) == D3D_OK);
                REQUIRE(dev.CreateTexture(tw, th, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
                REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
                for (UINT y = 0; y < th; ++y)
                    std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, &texels[size_t(y) * tw * 4], tw * 4);
                REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
                REQUIRE(dev.CreatePixelShaderFromText(program, &ps) == D3D_OK);
                REQUIRE(dev.SetPixelShader(ps) == D3D_OK);
                const float c0[4] = {1, 1, 1, 0};
                REQUIRE(dev.SetPixelShaderConstantF(0, c0, 1) == D3D_OK);
                REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
                for (D3DSAMPLERSTATETYPE f : {D3DSAMP_MINFILTER, D3DSAMP_MAGFILTER})
                    REQUIRE(dev.SetSamplerState(0, f, linear ? D3DTEXF_LINEAR : D3DTEXF_POINT) == D3D_OK);
                REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, add ? 1 : 0) == D3D_OK);
                REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE) == D3D_OK);
                REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE) == D3D_OK);
                REQUIRE(drawFullscreenQuad(dev) == D3D_OK);
                stats = dev.lastDrawStats();
                std::vector<uint8_t> out;
                REQUIRE(dev.LockRect(rt, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
                for (UINT y = 0; y < h; ++y) {
                    const uint8_t* row = static_cast<const uint8_t*>(lr.pBits) + y * lr.Pitch;
                    out.insert(out.end(), row, row + w * 4);
                }
                REQUIRE(dev.UnlockRect(rt) == D3D_OK);
                return out;
            };
            INFO(program << w << "x" << h << " from " << tw << "x" << th << (linear ? ", linear" : ", point")
                         << (add ? ", ONE/ONE" : "") << (format == D3DFMT_X8R8G8B8 ? ", X8R8G8B8" : ""));
            DeviceOptions quads, rows;
            quads.software.alignedPasses = false;
            rows.software.skipTiles = false;
            DrawStats qs;
            const std::vector<uint8_t> expected = draw(quads, qs);
            testutil::forEachSimdLevel([&](ps11::SimdLevel) {
                DrawStats rs;
                REQUIRE(draw(rows, rs) == expected);
                CHECK(rs.pixelsRowPath == rs.pixelsCovered);
                CHECK(rs.pixelsShaded == 0);
            });
        }
}

TEST_CASE("tile skipping: a program whose ONE/ONE adds zero whatever it reads is skipped only with skipping on",
          "[draw][aligned][skip]") {
    // anyData of `mov r0, c2` with c2 = 0, added ONE/ONE into an A8R8G8B8 target: a skip. With
    // skipping off the draw is a fill of that zero, merged over every pixel (nothing is left out);
    // with it on, the tiles are skipped (decided or not). The bytes stay the clear colour.
    for (bool skip : {false, true}) {
        DeviceOptions o;
        o.software.skipTiles = skip;
        o.software.timeTiles = false;
        Device dev(o);
        Handle rt{}, ps{};
        REQUIRE(dev.CreateRenderTarget(160, 120, D3DFMT_A8R8G8B8, 1, &rt) == D3D_OK);
        REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0x20406080u, 1.0f, 0) == D3D_OK);
        REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ndef c2, 0, 0, 0, 0\nmov r0, c2\n", &ps) == D3D_OK);
        REQUIRE(dev.SetPixelShader(ps) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE) == D3D_OK);
        REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE) == D3D_OK);
        for (int draw = 0; draw < 3; ++draw) {
            REQUIRE(drawFullscreenQuad(dev) == D3D_OK);
            const DrawStats& s = dev.lastDrawStats();
            INFO((skip ? "skipping on" : "skipping off") << ", draw " << draw);
            CHECK(s.pixelsCovered == 160u * 120u);
            CHECK(s.pixelsWritten == (skip ? 0u : 160u * 120u));
        }
        size_t other = 0;
        REQUIRE(dev.readSurface(rt, [&](const D3DLOCKED_RECT& lr) {
            for (UINT y = 0; y < 120; ++y)
                for (UINT x = 0; x < 160; ++x) {
                    uint32_t p;
                    std::memcpy(&p, static_cast<const uint8_t*>(lr.pBits) + y * UINT(lr.Pitch) + x * 4, 4);
                    other += p != 0x20406080u;
                }
        }) == D3D_OK);
        CHECK(other == 0);
    }
}
