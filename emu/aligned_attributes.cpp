// Device stage: the aligned-pass path's per-pixel attributes (emu/aligned_pass.h): texture
// coordinates, colours, fog and depth along a row span as the rasteriser interpolates them
// (emu/raster.h planeValue, divided by rhw with perspective), and the taps sampled per pixel from
// those coordinates (a rotated or perspective mapping, or a tap at its quads' mip levels).
#include <cstring>

#include "emu/aligned_pass.h"
#include "ps11/fill_lanes.h"
#include "ps11/texture_sampler_fast.h"

namespace emu {

namespace {

// 1 / rhw at pixels x .. x + n − 1 of row y of a triangle with perspective, as the rasteriser
// divides by it (rhw kept positive).
void rowInverseW(const TriangleSetup& s, int x, int y, int n, float* inv) {
    fillPlaneRow(s.rhw, s.ox, s.oy, x, y, n, inv);
    for (int i = 0; i < n; ++i) inv[i] = inverseRhw(inv[i]);
}

// rowInverseW into `lanes` on a triangle with perspective, which it returns; null (what
// rowAttribute then never reads) without.
const float* rowInverse(const TriangleSetup& s, int x, int y, int n, float* lanes) {
    if (!s.perspective) return nullptr;
    rowInverseW(s, x, y, n, lanes);
    return lanes;
}

// Attribute k at pixels x .. x + n − 1 of row y, as the rasteriser interpolates it: the constant,
// or planeValue, times `inv` (rowInverseW) on a triangle with perspective.
void rowAttribute(const TriangleSetup& s, int k, int x, int y, int n, const float* inv, float* dst) {
    if ((s.constMask >> k) & 1) {
        ps11::fillLanes(dst, n, s.constValue[size_t(k)]);
        return;
    }
    fillPlaneRow(s.attr[size_t(k)], s.ox, s.oy, x, y, n, dst);
    if (s.perspective)
        for (int i = 0; i < n; ++i) dst[i] *= inv[i];
}

}  // namespace

void fillRowFogDepth(const TriangleSetup& s, bool fog, bool z, int x, int y, int n, float* fogOut, float* zOut) {
    if (z) fillPlaneRow(s.z, s.ox, s.oy, x, y, n, zOut);
    if (!fog) return;
    alignas(32) float lanes[ps11::kMaxSpan];
    rowAttribute(s, kAttrSpecular + 3, x, y, n, rowInverse(s, x, y, n, lanes), fogOut);
}

bool rowKills(const ps11::TapPlan& plan, const TriangleSetup& s, int x, int y, int n, uint8_t* kept) {
    alignas(32) float lanes[ps11::kMaxSpan], c[ps11::kMaxSpan];
    const float* inv = rowInverse(s, x, y, n, lanes);
    std::memset(kept, 1, size_t(n));
    for (int set = 0; set < 8; ++set) {
        if (!((plan.killSets >> set) & 1)) continue;
        for (int k = 0; k < 3; ++k) {
            rowAttribute(s, attrTex(set, k), x, y, n, inv, c);
            for (int i = 0; i < n; ++i) kept[i] &= uint8_t(!(c[i] < 0.0f));
        }
    }
    uint8_t all = 1;
    for (int i = 0; i < n; ++i) all &= kept[i];
    return !all;
}

void tapCoords(const ps11::TapPlan& plan, int t, const TriangleSetup& s, int x, int y, int n, float* u, float* v) {
    const int set = plan.coordSet[size_t(t)];
    alignas(32) float lanes[ps11::kMaxSpan];
    const float* inv = rowInverse(s, x, y, n, lanes);
    rowAttribute(s, attrTex(set, 0), x, y, n, inv, u);
    rowAttribute(s, attrTex(set, 1), x, y, n, inv, v);
    if (!plan.projected(t)) return;
    alignas(32) float d[ps11::kMaxSpan];
    rowAttribute(s, attrTex(set, plan.divisor[size_t(t)]), x, y, n, inv, d);
    const bool zeroIsOne = (plan.zeroDivisorIsOne >> t) & 1;
    for (int i = 0; i < n; ++i) {
        u[i] = ps11::projectCoord(u[i], d[i], zeroIsOne);
        v[i] = ps11::projectCoord(v[i], d[i], zeroIsOne);
    }
}

void sampleFree(const AlignedDraw& draw, const TriangleSetup& s, int t, int x, int y, int n, QuadLevels& cache,
                ps11::Sampler* sampler, int16_t* const dst[4]) {
    const AlignedTap& tap = draw.taps[size_t(t)];
    alignas(32) float u[ps11::kMaxSpan], v[ps11::kMaxSpan];
    tapCoords(draw.plan, t, s, x, y, n, u, v);
    alignas(32) int32_t grid[4][ps11::kMaxSpan];
    if (!((draw.levelTaps.mask >> t) & 1)) {
        ps11::fastpath::Unorm8Run run;
        run.texels = tap.texels;
        run.width = tap.width, run.height = tap.height;
        run.linear = tap.linear;
        run.addressU = tap.addressU, run.addressV = tap.addressV;
        run.borderWord = tap.borderWord;
        run.scale = draw.fx12 ? 16 : 1;
        int32_t* const g[4] = {grid[0], grid[1], grid[2], grid[3]};
        draw.sample(run, n, u, v, g);
    } else {
        // Each pixel at the level, filter and mip blend its 2×2 quad picks (quadLevels), through
        // the worker's sampler (the fast kernel over runs of one level, the reference over
        // blends of two, as for the quad path).
        const QuadLevels::Entry& e =
            quadLevels(cache, s, draw.plan, t, *draw.levelTaps.texture[size_t(t)],
                       *draw.levelTaps.sampler[size_t(t)], draw.levelTaps.fixed, draw.levelTaps.weights8,
                       draw.target.color->width, x, y, n);
        thread_local ps11::LevelChoice lanes[ps11::kMaxSpan];
        for (int i = 0; i < n; ++i) lanes[i] = e.choice[size_t((x + i) >> 1)];
        ps11::SampleRequest req;
        req.stage = draw.plan.stage[size_t(t)];
        req.count = n;
        req.u = u, req.v = v;
        req.levels = lanes;
        req.precision = draw.fx12 ? ps11::Precision::Fx12 : ps11::Precision::Fx8;
        ps11::SampleResult out;
        for (int c = 0; c < 4; ++c) out.grid[c] = grid[c];
        sampler->sample(req, out);
    }
    for (int c = 0; c < 4; ++c)
        for (int i = 0; i < n; ++i) dst[c][i] = int16_t(grid[c][i]);
}

uint8_t fillRowColors(uint64_t colorAttrs, const TriangleSetup& s, int x, int y, int n,
                      float (*color)[ps11::kMaxSpan]) {
    // (Called per span: most post-processing programs read no colour.)
    const uint64_t used = colorAttrs & ((uint64_t(0xf) << kAttrDiffuse) | (uint64_t(0xf) << kAttrSpecular));
    if (!used) return 0;
    uint8_t uniform = 0;
    alignas(32) float lanes[ps11::kMaxSpan];
    const float* inv = (used & ~s.constMask) ? rowInverse(s, x, y, n, lanes) : nullptr;
    for (int k = 0; k < 8; ++k) {
        const int attr = k < 4 ? kAttrDiffuse + k : kAttrSpecular + (k - 4);
        if (!((used >> attr) & 1)) continue;
        if ((s.constMask >> attr) & 1) {
            color[k][0] = s.constValue[size_t(attr)];
            uniform = uint8_t(uniform | (1u << k));
            continue;
        }
        rowAttribute(s, attr, x, y, n, inv, color[k]);
    }
    return uniform;
}

void fillRowCoords(uint64_t attrs, const TriangleSetup& s, int x, int y, int n, float (*coords)[ps11::kMaxSpan]) {
    alignas(32) float lanes[ps11::kMaxSpan];
    const float* inv = rowInverse(s, x, y, n, lanes);
    for (int set = 0; set < kMaxTexSets; ++set)
        for (int c = 0; c < 4; ++c)
            if ((attrs >> attrTex(set, c)) & 1) rowAttribute(s, attrTex(set, c), x, y, n, inv, coords[4 * set + c]);
}

}  // namespace emu
