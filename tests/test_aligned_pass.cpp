// The aligned-pass path of DrawPrimitiveUP (emu/aligned_pass.h) against the quad path: random
// screen-aligned draws (target and texture sizes, texel formats, filters, every address mode,
// border colours, 1:1 / offset / scaled / downsampling coordinates, colour gradients, programs of
// ps_1_1–1_4, blending, alpha test, write masks, scissor) drawn by two devices, one with
// DeviceOptions::alignedPasses off, the aligned one at every SIMD level this CPU runs; the render
// targets must be identical byte for byte, and the aligned device must really have taken the row
// path (no helper lanes shaded). The cases are tests/aligned_cases.h's; the row paths' own
// machinery is tested in test_aligned_rows.cpp and test_aligned_kernels.cpp, tile skipping in test_tile_skip.cpp.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "aligned_cases.h"
#include "executed_texture_programs.h"
#include "emu/aligned_float.h"
#include "emu/aligned_pass.h"
#include "emu/aligned_pass_kernels.h"
#include "emu/device.h"
#include "emu/format.h"
#include "ps11/assembler.h"
#include "ps11/validator.h"
#include "simd_levels.h"

using namespace emu;

using namespace alignedcases;

TEST_CASE("aligned pass: random screen-aligned draws equal the quad path byte for byte", "[draw][aligned]") {
    std::mt19937 rng(20261125);
    int aligned = 0, cases = 0;
    for (int i = 0; i < 400; ++i) {
        const Case c = randomCase(rng);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = false;  // every pixel shaded: the statistics below hold
        // ps_1_4 programs run on the 1.4-class card, in fx8; every third case on that card in its
        // own fx12 (MaxValue 8: the generic executor's pre-sampled runs).
        fxProfile(c, i % 3 == 2, quadOpt, rowOpt);
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
            // The row path draws exactly the covered pixels (shading them, or copying a program
            // that copies one tap whatever it reads); the quad path adds helper lanes.
            if (rs.pixelsRowPath == rs.pixelsCovered && rs.pixelsShaded <= rs.pixelsCovered) ++aligned;
            CHECK(rs.instructions * qs.pixelsShaded == qs.instructions * rs.pixelsShaded);
        });
    }
    // Every case qualifies (fx8 or fx12, plain texture reads, screen-aligned): all must take the
    // row path, save those whose quads happened to be all covered.
    INFO(aligned << " of " << cases << " cases took the row path");
    CHECK(aligned * 10 >= cases * 9);
}

namespace {

// Gives each texture of `c` a mip chain of random length (random texels), a random MIP filter
// and, half the time, a min filter other than its mag filter. True when some chain has two
// levels or more.
bool addMipChains(Case& c, std::mt19937& rng) {
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
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
    return chains;
}

// Whether some texture of `c` blends two levels (a chain under MIP filter LINEAR).
bool trilinear(const Case& c) {
    return std::any_of(c.tex.begin(), c.tex.end(),
                       [](const Case::Tex& t) { return t.bound && !t.mips.empty() && t.mipFilter == D3DTEXF_LINEAR; });
}

// Whether some texture of `c` with a chain is not 8-bit (texels decoded).
bool decodedChain(const Case& c) {
    return std::any_of(c.tex.begin(), c.tex.end(), [](const Case::Tex& t) {
        return t.bound && !t.mips.empty() && emu::formatInfo(t.format)->cls != ps11::FormatClass::Unorm8;
    });
}

}  // namespace

