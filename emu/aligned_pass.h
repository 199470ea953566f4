// The aligned-pass path of DrawPrimitiveUP (docs/device.md "Aligned passes"): fx8 and fx12 triangles with a
// program whose texture reads are plain (ps11::tapPlan, ps11/executor_presampled_internal.h), or
// whose other texture instructions the executor samples itself per pixel (TapPlan::executes), are
// drawn row by row without quads. A tap whose coordinates are screen-aligned on the triangle (u
// depends on x only, v on y only, no perspective) has its texel columns and weights tabulated once
// per triangle and its rows once per pixel row, and its texels are filtered into int16 lanes (runs
// with a fixed weight and step through shared, cached H rows); any other tap (a rotated or
// perspective mapping) is sampled per pixel by the sampler's fast kernel. The executor runs
// pre-sampled, and 8-bit targets take plain and additive stores directly. Results are
// bit-identical to the quad path.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "emu/merge_plan.h"
#include "emu/output_merger.h"
#include "emu/raster.h"
#include "ps11/executor.h"
#include "ps11/executor_presampled_internal.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler.h"
#include "ps11/texture_sampler_fast.h"

namespace emu {

struct AlignedKernels;

// One texture read of the program, resolved against the draw's textures and sampler states.
struct AlignedTap {
    bool bound = false;               // no texture: every lookup is (0, 0, 0, 1)
    const uint8_t* texels = nullptr;  // level 0, b g r a bytes, rows width * 4 apart
    uint32_t width = 1, height = 1;
    bool linear = false;
    ps11::TextureAddress addressU = ps11::TextureAddress::Wrap, addressV = ps11::TextureAddress::Wrap;
    uint32_t borderWord = 0;  // D3DCOLOR (bytes b g r a)
    int coordSet = 0;
};

// A row path's taps whose level or filter the quads' level of detail picks (textures that are
// not levelZeroOnly): their level and filter are those of the triangles being drawn
// (triangleLevels, then setTapLevels on the draw).
struct LevelTaps {
    uint32_t mask = 0;  // bit per tap of the draw's TapPlan
    bool fixed = true;  // an fx profile (ps11::chooseLevel's `fixed`)
    bool weights8 = false;
    std::array<const ps11::Texture*, 8> texture{};
    std::array<const ps11::SamplerState*, 8> sampler{};
    std::array<uint8_t, 8> coordSet{};
    // Records tap i as one of them.
    void add(int i, const ps11::Texture& tex, const ps11::SamplerState& ss, int set) {
        mask |= 1u << i;
        texture[size_t(i)] = &tex;
        sampler[size_t(i)] = &ss;
        coordSet[size_t(i)] = uint8_t(set);
    }
};

// The level and filter of each of LevelTaps' taps on a set of triangles.
struct TapLevels {
    std::array<uint8_t, 8> level{};
    uint32_t linear = 0;  // bit per tap
    bool operator==(const TapLevels&) const = default;
};

// What one draw needs, shared read-only by the workers.
struct AlignedDraw {
    uint64_t serial = 0;  // unique per draw: H rows cached by workers are valid within one draw only
    const ps11::Executor* executor = nullptr;
    // The vector kernels of the SIMD level in force when the draw was prepared
    // (emu/aligned_pass_kernels.h); null: every pixel filtered and stored one at a time.
    const AlignedKernels* kernels = nullptr;
    // The sampler's fast kernel of that level, for taps sampled per pixel (freeTaps).
    ps11::fastpath::Unorm8Kernel sample = nullptr;
    ps11::TapPlan plan;
    std::array<AlignedTap, 8> taps{};
    uint32_t bound = 0;       // the taps with a texture (bit per tap)
    LevelTaps levelTaps;      // the taps whose level or filter the level of detail picks
    uint64_t colorAttrs = 0;  // diffuse/specular attribute bits the draw reads (the specular alpha under fog)
    // The coordinate attributes the texture instructions the plan executes read (plan.executes:
    // the executor samples those itself, from PixelInputs' coordinates; fillRowCoords).
    uint64_t executedAttrs = 0;
    MergeState merge;
    MergeTarget target;
    bool fx12 = false;         // fx12 grid integers (16 per 8-bit level) instead of fx8's
    // Stored here: an 8-bit target, no alpha test, all channels, and no blending (directStore) or
    // ONE/ONE ADD on every channel (directAdd), a run of a program with texkills only where none
    // of its pixels is killed (rowKills: the others merged over the pixels kept); under a depth
    // test (depthFirst) only the runs whose every pixel passed it, which is tested before they
    // are shaded (depthTestFirst, over the pixels kept: a killed one writes no depth), the others
    // merged with `afterDepth` over the pixels that passed; under fog (fogFirst) once the run's
    // lanes are fogged as the merger fogs them (fogGridFirst).
    bool directStore = false;
    bool directAdd = false;
    bool depthFirst = false;
    bool fogFirst = false;
    MergeState afterDepth;  // `merge` with its depth test and write off
    Plan mergePlan, afterDepthPlan;  // makePlan of each with `target`, made once (prepareAlignedDraw)
    bool wantZ = false;     // depth tested or written: each run's z goes to the merger (fillRowFogDepth)
    // wantZ, and the program writes its depth (texdepth, texm3x2depth): that goes to the merger
    // instead, and no run is stored directly.
    bool shaderDepth = false;
    // The program runs as chain rows (ps11::chainRows): fx8, reads no colour, stored here with
    // no depth test or fog first. The row path takes them on rows where a tap reads a texel row's
    // texels side by side (1:1, at texel centres or halfway between them; chainRow).
    bool chainRows = false;
};

// Decides whether a draw can take the aligned path (per-triangle checks come later) and fills
// `out`. `textures`/`samplers` are indexed by stage.
bool prepareAlignedDraw(const ps11::Executor& executor, ps11::Precision precision,
                        const std::array<std::shared_ptr<const ps11::Texture>, 8>& textures,
                        const std::array<ps11::SamplerState, 8>& samplers, const MergeState& merge,
                        const MergeTarget& target, bool wantZ, uint64_t usedAttrs, AlignedDraw& out);

// Per-triangle column tables of every tap: texel byte offsets of the pair (−1 = border) and the
// 8-bit weight per column; and the long runs: at least kMinAlignedRun columns whose first texel
// steps by a fixed 1..kMaxAlignedStep texels with one weight, filtered with vector kernels from
// shared H rows where the draw has them (AlignedDraw::kernels).
constexpr int kMinAlignedRun = 16;
constexpr int kMaxAlignedStep = 8;
constexpr int kMaxTapConfigs = 4;  // H-row configurations per tap (runs past these are filtered per pixel)

// One H-row configuration: texel rows of `texels` filtered horizontally with weight wx at texels
// i = step·j + phase (and i + 1), j in [jlo, jhi): the union of the runs of every tap that share
// the texture, weight, step and phase.
struct HConfig {
    const uint8_t* texels = nullptr;
    int32_t wx = 0, step = 1, phase = 0, jlo = 0, jhi = 0;
    // Texels [stageLo, stageHi) of the row: what every configuration on this texture reads,
    // deinterleaved once per texel row and shared by them (not set for tabulated configurations
    // and point reductions, wx = 0 at a step of 2 or more: their H rows read the texel row).
    int32_t stageLo = 0, stageHi = 0;
    // Tabulated configuration (step = 0, wx = −2): element j is absolute column jlo + j of one
    // tap's column table, H = (256 − w)·T[off0] + w·T[off1] with that column's pair and weight
    // (a magnified tap: consecutive columns share texels and weights change every column).
    // off0/off1/w point at column jlo of the tap's tables (byte offsets); `hash` is of their
    // contents over [jlo, jhi). Slots match by tableId; drawAlignedRows gives triangles whose
    // tables are equal the id of the first (they share rows).
    const int32_t* off0 = nullptr;
    const int32_t* off1 = nullptr;
    const int32_t* w = nullptr;
    int32_t rowTexels = 0;  // texels in a texel row (the texture's width)
    bool q16 = false;       // tabulated, every weight a multiple of 16: its H rows are of kind Q
    // Tabulated, its tap reading texel rows no neighbouring pixel row reads (a minification in v:
    // 2 texel rows or more a pixel row bilinear, 1 or more point): the cache would never find its
    // H rows again, so each pixel row builds them for its own columns (filterTap) instead.
    bool uncached = false;
    uint64_t hash = 0;
    uint64_t tableId = 0;  // unique per prepared table (a slot that checked it needs no second look)
};

struct AlignedTriangle {
    int x0 = 0, x1 = 0;  // columns tabulated: [x0, x1)
    struct Run {
        int32_t x0 = 0, x1 = 0;  // absolute columns [x0, x1)
        int32_t j0 = 0;          // element of column x0 in the config's H row (from jlo)
        int32_t config = 0;      // index into the tap's configs
        bool tabulated = false;  // a tabulated configuration's run (H rows of kind H whatever the weight)
    };
    struct Columns {
        std::vector<int32_t> off0, off1, w;
        std::vector<int32_t> run;  // per column: index into runs, −1 = filtered per pixel
        std::vector<Run> runs;
        std::array<int32_t, kMaxTapConfigs> configs{};  // indices into AlignedTriangle::configs
        int configCount = 0;
        bool tabulatedQ16 = false;  // its tabulated configuration's H rows are of kind Q (HConfig::q16)
    };
    std::array<Columns, 8> taps;
    std::vector<HConfig> configs;
    // Taps sampled per pixel on this triangle (bit per tap of the TapPlan, freeTaps): no tables.
    uint32_t freeTaps = 0;
    // Taps the caller has sampled per pixel whatever their mapping (set before the tables are
    // filled, or-ed into freeTaps): those whose level the level of detail picks, where the
    // triangle's quads do not all pick the part's one level and filter (quadLevels then picks
    // each pixel's).
    uint32_t levelFree = 0;
};

// True when the triangle qualifies (rowPathKind) and then fills its tables.
// `columns`, when given, are the tables' columns instead of tableColumns' (see pairColumns).
bool prepareAlignedTriangle(const AlignedDraw& draw, const TriangleSetup& s, AlignedTriangle& out,
                            const std::pair<int, int>* columns = nullptr);
// The second half of prepareAlignedTriangle: fills the tables of a qualifying triangle over
// out.x0 .. out.x1 (rowPathColumns' or pairColumns'). Triangles' tables are independent, so
// the renderer fills those of a chunk on its workers.
void fillAlignedTables(const AlignedDraw& draw, const TriangleSetup& s, AlignedTriangle& out);

// The columns [x0, x1) a row path's tables of the triangle span: the clip rect's, or for a
// triangle covering less than half of them (a sprite) its own. Triangles of one full-screen quad
// thus have equal tables and share their H rows. False when it covers no pixel.
bool tableColumns(const TriangleSetup& s, int& x0, int& x1);
// screenAligned and tableColumns.
bool rowPathColumns(const ps11::TapPlan& plan, const TriangleSetup& s, int& x0, int& x1);

// The taps of `plan` among `bound` (bit per tap) that the row paths sample per pixel on the
// triangle: a projected read (TapPlan::divisor), a tap whose u has a dy or whose v has a dx (a
// rotated, sheared or transposed mapping), and on a triangle with perspective every tap whose u
// or v is not constant. Each such lane's u and v are the quad path's (tapCoords) and the sampler
// filters them as the quad path's does: no tables, no H rows.
uint32_t freeTaps(const ps11::TapPlan& plan, uint32_t bound, const TriangleSetup& s);
// Both row paths' per-triangle condition, for any mapping of their taps: tableColumns.
// 0: the triangle takes quads; 1: screen-aligned (screenAligned: every tap tabulated, tile
// skipping may decide its tiles); 2: some tap sampled per pixel (freeTaps) or perspective.
int rowPathKind(const ps11::TapPlan& plan, uint32_t bound, const TriangleSetup& s, int& x0, int& x1);
// Tap t's u and v at pixels x .. x + n − 1 (n <= kMaxSpan) of row y as the executor samples
// them: its coordinate set's, as the rasteriser interpolates them (constant, planeValue, or with
// perspective planeValue of u·rhw times 1 / rhw: the same float operations in the same order), a
// projected read's then divided by its divisor component, interpolated the same way
// (ps11::projectCoord).
void tapCoords(const ps11::TapPlan& plan, int t, const TriangleSetup& s, int x, int y, int n, float* u, float* v);

// The columns two consecutive triangles' tables should share (their union), when both have
// narrow tables that overlap: the two halves of a sprite's quad cover column ranges a pixel apart
// at their slanted edges, so their own columns would give tables (and H rows) that are never
// shared. False when they are no such pair.
bool pairColumns(int a0, int a1, int b0, int b1, const ClipRect& clip, std::pair<int, int>& out);

// Triangles drawn row by row together (drawAlignedRows' group), and the most a chunk may have for
// tile skipping.
constexpr size_t kMaxAlignedTriangles = 16;
// Columns of tables a chunk's aligned triangles may hold at once, in target widths (each
// triangle's tables span the columns it covers, 16 bytes a column per tap: about 2 MB a tap at
// 1080p); the triangle past it starts the chunk's next part, so the tables of a mesh of large
// triangles stay bounded and every triangle still takes the row path.
constexpr int64_t kMaxAlignedColumnsPerTarget = 64;

// Per-worker cache of texel rows, kept for the rows of one draw: staged (deinterleaved into
// uint16 planes, once per texel row) and H rows (a staged row filtered horizontally for one
// HConfig). A blur's texel row serves two taps on each of two pixel rows; a 4:1 reduction's
// serves the two phases of its taps.
struct HRowCache {
    struct Slot {
        const uint8_t* row = nullptr;  // the texel row (identifies texture and row)
        HConfig config;                // wx = −1: the staged row, texels [jlo, jhi)
        int32_t stride = 0;            // elements per plane
        std::vector<uint16_t> data;
    };
    std::vector<std::unique_ptr<Slot>> slots;
    // Per slot, side by side for the lookup's scan (a group of sprites keeps dozens of slots): a
    // hash of its row and configuration (0: empty), and the pixel row that last used it (slots
    // in use on the current pixel row are never evicted).
    std::vector<uint64_t> keys, stamps;
    // A direct-mapped hint per key's low bits: the slot last found or filled for it, plus 1.
    std::array<uint32_t, 256> hint{};
    uint64_t serial = 0;  // the draw the slots belong to
    uint64_t stamp = 0;
    size_t hand = 0;  // where the search for a slot to take starts
    uint64_t staged = 0, built = 0, hits = 0;  // rows deinterleaved, H rows built and reused (tests, benchmarks)
};

// An H row's four planes: data + c·stride (returned whole, not as four pointers stored one by one
// and read back together, which the store buffer cannot forward).
struct HRowRef {
    const uint16_t* data = nullptr;
    size_t stride = 0;
};

// The H row of texel row `row` for `config` (planes from element jlo), from the worker's cache.
// Texel rows are first deinterleaved once per draw (a "staged" slot over the triangle's texel
// range of that texture), then combined per configuration; weight 0 at step 1 is the staged row
// itself (emu/aligned_hrows.cpp).
void hRow(const AlignedKernels& kernels, HRowCache& cache, const uint8_t* row, const HConfig& config, uint64_t tableId,
          HRowRef& planes);

// The level and filter of each 2×2 quad of a triangle's tap whose level the level of detail picks
// and which is sampled per pixel (freeTaps, freeLevels): chosen on the quad's first row drawn and
// kept for its other, within one drawAlignedRows call (which draws both rows of every quad: its
// bands start on even rows). Entries per (triangle, tap), indexed by quad column (x / 2).
struct QuadLevels {
    struct Entry {
        const TriangleSetup* setup = nullptr;
        int tap = -1;
        std::vector<ps11::LevelChoice> choice;
        std::vector<int32_t> stamp;  // quad row + 1 where `choice` holds that row's quad's
    };
    std::vector<Entry> entries;
    size_t used = 0;  // entries [0, used) belong to the current call
    // The entry of (setup, tap) in this call, or a fresh one for quads of a `width`-pixel target.
    Entry& entry(const TriangleSetup* setup, int tap, uint32_t width) {
        for (size_t i = 0; i < used; ++i)
            if (entries[i].setup == setup && entries[i].tap == tap) return entries[i];
        if (used == entries.size()) entries.emplace_back();
        Entry& e = entries[used++];
        e.setup = setup, e.tap = tap;
        const size_t quads = size_t(width) / 2 + 1;
        e.choice.resize(quads);
        e.stamp.assign(quads, 0);
        return e;
    }
};

// Per-worker buffers, allocated once.
struct AlignedScratch {
    alignas(32) int16_t r0[4][ps11::kMaxSpan];
    alignas(32) float color[8][ps11::kMaxSpan];  // diffuse r g b a, specular r g b a
    alignas(32) int32_t x[ps11::kMaxSpan], y[ps11::kMaxSpan];
    alignas(32) float fog[ps11::kMaxSpan], z[ps11::kMaxSpan];  // fillRowFogDepth
    alignas(32) uint8_t passed[ps11::kMaxSpan];                // depthTestFirst
    alignas(32) uint8_t kept[ps11::kMaxSpan];                  // rowKills
    alignas(32) uint8_t killed[ps11::kMaxSpan], live[ps11::kMaxSpan];  // a register's texkill (TapPlan::registerKills)
    alignas(32) float depth[ps11::kMaxSpan];                           // the program's depth (AlignedDraw::shaderDepth)
    // Chain rows' taps formed into rows of their own (with room for verticalBytes' whole groups).
    alignas(32) uint8_t tapBytes[8][4 * (ps11::kMaxSpan + 32)];
    // The worker's sampler, bound to the draw's textures and sampler states: it samples the taps
    // whose level the level of detail picks on triangles where they are sampled per pixel, at
    // their quads' levels (SampleRequest::levels), and the texture instructions the plan
    // executes. Set by the caller before drawAlignedRows.
    ps11::Sampler* sampler = nullptr;
    alignas(32) float coords[32][ps11::kMaxSpan];  // fillRowCoords (DrawAligned::executedAttrs)
    alignas(32) int32_t grid[4][ps11::kMaxSpan];
    alignas(32) float colorOut[4][ps11::kMaxSpan];
    HRowCache hrows;
    QuadLevels quadLevels;
};

// Whether the sampler reads level 0 with one filter at every level of detail (a 2-D texture, the
// same filter for minification and magnification, one level or MIP filter NONE): the row
// paths' per-texture condition (docs/textures.md "Level of detail").
bool levelZeroOnly(const ps11::Texture& tex, const ps11::SamplerState& ss);

// For a screen-aligned triangle `s` whose pixels lie in columns [x0, x1): the level and filter
// each of `taps` takes on every 2×2 quad the triangle's rows and columns touch, by the quad path's
// own rule (ps11::chooseLevel over the derivatives its quads compute from these coordinates).
// False where the quads do not all agree, where one blends two levels, or where a coordinate is
// not finite: the triangle is then shaded in quads.
bool triangleLevels(const LevelTaps& taps, const TriangleSetup& s, int x0, int x1, TapLevels& out);
// The level and filter of every 2×2 quad whose pixels include x .. x + n − 1 (n <= kMaxSpan) of
// row y, for tap `tap` of `plan` on triangle `s` (sampled per pixel, at tapCoords): the quad
// path's choice (ps11::chooseLevel, `fixed` and `weights8` as its sampler takes them) from the
// coordinates of the quad's top-left, top-right and bottom-left pixels, chosen on the quad's first
// row drawn and kept in `cache` for its other. Quad q = x / 2's is choice[q].
const QuadLevels::Entry& quadLevels(QuadLevels& cache, const TriangleSetup& s, const ps11::TapPlan& plan, int tap,
                                    const ps11::Texture& tex, const ps11::SamplerState& ss, bool fixed, bool weights8,
                                    uint32_t width, int x, int y, int n);
// Points each of draw.levelTaps at its level and filter in `levels` (before the triangles' tables
// are filled; a change starts a new serial, so no worker keeps H rows of another level).
void setTapLevels(AlignedDraw& draw, const TapLevels& levels);
// AlignedDraw::serial: unique per draw and per change of its taps' levels (the float row path's too).
uint64_t nextRowDrawSerial();

// Whether every texture-coordinate set of `plan` is screen-aligned on the triangle (u constant or
// a plane with dy = 0, v constant or a plane with dx = 0) and the triangle has no perspective:
// the row paths' per-triangle condition (colours are then constant or affine).
bool screenAligned(const ps11::TapPlan& plan, const TriangleSetup& s);
// The quad path's u of coordinate set `set` at columns x0 .. x0 + n − 1 (any row), and its v at
// row y (any column), on a screen-aligned triangle.
void columnU(const TriangleSetup& s, int set, int x0, int n, float* u);
float rowV(const TriangleSetup& s, int set, int y);

// The diffuse (color[0..3]) and specular (color[4..7]) lanes of pixels x .. x + n − 1 of row y
// that `colorAttrs` names, as the quad path interpolates them (affine, or with perspective divided
// by the interpolated rhw); one constant over the triangle is written to lane 0 alone and its bit
// k set in the result (ps11::PixelInputs::uniformColor).
uint8_t fillRowColors(uint64_t colorAttrs, const TriangleSetup& s, int x, int y, int n,
                      float (*color)[ps11::kMaxSpan]);
// The merger's other per-lane inputs for pixels x .. x + n − 1 of row y, as the spans of one row
// interpolate them (rasterizeRowSpans): the fog factor, the specular alpha (where `fog`), and z,
// linear on the screen (where `z`).
void fillRowFogDepth(const TriangleSetup& s, bool fog, bool z, int x, int y, int n, float* fogOut, float* zOut);
// The texture coordinate lanes of pixels x .. x + n − 1 of row y that `attrs` names, as the spans
// of one row interpolate them: attribute attrTex(set, c) into coords[4·set + c].
void fillRowCoords(uint64_t attrs, const TriangleSetup& s, int x, int y, int n, float (*coords)[ps11::kMaxSpan]);

struct AlignedStats {
    uint64_t pixels = 0, written = 0, texels = 0;
    uint64_t copiedDirect = 0;  // pixels of copied windows stored straight from the texel row
    ps11::ExecutorStats exec;
};

// What the row paths do in a window of columns (emu/tile_skip.h decides it per tile): shade (run
// the program), fill (every pixel's r0 is one constant: no texel is read and the program does not
// run), or copy (r0's channels are bit for bit the lookup of one tap, or constants: that tap alone
// is filtered). The merge
// and store are the draw's in every case.
enum class RowMode : uint8_t { Shade, Fill, Copy };
struct RowWindow {
    int x0 = 0, x1 = 0;  // columns [x0, x1)
    RowMode mode = RowMode::Shade;
    int copyTap = -1;               // Copy: the tap (index in the draw's TapPlan)
    uint8_t copyMask = 0xf;         // Copy: r0's channels from the tap (bit c); the others from grid/value
    std::array<int32_t, 4> grid{};  // Fill, fx profiles: r0's grid integers
    std::array<float, 4> value{};   // Fill, float profiles: r0's floats
};

// The windows a row path draws: those given (disjoint, in column order), or with none given one
// that shades every column; and the taps some window reads (bit per tap of the TapPlan).
struct RowWindows {
    const RowWindow* data = nullptr;
    size_t count = 0;
    uint32_t taps = 0;
};

RowWindows rowWindows(const RowWindow* windows, size_t count);

// The columns [xl, xr) of pixel row y that triangle s covers within the windows' span
// (windows[0].x0 to windows[count − 1].x1); false when there are none.
inline bool rowSpan(const TriangleSetup& s, int y, const RowWindow* windows, size_t count, int& xl, int& xr) {
    if (y < s.yMin || y >= s.yMax || !rowCoverage(s, y, xl, xr)) return false;
    xl = std::max(xl, windows[0].x0), xr = std::min(xr, windows[count - 1].x1);
    return xl < xr;
}

// Whether the row paths' tables of triangles a and b over the same columns are equal: every tap's
// u gives each column the same float (the same constant, or the same float row base and step;
// a table depends on nothing else of its triangle). A quad's second half then takes the first
// one's tables instead of filling its own (the renderer's prepareTables).
bool sameColumnTables(const TriangleSetup& a, const TriangleSetup& b, const ps11::TapPlan& plan);

// Joins the next triangle's run of pixel row y to [xl, xr) (this triangle's, rowSpan's) when
// the two are adjacent and give every pixel of the row the same attributes the row paths read:
// each tap's u and v and the colours `colorAttrs` names, bit for bit (the same float row base
// and step per column, or the same constant; u is not compared where the two share their tables,
// `sharedTables`: sameColumnTables compared it). The caller has checked that their tables cover
// the same columns (they are then equal). A quad's two halves split every row at the diagonal;
// joined, each row is one run: half the runs of a sprite, and full-width spans for a
// full-screen pass. True when joined (the next triangle's pixels of the row are then this run's).
// What it compares is worked out once per pair (joinPlan).
struct JoinPlan {
    // An attribute can agree on no row: constant in one triangle only, two different constants, or
    // float steps that differ (or rhw's under perspective).
    bool never = false;
    bool perspective = false;  // rhw's row bases compared row by row too
    // Attributes (bit k) compared row by row; the others agree on every row (the same constant,
    // or the same plane from the same origin, bit for bit).
    uint64_t rows = 0;
};
JoinPlan joinPlan(const TriangleSetup& s, const TriangleSetup& next, bool sharedTables, const ps11::TapPlan& plan,
                  uint64_t colorAttrs);
bool joinRow(const TriangleSetup& s, const TriangleSetup& next, const JoinPlan& plan, int y, const RowWindow* windows,
             size_t count, int& xl, int& xr);
// joinPlan of each consecutive pair of a drawAlignedRows group (pair i: triangles i and i + 1), made
// on first use (a band's call meets few of its pairs on a joined row; a sprite's pair is met again
// by the call of each band it crosses).
class JoinPlans {
public:
    template <typename Tri>
    JoinPlans(const Tri* const* tris, const TriangleSetup* const* setups, size_t count, const ps11::TapPlan& plan,
              uint64_t colorAttrs)
        : m_setups(setups), m_plan(plan), m_colorAttrs(colorAttrs) {
        for (size_t i = 0; i + 1 < count && i < kMaxAlignedTriangles; ++i)
            m_shared |= uint32_t(tris[i + 1] == tris[i]) << i;
    }
    JoinPlan pair(size_t i) {
        if (i >= kMaxAlignedTriangles)  // (u compared too: the same verdict, a larger group)
            return joinPlan(*m_setups[i], *m_setups[i + 1], false, m_plan, m_colorAttrs);
        if (!((m_made >> i) & 1)) {
            m_pairs[i] = joinPlan(*m_setups[i], *m_setups[i + 1], (m_shared >> i) & 1, m_plan, m_colorAttrs);
            m_made |= uint32_t(1) << i;
        }
        return m_pairs[i];
    }

private:
    const TriangleSetup* const* m_setups;
    const ps11::TapPlan& m_plan;
    uint64_t m_colorAttrs;
    uint32_t m_shared = 0, m_made = 0;  // bit per pair
    std::array<JoinPlan, kMaxAlignedTriangles> m_pairs;
};

// A whole-surface copy into the 8-bit target put off (SoftwareRendererOptions::putOffCopies)
// that drawAlignedRows makes as it draws: row y of the target is to hold the `width` words at
// row0 + y·pitch before the draw (a plain copy: same size and format) — on rows [0, height).
struct RowSource {
    const uint8_t* row0 = nullptr;
    size_t pitch = 0;
    int width = 0, height = 0;
};

// One target row under a RowSource (drawAlignedRows): which of its columns hold their words before the draw
// (copied from the source) or the draw's (written over those), as disjoint spans in column
// order. A draw's windows go left to right, so a span is most often added at the end.
class SourcedRow {
public:
    void start(const uint8_t* source, uint8_t* target, int width) {
        m_source = source, m_target = target, m_width = width, m_count = 0, m_whole = false;
    }
    // Where a direct store of columns [x, x + n) reads what is under them (ONE/ONE): the source,
    // where none of them holds a word yet (mark() them once stored), else the target, once the
    // ones not yet there are copied.
    const uint8_t* base(int x, int n) {
        if (!m_whole && !overlaps(x, x + n)) return m_source + 4 * size_t(x);
        materialise(x, n);
        return m_target + 4 * size_t(x);
    }
    // Columns [x, x + n) now hold the draw's words.
    void mark(int x, int n) {
        if (m_whole || n <= 0) return;
        int lo = x, hi = x + n;
        // (Spans ordered and disjoint: the new one joins those it touches.)
        int i = 0;
        while (i < m_count && m_spans[size_t(i)].second < lo) ++i;
        int j = i;
        for (; j < m_count && m_spans[size_t(j)].first <= hi; ++j)
            lo = std::min(lo, m_spans[size_t(j)].first), hi = std::max(hi, m_spans[size_t(j)].second);
        if (j == i && m_count == kMaxSpans) {
            // No room: joined to a neighbour, the columns between them copied.
            if (i > 0) {
                --i;
                copy(m_spans[size_t(i)].second, lo);
                lo = m_spans[size_t(i)].first;
            } else {
                copy(hi, m_spans[0].first);
                hi = m_spans[0].second;
            }
            j = i + 1;
        }
        const int removed = j - i;
        if (removed == 0) {
            for (int k = m_count; k > i; --k) m_spans[size_t(k)] = m_spans[size_t(k - 1)];
            ++m_count;
        } else {
            for (int k = j; k < m_count; ++k) m_spans[size_t(k - removed + 1)] = m_spans[size_t(k)];
            m_count -= removed - 1;
        }
        m_spans[size_t(i)] = {lo, hi};
    }
    // Columns [x, x + n) hold their words before the draw where nothing is there yet.
    void materialise(int x, int n) {
        if (m_whole) return;
        int at = x;
        const int end = std::min(x + n, m_width);
        for (int i = 0; i < m_count && at < end; ++i) {
            const auto [a, b] = m_spans[size_t(i)];
            if (b <= at) continue;
            if (a >= end) break;
            if (a > at) copy(at, a);
            at = std::max(at, b);
        }
        if (at < end) copy(at, end);
        if (x <= 0 && x + n >= m_width) {
            m_whole = true;
            return;
        }
        mark(x, n);
    }

private:
    static constexpr int kMaxSpans = 32;
    bool overlaps(int a, int b) const {
        for (int i = m_count - 1; i >= 0; --i) {
            if (m_spans[size_t(i)].second <= a) return false;  // (ordered: the rest end before it too)
            if (m_spans[size_t(i)].first < b) return true;
        }
        return false;
    }
    void copy(int a, int b) {
        std::memcpy(m_target + 4 * size_t(a), m_source + 4 * size_t(a), 4 * size_t(b - a));
    }
    const uint8_t* m_source = nullptr;
    uint8_t* m_target = nullptr;
    int m_width = 0, m_count = 0;
    bool m_whole = false;
    std::array<std::pair<int, int>, kMaxSpans + 1> m_spans{};
};

// fx12's grid scale: an 8-bit texel b is the grid value 16·b, 255 is kG12.
inline constexpr int32_t kG12 = ps11::gridScale(ps11::Precision::Fx12);

// ---- stores to 8-bit targets (emu/aligned_store.cpp) ----

// Stores (or adds, draw.directAdd, to the bytes at `base`: the row's own or a RowSource's) n
// pixels of int16 lanes r g b a (| orMask) to a row of the 8-bit target.
void storeLanes(const AlignedDraw& draw, const int16_t* const r[4], int n, uint32_t orMask, const uint8_t* base,
                uint8_t* row);
// n pixels' b g r a words from `src` to a row of the 8-bit target: each (word & keep) | set, or
// with `additive` (ONE/ONE ADD) that added with saturation to the bytes at `base` (the row's own,
// or a RowSource's), as storeLanes stores lanes.
void storeWords(const uint8_t* src, int n, uint32_t keep, uint32_t set, bool additive, const uint8_t* base,
                uint8_t* dst);
// n pixels of a row of the 8-bit target set to the b g r a word `word`, or with `additive` that
// word added with saturation to each at `base` (storeWords of n copies of it).
void fillWords(const uint8_t word[4], int n, bool additive, const uint8_t* base, uint8_t* dst);

// ---- per-pixel attributes (emu/aligned_attributes.cpp) ----

// The texkills of `plan` (TapPlan::killSets) at pixels x .. x + n − 1 of row y: kept[i] 0 where
// a tested set's x, y or z, interpolated as the rasteriser interpolates it, is below 0 (as the
// executor tests it: a NaN is kept), else 1. True when some pixel is killed.
bool rowKills(const ps11::TapPlan& plan, const TriangleSetup& s, int x, int y, int n, uint8_t* kept);

// Tap t's lanes for pixels x .. x + n − 1 (n <= kMaxSpan) of row y, sampled per pixel: the quad
// path's u and v, filtered by the sampler's fast kernel (the quad path's sampler takes the same
// kernel for a texture levelZeroOnly reads), its grid integers narrowed to int16; a tap whose
// level the level of detail picks through `sampler`, at its quads' levels.
void sampleFree(const AlignedDraw& draw, const TriangleSetup& s, int t, int x, int y, int n, QuadLevels& cache,
                ps11::Sampler* sampler, int16_t* const dst[4]);

// Draws rows [y0, y1) of `count` prepared triangles (tris[i] with setups[i], in primitive
// order): row by row, each row through every triangle in order. With `windows` (disjoint, in
// column order), only their columns, each as it says; every texel row the windows need is
// filtered once per pixel row for all of them. With `source`, each row of the target is first
// the source's, as if copied before the draw: direct stores (copied, filled and shaded windows)
// read (ONE/ONE) the source's words where the draw has not written yet and write the target's,
// the columns other paths write are copied just before, and the rest of the row after.
void drawAlignedRows(const AlignedDraw& draw, const AlignedTriangle* const* tris, const TriangleSetup* const* setups,
                     size_t count, int y0, int y1, AlignedScratch& scratch, AlignedStats& stats,
                     const RowWindow* windows = nullptr, size_t windowCount = 0, const RowSource* source = nullptr);

}  // namespace emu
