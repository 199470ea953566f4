// The output merger (docs/device.md "Output merger"): what happens to a shaded pixel after the
// pixel shader or fixed-function stages — vertex fog, alpha test, depth test and write, alpha
// blending, colour write mask — and the store into the render target, in the device's
// precision profile (docs/precision.md "Outputs").
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "emu/call_error.h"
#include "emu/d3d9types.h"
#include "emu/resources.h"
#include "emu/state.h"
#include "ps11/precision.h"
#include "ps11/sampler.h"  // kMaxSpan

namespace emu {

// The render states the merger reads, taken once per draw.
struct MergeState {
    bool alphaTest = false;
    D3DCMPFUNC alphaFunc = D3DCMP_ALWAYS;
    uint32_t alphaRef = 0;   // 0..255
    bool depthTest = false;  // ZENABLE and a depth surface bound
    bool depthWrite = false;
    D3DCMPFUNC depthFunc = D3DCMP_LESSEQUAL;
    bool fog = false;  // FOGENABLE with FOGTABLEMODE NONE: vertex fog from the specular alpha
    D3DCOLOR fogColor = 0;
    bool blend = false;
    D3DBLEND srcBlend = D3DBLEND_ONE, dstBlend = D3DBLEND_ZERO;
    D3DBLENDOP blendOp = D3DBLENDOP_ADD;
    bool separateAlpha = false;
    D3DBLEND srcBlendAlpha = D3DBLEND_ONE, dstBlendAlpha = D3DBLEND_ZERO;
    D3DBLENDOP blendOpAlpha = D3DBLENDOP_ADD;
    D3DCOLOR blendFactor = 0xffffffff;
    uint32_t colorWrite = 0xf;  // D3DCOLORWRITEENABLE_* bits: 1 r, 2 g, 4 b, 8 a
    ps11::Precision precision = ps11::Precision::Fx8;

    // From the device's render states; depthTest only when `hasDepth`.
    static MergeState from(const DeviceState& state, bool hasDepth, ps11::Precision precision);
    // True when no pixel can change the target (colour writes off and no depth write, …).
    bool writesNothing() const;
};

// Up to ps11::kMaxSpan shaded pixels, structure of arrays, in any order (lanes of 2x2 quads
// included) but each pixel at most once per call.
struct MergeInputs {
    int count = 0;
    const int32_t* x = nullptr;  // pixel coordinates inside the target
    const int32_t* y = nullptr;
    const uint8_t* live = nullptr;  // 1 = covered and not discarded by texkill; null = all live
    // The lanes are pixels x[0] .. x[0] + count − 1 of row y[0] (the row paths' spans): the
    // merger may store them as one run (x and y must still be given and say the same).
    bool row = false;
    // r0 from the executor: color (real values; may be null where mergeReadsColor says the merge
    // never reads it, and then reads as 0); grid in fx profiles (value = grid / G), null
    // otherwise. The merger uses grid when given.
    const float* color[4] = {};
    const int32_t* grid[4] = {};
    const float* fog = nullptr;  // fog factor per lane (1 = no fog; clamped to [0, 1]; null = 1), when MergeState::fog
    const float* z = nullptr;    // depth per lane (clamped to [0, 1]; null = 0), used when depthTest
};

struct MergeTarget {
    Image* color = nullptr;  // A8R8G8B8, X8R8G8B8, A16B16G16R16F, A32B32G32R32F or R32F; may be null
    Image* depth = nullptr;  // a depth format, or null
};

// Counts of live pixels; written + alphaRejected + depthRejected = the live lanes.
struct MergeStats {
    uint64_t written = 0;        // pixels that passed every test and reached the store (whatever the mask)
    uint64_t alphaRejected = 0;  // failed the alpha test
    uint64_t depthRejected = 0;  // failed the depth test
};

// The stored byte of a saturated fx12 grid value n in [0, 4080]: round_half_even(n / 16)
// (n = 16q + r rounds up when r > 8, or r == 8 and q is odd).
inline uint32_t unorm8OfFx12(int32_t n) { return uint32_t(n + 7 + ((n >> 4) & 1)) >> 4; }

// Whether mergePixels reads MergeInputs::color: always in the float profiles; in fx profiles,
// which merge from the grid, only into float colour targets.
bool mergeReadsColor(ps11::Precision precision, const MergeTarget& target);

// Merges the pixels into the target. Thread-safe for calls that touch disjoint pixels.
// Another colour format, a non-depth format as `depth`, or pixels outside the target are the
// caller's programming errors: asserted (debug), and skipped in release builds.
void mergePixels(const MergeState& state, const MergeInputs& in, const MergeTarget& target, MergeStats* stats);

// The same with the plan made once for a draw's many calls (makePlan of `state` and the target,
// emu/merge_plan.h; ok): valid while both are as they were.
struct Plan;
void mergePixels(const Plan& plan, const MergeState& state, const MergeInputs& in, MergeStats* stats);

// The depth test, and the write where it passes, of the live lanes of `in` (x, y, z, live, row),
// as mergePixels makes it first when no alpha test comes before it; passed[i] says which lanes
// passed. True when every lane did. A row path tests a run so before shading it: the run's colour
// then merges by `state` with its depth test off (MergeState::depthTest, depthWrite), over the
// lanes that passed. Requires state.depthTest, a depth target and no alpha test.
bool depthTestFirst(const MergeState& state, const MergeInputs& in, const MergeTarget& target, uint8_t* passed,
                    MergeStats* stats);

// Vertex fog of an fx profile into an 8-bit target over the lanes of `in` (count, fog), in place
// in grid[0..2] (r g b on the profile's grid), as mergePixels applies it first: each becomes
// f·s + (1 − f)·FOGCOLOR of the saturated s, rounded once. A row path fogs a run so before it
// stores the run itself. Requires state.fog, an fx precision and an 8-bit colour target.
void fogGridFirst(const MergeState& state, const MergeInputs& in, const MergeTarget& target,
                  int32_t (*grid)[ps11::kMaxSpan]);

// Draw-time check of the states the merger reads (ValidateDevice-style): nullopt when they are
// usable, else D3DERR_INVALIDCALL, E4160, "D3DRS_SRCBLEND 99 is not a D3DBLEND value" for an
// unknown D3DBLEND / D3DBLENDOP / D3DCMPFUNC value in a state that is in use (the caller
// prefixes its call's name). (MergeState::from never fails: unknown values act as the state's
// D3D9 default.)
std::optional<CallError> mergeStateError(const DeviceState& state);

}  // namespace emu
