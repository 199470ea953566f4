// Helper of the texel-tile tests (test_intervals.cpp, test_tile_facts.cpp): a one-level texture
// read in place from 8-bit A8R8G8B8 bytes or A32B32G32R32F floats.
#pragma once

#include <catch2/catch.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ps11/texture.h"

namespace tiletest {

// A8R8G8B8 from `bytes` where `unorm8`, else A32B32G32R32F from `floats` (the other one unused);
// both must outlive the texture, which reads them in place.
inline ps11::Texture levelTexture(bool unorm8, uint32_t w, uint32_t h, const std::vector<uint8_t>& bytes,
                                  const std::vector<float>& floats) {
    ps11::TextureLevelBytes level;
    level.width = w, level.height = h;
    level.data = unorm8 ? bytes.data() : reinterpret_cast<const uint8_t*>(floats.data());
    level.rowPitch = size_t(w) * (unorm8 ? 4 : 16);
    std::string error;
    std::optional<ps11::Texture> t =
        ps11::Texture::fromLevels(unorm8 ? ps11::TexFormat::A8R8G8B8 : ps11::TexFormat::A32B32G32R32F, false, &level,
                                  1, ps11::SignedDecode::Snorm, error);
    INFO(error);
    REQUIRE(t);
    return std::move(*t);
}

}  // namespace tiletest
