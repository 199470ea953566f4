// The rasteriser (docs/device.md "Rasterisation"): D3D9 rules on screen-space triangles from
// emu/vertex.h. Pixel centres at integer coordinates; coverage by fixed-point edge functions
// with 8 sub-pixel bits and the top-left fill rule, evaluated exactly in 64-bit integers per
// row; a clip rectangle (viewport ∩ scissor ∩ target); perspective-correct attributes; z linear
// in screen space; output as spans of 2×2 quads (ps11::PixelInputs::quads) with helper lanes.
#pragma once

#include <array>
#include <cstdint>
#include <functional>

#include "emu/vertex.h"
#include "ps11/sampler.h"

namespace emu {

// Sub-pixel precision of vertex positions: coordinates are snapped to 1/256 pixel.
constexpr int kSubPixelBits = 8;

// Pixels x0 <= x < x1, y0 <= y < y1.
struct ClipRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// value(x, y) = base + dx·(x − ox) + dy·(y − oy), in double.
struct Plane {
    double base = 0, dx = 0, dy = 0;
};

// The rasteriser's value of a plane at pixel (x, y) (not perspective-divided): the float sum
// float(planeRowBase(p, ox, oy, y)) + float(p.dx) · float(x), with no contraction into an FMA.
// Spans compute exactly this per lane, so a value depends on the pixel only.
inline double planeRowBase(const Plane& p, double ox, double oy, int y) {
    return p.base + p.dx * (0.0 - ox) + p.dy * (double(y) - oy);
}
float planeValue(const Plane& p, double ox, double oy, int x, int y);
// planeValue at pixels x0 .. x0 + n − 1 of row y (the row paths' lanes, rasterizeRowSpans').
void fillPlaneRow(const Plane& p, double ox, double oy, int x0, int y, int n, float* out);
// The factor a lane's attr·rhw planes are multiplied by under perspective: 1 / rhw, rhw kept
// positive (helper lanes far outside a triangle may extrapolate it to <= 0).
inline float inverseRhw(float rhw) { return 1.0f / (rhw > 1e-30f ? rhw : 1e-30f); }

struct TriangleSetup {
    // Edge i: E(X, Y) = a·X + b·Y + c with X, Y in 1/256 pixel; a pixel centre is covered when
    // E >= t for all three edges (t = 0 on top and left edges, 1 on the others).
    std::array<int64_t, 3> a{}, b{}, c{}, t{};
    int yMin = 0, yMax = 0;  // rows that may be covered, inside the clip rect
    ClipRect clip;
    double ox = 0, oy = 0;     // plane origin (vertex 0, snapped)
    bool perspective = false;  // rhw differs between vertices: attributes are attr·rhw planes
    Plane rhw, z;
    uint64_t constMask = 0;  // attributes equal at the three vertices: constValue, no plane
    std::array<float, kAttrCount> constValue{};
    std::array<Plane, kAttrCount> attr{};
};

// Sets up a triangle; false when it covers nothing (degenerate after snapping, or outside the
// clip rect). `used` selects the attributes to interpolate.
bool setupTriangle(const ScreenTriangle& tri, uint64_t used, const ClipRect& clip, TriangleSetup& out);

// The covered pixels of row y: [xl, xr) inside the clip rect; false when empty.
bool rowCoverage(const TriangleSetup& s, int y, int& xl, int& xr);
// The columns [xlo, xhi) that rowCoverage covers on any row of the triangle (the union of its
// rows' spans), stepping each edge's bound from row to row instead of dividing on every row;
// false when no row is covered.
bool coveredColumns(const TriangleSetup& s, int& xlo, int& xhi);

// A span of up to ps11::kMaxSpan lanes laid out as 2×2 quads: lanes 4i..4i+3 are
// (x, y), (x+1, y), (x, y+1), (x+1, y+1) of quad i. Helper lanes (outside the triangle or the
// clip rect) have live = 0: they are shaded so the sampler sees the quad, never written.
struct QuadSpan {
    int count = 0;  // lanes, a multiple of 4
    int liveCount = 0;
    alignas(32) int32_t x[ps11::kMaxSpan];
    alignas(32) int32_t y[ps11::kMaxSpan];
    alignas(32) uint8_t live[ps11::kMaxSpan];
    alignas(32) float z[ps11::kMaxSpan];
    alignas(32) float attr[kAttrCount][ps11::kMaxSpan];
    // Lanes of attr[k] already holding constFill[k] (constant attributes are not refilled per span).
    std::array<int, kAttrCount> constLanes{};
    std::array<float, kAttrCount> constFill{};
};

// Rasterises rows [y0, y1) of the triangle (y0 even; rows outside the triangle's range are
// skipped), filling `span` with the attributes in `used` (and z when `wantZ`) and calling
// `emit(span)` for each span, left to right within a row pair, row pairs top to bottom.
void rasterizeRows(const TriangleSetup& s, int y0, int y1, uint64_t used, bool wantZ, QuadSpan& span,
                   const std::function<void(QuadSpan&)>& emit);

// Rasterises rows [y0, y1) of the triangle as spans of one row each (up to ps11::kMaxSpan
// covered pixels, left to right, no helper lanes: PixelInputs::quads off), with the attributes
// each pixel gets in rasterizeRows. For draws whose every lookup is the same without quads
// (ps11::lodFree): the software renderer's spans then (docs/device.md "Rasterisation").
void rasterizeRowSpans(const TriangleSetup& s, int y0, int y1, uint64_t used, bool wantZ, QuadSpan& span,
                       const std::function<void(QuadSpan&)>& emit);

}  // namespace emu
