// Texture formats: their names and packed sizes (ps11/formats.h).
#include "ps11/formats.h"

#include <cctype>

namespace ps11 {

const NameEntry<TexFormat> kTexFormatNames[13] = {
    {"A8R8G8B8", TexFormat::A8R8G8B8},
    {"X8R8G8B8", TexFormat::X8R8G8B8},
    {"A8", TexFormat::A8},
    {"L8", TexFormat::L8},
    {"A8L8", TexFormat::A8L8},
    {"V8U8", TexFormat::V8U8},
    {"L6V5U5", TexFormat::L6V5U5},
    {"X8L8V8U8", TexFormat::X8L8V8U8},
    {"Q8W8V8U8", TexFormat::Q8W8V8U8},
    {"V16U16", TexFormat::V16U16},
    {"A16B16G16R16F", TexFormat::A16B16G16R16F},
    {"A32B32G32R32F", TexFormat::A32B32G32R32F},
    {"R32F", TexFormat::R32F},
};

const char* texFormatName(TexFormat f) {
    for (const auto& e : kTexFormatNames)
        if (e.value == f) return e.name;
    return "?";
}

std::optional<TexFormat> parseTexFormat(std::string_view name) {
    for (const auto& e : kTexFormatNames) {
        std::string_view n = e.name;
        if (n.size() != name.size()) continue;
        bool same = true;
        for (size_t i = 0; i < n.size() && same; ++i)
            same = std::tolower(static_cast<unsigned char>(n[i])) == std::tolower(static_cast<unsigned char>(name[i]));
        if (same) return e.value;
    }
    return std::nullopt;
}

bool isFloatFormat(TexFormat f) {
    return f == TexFormat::A16B16G16R16F || f == TexFormat::A32B32G32R32F || f == TexFormat::R32F;
}

int formatBits(TexFormat f) {
    switch (f) {
        case TexFormat::A8:
        case TexFormat::L8:
            return 8;
        case TexFormat::A8L8:
        case TexFormat::V8U8:
        case TexFormat::L6V5U5:
            return 16;
        case TexFormat::A16B16G16R16F:
        case TexFormat::A32B32G32R32F:
        case TexFormat::R32F:
            return 0;
        default:
            return 32;
    }
}

}  // namespace ps11
