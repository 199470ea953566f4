// The software sampler stage: level selection from 2x2 quads, per-axis texel addressing
// (wrap / mirror / clamp / border / mirroronce) and the exact weighted sums of
// docs/precision.md "Sampling" (8-bit weights, one round-half-even in fx profiles; float32 in
// float profiles) on the reference path, and the dispatch of 8-bit 2-D fx lookups to the fast
// kernels of texture_sampler_fast*.cpp (docs/textures.md "Fast path").
#include "ps11/texture_sampler.h"

#include "ps11/texture_sampler_fast.h"
#include "ps11/texture_sampler_internal.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace ps11 {

namespace {

constexpr int kSlots = 2;  // mip levels blended per lane (linear mip filter)

// round_half_even(v / 2^s) for s >= 1, branch-free: adding half - 1 plus the quotient's low
// bit carries exactly when the remainder is above half, or equal to it with an odd quotient.
inline int64_t roundShift(int64_t v, int s) { return (v + ((int64_t(1) << (s - 1)) - 1) + ((v >> s) & 1)) >> s; }

// Per lane: which levels (slot 0, and slot 1 for a linear mip blend) and which filter.
struct LaneLevels {
    uint8_t level[kSlots][kMaxSpan];
    uint8_t slots[kMaxSpan];
    uint8_t linear[kMaxSpan];  // 1 = bilinear/trilinear taps, 0 = point
    int32_t mipW[kMaxSpan];    // fx: weight of slot 1 in 0..256 (slot 0 gets 256 - w)
    float mipF[kMaxSpan];      // float: weight of slot 1
};

// Per lane and axis: the two texel indices after the address mode (-1 = border) and the weight
// of i1 (fx: 0..256, float: [0, 1]).
struct AxisTaps {
    int32_t i0[kMaxSpan], i1[kMaxSpan];
    int32_t w[kMaxSpan];
    float f[kMaxSpan];
};

template <TextureAddress Mode>
void axisPassT(int count, const float* coord, const uint32_t* extent, const uint8_t* level, const uint8_t* linear,
               AxisTaps& out) {
    for (int i = 0; i < count; ++i) {
        const uint32_t n = extent[level[i]];
        double fl, fr;
        texelPosition(coord[i], n, linear[i] != 0, fl, fr);
        addressPair<Mode>(fl, n, out.i0[i], out.i1[i]);
        out.w[i] = linear[i] ? weight8(fr) : 0;  // 8-bit weight, ties to even
        out.f[i] = linear[i] ? float(fr) : 0.0f;
    }
}

void axisPass(TextureAddress mode, int count, const float* coord, const uint32_t* extent, const uint8_t* level,
              const uint8_t* linear, AxisTaps& out) {
    switch (mode) {
        case TextureAddress::Wrap:
            return axisPassT<TextureAddress::Wrap>(count, coord, extent, level, linear, out);
        case TextureAddress::Mirror:
            return axisPassT<TextureAddress::Mirror>(count, coord, extent, level, linear, out);
        case TextureAddress::Clamp:
            return axisPassT<TextureAddress::Clamp>(count, coord, extent, level, linear, out);
        case TextureAddress::Border:
            return axisPassT<TextureAddress::Border>(count, coord, extent, level, linear, out);
        case TextureAddress::MirrorOnce:
            return axisPassT<TextureAddress::MirrorOnce>(count, coord, extent, level, linear, out);
    }
    axisPassT<TextureAddress::Wrap>(count, coord, extent, level, linear, out);  // invalid state: wrap
}

// Texel sources: 4 channels of texel `i` (level offset included) in the profile's terms.
struct U8Grid {
    const uint8_t* p;
    int64_t scale;  // 1 (fx8) or 16 (fx12)
    void get(size_t i, int64_t t[4]) const {
        for (int c = 0; c < 4; ++c) t[c] = int64_t(p[i * 4 + size_t(kUnorm8Byte[c])]) * scale;
    }
};
struct IntGrid {
    const int32_t* p;
    void get(size_t i, int64_t t[4]) const {
        for (int c = 0; c < 4; ++c) t[c] = p[i * 4 + size_t(c)];
    }
};
struct U8Float {
    const uint8_t* p;
    const float* table;
    void get(size_t i, float t[4]) const {
        for (int c = 0; c < 4; ++c) t[c] = table[p[i * 4 + size_t(kUnorm8Byte[c])]];
    }
};
struct ValueFloat {
    const float* p;
    void get(size_t i, float t[4]) const {
        for (int c = 0; c < 4; ++c) t[c] = p[i * 4 + size_t(c)];
    }
};
// A float texture read in place (Texture::floatTexels): its texels decoded as they are read, and
// in fx profiles each channel's grid taken then (texelGridOf), so no first read converts it whole.
struct RowFloat {
    FloatTexels f;
    void get(size_t i, float t[4]) const { f.get(i, t); }
};
struct RowGrid {
    FloatTexels f;
    Precision p;
    void get(size_t i, int64_t t[4]) const {
        float v[4];
        f.get(i, v);
        for (int c = 0; c < 4; ++c) t[c] = texelGridOf(v[c], p);
    }
};

struct CombineInput {
    int count;
    const TextureLevelInfo* levels;
    const LaneLevels* lanes;
    const AxisTaps (*taps)[3];  // [slot][axis]
};

// One tap: texel (ix, iy, iz) of a level, or the border colour when any index is -1.
template <class Src, class T>
inline void tap(const Src& src, const TextureLevelInfo& li, int32_t ix, int32_t iy, int32_t iz, const T* border,
                T t[4]) {
    if ((ix | iy | iz) < 0) {
        for (int c = 0; c < 4; ++c) t[c] = border[c];
        return;
    }
    src.get(li.offset + (size_t(iz) * li.height + size_t(iy)) * li.width + size_t(ix), t);
}

// fx: every tap weighted exactly (denominator 2^24 per level, 2^8 for the mip blend), one
// round-half-even at the end (docs/precision.md "Sampling").
template <class Src, bool Volume>
void combineFx(const CombineInput& in, const Src& src, const int64_t* border, int32_t* const* dst) {
    const LaneLevels& L = *in.lanes;
    for (int i = 0; i < in.count; ++i) {
        int64_t acc[4] = {0, 0, 0, 0};
        const int slots = L.slots[i];
        for (int s = 0; s < slots; ++s) {
            const TextureLevelInfo& li = in.levels[L.level[s][i]];
            const AxisTaps& ax = in.taps[s][0];
            const AxisTaps& ay = in.taps[s][1];
            const AxisTaps& az = in.taps[s][2];
            const int64_t mw = slots == 1 ? 256 : s == 0 ? 256 - L.mipW[i] : L.mipW[i];
            int64_t t[4];
            if (!L.linear[i]) {
                tap(src, li, ax.i0[i], ay.i0[i], Volume ? az.i0[i] : 0, border, t);
                for (int c = 0; c < 4; ++c) acc[c] += t[c] * (mw << 24);
                continue;
            }
            const int64_t wx[2] = {256 - ax.w[i], ax.w[i]}, wy[2] = {256 - ay.w[i], ay.w[i]};
            const int64_t wz[2] = {Volume ? 256 - az.w[i] : 256, Volume ? az.w[i] : 0};
            const int32_t ix[2] = {ax.i0[i], ax.i1[i]}, iy[2] = {ay.i0[i], ay.i1[i]};
            const int32_t iz[2] = {Volume ? az.i0[i] : 0, Volume ? az.i1[i] : 0};
            for (int z = 0; z < (Volume ? 2 : 1); ++z)
                for (int y = 0; y < 2; ++y)
                    for (int x = 0; x < 2; ++x) {
                        tap(src, li, ix[x], iy[y], iz[z], border, t);
                        const int64_t w = wx[x] * wy[y] * wz[z] * mw;
                        for (int c = 0; c < 4; ++c) acc[c] += t[c] * w;
                    }
        }
        for (int c = 0; c < 4; ++c) dst[c][i] = int32_t(roundShift(acc[c], 32));
    }
}

inline float lerpf(float a, float b, float f) { return (1.0f - f) * a + f * b; }

// float/ideal: float32 weights, separable lerps u, then v, then w, then the mip blend.
template <class Src, bool Volume>
void combineFloat(const CombineInput& in, const Src& src, const float* border, float* const* dst) {
    const LaneLevels& L = *in.lanes;
    for (int i = 0; i < in.count; ++i) {
        float res[kSlots][4];
        const int slots = L.slots[i];
        for (int s = 0; s < slots; ++s) {
            const TextureLevelInfo& li = in.levels[L.level[s][i]];
            const AxisTaps& ax = in.taps[s][0];
            const AxisTaps& ay = in.taps[s][1];
            const AxisTaps& az = in.taps[s][2];
            if (!L.linear[i]) {
                tap(src, li, ax.i0[i], ay.i0[i], Volume ? az.i0[i] : 0, border, res[s]);
                continue;
            }
            float plane[2][4];
            for (int z = 0; z < (Volume ? 2 : 1); ++z) {
                const int32_t iz = Volume ? (z ? az.i1[i] : az.i0[i]) : 0;
                float t00[4], t10[4], t01[4], t11[4];
                tap(src, li, ax.i0[i], ay.i0[i], iz, border, t00);
                tap(src, li, ax.i1[i], ay.i0[i], iz, border, t10);
                tap(src, li, ax.i0[i], ay.i1[i], iz, border, t01);
                tap(src, li, ax.i1[i], ay.i1[i], iz, border, t11);
                for (int c = 0; c < 4; ++c)
                    plane[z][c] = lerpf(lerpf(t00[c], t10[c], ax.f[i]), lerpf(t01[c], t11[c], ax.f[i]), ay.f[i]);
            }
            for (int c = 0; c < 4; ++c) res[s][c] = Volume ? lerpf(plane[0][c], plane[1][c], az.f[i]) : plane[0][c];
        }
        for (int c = 0; c < 4; ++c) dst[c][i] = slots == 1 ? res[0][c] : lerpf(res[0][c], res[1][c], L.mipF[i]);
    }
}

Filter effective(Filter f) { return f == Filter::Linear ? Filter::Linear : Filter::Point; }

}  // namespace

