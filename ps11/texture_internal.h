// Building a Texture texel by texel, level by level: what the .ps11test model's textureFromDesc
// (ps11/testfile_textures.cpp) hands its texels over with. Not part of the public API (not
// installed): Texture::fromLevels is the public way in.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ps11/texture.h"

namespace ps11 {

class TextureBuilder {
public:
    // Checks the extents (kMaxTextureSide per side, kMaxVolumeSide deep; `depth` counts only for
    // a volume) and lays out `count` levels of `fmt` (0 = the full chain, down to 1x1x1); false
    // with `error` set when they are beyond the limits or past kMaxResourceBytes.
    bool start(TexFormat fmt, bool volume, uint32_t width, uint32_t height, uint32_t depth, uint32_t count,
               std::string& error);
    uint32_t levelCount() const;
    const TextureLevelInfo& level(uint32_t k) const;
    // Stores texel `index` (level offset + texel) from a word in the format's natural packing
    // (Unorm8 and signed formats; docs/test-format.md). Ignored for float formats.
    void storeWord(size_t index, uint32_t word);
    // Stores texel `index` of a float format from channel values r g b a: the channels the format
    // has, half-rounded where it stores halves; the others 1 (Zero channels 0). Ignored otherwise.
    void storeFloats(size_t index, const std::array<float, 4>& value);
    // Level k (>= 1) as the 2x2 (2x2x2) box filter of level k - 1, rounded half-even in the
    // stored form (docs/textures.md).
    void generateLevel(uint32_t k);
    // The texture, its signed channels decoded by `decode` (the hardware class's rule). Once.
    Texture finish(SignedDecode decode);

private:
    Texture m_texture;
    const FormatRow* m_row = nullptr;
    TexelStorage m_storage = TexelStorage::Unorm8;
    bool m_floats = false, m_half = false;
    std::vector<int32_t> m_raw;  // signed formats while building
    std::vector<float> m_rawf;   // float formats while building
};

}  // namespace ps11
