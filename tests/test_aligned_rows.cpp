// The row paths' own machinery against the quad path: one device across draws, H rows and texel
// rows cached by workers (never outliving their draw), magnified and half-texel taps, tabulated
// runs, sprites (draws of many small quads, row tables kept between draws) and joined rows. The
// store kernels, RowSource rows and reductions are test_aligned_kernels.cpp's; the random
// differential cases test_aligned_pass.cpp's.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
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
#include "aligned_cases.h"
#include "aligned_rows_util.h"
#include "simd_levels.h"

using namespace emu;

using namespace emu;

using namespace alignedcases;
using namespace alignedrows;

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


TEST_CASE("aligned pass: H rows cached by a worker never outlive their draw", "[draw][aligned]") {
    // The device may place a new texture copy where a freed one was, so two draws can sample the
    // same address with different texels. Driven below the device: the same buffer, rewritten
    // between two draws of the same triangles, must give each draw its own texels.
    const int w = 48, h = 6;
    const std::unique_ptr<ps11::Executor> exec = copyExecutor(ps11::Precision::Fx8);
    std::vector<uint8_t> texels(size_t(w) * h * 4);
    Image target = blankTarget(w, h);
    // The 1:1 quad with the tap a quarter texel right (one weight along whole rows).
    TriangleSetup setups[2];
    uint64_t used = 0;
    quadSetups(w, h, 0.25f, 0.0f, setups, used);
    AlignedScratch* scratch = new AlignedScratch;  // one worker's, kept across the draws
    std::mt19937 rng(99);
    for (int draw = 0; draw < 2; ++draw) {
        for (uint8_t& b : texels) b = uint8_t(rng());
        AlignedDraw d;
        AlignedTriangle at[2];
        tapDraw(*exec, target, used, texels, w, h, true, d);
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
            REQUIRE(prepareFloatRowDraw(*exec, ps11::Precision::Float, 0, none, samplers, merge,
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

TEST_CASE("aligned pass: magnified taps (2x, 3x, 4x, 8x, 16x, non-integer) equal the quad path byte for byte",
          "[draw][aligned]") {
    // A glare composite's blurred tap reads a small texture magnified: consecutive columns share
    // their texels and the weight changes every column (tabulated H rows; at 2x, 4x and 8x every
    // weight is a multiple of 16, kind Q, at 16x of 8 only). Every address mode,
    // border colours, coordinates past [0, 1] (border and wrapped texels inside a row), point
    // and linear filters, one or two threads.
    std::mt19937 rng(20261127);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    const float scales[] = {2.0f, 3.0f, 8.0f, 2.5f, 1.75f, 5.3f, 1.0f / 0.9f, 4.0f, 16.0f};
    int aligned = 0, cases = 0;
    for (int i = 0; i < 280; ++i) {
        Case c = randomCase(rng);
        const float scale = scales[size_t(i) % std::size(scales)];
        c.w = UINT(uni(16, 420));
        c.h = UINT(uni(2, 20));
        // An integer scale over a target of whole multiples half the time: the texture spans the
        // target exactly, so its weights are those of the scale (multiples of 256 / scale).
        if (scale == std::floor(scale) && uni(0, 1)) {
            const UINT k = UINT(scale);
            c.w = std::max(k, c.w / k * k);
            c.h = std::max(k, (c.h + k) / k * k);
        }
        c.rtInit.resize(size_t(c.w) * c.h * 4);
        for (uint8_t& b : c.rtInit) b = uint8_t(rng());
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
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = false;  // every pixel shaded: the row path's count below holds
        fxProfile(c, false, quadOpt, rowOpt);
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
            if (rs.pixelsRowPath == rs.pixelsCovered && rs.pixelsShaded <= rs.pixelsCovered) ++aligned;
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
        const float dx[4] = {-0.5f + ox, 0.5f + ox, -0.5f + ox, 0.5f + ox};
        const float dy[4] = {-0.5f + oy, -0.5f + oy, 0.5f + oy, 0.5f + oy};
        screenQuad(c, t, dx, dy);
        c.blend = DWORD(uni(0, 1));
        // A scissor rectangle now and then: spans that start and end anywhere.
        c.scissor = uni(0, 2) == 0;
        c.scissorRect = RECT{uni(0, 40), 0, int(c.w) - uni(0, 40), int(c.h)};
        INFO("case " << i << ": " << c.w << "x" << c.h << ", scale " << scale << ", offset " << ox << ", " << oy
                     << (c.scissor ? ", scissor" : ""));
        requireRowsAtEveryLevel(c, ps11::Precision::Fx8, 1 + (i & 1));
    }
}

TEST_CASE("aligned pass: chain rows' half-texel taps on shared texel rows equal the quad path", "[draw][aligned]") {
    // Four LINEAR taps of one texture at whole or half texels: on a few rows (dy in −1 … +½, so
    // taps read the same texel rows at vertical weight 0 or ½, halfway along the row or not) and
    // now and then far apart along a row (up to ±9½ texels, or pairs up to 17 texels apart). Chain rows form each tap's rounded
    // means once and later taps on the same rows read them one or more texels over, or copy the
    // runs they share. Every address mode, rows wider than a span, a scissor now and then.
    std::mt19937 rng(20261201);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    for (int i = 0; i < 60; ++i) {
        const UINT w = UINT(uni(0, 2) ? uni(150, 1200) : uni(17, 60));
        const UINT h = UINT(uni(2, 6));
        Case c = randomTarget(rng, w, h);
        Case::Tex t;
        t.w = c.w, t.h = c.h;
        t.bytes.resize(size_t(t.w) * t.h * 4);
        for (uint8_t& b : t.bytes) b = uint8_t(uni(0, 5) ? rng() : 255);
        t.filter = D3DTEXF_LINEAR;
        t.addressU = DWORD(uni(1, 5));
        t.addressV = DWORD(uni(1, 5));
        t.border = DWORD(rng());
        c.tex.assign(4, t);
        c.oneTexture = true;
        c.program = kPrograms[1];
        for (auto& k : c.consts)
            for (float& v : k) v = float(uni(0, 8)) / 16.0f;
        const int reach = uni(0, 3) ? 4 : 19;  // half texels either way along a row
        float dx[4], dy[4];
        for (int s = 0; s < 4; ++s) {
            dx[s] = float(uni(-reach, reach)) / 2.0f;
            dy[s] = float(uni(-2, 1)) / 2.0f;
        }
        if (uni(0, 2) == 0) {
            // Pairs on the same rows 1, 2, 3, 16 or 17 texels apart: the second reads the first's
            // means from where they start up to past its last (formed 16 texels further).
            const int apart[] = {1, 2, 3, 16, 17};
            for (int s : {1, 3}) {
                dx[s] = dx[s - 1] + float(apart[uni(0, 4)]);
                dy[s] = dy[s - 1];
            }
        }
        screenQuad(c, t, dx, dy);
        c.blend = DWORD(uni(0, 1));
        c.scissor = uni(0, 3) == 0;
        c.scissorRect = RECT{uni(0, 12), 0, int(c.w) - uni(0, 12), int(c.h)};
        INFO("case " << i << ": " << c.w << "x" << c.h << ", taps (" << dx[0] << ", " << dy[0] << ") (" << dx[1] << ", "
                     << dy[1] << ") (" << dx[2] << ", " << dy[2] << ") (" << dx[3] << ", " << dy[3] << ")"
                     << (c.scissor ? ", scissor" : ""));
        requireRowsAtEveryLevel(c, ps11::Precision::Fx8, 1 + (i & 1));
    }
}

TEST_CASE("aligned pass: separable blur passes (chain rows) equal the quad path", "[draw][aligned]") {
    // The glow's passes, which the row path runs as chain rows (ps11::runChainRow): two to four
    // taps of one texture along a row (at whole texels, or halfway between two with LINEAR) or
    // along a column (whole texels), weighted by non-negative constants, _sat or not, drawn over
    // the target or added to it (ONE/ONE), into A8R8G8B8 or X8R8G8B8, every address mode (the
    // columns at the edges read clamped, wrapped or border texels: filtered per pixel between the
    // chain rows), rows wider than a span, a scissor now and then; and now and then a constant
    // with a negative channel or a swizzled tap, which are no chain; a stage without a texture
    // (the glow's last pass of fewer taps).
    std::mt19937 rng(20261130);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    const char* programs[] = {
        "ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\nmad r0, t1, c1, r0\nmad r0, t2, c2, r0\n"
        "mad r0, t3, c3, r0\n",
        "ps_1_1\ntex t0\ntex t1\ntex t2\nmul r0, t0, c0\nmad r0, t1, c1, r0\nmad_sat r0, t2, c2, r0\n",
        "ps_1_1\ntex t0\ntex t1\nmul r0, c0, t0\nmad r0, c1, t1, r0\n",
        "ps_1_3\ntex t0\ntex t1\ntex t2\nmul r0, t2, c0\nmad r0, t1, c1, r0\nmad r0, t0, c2, r0\n",
        "ps_1_1\ntex t0\ntex t1\nmul r0, t0.a, c0\nmad r0, t1, c1, r0\n",  // swizzled: no chain
    };
    for (int i = 0; i < 40; ++i) {
        const UINT w = UINT(uni(200, 700));
        const UINT h = UINT(uni(2, 7));
        Case c = randomTarget(rng, w, h);
        // Every address mode along a row and along a column, the rest random.
        const bool horizontal = (i / 5) % 2 == 0;
        const bool half = horizontal && uni(0, 1);
        Case::Tex t;
        t.w = c.w, t.h = c.h;
        t.bytes.resize(size_t(t.w) * t.h * 4);
        for (uint8_t& b : t.bytes) b = uint8_t(uni(0, 5) ? rng() : 255);
        t.filter = half || uni(0, 1) ? D3DTEXF_LINEAR : D3DTEXF_POINT;
        t.addressU = t.addressV = DWORD(1 + i % 5);
        t.border = DWORD(rng());
        c.tex.assign(4, t);
        c.oneTexture = true;
        c.tex[3].bound = uni(0, 3) != 0;  // a last pass of fewer taps: stage 3 reads (0, 0, 0, 1)
        c.program = programs[size_t(uni(0, int(std::size(programs)) - 1))];
        for (auto& k : c.consts)
            for (float& v : k) v = float(uni(0, 16)) / 16.0f;
        if (uni(0, 7) == 0) c.consts[uni(0, 3)][uni(0, 3)] = -float(uni(1, 16)) / 16.0f;
        float dx[4], dy[4];  // taps at −2, −1, 0, +1 (+½)
        for (int s = 0; s < 4; ++s) {
            const float o = float(s - 2) + (half ? 0.5f : 0.0f);
            dx[s] = horizontal ? o : 0.0f, dy[s] = horizontal ? 0.0f : o;
        }
        screenQuad(c, t, dx, dy);
        c.blend = DWORD(uni(0, 1));
        c.scissor = uni(0, 3) == 0;
        c.scissorRect = RECT{uni(0, 40), 0, int(c.w) - uni(0, 40), int(c.h)};
        INFO("case " << i << ": " << c.w << "x" << c.h << (horizontal ? ", along a row" : ", along a column")
                     << (half ? ", halfway" : "") << ", " << c.program << (c.scissor ? ", scissor" : ""));
        requireRowsAtEveryLevel(c, ps11::Precision::Fx8, 1 + (i & 1));
    }
}

TEST_CASE("aligned pass: composites of a 1:1 tap and a magnified one equal the quad path",
          "[draw][aligned]") {
    // Programs of one product (Sousa's screen composite mad r0, t1, 1-t0, t0, a scale, a tap
    // added: chain rows in fx8) over a scene read 1:1 (t0, at texel centres or halfway between two
    // texels or rows; chain rows read it from its texel rows at vertical weight 0) and a glare texture magnified 2× to 8× or by any factor (t1,
    // LINEAR, blended into words from its H rows or filtered per pixel at the edges), every
    // address mode, drawn over the target or added to it, into A8R8G8B8 or X8R8G8B8; and a
    // program that reads the magnified tap alone (the pre-sampled path).
    std::mt19937 rng(20261201);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    const char* programs[] = {
        "ps_1_1\ntex t0\ntex t1\nmad r0, t1, 1-t0, t0\n",
        "ps_1_1\ntex t0\nmul r0, t0, c0\n",
        "ps_1_1\ntex t0\ntex t1\nmad r0, t1, c0, t0\n",
        "ps_1_1\ntex t0\ntex t1\nmad_sat r0, 1-t1, t0, t1\n",
        "ps_1_1\ntex t0\ntex t1\nmul r0, t1, 1-t0\n",
        "ps_1_1\ntex t0\ntex t1\nmad r0, t0, t1, c1\n",
        "ps_1_1\ntex t0\ntex t1\nmul r0, t1, c0\n",
    };
    for (int i = 0; i < 36; ++i) {
        const UINT w = UINT(uni(200, 700));
        const UINT h = UINT(uni(3, 20));
        Case c = randomTarget(rng, w, h);
        const int scales[] = {2, 4, 8, 3};
        const int scale = scales[i % 4];
        Case::Tex scene, glare;
        scene.w = c.w, scene.h = c.h;
        glare.w = UINT((int(c.w) + scale - 1) / scale + uni(0, 1)), glare.h = UINT((int(c.h) + scale - 1) / scale);
        for (Case::Tex* t : {&scene, &glare}) {
            t->bytes.resize(size_t(t->w) * t->h * 4);
            for (uint8_t& b : t->bytes) b = uint8_t(uni(0, 5) ? rng() : 255);
            t->addressU = DWORD(1 + uni(0, 4)), t->addressV = DWORD(1 + uni(0, 4));
            t->border = DWORD(rng());
        }
        const bool half = uni(0, 3) == 0;   // the scene read halfway between two texels
        const bool halfV = uni(0, 3) == 0;  // or between two rows
        scene.filter = half || halfV || uni(0, 1) ? D3DTEXF_LINEAR : D3DTEXF_POINT;
        glare.filter = D3DTEXF_LINEAR;
        c.tex.assign(4, scene);
        c.tex[1] = glare;
        c.tex[2].bound = c.tex[3].bound = false;
        c.program = programs[size_t(uni(0, int(std::size(programs)) - 1))];
        for (auto& k : c.consts)
            for (float& v : k) v = float(uni(0, 16)) / 16.0f;
        const float xs[4] = {-0.5f, float(c.w) - 0.5f, float(c.w) - 0.5f, -0.5f};
        const float ys[4] = {-0.5f, -0.5f, float(c.h) - 0.5f, float(c.h) - 0.5f};
        for (int k : {0, 1, 2, 0, 2, 3}) {
            Vtx q{xs[k], ys[k], 0.5f, 1.0f, 0xffffffffu, 0xff000000u, {}};
            for (int s = 0; s < 4; ++s) {
                q.uv[s][0] = ((k == 1 || k == 2) ? 1.0f : 0.0f) + (s == 0 && half ? 0.5f / float(scene.w) : 0.0f);
                q.uv[s][1] = (k >= 2 ? 1.0f : 0.0f) + (s == 0 && halfV ? 0.5f / float(scene.h) : 0.0f);
            }
            c.verts.push_back(q);
        }
        c.blend = DWORD(uni(0, 1));
        c.scissor = uni(0, 3) == 0;
        c.scissorRect = RECT{uni(0, 40), 0, int(c.w) - uni(0, 40), int(c.h)};
        // fx8 every time; then float, ideal, or the d3d9 class's float profile with 8-bit filter
        // weights, by turns (the float row path).
        const ps11::Precision other = i % 3 == 1 ? ps11::Precision::Float : ps11::Precision::Ideal;
        const ps11::HardwareClass* d3d9 = i % 3 == 0 ? ps11::findHardware("d3d9") : nullptr;
        REQUIRE((i % 3 != 0 || d3d9));
        INFO("case " << i << ": " << c.w << "x" << c.h << ", glare " << glare.w << "x" << glare.h
                     << (half ? ", scene halfway" : "") << (halfV ? ", scene between rows" : "") << ", " << c.program
                     << (c.scissor ? ", scissor" : ""));
        requireRowsAtEveryLevel(c, ps11::Precision::Fx8, 1 + (i & 1));
        requireRowsAtEveryLevel(c, other, 1 + (i & 1), d3d9);
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
    Image target = blankTarget(w, h);
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
        tapDraw(*exec, target, used, texels, tw, h, true, d);
        AlignedTriangle at;
        REQUIRE(prepareAlignedTriangle(d, setup, at));
        int tabulated = 0;
        for (const AlignedTriangle::Run& r : at.taps[0].runs)
            if (r.tabulated) tabulated += r.x1 - r.x0;
        INFO("scale " << scale);
        CHECK(tabulated >= w - 2 * int(scale + 1));
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
        quadAndRowOptions(i, quadOpt, rowOpt);
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
