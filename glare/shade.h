// One pixel shader over the half-pixel full-screen quad on images: what `ps11 shade` runs, and
// the building block of the fits report's fx8-against-ideal numbers.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "emu/device.h"
#include "emu/image_file.h"

namespace glare {

struct ShadeTexture {
    emu::FloatImage image;  // values as given; 8-bit textures round them (the ideal profile keeps floats)
    emu::D3DTEXTUREFILTERTYPE filter = emu::D3DTEXF_LINEAR;
};

struct ShadeRequest {
    std::string shaderText;                        // ps_1_x assembly
    std::vector<std::optional<ShadeTexture>> textures;  // stage i (null: nothing bound)
    std::vector<std::pair<int, std::array<float, 4>>> constants;
    uint32_t width = 0, height = 0;  // the output; 0 = texture 0's size
};

// Draws the shader once into a width x height target: A8R8G8B8, or A32B32G32R32F under the ideal
// profile (values are then not quantised; the merger still clamps to [0, 1]). Texture coordinate
// set i covers texture i edge to edge. nullopt with `error` naming the device call on failure.
std::optional<emu::FloatImage> shade(const emu::DeviceOptions& options, const ShadeRequest& request, std::string& error);

}  // namespace glare
