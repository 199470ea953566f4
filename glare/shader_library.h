// The glare techniques' ps_1_1 shaders (glare/shaders/*.psh), compiled into the program as text
// by cmake/embed_shaders.cmake so the command line needs no source tree.
#pragma once

#include <string_view>
#include <vector>

namespace glare {

struct EmbeddedShader {
    std::string_view name;  // "adaptive_bright.psh"
    std::string_view text;
};

const std::vector<EmbeddedShader>& embeddedShaders();

}  // namespace glare
