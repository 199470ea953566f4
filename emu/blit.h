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

}  // namespace emu