bool lodFree(const Texture& tex, const SamplerState& st) {
    return (tex.levelCount() == 1 || st.mipFilter == Filter::None) &&
           effective(st.magFilter) == effective(st.minFilter);
}

// rho = the longer of the two derivative vectors, LOD = log2(rho). Mag filter at LOD <= 0, else
// min filter; mip none: level 0; point: nearest level (ties up); linear: the two levels around
// LOD with an 8-bit weight (fx, and the float profile's 8-bit weights).
LevelChoice chooseLevel(const Texture& tex, const SamplerState& st, double dx2, double dy2, bool fixed, bool weights8) {
    const int levels = tex.levelCount();
    const double rho2 = std::max(dx2, dy2);
    LevelChoice c;
    // LOD > 0 exactly where rho2 > 1 (log2 is monotone and log2(1) = 0; a NaN LOD counts as 0):
    // a magnified quad needs no log.
    if (!(rho2 > 1.0)) {
        c.linear = effective(st.magFilter) == Filter::Linear;
        return c;
    }
    const double lod = 0.5 * std::log2(rho2);  // log2(sqrt(rho2)), > 0
    if (levels > 1) {
        // floor(x) >= k exactly where x >= k for an integer k; below that, 0 < x < 2^31 and the
        // conversion's truncation is the floor.
        if (st.mipFilter == Filter::Point) {
            const double n = lod + 0.5;
            c.level0 = n >= double(levels - 1) ? levels - 1 : int(n);
        } else if (st.mipFilter == Filter::Linear) {
            if (lod >= double(levels - 1)) {
                c.level0 = levels - 1;
            } else {
                const double a = double(int(lod));
                c.level0 = int(a);
                c.level1 = c.level0 + 1;
                const double frac = lod - a;
                if (fixed || weights8) {
                    c.mipW = weight8(frac);
                    if (c.mipW == 256) c.level0 = c.level1;  // exactly the upper level
                    c.slots = c.mipW == 0 || c.mipW == 256 ? 1 : 2;
                    c.mipF = float(c.mipW) / 256.0f;
                } else {
                    c.mipF = float(frac);
                    c.slots = c.mipF == 0.0f ? 1 : 2;
                }
            }
        }
    }
    c.linear = effective(st.minFilter) == Filter::Linear;
    return c;
}

