// The software renderer (docs/device.md "Drawing"): triangle setup and rasterisation
// (emu/raster.h) in bands of rows over a worker pool, the executor over 2×2-quad spans with a
// TextureSampler per worker, screen-aligned passes on the row path (emu/aligned_pass.h), and the
// output merger (emu/output_merger.h). It draws what the device front resolved (emu/renderer.h).
#pragma once

#include <memory>
#include <vector>

#include "emu/renderer.h"

namespace emu {

// What only the software renderer has.
struct SoftwareRendererOptions {
    int threads = 0;  // worker threads of draws; 0 = all cores
    // Rows instead of 2x2 quads (bit-identical images; no helper lanes, so fewer pixels shaded):
    // the row paths of emu/aligned_pass.h (fx8, fx12) and emu/aligned_float.h (float, ideal), and
    // spans of one row (rasterizeRowSpans) for any other triangle whose every lookup is
    // ps11::lodFree. Off: every draw goes through 2x2 quads.
    bool alignedPasses = true;
    // The sampler's fast kernels for 8-bit 2-D textures (ps11/texture_sampler_fast.h) on the spans
    // and quads (TextureSampler::setFastPath; bit-identical images). Off: every lookup there by
    // the reference path (the row paths, which only alignedPasses turns off, sample with the
    // kernels themselves).
    bool fastSampler = true;
    // Tiles of row-path draws whose result the interval evaluator decides are filled, copied or
    // skipped instead of shaded (emu/tile_skip.h; bit-identical images). Off: every tile drawn (a
    // program that copies one tap whatever it reads is still drawn as that copy: TileSkipper::anyData).
    bool skipTiles = true;
    // Whether deciding a program's tiles pays is judged by the wall time per pixel of its
    // decided draws against its undecided ones (the draws' own times, so it varies from run to
    // run; never a byte). Off: by the share of tiles saved alone (deterministic: tests that count
    // decided tiles turn timing off).
    bool timeTiles = true;
    // A StretchRect onto a whole surface is put off until something reads or writes the
    // destination or writes the source; a draw into the destination then copies each band of
    // rows just before it draws them (the composite over a copied scene reads its target while
    // the rows are in cache), or with the fx row path drawing tiles, makes the copy as it
    // stores (drawAlignedRows' RowSource). Off: the copy is made by StretchRect. Either way the
    // same bytes.
    bool putOffCopies = true;
};

struct SoftwareDrawContext;  // the worker pool and the executor cache (software_renderer.cpp)

class SoftwareRenderer final : public Renderer {
public:
    explicit SoftwareRenderer(const SoftwareRendererOptions& options);
    ~SoftwareRenderer() override;
    bool draw(const DrawCall& call, DrawStats& stats, CallError& error) override;
    // In the front's images (emu/blit.h): the software renderer keeps no copies.
    bool clear(const ClearCall& call) override;
    bool stretchRect(const StretchCall& call) override;
    // Copies put off (SoftwareRendererOptions::putOffCopies): the destination is newer here
    // until the copy is made, which readBack, beforeWrite (of the source) and release do.
    bool leftNewer(const SurfaceDesc& surface) const override;
    void readBack(const SurfaceDesc& surface) override;
    void beforeWrite(uint32_t resource) override;
    void release(uint32_t resource) override;
    const char* name() const override { return "software"; }
    ThreadPool* workers() override;
    const SoftwareRendererOptions& options() const { return m_options; }

private:
    SoftwareDrawContext& context();
    // Makes the copies put off that write `into` or read `from` (images; null matches none), or
    // read the resource `fromResource` (0: none).
    void makeCopies(const Image* into, const Image* from, uint32_t fromResource = 0);
    void copyRows(const StretchCall& call, int64_t rows);  // the whole call over the workers

    SoftwareRendererOptions m_options;
    std::unique_ptr<SoftwareDrawContext> m_context;  // created by the first draw (threads start then)
    std::vector<StretchCall> m_putOff;               // copies not made yet, in call order
};

}  // namespace emu
