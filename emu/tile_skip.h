// Tile skipping (docs/device.md "Tile skipping"): before a tile of a row-path draw is drawn,
// the renderer bounds what its taps can read — the per-tile facts of each texture
// (ps11/texture_tiles.h) over the texels the tile's coordinates reach, the colours at its corners
// — and runs the interval evaluator (ps11/intervals.h) over those ranges. Where r0 is one
// constant the tile is filled without shading; where each channel is bit for bit that channel of
// one tap's lookup or a constant, only that tap is filtered (a copy); where the merge of that constant leaves the target as it is (ONE/ONE
// of zero into an 8-bit target), nothing is drawn. Every claim holds for every input inside the
// ranges, so images are byte-identical with skipping off.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>

#include "emu/aligned_pass.h"
#include "emu/raster.h"
#include "emu/renderer.h"
#include "ps11/intervals.h"
#include "ps11/texture_tiles.h"

namespace emu {

class ThreadPool;

// Columns per tile; a tile's rows are the renderer's band of rows.
constexpr int kSkipTileColumns = 64;

enum class TileAction : uint8_t { Shade, Fill, Copy, Skip };

struct TileDecision {
    TileAction action = TileAction::Shade;
    int copyTap = -1;               // Copy: the tap in the draw's TapPlan
    uint8_t copyMask = 0xf;         // Copy: r0's channels from the tap; the others are constants (grid/value)
    std::array<int32_t, 4> grid{};  // Fill: r0 (fx grid integers; float profiles: `value`)
    std::array<float, 4> value{};
    bool operator==(const TileDecision& o) const {
        return action == o.action && copyTap == o.copyTap && copyMask == o.copyMask && grid == o.grid &&
               std::memcmp(value.data(), o.value.data(), sizeof value) == 0;
    }
    // The row paths' window for columns [x0, x1) (Skip: nothing to draw).
    RowWindow window(int x0, int x1) const;
};

// Tiles shaded, filled, copied and skipped (DrawStats).
struct TileCounts {
    uint64_t shaded = 0, filled = 0, copied = 0, skipped = 0;
};

// A worker's last evaluation: tiles whose input ranges equal the last one's (a run of zero or
// constant tiles) take its decision without evaluating again. Valid within one draw.
struct TileMemo {
    uint64_t skipper = 0;  // the id of the draw's TileSkipper it belongs to
    bool valid = false;
    ps11::IntervalInputs in, last;
    TileDecision decision;
    // The last evaluations over widened inputs (TileSkipper::widenedCopy), taken round robin.
    struct Widened {
        bool valid = false;
        uint8_t stages = 0;  // bit per stage widened to the whole texture's range
        ps11::IntervalInputs in;
        TileDecision decision;
    };
    std::array<Widened, 4> widened{};
    size_t nextWidened = 0;
    ps11::IntervalInputs wide;  // scratch
};

class TileSkipper {
public:
    // For a draw on a row path with tap plan `plan`: nullopt when its tiles cannot be decided
    // (texture coordinates read as values, dependent reads, a program the evaluator refuses).
    // Computes the per-tile facts of the textures the program reads where they are missing, over
    // `pool`.
    // With `scan` off no facts are computed: the skipper then serves anyData() alone.
    static std::unique_ptr<TileSkipper> create(const ps11::Program& program, const DrawCall& call,
                                               const ps11::TapPlan& plan, ThreadPool& pool, bool scan = true);

    // The decision every tile takes whatever its textures hold: each stage over every value its
    // texture's format can hold (8-bit: [0, 1]; others: anything), the border colour added where
    // an axis may reach it, colours anything. A program that reduces to a copy of one tap for
    // every input (a composite of one texture scaled by 1) is then copied without a decision per
    // tile; Shade where nothing better holds.
    TileDecision anyData() const;

    // The decision for pixels [x0, x1) × [y0, y1) of the triangles `tris` (those that may
    // cover the tile, all on the row path); `memo` is the calling worker's.
    TileDecision decide(const TriangleSetup* const* tris, size_t count, int x0, int x1, int y0, int y1,
                        TileMemo& memo) const;

private:
    struct Stage;
    TileDecision evaluate(const ps11::IntervalInputs& in) const;
    // The ranges of every stage the program reads into `in`: (0, 0, 0, 1) for a stage without a
    // texture, `bound(stage, out)` for the others (false: nothing known; then false).
    template <class F>
    bool stageRanges(ps11::IntervalInputs& in, F bound) const;
    // A copy decided over the tile's inputs with the varying stages widened to their whole
    // texture's range, where a copied channel varies in the tile (so the tile's own evaluation
    // could not have filled or skipped it).
    std::optional<TileDecision> widenedCopy(const ps11::IntervalInputs& in, TileMemo& memo) const;
    // A stage's lookup ranges from its texels' range (and the border colour): false when nothing
    // is known of a channel.
    bool lookupRanges(const Stage& st, ps11::TexelRange r, bool border, ps11::ValueRange4& out) const;
    struct Stage {
        bool read = false;
        std::shared_ptr<const ps11::Texture> texture;  // null: unbound, (0, 0, 0, 1)
        std::shared_ptr<const ps11::TexelTiles> tiles;
        ps11::SamplerState sampler;
        int coordSet = 0;
        int tap = -1;  // the plan's tap of this stage (−1 when none or several)
        ps11::ValueRange4 whole{};  // the lookups' range over the whole texture (m_widens)
    };
    uint64_t m_id = 0;  // unique per TileSkipper (memos of an earlier draw never match)
    std::optional<ps11::IntervalEvaluator> m_eval;
    std::array<Stage, 8> m_stages{};
    uint64_t m_colorAttrs = 0;
    bool m_fx = true;
    double m_grid = 255;          // fx: the grid scale G
    bool m_zeroAddIsNoOp = false;  // the merge of a zero r0 leaves every target byte as it is
    bool m_writesNothing = false;
    bool m_widens = false;  // widenedCopy applies: no colour inputs, every texture's range known
};

}  // namespace emu
