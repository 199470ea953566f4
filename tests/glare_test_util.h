// Helpers of the glare tests (test_glare.cpp, test_glare_graph.cpp, test_glare_sprites.cpp): a
// uniform image, runner options of a size and profile, and a technique's preset.
#pragma once

#include <catch2/catch.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>

#include "emu/image_file.h"
#include "glare/runner.h"
#include "glare/technique.h"

namespace glaretest {

using namespace glare;

inline emu::FloatImage uniform(uint32_t w, uint32_t h, float r, float g, float b, float a = 1) {
    emu::FloatImage img{w, h, {}};
    for (size_t i = 0; i < size_t(w) * h; ++i) img.rgba.insert(img.rgba.end(), {r, g, b, a});
    return img;
}

inline RunnerOptions options(uint32_t w, uint32_t h, std::optional<ps11::Precision> p = std::nullopt) {
    RunnerOptions ro;
    ro.width = w;
    ro.height = h;
    ro.device.precision = p;
    return ro;
}

inline Settings preset(const char* technique, const char* name = "published") {
    return *presetSettings(*findTechnique(technique), name);
}

}  // namespace glaretest