namespace {

// A quad's squared derivative lengths in level-0 texels (quadLevel): size holds level 0's
// extents, axes is 2 or 3 (a volume).
inline void quadDerivatives(const double size[3], int axes, const float tl[3], const float tr[3], const float bl[3],
                            double& dx2, double& dy2) {
    dx2 = 0, dy2 = 0;
    for (int a = 0; a < axes; ++a) {
        const double c0 = double(tl[a]) * size[a];
        const double ddx = double(tr[a]) * size[a] - c0, ddy = double(bl[a]) * size[a] - c0;
        dx2 += ddx * ddx;
        dy2 += ddy * ddy;
    }
}

}  // namespace

LevelChoice quadLevel(const Texture& tex, const SamplerState& st, const float tl[3], const float tr[3],
                      const float bl[3], bool fixed, bool weights8) {
    const double size[3] = {double(tex.level(0).width), double(tex.level(0).height), double(tex.level(0).depth)};
    double dx2, dy2;
    quadDerivatives(size, tex.isVolume() ? 3 : 2, tl, tr, bl, dx2, dy2);
    return chooseLevel(tex, st, dx2, dy2, fixed, weights8);
}

namespace {

// Lanes [i, i + 4) of L take choice c.
inline void setQuad(LaneLevels& L, int i, const LevelChoice& c) {
    auto bytes = [&](uint8_t* p, int v) {
        const uint32_t word = uint32_t(uint8_t(v)) * 0x01010101u;
        std::memcpy(p + i, &word, 4);
    };
    bytes(L.level[0], c.level0), bytes(L.level[1], c.level1), bytes(L.slots, c.slots), bytes(L.linear, c.linear);
    for (int k = 0; k < 4; ++k) L.mipW[i + k] = c.mipW, L.mipF[i + k] = c.mipF;
}

// Lane i of L takes choice c.
inline void setLane(LaneLevels& L, int i, const LevelChoice& c) {
    L.level[0][i] = uint8_t(c.level0);
    L.level[1][i] = uint8_t(c.level1);
    L.slots[i] = uint8_t(c.slots);
    L.linear[i] = c.linear;
    L.mipW[i] = c.mipW;
    L.mipF[i] = c.mipF;
}

// Level selection (docs/textures.md "Level of detail"): per 2x2 quad, the screen derivatives of
// (u*W, v*H, w*D) at level 0 from the top-left lane, then chooseLevel (quadLevel); or the
// caller's choice per lane (SampleRequest::levels).
void selectLevels(const SampleRequest& req, int count, const float* const coord[3], const Texture& tex,
                  const SamplerState& st, bool fixed, bool weights8, LaneLevels& L,
                  const fastpath::SamplerKernels* kernels = nullptr) {
    const bool magLinear = effective(st.magFilter) == Filter::Linear;
    if (req.levels) {
        for (int i = 0; i < count; ++i) setLane(L, i, req.levels[i]);
        return;
    }
    // Without quads, or when every LOD gives level 0 with one filter (one level or no mip
    // filter, and MIN = MAG), no LOD is computed.
    if (!req.quads || lodFree(tex, st)) {
        for (int i = 0; i < count; ++i)
            L.level[0][i] = L.level[1][i] = 0, L.slots[i] = 1, L.linear[i] = magLinear, L.mipW[i] = 0, L.mipF[i] = 0.0f;
        return;
    }
    const double size[3] = {double(tex.level(0).width), double(tex.level(0).height), double(tex.level(0).depth)};
    const int axes = tex.isVolume() ? 3 : 2;
    int first = 0;  // the quads from here on: chooseLevel
    if (kernels && (fixed || weights8) && axes == 2) {
        // The fast paths' 8-bit weights on a 2-D texture: the SIMD level's chooseQuadLevels for the span's
        // first quads; those it leaves (slots 0) to chooseLevel.
        constexpr int kQuads = kMaxSpan / 4;
        alignas(32) double rho2[kQuads];
        alignas(16) int32_t l0[kQuads], l1[kQuads], slots[kQuads], mipW[kQuads], linear[kQuads];
        fastpath::QuadLevelRun run;
        run.levels = tex.levelCount();
        run.mipFilter = st.mipFilter == Filter::Point || st.mipFilter == Filter::Linear ? st.mipFilter : Filter::None;
        run.minLinear = effective(st.minFilter) == Filter::Linear, run.magLinear = magLinear;
        run.width = size[0], run.height = size[1];
        const int done = kernels->chooseQuadLevels(run, count, coord[0], coord[1], rho2, l0, l1, slots, mipW, linear);
        for (int k = 0; k < done; ++k) {
            LevelChoice c;
            if (slots[k] == 0) {
                c = chooseLevel(tex, st, rho2[k], rho2[k], fixed, weights8);  // (max(r, r) = r)
            } else {
                c.level0 = l0[k], c.level1 = l1[k], c.slots = slots[k], c.linear = linear[k] != 0;
                c.mipW = mipW[k], c.mipF = float(mipW[k]) / 256.0f;
            }
            setQuad(L, 4 * k, c);
        }
        first = 4 * done;
    }
    // quadLevel per quad; a quad whose derivatives equal the last computed quad's takes its
    // choice (chooseLevel depends on them alone).
    double lastX = std::numeric_limits<double>::quiet_NaN(), lastY = lastX;
    LevelChoice c;
    for (int q = first; q < count; q += 4) {
        const int tl = q, tr = q + 1 < count ? q + 1 : q, bl = q + 2 < count ? q + 2 : q;
        const float ctl[3] = {coord[0][tl], coord[1][tl], coord[2][tl]};
        const float ctr[3] = {coord[0][tr], coord[1][tr], coord[2][tr]};
        const float cbl[3] = {coord[0][bl], coord[1][bl], coord[2][bl]};
        double dx2, dy2;
        quadDerivatives(size, axes, ctl, ctr, cbl, dx2, dy2);
        if (!(dx2 == lastX && dy2 == lastY)) {  // (NaN never equals: computed again)
            c = chooseLevel(tex, st, dx2, dy2, fixed, weights8);
            lastX = dx2, lastY = dy2;
        }
        for (int i = q; i < std::min(q + 4, count); ++i) setLane(L, i, c);
    }
}

alignas(64) const float kZeros[kMaxSpan] = {};

}  // namespace

