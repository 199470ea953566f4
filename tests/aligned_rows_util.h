// Helpers of the row-path machinery tests (test_aligned_rows.cpp, test_aligned_kernels.cpp): a
// copy executor, blank targets and draws set up below the device, 1:1 quads, and the check that
// a case drawn on the row path at every SIMD level equals the quad path.
#pragma once

#include <catch2/catch.hpp>

#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "emu/aligned_pass.h"
#include "emu/device.h"
#include "emu/format.h"
#include "ps11/assembler.h"
#include "ps11/validator.h"
#include "aligned_cases.h"
#include "simd_levels.h"

namespace alignedrows {

using namespace emu;
using namespace alignedcases;

// Below the device: a copy program (`mov r0, t0`) for the profile's executor.
inline std::unique_ptr<ps11::Executor> copyExecutor(ps11::Precision precision) {
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

// A w×h A8R8G8B8 target of zero bytes.
inline Image blankTarget(int w, int h) {
    Image target;
    target.format = formatInfo(D3DFMT_A8R8G8B8);
    target.width = uint32_t(w), target.height = uint32_t(h), target.rowPitch = 4 * uint32_t(w);
    target.bytes.assign(size_t(w) * size_t(h) * 4, 0);
    return target;
}

// A draw of `exec` (fx8) into `target` whose tap 0 reads `texels` by hand (w×h texels, clamped,
// bilinear or point), set up below the device (prepareAlignedDraw gives it a new serial).
inline void tapDraw(const ps11::Executor& exec, Image& target, uint64_t used, const std::vector<uint8_t>& texels, uint32_t w,
             uint32_t h, bool linear, AlignedDraw& d) {
    std::array<std::shared_ptr<const ps11::Texture>, 8> none{};
    std::array<ps11::SamplerState, 8> samplers{};
    MergeState merge;
    REQUIRE(prepareAlignedDraw(exec, ps11::Precision::Fx8, none, samplers, merge, MergeTarget{&target, nullptr}, false,
                               used, d));
    AlignedTap& tap = d.taps[0];
    tap.bound = true;
    d.bound = 1;
    tap.texels = texels.data();
    tap.width = w, tap.height = h;
    tap.linear = linear;
    tap.addressU = tap.addressV = ps11::TextureAddress::Clamp;
}

// The two triangles of the 1:1 quad over a w×h target, tap 0's coordinates shifted by (du, dv)
// texels; `used` is what they interpolate.
inline void quadSetups(int w, int h, float du, float dv, TriangleSetup setups[2], uint64_t& used) {
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

// A quad over the whole c.w × c.h target whose stage s reads texture t 1:1, its texel offset by
// (dx[s], dy[s]) texels.
inline void screenQuad(Case& c, const Case::Tex& t, const float dx[4], const float dy[4]) {
    const float xs[4] = {-0.5f, float(c.w) - 0.5f, float(c.w) - 0.5f, -0.5f};
    const float ys[4] = {-0.5f, -0.5f, float(c.h) - 0.5f, float(c.h) - 0.5f};
    for (int k : {0, 1, 2, 0, 2, 3}) {
        Vtx q{xs[k], ys[k], 0.5f, 1.0f, 0xffffffffu, 0xff000000u, {}};
        for (int s = 0; s < 4; ++s) {
            q.uv[s][0] = ((k == 1 || k == 2) ? 1.0f : 0.0f) + dx[s] / float(t.w);
            q.uv[s][1] = (k >= 2 ? 1.0f : 0.0f) + dy[s] / float(t.h);
        }
        c.verts.push_back(q);
    }
}

// The case drawn in quads and on the row path (tiles not decided) at every SIMD level: the same
// bytes, every covered pixel shaded in rows. In `precision`, or with `hardware` its class's
// own profile and filter weights.
inline void requireRowsAtEveryLevel(const Case& c, ps11::Precision precision, int threads,
                             const ps11::HardwareClass* hardware = nullptr) {
    DeviceOptions quadOpt, rowOpt;
    quadOpt.software.alignedPasses = false;
    rowOpt.software.skipTiles = false;
    quadOpt.hardware = rowOpt.hardware = hardware;
    if (!hardware) quadOpt.precision = rowOpt.precision = precision;
    quadOpt.software.threads = rowOpt.software.threads = threads;
    Device quadDev(quadOpt);
    DrawStats qs;
    const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
    testutil::forEachSimdLevel([&](ps11::SimdLevel) {
        Device rowDev(rowOpt);
        DrawStats rs;
        REQUIRE(drawCase(rowDev, c, rs) == expected);
        CHECK(rs.pixelsRowPath == rs.pixelsCovered);
        CHECK(rs.pixelsShaded == rs.pixelsCovered);
    });
}

}  // namespace alignedrows
