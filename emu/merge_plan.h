// The output merger's plan (docs/output-merger.md): the render states of one draw resolved into
// per-channel blend factors, compare masks, the enabled channels and the target kinds. The
// software merger (emu/output_merger.cpp) runs its loops from it; the GL renderer
// (emu/gl/glsl_merge.cpp) generates its merge code from the same plan.
#pragma once

#include <cstddef>
#include <cstdint>

#include "emu/output_merger.h"

namespace emu {

// Compare: D3DCMPFUNC - 1 is a 3-bit mask of the outcomes that pass (bit 0 less, bit 1 equal,
// bit 2 greater): NEVER 0, LESS 1, EQUAL 2, LESSEQUAL 3, GREATER 4, NOTEQUAL 5, GREATEREQUAL 6,
// ALWAYS 7. Bit 3 is the unordered outcome of a NaN (passes NOTEQUAL and ALWAYS, as IEEE).
inline uint32_t cmpMask(D3DCMPFUNC f) {
    uint32_t m = uint32_t(f) - 1;
    return m | ((m == 5 || m == 7) ? 8u : 0u);
}

// Per-pixel value slots a factor selects from (all on the same scale: the grid G in fx
// profiles, 1.0 in float arithmetic).
enum Slot : uint8_t {
    kZero = 0,
    kOne = 1,
    kSrc = 2,   // 2..5: source r g b a
    kDst = 6,   // 6..9: destination r g b a
    kSat = 10,  // min(As, 1 - Ad)
    kBf = 11,   // 11..14: BLENDFACTOR r g b a
    kSlots = 15
};

// A factor is base + sign * slot: inverse factors are 1 - slot.
struct Factor {
    uint8_t slot = kZero;
    bool inv = false;
};

enum class OpKind : uint8_t { Linear, Min, Max };

struct ChannelPlan {
    Factor src, dst;
    OpKind kind = OpKind::Linear;
    int32_t cs = 1, cd = 1;  // Linear: cs * src * Fs + cd * dst * Fd
};

enum class TargetKind : uint8_t { Argb8, Xrgb8, Rgba16F, Rgba32F, R32F };

// A surface's addressing, copied into the loops (so stores through byte pointers, which may
// alias anything, do not force reloads of the Image's fields).
struct Surf {
    uint8_t* base = nullptr;
    size_t pitch = 0;
    uint32_t bpp = 0;
    uint8_t* at(uint32_t x, uint32_t y) const { return base + size_t(y) * pitch + size_t(x) * bpp; }
};
enum class DepthKind : uint8_t { D16, D24, D32, D32F };

struct Plan {
    ps11::Precision precision = ps11::Precision::Fx8;
    bool alphaTest = false, depthTest = false, depthWrite = false, fog = false, blend = false;
    uint32_t alphaMask = 7, depthMask = 3;
    uint32_t alphaRef = 0;
    uint8_t fogByte[3] = {};  // FOGCOLOR r g b
    uint8_t bfByte[4] = {};   // BLENDFACTOR r g b a
    ChannelPlan ch[4];
    uint32_t channels = 0;  // enabled and changing channels, bit c = r g b a
    Image* color = nullptr;
    Image* depth = nullptr;
    Surf colorSurf, depthSurf;
    uint32_t boundW = 0, boundH = 0;  // pixels outside are skipped (asserted)
    TargetKind target = TargetKind::Argb8;
    DepthKind depthKind = DepthKind::D16;
};

// The plan of one call; `ok` false for a colour target of another format or a depth target of
// a non-depth format (the caller's programming error).
Plan makePlan(const MergeState& state, const MergeTarget& target, bool& ok);

}  // namespace emu