TextureSampler::TextureSampler(bool fastPath) : m_fastPath(fastPath) {
    for (int i = 0; i < kMaxSamplerStages; ++i) setSamplerState(i, SamplerState{});
}

bool TextureSampler::bind(int stage, std::shared_ptr<const Texture> texture) {
    if (stage < 0 || stage >= kMaxSamplerStages) return false;
    m_stages[size_t(stage)].texture = std::move(texture);
    return true;
}

bool TextureSampler::setSamplerState(int stage, const SamplerState& state) {
    if (stage < 0 || stage >= kMaxSamplerStages) return false;
    Stage& s = m_stages[size_t(stage)];
    s.state = state;
    for (size_t c = 0; c < 4; ++c) {
        // The border colour on the fx grids, rounded half-even (docs/textures.md).
        s.borderGrid8[c] = std::clamp(toGrid(double(state.border[c]), Precision::Fx8), -kMaxTexelGrid, kMaxTexelGrid);
        s.borderGrid12[c] = std::clamp(toGrid(double(state.border[c]), Precision::Fx12), -kMaxTexelGrid, kMaxTexelGrid);
    }
    return true;
}

bool TextureSampler::hasTexture(int stage) const {
    return stage >= 0 && stage < kMaxSamplerStages && m_stages[size_t(stage)].texture != nullptr;
}

