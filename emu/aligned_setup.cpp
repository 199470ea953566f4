// Device stage: the aligned-pass path's set-up (emu/aligned_pass.h). Whether a draw can take a
// row path, and per triangle which taps its rows tabulate: the column tables of texel pairs and
// weights, their runs of a fixed step, and where one triangle's rows join the next's. The rows
// themselves are drawn in emu/aligned_pass.cpp. Exactness: the tables hold the very texel pairs
// and weights the TextureSampler's kernels compute for the same coordinates
// (ps11::fastpath::axisTable), and the coordinates are the rasteriser's own formula (emu/raster.h
// planeValue; this file is compiled without FMA contraction so that it evaluates it alike).
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "emu/aligned_pass.h"
#include "emu/aligned_pass_kernels.h"
#include "ps11/texture_sampler_fast.h"

namespace emu {

uint64_t nextRowDrawSerial() {
    static std::atomic<uint64_t> serials{0};
    return ++serials;
}

bool prepareAlignedDraw(const ps11::Executor& executor, ps11::Precision precision,
                        const std::array<std::shared_ptr<const ps11::Texture>, 8>& textures,
                        const std::array<ps11::SamplerState, 8>& samplers, const MergeState& merge,
                        const MergeTarget& target, bool wantZ, uint64_t usedAttrs, AlignedDraw& out) {
    const bool fx12 = precision == ps11::Precision::Fx12;
    if ((precision != ps11::Precision::Fx8 && !fx12) || !target.color) return false;
    AlignedDraw d;
    if (!ps11::tapPlan(executor, d.plan, true)) return false;
    // Instructions the executor samples itself, per pixel at level 0 (as the spans of one row
    // sample them): their textures must not depend on the level of detail.
    for (int s = 0; s < 8 && d.plan.executes; ++s)
        if ((d.plan.executedStages >> s) & 1 && textures[size_t(s)] && !ps11::lodFree(*textures[size_t(s)], samplers[size_t(s)]))
            return false;
    d.fx12 = fx12;
    d.serial = nextRowDrawSerial();
    d.executor = &executor;
    d.kernels = alignedKernels(ps11::simdLevel());
    d.sample = ps11::fastpath::samplerKernels(ps11::simdLevel()).unorm8;
    for (int i = 0; i < d.plan.count; ++i) {
        const int stage = d.plan.stage[size_t(i)];
        AlignedTap& tap = d.taps[size_t(i)];
        tap.coordSet = d.plan.coordSet[size_t(i)];
        const std::shared_ptr<const ps11::Texture>& tex = textures[size_t(stage)];
        if (!tex) continue;  // (0, 0, 0, 1)
        const ps11::SamplerState& ss = samplers[size_t(stage)];
        if (tex->isVolume() || tex->storage() != ps11::TexelStorage::Unorm8) {
            // A texture the row path does not filter (signed, float, volume): the executor samples
            // the tap per pixel as run() does, where the level of detail cannot matter.
            if (!ps11::lodFree(*tex, ss)) return false;
            d.plan.executedTaps = uint8_t(d.plan.executedTaps | (1u << i));
            d.plan.executes = true;
            d.plan.executedSets = uint8_t(d.plan.executedSets | (1u << tap.coordSet));
            d.plan.executedStages = uint8_t(d.plan.executedStages | (1u << stage));
            continue;  // (not bound: no tables, no fill)
        }
        const ps11::TextureLevelInfo& li = tex->level(0);
        tap.bound = true;
        d.bound |= 1u << i;
        tap.texels = tex->unorm8() + li.offset * 4;
        tap.width = li.width;
        tap.height = li.height;
        tap.linear = ss.magFilter == ps11::Filter::Linear;
        if (!ps11::lodFree(*tex, ss)) d.levelTaps.add(i, *tex, ss, tap.coordSet);
        tap.addressU = ss.addressU;
        tap.addressV = ss.addressV;
        // The border colour's bytes (the device sets it from a D3DCOLOR: byte / 255 per channel).
        uint32_t word = 0;
        for (int c = 0; c < 4; ++c) {
            const float f = ss.border[size_t(c)] * 255.0f;
            const uint32_t b = uint32_t(std::clamp(f, 0.0f, 255.0f) + 0.5f);
            if (float(b) / 255.0f != ss.border[size_t(c)]) return false;
            word |= b << (8 * ps11::kUnorm8Byte[c]);
        }
        tap.borderWord = word;
    }
    for (int set = 0; set < kMaxTexSets; ++set)
        if ((d.plan.executedSets >> set) & 1)
            for (int c = 0; c < 4; ++c) d.executedAttrs |= usedAttrs & (uint64_t(1) << attrTex(set, c));
    d.colorAttrs = usedAttrs & ((uint64_t(0xF) << kAttrDiffuse) | (uint64_t(0xF) << kAttrSpecular));
    d.merge = merge;
    d.target = target;
    d.wantZ = wantZ;
    const D3DFORMAT f = target.color->format->format;
    const bool unorm = f == D3DFMT_A8R8G8B8 || f == D3DFMT_X8R8G8B8;
    // (A depth write comes with a depth test: MergeState::from.)
    const bool plain = unorm && !merge.alphaTest && merge.colorWrite == 0xf && (merge.depthTest || !merge.depthWrite) &&
                       (!merge.depthTest || target.depth);
    // (A register's texkill, and a depth the program writes, are known once the run is shaded:
    // its runs are merged over the pixels it keeps, the depth tested and written by the merger.)
    d.shaderDepth = wantZ && executor.writesDepth();
    d.directStore = plain && !merge.blend && !d.plan.registerKills && !d.shaderDepth;
    const bool oneOne =
        merge.srcBlend == D3DBLEND_ONE && merge.dstBlend == D3DBLEND_ONE && merge.blendOp == D3DBLENDOP_ADD &&
        (!merge.separateAlpha || (merge.srcBlendAlpha == D3DBLEND_ONE && merge.dstBlendAlpha == D3DBLEND_ONE &&
                                  merge.blendOpAlpha == D3DBLENDOP_ADD));
    d.directAdd = plain && merge.blend && oneOne && !d.plan.registerKills && !d.shaderDepth;
    d.depthFirst = (d.directStore || d.directAdd) && merge.depthTest;
    d.fogFirst = (d.directStore || d.directAdd) && merge.fog;
    d.afterDepth = merge;
    d.afterDepth.depthTest = d.afterDepth.depthWrite = false;
    bool planned = false, plannedAfter = false;
    d.mergePlan = makePlan(d.merge, target, planned);
    d.afterDepthPlan = makePlan(d.afterDepth, target, plannedAfter);
    if (!planned || !plannedAfter) return false;
    d.chainRows = !fx12 && d.kernels && ps11::chainRows(executor) && d.colorAttrs == 0 && !d.plan.executedTaps &&
                  (d.directStore || d.directAdd) && !d.depthFirst && !d.fogFirst;
    out = d;
    return true;
}

bool levelZeroOnly(const ps11::Texture& tex, const ps11::SamplerState& ss) {
    return !tex.isVolume() && ps11::lodFree(tex, ss);
}

namespace {

// The distinct values of `v` (at most `cap`; false past it).
bool addDistinct(std::vector<double>& set, double v, size_t cap) {
    if (std::find(set.begin(), set.end(), v) != set.end()) return true;
    if (set.size() >= cap) return false;
    set.push_back(v);
    return true;
}

}  // namespace

bool triangleLevels(const LevelTaps& taps, const TriangleSetup& s, int x0, int x1, TapLevels& out) {
    out = TapLevels{};
    // The quads' columns and rows: pairs from even coordinates over the triangle's pixels.
    const int cx0 = x0 & ~1, cx1 = x1 + (x1 & 1), ry0 = s.yMin & ~1, ry1 = s.yMax + (s.yMax & 1);
    if (cx0 >= cx1 || ry0 >= ry1) return false;
    std::vector<float> u(size_t(cx1 - cx0));
    // A quad's squared derivative lengths at level 0 (ps11 selectLevels): with u a function of
    // the column and v of the row (screenAligned), dx2 = ((u(x+1) − u(x))·W)² and
    // dy2 = ((v(y+1) − v(y))·H)² exactly where the coordinates are finite (the other terms are
    // +0), so a quad's choice is chooseLevel of its column's dx2 and its row's dy2.
    constexpr size_t kMaxDistinct = 16;
    std::vector<double> dx2s, dy2s;
    for (int i = 0; i < 8; ++i) {
        if (!((taps.mask >> i) & 1)) continue;
        const ps11::Texture& tex = *taps.texture[size_t(i)];
        const int set = taps.coordSet[size_t(i)];
        const double w = double(tex.level(0).width), h = double(tex.level(0).height);
        dx2s.clear();
        dy2s.clear();
        columnU(s, set, cx0, cx1 - cx0, u.data());
        for (size_t k = 0; k + 1 < u.size(); k += 2) {
            if (!std::isfinite(u[k]) || !std::isfinite(u[k + 1])) return false;
            const double d = double(u[k + 1]) * w - double(u[k]) * w;
            if (!addDistinct(dx2s, d * d, kMaxDistinct)) return false;
        }
        for (int y = ry0; y < ry1; y += 2) {
            const float v0 = rowV(s, set, y), v1 = rowV(s, set, y + 1);
            if (!std::isfinite(v0) || !std::isfinite(v1)) return false;
            const double d = double(v1) * h - double(v0) * h;
            if (!addDistinct(dy2s, d * d, kMaxDistinct)) return false;
        }
        // Every quad's rho2 = max(dx2, dy2) is one of these values at or above the other axis's least.
        const double dxLeast = *std::min_element(dx2s.begin(), dx2s.end());
        const double dyLeast = *std::min_element(dy2s.begin(), dy2s.end());
        bool first = true;
        ps11::LevelChoice pick;
        auto agree = [&](double rho2) {
            const ps11::LevelChoice c =
                ps11::chooseLevel(tex, *taps.sampler[size_t(i)], rho2, rho2, taps.fixed, taps.weights8);
            if (first) pick = c, first = false;
            return c == pick && c.slots == 1;
        };
        for (double a : dx2s)
            if (a >= dyLeast && !agree(a)) return false;
        for (double b : dy2s)
            if (b >= dxLeast && !agree(b)) return false;
        out.level[size_t(i)] = uint8_t(pick.level0);
        out.linear |= uint32_t(pick.linear) << i;
    }
    return true;
}

const QuadLevels::Entry& quadLevels(QuadLevels& cache, const TriangleSetup& s, const ps11::TapPlan& plan, int tap,
                                    const ps11::Texture& tex, const ps11::SamplerState& ss, bool fixed, bool weights8,
                                    uint32_t width, int x, int y, int n) {
    QuadLevels::Entry& e = cache.entry(&s, tap, width);
    const int qy = y & ~1, q0 = x >> 1, q1 = (x + n - 1) >> 1;  // quads [q0, q1]
    const int32_t mark = qy + 1;                                 // (stamps start at 0)
    int lo = q0;
    while (lo <= q1 && e.stamp[size_t(lo)] == mark) ++lo;
    if (lo > q1) return e;
    int hi = q1;
    while (e.stamp[size_t(hi)] == mark) --hi;
    // Quads [lo, hi]: the coordinates the quad path gives their top-left, top-right and
    // bottom-left pixels (the rasteriser interpolates helper lanes from the same planes), and its
    // choice from them.
    alignas(32) float ut[ps11::kMaxSpan], vt[ps11::kMaxSpan], ub[ps11::kMaxSpan], vb[ps11::kMaxSpan];
    for (int first = 2 * lo; first < 2 * hi + 2; first += ps11::kMaxSpan) {
        const int len = std::min(ps11::kMaxSpan, 2 * hi + 2 - first);
        tapCoords(plan, tap, s, first, qy, len, ut, vt);
        tapCoords(plan, tap, s, first, qy + 1, len, ub, vb);
        for (int q = 0; q < len; q += 2) {
            const float tl[3] = {ut[q], vt[q], 0.0f}, tr[3] = {ut[q + 1], vt[q + 1], 0.0f}, bl[3] = {ub[q], vb[q], 0.0f};
            const size_t qi = size_t((first + q) >> 1);
            e.choice[qi] = ps11::quadLevel(tex, ss, tl, tr, bl, fixed, weights8);
            e.stamp[qi] = mark;
        }
    }
    return e;
}

void setTapLevels(AlignedDraw& draw, const TapLevels& levels) {
    bool changed = false;
    for (int i = 0; i < draw.plan.count; ++i) {
        if (!((draw.levelTaps.mask >> i) & 1)) continue;
        AlignedTap& tap = draw.taps[size_t(i)];
        const ps11::Texture& tex = *draw.levelTaps.texture[size_t(i)];
        const ps11::TextureLevelInfo& li = tex.level(levels.level[size_t(i)]);
        const uint8_t* texels = tex.unorm8() + li.offset * 4;
        const bool linear = (levels.linear >> i) & 1;
        changed |= texels != tap.texels || linear != tap.linear;
        tap.texels = texels;
        tap.width = li.width;
        tap.height = li.height;
        tap.linear = linear;
    }
    if (changed) draw.serial = nextRowDrawSerial();
}

bool screenAligned(const ps11::TapPlan& plan, const TriangleSetup& s) {
    if (s.perspective) return false;
    for (int i = 0; i < plan.count; ++i) {
        if (plan.projected(i)) return false;
        const int ku = attrTex(plan.coordSet[size_t(i)], 0), kv = ku + 1;
        if (!((s.constMask >> ku) & 1) && s.attr[size_t(ku)].dy != 0.0) return false;
        if (!((s.constMask >> kv) & 1) && s.attr[size_t(kv)].dx != 0.0) return false;
    }
    return true;
}

void columnU(const TriangleSetup& s, int set, int x0, int n, float* u) {
    const int k = attrTex(set, 0);
    if ((s.constMask >> k) & 1) {
        std::fill_n(u, n, s.constValue[size_t(k)]);
        return;
    }
    fillPlaneRow(s.attr[size_t(k)], s.ox, s.oy, x0, s.yMin, n, u);  // (u does not depend on the row)
}

float rowV(const TriangleSetup& s, int set, int y) {
    const int k = attrTex(set, 1);
    return (s.constMask >> k) & 1 ? s.constValue[size_t(k)] : planeValue(s.attr[size_t(k)], s.ox, s.oy, 0, y);
}

bool tableColumns(const TriangleSetup& s, int& x0, int& x1) {
    int xlo = 0, xhi = 0;
    if (!coveredColumns(s, xlo, xhi)) return false;
    const bool narrow = 2 * (xhi - xlo) < s.clip.x1 - s.clip.x0;
    x0 = narrow ? xlo : s.clip.x0;
    x1 = narrow ? xhi : s.clip.x1;
    return true;
}

bool rowPathColumns(const ps11::TapPlan& plan, const TriangleSetup& s, int& x0, int& x1) {
    // (covering nothing: the quad path finds that too)
    return screenAligned(plan, s) && tableColumns(s, x0, x1);
}

uint32_t freeTaps(const ps11::TapPlan& plan, uint32_t bound, const TriangleSetup& s) {
    uint32_t mask = 0;
    for (int i = 0; i < plan.count; ++i) {
        if (!((bound >> i) & 1)) continue;
        const int ku = attrTex(plan.coordSet[size_t(i)], 0), kv = ku + 1;
        const bool cu = (s.constMask >> ku) & 1, cv = (s.constMask >> kv) & 1;
        const bool free = plan.projected(i) ||
                          (s.perspective ? !(cu && cv)
                                         : (!cu && s.attr[size_t(ku)].dy != 0.0) || (!cv && s.attr[size_t(kv)].dx != 0.0));
        if (free) mask |= 1u << i;
    }
    return mask;
}

int rowPathKind(const ps11::TapPlan& plan, uint32_t bound, const TriangleSetup& s, int& x0, int& x1) {
    if (!tableColumns(s, x0, x1)) return 0;
    return s.perspective || freeTaps(plan, bound, s) ? 2 : 1;
}

namespace {

// Whether attribute k takes the same value at every pixel of row ya in triangle a as of row yb
// in triangle b, as the row paths compute it (planeValue: float row base plus float step times
// the column).
bool sameOnRow(const TriangleSetup& a, const TriangleSetup& b, int k, int ya, int yb) {
    const bool ca = (a.constMask >> k) & 1, cb = (b.constMask >> k) & 1;
    if (ca != cb) return false;
    auto bits = [](float f) { return std::bit_cast<uint32_t>(f); };
    if (ca) return bits(a.constValue[size_t(k)]) == bits(b.constValue[size_t(k)]);
    const Plane &pa = a.attr[size_t(k)], &pb = b.attr[size_t(k)];
    return bits(float(pa.dx)) == bits(float(pb.dx)) &&
           bits(float(planeRowBase(pa, a.ox, a.oy, ya))) == bits(float(planeRowBase(pb, b.ox, b.oy, yb)));
}

}  // namespace

bool sameColumnTables(const TriangleSetup& a, const TriangleSetup& b, const ps11::TapPlan& plan) {
    // (u has no dy on the row paths: its row base is that of any row, yMin's as columnU takes it)
    for (int i = 0; i < plan.count; ++i)
        if (!sameOnRow(a, b, attrTex(plan.coordSet[size_t(i)], 0), a.yMin, b.yMin)) return false;
    return true;
}

JoinPlan joinPlan(const TriangleSetup& s, const TriangleSetup& next, bool sharedTables, const ps11::TapPlan& plan,
                  uint64_t colorAttrs) {
    JoinPlan jp;
    auto bits = [](float f) { return std::bit_cast<uint32_t>(f); };
    auto bits64 = [](double d) { return std::bit_cast<uint64_t>(d); };
    // With perspective the attributes compared are the planes of attr·rhw: rhw must agree too.
    if (s.perspective != next.perspective || (s.perspective && bits(float(s.rhw.dx)) != bits(float(next.rhw.dx)))) {
        jp.never = true;
        return jp;
    }
    jp.perspective = s.perspective;
    const bool sameOrigin = bits64(s.ox) == bits64(next.ox) && bits64(s.oy) == bits64(next.oy);
    // sameOnRow's tests that do not depend on the row, once.
    auto add = [&](int k) {
        const bool ca = (s.constMask >> k) & 1, cb = (next.constMask >> k) & 1;
        if (ca != cb || (ca && bits(s.constValue[size_t(k)]) != bits(next.constValue[size_t(k)]))) jp.never = true;
        if (ca || cb) return;
        const Plane &pa = s.attr[size_t(k)], &pb = next.attr[size_t(k)];
        if (bits(float(pa.dx)) != bits(float(pb.dx))) jp.never = true;
        const bool samePlane = sameOrigin && bits64(pa.base) == bits64(pb.base) && bits64(pa.dx) == bits64(pb.dx) &&
                               bits64(pa.dy) == bits64(pb.dy);
        if (!samePlane) jp.rows |= uint64_t(1) << k;
    };
    for (int i = 0; i < plan.count; ++i) {
        const int ku = attrTex(plan.coordSet[size_t(i)], 0);
        if (!sharedTables) add(ku);
        add(ku + 1);
        if (plan.projected(i)) add(attrTex(plan.coordSet[size_t(i)], plan.divisor[size_t(i)]));
    }
    for (int set = 0; set < 8; ++set)
        if ((plan.killSets >> set) & 1)
            for (int k = 0; k < 3; ++k) add(attrTex(set, k));
    for (int k = 0; k < kAttrCount; ++k)
        if ((colorAttrs >> k) & 1) add(k);
    return jp;
}

bool joinRow(const TriangleSetup& s, const TriangleSetup& next, const JoinPlan& plan, int y, const RowWindow* windows,
             size_t count, int& xl, int& xr) {
    if (plan.never) return false;
    int nl = 0, nr = 0;
    if (!rowSpan(next, y, windows, count, nl, nr) || (nl != xr && nr != xl)) return false;
    auto bits = [](float f) { return std::bit_cast<uint32_t>(f); };
    if (plan.perspective &&
        bits(float(planeRowBase(s.rhw, s.ox, s.oy, y))) != bits(float(planeRowBase(next.rhw, next.ox, next.oy, y))))
        return false;
    for (uint64_t m = plan.rows; m; m &= m - 1)
        if (!sameOnRow(s, next, std::countr_zero(m), y, y)) return false;
    xl = std::min(xl, nl), xr = std::max(xr, nr);
    return true;
}

bool pairColumns(int a0, int a1, int b0, int b1, const ClipRect& clip, std::pair<int, int>& out) {
    const int width = clip.x1 - clip.x0;
    const bool narrow = a1 - a0 < width && b1 - b0 < width;
    if (!narrow || std::max(a0, b0) >= std::min(a1, b1)) return false;
    out = {std::min(a0, b0), std::max(a1, b1)};
    return true;
}

bool prepareAlignedTriangle(const AlignedDraw& draw, const TriangleSetup& s, AlignedTriangle& out,
                            const std::pair<int, int>* columns) {
    if (!rowPathKind(draw.plan, draw.bound, s, out.x0, out.x1)) return false;
    if (columns) out.x0 = columns->first, out.x1 = columns->second;
    out.levelFree = 0;
    fillAlignedTables(draw, s, out);
    return true;
}

void fillAlignedTables(const AlignedDraw& draw, const TriangleSetup& s, AlignedTriangle& out) {
    out.configs.clear();
    out.freeTaps = freeTaps(draw.plan, draw.bound, s) | out.levelFree;
    const int n = out.x1 - out.x0;
    thread_local std::vector<float> u;
    u.resize(size_t(std::max(n, 0)));
    for (int i = 0; i < draw.plan.count; ++i) {
        const AlignedTap& tap = draw.taps[size_t(i)];
        AlignedTriangle::Columns& cols = out.taps[size_t(i)];
        cols.runs.clear();
        cols.configCount = 0;
        cols.tabulatedQ16 = false;
        if (!tap.bound || ((out.freeTaps >> i) & 1)) {  // no table (the triangle may be a previous chunk's or draw's)
            cols.off0.clear(), cols.off1.clear(), cols.w.clear(), cols.run.clear();
            continue;
        }
        columnU(s, tap.coordSet, out.x0, n, u.data());
        cols.off0.resize(size_t(n));
        cols.off1.resize(size_t(n));
        cols.w.resize(size_t(n));
        ps11::fastpath::axisTable(tap.addressU, tap.linear, n, u.data(), tap.width, cols.off0.data(), cols.off1.data(),
                                  cols.w.data());
        // Long runs (vector kernels only): at least kMinAlignedRun columns whose first texel
        // i0 steps by a fixed 1..kMaxAlignedStep texels with one weight, none on the border, and
        // i1 = i0 + 1 when the weight is not 0 (the H rows read texels i0 and i0 + 1).
        cols.run.assign(size_t(n), -1);
        auto ok = [&](int x) {
            const int32_t i0 = cols.off0[size_t(x)], w = cols.w[size_t(x)];
            return i0 >= 0 && (w == 0 || cols.off1[size_t(x)] == i0 + 1);
        };
        for (int x = 0; draw.kernels && x < n;) {
            int e = x + 1;
            const int32_t step = x + 1 < n ? cols.off0[size_t(x + 1)] - cols.off0[size_t(x)] : 0;
            if (ok(x) && step >= 1 && step <= kMaxAlignedStep)
                while (e < n && ok(e) && cols.w[size_t(e)] == cols.w[size_t(x)] &&
                       cols.off0[size_t(e)] - cols.off0[size_t(e - 1)] == step)
                    ++e;
            if (e - x < kMinAlignedRun) {
                ++x;
                continue;
            }
            // The H-row configuration: shared by every tap on this texture with the same weight,
            // step and phase; its range grows to cover the run.
            const int32_t i0 = cols.off0[size_t(x)], wx = cols.w[size_t(x)];
            const int32_t phase = i0 % step, j0 = (i0 - phase) / step;
            int ci = -1;
            for (size_t c = 0; c < out.configs.size(); ++c) {
                const HConfig& h = out.configs[c];
                if (h.texels == tap.texels && h.wx == wx && h.step == step && h.phase == phase) ci = int(c);
            }
            if (ci < 0) {
                out.configs.push_back(HConfig{tap.texels, wx, step, phase, j0, j0 + (e - x), 0, 0});
                out.configs.back().rowTexels = int32_t(tap.width);
                ci = int(out.configs.size()) - 1;
            }
            HConfig& h = out.configs[size_t(ci)];
            h.jlo = std::min(h.jlo, j0);
            h.jhi = std::max(h.jhi, j0 + (e - x));
            int slot = -1;
            for (int c = 0; c < cols.configCount; ++c)
                if (cols.configs[size_t(c)] == ci) slot = c;
            if (slot < 0 && cols.configCount < kMaxTapConfigs) {
                slot = cols.configCount++;
                cols.configs[size_t(slot)] = ci;
            }
            if (slot >= 0) {
                cols.runs.push_back(AlignedTriangle::Run{out.x0 + x, out.x0 + e, j0, slot});
                std::fill(cols.run.begin() + x, cols.run.begin() + e, int32_t(cols.runs.size() - 1));
            }
            x = e;
        }
        // Tabulated runs over the columns left (a magnified tap: step 0, a weight per column):
        // at least kMinAlignedRun columns with both texels off the border (or weight 0), filtered
        // from H rows built per column from the table; one configuration per tap.
        auto tabOk = [&](int x) {
            return cols.run[size_t(x)] < 0 && cols.off0[size_t(x)] >= 0 &&
                   (cols.w[size_t(x)] == 0 || cols.off1[size_t(x)] >= 0);
        };
        int tabSlot = -1, tabConfig = -1;
        for (int x = 0; draw.kernels && x < n;) {
            if (!tabOk(x)) {
                ++x;
                continue;
            }
            int e = x + 1;
            while (e < n && tabOk(e)) ++e;
            if (e - x >= kMinAlignedRun && tabSlot < 0 && cols.configCount < kMaxTapConfigs) {
                HConfig h{tap.texels, -2, 0, 0, out.x0 + x, out.x0 + e, 0, 0};
                out.configs.push_back(h);
                tabConfig = int(out.configs.size()) - 1;
                tabSlot = cols.configCount++;
                cols.configs[size_t(tabSlot)] = tabConfig;
            }
            if (e - x >= kMinAlignedRun && tabSlot >= 0) {
                HConfig& h = out.configs[size_t(tabConfig)];
                h.jlo = std::min(h.jlo, out.x0 + x);
                h.jhi = std::max(h.jhi, out.x0 + e);
                cols.runs.push_back(AlignedTriangle::Run{out.x0 + x, out.x0 + e, out.x0 + x, tabSlot, true});
                std::fill(cols.run.begin() + x, cols.run.begin() + e, int32_t(cols.runs.size() - 1));
            }
            x = e;
        }
        // Texel indices to byte offsets within a row (−1 stays the border). Weight 0 reads only
        // the first texel: its second becomes the first (the same sum, and tabulated H rows read
        // both).
        for (int x = 0; x < n; ++x) {
            if (cols.off0[size_t(x)] >= 0) cols.off0[size_t(x)] *= 4;
            if (cols.off1[size_t(x)] >= 0) cols.off1[size_t(x)] *= 4;
            if (cols.w[size_t(x)] == 0 && cols.off0[size_t(x)] >= 0) cols.off1[size_t(x)] = cols.off0[size_t(x)];
        }
        if (tabConfig >= 0) {
            HConfig& h = out.configs[size_t(tabConfig)];
            const size_t at = size_t(h.jlo - out.x0), len = size_t(h.jhi - h.jlo);
            h.rowTexels = int32_t(tap.width);
            h.off0 = cols.off0.data() + at;
            h.off1 = cols.off1.data() + at;
            h.w = cols.w.data() + at;
            uint64_t hash = 1469598103934665603ull;
            for (size_t k = 0; k < len; ++k)
                for (const int32_t v : {h.off0[k], h.off1[k], h.w[k]}) hash = (hash ^ uint32_t(v)) * 1099511628211ull;
            h.hash = hash;
            h.q16 = std::all_of(h.w, h.w + len, [](int32_t w) { return w % 16 == 0; });
            // (Tabulated triangles have no perspective: v moves by one step a row.)
            const float dv = (rowV(s, tap.coordSet, s.yMin + 1) - rowV(s, tap.coordSet, s.yMin)) * float(tap.height);
            h.uncached = std::abs(dv) >= (tap.linear ? 2.0f : 1.0f);
            cols.tabulatedQ16 = h.q16;
            static std::atomic<uint64_t> tableIds{0};
            h.tableId = ++tableIds;
        }
    }
    // Each texture's staged range: the texels every configuration on it reads. (Tabulated rows and
    // point reductions, hRow's kind A at a step of 2 or more, read straight from the texel rows.)
    auto staged = [](const HConfig& h) { return h.wx != -2 && !(h.wx == 0 && h.step >= 2); };
    for (HConfig& h : out.configs) {
        if (!staged(h)) continue;
        h.stageLo = h.step * h.jlo + h.phase;
        h.stageHi = h.step * (h.jhi - 1) + h.phase + 1 + (h.wx != 0);
    }
    for (HConfig& h : out.configs)
        for (const HConfig& o : out.configs)
            if (o.texels == h.texels && staged(h) && staged(o))
                h.stageLo = std::min(h.stageLo, o.stageLo), h.stageHi = std::max(h.stageHi, o.stageHi);
    // Run starts relative to their H row's first element, now that the ranges are final.
    for (int i = 0; i < draw.plan.count; ++i) {
        AlignedTriangle::Columns& cols = out.taps[size_t(i)];
        for (AlignedTriangle::Run& r : cols.runs) r.j0 -= out.configs[size_t(cols.configs[size_t(r.config)])].jlo;
    }
}

}  // namespace emu
