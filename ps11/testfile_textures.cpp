// The .ps11test model's textures and samplers handed to the library: [texture N] sections
// checked (sizes, levels, texel kinds) and built with ps11::TextureBuilder, [sampler N] sections
// as sampler state.
#include "ps11/testfile_textures.h"

#include <vector>

#include "ps11/texture_internal.h"

namespace ps11 {

std::optional<Texture> textureFromDesc(const TextureDesc& desc, SignedDecode decode, std::string& error) {
    const TexFormat fmt = desc.format.value;
    const bool volume = desc.isVolume();
    TextureBuilder b;
    if (!b.start(fmt, volume, desc.width, desc.height, desc.depth, desc.levels.value, error)) return std::nullopt;
    const uint32_t count = b.levelCount();

    // Which levels the description gives; the others (levels 0) are generated.
    std::vector<const TextureLevel*> given(count, nullptr);
    for (const TextureLevel& l : desc.data) {
        if (l.level >= count) {
            error = "data for level " + std::to_string(l.level) + " beyond the texture's " + std::to_string(count) +
                    " levels";
            return std::nullopt;
        }
        const TextureLevelInfo& li = b.level(l.level);
        size_t n = size_t(li.width) * li.height * li.depth;
        if (!l.hasFill && l.texels.size() != n) {
            error = "level " + std::to_string(l.level) + " has " + std::to_string(l.texels.size()) +
                    " texels, expected " + std::to_string(n);
            return std::nullopt;
        }
        given[l.level] = &l;
    }
    if (!given[0]) {
        error = "texture has no data for level 0";
        return std::nullopt;
    }
    if (desc.levels.value != 0)
        for (uint32_t k = 1; k < count; ++k)
            if (!given[k]) {
                error = "texture has no data for level " + std::to_string(k);
                return std::nullopt;
            }

    const bool floats = isFloatFormat(fmt);
    const int bits = formatBits(fmt);
    auto checkTexel = [&](const Texel& x) {
        if (floats != (x.count > 0)) {
            error = std::string("format ") + texFormatName(fmt) +
                    (floats ? " takes float texels" : " takes packed texel words, not floats");
            return false;
        }
        if (!floats && bits < 32 && (x.bits >> bits) != 0) {
            error = "texel word " + std::to_string(x.bits) + " does not fit format " + texFormatName(fmt);
            return false;
        }
        return true;
    };
    auto store = [&](size_t index, const Texel& x) {
        if (floats)
            b.storeFloats(index, x.value);
        else
            b.storeWord(index, x.bits);
    };

    for (uint32_t k = 0; k < count; ++k) {
        if (!given[k]) {
            b.generateLevel(k);
            continue;
        }
        const TextureLevelInfo& li = b.level(k);
        const size_t n = size_t(li.width) * li.height * li.depth;
        const TextureLevel& l = *given[k];
        if (l.hasFill) {
            if (!checkTexel(l.fill)) return std::nullopt;
            for (size_t i = 0; i < n; ++i) store(li.offset + i, l.fill);
        } else {
            for (size_t i = 0; i < n; ++i) {
                if (!checkTexel(l.texels[i])) return std::nullopt;
                store(li.offset + i, l.texels[i]);
            }
        }
    }
    return b.finish(decode);
}

SamplerState samplerStateFromDesc(const SamplerDesc& desc) {
    SamplerState s;
    s.minFilter = desc.minFilter.value;
    s.magFilter = desc.magFilter.value;
    s.mipFilter = desc.mipFilter.value;
    s.addressU = desc.addressU.value;
    s.addressV = desc.addressV.value;
    s.addressW = desc.addressW.value;
    s.border = desc.border.value.rgba;
    return s;
}

}  // namespace ps11