namespace {

// The reference path (docs/textures.md "Sampling"): level selection, per-axis addressing with the
// mode as a template argument, one combine loop per (profile kind, storage, 2-D/volume). Returns
// the texels fetched.
uint64_t sampleReference(const SampleRequest& req, int count, const float* const coord[3], const Texture& tex,
                         const SamplerState& ss, const std::array<int32_t, 4>& borderGrid, int32_t* const* gridDst,
                         float* const* valueDst, bool floatWeights8) {
    const bool fixed = isFixedPoint(req.precision);
    const bool weights8 = !fixed && floatWeights8;
    const bool volume = tex.isVolume();
    LaneLevels lanes;
    selectLevels(req, count, coord, tex, ss, fixed, weights8, lanes);

    // Per-level extents per axis, then the addressing passes (mode chosen once per axis).
    const int levels = tex.levelCount();
    uint32_t extent[3][16];
    for (int k = 0; k < levels && k < 16; ++k) {
        extent[0][k] = tex.level(k).width;
        extent[1][k] = tex.level(k).height;
        extent[2][k] = tex.level(k).depth;
    }
    const int axes = volume ? 3 : 2;
    const TextureAddress modes[3] = {ss.addressU, ss.addressV, ss.addressW};
    bool anyTwo = false;
    uint64_t fetched = 0;
    for (int i = 0; i < count; ++i) {
        anyTwo |= lanes.slots[i] == 2;
        fetched += uint64_t(lanes.slots[i]) * (lanes.linear[i] ? (volume ? 8 : 4) : 1);
    }
    static thread_local AxisTaps taps[kSlots][3];
    for (int s = 0; s < (anyTwo ? 2 : 1); ++s)
        for (int a = 0; a < axes; ++a)
            axisPass(modes[a], count, coord[a], extent[a], lanes.level[s], lanes.linear, taps[s][a]);
    // The class's 8-bit sub-texel weights in the float profile: the same w/256 as fx, lerped in
    // float32 (docs/precision.md "Sampling").
    if (weights8)
        for (int s = 0; s < (anyTwo ? 2 : 1); ++s)
            for (int a = 0; a < axes; ++a)
                for (int i = 0; i < count; ++i) taps[s][a].f[i] = float(taps[s][a].w[i]) / 256.0f;

    CombineInput in{count, &tex.level(0), &lanes, taps};
    if (fixed) {
        const int64_t border[4] = {borderGrid[0], borderGrid[1], borderGrid[2], borderGrid[3]};
        if (tex.storage() == TexelStorage::Unorm8) {
            U8Grid src{tex.unorm8(), gridScale(req.precision) / 255};
            volume ? combineFx<U8Grid, true>(in, src, border, gridDst)
                   : combineFx<U8Grid, false>(in, src, border, gridDst);
        } else if (tex.readsInPlace()) {
            RowGrid src{tex.floatTexels(), req.precision};
            volume ? combineFx<RowGrid, true>(in, src, border, gridDst)
                   : combineFx<RowGrid, false>(in, src, border, gridDst);
        } else {
            IntGrid src{tex.grid(req.precision)};
            volume ? combineFx<IntGrid, true>(in, src, border, gridDst)
                   : combineFx<IntGrid, false>(in, src, border, gridDst);
        }
    } else {
        const float* border = ss.border.data();
        if (tex.storage() == TexelStorage::Unorm8) {
            U8Float src{tex.unorm8(), Texture::unorm8Values()};
            volume ? combineFloat<U8Float, true>(in, src, border, valueDst)
                   : combineFloat<U8Float, false>(in, src, border, valueDst);
        } else if (const float* values = tex.values()) {
            ValueFloat src{values};
            volume ? combineFloat<ValueFloat, true>(in, src, border, valueDst)
                   : combineFloat<ValueFloat, false>(in, src, border, valueDst);
        } else {
            RowFloat src{tex.floatTexels()};
            volume ? combineFloat<RowFloat, true>(in, src, border, valueDst)
                   : combineFloat<RowFloat, false>(in, src, border, valueDst);
        }
    }
    return fetched;
}

// The border colour as a b g r a byte word when its grid value is byte * scale for bytes in
// 0..255 (so the fast kernels can treat it as a texel); false otherwise.
bool borderAsWord(const std::array<int32_t, 4>& grid, int32_t scale, uint32_t& word) {
    word = 0;
    for (int c = 0; c < 4; ++c) {
        const int32_t g = grid[size_t(c)];
        if (g < 0 || g > 255 * scale || g % scale != 0) return false;
        word |= uint32_t(g / scale) << (8 * kUnorm8Byte[c]);
    }
    return true;
}

// The lanes of one set (forEachSet), gathered: coordinates, mip weights (fx and float), the groups
// they came from, and room for the kernels' results.
struct SetScratch {
    alignas(64) float u[kMaxSpan], v[kMaxSpan];
    alignas(64) int32_t mipW[kMaxSpan];
    alignas(64) float mipF[kMaxSpan];
    alignas(64) int32_t grid[4][kMaxSpan];
    alignas(64) float value[2][4][kMaxSpan];
    int16_t next[kMaxSpan];    // the next group of the same set (−1: none), by group start lane
    uint32_t key[kMaxSpan];    // laneKey of the group starting at each lane
    int16_t groups[kMaxSpan];  // the visited set's groups' first lanes, in gathered order
    int groupCount = 0, step = 1;
};

// Per lane the set it belongs to: its level, filter and blend (the key a fast kernel's run needs).
uint32_t laneKey(const LaneLevels& lanes, int i) {
    const bool two = lanes.slots[i] == 2;
    return uint32_t(lanes.level[0][i]) | (two ? uint32_t(lanes.level[1][i]) << 5 | 1u << 10 : 0u) |
           uint32_t(lanes.linear[i] != 0) << 11;
}

// The key of each group (`step` lanes from 0) into s.key; returns how many runs of consecutive
// groups share a key.
int groupKeys(int count, int step, const LaneLevels& lanes, SetScratch& s) {
    int runs = 0;
    for (int q = 0; q < count; q += step) {
        s.key[q] = laneKey(lanes, q);
        runs += q == 0 || s.key[q] != s.key[q - step];
    }
    return runs;
}

// The span's groups (`step` lanes each, all of one key; s.key from groupKeys) set by set: for each
// distinct key every group of that key is gathered into s (u, v, mipW, mipF, groups) and
// visit(first group's lane, n) is called to sample the n lanes as one run and put them back
// (putBack). Every lane's result depends on its own coordinates alone, so this gives what
// sampling the groups one by one gives, in any order of the sets.
template <class Visit>
void forEachSet(int count, int step, const LaneLevels& lanes, const float* const coord[3], SetScratch& s,
                const Visit& visit) {
    s.step = step;
    auto gather = [&](const int16_t* groups, int g) {
        int n = 0;
        for (int j = 0; j < g; ++j) {
            const int q = groups[j];
            s.groups[j] = int16_t(q);
            if (q + step <= count && step == 4) {  // a whole quad: four lanes at once
                std::memcpy(s.u + n, coord[0] + q, 4 * sizeof(float));
                std::memcpy(s.v + n, coord[1] + q, 4 * sizeof(float));
                std::memcpy(s.mipW + n, lanes.mipW + q, 4 * sizeof(int32_t));
                std::memcpy(s.mipF + n, lanes.mipF + q, 4 * sizeof(float));
                n += 4;
                continue;
            }
            for (int i = q; i < q + step && i < count; ++i) {
                s.u[n] = coord[0][i], s.v[n] = coord[1][i], s.mipW[n] = lanes.mipW[i], s.mipF[n] = lanes.mipF[i];
                ++n;
            }
        }
        s.groupCount = g;
        visit(groups[0], n);
    };
    // A key (laneKey) names level 0, whether a blend, level 1 and the filter. Where every blend's
    // level 1 is the next level (as chooseLevel's are), id = level 0 · 4 + blend · 2 + filter
    // names the same sets: the groups are counted per id and sorted by it, with no search.
    constexpr int kIds = 16 * 4;
    bool compact = true;
    for (int q = 0; q < count; q += step) {
        const uint32_t k = s.key[q], level0 = k & 31u;
        compact &= level0 < 16 && (!(k >> 10 & 1u) || (k >> 5 & 31u) == level0 + 1);
    }
    int16_t order[kMaxSpan];
    if (compact) {
        auto id = [&](int q) {
            const uint32_t k = s.key[q];
            return int((k & 31u) << 2 | (k >> 9 & 2u) | (k >> 11 & 1u));
        };
        int16_t start[kIds + 1] = {};
        for (int q = 0; q < count; q += step) ++start[id(q) + 1];
        for (int i = 0; i < kIds; ++i) start[i + 1] = int16_t(start[i + 1] + start[i]);
        int16_t fill[kIds];
        std::memcpy(fill, start, sizeof(fill));
        for (int q = 0; q < count; q += step) order[fill[id(q)]++] = int16_t(q);
        for (int i = 0; i < kIds; ++i)
            if (start[i + 1] > start[i]) gather(order + start[i], start[i + 1] - start[i]);
        return;
    }
    // Otherwise each distinct key's groups in the order of its first group.
    constexpr int kMaxKeys = 64;
    uint32_t keys[kMaxKeys];
    int16_t first[kMaxKeys], last[kMaxKeys];
    int distinct = 0;
    for (int q = 0; q < count; q += step) {
        const uint32_t k = s.key[q];
        int slot = 0;
        while (slot < distinct && keys[slot] != k) ++slot;
        s.next[q] = -1;
        if (slot == distinct) {
            if (distinct == kMaxKeys) {
                order[0] = int16_t(q);
                gather(order, 1);
                continue;
            }
            keys[distinct] = k, first[distinct] = int16_t(q), last[distinct] = int16_t(q), ++distinct;
        } else {
            s.next[last[slot]] = int16_t(q), last[slot] = int16_t(q);
        }
    }
    for (int k = 0; k < distinct; ++k) {
        int g = 0;
        for (int q = first[k]; q >= 0; q = s.next[q]) order[g++] = int16_t(q);
        gather(order, g);
    }
}

// The visited set's results (src, in gathered order) back into the span's lanes (dst), group by
// group.
template <class T>
void putBack(const SetScratch& s, int count, const T* const src[4], T* const dst[4]) {
    int n = 0;
    for (int g = 0; g < s.groupCount; ++g) {
        const int q = s.groups[g];
        if (s.step == 4 && q + 4 <= count) {  // a whole quad (a copy of a known size)
            for (int c = 0; c < 4; ++c) std::memcpy(dst[c] + q, src[c] + n, 4 * sizeof(T));
            n += 4;
            continue;
        }
        for (int i = q; i < q + s.step && i < count; ++i, ++n)
            for (int c = 0; c < 4; ++c) dst[c][i] = src[c][n];
    }
}

}  // namespace

