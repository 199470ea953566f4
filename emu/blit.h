// Clear and StretchRect in the front's images (docs/device.md "Clear", "StretchRect"): what the
// software renderer does for these calls, and what the front does itself when a renderer that
// keeps copies leaves a call to it (emu/renderer.h).
#pragma once

#include <cstdint>
#include <vector>

#include "emu/renderer.h"

namespace emu {

// One destination column (or row) of a StretchRect: POINT reads source texel i0; LINEAR blends
// i0 and i1 with weight w1 on i1 (8 bits of sub-texel weight in fx profiles), both clamped to the
// source rect.
struct StretchTap {
    int64_t i0 = 0, i1 = 0;
    double w1 = 0;
};
// The taps of every destination column (`horizontal`) or row, by the texel-centre mapping.
std::vector<StretchTap> stretchTaps(const StretchCall& call, bool horizontal);

// Rows [first, last) of a call's work, so that workers can share one call.
struct RowRange {
    int64_t first = 0, last = INT64_MAX;
};
// Fills the call's boxes of call.color.image and call.depth.image (when valid); `rows` limits the
// work to image rows [first, last) (the default is every row).
void clearImages(const ClearCall& call, RowRange rows = {});
// Copies call.sourceRect of call.source.image to call.destRect of call.dest.image, scaling with
// POINT or LINEAR filtering (texel-centre mapping; 8-bit weights in fx profiles, rounded once).
// `rows` limits the work to destination rows [first, last) of the rect (relative to its top);
// the default is every row.
void stretchImages(const StretchCall& call, RowRange rows = {});

// A whole-surface copy put off into a draw's target, made band by band by the draw's own writes
// (docs/device.md "StretchRect"): where the copy is one of a single format at the same size, a
// band whose every write adds onto the target (ONE/ONE: the fx row paths' direct stores) adds
// onto the copy's source instead of copying the band first. A pixel's first write reads the
// source, any later one the target; the band's pixels no write reached are copied when it is done.
// One per worker; a band is the worker's own.
class BandCopy {
public:
    // Whether `call` is such a copy: one format, the source rect the destination's size, the
    // destination whole.
    static bool rowCopy(const StretchCall& call);
    // Starts target rows [y0, y1) of the copy `call` (rowCopy): no pixel written yet.
    void begin(const StretchCall& call, int y0, int y1);
    // The words an additive write of pixels [x, x + n) of row y (within the band) adds onto: the
    // copy's source where none of them was written yet, else `dst` (the target's row at x), after
    // the ones not written yet were copied there. Every one of them counts as written after.
    const uint8_t* base(int x, int y, int n, uint8_t* dst);
    // Copies the band's pixels no write reached.
    void finish();

private:
    const uint8_t* source(int x, int y) const;
    const StretchCall* m_call = nullptr;
    int m_y0 = 0, m_y1 = 0;
    size_t m_words = 0;            // 64-pixel words of written bits per row
    size_t m_bytes = 4;            // per texel
    std::vector<uint64_t> m_bits;  // bit x of row y: pixel (x, y) written
};

}  // namespace emu
