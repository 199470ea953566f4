// Texture formats, filters and address modes as the runtime names them: the textures, the
// sampler, the device and the .ps11test model all use these (the model reads its words from
// here, not the other way round).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace ps11 {

// A name and the value it stands for (format names, and the .ps11test reader's word tables).
template <class E>
struct NameEntry {
    const char* name;
    E value;
};

// Texture formats (D3DFMT_* without the prefix) the textures and the sampler decode.
enum class TexFormat : uint8_t {
    A8R8G8B8,
    X8R8G8B8,
    A8,
    L8,
    A8L8,
    V8U8,
    L6V5U5,
    X8L8V8U8,
    Q8W8V8U8,
    V16U16,
    A16B16G16R16F,
    A32B32G32R32F,
    R32F,
};
// Every format with its name, in enum order.
extern const NameEntry<TexFormat> kTexFormatNames[13];
const char* texFormatName(TexFormat f);
std::optional<TexFormat> parseTexFormat(std::string_view name);  // case-insensitive
bool isFloatFormat(TexFormat f);
int formatBits(TexFormat f);  // bits per texel of a packed format (0 for float formats)

enum class Filter : uint8_t { None = 0, Point = 1, Linear = 2 };  // D3DTEXF_*
// D3DTADDRESS_* (values as in d3d9types.h).
enum class TextureAddress : uint8_t { Wrap = 1, Mirror = 2, Clamp = 3, Border = 4, MirrorOnce = 5 };

}  // namespace ps11