void floatAxisTaps(TextureAddress mode, bool linear, bool weights8, int count, const float* coord, uint32_t extent,
                   int32_t* i0, int32_t* i1, float* f) {
    // axisPassT's rule for lanes of one level and one filter, vectorised per SIMD level.
    fastpath::samplerKernels(simdLevel()).floatAxis(mode, linear, weights8, count, coord, extent, i0, i1, f);
}

void TextureSampler::sample(const SampleRequest& req, SampleResult& out) {
    const int count = std::clamp(req.count, 0, kMaxSpan);
    const bool fixed = isFixedPoint(req.precision);
    out.unitRange = false;
    // 8-bit weights in the float profile where the hardware class has them; never in ideal.
    const bool floatWeights8 = m_weightBits == 8 && req.precision == Precision::Float;
    // Outputs the caller did not ask for go to scratch, so the kernels never test pointers.
    int32_t scratchGrid[4][kMaxSpan];
    float scratchValue[4][kMaxSpan];
    int32_t* gridDst[4];
    float* valueDst[4];
    for (int c = 0; c < 4; ++c) {
        gridDst[c] = out.grid[c] ? out.grid[c] : scratchGrid[c];
        valueDst[c] = out.value[c] ? out.value[c] : scratchValue[c];
    }

    const Stage* st = req.stage >= 0 && req.stage < kMaxSamplerStages ? &m_stages[size_t(req.stage)] : nullptr;
    if (!st || !st->texture || st->texture->levelCount() == 0) {
        // spec §6.4: a stage without a texture samples as (0, 0, 0, 1).
        const int32_t one = gridScale(req.precision);
        for (int c = 0; c < 4; ++c)
            for (int i = 0; i < count; ++i) {
                if (fixed)
                    gridDst[c][i] = c == 3 ? one : 0;
                else
                    valueDst[c][i] = c == 3 ? 1.0f : 0.0f;
            }
        return;
    }
    const Texture& tex = *st->texture;
    const SamplerState& ss = st->state;
    const float* coord[3] = {req.u ? req.u : kZeros, req.dims >= 2 && req.v ? req.v : kZeros,
                             req.dims >= 3 && req.w ? req.w : kZeros};
    const std::array<int32_t, 4>& borderGrid = req.precision == Precision::Fx12 ? st->borderGrid12 : st->borderGrid8;

    uint64_t fetched = 0, fastLanes = 0;
    if (m_fastPath && fixed && !tex.isVolume() && tex.storage() == TexelStorage::Unorm8) {
        fastpath::Unorm8Run run;
        run.addressU = ss.addressU;
        run.addressV = ss.addressV;
        run.scale = gridScale(req.precision) / 255;
        const bool border = ss.addressU == TextureAddress::Border || ss.addressV == TextureAddress::Border;
        if (!border || borderAsWord(borderGrid, run.scale, run.borderWord)) {
            const fastpath::SamplerKernels& kernels = fastpath::samplerKernels(simdLevel());
            auto levelRun = [&](fastpath::Unorm8Run& r, int level, bool linear) {
                const TextureLevelInfo& li = tex.level(level);
                r.texels = tex.unorm8() + li.offset * 4;
                r.width = li.width, r.height = li.height, r.linear = linear;
            };
            auto fastRun = [&](int first, int n, int level, bool linear) {
                levelRun(run, level, linear);
                int32_t* dst[4] = {gridDst[0] + first, gridDst[1] + first, gridDst[2] + first, gridDst[3] + first};
                kernels.unorm8(run, n, coord[0] + first, coord[1] + first, dst);
                fetched += uint64_t(n) * (linear ? 4 : 1);
                fastLanes += uint64_t(n);
            };
            const bool magLinear = effective(ss.magFilter) == Filter::Linear;
            if (!req.levels && (!req.quads || lodFree(tex, ss))) {
                fastRun(0, count, 0, magLinear);  // level 0, one filter (docs/textures.md "Level of detail")
            } else {
                // Per quad (or per lane, where the caller gives the levels) level, filter and mip
                // blend, then runs of whole quads (lanes) that agree: one level -> the kernel, a
                // linear mip blend of two -> the two-level kernel, each lane at its own weight.
                static thread_local LaneLevels lanes;
                selectLevels(req, count, coord, tex, ss, true, false, lanes, &kernels);
                const int step = req.levels ? 1 : 4;
                // Groups (quads, or lanes) of one level, filter and blend are drawn together
                // wherever they lie in the span when runs of consecutive ones are short (each
                // quad at a level of its own, as a dependent read's often is): forEachSet.
                static thread_local SetScratch set;
                if (groupKeys(count, step, lanes, set) * 16 > count) {
                    forEachSet(count, step, lanes, coord, set, [&](int g, int n) {
                        const bool two = lanes.slots[g] == 2, linear = lanes.linear[g] != 0;
                        int32_t* dst[4] = {set.grid[0], set.grid[1], set.grid[2], set.grid[3]};
                        fastpath::Unorm8Run lower = run;
                        levelRun(lower, lanes.level[0][g], linear);
                        if (two) {
                            fastpath::Unorm8Run upper = run;
                            levelRun(upper, lanes.level[1][g], linear);
                            kernels.unorm8Mip(lower, upper, set.mipW, n, set.u, set.v, dst);
                        } else {
                            kernels.unorm8(lower, n, set.u, set.v, dst);
                        }
                        const int32_t* src[4] = {set.grid[0], set.grid[1], set.grid[2], set.grid[3]};
                        putBack(set, count, src, gridDst);
                        fetched += uint64_t(n) * (two ? 2 : 1) * (linear ? 4 : 1);
                        fastLanes += uint64_t(n);
                    });
                    m_fetched.fetch_add(fetched, std::memory_order_relaxed);
                    m_fastLanes.fetch_add(fastLanes, std::memory_order_relaxed);
                    out.unitRange = true;
                    return;
                }
                for (int q = 0; q < count;) {
                    const bool two = lanes.slots[q] == 2;
                    int e = q + step;
                    while (e < count && (lanes.slots[e] == 2) == two && lanes.level[0][e] == lanes.level[0][q] &&
                           lanes.linear[e] == lanes.linear[q])
                        e += step;
                    e = std::min(e, count);
                    const bool linear = lanes.linear[q] != 0;
                    if (!two) {
                        fastRun(q, e - q, lanes.level[0][q], linear);
                    } else {
                        fastpath::Unorm8Run upper = run;
                        levelRun(run, lanes.level[0][q], linear);
                        levelRun(upper, lanes.level[1][q], linear);
                        int32_t* dst[4] = {gridDst[0] + q, gridDst[1] + q, gridDst[2] + q, gridDst[3] + q};
                        kernels.unorm8Mip(run, upper, lanes.mipW + q, e - q, coord[0] + q, coord[1] + q, dst);
                        fetched += 2 * uint64_t(e - q) * (linear ? 4 : 1);
                        fastLanes += uint64_t(e - q);
                    }
                    q = e;
                }
            }
            m_fetched.fetch_add(fetched, std::memory_order_relaxed);
            m_fastLanes.fetch_add(fastLanes, std::memory_order_relaxed);
            out.unitRange = true;  // 8-bit texels, a border of bytes and their blends: [0, G]
            return;
        }
    }
    if (m_fastPath && !fixed && !tex.isVolume() && tex.storage() == TexelStorage::Unorm8) {
        // float and ideal: the reference's floats eight lanes a step (Unorm8FloatKernel).
        const fastpath::SamplerKernels& kernels = fastpath::samplerKernels(simdLevel());
        fastpath::Unorm8FloatRun run;
        run.weights8 = floatWeights8;
        run.addressU = ss.addressU, run.addressV = ss.addressV;
        run.border = ss.border.data();
        auto levelRun = [&](int level, bool linear) {
            const TextureLevelInfo& li = tex.level(level);
            run.texels = tex.unorm8() + li.offset * 4;
            run.width = li.width, run.height = li.height, run.linear = linear;
        };
        if (!req.levels && lodFree(tex, ss)) {
            levelRun(0, effective(ss.magFilter) == Filter::Linear);  // level 0, its one filter
            kernels.unorm8Float(run, count, coord[0], coord[1], valueDst);
            fetched = uint64_t(count) * (run.linear ? 4 : 1);
        } else {
            // Each quad's (or lane's) level, filter and mip blend as the reference chooses them,
            // then set by set: one level, the kernel; two, the kernel at each and the reference's
            // blend of the two (lerpf with its weight).
            static thread_local LaneLevels lanes;
            static thread_local SetScratch set;
            selectLevels(req, count, coord, tex, ss, false, floatWeights8, lanes, &kernels);
            groupKeys(count, req.levels ? 1 : 4, lanes, set);
            forEachSet(count, req.levels ? 1 : 4, lanes, coord, set, [&](int g, int n) {
                const bool two = lanes.slots[g] == 2, linear = lanes.linear[g] != 0;
                float* lower[4] = {set.value[0][0], set.value[0][1], set.value[0][2], set.value[0][3]};
                float* upper[4] = {set.value[1][0], set.value[1][1], set.value[1][2], set.value[1][3]};
                levelRun(lanes.level[0][g], linear);
                kernels.unorm8Float(run, n, set.u, set.v, lower);
                if (two) {
                    levelRun(lanes.level[1][g], linear);
                    kernels.unorm8Float(run, n, set.u, set.v, upper);
                    for (int c = 0; c < 4; ++c)
                        for (int j = 0; j < n; ++j) lower[c][j] = lerpf(lower[c][j], upper[c][j], set.mipF[j]);
                }
                const float* src[4] = {lower[0], lower[1], lower[2], lower[3]};
                putBack(set, count, src, valueDst);
                fetched += uint64_t(n) * (two ? 2 : 1) * (linear ? 4 : 1);
            });
        }
        m_fetched.fetch_add(fetched, std::memory_order_relaxed);
        m_fastLanes.fetch_add(uint64_t(count), std::memory_order_relaxed);
        // Blends of bytes / 255 and of a border colour in [0, 1] stay in [0, 1].
        bool unit = true;
        for (float b : ss.border) unit = unit && b >= 0.0f && b <= 1.0f;
        out.unitRange = unit;
        return;
    }
    fetched = sampleReference(req, count, coord, tex, ss, borderGrid, gridDst, valueDst, floatWeights8);
    m_fetched.fetch_add(fetched, std::memory_order_relaxed);
}

}  // namespace ps11
