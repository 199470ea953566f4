// The row path of the float profiles (docs/device.md "Aligned passes"): the float and ideal
// counterpart of emu/aligned_pass.h. Triangles are drawn row by row without quads: each
// screen-aligned tap's (u depends on x only, v on y only, no perspective) addressing (texel pair
// and weight, ps11::floatAxisTaps) is tabulated once per column and once per row instead of per
// lane, and any other tap is sampled per pixel by the worker's sampler; a linear tap's
// horizontal lerps are made once per texel row ("H rows", kept while the rows that need them are
// drawn) and each pixel takes one vertical lerp; the executor runs its float program over the row
// with a sampler that hands out these values, and the output merger merges the row. The
// arithmetic is the reference sampler's, operation for operation, so results are bit-identical
// to the quad path.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "emu/aligned_pass.h"
#include "emu/merge_plan.h"
#include "emu/output_merger.h"
#include "emu/raster.h"
#include "ps11/executor.h"
#include "ps11/executor_presampled_internal.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler_fast.h"
#include "ps11/texture_sampler.h"

namespace emu {

// One texture read of the program, resolved against the draw's textures and sampler states.
struct FloatRowTap {
    bool bound = false;  // no texture: every lookup is (0, 0, 0, 1)
    int stage = 0, coordSet = 0;
    bool unorm8 = false;             // texels as b g r a bytes (else float r g b a values)
    const uint8_t* bytes = nullptr;  // level 0 (Unorm8)
    const float* values = nullptr;   // level 0 (Decoded as four float32), else:
    ps11::FloatTexels texels;        // level 0 read in its own float layout (values null)
    uint32_t width = 1, height = 1;
    bool linear = false;
    ps11::TextureAddress addressU = ps11::TextureAddress::Wrap, addressV = ps11::TextureAddress::Wrap;
    std::array<float, 4> border{};
    // Every value the tap returns is finite and not negative (8-bit texels, such a border): then
    // a lerp with weight 0 is its first operand exactly.
    bool nonNegative = false;
    // Every value it returns lies in [0, 1] or is −0.0 (8-bit texels, a border inside [0, 1]):
    // ps11::SampleResult::unitRange.
    bool unitRange = false;
};

struct FloatRowKernels;

// What one draw needs, shared read-only by the workers.
struct FloatRowDraw {
    uint64_t serial = 0;                       // unique per draw: H rows kept by workers are valid within one draw only
    const FloatRowKernels* kernels = nullptr;  // the SIMD level's (emu/aligned_float_kernels.h)
    const ps11::fastpath::SamplerKernels* sampler = nullptr;  // the SIMD level's (ps11/texture_sampler_fast.h)
    const ps11::Executor* executor = nullptr;
    ps11::TapPlan plan;
    std::array<FloatRowTap, 8> taps{};
    uint32_t bound = 0;     // the taps with a texture (bit per tap)
    bool weights8 = false;  // the float profile on a class with 8-bit filter weights
    uint64_t colorAttrs = 0;
    // The coordinate attributes the texture instructions the plan executes read (plan.executes:
    // the executor samples those through the worker's sampler, from the row's coordinates).
    uint64_t executedAttrs = 0;
    MergeState merge;
    MergeTarget target;
    Plan mergePlan;      // makePlan(merge, target), made once (prepareFloatRowDraw)
    bool wantZ = false;  // depth tested or written: each run's z goes to the merger (fillRowFogDepth)
    bool shaderDepth = false;  // wantZ, and the program writes its depth: that goes to the merger instead
    LevelTaps levelTaps;  // the taps whose level or filter the level of detail picks
};

// Decides whether a draw can take the float row path (float or ideal precision; plain and
// projected reads, texkills of coordinate sets (rowKills, per run), and the other texture
// instructions, TapPlan::executes, which sample lodFree textures) and fills `out`. The rows filter
// one plain read a stage of a 2-D texture; a volume texture's plain read and two plain reads of one
// stage are executed too (TapPlan::executedTaps: lodFree, not bound). A texture whose level or
// filter the level of detail picks is one of levelTaps: its triangles take the row path where
// triangleLevels finds one level.
bool prepareFloatRowDraw(const ps11::Executor& executor, ps11::Precision precision, int weightBits,
                         const std::array<std::shared_ptr<const ps11::Texture>, 8>& textures,
                         const std::array<ps11::SamplerState, 8>& samplers, const MergeState& merge,
                         const MergeTarget& target, bool wantZ, uint64_t usedAttrs, FloatRowDraw& out);

// Per triangle: every tap's column table over the clip rect's columns.
struct FloatRowTriangle {
    int x0 = 0, x1 = 0;
    struct Columns {
        std::vector<int32_t> i0, i1;
        std::vector<float> f;
        // The columns in stretches, in order, covering them all: kSeq, texel pairs k + q and
        // k + q + 1 (a 1:1 or minified-by-none run); kInside, both texels in the row; kBorder, a
        // border texel among them.
        enum Kind : uint8_t { kSeq, kInside, kBorder };
        struct Stretch {
            int32_t x0, x1;
            Kind kind;
        };
        std::vector<Stretch> stretches;
        // A point tap's runs: runEnd[i] is the first column after i whose texel does not follow
        // i0[i] one by one (i0[j] != i0[i] + (j − i)), or the column count (empty for linear taps).
        std::vector<int32_t> runEnd;
        // Equal tables of one draw share their H rows (a full-screen quad's two triangles, the
        // taps of a vertical blur): shareFloatRowTables gives them the id of the first.
        uint64_t tableId = 0;
        // A linear tap moving 2 texel rows or more a pixel row (a minification in v): no other
        // pixel row reads its texel rows, so its H rows are built into the worker's own slots
        // (FloatRowScratch::own) without a search of the kept ones (as HConfig::uncached).
        bool uncached = false;
    };
    std::array<Columns, 8> taps;
    // Taps sampled per pixel on this triangle (bit per tap, freeTaps): no tables; the worker's
    // sampler (FloatRowScratch::sampler) filters them.
    uint32_t freeTaps = 0;
    uint32_t levelFree = 0;  // as AlignedTriangle::levelFree
};

// Gives each tap's table of tris[0 .. count) an id, the same to taps of the triangle or the one before whose H
// rows are equal (same texels, border, columns, texel pairs and weights), so drawFloatRows
// builds their H rows once.
// `tableOf[i]`: the triangle whose tables serve triangle i (i, or its quad's first half, whose ids
// it then has).
void shareFloatRowTables(const FloatRowDraw& draw, FloatRowTriangle* tris, const uint8_t* prepared,
                         const uint32_t* tableOf, size_t count);

// True when the triangle qualifies (rowPathKind), and then fills its tables.
// `columns`, when given, are the tables' columns instead of tableColumns' (see pairColumns).
bool prepareFloatRowTriangle(const FloatRowDraw& draw, const TriangleSetup& s, FloatRowTriangle& out,
                             const std::pair<int, int>* columns = nullptr);
// Its second half: the tables over out.x0 .. out.x1 (as fillAlignedTables).
void fillFloatRowTables(const FloatRowDraw& draw, const TriangleSetup& s, FloatRowTriangle& out);
// setTapLevels of the float row path.
void setTapLevels(FloatRowDraw& draw, const TapLevels& levels);

// Per-worker buffers, allocated once and kept by the worker.
struct FloatRowScratch {
    // The worker's sampler, bound to the draw's textures and sampler states: it filters the taps
    // sampled per pixel (their lanes' u and v from tapCoords, no quads: such a texture's level
    // and filter never depend on them, levelZeroOnly) and the instructions the plan executes.
    // Set by the caller before drawFloatRows.
    ps11::Sampler* sampler = nullptr;
    alignas(32) float color[8][ps11::kMaxSpan];
    alignas(32) float coords[32][ps11::kMaxSpan];  // fillRowCoords (FloatRowDraw::executedAttrs)
    alignas(32) float out[4][ps11::kMaxSpan];
    alignas(32) int32_t x[ps11::kMaxSpan], y[ps11::kMaxSpan];
    alignas(32) float fog[ps11::kMaxSpan], z[ps11::kMaxSpan];  // fillRowFogDepth
    alignas(32) uint8_t kept[ps11::kMaxSpan];                  // rowKills
    alignas(32) uint8_t killed[ps11::kMaxSpan];                // a register's texkill (TapPlan::registerKills)
    alignas(32) float depth[ps11::kMaxSpan];                   // the program's depth (FloatRowDraw::shaderDepth)
    // H rows: texel rows filtered horizontally over the triangle's columns, planar r g b a (4 ×
    // columns floats each), keyed by draw, column table and texel row, shared by every tap with
    // that table (a vertical blur's taps read each other's rows). Slots used by the pixel row
    // being drawn (stamp > rowStart) are never replaced; the pool grows to what a row needs.
    struct HRow {
        uint64_t serial = 0;
        uint64_t tableId = 0;
        int32_t row = 0;
        uint64_t stamp = 0;
        std::vector<float> h;
    };
    std::vector<HRow> hrows;
    // The H rows of uncached taps (Columns::uncached): two a tap, rebuilt on every pixel row.
    std::array<HRow, 16> own;
    // Texel rows as planar r g b a floats (8-bit ones decoded, float ones deinterleaved: the
    // taps of a horizontal blur read one row), keyed by draw, the row's first byte and its
    // width (a texture's memory is rewritten between draws); kept like the H rows.
    struct DecodedRow {
        uint64_t serial = 0;
        const uint8_t* row = nullptr;
        uint32_t width = 0;
        uint64_t stamp = 0;
        bool nan = false;  // holds a NaN (float textures)
        std::vector<float> v;
    };
    std::vector<DecodedRow> decoded;
    uint64_t stamp = 0, rowStart = 0;
    QuadLevels quadLevels;  // per-quad levels of taps sampled per pixel (quadLevels)
};

// Draws rows [y0, y1) of prepared triangles tris[0 .. count), row by row and within a row in
// primitive order; with `windows` (disjoint, in column order), only their columns, each as it
// says (emu/aligned_pass.h).
void drawFloatRows(const FloatRowDraw& draw, const FloatRowTriangle* const* tris, const TriangleSetup* const* setups,
                   size_t count, int y0, int y1, FloatRowScratch& sc, AlignedStats& stats,
                   const RowWindow* windows = nullptr, size_t windowCount = 0);

}  // namespace emu
