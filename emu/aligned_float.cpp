// The float profiles' row path (emu/aligned_float.h): tabulated addressing, H rows of lerps, the
// executor over rows with a sampler that serves them, the output merger over rows.
#include "emu/aligned_float.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include "emu/aligned_float_kernels.h"
#include "emu/vertex.h"
#include "ps11/fill_lanes.h"

namespace emu {

namespace {

bool linearFilter(ps11::Filter f) { return f == ps11::Filter::Linear; }

// The reference sampler's lerp (texture_sampler.cpp combineFloat), in the same order.
inline float lerpf(float a, float b, float f) { return (1.0f - f) * a + f * b; }

// ps11::Texture::unorm8Values(), fetched once.
const float* const kUnorm8 = ps11::Texture::unorm8Values();

// Texel (ix, iy) of level 0 as float r g b a, or the border colour when an index is −1.
inline void texel(const FloatRowTap& tap, int32_t ix, int32_t iy, float t[4]) {
    if ((ix | iy) < 0) {
        for (int c = 0; c < 4; ++c) t[c] = tap.border[size_t(c)];
        return;
    }
    const size_t i = (size_t(iy) * tap.width + size_t(ix)) * 4;
    if (tap.unorm8) {
        for (int c = 0; c < 4; ++c) t[c] = kUnorm8[tap.bytes[i + size_t(ps11::kUnorm8Byte[c])]];
    } else if (tap.values) {
        for (int c = 0; c < 4; ++c) t[c] = tap.values[i + size_t(c)];
    } else {
        tap.texels.get(i / 4, t);
    }
}

// ---- the Baseline level's kernels (emu/aligned_float_kernels.h) ----

void lerpColumnsBase(const float* a, const float* b, const float* f, int n, float* out) {
    int j = 0;
#if defined(__SSE2__)
    for (; j + 4 <= n; j += 4) {
        const __m128 fv = _mm_loadu_ps(f + j), gv = _mm_sub_ps(_mm_set1_ps(1.0f), fv);
        _mm_storeu_ps(out + j, _mm_add_ps(_mm_mul_ps(gv, _mm_loadu_ps(a + j)), _mm_mul_ps(fv, _mm_loadu_ps(b + j))));
    }
#endif
    for (; j < n; ++j) out[j] = lerpf(a[j], b[j], f[j]);
}

void lerpGatherBase(const float* d, int /*len*/, const int32_t* i0, const int32_t* i1, const float* f, int n,
                    float* out) {
    for (int j = 0; j < n; ++j) out[j] = lerpf(d[i0[j]], d[i1[j]], f[j]);
}

void lerpWordsBase(const uint8_t* row, int /*len*/, const int32_t* i0, const int32_t* i1, const float* f, int n,
                   float* out, size_t stride) {
    for (int j = 0; j < n; ++j) {
        const uint8_t *a = row + 4 * size_t(i0[j]), *b = row + 4 * size_t(i1[j]);
        for (size_t c = 0; c < 4; ++c)
            out[c * stride + size_t(j)] =
                lerpf(kUnorm8[a[ps11::kUnorm8Byte[c]]], kUnorm8[b[ps11::kUnorm8Byte[c]]], f[j]);
    }
}

bool lerpValuesBase(const float* rgba, int /*len*/, const int32_t* i0, const int32_t* i1, const float* f, int n,
                    float* out, size_t stride) {
    for (int j = 0; j < n; ++j)
        for (size_t c = 0; c < 4; ++c)
            out[c * stride + size_t(j)] = lerpf(rgba[4 * size_t(i0[j]) + c], rgba[4 * size_t(i1[j]) + c], f[j]);
    return true;  // (lerpf itself: the reference's order)
}

void lerpRowBase(const float* a, const float* b, float f, int n, float* out) {
    int j = 0;
#if defined(__SSE2__)
    const __m128 fv = _mm_set1_ps(f), gv = _mm_set1_ps(1.0f - f);
    for (; j + 4 <= n; j += 4)
        _mm_storeu_ps(out + j, _mm_add_ps(_mm_mul_ps(gv, _mm_loadu_ps(a + j)), _mm_mul_ps(fv, _mm_loadu_ps(b + j))));
#endif
    for (; j < n; ++j) out[j] = lerpf(a[j], b[j], f);
}

void decodeBase(const uint8_t* row, int n, float* out, size_t stride) {
    int i = 0;
#if defined(__SSE2__)
    // kUnorm8[b] is float(b) / 255.0f for every byte (tests/test_texture_sampler.cpp checks it): four
    // texels per step, each channel's bytes shifted out of the b g r a words and divided.
    const __m128i byte = _mm_set1_epi32(0xff);
    const __m128 k255 = _mm_set1_ps(255.0f);
    constexpr int kShift[4] = {16, 8, 0, 24};  // r g b a
    for (; i + 4 <= n; i += 4) {
        const __m128i w = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 4 * i));
        for (size_t c = 0; c < 4; ++c)
            _mm_storeu_ps(out + c * stride + size_t(i),
                          _mm_div_ps(_mm_cvtepi32_ps(_mm_and_si128(_mm_srli_epi32(w, kShift[c]), byte)), k255));
    }
#endif
    for (; i < n; ++i)
        for (size_t c = 0; c < 4; ++c) out[c * stride + size_t(i)] = kUnorm8[row[4 * i + ps11::kUnorm8Byte[c]]];
}

