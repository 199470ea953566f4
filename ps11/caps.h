// The limits of the emulated Direct3D 9 device and its ps_1_x hardware, stated once: D3DCAPS9
// values of the era's parts and the project's own allocation bounds. The device, the sampler,
// the vertex stage and the .ps11test reader take their limits from here.
#pragma once

#include <cstdint>

namespace ps11 {

constexpr int kMaxTextureStages = 8;          // MaxTextureBlendStages; samplers 0-7 (D3DCAPS9)
constexpr int kMaxTexCoordSets = 8;           // D3DFVF_TEX8: texture coordinate sets of a vertex
constexpr uint32_t kMaxTextureSide = 16384;   // MaxTextureWidth / MaxTextureHeight
constexpr uint32_t kMaxVolumeSide = 2048;     // MaxVolumeExtent
// One resource's memory, checked before allocating: a device resource in D3D9's layout (all
// levels) and a ps11::Texture with its decoded copies.
constexpr uint64_t kMaxResourceBytes = uint64_t(1) << 30;

}  // namespace ps11
