// TEMPORARY (branch draw only, deleted when main has emu/ffp.cpp and emu/output_merger.cpp):
// a minimal output merger (plain store to 8-bit ARGB targets, no fog/alpha/depth/blend) and a
// fixed-function lowering that refuses, so the draw path links and can be tested alone.
#include <cmath>

#include "emu/ffp.h"
#include "emu/output_merger.h"

namespace emu {

std::optional<LoweredStages> lowerFixedFunction(const DeviceState&, std::string& error) {
    error = "E4110 fixed function arrives with the ffp branch";
    return std::nullopt;
}

MergeState MergeState::from(const DeviceState& state, bool, ps11::Precision precision) {
    MergeState m;
    m.colorWrite = state.renderState(D3DRS_COLORWRITEENABLE) & 0xf;
    m.precision = precision;
    return m;
}

bool MergeState::writesNothing() const { return colorWrite == 0; }

void mergePixels(const MergeState& state, const MergeInputs& in, const MergeTarget& target, MergeStats* stats) {
    if (!target.color) return;
    for (int i = 0; i < in.count; ++i) {
        if (in.live && !in.live[i]) continue;
        uint8_t* p = target.color->texel(uint32_t(in.x[i]), uint32_t(in.y[i]));
        uint8_t rgba[4];
        for (int c = 0; c < 4; ++c) {
            if (state.precision == ps11::Precision::Fx8 && in.grid[c]) {
                rgba[c] = uint8_t(std::clamp(in.grid[c][i], 0, 255));
            } else {
                const float v = std::clamp(in.color[c][i], 0.0f, 1.0f);
                rgba[c] = uint8_t(std::nearbyint(v * 255.0f));
            }
        }
        p[0] = rgba[2];
        p[1] = rgba[1];
        p[2] = rgba[0];
        p[3] = target.color->format->format == D3DFMT_X8R8G8B8 ? 0xff : rgba[3];
        if (stats) ++stats->written;
    }
}

}  // namespace emu