TEST_CASE("aligned pass: mip chains and MIN != MAG filters take the row path where every quad picks one level",
          "[draw][aligned]") {
    // The random cases (1:1 passes, 2:1 … 4:1 reductions, magnifications, any rectangle) with mip
    // chains of any length, each MIP filter and a min filter that differs from the mag filter
    // half the time, in fx8, fx12, float and ideal: the level and filter each quad picks must be
    // the quad path's.
    std::mt19937 rng(20261130);
    int cases = 0, rows = 0, mipRows = 0;
    std::array<int, 4> profileRows{};
    for (int i = 0; i < 400; ++i) {
        const int profile = i % 4;  // fx8, fx12 (the radeon8500 class), float, ideal
        Case c = randomCase(rng, profile >= 2);
        const bool chains = addMipChains(c, rng);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        fxProfile(c, profile == 1, quadOpt, rowOpt);
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
    // down (levels 1, 2 and 1). The row path reads the level of the first for the triangles that
    // pick it, and samples the others' taps per pixel, each at its quad's level.
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
    // Every rectangle on the row path (the second's tap sampled per pixel, at its quads' level).
    CHECK(rs.pixelsRowPath == 3 * 32 * 16);
    CHECK(rs.pixelsShaded == rs.pixelsCovered);
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
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = uni(0, 1) == 0;
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
            withoutNaNs(c);
        }
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        floatProfile(c, i, (i / 2) % 2 != 0, quadOpt, rowOpt);
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
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = (i % 3) == 0;  // such triangles' tiles are never decided
        fxProfile(c, i % 4 == 1, quadOpt, rowOpt);  // radeon8500, fx12: taps sampled per pixel at scale 16
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << " rhw " << c.verts[0].rhw << " program:\n" << c.program);
        testutil::forEachSimdLevel([&](ps11::SimdLevel) { requireRowsEqual(rowOpt, c, expected, qs, cases, rowPath); });
    }
    INFO(rowPath << " of " << cases << " cases took the row path");
    CHECK(rowPath * 10 >= cases * 9);
}

TEST_CASE("aligned pass: rotated and perspective draws of mip chains pick each pixel's level as its quad does",
          "[draw][aligned]") {
    // The random rotated, sheared and perspective cases with mip chains, every MIP filter and
    // MIN != MAG half the time, in fx8 and fx12: the row path samples them per pixel, each pixel
    // at the level, filter and mip blend of its 2×2 quad.
    std::mt19937 rng(20261201);
    int cases = 0, rows = 0, mipRows = 0, trilinearRows = 0;
    for (int i = 0; i < 300; ++i) {
        Case c = randomCase(rng);
        const bool chains = addMipChains(c, rng);
        anyMapping(c, rng);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        fxProfile(c, i % 4 == 1, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << " rhw " << c.verts[0].rhw << " program:\n" << c.program);
        const int before = rows;
        requireRowsEqual(rowOpt, c, expected, qs, cases, rows);
        if (chains && rows > before) ++mipRows;
        if (trilinear(c) && rows > before) ++trilinearRows;
    }
    INFO(rows << " of " << cases << " cases took the row path, " << mipRows << " with a mip chain, " << trilinearRows
              << " with a blend of two levels");
    CHECK(rows * 4 >= cases * 3);
    CHECK(mipRows * 4 >= cases * 3);
    CHECK(trilinearRows * 2 >= cases);
}