void transposeBase(const float* v, int n, float* out, size_t stride) {
    int i = 0;
#if defined(__SSE2__)
    // Four texels a step: a 4×4 transpose (shuffles move the bits as they are).
    const bool ahead = 16 * n >= kPrefetchRowBytes;
    for (; i + 4 <= n; i += 4) {
        if (ahead) _mm_prefetch(reinterpret_cast<const char*>(v + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
        __m128 t0 = _mm_loadu_ps(v + 4 * i), t1 = _mm_loadu_ps(v + 4 * i + 4), t2 = _mm_loadu_ps(v + 4 * i + 8),
               t3 = _mm_loadu_ps(v + 4 * i + 12);
        _MM_TRANSPOSE4_PS(t0, t1, t2, t3);
        _mm_storeu_ps(out + i, t0);
        _mm_storeu_ps(out + stride + i, t1);
        _mm_storeu_ps(out + 2 * stride + i, t2);
        _mm_storeu_ps(out + 3 * stride + i, t3);
    }
#endif
    for (; i < n; ++i)
        for (size_t c = 0; c < 4; ++c) out[c * stride + size_t(i)] = v[4 * size_t(i) + c];
}

const FloatRowKernels kBaseline{&lerpColumnsBase, &lerpGatherBase, &lerpWordsBase, &lerpValuesBase,
                                &lerpRowBase,     &decodeBase,     &transposeBase};

}  // namespace

const FloatRowKernels& floatRowKernels(ps11::SimdLevel level) {
#if defined(PS11_HAVE_AVX512)
    return *ps11::simdTable<FloatRowKernels>(level, &kBaseline, &avx2::kFloatRow,
                                             ps11::madeTable(level, ps11::SimdLevel::Avx512, &avx512::floatRowTable));
#elif defined(PS11_HAVE_AVX2)
    return *ps11::simdTable<FloatRowKernels>(level, &kBaseline, &avx2::kFloatRow);
#else
    (void)level;
    return kBaseline;
#endif
}

namespace {

// One tap's texel rows for the pixel row being drawn.
struct RowTaps {
    int32_t j0 = 0, j1 = 0;
    float fy = 0;
    const float* h0 = nullptr;  // linear taps: H rows of j0 and j1 (planar, `width` columns)
    const float* h1 = nullptr;
};

// Texel row j (in the texture) of a tap as planar r g b a floats: an 8-bit tap's decoded
// (kUnorm8 values), a float tap's deinterleaved; done once per worker and kept while recent;
// valid until the next pixel row.
const float* decodedRow(const FloatRowDraw& draw, const FloatRowTap& tap, int32_t j, FloatRowScratch& sc,
                        bool* nan = nullptr) {
    const size_t tw = tap.width;
    const uint8_t* row = tap.unorm8   ? tap.bytes + size_t(j) * tw * 4
                         : tap.values ? reinterpret_cast<const uint8_t*>(tap.values + size_t(j) * tw * 4)
                                      : tap.texels.base + size_t(j) * tw * tap.texels.stride;
    FloatRowScratch::DecodedRow* slot = nullptr;
    for (FloatRowScratch::DecodedRow& d : sc.decoded) {
        if (d.serial == draw.serial && d.row == row && d.width == tap.width) {
            d.stamp = ++sc.stamp;
            if (nan) *nan = d.nan;
            return d.v.data();
        }
        if (d.stamp <= sc.rowStart && (!slot || d.stamp < slot->stamp)) slot = &d;
    }
    if (!slot) slot = &sc.decoded.emplace_back();  // every row serves this pixel row
    slot->v.resize(4 * tw);
    slot->nan = false;
    if (tap.unorm8) {
        draw.kernels->decode(row, int(tw), slot->v.data(), tw);
    } else if (!tap.values) {
        float* out = slot->v.data();
        bool nanSeen = false;
        const ps11::FloatTexels texels = tap.texels.from(size_t(j) * tw);
        for (size_t i = 0; i < tw; ++i) {
            float t[4];
            texels.get(i, t);
            for (size_t c = 0; c < 4; ++c) {
                nanSeen |= t[c] != t[c];
                out[c * tw + i] = t[c];
            }
        }
        slot->nan = nanSeen;
    } else {
        const float* v = tap.values + size_t(j) * tw * 4;
        float* out = slot->v.data();
        bool nanSeen = false;
        size_t i = 0;
#if defined(__SSE2__)
        // Four texels at a time: a 4×4 transpose, NaNs noted by an unordered compare.
        __m128 unordered = _mm_setzero_ps();
        const bool ahead = 16 * tw >= kPrefetchRowBytes;
        for (; i + 4 <= tw; i += 4) {
            if (ahead) _mm_prefetch(reinterpret_cast<const char*>(v + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
            __m128 t0 = _mm_loadu_ps(v + 4 * i), t1 = _mm_loadu_ps(v + 4 * i + 4), t2 = _mm_loadu_ps(v + 4 * i + 8),
                   t3 = _mm_loadu_ps(v + 4 * i + 12);
            unordered = _mm_or_ps(unordered, _mm_or_ps(_mm_cmpunord_ps(t0, t1), _mm_cmpunord_ps(t2, t3)));
            _MM_TRANSPOSE4_PS(t0, t1, t2, t3);
            _mm_storeu_ps(out + i, t0);
            _mm_storeu_ps(out + tw + i, t1);
            _mm_storeu_ps(out + 2 * tw + i, t2);
            _mm_storeu_ps(out + 3 * tw + i, t3);
        }
        nanSeen = _mm_movemask_ps(unordered) != 0;
#endif
        for (; i < tw; ++i)
            for (size_t c = 0; c < 4; ++c) {
                const float x = v[4 * i + c];
                nanSeen |= x != x;
                out[c * tw + i] = x;
            }
        slot->nan = nanSeen;
    }
    if (nan) *nan = slot->nan;
    slot->serial = draw.serial;
    slot->row = row;
    slot->width = tap.width;
    slot->stamp = ++sc.stamp;
    return slot->v.data();
}

// The H row of texel row j for a linear tap: per column, the horizontal lerp of its texel pair
// (the first step of combineFloat), over every column of the triangle. Kept per worker and
// shared by the taps whose column tables are equal, so a magnified tap builds each texel row
// once for all the pixel rows it serves and a vertical blur one row per pixel row.
// `own`: built there, without looking for it among the kept rows or keeping it (an uncached tap's).
const float* hRow(const FloatRowDraw& draw, const FloatRowTriangle& tri, int t, int32_t j, FloatRowScratch& sc,
                  FloatRowScratch::HRow* own = nullptr) {
    const uint64_t id = own ? 0 : tri.taps[size_t(t)].tableId;
    FloatRowScratch::HRow* victim = own;
    for (size_t i = 0; !own && i < sc.hrows.size(); ++i) {
        FloatRowScratch::HRow& h = sc.hrows[i];
        if (h.serial == draw.serial && h.tableId == id && h.row == j) {
            h.stamp = ++sc.stamp;
            return h.h.data();
        }
        if (h.stamp <= sc.rowStart && (!victim || h.stamp < victim->stamp)) victim = &h;
    }
    if (!victim) victim = &sc.hrows.emplace_back();  // every slot serves this pixel row
    FloatRowScratch::HRow& h = *victim;
    const FloatRowTap& tap = draw.taps[size_t(t)];
    const FloatRowTriangle::Columns& cols = tri.taps[size_t(t)];
    const size_t w = size_t(tri.x1 - tri.x0);
    h.h.resize(4 * w);
    size_t x = 0;
    // A row holding a NaN is filtered by lerpf one column at a time below: which of two NaNs a sum
    // returns depends on the order of its operands, which the compiler picks for lerpf as it does
    // for the reference sampler's; without NaNs the vector kernels' results are the same whatever
    // the order.
    bool nan = false;
    // A row whose columns have no run of consecutive pairs (a minification's) is filtered from
    // the texels where they are (8-bit words, or float r g b a); the others from the decoded row.
    const bool inPlace = j >= 0 && (tap.unorm8 || tap.values) &&
                         std::none_of(cols.stretches.begin(), cols.stretches.end(),
                                      [](const auto& st) { return st.kind == FloatRowTriangle::Columns::kSeq; });
    if (inPlace) {
        const size_t at = size_t(j) * tap.width * 4;
        for (const FloatRowTriangle::Columns::Stretch& st : cols.stretches) {
            const size_t x0 = size_t(st.x0);
            const int n = st.x1 - st.x0;
            const int32_t *i0 = cols.i0.data() + x0, *i1 = cols.i1.data() + x0;
            if (st.kind == FloatRowTriangle::Columns::kInside) {
                if (tap.unorm8) {
                    draw.kernels->lerpWords(tap.bytes + at, int(tap.width), i0, i1, cols.f.data() + x0, n,
                                            h.h.data() + x0, w);
                    continue;
                }
                if (draw.kernels->lerpValues(tap.values + at, int(tap.width), i0, i1, cols.f.data() + x0, n,
                                             h.h.data() + x0, w))
                    continue;
            }
            // Border columns, and a run whose lerps gave a NaN: one column at a time (lerpf).
            float a[4], b[4];
            for (size_t q = x0; q < size_t(st.x1); ++q) {
                texel(tap, cols.i0[q], j, a);
                texel(tap, cols.i1[q], j, b);
                for (size_t c = 0; c < 4; ++c) h.h[c * w + q] = lerpf(a[c], b[c], cols.f[q]);
            }
        }
        x = w;
    }
    const float* dec = j >= 0 && !inPlace ? decodedRow(draw, tap, j, sc, &nan) : nullptr;
    if (dec && !nan) {
        // By stretches (prepareFloatRowTriangle): consecutive texel pairs with vector loads, other
        // pairs inside the row gathered, border columns one at a time; the same operations in the
        // same order as lerpf.
        const FloatRowKernels& k = *draw.kernels;
        const size_t tw = tap.width;
        const int32_t* i0 = cols.i0.data();
        const int32_t* i1 = cols.i1.data();
        const float* f = cols.f.data();
        float* out = h.h.data();
        for (const FloatRowTriangle::Columns::Stretch& st : cols.stretches) {
            const int n = st.x1 - st.x0;
            const size_t x0 = size_t(st.x0);
            switch (st.kind) {
                case FloatRowTriangle::Columns::kSeq:
                    for (size_t c = 0; c < 4; ++c) {
                        const float* d = dec + c * tw + size_t(i0[x0]);
                        k.lerpColumns(d, d + 1, f + x0, n, out + c * w + x0);
                    }
                    break;
                case FloatRowTriangle::Columns::kInside:
                    for (size_t c = 0; c < 4; ++c)
                        k.lerpGather(dec + c * tw, int(tw), i0 + x0, i1 + x0, f + x0, n, out + c * w + x0);
                    break;
                case FloatRowTriangle::Columns::kBorder:
                    for (size_t q = x0; q < size_t(st.x1); ++q)
                        for (size_t c = 0; c < 4; ++c) {
                            const float a = i0[q] >= 0 ? dec[c * tw + size_t(i0[q])] : tap.border[c];
                            const float b = i1[q] >= 0 ? dec[c * tw + size_t(i1[q])] : tap.border[c];
                            out[c * w + q] = lerpf(a, b, f[q]);
                        }
                    break;
            }
        }
        x = w;
    }
    float a[4], b[4];
    for (; x < w; ++x) {
        texel(tap, cols.i0[x], j, a);
        texel(tap, cols.i1[x], j, b);
        for (size_t c = 0; c < 4; ++c) h.h[c * w + x] = lerpf(a[c], b[c], cols.f[x]);
    }
    h.serial = draw.serial;
    h.tableId = id;
    h.row = j;
    h.stamp = ++sc.stamp;
    return h.h.data();
}

// Ones: every texture-coordinate set's third and fourth components on the row path.
const auto kOnes = [] {
    std::array<float, ps11::kMaxSpan> t{};
    t.fill(1.0f);
    return t;
}();

// An 8-bit tap sampled per pixel (a coordinate set that is not screen-aligned): the sampler's
// own float kernel (ps11/texture_sampler_fast.h: the reference's addressing and lerps, u then v),
// for lanes [0, n).
void sampleFreeUnorm8(const FloatRowDraw& draw, const FloatRowTap& tap, const float* u, const float* v, int n,
                      float* const out[4]) {
    ps11::fastpath::Unorm8FloatRun run;
    run.texels = tap.bytes;
    run.width = tap.width, run.height = tap.height;
    run.linear = tap.linear;
    run.weights8 = draw.weights8;
    run.addressU = tap.addressU, run.addressV = tap.addressV;
    run.border = tap.border.data();
    draw.sampler->unorm8Float(run, n, u, v, out);
}

// The sampler the executor sees on the row path: lanes are pixels x .. x + n − 1 of one row,
// each plain read served by its stage's tap (prepareFloatRowDraw executes the others: two of a
// stage, a volume texture's).
class RowSampler final : public ps11::Sampler {
public:
    RowSampler(const FloatRowDraw& draw, const std::array<RowTaps, 8>& rows, QuadLevels& quadLevels)
        : m_draw(draw), m_rows(rows), m_quadLevels(&quadLevels) {
        m_tapOf.fill(-1);
        for (int t = 0; t < draw.plan.count; ++t) m_tapOf[draw.plan.stage[size_t(t)]] = int8_t(t);
    }
    void setTriangle(const FloatRowTriangle& tri, const TriangleSetup& s, int y, ps11::Sampler* perPixel) {
        m_tri = &tri, m_setup = &s, m_y = y, m_perPixel = perPixel;
    }
    void setX(int x) { m_x = x; }

    void sample(const ps11::SampleRequest& req, ps11::SampleResult& out) override {
        const int n = req.count;
        const int t = req.plainRead && req.stage >= 0 && req.stage < 8 ? m_tapOf[size_t(req.stage)] : -1;
        if ((t < 0 && req.stage >= 0 && req.stage < 8 && ((m_draw.plan.executedStages >> req.stage) & 1)) ||
            (t >= 0 && ((m_draw.plan.executedTaps >> t) & 1))) {
            m_perPixel->sample(req, out);  // an instruction or plain read the plan executes: as run() samples it
            return;
        }
        const FloatRowTap* tap = t >= 0 ? &m_draw.taps[size_t(t)] : nullptr;
        if (!tap || !tap->bound) {
            for (int c = 0; c < 4; ++c) ps11::fillLanes(out.value[c], n, c == 3 ? 1.0f : 0.0f);
            out.unitRange = true;
            return;
        }
        if ((m_tri->freeTaps >> t) & 1) {
            // Sampled per pixel: the quad path's coordinates through the draw's own sampler.
            alignas(32) float u[ps11::kMaxSpan], v[ps11::kMaxSpan];
            tapCoords(m_draw.plan, t, *m_setup, m_x + req.lane, m_y, n, u, v);
            if ((m_draw.levelTaps.mask >> t) & 1) {
                // Each pixel at the level, filter and mip blend its 2×2 quad picks (quadLevels):
                // 8-bit texels at one level by the vector kernel, the rest (blends of two levels,
                // other formats) by the worker's sampler at those levels.
                const LevelTaps& lt = m_draw.levelTaps;
                const ps11::Texture& tex = *lt.texture[size_t(t)];
                const int x = m_x + req.lane;
                const QuadLevels::Entry& e = quadLevels(*m_quadLevels, *m_setup, m_draw.plan, t, tex,
                                                        *lt.sampler[size_t(t)], lt.fixed, lt.weights8,
                                                        m_draw.target.color->width, x, m_y, n);
                thread_local ps11::LevelChoice lanes[ps11::kMaxSpan];
                FloatRowTap level = *tap;
                for (int i = 0; i < n;) {
                    const ps11::LevelChoice& c = e.choice[size_t((x + i) >> 1)];
                    int end = i + 1;
                    while (end < n && e.choice[size_t((x + end) >> 1)] == c) ++end;
                    float* const o[4] = {out.value[0] + i, out.value[1] + i, out.value[2] + i, out.value[3] + i};
                    if (tap->unorm8 && c.slots == 1) {
                        const ps11::TextureLevelInfo& li = tex.level(c.level0);
                        level.bytes = tex.unorm8() + li.offset * 4;
                        level.width = li.width, level.height = li.height;
                        level.linear = c.linear;
                        sampleFreeUnorm8(m_draw, level, u + i, v + i, end - i, o);
                        m_fetched += uint64_t(end - i) * (level.linear ? 4 : 1);
                        m_levelTexels += uint64_t(end - i) * (level.linear ? 4 : 1);
                    } else {
                        std::fill_n(lanes, end - i, c);
                        ps11::SampleRequest sub = req;
                        sub.count = end - i;
                        sub.u = u + i, sub.v = v + i;
                        sub.quads = false;
                        sub.levels = lanes;
                        ps11::SampleResult part;
                        for (int ch = 0; ch < 4; ++ch) part.value[ch] = o[ch];
                        m_perPixel->sample(sub, part);  // (its texels are counted by that sampler)
                    }
                    i = end;
                }
                out.unitRange = tap->unitRange;
                return;
            }
            if (tap->unorm8) {
                sampleFreeUnorm8(m_draw, *tap, u, v, n, out.value);
                out.unitRange = tap->unitRange;
                m_fetched += uint64_t(n) * (tap->linear ? 4 : 1);
                return;
            }
            ps11::SampleRequest full = req;
            full.u = u, full.v = v;
            full.quads = false;
            m_perPixel->sample(full, out);  // (its texels are counted by that sampler)
            return;
        }
        out.unitRange = tap->unitRange;
        const RowTaps& r = m_rows[size_t(t)];
        const size_t first = size_t(m_x - m_tri->x0) + size_t(req.lane);  // lanes are consecutive
        if (tap->linear) {
            const size_t w = size_t(m_tri->x1 - m_tri->x0);
            if (r.fy == 0.0f && tap->nonNegative) {
                // (1 − 0)·a + 0·b is a: 8-bit texels, the border colour and their lerps are
                // finite and not negative (a 1:1 row under 8-bit weights).
                for (int c = 0; c < 4; ++c)
                    std::memcpy(out.value[c], r.h0 + size_t(c) * w + first, sizeof(float) * size_t(n));
                m_fetched += uint64_t(n) * 4;
                return;
            }
            for (int c = 0; c < 4; ++c)
                m_draw.kernels->lerpRow(r.h0 + size_t(c) * w + first, r.h1 + size_t(c) * w + first, r.fy, n,
                                        out.value[c]);
            m_fetched += uint64_t(n) * 4;
            return;
        }
        const FloatRowTriangle::Columns& cols = m_tri->taps[size_t(t)];
        const int32_t* i0 = cols.i0.data() + first;
        // The end of the run of lanes from i whose texels follow i0[i] one by one (the table's).
        const auto runEnd = [&](int i) { return std::min(n, int(cols.runEnd[first + size_t(i)] - int32_t(first))); };
        // (The channel arrays' distance as addresses: they need not be one array's parts.)
        const auto at = [&](int c) { return reinterpret_cast<uintptr_t>(out.value[c]); };
        const uintptr_t step = at(1) - at(0);
        const ptrdiff_t stride = ptrdiff_t(step / sizeof(float));
        const bool strided = at(1) > at(0) && step % sizeof(float) == 0 && stride >= n && at(2) - at(1) == step &&
                             at(3) - at(2) == step;
        if (!tap->unorm8 && tap->values && r.j0 >= 0 && strided) {
            // A float row's texels moved where they lie into the lanes, bit for bit: runs of
            // consecutive texels by the transpose kernel, border lanes the border colour.
            const float* values = tap->values + size_t(r.j0) * tap->width * 4;
            float* const dst = out.value[0];
            int i = 0;
            while (i < n) {
                const int32_t k = i0[i];
                if (k < 0) {
                    for (int c = 0; c < 4; ++c) dst[c * stride + i] = tap->border[size_t(c)];
                    ++i;
                    continue;
                }
                const int e = runEnd(i);
                m_draw.kernels->transpose(values + 4 * size_t(k), e - i, dst + i, size_t(stride));
                i = e;
            }
            m_fetched += uint64_t(n);
            return;
        }
        if (tap->unorm8 && r.j0 >= 0 && strided) {
            // An 8-bit row's texels decoded where they lie into the lanes (the result's channel
            // arrays one stride apart, as the executor's are): runs of consecutive texels by the
            // decode kernel, other lanes by the value table.
            const uint8_t* bytes = tap->bytes + size_t(r.j0) * tap->width * 4;
            float* const dst = out.value[0];
            int i = 0;
            while (i < n) {
                const int32_t k = i0[i];
                const int e = k >= 0 ? runEnd(i) : i + 1;
                if (e - i >= 8) {
                    m_draw.kernels->decode(bytes + 4 * size_t(k), e - i, dst + i, size_t(stride));
                    i = e;
                    continue;
                }
                for (; i < e; ++i) {
                    const int32_t q = i0[i];
                    for (int c = 0; c < 4; ++c)
                        dst[c * stride + i] = q >= 0 ? kUnorm8[bytes[4 * size_t(q) + size_t(ps11::kUnorm8Byte[c])]]
                                                     : tap->border[size_t(c)];
                }
            }
            m_fetched += uint64_t(n);
            return;
        }
        float v[4];
        for (int i = 0; i < n; ++i) {
            texel(*tap, i0[i], r.j0, v);
            for (int c = 0; c < 4; ++c) out.value[c][i] = v[c];
        }
        m_fetched += uint64_t(n);
    }
    bool hasTexture(int stage) const override {
        const int t = stage >= 0 && stage < 8 ? m_tapOf[size_t(stage)] : -1;
        return t >= 0 && m_draw.taps[size_t(t)].bound;
    }
    uint64_t texelsFetched() const override { return m_fetched; }
    // The texels of taps at their quads' levels this sampler filtered itself since the last call
    // (the row's count per pixel leaves such taps out; the worker's sampler counts the others).
    uint64_t takeLevelTexels() { return std::exchange(m_levelTexels, 0); }

private:
    const FloatRowDraw& m_draw;
    const FloatRowTriangle* m_tri = nullptr;
    const TriangleSetup* m_setup = nullptr;
    ps11::Sampler* m_perPixel = nullptr;
    int m_y = 0;
    const std::array<RowTaps, 8>& m_rows;
    QuadLevels* m_quadLevels;
    std::array<int8_t, 8> m_tapOf{};
    int m_x = 0;
    uint64_t m_fetched = 0;
    uint64_t m_levelTexels = 0;
};

}  // namespace

bool prepareFloatRowDraw(const ps11::Executor& executor, ps11::Precision precision, int weightBits,
                         const std::array<std::shared_ptr<const ps11::Texture>, 8>& textures,
                         const std::array<ps11::SamplerState, 8>& samplers, const MergeState& merge,
                         const MergeTarget& target, bool wantZ, uint64_t usedAttrs, FloatRowDraw& out) {
    if (precision != ps11::Precision::Float && precision != ps11::Precision::Ideal) return false;
    if (!target.color) return false;
    FloatRowDraw d;
    if (!ps11::plainTaps(executor, d.plan, true)) return false;
    d.serial = nextRowDrawSerial();
    d.kernels = &floatRowKernels(ps11::simdLevel());
    d.sampler = &ps11::fastpath::samplerKernels(ps11::simdLevel());
    d.executor = &executor;
    d.weights8 = weightBits == 8 && precision == ps11::Precision::Float;
    d.levelTaps.fixed = false;
    d.levelTaps.weights8 = d.weights8;
    // The stages two plain reads sample (ps_1_4's two phases): the row sampler tells plain reads
    // apart by stage, so those are sampled per pixel, as below.
    uint32_t stagesSeen = 0, stagesTwice = 0;
    for (int i = 0; i < d.plan.count; ++i) {
        const uint32_t bit = 1u << d.plan.stage[size_t(i)];
        stagesTwice |= stagesSeen & bit;
        stagesSeen |= bit;
    }
    for (int i = 0; i < d.plan.count; ++i) {
        const int stage = d.plan.stage[size_t(i)];
        FloatRowTap& tap = d.taps[size_t(i)];
        tap.stage = stage;
        tap.coordSet = d.plan.coordSet[size_t(i)];
        const std::shared_ptr<const ps11::Texture>& tex = textures[size_t(stage)];
        if (!tex) continue;  // (0, 0, 0, 1)
        const ps11::SamplerState& ss = samplers[size_t(stage)];
        if (tex->isVolume() || ((stagesTwice >> stage) & 1)) {
            // A plain read the rows do not filter (a volume texture's; one of two of a stage): the
            // executor samples it per pixel as run() does, from its set's coordinates, where the
            // level of detail cannot matter (TapPlan::executedTaps; not bound: no tables).
            if (!ps11::lodFree(*tex, ss)) return false;
            d.plan.executedTaps = uint8_t(d.plan.executedTaps | (1u << i));
            d.plan.executes = true;
            d.plan.executedSets = uint8_t(d.plan.executedSets | (1u << tap.coordSet));
            d.plan.executedStages = uint8_t(d.plan.executedStages | (1u << stage));
            continue;
        }
        if (!ps11::lodFree(*tex, ss)) d.levelTaps.add(i, *tex, ss, tap.coordSet);
        const ps11::TextureLevelInfo& li = tex->level(0);
        tap.bound = true;
        d.bound |= 1u << i;
        tap.unorm8 = tex->storage() == ps11::TexelStorage::Unorm8;
        if (tap.unorm8)
            tap.bytes = tex->unorm8() + li.offset * 4;
        else if (tex->values())
            tap.values = tex->values() + li.offset * 4;
        else
            tap.texels = tex->floatTexels().from(li.offset);
        tap.width = li.width;
        tap.height = li.height;
        tap.linear = linearFilter(ss.magFilter);
        tap.addressU = ss.addressU;
        tap.addressV = ss.addressV;
        tap.border = ss.border;
        tap.nonNegative = tap.unorm8 && std::all_of(tap.border.begin(), tap.border.end(), [](float b) {
                              return b >= 0.0f && b <= std::numeric_limits<float>::max() && !std::signbit(b);
                          });
        tap.unitRange = tap.unorm8 && std::all_of(tap.border.begin(), tap.border.end(),
                                                  [](float b) { return b >= 0.0f && b <= 1.0f; });
    }
    if (d.plan.executes) {
        // The executed instructions are sampled per pixel at level 0 (no quads), from their sets'
        // coordinates; the row sampler tells the plain reads of a stage from them
        // (SampleRequest::plainRead) and needs no coordinates for those, so stages and sets may
        // be shared.
        for (int s = 0; s < 8; ++s)
            if ((d.plan.executedStages >> s) & 1 && textures[size_t(s)] &&
                !ps11::lodFree(*textures[size_t(s)], samplers[size_t(s)]))
                return false;
        for (int set = 0; set < kMaxTexSets; ++set)
            if ((d.plan.executedSets >> set) & 1)
                for (int c = 0; c < 4; ++c) d.executedAttrs |= usedAttrs & (uint64_t(1) << attrTex(set, c));
    }
    d.colorAttrs = usedAttrs & ((uint64_t(0xF) << kAttrDiffuse) | (uint64_t(0xF) << kAttrSpecular));
    d.merge = merge;
    d.target = target;
    bool planned = false;
    d.mergePlan = makePlan(merge, target, planned);
    if (!planned) return false;
    d.wantZ = wantZ;
    d.shaderDepth = wantZ && executor.writesDepth();
    out = d;
    return true;
}

void setTapLevels(FloatRowDraw& draw, const TapLevels& levels) {
    bool changed = false;
    for (int i = 0; i < draw.plan.count; ++i) {
        if (!((draw.levelTaps.mask >> i) & 1)) continue;
        FloatRowTap& tap = draw.taps[size_t(i)];
        const ps11::Texture& tex = *draw.levelTaps.texture[size_t(i)];
        const ps11::TextureLevelInfo& li = tex.level(levels.level[size_t(i)]);
        const bool linear = (levels.linear >> i) & 1;
        const uint8_t* bytes = tap.unorm8 ? tex.unorm8() + li.offset * 4 : nullptr;
        const float* values = tap.unorm8 || !tex.values() ? nullptr : tex.values() + li.offset * 4;
        const ps11::FloatTexels texels = tap.unorm8 || values ? ps11::FloatTexels{} : tex.floatTexels().from(li.offset);
        changed |= bytes != tap.bytes || values != tap.values || texels.base != tap.texels.base || linear != tap.linear;
        tap.bytes = bytes;
        tap.values = values;
        tap.texels = texels;
        tap.width = li.width;
        tap.height = li.height;
        tap.linear = linear;
    }
    if (changed) draw.serial = nextRowDrawSerial();
}

namespace {

// Runs of consecutive texel pairs shorter than this are gathered.
constexpr int kMinSeqColumns = 8;

void columnStretches(FloatRowTriangle::Columns& cols, int n) {
    using C = FloatRowTriangle::Columns;
    cols.stretches.clear();
    auto add = [&](int x0, int x1, C::Kind kind) {
        // (Two runs of consecutive pairs never merge: each starts at its own texel.)
        if (kind != C::kSeq && !cols.stretches.empty() && cols.stretches.back().kind == kind &&
            cols.stretches.back().x1 == x0)
            cols.stretches.back().x1 = x1;
        else
            cols.stretches.push_back({x0, x1, kind});
    };
    const int32_t* i0 = cols.i0.data();
    const int32_t* i1 = cols.i1.data();
    int x = 0;
    while (x < n) {
        if (i0[x] < 0 || i1[x] < 0) {
            add(x, x + 1, C::kBorder);
            ++x;
            continue;
        }
        int e = x + 1;
        while (e < n && i0[e] == i0[x] + (e - x) && i1[e] == i0[e] + 1) ++e;
        if (i1[x] == i0[x] + 1 && e - x >= kMinSeqColumns) {
            add(x, e, C::kSeq);
            x = e;
            continue;
        }
        add(x, x + 1, C::kInside);
        ++x;
    }
}

}  // namespace

bool prepareFloatRowTriangle(const FloatRowDraw& draw, const TriangleSetup& s, FloatRowTriangle& out,
                             const std::pair<int, int>* columns) {
    if (!rowPathKind(draw.plan, draw.bound, s, out.x0, out.x1)) return false;
    if (columns) out.x0 = columns->first, out.x1 = columns->second;
    out.levelFree = 0;
    fillFloatRowTables(draw, s, out);
    return true;
}

void fillFloatRowTables(const FloatRowDraw& draw, const TriangleSetup& s, FloatRowTriangle& out) {
    const int n = out.x1 - out.x0;
    out.freeTaps = freeTaps(draw.plan, draw.bound, s) | out.levelFree;
    thread_local std::vector<float> u;
    u.resize(static_cast<size_t>(std::max(n, 0)));
    for (int i = 0; i < draw.plan.count; ++i) {
        const FloatRowTap& tap = draw.taps[size_t(i)];
        FloatRowTriangle::Columns& cols = out.taps[size_t(i)];
        if (!tap.bound || ((out.freeTaps >> i) & 1)) {  // no table (the triangle may be a previous chunk's or draw's)
            cols.i0.clear(), cols.i1.clear(), cols.f.clear(), cols.stretches.clear(), cols.runEnd.clear();
            continue;
        }
        columnU(s, tap.coordSet, out.x0, n, u.data());
        cols.i0.resize(size_t(n));
        cols.i1.resize(size_t(n));
        cols.f.resize(size_t(n));
        ps11::floatAxisTaps(tap.addressU, tap.linear, draw.weights8, n, u.data(), tap.width, cols.i0.data(),
                            cols.i1.data(), cols.f.data());
        columnStretches(cols, n);
        // (Row-path triangles have no perspective: v moves by one step a row.)
        const float dv = (rowV(s, tap.coordSet, s.yMin + 1) - rowV(s, tap.coordSet, s.yMin)) * float(tap.height);
        cols.uncached = tap.linear && std::abs(dv) >= 2.0f;
        cols.runEnd.resize(tap.linear ? 0 : size_t(n));
        if (!tap.linear)
            for (int x = n - 1; x >= 0; --x)
                cols.runEnd[size_t(x)] =
                    x + 1 < n && cols.i0[size_t(x) + 1] == cols.i0[size_t(x)] + 1 ? cols.runEnd[size_t(x) + 1] : x + 1;
    }
}

void shareFloatRowTables(const FloatRowDraw& draw, FloatRowTriangle* tris, const uint8_t* prepared,
                         const uint32_t* tableOf, size_t count) {
    static std::atomic<uint64_t> ids{0};
    // Two taps' H rows are equal when they filter the same texels (texture, border) with the same
    // columns, texel pairs and weights (compared by bits; an unbound tap's table is empty).
    // Triangles are compared by the tables that serve them.
    auto sameRows = [&](size_t i, int t, size_t j, int u) {
        const FloatRowTap &a = draw.taps[size_t(t)], &b = draw.taps[size_t(u)];
        const FloatRowTriangle &ti = tris[tableOf[i]], &tj = tris[tableOf[j]];
        const FloatRowTriangle::Columns &c = ti.taps[size_t(t)], &o = tj.taps[size_t(u)];
        return a.bound == b.bound && a.unorm8 == b.unorm8 && a.bytes == b.bytes && a.values == b.values &&
               a.texels.base == b.texels.base && a.width == b.width && a.border == b.border && tj.x0 == ti.x0 &&
               tj.x1 == ti.x1 && o.i0 == c.i0 && o.i1 == c.i1 && o.f.size() == c.f.size() &&
               (c.f.empty() || std::memcmp(o.f.data(), c.f.data(), sizeof(float) * c.f.size()) == 0);
    };
    for (size_t i = 0; i < count; ++i) {
        if (!prepared[i] || tableOf[i] != i) continue;  // served by another's tables: its ids
        for (int t = 0; t < draw.plan.count; ++t) {
            FloatRowTriangle::Columns& c = tris[i].taps[size_t(t)];
            c.tableId = 0;
            // The triangle before (a quad's other half) and this one's earlier taps: a draw of
            // many triangles compares each with a few, not all.
            for (size_t j = i > 0 ? i - 1 : 0; j <= i && !c.tableId; ++j)
                for (int u = 0; u < (j < i ? draw.plan.count : t) && !c.tableId; ++u)
                    if (prepared[j] && sameRows(i, t, j, u)) c.tableId = tris[tableOf[j]].taps[size_t(u)].tableId;
            if (!c.tableId) c.tableId = ++ids;
        }
    }
}

void drawFloatRows(const FloatRowDraw& draw, const FloatRowTriangle* const* tris, const TriangleSetup* const* setups,
                   size_t count, int y0, int y1, FloatRowScratch& sc, AlignedStats& stats, const RowWindow* windows,
                   size_t windowCount) {
    const ps11::Executor& exec = *draw.executor;
    const RowWindows ws = rowWindows(windows, windowCount);
    windows = ws.data, windowCount = ws.count;
    const uint32_t neededTaps = ws.taps;
    const int taps = draw.plan.count;
    std::array<RowTaps, 8> rows{};
    sc.quadLevels.used = 0;  // (a quad's two rows are drawn in one call: bands start on even rows)
    RowSampler sampler(draw, rows, sc.quadLevels);
    ps11::PixelInputs in;
    for (int c = 0; c < 4; ++c) {
        if ((draw.colorAttrs >> (kAttrDiffuse + c)) & 1) in.color[0][c] = sc.color[c];
        if ((draw.colorAttrs >> (kAttrSpecular + c)) & 1) in.color[1][c] = sc.color[4 + c];
    }
    // (RowSampler serves the plain reads by lane position (SampleRequest::lane) and divides
    // their coordinates itself, tapCoords: the executor sees (0, 0, 1, 1) for their sets, so no
    // texkill of the executor's kills a lane there; the runs test them, rowKills.)
    for (int set = 0; set < ps11::kMaxTexCoordSets; ++set) {
        in.texcoord[set][2] = in.texcoord[set][3] = kOnes.data();
        // (The sets the plan's executed instructions read: their coordinates, as spans give them.)
        if ((draw.plan.executedSets >> set) & 1)
            for (int c = 0; c < 4; ++c)
                in.texcoord[set][c] = (draw.executedAttrs >> attrTex(set, c)) & 1 ? sc.coords[4 * set + c] : nullptr;
    }
    ps11::PixelOutputs outp;
    for (int c = 0; c < 4; ++c) outp.color[c] = sc.out[c];
    // (A register's texkill discards lanes: merged over the others. A coordinate set's texkill
    // kills no lane here where the set is a plain read's alone (0, 0, 1), and the lanes rowKills
    // kills where an executed instruction reads it too (its coordinates): rowKills tests them.)
    outp.killed = draw.plan.registerKills ? sc.killed : nullptr;
    outp.depth = draw.shaderDepth ? sc.depth : nullptr;  // (the program's depth, for the merger)
    uint64_t texelsPerPixel = 0;
    for (int t = 0; t < taps; ++t)
        texelsPerPixel += draw.taps[size_t(t)].bound ? (draw.taps[size_t(t)].linear ? 4 : 1) : 0;
    JoinPlans joins(tris, setups, count, draw.plan, draw.colorAttrs);  // (joinRow)
    // Row by row, and within a row the triangles in primitive order (every pixel sees them in
    // order; the H rows of a pixel row serve all of them: a full-screen quad's two triangles
    // share their tables, so each texel row is filtered once, not once per triangle).
    for (int y = y0; y < y1; ++y) {
        sc.rowStart = sc.stamp;  // H rows used from here on serve this pixel row
        for (size_t ti = 0; ti < count; ++ti) {
            const FloatRowTriangle& tri = *tris[ti];
            const TriangleSetup& s = *setups[ti];
            int xl = 0, xr = 0;
            if (!rowSpan(s, y, windows, windowCount, xl, xr)) continue;
            // The quad's other half, when its run of this row continues this one's (joinRow).
            // (Not under a depth test: the two halves' z planes are their own. Nor where a tap is
            // sampled at its quads' levels: those come from the quad's two rows, and joinRow
            // compares one.)
            const bool joined = !draw.wantZ && !(tri.freeTaps & draw.levelTaps.mask) && !draw.executedAttrs &&
                                ti + 1 < count &&
                                tris[ti + 1]->x0 == tri.x0 &&
                                tris[ti + 1]->x1 == tri.x1 &&
                                joinRow(s, *setups[ti + 1], joins.pair(ti), y, windows, windowCount, xl, xr);
            sampler.setTriangle(tri, s, y, sc.sampler);
            // (The worker's sampler counts the texels of the per-pixel taps it serves: not 8-bit,
            // or at their quads' levels, which the row sampler counts where it filters them.)
            uint64_t rowTexelsPerPixel = texelsPerPixel;
            for (int t = 0; t < taps; ++t)
                if (((tri.freeTaps >> t) & 1) && draw.taps[size_t(t)].bound &&
                    (!draw.taps[size_t(t)].unorm8 || ((draw.levelTaps.mask >> t) & 1)))
                    rowTexelsPerPixel -= draw.taps[size_t(t)].linear ? 4 : 1;
            for (int t = 0; t < taps; ++t) {
                const FloatRowTap& tap = draw.taps[size_t(t)];
                if (!tap.bound || !((neededTaps >> t) & 1) || ((tri.freeTaps >> t) & 1)) continue;
                const float v = rowV(s, tap.coordSet, y);
                RowTaps& r = rows[size_t(t)];
                ps11::floatAxisTaps(tap.addressV, tap.linear, draw.weights8, 1, &v, tap.height, &r.j0, &r.j1, &r.fy);
                if (tap.linear) {
                    const bool own = tri.taps[size_t(t)].uncached;
                    r.h0 = hRow(draw, tri, t, r.j0, sc, own ? &sc.own[2 * size_t(t)] : nullptr);
                    r.h1 = hRow(draw, tri, t, r.j1, sc, own ? &sc.own[2 * size_t(t) + 1] : nullptr);
                }
                // (Point taps read the lanes' texels straight from the row: RowSampler::sample.)
            }
            for (size_t wi = 0; wi < windowCount; ++wi) {
                const RowWindow* window = &windows[wi];
                const RowMode mode = window->mode;
                const int wl = std::max(xl, window->x0), wr = std::min(xr, window->x1);
                for (int x = wl; x < wr; x += ps11::kMaxSpan) {
                    const int n = std::min(ps11::kMaxSpan, wr - x);
                    sampler.setX(x);
                    if (mode == RowMode::Shade) {
                        in.uniformColor = fillRowColors(draw.colorAttrs, s, x, y, n, sc.color);
                        if (draw.executedAttrs) fillRowCoords(draw.executedAttrs, s, x, y, n, sc.coords);
                        in.count = n;
                        exec.run(in, sampler, outp, &stats.exec);
                        stats.texels += uint64_t(n) * rowTexelsPerPixel + sampler.takeLevelTexels();
                    } else if (mode == RowMode::Copy) {
                        // r0 is the tap's lookup bit for bit (emu/tile_skip.h): the sampler's lanes.
                        const FloatRowTap& tap = draw.taps[size_t(window->copyTap)];
                        ps11::SampleRequest req;
                        req.stage = tap.stage;
                        req.count = n;
                        req.precision = exec.options().precision;
                        req.plainRead = true;  // (lanes from 0: RowSampler reads no coordinates)
                        ps11::SampleResult res;
                        for (int c = 0; c < 4; ++c) res.value[c] = sc.out[c];
                        sampler.sample(req, res);
                        for (int c = 0; c < 4; ++c)
                            if (!((window->copyMask >> c) & 1)) ps11::fillLanes(sc.out[c], n, window->value[size_t(c)]);
                        stats.texels += uint64_t(n) * (tap.bound ? (tap.linear ? 4 : 1) : 0);
                    } else {
                        for (int c = 0; c < 4; ++c) ps11::fillLanes(sc.out[c], n, window->value[size_t(c)]);
                    }
                    MergeInputs mi;
                    mi.count = n;
                    for (int i = 0; i < n; ++i) sc.x[i] = x + i, sc.y[i] = y;
                    mi.x = sc.x;
                    mi.y = sc.y;
                    mi.row = true;
                    if (draw.plan.killSets && rowKills(draw.plan, s, x, y, n, sc.kept)) mi.live = sc.kept;
                    if (draw.plan.registerKills && mode == RowMode::Shade) {
                        if (!mi.live) std::memset(sc.kept, 1, size_t(n));
                        for (int i = 0; i < n; ++i) sc.kept[i] = uint8_t(sc.kept[i] & (sc.killed[i] ^ 1));
                        mi.live = sc.kept;
                    }
                    // (The program's own depth where it writes one: shaded runs only, the tiles of
                    // such draws never being decided.)
                    const bool z = draw.wantZ && !draw.shaderDepth;
                    fillRowFogDepth(s, draw.merge.fog, z, x, y, n, sc.fog, sc.z);
                    mi.fog = draw.merge.fog ? sc.fog : nullptr;
                    mi.z = draw.shaderDepth ? sc.depth : z ? sc.z : nullptr;
                    for (int c = 0; c < 4; ++c) mi.color[c] = sc.out[c];
                    MergeStats ms;
                    mergePixels(draw.mergePlan, draw.merge, mi, &ms);
                    stats.written += ms.written;
                    stats.pixels += uint64_t(n);
                }
            }
            if (joined) ++ti;  // its pixels of this row were drawn
        }
    }
}

}  // namespace emu
