// Device stage: the aligned-pass path of DrawPrimitiveUP (emu/aligned_pass.h), drawing its rows
// (the set-up, tables and joins are emu/aligned_setup.cpp; the per-worker H-row cache
// emu/aligned_hrows.cpp; the per-pixel attributes emu/aligned_attributes.cpp; the stores to 8-bit
// targets emu/aligned_store.cpp): per-row filtering of each tap into int16 lanes (scalar for any
// footprint, the SIMD level's vector kernels for runs of columns that step a fixed number of
// texels with a fixed weight) or into words (chain rows), the pre-sampled executor run or the
// chain-row one, and the stores. The blend is the exact sum Σ w·byte rounded once,
// half to even (docs/precision.md "Sampling"); the row coordinates are the rasteriser's own
// formula (emu/raster.h planeValue).
#include "emu/aligned_pass.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <limits>

#include "emu/aligned_pass_kernels.h"
#include "emu/format.h"
#include "ps11/fill_lanes.h"
#include "ps11/texture_sampler_fast.h"

namespace emu {

namespace {

// The filtered value of a four-texel sum t = Σ byte·weight (weights of 65536 in all, t < 2^24):
// fx8 round_half_even(t / 65536); fx12 round_half_even(16·t / 65536) = round_half_even(t / 4096).
template <bool Fx12>
inline int32_t roundBlend(uint32_t t) {
    constexpr int kShift = Fx12 ? 12 : 16;
    return int32_t((t + ((1u << (kShift - 1)) - 1) + ((t >> kShift) & 1u)) >> kShift);
}

// Channel c (r g b a) of a b g r a word.
inline uint32_t channel(uint32_t word, int c) { return (word >> (8 * ps11::kUnorm8Byte[c])) & 0xffu; }

// One row of one tap: the two texel rows (null = border), the vertical weight, and per config of
// the tap the H-row planes of both texel rows (not ready: the tap's runs are filtered per pixel
// on this row, a border row).
struct TapRow {
    const uint8_t* row0 = nullptr;
    const uint8_t* row1 = nullptr;
    int32_t wy = 0;
    struct Planes {
        const uint16_t* p[4];
    };
    std::array<Planes, kMaxTapConfigs> h0{}, h1{};
    std::array<bool, kMaxTapConfigs> ready{};
    // Point texels of one row at step 1 (a 1:1 point tap, weight 0 both ways): filterTap
    // deinterleaves them from the texel row into the lanes, no H row staged.
    std::array<bool, kMaxTapConfigs> direct{};
};

// Any footprint, one pixel at a time: the exact four-texel sum of the reference, column x (of the
// triangle's columns), r g b a.
template <bool Fx12>
inline void filterTexel(const AlignedTap& tap, const AlignedTriangle::Columns& cols, const TapRow& row, int x,
                        int32_t out[4]) {
    const int32_t wy = row.wy;
    const int32_t o0 = cols.off0[size_t(x)], o1 = cols.off1[size_t(x)], wx = cols.w[size_t(x)];
    const uint32_t a = row.row0 && o0 >= 0 ? load32(row.row0 + o0) : tap.borderWord;
    const uint32_t b = row.row0 && o1 >= 0 ? load32(row.row0 + o1) : tap.borderWord;
    const uint32_t c = row.row1 && o0 >= 0 ? load32(row.row1 + o0) : tap.borderWord;
    const uint32_t d = row.row1 && o1 >= 0 ? load32(row.row1 + o1) : tap.borderWord;
    for (int ch = 0; ch < 4; ++ch) {
        const uint32_t h0 = channel(a, ch) * uint32_t(256 - wx) + channel(b, ch) * uint32_t(wx);
        const uint32_t h1 = channel(c, ch) * uint32_t(256 - wx) + channel(d, ch) * uint32_t(wx);
        out[ch] = roundBlend<Fx12>(h0 * uint32_t(256 - wy) + h1 * uint32_t(wy));
    }
}

// filterTexel over pixels [first, first + count) into lanes [lane, lane + count) of out.
template <bool Fx12>
void filterScalar(const AlignedTap& tap, const AlignedTriangle::Columns& cols, const TapRow& row, int colBase,
                  int first, int count, int lane, int16_t* const out[4]) {
    for (int i = 0; i < count; ++i) {
        int32_t v[4];
        filterTexel<Fx12>(tap, cols, row, first + i - colBase, v);
        for (int ch = 0; ch < 4; ++ch) out[ch][lane + i] = int16_t(v[ch]);
    }
}

// What the vertical blend of a vector run reads from column x on: both texel rows' H-row planes
// (the second only at vertical weight ≠ 0) and their kind.
struct BlendRows {
    const uint16_t* h0[4];
    const uint16_t* h1[4];
    HKind kind;
};
inline BlendRows blendRows(const TapRow& row, const AlignedTriangle::Columns& cols, const AlignedTriangle::Run& run,
                           int x, int colBase) {
    const int j = run.j0 + (x - run.x0);
    const TapRow::Planes& p0 = row.h0[size_t(run.config)];
    const TapRow::Planes& p1 = row.h1[size_t(run.config)];
    BlendRows b{};
    for (int c = 0; c < 4; ++c) {
        b.h0[c] = p0.p[c] + j;
        b.h1[c] = row.wy ? p1.p[c] + j : nullptr;
    }
    b.kind = run.tabulated ? (cols.tabulatedQ16 ? HKind::Q : HKind::H) : hKindOf(cols.w[size_t(x - colBase)]);
    return b;
}

// A copied window's columns [x, x + n) of its tap, stored (or added) as words without lanes.
// - A tap that reads consecutive texels of one row with zero weights (a 1:1 tap, point or at
//   texel centres): the filter returns each texel's own bytes ((256·256·t + 2¹⁵) >> 16 = t), and
//   a plain store writes them back in the same b g r a order, so the texel bytes are the target's
//   (| orMask for X8R8G8B8), then the constant channels; an additive store (ONE/ONE into an 8-bit
//   target) adds those bytes to the target's with saturation, as storeRow does.
// - fx8, columns all in vector runs whose H rows are ready (a magnified or blended tap: a glare
//   composite's): each run's vertical blend goes to the target as words (verticalStore), the
//   bytes vertical makes and storeRow packs, masked and added the same way.
// None where the columns do not qualify (the caller filters).
enum class CopyRoute { None, Texels, Blended };
CopyRoute copyTexels(const AlignedDraw& draw, const AlignedTriangle& tri, const std::array<TapRow, 8>& rows,
                     const RowWindow& window, int x, int n, uint32_t orMask, bool additive, const uint8_t* base,
                     uint8_t* dst) {
    const int t = window.copyTap;
    const AlignedTap& tap = draw.taps[size_t(t)];
    const TapRow& row = rows[size_t(t)];
    if (!tap.bound || ((tri.freeTaps >> t) & 1) || !row.row0) return CopyRoute::None;
    const AlignedTriangle::Columns& cols = tri.taps[size_t(t)];
    const size_t i0 = size_t(x - tri.x0);
    const int32_t o = cols.off0[i0];
    // 1:1 texels: a vector run of step 1 and weight 0 covering the columns qualifies as a whole;
    // otherwise each column is checked.
    bool texels = row.wy == 0 && o >= 0;
    if (texels) {
        const int32_t r = cols.run[i0];
        bool whole = false;
        if (r >= 0) {
            const AlignedTriangle::Run& run = cols.runs[size_t(r)];
            const HConfig& h = tri.configs[size_t(cols.configs[size_t(run.config)])];
            whole = !run.tabulated && h.step == 1 && h.wx == 0 && run.x1 >= x + n;
        }
        for (int i = 0; i < n && !whole && texels; ++i)
            texels = cols.off0[i0 + size_t(i)] == o + 4 * i && cols.w[i0 + size_t(i)] == 0;
    }
    // Else ready vector runs over every column.
    if (!texels) {
        if (draw.fx12 || !draw.kernels) return CopyRoute::None;
        for (int c = x; c < x + n;) {
            const int32_t r = cols.run[size_t(c - tri.x0)];
            if (r < 0 || !row.ready[size_t(cols.runs[size_t(r)].config)]) return CopyRoute::None;
            c = int(cols.runs[size_t(r)].x1);
        }
    }
    uint32_t keep = ~0u, set = orMask;  // the constant channels' bytes (b g r a: r g b a at 2 1 0 3)
    for (int c = 0; c < 4; ++c)
        if (!((window.copyMask >> c) & 1)) {
            const int shift = 8 * ps11::kUnorm8Byte[c];
            keep &= ~(0xffu << shift);
            int32_t byte = std::clamp<int32_t>(window.grid[size_t(c)], 0, 255);
            if (draw.fx12) {
                // fx12: a texel's grid value is 16·b, whose byte is b, and 16·b + 16·d adds bytes
                // with saturation; a constant between two bytes would round with the sum: filtered.
                const int32_t g = std::clamp<int32_t>(window.grid[size_t(c)], 0, kG12);
                if (additive && g % 16 != 0) return CopyRoute::None;
                byte = int32_t(unorm8OfFx12(g));
            }
            set |= uint32_t(byte) << shift;
        }
    if (texels) {
        storeWords(row.row0 + o, n, keep, set, additive, base, dst);
        return CopyRoute::Texels;
    }
    for (int c = x; c < x + n;) {
        const AlignedTriangle::Run& run = cols.runs[size_t(cols.run[size_t(c - tri.x0)])];
        const int e = std::min(x + n, int(run.x1));
        uint8_t* const out = dst + 4 * (c - x);
        const uint8_t* const under = base + 4 * (c - x);
        if (row.direct[size_t(run.config)]) {
            storeWords(row.row0 + cols.off0[size_t(c - tri.x0)], e - c, keep, set, additive, under, out);
        } else {
            const BlendRows b = blendRows(row, cols, run, c, tri.x0);
            draw.kernels->verticalStore(b.kind, b.h0, b.h1, row.wy, e - c, keep, set, additive, under, out);
        }
        c = e;
    }
    return CopyRoute::Blended;
}

// Sets the texel rows and vertical weight of `r` for the row's v (its H-row planes are the
// caller's to set).
void setTapRow(TapRow& r, const AlignedTap& tap, float v) {
    int32_t j0 = 0, j1 = 0, w = 0;
    ps11::fastpath::axisTable(tap.addressV, tap.linear, 1, &v, tap.height, &j0, &j1, &w);
    const size_t pitch = size_t(tap.width) * 4;
    r.row0 = j0 >= 0 ? tap.texels + size_t(j0) * pitch : nullptr;
    r.row1 = j1 >= 0 ? tap.texels + size_t(j1) * pitch : nullptr;
    r.wy = w;
}

// Stretches of columns outside vector runs at least this long are filtered with the tabulated
// kernels directly (filterTap).
constexpr int kMinDirectColumns = 8;

// Filters pixels [first, first + count) of a row of one tap into out[c][0 .. count); vector runs
// (only where the draw has kernels) with `kernels`.
// GCC's SLP vectoriser would read out[] two pointers per 16-byte load, and the caller writes them
// one by one: a load the store buffer cannot forward, a stall on every call (6 % of a composite).
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-slp-vectorize")))
#endif
void filterTap(const AlignedKernels* kernels, bool fx12, const AlignedTap& tap, const AlignedTriangle::Columns& cols,
               const TapRow& row, int colBase, int first, int count, int16_t* const out[4]) {
    if (!tap.bound) {
        for (int c = 0; c < 4; ++c) ps11::fillLanes(out[c], count, int16_t(c == 3 ? (fx12 ? kG12 : 255) : 0));
        return;
    }
    // fx12 takes the vertical kernel that rounds 16·t / 65536 and its texels times 16.
    const auto vertical = kernels ? (fx12 ? kernels->vertical12 : kernels->vertical) : nullptr;
    auto vectorRun = [&](int x) {
        const int32_t r = cols.run[size_t(x - colBase)];
        return r >= 0 && row.ready[size_t(cols.runs[size_t(r)].config)] ? r : -1;
    };
    int x = first;
    const int end = first + count;
    while (x < end) {
        const int r = vectorRun(x);
        if (r >= 0) {
            const AlignedTriangle::Run& run = cols.runs[size_t(r)];
            const int e = std::min(end, int(run.x1));
            if (row.direct[size_t(run.config)]) {
                const int n = e - x, n16 = n & ~15;  // whole groups: the kernel writes no lane past them
                const int lane = x - first;
                uint16_t* const dst[4] = {
                    reinterpret_cast<uint16_t*>(out[0] + lane), reinterpret_cast<uint16_t*>(out[1] + lane),
                    reinterpret_cast<uint16_t*>(out[2] + lane), reinterpret_cast<uint16_t*>(out[3] + lane)};
                const uint8_t* texels = row.row0 + cols.off0[size_t(x - colBase)];
                if (n16) kernels->deinterleave(texels, n16, dst);
                if (n > n16) {
                    // The last texels into a group of its own (the kernel fills a whole group and
                    // reads no texel past the count), then the lanes that are this run's.
                    alignas(32) uint16_t tail[4][16];
                    uint16_t* const t[4] = {tail[0], tail[1], tail[2], tail[3]};
                    kernels->deinterleave(texels + 4 * n16, n - n16, t);
                    for (int c = 0; c < 4; ++c) std::memcpy(dst[c] + n16, tail[c], sizeof(uint16_t) * size_t(n - n16));
                }
                if (fx12)
                    for (int c = 0; c < 4; ++c)
                        for (int i = 0; i < n; ++i) dst[c][i] = uint16_t(dst[c][i] << 4);
                x = e;
                continue;
            }
            const BlendRows b = blendRows(row, cols, run, x, colBase);
            vertical(b.kind, b.h0, b.h1, row.wy, e - x, x - first, out);
            x = e;
            continue;
        }
        // Up to the next ready vector run: columns whose texels are all inside the texture, with
        // both texel rows at hand, have their H rows built for these columns alone and blended at
        // once (the tabulated kernels without the cache: stretches shorter than a run, and runs of
        // an uncached configuration, HConfig::uncached); border texels, short stretches or no
        // vector kernels, one pixel at a time. (A run's columns all lie inside the texture: a run
        // that is not ready is passed whole.)
        int e = x;
        bool inside = kernels && row.row0 && (row.wy == 0 || row.row1);
        while (e < end) {
            const size_t i = size_t(e - colBase);
            const int32_t r = cols.run[i];
            if (r >= 0) {
                const AlignedTriangle::Run& run = cols.runs[size_t(r)];
                if (row.ready[size_t(run.config)]) break;
                e = std::min(end, int(run.x1));
                continue;
            }
            inside = inside && cols.off0[i] >= 0 && cols.off1[i] >= 0;
            ++e;
        }
        inside = inside && e - x >= kMinDirectColumns;
        if (inside) {
            alignas(32) uint16_t planes[2][4][ps11::kMaxSpan + kHRowPad];
            uint16_t* const h0[4] = {planes[0][0], planes[0][1], planes[0][2], planes[0][3]};
            uint16_t* const h1[4] = {planes[1][0], planes[1][1], planes[1][2], planes[1][3]};
            const size_t at = size_t(x - colBase);
            for (int done = 0; done < e - x; done += ps11::kMaxSpan) {
                const int n = std::min(ps11::kMaxSpan, e - x - done);
                const size_t k = at + size_t(done);
                kernels->buildTabulated(row.row0, int(tap.width), &cols.off0[k], &cols.off1[k], &cols.w[k], n, h0, 0);
                if (row.wy != 0)
                    kernels->buildTabulated(row.row1, int(tap.width), &cols.off0[k], &cols.off1[k], &cols.w[k], n, h1, 0);
                const uint16_t* const c0[4] = {h0[0], h0[1], h0[2], h0[3]};
                const uint16_t* const c1[4] = {h1[0], h1[1], h1[2], h1[3]};
                vertical(HKind::H, c0, c1, row.wy, n, x + done - first, out);
            }
        } else {
            if (fx12)
                filterScalar<true>(tap, cols, row, colBase, x, e - x, x - first, out);
            else
                filterScalar<false>(tap, cols, row, colBase, x, e - x, x - first, out);
        }
        x = e;
    }
}

// ---- chain rows (AlignedDraw::chainRows) ----

// A configuration whose runs chain rows read as they lie: one texel a column, at horizontal
// weight 0 or 128.
inline bool chainConfig(const HConfig& h) { return h.step == 1 && (h.wx == 0 || h.wx == 128); }

// A texel row of (0, 0, 0, 1) texels, what a stage without a texture reads, for chain rows.
const uint8_t* unboundRow() {
    static const auto row = [] {
        std::array<uint8_t, 4 * (ps11::kMaxSpan + 1)> r{};
        for (size_t i = size_t(ps11::kUnorm8Byte[3]); i < r.size(); i += 4) r[i] = 255;
        return r;
    }();
    return row.data();
}

// Whether a chain configuration's run reads this row's texels as they lie (vertical weight 0:
// each column's texel, or the mean of it and the next) or as rounded means of the two texel rows
// (weight 128, both rows texels: the half-texel taps of Sousa's pinwheel and of box and 3×3
// filters). Chain rows take those with no H rows.
inline bool chainWeight(const TapRow& row) { return row.row0 && (row.wy == 0 || (row.wy == 128 && row.row1)); }

// Whether chain rows run this row: every tap is filtered on the row path (none is sampled per
// pixel at its quads' levels), and one reads its texel rows as they lie (a chain configuration at
// chainWeight: what saves the r g b a planes). Where every tap is blended from H rows (a
// magnified tap), blending them into planes, as the pre-sampled run takes them, costs less than
// into words.
bool chainRow(const AlignedDraw& draw, const AlignedTriangle& tri, const std::array<TapRow, 8>& rows) {
    bool asItLies = false;
    for (int t = 0; t < draw.plan.count; ++t) {
        if (!draw.taps[size_t(t)].bound) continue;
        if ((tri.freeTaps >> t) & 1) return false;
        const TapRow& r = rows[size_t(t)];
        const AlignedTriangle::Columns& cols = tri.taps[size_t(t)];
        for (int c = 0; c < cols.configCount && !asItLies; ++c)
            asItLies = chainWeight(r) && chainConfig(tri.configs[size_t(cols.configs[size_t(c)])]);
    }
    return asItLies;
}

// Tap t's chain run at column c, where its texel rows are read as they lie (chainWeight), or null.
// (Inlined: it runs for every tap of every chain row and its columns between runs.)
[[gnu::always_inline]] inline const AlignedTriangle::Run* chainRun(const AlignedTriangle& tri,
                                                                const AlignedTriangle::Columns& cols,
                                                                const TapRow& row, int c) {
    const int32_t r = cols.run[size_t(c - tri.x0)];
    if (r < 0 || !chainWeight(row)) return nullptr;
    const AlignedTriangle::Run& run = cols.runs[size_t(r)];
    return !run.tabulated && chainConfig(tri.configs[size_t(cols.configs[size_t(run.config)])]) ? &run : nullptr;
}

// Tap t of columns [x, x + n) straight from its texel row, where one chain run covers them all.
bool directTap(const AlignedDraw& draw, const AlignedTriangle& tri, const std::array<TapRow, 8>& rows, int t, int x,
               int n, ps11::ChainRowTap& tap) {
    if (!draw.taps[size_t(t)].bound) {
        tap = ps11::ChainRowTap{unboundRow(), false};
        return true;
    }
    const AlignedTriangle::Columns& cols = tri.taps[size_t(t)];
    const TapRow& row = rows[size_t(t)];
    const AlignedTriangle::Run* run = chainRun(tri, cols, row, x);
    if (!run || row.wy != 0 || int(run->x1) < x + n) return false;
    const HConfig& h = tri.configs[size_t(cols.configs[size_t(run->config)])];
    tap = ps11::ChainRowTap{row.row0 + cols.off0[size_t(x - tri.x0)], h.wx != 0};
    return true;
}

// Texels past a chain row's span that a tap's row of means is formed for (AlignedScratch::tapBytes
// has room for 32).
constexpr int kFormedPast = 16;

// Words of means a tap formed on a chain row (patchedRow: its longest run's): their texel rows,
// weights and form (halfway: of each texel and the next), where the first word's texels lie (src,
// in row0) and where `pixels` words are.
// (No member initialisers: a row's array of them is set tap by tap, FormedRow{} for none.)
struct FormedRow {
    const uint8_t* row0;
    const uint8_t* row1;
    int32_t wy;
    bool halfway;
    const uint8_t* src;
    const uint8_t* bytes;
    int pixels;
};

// The words of an earlier tap's formed row (formed[0, count)) that are `key`'s: the same texel
// rows, weights and form, its `pixels` words from key.src on within that row's (a box or 3×3
// blur's taps ±½ texel apart read each other's means one texel over), or null.
const uint8_t* formedWords(const FormedRow& key, const FormedRow* formed, int count) {
    for (int u = 0; u < count; ++u) {
        const FormedRow& f = formed[u];
        if (!f.bytes || f.row0 != key.row0 || f.row1 != key.row1 || f.wy != key.wy || f.halfway != key.halfway ||
            key.src < f.src)
            continue;
        const ptrdiff_t delta = key.src - f.src;
        if (delta % 4 == 0 && delta / 4 + key.pixels <= f.pixels) return f.bytes + delta;
    }
    return nullptr;
}

// Tap t's columns [x, x + n) straight from an earlier tap's formed row (formedWords), where one
// run of means covers them all, or null.
const uint8_t* sharedRow(const AlignedDraw& draw, const AlignedTriangle& tri, const std::array<TapRow, 8>& rows,
                         int t, int x, int n, const FormedRow* formed) {
    if (!draw.taps[size_t(t)].bound) return nullptr;
    const AlignedTriangle::Columns& cols = tri.taps[size_t(t)];
    const TapRow& row = rows[size_t(t)];
    const AlignedTriangle::Run* run = chainRun(tri, cols, row, x);
    if (!run || int(run->x1) < x + n) return nullptr;
    const bool halfway = tri.configs[size_t(cols.configs[size_t(run->config)])].wx != 0;
    if (row.wy == 0 && !halfway) return nullptr;
    const FormedRow key{row.row0, row.row1, row.wy, halfway, row.row0 + cols.off0[size_t(x - tri.x0)], nullptr, n};
    return formedWords(key, formed, t);
}

// Tap t's filtered texels of columns [x, x + n) (n <= kMaxSpan) as a row of words of its own, for
// chain rows: chain runs copied from the texel row or formed as the rounded means of their two or
// four texels (meanBytes: a halfway tap's, either way or both; or copied where an earlier tap
// formed them, formed[0, t)), runs with H rows blended into words (verticalBytes), each other
// column at weight 0 both ways its one texel (or the border colour's bytes), the rest filtered
// per pixel (filterTexel for a few columns, filterTap for a longer stretch). formed[t], which the
// caller cleared, says where its longest run of means is for the taps after it.
const uint8_t* patchedRow(const AlignedDraw& draw, const AlignedTriangle& tri, const std::array<TapRow, 8>& rows,
                          int t, int x, int n, AlignedScratch& sc, FormedRow* formed) {
    const AlignedTap& tap = draw.taps[size_t(t)];
    if (!tap.bound) return unboundRow();
    const AlignedTriangle::Columns& cols = tri.taps[size_t(t)];
    const TapRow& row = rows[size_t(t)];
    uint8_t* const out = sc.tapBytes[t];
    auto blendRun = [&](int c) -> const AlignedTriangle::Run* {
        const int32_t r = cols.run[size_t(c - tri.x0)];
        if (r < 0) return nullptr;
        const AlignedTriangle::Run& run = cols.runs[size_t(r)];
        return row.ready[size_t(run.config)] && !row.direct[size_t(run.config)] ? &run : nullptr;
    };
    auto onePoint = [&](int c) { return row.wy == 0 && row.row0 && cols.w[size_t(c - tri.x0)] == 0; };
    for (int c = x; c < x + n;) {
        uint8_t* dst = out + 4 * size_t(c - x);
        if (const AlignedTriangle::Run* run = chainRun(tri, cols, row, c)) {
            const int e = std::min(x + n, int(run->x1));
            const int32_t off = cols.off0[size_t(c - tri.x0)];
            const uint8_t* const r0 = row.row0 + off;
            const bool halfway = tri.configs[size_t(cols.configs[size_t(run->config)])].wx != 0;
            int m = e - c;
            if (row.wy != 0 || halfway) {
                const FormedRow key{row.row0, row.row1, row.wy, halfway, r0, nullptr, m};
                if (const uint8_t* earlier = formedWords(key, formed, t)) {
                    std::memcpy(dst, earlier, 4 * size_t(m));
                    c = e;
                    continue;
                }
                // The row's last run: formed kFormedPast texels further where the texel row has
                // them, for a later tap on the same rows a few texels to the right.
                if (e == x + n) m += std::clamp(int(tap.width) - off / 4 - (halfway ? 1 : 0) - m, 0, kFormedPast);
                if (m > formed[t].pixels) formed[t] = FormedRow{row.row0, row.row1, row.wy, halfway, r0, dst, m};
            }
            if (row.wy == 0 && !halfway) {
                std::memcpy(dst, r0, 4 * size_t(m));
            } else if (row.wy == 0) {
                const uint8_t* const src[4] = {r0, r0 + 4, nullptr, nullptr};
                draw.kernels->meanBytes(src, 2, 4 * m, dst);
            } else {
                const uint8_t* const r1 = row.row1 + off;
                const uint8_t* const src[4] = {r0, r1, r0 + 4, r1 + 4};
                draw.kernels->meanBytes(src, halfway ? 4 : 2, 4 * m, dst);
            }
            c = e;
            continue;
        }
        if (const AlignedTriangle::Run* run = blendRun(c)) {
            const int e = std::min(x + n, int(run->x1));
            const BlendRows b = blendRows(row, cols, *run, c, tri.x0);
            draw.kernels->verticalBytes(b.kind, b.h0, b.h1, row.wy, e - c, dst);
            c = e;
            continue;
        }
        if (onePoint(c)) {
            const size_t k = size_t(c - tri.x0);
            const uint32_t word = cols.off0[k] >= 0 ? load32(row.row0 + cols.off0[k]) : tap.borderWord;
            std::memcpy(dst, &word, 4);
            ++c;
            continue;
        }
        int e = c + 1;
        while (e < x + n && !chainRun(tri, cols, row, e) && !blendRun(e) && !onePoint(e)) ++e;
        if (e - c < kMinDirectColumns) {
            // A few columns (a clamped or bordered edge): each pixel's bytes at once.
            for (; c < e; ++c) {
                int32_t v[4];
                filterTexel<false>(tap, cols, row, c - tri.x0, v);
                for (int ch = 0; ch < 4; ++ch) out[4 * size_t(c - x) + size_t(ps11::kUnorm8Byte[ch])] = uint8_t(v[ch]);
            }
            continue;
        }
        int16_t* const planes[4] = {sc.r0[0], sc.r0[1], sc.r0[2], sc.r0[3]};
        filterTap(draw.kernels, false, tap, cols, row, tri.x0, c, e - c, planes);
        const int16_t* const lanes[4] = {sc.r0[0], sc.r0[1], sc.r0[2], sc.r0[3]};
        const int stored = draw.kernels->storeRow(false, lanes, e - c, 0, dst, dst);
        for (int i = stored; i < e - c; ++i)
            for (int ch = 0; ch < 4; ++ch) dst[4 * i + ps11::kUnorm8Byte[ch]] = uint8_t(sc.r0[ch][i]);
        c = e;
    }
    return out;
}

}  // namespace

const AlignedKernels* alignedKernels(ps11::SimdLevel level) {
#if defined(PS11_HAVE_AVX512)
    return ps11::simdTable<AlignedKernels>(level, nullptr, &avx2::kAligned,
                                           ps11::madeTable(level, ps11::SimdLevel::Avx512, &avx512::alignedTable));
#elif defined(PS11_HAVE_AVX2)
    return ps11::simdTable<AlignedKernels>(level, nullptr, &avx2::kAligned);
#else
    (void)level;
    return nullptr;
#endif
}

RowWindows rowWindows(const RowWindow* windows, size_t count) {
    static const RowWindow whole{std::numeric_limits<int>::min(), std::numeric_limits<int>::max()};
    RowWindows w{windows, count, 0};
    if (!windows || count == 0) w.data = &whole, w.count = 1;
    for (size_t i = 0; i < w.count; ++i)
        w.taps |= w.data[i].mode == RowMode::Shade  ? 0xffu
                  : w.data[i].mode == RowMode::Copy ? 1u << w.data[i].copyTap
                                                    : 0u;
    return w;
}

void drawAlignedRows(const AlignedDraw& draw, const AlignedTriangle* const* tris, const TriangleSetup* const* setups,
                     size_t count, int y0, int y1, AlignedScratch& sc, AlignedStats& stats, const RowWindow* windows,
                     size_t windowCount, const RowSource* source) {
    const RowWindows ws = rowWindows(windows, windowCount);
    // The word of the last filled window stored directly (made once per window, not per row).
    const RowWindow* wordOf = nullptr;
    uint8_t fillWord[4] = {0, 0, 0, 0};
    windows = ws.data, windowCount = ws.count;
    const uint32_t neededTaps = ws.taps;
    const ps11::Executor& exec = *draw.executor;
    Image& target = *draw.target.color;
    const bool x8 = target.format->format == D3DFMT_X8R8G8B8;
    const uint32_t orMask = x8 ? 0xff000000u : 0u;
    const int taps = draw.plan.count;
    int16_t* const r0[4] = {sc.r0[0], sc.r0[1], sc.r0[2], sc.r0[3]};
    const int16_t* const r0c[4] = {sc.r0[0], sc.r0[1], sc.r0[2], sc.r0[3]};
    ps11::PixelInputs in;
    for (int c = 0; c < 4; ++c) {
        if ((draw.colorAttrs >> (kAttrDiffuse + c)) & 1) in.color[0][c] = sc.color[c];
        if ((draw.colorAttrs >> (kAttrSpecular + c)) & 1) in.color[1][c] = sc.color[4 + c];
        for (int set = 0; set < kMaxTexSets; ++set)
            if ((draw.executedAttrs >> attrTex(set, c)) & 1) in.texcoord[set][c] = sc.coords[4 * set + c];
    }
    std::array<TapRow, 8> rows{};
    // The executor asks for each tap's lanes chunk by chunk and they are filtered straight into
    // its registers.
    // r0 comes back chunk by chunk: stored to the target row at once where the store is direct
    // (`out`: the row's first pixel), else kept in sc.r0 for the output merger.
    struct FillCtx {
        const AlignedDraw* draw;
        const AlignedTriangle* tri;
        const TriangleSetup* setup;
        const std::array<TapRow, 8>* rows;
        int x, y;
        uint8_t* out;
        const uint8_t* under;  // what an additive store adds to: out, or a RowSource's row
        uint32_t orMask;
        int16_t* const* r0;
        QuadLevels* quadLevels;
        ps11::Sampler* sampler;
    } ctx{&draw, nullptr, nullptr, &rows, 0, 0, nullptr, nullptr, orMask, r0, &sc.quadLevels, sc.sampler};
    sc.quadLevels.used = 0;  // (a quad's two rows are drawn in one call: bands start on even rows)
    const ps11::TapFill fill = [](void* p, int tap, int first, int count, int16_t* const dst[4]) {
        const FillCtx& f = *static_cast<const FillCtx*>(p);
        if ((f.tri->freeTaps >> tap) & 1) {
            sampleFree(*f.draw, *f.setup, tap, f.x + first, f.y, count, *f.quadLevels, f.sampler, dst);
            return;
        }
        filterTap(f.draw->kernels, f.draw->fx12, f.draw->taps[size_t(tap)], f.tri->taps[size_t(tap)],
                  (*f.rows)[size_t(tap)], f.tri->x0, f.x + first, count, dst);
    };
    const ps11::ResultSink sink = [](void* p, int first, int count, const int16_t* const lanes[4]) {
        const FillCtx& f = *static_cast<const FillCtx*>(p);
        if (f.out) {
            storeLanes(*f.draw, lanes, count, f.orMask, f.under + 4 * first, f.out + 4 * first);
            return;
        }
        for (int c = 0; c < 4; ++c) std::memcpy(f.r0[c] + first, lanes[c], sizeof(int16_t) * size_t(count));
    };
    // Chain rows only where every window shades (a copied window's tap reads the H rows).
    bool shadesOnly = true;
    for (size_t wi = 0; wi < windowCount; ++wi) shadesOnly = shadesOnly && windows[wi].mode != RowMode::Copy;
    HRowCache& cache = sc.hrows;
    if (cache.serial != draw.serial) {
        // Another draw: its textures may have changed since (the slots keep their memory).
        for (const std::unique_ptr<HRowCache::Slot>& sl : cache.slots) sl->row = nullptr;
        std::fill(cache.keys.begin(), cache.keys.end(), 0);
        std::fill(cache.stamps.begin(), cache.stamps.end(), 0);
        cache.serial = draw.serial;
    }
    HRowRef planes{};
    float tapV[8] = {};  // each tap's v on the current pixel row
    ps11::ChainRowTap chainTaps[8];  // a chain row's taps (set tap by tap on each)
    // Tabulated configurations: a triangle whose table equals an earlier one's over the same
    // columns takes that one's id, so their H rows are shared (a full-screen quad's two halves).
    // (Only the entries of existing configurations are set and read.)
    std::array<std::array<uint64_t, 8 * kMaxTapConfigs>, kMaxAlignedTriangles> tabIds;
    for (size_t ti = 0; ti < count && ti < kMaxAlignedTriangles; ++ti) {
        const std::vector<HConfig>& cs = tris[ti]->configs;
        for (size_t c = 0; c < cs.size() && c < tabIds[ti].size(); ++c) {
            const HConfig& h = cs[c];
            tabIds[ti][c] = h.tableId;
            if (h.wx != -2) continue;
            const size_t n = size_t(h.jhi - h.jlo);
            for (size_t tj = 0; tj < ti && tabIds[ti][c] == h.tableId; ++tj) {
                const std::vector<HConfig>& os = tris[tj]->configs;
                for (size_t oc = 0; oc < os.size() && oc < tabIds[tj].size(); ++oc) {
                    const HConfig& o = os[oc];
                    if (o.wx == -2 && o.texels == h.texels && o.jlo == h.jlo && o.jhi == h.jhi && o.hash == h.hash &&
                        std::memcmp(o.off0, h.off0, 4 * n) == 0 && std::memcmp(o.off1, h.off1, 4 * n) == 0 &&
                        std::memcmp(o.w, h.w, 4 * n) == 0) {
                        tabIds[ti][c] = tabIds[tj][oc];
                        break;
                    }
                }
            }
        }
    }
    JoinPlans joins(tris, setups, count, draw.plan, draw.colorAttrs);  // (joinRow)
    // Row by row, and within a row the triangles in primitive order (every pixel sees them in
    // order; the H rows of a pixel row serve all of them).
    SourcedRow sourced;
    for (int y = y0; y < y1; ++y) {
        ++cache.stamp;
        const bool fromSource = source && y >= 0 && y < source->height;
        if (fromSource) sourced.start(source->row0 + size_t(y) * source->pitch, target.texel(0, uint32_t(y)), source->width);
        for (size_t ti = 0; ti < count; ++ti) {
            const AlignedTriangle& tri = *tris[ti];
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
            ctx.tri = &tri;
            ctx.setup = &s;
            ctx.y = y;
            for (int t = 0; t < taps; ++t) {
                const AlignedTap& tap = draw.taps[size_t(t)];
                if (!tap.bound || !((neededTaps >> t) & 1) || ((tri.freeTaps >> t) & 1)) continue;
                TapRow& r = rows[size_t(t)];
                // Taps at the same v of the same texture (a horizontal blur's) read the same rows.
                tapV[t] = rowV(s, tap.coordSet, y);
                int same = -1;
                for (int u = 0; u < t && same < 0; ++u) {
                    const AlignedTap& o = draw.taps[size_t(u)];
                    if (o.bound && ((neededTaps >> u) & 1) && !((tri.freeTaps >> u) & 1) && o.texels == tap.texels &&
                        o.height == tap.height &&
                        o.addressV == tap.addressV && o.linear == tap.linear &&
                        std::bit_cast<uint32_t>(tapV[u]) == std::bit_cast<uint32_t>(tapV[t]))
                        same = u;
                }
                if (same >= 0) {
                    r.row0 = rows[size_t(same)].row0, r.row1 = rows[size_t(same)].row1, r.wy = rows[size_t(same)].wy;
                } else {
                    setTapRow(r, tap, tapV[t]);
                }
            }
            // Chain rows read the texel rows of chain configurations' runs at vertical weight 0
            // or 128: those need no H rows.
            const bool chain = draw.chainRows && shadesOnly && chainRow(draw, tri, rows);
            for (int t = 0; t < taps; ++t) {
                const AlignedTap& tap = draw.taps[size_t(t)];
                if (!tap.bound || !((neededTaps >> t) & 1) || ((tri.freeTaps >> t) & 1)) continue;
                TapRow& r = rows[size_t(t)];
                // The H rows of the tap's long runs (built on first use, shared by taps and rows).
                const AlignedTriangle::Columns& cols = tri.taps[size_t(t)];
                const bool rowsOk = r.row0 && (r.row1 || r.wy == 0);
                for (int c = 0; c < cols.configCount; ++c) {
                    const size_t ci = size_t(cols.configs[size_t(c)]);
                    const HConfig& h = tri.configs[ci];
                    r.ready[size_t(c)] = rowsOk && !(chain && chainWeight(r) && chainConfig(h)) && !h.uncached;
                    if (!r.ready[size_t(c)]) continue;
                    r.direct[size_t(c)] = h.wx == 0 && h.step == 1 && r.wy == 0;
                    if (r.direct[size_t(c)]) continue;
                    const uint64_t id =
                        ti < kMaxAlignedTriangles && ci < tabIds[ti].size() ? tabIds[ti][ci] : h.tableId;
                    hRow(*draw.kernels, cache, r.row0, h, id, planes);
                    for (int ch = 0; ch < 4; ++ch) r.h0[size_t(c)].p[ch] = planes.data + size_t(ch) * planes.stride;
                    if (r.wy != 0) {
                        hRow(*draw.kernels, cache, r.row1, h, id, planes);
                        for (int ch = 0; ch < 4; ++ch) r.h1[size_t(c)].p[ch] = planes.data + size_t(ch) * planes.stride;
                    }
                }
            }
            for (size_t wi = 0; wi < windowCount; ++wi) {
                const RowWindow* window = &windows[wi];
                const RowMode mode = window->mode;
                const int wl = std::max(xl, window->x0), wr = std::min(xr, window->x1);
                for (int x = wl; x < wr; x += ps11::kMaxSpan) {
                    const int n = std::min(ps11::kMaxSpan, wr - x);
                    for (int t = 0; t < taps; ++t)
                        if ((mode == RowMode::Shade || (mode == RowMode::Copy && t == window->copyTap)) &&
                            !(((tri.freeTaps & draw.levelTaps.mask) >> t) & 1))  // (those the sampler counts)
                            stats.texels +=
                                uint64_t(n) * (draw.taps[size_t(t)].bound ? (draw.taps[size_t(t)].linear ? 4 : 1) : 0);
                    ctx.x = x;
                    // Stored here, or merged by `mergeState` over the lanes `live` (null: all).
                    bool direct = draw.directStore || draw.directAdd;
                    const MergeState* mergeState = &draw.merge;
                    const uint8_t* live = nullptr;
                    const bool kills = draw.plan.killSets && rowKills(draw.plan, s, x, y, n, sc.kept);
                    if (kills) {  // merged over the pixels kept
                        direct = false;
                        live = sc.kept;
                    }
                    if (draw.depthFirst) {
                        // The run's depth test first: stored here where every pixel passed.
                        for (int i = 0; i < n; ++i) sc.x[i] = x + i, sc.y[i] = y;
                        MergeInputs zi;
                        zi.count = n;
                        zi.x = sc.x;
                        zi.y = sc.y;
                        zi.row = true;
                        fillRowFogDepth(s, false, true, x, y, n, nullptr, sc.z);
                        zi.z = sc.z;
                        zi.live = live;
                        direct = depthTestFirst(draw.merge, zi, draw.target, sc.passed, nullptr) && !kills;
                        mergeState = &draw.afterDepth;
                        live = direct ? nullptr : sc.passed;
                    }
                    // (Fogged runs are stored once their lanes are fogged.)
                    const bool storeAsShaded = direct && !draw.fogFirst;
                    // (Under a RowSource: columns written other than by a direct store — of a
                    // copied, filled or shaded run, each reading sourced.base() — hold the
                    // source's words first.)
                    const bool shadeStored = mode == RowMode::Shade && !chain && storeAsShaded;
                    if (fromSource && !(mode == RowMode::Copy && storeAsShaded) && !shadeStored &&
                        !(mode == RowMode::Fill && storeAsShaded && !(draw.fx12 && draw.directAdd)))
                        sourced.materialise(x, n);
                    if (mode == RowMode::Shade && chain) {
                        // Chain rows, each tap read from its texel row where a chain run covers
                        // the columns, else from a row of its own (patchedRow: a magnified or
                        // blended tap, a horizontal blur's taps at a clamped or bordered edge).
                        FormedRow formed[8];
                        for (int t = 0; t < taps; ++t) {
                            formed[t] = FormedRow{};
                            if (directTap(draw, tri, rows, t, x, n, chainTaps[t])) continue;
                            const uint8_t* row = sharedRow(draw, tri, rows, t, x, n, formed);
                            if (!row) row = patchedRow(draw, tri, rows, t, x, n, sc, formed);
                            chainTaps[t] = ps11::ChainRowTap{row, false};
                        }
                        ps11::runChainRow(exec, chainTaps, n, target.texel(uint32_t(x), uint32_t(y)),
                                          ps11::ChainRowStore{orMask, draw.directAdd}, &stats.exec);
                        stats.pixels += uint64_t(n);
                        stats.written += uint64_t(n);
                        continue;
                    }
                    if (mode == RowMode::Shade) {
                        in.uniformColor = fillRowColors(draw.colorAttrs, s, x, y, n, sc.color);
                        if (draw.executedAttrs) fillRowCoords(draw.executedAttrs, s, x, y, n, sc.coords);
                        in.count = n;
                        ctx.out = storeAsShaded ? target.texel(uint32_t(x), uint32_t(y)) : nullptr;
                        ctx.under = fromSource && storeAsShaded ? sourced.base(x, n) : ctx.out;
                        ps11::PixelOutputs more;
                        more.killed = draw.plan.registerKills ? sc.killed : nullptr;
                        more.depth = draw.shaderDepth ? sc.depth : nullptr;
                        ps11::runPresampled(exec, in, fill, sink, &ctx, &stats.exec,
                                            ps11::PresampledRun{sc.sampler, &more, draw.plan.executedTaps});
                        if (draw.plan.registerKills) {  // (never stored as shaded: directStore is off)
                            for (int i = 0; i < n; ++i) sc.live[i] = uint8_t((live ? live[i] : 1) & (sc.killed[i] ^ 1));
                            live = sc.live;
                        }
                        if (fromSource && storeAsShaded) sourced.mark(x, n);
                        if (storeAsShaded) {
                            stats.pixels += uint64_t(n);
                            stats.written += uint64_t(n);
                            continue;
                        }
                    } else if (mode == RowMode::Copy) {
                        uint8_t* const at = target.texel(uint32_t(x), uint32_t(y));
                        const CopyRoute route =
                            storeAsShaded ? copyTexels(draw, tri, rows, *window, x, n, orMask, draw.directAdd,
                                                       fromSource ? sourced.base(x, n) : at, at)
                                          : CopyRoute::None;
                        if (fromSource) {
                            if (route != CopyRoute::None)
                                sourced.mark(x, n);
                            else
                                sourced.materialise(x, n);  // (filtered into lanes and stored below)
                        }
                        if (route != CopyRoute::None) {
                            stats.pixels += uint64_t(n);
                            stats.written += uint64_t(n);
                            if (route == CopyRoute::Texels) stats.copiedDirect += uint64_t(n);
                            continue;
                        }
                        fill(&ctx, window->copyTap, 0, n, r0);
                        for (int c = 0; c < 4; ++c)
                            if (!((window->copyMask >> c) & 1))
                                ps11::fillLanes(sc.r0[c], n, int16_t(window->grid[size_t(c)]));
                    } else if (storeAsShaded && !(draw.fx12 && draw.directAdd)) {
                        // A filled run stored directly: its word is what storeLanes makes of one
                        // lane, written n times, or (fx8) added n times with saturation, as
                        // storeLanes writes or adds every lane. (fx12 adds the 12-bit value and
                        // rounds the sum once: not a byte added.)
                        if (wordOf != window) {
                            // (Whole groups of lanes: the store kernels read them past the count.)
                            alignas(64) int16_t lanes[4][64];
                            for (int c = 0; c < 4; ++c)
                                ps11::fillLanes(lanes[c], 64, int16_t(window->grid[size_t(c)]));
                            const int16_t* const one[4] = {lanes[0], lanes[1], lanes[2], lanes[3]};
                            std::memset(fillWord, 0, sizeof fillWord);
                            storeLanes(draw, one, 1, orMask, fillWord, fillWord);
                            wordOf = window;
                        }
                        uint8_t* const at = target.texel(uint32_t(x), uint32_t(y));
                        fillWords(fillWord, n, draw.directAdd, fromSource ? sourced.base(x, n) : at, at);
                        if (fromSource) sourced.mark(x, n);
                        stats.pixels += uint64_t(n);
                        stats.written += uint64_t(n);
                        continue;
                    } else {
                        for (int c = 0; c < 4; ++c) ps11::fillLanes(sc.r0[c], n, int16_t(window->grid[size_t(c)]));
                    }
                    stats.pixels += uint64_t(n);
                    uint8_t* row = target.texel(uint32_t(x), uint32_t(y));
                    if (direct && draw.fogFirst) {
                        // The run's fog, as the merger applies it first, on its lanes.
                        MergeInputs fi;
                        fi.count = n;
                        fillRowFogDepth(s, true, false, x, y, n, sc.fog, nullptr);
                        fi.fog = sc.fog;
                        for (int c = 0; c < 3; ++c)
                            for (int i = 0; i < n; ++i) sc.grid[c][i] = sc.r0[c][i];
                        fogGridFirst(draw.merge, fi, draw.target, sc.grid);
                        for (int c = 0; c < 3; ++c)
                            for (int i = 0; i < n; ++i) sc.r0[c][i] = int16_t(sc.grid[c][i]);  // (in [0, G])
                    }
                    if (direct) {
                        storeLanes(draw, r0c, n, orMask, row, row);
                        stats.written += uint64_t(n);
                        continue;
                    }
                    // Anything else: the output merger over the row.
                    MergeInputs mi;
                    mi.count = n;
                    if (!draw.depthFirst)
                        for (int i = 0; i < n; ++i) sc.x[i] = x + i, sc.y[i] = y;
                    mi.x = sc.x;
                    mi.y = sc.y;
                    mi.row = true;
                    mi.live = live;
                    // (The program's own depth where it writes one: shaded runs only, the tiles of
                    // such draws never being decided.)
                    const bool z = draw.wantZ && !draw.depthFirst && !draw.shaderDepth;
                    fillRowFogDepth(s, draw.merge.fog, z, x, y, n, sc.fog, sc.z);
                    mi.fog = draw.merge.fog ? sc.fog : nullptr;
                    mi.z = draw.shaderDepth ? sc.depth : z ? sc.z : nullptr;
                    // (The merger merges fx profiles from the grid: mergeReadsColor says where it also
                    // reads the real values.)
                    const bool readsColor =
                        mergeReadsColor(draw.fx12 ? ps11::Precision::Fx12 : ps11::Precision::Fx8, draw.target);
                    const float g = float(ps11::gridScale(draw.fx12 ? ps11::Precision::Fx12 : ps11::Precision::Fx8));
                    for (int c = 0; c < 4; ++c) {
                        for (int i = 0; i < n; ++i) sc.grid[c][i] = sc.r0[c][i];
                        if (readsColor)
                            for (int i = 0; i < n; ++i) sc.colorOut[c][i] = float(sc.r0[c][i]) / g;
                        mi.color[c] = readsColor ? sc.colorOut[c] : nullptr;
                        mi.grid[c] = sc.grid[c];
                    }
                    MergeStats ms;
                    mergePixels(mergeState == &draw.afterDepth ? draw.afterDepthPlan : draw.mergePlan, *mergeState, mi,
                                &ms);
                    stats.written += ms.written;
                }
            }
            if (joined) ++ti;  // its pixels of this row were drawn
        }
        if (fromSource) sourced.materialise(0, source->width);  // (the columns no store wrote)
    }
}

}  // namespace emu