TEST_CASE("float row path: random rotated, sheared and perspective draws in float and ideal equal the quad path",
          "[draw][aligned]") {
    std::mt19937 rng(20261130);
    int rowPath = 0, cases = 0;
    for (int i = 0; i < 200; ++i) {
        Case c = randomCase(rng, (i & 2) != 0);
        anyMapping(c, rng);
        withoutNaNs(c);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        floatProfile(c, i, (i / 4) % 2 != 0, quadOpt, rowOpt);
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

TEST_CASE("float row path: rotated and perspective draws of mip chains pick each pixel's level as its quad does",
          "[draw][aligned]") {
    // The same in float and ideal (and the D3D9 class's 8-bit weights), every format: the float row
    // path samples them per pixel, each at its quad's level, filter and mip blend.
    std::mt19937 rng(20261202);
    int cases = 0, rows = 0, mipRows = 0, trilinearRows = 0, decodedRows = 0;
    for (int i = 0; i < 300; ++i) {
        Case c = randomCase(rng, (i & 2) != 0);
        const bool chains = addMipChains(c, rng);
        anyMapping(c, rng);
        withoutNaNs(c);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        floatProfile(c, i, (i / 4) % 2 != 0, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", rhw " << c.verts[0].rhw
                     << ", program:\n"
                     << c.program);
        const int before = rows;
        requireRowsEqual(rowOpt, c, expected, qs, cases, rows);
        if (chains && rows > before) ++mipRows;
        if (trilinear(c) && rows > before) ++trilinearRows;
        if (decodedChain(c) && rows > before) ++decodedRows;
    }
    INFO(rows << " of " << cases << " cases took the row path, " << mipRows << " with a mip chain, " << trilinearRows
              << " with a blend of two levels, " << decodedRows << " with a chain of decoded texels");
    CHECK(rows * 4 >= cases * 3);
    CHECK(mipRows * 4 >= cases * 3);
    CHECK(trilinearRows * 2 >= cases);
    CHECK(decodedRows * 10 >= cases);
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

// Projected reads (ps11::TapPlan::divisor): each stage D3DTTFF_PROJECTED with COUNT3, COUNT4 or
// COUNT0 (q), or no flag, and each vertex its sets' r and q (q anywhere in [−0.5, 2]: divisors
// near and through 0 too); a third of the cases a ps_1_4 program reading through _dw.xyw. Any
// mapping half the time, mip chains a third of the time. The row paths sample them per pixel at
// the divided coordinates (tapCoords).
void projectedReads(Case& c, std::mt19937& rng, bool chains) {
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    const DWORD flags[] = {0, D3DTTFF_PROJECTED | D3DTTFF_COUNT3, D3DTTFF_PROJECTED | D3DTTFF_COUNT4,
                           D3DTTFF_PROJECTED};
    for (DWORD& f : c.transformFlags) f = flags[rng() % 4];
    const char* const dw[] = {
        "ps_1_4\ntexld r0, t0_dw.xyw\ntexld r1, t1\nmul r0, r0, r1\n",
        "ps_1_4\ntexld r2, t3_dw.xyw\ntexld r3, t2_dw.xyw\nmad r0, r2, c0, r3\n",
        "ps_1_4\ntexld r1, t1_dw.xyw\nphase\ntexld r0, t0_dw.xyw\nlrp r0.rgb, c3, r0, r1\n",
    };
    if (rng() % 3 == 0) c.program = dw[rng() % 3];
    if (chains) addMipChains(c, rng);
    if (rng() & 1) anyMapping(c, rng);
    c.rq.resize(c.verts.size());
    for (auto& v : c.rq)
        for (auto& set : v) set = {real(-1.0f, 2.0f), rng() % 8 == 0 ? real(-0.5f, 2.0f) : real(0.25f, 2.0f)};
}

TEST_CASE("aligned pass: projected reads take the row path and equal the quad path byte for byte", "[draw][aligned]") {
    std::mt19937 rng(20261203);
    int rowPath = 0, cases = 0;
    for (int i = 0; i < 300; ++i) {
        Case c = randomCase(rng);
        projectedReads(c, rng, i % 3 == 0);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = (i % 3) == 1;  // (projected taps' tiles are never decided)
        fxProfile(c, i % 4 == 1, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << " flags " << c.transformFlags[0] << " "
                     << c.transformFlags[1] << " " << c.transformFlags[2] << " " << c.transformFlags[3]
                     << " program:\n"
                     << c.program);
        testutil::forEachSimdLevel([&](ps11::SimdLevel) { requireRowsEqual(rowOpt, c, expected, qs, cases, rowPath); });
    }
    INFO(rowPath << " of " << cases << " cases took the row path");
    CHECK(rowPath * 10 >= cases * 7);
}

TEST_CASE("float row path: projected reads in float and ideal equal the quad path byte for byte", "[draw][aligned]") {
    std::mt19937 rng(20261204);
    int rowPath = 0, cases = 0;
    for (int i = 0; i < 200; ++i) {
        Case c = randomCase(rng, (i & 2) != 0);
        projectedReads(c, rng, i % 3 == 0);
        withoutNaNs(c);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        floatProfile(c, i, (i / 4) % 2 != 0, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", flags "
                     << c.transformFlags[0] << " " << c.transformFlags[1] << " " << c.transformFlags[2] << " "
                     << c.transformFlags[3] << ", program:\n"
                     << c.program);
        requireRowsEqual(rowOpt, c, expected, qs, cases, rowPath);
    }
    INFO(rowPath << " of " << cases << " cases took the row path");
    CHECK(rowPath * 10 >= cases * 7);
}

// Texkills of coordinate sets (ps11::TapPlan::killSets): random cases with any mapping half the
// time, each set's x and y anywhere in [−1.5, 2.5] there (and in [0, 1] on screen-aligned quads,
// shifted by up to −0.3), its z in [−1, 2] (Case::rq), depth and fog as the random cases have
// them. A run with a killed pixel is merged over the pixels kept, which write neither colour nor
// depth.
void texkills(Case& c, std::mt19937& rng) {
    const char* const programs[] = {
        "ps_1_1\ntex t0\ntexkill t1\nmul r0, t0, v0\n",
        "ps_1_1\ntexkill t0\ntex t1\nmov r0, t1\n",
        "ps_1_3\ntex t0\ntexkill t2\ntex t3\nmad r0, t0, c0, t3\n",
        "ps_1_4\ntexld r0, t0\ntexkill t1\nmul r0, r0, c0\n",
        "ps_1_4\ntexkill t2\ntexld r1, t1\nphase\ntexld r0, t0\nmad r0.rgb, r0, c1, r1\n",
    };
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    c.program = programs[rng() % 5];
    if (rng() & 1) {
        anyMapping(c, rng);
    } else {
        const float du = real(-0.3f, 0.0f), dv = real(-0.3f, 0.0f);
        for (Vtx& v : c.verts)
            for (auto& uv : v.uv) uv[0] += du, uv[1] += dv;
    }
    c.rq.resize(c.verts.size());
    for (auto& v : c.rq)
        for (auto& set : v) set = {real(-1.0f, 2.0f), 1.0f};
}

// Whether case c's texkill kills a pixel the quad path would write without it.
bool killsSome(const Case& c, const DeviceOptions& quadOpt, const DrawStats& qs) {
    Case whole = c;
    const size_t at = whole.program.find("texkill");
    whole.program.erase(at, whole.program.find('\n', at) + 1 - at);
    Device wholeDev(quadOpt);
    DrawStats ws;
    (void)drawCase(wholeDev, whole, ws);
    return qs.pixelsWritten < ws.pixelsWritten;
}

TEST_CASE("aligned pass: texkills of coordinate sets take the row path and equal the quad path byte for byte",
          "[draw][aligned]") {
    std::mt19937 rng(20261205);
    int rowPath = 0, cases = 0, killing = 0;
    for (int i = 0; i < 300; ++i) {
        Case c = randomCase(rng);
        texkills(c, rng);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = (i % 3) == 1;  // (texkills read coordinates: tiles are never decided)
        fxProfile(c, i % 4 == 1, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        if (killsSome(c, quadOpt, qs)) ++killing;
        INFO("case " << i << ": " << c.w << "x" << c.h << " depth " << c.depth << " program:\n" << c.program);
        testutil::forEachSimdLevel([&](ps11::SimdLevel) { requireRowsEqual(rowOpt, c, expected, qs, cases, rowPath); });
    }
    INFO(rowPath << " of " << cases << " cases took the row path, " << killing << " killed pixels");
    CHECK(rowPath * 10 >= cases * 8);
    CHECK(killing * 2 >= 300);
}

TEST_CASE("float row path: texkills of coordinate sets in float and ideal equal the quad path byte for byte",
          "[draw][aligned]") {
    std::mt19937 rng(20261206);
    int rowPath = 0, cases = 0, killing = 0;
    for (int i = 0; i < 200; ++i) {
        Case c = randomCase(rng, (i & 2) != 0);
        texkills(c, rng);
        withoutNaNs(c);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        floatProfile(c, i, (i / 4) % 2 != 0, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        if (killsSome(c, quadOpt, qs)) ++killing;
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", depth " << c.depth
                     << ", program:\n"
                     << c.program);
        requireRowsEqual(rowOpt, c, expected, qs, cases, rowPath);
    }
    INFO(rowPath << " of " << cases << " cases took the row path, " << killing << " killed pixels");
    CHECK(rowPath * 10 >= cases * 8);
    CHECK(killing * 2 >= 200);
}

// The programs of executed_texture_programs.h: texbem/texbeml under random bump matrices, texm3x2
// and texm3x3 rows (the eye from the coordinates' w), texkills of a register (a killed pixel
// writes neither colour nor depth) and the program's own depth (tested against, and written into,
// the depth buffer where the case has one). The
// executor samples those per pixel from the row's coordinates (fillRowCoords). A sixth of the cases
// read a V8U8 bump map through a plain tap (which the executor then samples too: the fx row path
// filters 8-bit unsigned textures only), a third have four-component coordinates, half any
// mapping.
void dependentReads(Case& c, std::mt19937& rng) {
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    c.program = executedprograms::kPrograms[rng() % std::size(executedprograms::kPrograms)];
    for (auto& stage : c.bump)
        for (float& m : stage) m = rng() % 4 == 0 ? 0.0f : real(-1.5f, 1.5f);
    if (rng() % 6 == 0) {
        Case::Tex& t = c.tex[0];
        t.format = D3DFMT_V8U8;
        t.bytes.resize(size_t(t.w) * t.h * texelBytes(t.format));
        for (uint8_t& b : t.bytes) b = uint8_t(rng());
        c.oneTexture = false;
    }
    if (rng() & 1) anyMapping(c, rng);
    if (rng() % 3 == 0) {
        c.rq.resize(c.verts.size());
        for (auto& v : c.rq)
            for (auto& set : v) set = {real(-1.0f, 2.0f), real(-1.0f, 2.0f)};
    }
}

TEST_CASE("aligned pass: dependent reads take the row path and equal the quad path byte for byte", "[draw][aligned]") {
    std::mt19937 rng(20261207);
    int rowPath = 0, cases = 0, bumpMaps = 0, killing = 0, ownDepth = 0;
    for (int i = 0; i < 500; ++i) {
        Case c = randomCase(rng);
        dependentReads(c, rng);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = (i % 3) == 1;  // (dependent reads: tiles are never decided)
        fxProfile(c, i % 4 == 1, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << " depth " << c.depth << ", " << profileName(quadOpt)
                     << ", program:\n"
                     << c.program);
        int caseRows = 0, caseCount = 0;
        testutil::forEachSimdLevel(
            [&](ps11::SimdLevel) { requireRowsEqual(rowOpt, c, expected, qs, caseCount, caseRows); });
        // (Pixels a register's texkill discarded: covered, not written, nothing else refusing them.)
        if (c.program.find("texkill") != std::string::npos && !c.depth && !c.alphaTest && c.writeMask &&
            qs.pixelsWritten < qs.pixelsCovered)
            ++killing;
        if (c.depth && c.program.find("depth") != std::string::npos && qs.pixelsCovered) ++ownDepth;
        if (c.tex[0].format == D3DFMT_V8U8 && c.tex[0].bound &&
            (c.program.find("\ntex t0\n") != std::string::npos ||
             c.program.find("\ntexld r0, t0\n") != std::string::npos))
            bumpMaps += caseCount > 0;  // (a plain read of a signed texture, sampled by the executor)
        cases += caseCount, rowPath += caseRows;
    }
    INFO(rowPath << " of " << cases << " cases took the row path, " << bumpMaps << " read a V8U8 bump map, "
                 << killing << " killed pixels, " << ownDepth << " tested the program's depth");
    CHECK(rowPath * 10 >= cases * 8);
    CHECK(bumpMaps >= 15);
    CHECK(killing >= 10);
    CHECK(ownDepth >= 8);
}

TEST_CASE("float row path: dependent reads in float and ideal equal the quad path byte for byte", "[draw][aligned]") {
    std::mt19937 rng(20261208);
    int rowPath = 0, cases = 0, ownDepth = 0;
    for (int i = 0; i < 260; ++i) {
        Case c = randomCase(rng, (i & 2) != 0);
        dependentReads(c, rng);
        withoutNaNs(c);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = (i % 3) == 1;
        floatProfile(c, i, (i / 4) % 2 != 0, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", depth " << c.depth
                     << ", program:\n"
                     << c.program);
        requireRowsEqual(rowOpt, c, expected, qs, cases, rowPath);
        if (c.depth && c.program.find("depth") != std::string::npos && qs.pixelsCovered) ++ownDepth;
    }
    INFO(rowPath << " of " << cases << " cases took the row path, " << ownDepth << " tested the program's depth");
    CHECK(rowPath * 10 >= cases * 10);
    CHECK(ownDepth >= 4);
}

TEST_CASE("float row path: plain reads it does not filter, sampled by the executor, equal the quad path", "[draw][aligned]") {
    // The float row path filters 2-D levels, one plain read a stage; a volume texture's plain read
    // (w from the set's third component) and two plain reads of one stage (ps_1_4's phases) are
    // left to the executor, per pixel at level 0 (TapPlan::executedTaps), and the draw's tiles are
    // never decided. Three cases in four read a volume texture at stage 0.
    static const char* const programs[] = {
        "ps_1_1\ntex t0\ntex t1\nmad r0, t0, c0, t1\n",
        "ps_1_1\ntex t0\nmul r0, t0, v0\n",
        "ps_1_4\ntexld r0, t0\ntexld r1, t1\nmad r0, r0, c0, r1\n",
        "ps_1_4\ntexld r0, t0\nphase\ntexld r0, t1\nmul r0, r0, c0\n",
    };
    std::mt19937 rng(20261210);
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    int rowPath = 0, cases = 0;
    for (int i = 0; i < 160; ++i) {
        Case c = randomCase(rng, (i & 2) != 0);
        withoutNaNs(c);
        c.program = programs[rng() % std::size(programs)];
        Case::Tex& t = c.tex[0];
        t.format = D3DFMT_A8R8G8B8;
        t.d = i % 4 == 3 ? 1 : 2 + UINT(rng() % 4);
        t.mips.clear();
        t.minFilter = 0, t.mipFilter = D3DTEXF_NONE;
        t.bound = true;
        t.bytes.resize(size_t(t.w) * t.h * t.d * 4);
        for (uint8_t& b : t.bytes) b = uint8_t(rng());
        c.oneTexture = false;
        c.rq.resize(c.verts.size());
        for (auto& v : c.rq)
            for (auto& set : v) set = {real(-0.5f, 1.5f), real(0.5f, 2.0f)};
        if (rng() & 1) anyMapping(c, rng);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = (i % 3) == 1;
        floatProfile(c, i, (i / 4) % 2 != 0, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", depth " << t.d
                     << ", program:\n"
                     << c.program);
        requireRowsEqual(rowOpt, c, expected, qs, cases, rowPath);
    }
    INFO(rowPath << " of " << cases << " cases took the row path");
    CHECK(rowPath * 10 >= cases * 8);
}

TEST_CASE("aligned pass: plain reads of signed, float and half textures take the fx row path, sampled by the executor",
          "[draw][aligned]") {
    // The fx row path filters 8-bit unsigned textures itself; a plain read of any other 2-D
    // texture without a level of detail is left to the executor (ps11::TapPlan::executedTaps),
    // its texels of any sign (the fast path's sign analysis without them), and the draw's tiles
    // are never decided.
    std::mt19937 rng(20261209);
    int rowPath = 0, cases = 0, executed = 0;
    for (int i = 0; i < 300; ++i) {
        Case c = randomCase(rng, true);
        withoutNaNs(c);
        if (rng() & 1) anyMapping(c, rng);
        DeviceOptions quadOpt, rowOpt;
        quadAndRowOptions(i, quadOpt, rowOpt);
        rowOpt.software.skipTiles = (i % 3) == 1;
        fxProfile(c, i % 4 == 1, quadOpt, rowOpt);
        Device quadDev(quadOpt);
        DrawStats qs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i << ": " << c.w << "x" << c.h << ", " << profileName(quadOpt) << ", program:\n" << c.program);
        int caseRows = 0, caseCount = 0;
        requireRowsEqual(rowOpt, c, expected, qs, caseCount, caseRows);
        bool other = false;
        for (const Case::Tex& t : c.tex)
            other = other || (t.bound && t.format != D3DFMT_A8R8G8B8 && t.format != D3DFMT_L8);
        executed += other && caseRows;
        cases += caseCount, rowPath += caseRows;
    }
    INFO(rowPath << " of " << cases << " cases took the row path, " << executed << " with a texture it does not filter");
    CHECK(rowPath * 10 >= cases * 8);
    CHECK(executed >= 100);
}
