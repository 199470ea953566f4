// Renderer stage: the software renderer. A resolved DrawCall (emu/renderer.h) becomes screen
// triangles in chunks, triangle setups, rows in bands over the worker pool, the executor over
// 2×2-quad spans (or the aligned-pass row path) and the output merger. docs/device.md "Drawing".
#include "emu/software_renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <optional>
#include <functional>
#include <unordered_map>

#include "emu/aligned_float.h"
#include "emu/aligned_pass.h"
#include "emu/blit.h"
#include "emu/thread_pool.h"
#include "emu/tile_skip.h"
#include "ps11/diagnostics.h"

namespace emu {

namespace {

// Rows per band handed to a worker: even (quads) and small enough to balance two threads.
constexpr int kBandRows = 16;
// A StretchRect or Clear shares its rows among the workers from this many texels read or
// written per worker.
constexpr int64_t kMinBlitTexelsPerWorker = 16384;
// Executors kept per renderer (cleared when full).
constexpr size_t kMaxCachedExecutors = 64;
// Triangles processed per chunk (vertex processing, setup, rasterisation).
constexpr uint32_t kChunkTriangles = 1024;
// A program whose tiles did not pay to decide is decided again this many draws later; each
// further decision that does not pay doubles the wait, up to kMaxTileRetryDraws (a program that
// never pays, such as a composite over a bright scene, then decides one draw in 32; one that
// starts to pay is noticed within as many draws).
constexpr uint32_t kTileRetryDraws = 4, kMaxTileRetryDraws = 32;
// Where the renderer times its draws (SoftwareRendererOptions::timeTiles): a program that pays
// is drawn without deciding on every kTileProbeDraws-th draw, so that both of its times stay
// current; the times are moving averages with this weight for the newest draw.
constexpr uint32_t kTileProbeDraws = 16;
constexpr double kTileTimeWeight = 0.5;

// Executor outputs and the merged live mask of one span.
struct Lanes {
    alignas(32) float color[4][ps11::kMaxSpan];
    alignas(32) int32_t grid[4][ps11::kMaxSpan];
    alignas(32) uint8_t killed[ps11::kMaxSpan];
    alignas(32) uint8_t live[ps11::kMaxSpan];
    alignas(32) float depth[ps11::kMaxSpan];
};

// What a worker keeps between draws (no allocation per draw): its span, lanes and sampler.
struct WorkerScratch {
    QuadSpan span;
    Lanes lanes;
    ps11::TextureSampler sampler;
    AlignedScratch aligned;
    FloatRowScratch floatRows;
};

}  // namespace

struct SoftwareDrawContext {
    explicit SoftwareDrawContext(int threads) : sharedPool(ThreadPool::shared(threads)), pool(*sharedPool) {
        for (int i = 0; i < pool.size(); ++i) scratch.push_back(std::make_unique<WorkerScratch>());
    }
    std::shared_ptr<ThreadPool> sharedPool;  // the process's workers of this count (ThreadPool::shared)
    ThreadPool& pool;
    std::vector<std::unique_ptr<WorkerScratch>> scratch;  // one per worker
    // Executors by DrawProgram::key (a program's identity for the device's lifetime).
    std::unordered_map<uint64_t, std::unique_ptr<ps11::Executor>> executors;
    // By DrawProgram::key and target size: whether deciding tiles paid on the program's last
    // decided draw, its draws since, and how many draws it waits before deciding again; where
    // draws are timed, the wall time per covered pixel of its decided and undecided draws
    // (moving averages, 0 until measured) and its decided draws since the last undecided one.
    struct TileHistory {
        bool paid = true;
        uint32_t since = 0;
        uint32_t wait = kTileRetryDraws;
        double tiledNs = 0, plainNs = 0;
        uint32_t decidedInARow = 0;
        bool warm = false;  // a decided draw was seen: the first, which scans its textures' facts, is not timed
    };
    std::unordered_map<uint64_t, TileHistory> tileHistory;
    // A draw into the destination of a copy put off: which bands of its rows have been copied.
    std::vector<uint8_t> bandCopied;
    // A chunk's triangles, setups, row-path tables and bands, kept between draws: a draw of
    // sprites allocated and first touched about 2 MB of them every time (page faults, then the
    // tables' own vectors), a tenth of its time. Tables are filled anew per chunk and keep their
    // memory (grown, never shrunk below a chunk's count).
    struct Chunk {
        std::vector<ScreenTriangle> tris;
        std::vector<TriangleSetup> setups;
        // Setups past the row-path column budget of the ones before them: the chunk's next part.
        std::vector<TriangleSetup> rest;
        std::vector<AlignedTriangle> alignedTris;
        std::vector<FloatRowTriangle> floatTris;
        std::vector<uint8_t> isAligned;
        // The triangle whose row tables serve each one: itself, or the first half of its quad
        // where the tables would be equal (sameColumnTables: the second half fills none).
        std::vector<uint32_t> tableOf;
        std::vector<uint32_t> bandStart, bandFill, bandTris;
    } chunk;
};

SoftwareRenderer::SoftwareRenderer(const SoftwareRendererOptions& options) : m_options(options) {}

SoftwareRenderer::~SoftwareRenderer() = default;

SoftwareDrawContext& SoftwareRenderer::context() {
    if (!m_context) m_context = std::make_unique<SoftwareDrawContext>(m_options.threads);
    return *m_context;
}

bool SoftwareRenderer::clear(const ClearCall& call) {
    context();
    // Copies put off that read what this clears are made first, and one into its target (a
    // clear may cover part of it).
    makeCopies(call.color.image, call.color.image);
    makeCopies(nullptr, call.depth.image);
    // Image rows in bands over the workers, as stretchRect's (each row is written by one of them).
    int64_t rows = 0, texels = 0;
    for (const SurfaceDesc* ref : {&call.color, &call.depth})
        if (ref->valid()) rows = std::max<int64_t>(rows, ref->image->height);
    for (const PixelBox& b : call.boxes) texels += std::max<int64_t>(b.x1 - b.x0, 0) * std::max<int64_t>(b.y1 - b.y0, 0);
    const int workers = int(std::clamp<int64_t>(texels / kMinBlitTexelsPerWorker, 1, m_context->pool.size()));
    m_context->pool.run(workers,
                        [&](int w) { clearImages(call, RowRange{rows * w / workers, rows * (w + 1) / workers}); });
    return true;
}

ThreadPool* SoftwareRenderer::workers() { return &context().pool; }

void SoftwareRenderer::copyRows(const StretchCall& call, int64_t rows) {
    // Destination rows in bands over the workers (each row is written by one of them).
    // The work is the texels read: four a pixel for LINEAR, whose scattered reads of a reduction
    // wait on memory.
    const int64_t texels = rows * (call.destRect.x1 - call.destRect.x0) * (call.linear ? 4 : 1);
    const int workers = int(std::clamp<int64_t>(texels / kMinBlitTexelsPerWorker, 1, context().pool.size()));
    m_context->pool.run(workers, [&](int w) {
        stretchImages(call, RowRange{rows * w / workers, rows * (w + 1) / workers});
    });
}

void SoftwareRenderer::makeCopies(const Image* into, const Image* from, uint32_t fromResource) {
    // In call order: a copy reads what the ones before it wrote.
    for (size_t i = 0; i < m_putOff.size();) {
        const StretchCall& c = m_putOff[i];
        if ((into && c.dest.image == into) || (from && c.source.image == from) ||
            (fromResource && c.source.resource == fromResource)) {
            const StretchCall call = c;
            m_putOff.erase(m_putOff.begin() + std::ptrdiff_t(i));
            // (Copies into its source: none, since stretchRect made them before putting this one
            // off and nothing puts one off into a source; kept as the rule's statement.)
            makeCopies(call.source.image, nullptr);
            copyRows(call, call.destRect.y1 - call.destRect.y0);
            i = 0;
            continue;
        }
        ++i;
    }
}

bool SoftwareRenderer::stretchRect(const StretchCall& call) {
    context();
    // The source's newest bytes, and nothing put off still reading what this overwrites.
    makeCopies(call.source.image, call.dest.image);
    const Image& d = *call.dest.image;
    const bool whole = call.destRect.x0 == 0 && call.destRect.y0 == 0 && call.destRect.x1 == int64_t(d.width) &&
                       call.destRect.y1 == int64_t(d.height) && d.depth == 1;
    if (m_options.putOffCopies && call.mayPutOff && whole) {
        // It writes every byte of the destination: a copy put off into it is dropped.
        std::erase_if(m_putOff, [&](const StretchCall& c) { return c.dest.image == call.dest.image; });
        m_putOff.push_back(call);
        return true;
    }
    makeCopies(call.dest.image, nullptr);
    copyRows(call, call.destRect.y1 - call.destRect.y0);
    return true;
}

bool SoftwareRenderer::leftNewer(const SurfaceDesc& surface) const {
    return std::any_of(m_putOff.begin(), m_putOff.end(),
                       [&](const StretchCall& c) { return c.dest.image == surface.image; });
}

void SoftwareRenderer::readBack(const SurfaceDesc& surface) { makeCopies(surface.image, nullptr); }

void SoftwareRenderer::beforeWrite(uint32_t resource) { makeCopies(nullptr, nullptr, resource); }

void SoftwareRenderer::release(uint32_t resource) {
    makeCopies(nullptr, nullptr, resource);
    std::erase_if(m_putOff, [&](const StretchCall& c) { return c.dest.resource == resource; });
}

bool SoftwareRenderer::draw(const DrawCall& call, DrawStats& stats, CallError& error) {
    SoftwareDrawContext& dc = context();
    const DrawProgram& prog = call.program;

    // ---- the executor of the program (one per program identity) ----
    auto it = dc.executors.find(prog.key);
    if (it == dc.executors.end()) {
        ps11::Diagnostics diags;
        std::unique_ptr<ps11::Executor> e =
            ps11::Executor::create(*prog.program, ps11::executorOptionsFor(call.hardware), diags);
        if (!e) {
            error.hr = D3DERR_INVALIDCALL;
            error.code = "E4121";
            error.message = prog.fixedFunction ? "the executor refused the fixed-function program"
                                               : "the executor refused the pixel shader";
            return false;
        }
        if (dc.executors.size() >= kMaxCachedExecutors) dc.executors.clear();
        it = dc.executors.emplace(prog.key, std::move(e)).first;
    }
    ps11::Executor& executor = *it->second;

    // Copies put off that read the targets are made first. One into the colour target is made
    // band by band, each band's rows just before the band is drawn (so a blend reads them from
    // cache), and the bands the draw does not reach after it; a draw of several chunks, whose
    // bands are visited once per chunk, has it made first.
    Image* const colorImage = call.target.color;
    makeCopies(nullptr, colorImage);
    makeCopies(call.target.depth, call.target.depth);
    std::optional<StretchCall> fused;
    if (colorImage) {
        auto pending = std::find_if(m_putOff.begin(), m_putOff.end(),
                                    [&](const StretchCall& c) { return c.dest.image == colorImage; });
        if (pending != m_putOff.end() && call.primitiveCount <= kChunkTriangles) {
            fused = *pending;
            m_putOff.erase(pending);
        } else if (pending != m_putOff.end()) {
            makeCopies(colorImage, nullptr);
        }
    }
    std::vector<uint8_t>& bandCopied = dc.bandCopied;
    if (fused) bandCopied.assign((size_t(colorImage->height) + kBandRows - 1) / kBandRows, 0);
    // A plain copy (one size, one 8-bit b g r a format) put off into the target of a draw by
    // the fx row path (alignedDraw) is made by the draw itself on the bands that path draws alone
    // (drawAlignedRows' RowSource): a direct store reads the source's words and writes the
    // target's, so those columns are not copied first.
    RowSource rowSource;
    if (fused && colorImage->format->bytes == 4 && colorImage->format->cls == FormatClass::Unorm8 &&
        fused->source.image->format == colorImage->format && fused->destRect.x0 == 0 && fused->destRect.y0 == 0 &&
        fused->destRect.x1 == int64_t(colorImage->width) && fused->destRect.y1 == int64_t(colorImage->height) &&
        fused->sourceRect.x1 - fused->sourceRect.x0 == int64_t(colorImage->width) &&
        fused->sourceRect.y1 - fused->sourceRect.y0 == int64_t(colorImage->height)) {
        rowSource.row0 = fused->source.image->texel(uint32_t(fused->sourceRect.x0), uint32_t(fused->sourceRect.y0));
        rowSource.pitch = fused->source.image->rowPitch;
        rowSource.width = int(colorImage->width);
        rowSource.height = int(colorImage->height);
    }
    auto copyBand = [&](int band) {
        if (bandCopied[size_t(band)]) return;  // (a band a chunk's earlier part reached)
        stretchImages(*fused, RowRange{int64_t(band) * kBandRows, int64_t(band + 1) * kBandRows});
        bandCopied[size_t(band)] = 1;
    };
    // On every way out: the bands not copied yet, over the workers.
    struct AtExit {
        std::function<void()> run;
        ~AtExit() { run(); }
    } copyRest{[&] {
        if (!fused) return;
        std::vector<int> rest;
        for (size_t b = 0; b < bandCopied.size(); ++b)
            if (!bandCopied[b]) rest.push_back(int(b));
        const int64_t texels = int64_t(rest.size()) * kBandRows * int64_t(colorImage->width);
        const int workers = int(std::clamp<int64_t>(texels / kMinBlitTexelsPerWorker, 1, dc.pool.size()));
        std::atomic<size_t> nextRest{0};
        dc.pool.run(workers, [&](int) {
            for (size_t i; (i = nextRest.fetch_add(1, std::memory_order_relaxed)) < rest.size();) copyBand(rest[i]);
        });
    }};

    for (int i = 0; i < kMaxPsConstants; ++i) executor.setConstant(i, prog.constants[size_t(i)]);
    for (int s = 0; s < kMaxStages; ++s) executor.setStageState(s, prog.stages[size_t(s)]);

    const uint32_t sampled = executor.sampledStages();
    // Triangles that take neither row path are shaded in rows too, without helper lanes, when
    // no lookup depends on quads (every sampled texture ps11::lodFree); else in 2×2 quads.
    bool rowSpans = m_options.alignedPasses;
    for (int s = 0; s < kMaxSamplers && rowSpans; ++s)
        if ((sampled >> s) & 1 && call.textures[size_t(s)])
            rowSpans = ps11::lodFree(*call.textures[size_t(s)], call.samplers[size_t(s)]);
    const MergeState& merge = call.merge;
    const MergeTarget& mtarget = call.target;
    const bool shaderDepth = executor.writesDepth();
    const bool kills = prog.kills;
    const bool wantZ = merge.depthTest || (merge.depthWrite && mtarget.depth);
    const uint64_t used = call.usedAttributes;
    const ClipRect clip = call.clip;
    const ps11::Precision precision = call.hardware.precision;

    // Triangles go through in chunks (memory stays bounded for any count); chunks run one after
    // the other, so primitive order holds across them.
    std::vector<ScreenTriangle>& tris = dc.chunk.tris;
    std::vector<TriangleSetup>& setups = dc.chunk.setups;
    // Screen-aligned passes: rows without quads (emu/aligned_pass.h), decided per triangle.
    AlignedDraw aligned;
    const bool alignedDraw =
        m_options.alignedPasses &&
        prepareAlignedDraw(executor, precision, call.textures, call.samplers, merge, mtarget, wantZ, used, aligned);
    std::vector<AlignedTriangle>& alignedTris = dc.chunk.alignedTris;
    // The float profiles' row path (emu/aligned_float.h), the same per-triangle decision.
    FloatRowDraw floatRows;
    const bool floatDraw = m_options.alignedPasses && !alignedDraw &&
                           prepareFloatRowDraw(executor, precision, call.hardware.weightBits, call.textures,
                                               call.samplers, merge, mtarget, wantZ, used, floatRows);
    std::vector<FloatRowTriangle>& floatTris = dc.chunk.floatTris;
    // Tiles the interval evaluator decides (emu/tile_skip.h), on chunks drawn wholly by a row path.
    // Deciding costs 0.4–3 µs a tile, and the first read of a texture scans its facts: a program
    // whose last decided draw did not pay (timed: took longer per pixel than its undecided
    // draws; untimed: fewer than a quarter of its tiles saved work — filled, skipped, or copied
    // where that saves) is shaded without deciding, and decided again on its kTileRetryDraws-th
    // draw after (which tiles are decided never changes a byte, only the time).
    std::unique_ptr<TileSkipper> skipper;
    // A copied tile saves work where the program reads more than that one tap, where the program
    // is the float executor's, or where its texels went straight to an 8-bit target (no filter, no
    // program: counted as drawn); the fx8 kernels of a one-tap program cost little next to filtering
    // the tap, which a copy does too, so such copies do not pay for deciding.
    const int tapCount = alignedDraw ? aligned.plan.count : floatDraw ? floatRows.plan.count : 0;
    const bool copiesSave = tapCount > 1 || floatDraw;
    std::atomic<uint64_t> copiesSaving{0}, copiedDirect{0};
    if (dc.tileHistory.size() > kMaxCachedExecutors) dc.tileHistory.clear();
    // (One program drawn at several sizes, as a blur pyramid's levels, has a history per size:
    // a small draw's fixed costs weigh more.)
    const uint64_t historyKey = prog.key ^ (uint64_t(uint32_t(clip.x1 - clip.x0)) << 40) ^
                                (uint64_t(uint32_t(clip.y1 - clip.y0)) << 20);
    SoftwareDrawContext::TileHistory& history = dc.tileHistory[historyKey];
    // (Meshes of more triangles than a row-path chunk takes are never tiled: no skipper, no scan.)
    // (Nor are draws whose taps' levels the level of detail picks: the tiles' facts are level 0's.)
    // (Tile-shaped: what drawBandTiles draws. Tileable: decided per tile, with skipping on.)
    // (Nor are those whose program's depth is tested or written: a tile's fill has none. Nor
    // those whose plain reads the executor samples itself: a copied tile would filter them.)
    const bool tileShaped = (alignedDraw || floatDraw) && !aligned.levelTaps.mask && !floatRows.levelTaps.mask &&
                            call.primitiveCount <= kMaxAlignedTriangles && !(shaderDepth && wantZ) &&
                            !(alignedDraw && aligned.plan.executedTaps) && !(floatDraw && floatRows.plan.executedTaps);
    const bool tileable = m_options.skipTiles && tileShaped;
    bool decide = tileable && (history.paid || ++history.since >= history.wait);
    // Timed: a program that pays is drawn undecided once after its second decided draw (the
    // first one's time, with the first reads of textures that may stay, is not taken), then on
    // every kTileProbeDraws-th.
    if (decide && m_options.timeTiles && history.paid && history.tiledNs > 0 &&
        (history.plainNs == 0 || history.decidedInARow >= kTileProbeDraws))
        decide = false;
    const auto drawStart = std::chrono::steady_clock::now();
    const uint64_t coveredBefore = stats.pixelsCovered;
    // The skipper is made for the first chunk whose every triangle is screen-aligned (a draw of
    // rotated or perspective triangles scans no texture and counts as undecided).
    bool skipperTried = false;
    bool anyDataTried = false;
    TileDecision anyData;  // TileSkipper::anyData, once asked
    const DrawStats tilesBefore = stats;
    std::vector<uint8_t>& isAligned = dc.chunk.isAligned;
    std::vector<uint32_t>& tableOf = dc.chunk.tableOf;
    std::vector<uint32_t>& bandStart = dc.chunk.bandStart;
    std::vector<uint32_t>& bandFill = dc.chunk.bandFill;
    std::vector<uint32_t>& bandTris = dc.chunk.bandTris;
    for (uint32_t first = 0; first < call.primitiveCount; first += kChunkTriangles) {
        const uint32_t chunk = std::min(kChunkTriangles, call.primitiveCount - first);
        tris.clear();
        setups.clear();
        call.assemble(first, chunk, tris);
        for (const ScreenTriangle& t : tris) {
            TriangleSetup& s = setups.emplace_back();
            if (!setupTriangle(t, used, clip, s)) setups.pop_back();
        }
        stats.trianglesDrawn += setups.size();
        std::vector<TriangleSetup>& rest = dc.chunk.rest;
        rest.clear();
        // The chunk in parts: each takes the triangles whose row-path tables fit the column
        // budget, and the triangles after them are the next part (in primitive order, so each
        // pixel's order holds). Draws of many sprites stay on the row path.
        bool nextPart = false;
        do {
            if (nextPart) {
                setups.swap(rest);
                rest.clear();
            }
            nextPart = true;
            int yLo = clip.y1, yHi = clip.y0;
            isAligned.assign(setups.size(), 0);
            // Tables for the part's triangles, in order, while their columns fit the budget (the same
            // for both row paths: a float table holds 12 bytes a column per tap, an fx8 one 16), a
            // quad's two halves over the same columns so they share tables and H rows (pairColumns).
            // Which triangles and columns is decided here, and the triangle past the budget starts
            // the next part; the tables are filled on the workers (independent per triangle: a
            // full-screen quad's two halves fill at once).
            // `rowPath(s, t)`: 0 quads, 1 screen-aligned, 2 the row path with taps sampled per
            // pixel (rowPathKind; those never share tables, and their tiles are not decided); it
            // sets the row triangle's columns t.x0, t.x1 and its levelFree.
            // `settle()` runs once the part's triangles are chosen, before their tables are filled.
            auto prepareTables = [&](auto& rowTris, const ps11::TapPlan& plan, int taps, auto rowPath, auto settle,
                                     auto fill) {
                if (rowTris.size() < setups.size()) rowTris.resize(setups.size());
                tableOf.resize(setups.size());
                const int64_t budget = kMaxAlignedColumnsPerTarget * std::max(clip.x1 - clip.x0, 1);
                int64_t columns = 0;
                bool paired = false;  // the triangle before was paired with the one before it
                for (size_t i = 0; i < setups.size() && columns <= budget; ++i) {
                    auto& t = rowTris[i];
                    tableOf[i] = uint32_t(i);
                    isAligned[i] = uint8_t(rowPath(setups[i], t));
                    std::pair<int, int> both;
                    const bool pair = isAligned[i] && i > 0 && isAligned[i - 1] && !paired &&
                                      pairColumns(rowTris[i - 1].x0, rowTris[i - 1].x1, t.x0, t.x1, clip, both);
                    if (pair) {
                        auto& p = rowTris[i - 1];
                        columns -= p.x1 - p.x0;
                        p.x0 = t.x0 = both.first;
                        p.x1 = t.x1 = both.second;
                        columns += p.x1 - p.x0;
                    }
                    if (isAligned[i] == 1 && i > 0 && isAligned[i - 1] == 1 && tableOf[i - 1] == i - 1 &&
                        t.x0 == rowTris[i - 1].x0 && t.x1 == rowTris[i - 1].x1 &&
                        sameColumnTables(setups[i - 1], setups[i], plan))
                        tableOf[i] = uint32_t(i - 1);
                    paired = pair;
                    if (isAligned[i]) columns += t.x1 - t.x0;
                    if (columns > budget) {
                        rest.assign(setups.begin() + ptrdiff_t(i), setups.end());
                        setups.resize(i);
                        isAligned.resize(i);
                        tableOf.resize(i);
                    }
                }
                settle();
                // About a microsecond per 64 columns of one tap: the workers share from 1024.
                const int64_t work = columns * std::max(taps, 1);
                const int workers = int(std::clamp<int64_t>(work / 1024, 1, dc.pool.size()));
                std::atomic<size_t> nextTri{0};
                dc.pool.run(workers, [&](int) {
                    for (size_t i; (i = nextTri.fetch_add(1, std::memory_order_relaxed)) < setups.size();)
                        if (isAligned[i] && tableOf[i] == i) fill(setups[i], rowTris[i]);
                });
            };
            // Taps whose level the quads' level of detail picks (LevelTaps): a part's screen-aligned
            // triangles read them at the one level and filter every quad of theirs picks, the part's
            // (the first such triangle's); on any other triangle they are sampled per pixel, each at
            // its quad's level, filter and mip blend (levelFree, quadLevels).
            TapLevels partLevels;
            bool partHasLevels = false;
            auto levelKind = [&](const LevelTaps& taps, const ps11::TapPlan& plan, uint32_t bound,
                                 const TriangleSetup& s, auto& t) {
                t.levelFree = 0;
                const int kind = rowPathKind(plan, bound, s, t.x0, t.x1);  // (sets x0, x1)
                if (kind == 0 || !taps.mask) return kind;
                TapLevels levels;
                if (kind == 1 && triangleLevels(taps, s, t.x0, t.x1, levels) &&
                    (!partHasLevels || levels == partLevels)) {
                    partLevels = levels;
                    partHasLevels = true;
                    return 1;
                }
                t.levelFree = taps.mask & ~freeTaps(plan, bound, s);
                return 2;
            };
            if (alignedDraw)
                prepareTables(
                    alignedTris, aligned.plan, aligned.plan.count,
                    [&](const TriangleSetup& s, AlignedTriangle& t) {
                        return levelKind(aligned.levelTaps, aligned.plan, aligned.bound, s, t);
                    },
                    [&] {
                        if (partHasLevels) setTapLevels(aligned, partLevels);
                    },
                    [&](const TriangleSetup& s, AlignedTriangle& t) { fillAlignedTables(aligned, s, t); });
            if (floatDraw) {
                prepareTables(
                    floatTris, floatRows.plan, floatRows.plan.count,
                    [&](const TriangleSetup& s, FloatRowTriangle& t) {
                        return levelKind(floatRows.levelTaps, floatRows.plan, floatRows.bound, s, t);
                    },
                    [&] {
                        if (partHasLevels) setTapLevels(floatRows, partLevels);
                    },
                    [&](const TriangleSetup& s, FloatRowTriangle& t) { fillFloatRowTables(floatRows, s, t); });
                shareFloatRowTables(floatRows, floatTris.data(), isAligned.data(), tableOf.data(), setups.size());
            }
            if (setups.empty()) continue;
            for (const TriangleSetup& t : setups) {
                yLo = std::min(yLo, t.yMin);
                yHi = std::max(yHi, t.yMax);
            }
            const bool tileShape = tileShaped && setups.size() <= kMaxAlignedTriangles &&
                                   std::all_of(isAligned.begin(), isAligned.end(), [](uint8_t a) { return a == 1; });
            const bool tileChunk = decide && tileable && tileShape;
            if (tileChunk && !skipperTried) {
                skipperTried = true;
                skipper =
                    TileSkipper::create(*prog.program, call, alignedDraw ? aligned.plan : floatRows.plan, dc.pool);
            }
            const bool tiles = tileChunk && skipper;
            // A chunk not decided tile by tile (skipping off, deciding did not pay lately, or the
            // program cannot be) whose program makes one decision whatever its textures hold
            // (TileSkipper::anyData: a composite of one texture scaled by 1 is a copy of it) is drawn
            // as that: a specialisation of the program, as the executor's fast paths are, taken
            // with skipping on or off (no pixel is left out: a skip, the merge of a zero that
            // changes nothing, is drawn as that fill with skipping off). No facts are scanned, no
            // tile is evaluated, and no tile is counted as decided. Asked once per draw
            // (bench_draw: a 1×1 blur's 3.9 µs did not change).
            if (!tiles && tileShape && !anyDataTried) {
                anyDataTried = true;
                const std::unique_ptr<TileSkipper> sk = TileSkipper::create(
                    *prog.program, call, alignedDraw ? aligned.plan : floatRows.plan, dc.pool, false);
                if (sk) anyData = sk->anyData();
                if (anyData.action == TileAction::Skip && !m_options.skipTiles) anyData.action = TileAction::Fill;
            }
            const TileDecision* fixed = !tiles && tileShape && anyData.action != TileAction::Shade ? &anyData : nullptr;

            // ---- rows in bands over the workers ----
            const int firstBand = (yLo & ~1) / kBandRows;
            const int lastBand = (yHi + kBandRows - 1) / kBandRows;
            const int bands = lastBand - firstBand;
            // Each band's triangles in primitive order (a draw of many small triangles, such as
            // sprites, visits each triangle only in the bands it touches).
            bandStart.assign(size_t(bands) + 1, 0);
            for (const TriangleSetup& t : setups)
                for (int b = std::max(t.yMin / kBandRows - firstBand, 0);
                     b < bands && (firstBand + b) * kBandRows < t.yMax; ++b)
                    ++bandStart[size_t(b) + 1];
            for (int b = 0; b < bands; ++b) bandStart[size_t(b) + 1] += bandStart[size_t(b)];
            bandTris.resize(bandStart[size_t(bands)]);
            bandFill.assign(bandStart.begin(), bandStart.end() - 1);
            for (uint32_t i = 0; i < setups.size(); ++i) {
                const TriangleSetup& t = setups[i];
                for (int b = std::max(t.yMin / kBandRows - firstBand, 0);
                     b < bands && (firstBand + b) * kBandRows < t.yMax; ++b)
                    bandTris[bandFill[size_t(b)]++] = i;
            }
            const int workers = std::min(dc.pool.size(), bands);
            // Bands in a contiguous range per worker: a worker's H rows of one band's last pixel
            // rows are those its next band reads first (magnified and offset taps).
            RangeQueue bandQueue(bands, workers);
            std::vector<DrawStats> workerStats(size_t(std::max(workers, 1)));
            const bool fx = ps11::isFixedPoint(precision);
            dc.pool.run(workers, [&](int w) {
                WorkerScratch& ws0 = *dc.scratch[size_t(w)];
                ps11::TextureSampler& sampler = ws0.sampler;
                sampler.setWeightBits(call.hardware.weightBits);
                sampler.setFastPath(m_options.fastSampler);
                for (int s = 0; s < kMaxSamplers; ++s) {
                    // Stages the program does not sample are unbound (no texture kept alive).
                    sampler.bind(s, (sampled >> s) & 1 ? call.textures[size_t(s)] : nullptr);
                    if ((sampled >> s) & 1) sampler.setSamplerState(s, call.samplers[size_t(s)]);
                }
                ws0.floatRows.sampler = &sampler;  // the row paths' taps sampled per pixel
                ws0.aligned.sampler = &sampler;
                const uint64_t fetchedBefore = sampler.texelsFetched();
                QuadSpan* span = &ws0.span;
                Lanes* lanes = &ws0.lanes;
                ps11::PixelInputs in;
                in.quads = !rowSpans;
                for (int c = 0; c < 4; ++c) {
                    if ((used >> (kAttrDiffuse + c)) & 1) in.color[0][c] = span->attr[kAttrDiffuse + c];
                    if ((used >> (kAttrSpecular + c)) & 1) in.color[1][c] = span->attr[kAttrSpecular + c];
                    for (int t = 0; t < kMaxTexSets; ++t)
                        if ((used >> attrTex(t, c)) & 1) in.texcoord[t][c] = span->attr[attrTex(t, c)];
                }
                ps11::PixelOutputs outp;
                const bool readsColor = mergeReadsColor(precision, mtarget);
                for (int c = 0; c < 4; ++c) {
                    outp.color[c] = readsColor ? lanes->color[c] : nullptr;
                    if (fx) outp.grid[c] = lanes->grid[c];
                }
                outp.killed = lanes->killed;
                outp.depth = shaderDepth ? lanes->depth : nullptr;
                ps11::ExecutorStats es;
                MergeStats ms;
                DrawStats& ws = workerStats[size_t(w)];
                auto emit = [&](QuadSpan& sp) {
                    in.count = sp.count;
                    executor.run(in, sampler, outp, &es);
                    if (kills)
                        for (int L = 0; L < sp.count; ++L)
                            lanes->live[L] = uint8_t(sp.live[L] & (lanes->killed[L] ^ 1));
                    MergeInputs mi;
                    mi.count = sp.count;
                    mi.x = sp.x;
                    mi.y = sp.y;
                    // (A row span's lanes are one run of a row, every one covered.)
                    mi.live = kills ? lanes->live : rowSpans ? nullptr : sp.live;
                    mi.row = rowSpans;
                    for (int c = 0; c < 4; ++c) {
                        mi.color[c] = readsColor ? lanes->color[c] : nullptr;
                        mi.grid[c] = fx ? lanes->grid[c] : nullptr;
                    }
                    mi.fog = merge.fog ? sp.attr[kAttrSpecular + 3] : nullptr;
                    mi.z = shaderDepth ? lanes->depth : (wantZ ? sp.z : nullptr);
                    mergePixels(merge, mi, mtarget, &ms);
                    ws.pixelsCovered += uint64_t(sp.liveCount);
                };
                const std::function<void(QuadSpan&)> emitFn = emit;
                AlignedStats as;
                std::vector<RowWindow> windows;
                TileMemo memo;
                // A band of a chunk drawn wholly by a row path, tile by tile (emu/tile_skip.h).
                // True where it drew the band's rows (with `source`: every row then holds the
                // copy under what was drawn); false where it drew nothing.
                auto drawBandTiles = [&](int b, int by0, int by1, const RowSource* source) {
                    const TriangleSetup* bt[kMaxAlignedTriangles];
                    const AlignedTriangle* at[kMaxAlignedTriangles];
                    const FloatRowTriangle* ft[kMaxAlignedTriangles];
                    size_t n = 0;
                    int ty0 = by1, ty1 = by0;
                    for (uint32_t k = bandStart[size_t(b)]; k < bandStart[size_t(b) + 1] && n < kMaxAlignedTriangles;
                         ++k) {
                        const uint32_t i = bandTris[k];
                        bt[n] = &setups[i];
                        ft[n] = floatDraw ? &floatTris[tableOf[i]] : nullptr;
                        at[n++] = floatDraw ? nullptr : &alignedTris[tableOf[i]];
                        ty0 = std::min(ty0, std::max(by0, setups[i].yMin));
                        ty1 = std::max(ty1, std::min(by1, setups[i].yMax));
                    }
                    if (n == 0 || ty0 >= ty1) return false;
                    // The columns the band's triangles cover (a small quad decides only its own tiles).
                    int tx0 = clip.x1, tx1 = clip.x0;
                    for (size_t t = 0; t < n; ++t)
                        for (int y = std::max(ty0, bt[t]->yMin); y < std::min(ty1, bt[t]->yMax); ++y) {
                            int xl = 0, xr = 0;
                            if (rowCoverage(*bt[t], y, xl, xr)) tx0 = std::min(tx0, xl), tx1 = std::max(tx1, xr);
                        }
                    if (tx0 >= tx1) return false;
                    // Runs of tiles with one decision become the windows of one pass over the band's
                    // rows (each texel row the windows need is filtered once per pixel row).
                    windows.clear();
                    auto addRun = [&](const TileDecision& d, int xa, int xb, uint64_t count) {
                        if (fixed) count = 0;  // (not decided per tile: not counted)
                        switch (d.action) {
                            case TileAction::Shade:
                                ws.tilesShaded += count;
                                break;
                            case TileAction::Fill:
                                ws.tilesFilled += count;
                                break;
                            case TileAction::Copy:
                                ws.tilesCopied += count;
                                if (copiesSave) copiesSaving.fetch_add(count, std::memory_order_relaxed);
                                break;
                            case TileAction::Skip:
                                ws.tilesSkipped += count;
                                // Nothing is drawn; the pixels are still covered.
                                for (int y = by0; y < by1; ++y)
                                    for (size_t t = 0; t < n; ++t) {
                                        int xl = 0, xr = 0;
                                        if (y >= bt[t]->yMin && y < bt[t]->yMax && rowCoverage(*bt[t], y, xl, xr))
                                            as.pixels += uint64_t(std::max(0, std::min(xr, xb) - std::max(xl, xa)));
                                    }
                                return;
                        }
                        windows.push_back(d.window(xa, xb));
                    };
                    TileDecision run;
                    int runX0 = tx0;
                    uint64_t runTiles = 0;
                    for (int x = tx0; x < tx1; x += kSkipTileColumns) {
                        const int xe = std::min(tx1, x + kSkipTileColumns);
                        const TileDecision d = fixed ? *fixed : skipper->decide(bt, n, x, xe, ty0, ty1, memo);
                        if (runTiles && !(d == run)) {
                            addRun(run, runX0, x, runTiles);
                            runTiles = 0;
                        }
                        if (!runTiles) run = d, runX0 = x;
                        ++runTiles;
                    }
                    if (runTiles) addRun(run, runX0, tx1, runTiles);
                    if (windows.empty()) return false;
                    if (floatDraw) {
                        drawFloatRows(floatRows, ft, bt, n, by0, by1, ws0.floatRows, as, windows.data(),
                                      windows.size());
                    } else {
                        drawAlignedRows(aligned, at, bt, n, by0, by1, ws0.aligned, as, windows.data(), windows.size(),
                                        source);
                    }
                    return true;
                };
                for (;;) {
                    const int b = bandQueue.take(w);
                    if (b < 0) break;
                    const int by0 = (firstBand + b) * kBandRows;
                    const int by1 = by0 + kBandRows;
                    // (A band the fx row path draws alone — tile by tile, or every triangle of a
                    // chunk of at most kMaxAlignedTriangles taking it — makes its copy as it draws.)
                    const bool sourced = (tiles || fixed || tileShape) && alignedDraw && rowSource.row0 &&
                                         !bandCopied[size_t(firstBand + b)];
                    if (fused && !sourced) copyBand(firstBand + b);
                    // Consecutive aligned triangles go row by row together (emu/aligned_pass.h).
                    const AlignedTriangle* group[kMaxAlignedTriangles];
                    const FloatRowTriangle* floatGroup[kMaxAlignedTriangles];
                    const TriangleSetup* groupSetups[kMaxAlignedTriangles];
                    size_t grouped = 0;
                    auto flush = [&](const RowSource* source = nullptr) {
                        if (grouped && floatDraw)
                            drawFloatRows(floatRows, floatGroup, groupSetups, grouped, by0, by1, ws0.floatRows, as);
                        else if (grouped)
                            drawAlignedRows(aligned, group, groupSetups, grouped, by0, by1, ws0.aligned, as, nullptr, 0,
                                            source);
                        grouped = 0;
                    };
                    if (tiles || fixed) {
                        if (!drawBandTiles(b, by0, by1, sourced ? &rowSource : nullptr) && sourced)
                            copyBand(firstBand + b);  // (nothing drawn: copied now as before)
                        if (sourced) bandCopied[size_t(firstBand + b)] = 1;
                        continue;
                    }
                    for (uint32_t k = bandStart[size_t(b)]; k < bandStart[size_t(b) + 1]; ++k) {
                        const uint32_t i = bandTris[k];
                        const TriangleSetup& s = setups[i];
                        if (isAligned[i]) {
                            if (grouped == kMaxAlignedTriangles) flush();  // groups in order: each pixel's order holds
                            if (floatDraw)
                                floatGroup[grouped] = &floatTris[tableOf[i]];
                            else
                                group[grouped] = &alignedTris[tableOf[i]];
                            groupSetups[grouped++] = &s;
                            continue;
                        }
                        flush();
                        if (rowSpans)
                            rasterizeRowSpans(s, by0, by1, used, wantZ, *span, emitFn);
                        else
                            rasterizeRows(s, by0, by1, used, wantZ, *span, emitFn);
                    }
                    // (tileShape: every triangle of the band is in this one group.)
                    if (sourced && grouped == 0) copyBand(firstBand + b);  // (nothing to draw)
                    flush(sourced ? &rowSource : nullptr);
                    if (sourced) bandCopied[size_t(firstBand + b)] = 1;
                }
                // The draw's textures are not kept alive past it: a texture read in place would
                // otherwise be copied on its next write (Device::prepareWrite).
                for (int s = 0; s < kMaxSamplers; ++s) sampler.bind(s, nullptr);
                copiedDirect.fetch_add(as.copiedDirect, std::memory_order_relaxed);
                ws.pixelsCovered += as.pixels;
                ws.pixelsRowPath = as.pixels;
                ws.pixelsShaded = es.pixels + as.exec.pixels;
                ws.instructions = es.instructions + as.exec.instructions;
                ws.pixelsWritten = ms.written + as.written;
                ws.texelsFetched = sampler.texelsFetched() - fetchedBefore + as.texels;
            });
            for (const DrawStats& ws : workerStats) {
                stats.pixelsCovered += ws.pixelsCovered;
                stats.pixelsRowPath += ws.pixelsRowPath;
                stats.pixelsShaded += ws.pixelsShaded;
                stats.instructions += ws.instructions;
                stats.pixelsWritten += ws.pixelsWritten;
                stats.texelsFetched += ws.texelsFetched;
                stats.tilesShaded += ws.tilesShaded;
                stats.tilesFilled += ws.tilesFilled;
                stats.tilesCopied += ws.tilesCopied;
                stats.tilesSkipped += ws.tilesSkipped;
            }
        } while (!rest.empty());
    }
    // The draw's time per covered pixel, into the history of how it was drawn.
    if (m_options.timeTiles && tileable && stats.pixelsCovered > coveredBefore) {
        const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - drawStart).count();
        const double nsPerPixel = ns / double(stats.pixelsCovered - coveredBefore);
        double& avg = skipper ? history.tiledNs : history.plainNs;
        if (!skipper || history.warm)
            avg = avg == 0 ? nsPerPixel : (1 - kTileTimeWeight) * avg + kTileTimeWeight * nsPerPixel;
        history.warm = history.warm || skipper;
        history.decidedInARow = skipper ? history.decidedInARow + 1 : 0;
    }
    if (skipper) {
        const uint64_t shaded = stats.tilesShaded - tilesBefore.tilesShaded;
        const uint64_t copied = stats.tilesCopied - tilesBefore.tilesCopied;
        const uint64_t copiesSaved =
            std::min(copied, copiesSaving.load() + copiedDirect.load() / uint64_t(kBandRows * kSkipTileColumns));
        const uint64_t saved =
            stats.tilesFilled + stats.tilesSkipped - tilesBefore.tilesFilled - tilesBefore.tilesSkipped + copiesSaved;
        // Timed: it paid where decided draws took less time per pixel than undecided ones;
        // until an undecided draw is timed, and untimed: a quarter of the tiles or more saved.
        const bool paid = m_options.timeTiles && history.plainNs > 0 ? history.tiledNs < history.plainNs
                                                                     : saved * 4 >= shaded + copied + saved - copiesSaved;
        // The first miss after paying waits kTileRetryDraws; each miss after a miss doubles it.
        history.wait = paid || history.paid ? kTileRetryDraws : std::min(2 * history.wait, kMaxTileRetryDraws);
        history.paid = paid;
        history.since = 0;
    }
    return true;
}

}  // namespace emu
