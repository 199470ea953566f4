// Image files on disk: PNG through libpng, read into and written from 8-bit RGBA
// (docs/images.md). Errors are returned as "PATH: what went wrong", never thrown or printed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace emu {

// An 8-bit image: r g b a per pixel, rows top to bottom, no padding (rgba.size() == width * height * 4).
struct RgbaImage {
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgba;
};

// The largest image read or written: a side, and the bytes of its RGBA8 pixels. Checked against a
// file's header before any pixel memory is allocated. 16384 a side is exactly 1 GiB of RGBA8, so the
// byte limit binds only if the side limit is raised.
inline constexpr uint32_t kMaxImageSide = 16384;
inline constexpr uint64_t kMaxImageBytes = uint64_t(1) << 30;

// Writes an 8-bit RGBA PNG (no interlace). False with `error` = "PATH: what went wrong" (cannot create, disk full,
// an image whose size or buffer is wrong); a file left half written is removed.
bool writePng(const std::string& path, const RgbaImage& image, std::string& error);

// Reads any PNG libpng reads (palette, grey, grey+alpha, RGB, RGBA, 1/2/4/16-bit, interlaced, tRNS) into RGBA8:
// 16-bit samples scaled to 8 with rounding, tRNS as alpha, alpha 255 where the file has none; sample values as
// stored (no gamma or colour-space conversion). nullopt with `error` = "PATH: what is wrong" for a missing file,
// not-a-PNG, truncated or corrupt data (with libpng's message), or a size past the limits above.
std::optional<RgbaImage> readPng(const std::string& path, std::string& error);

// readPng from memory (what the fuzzer drives); `name` stands for the path in messages.
std::optional<RgbaImage> readPngMemory(const uint8_t* data, size_t size, const std::string& name, std::string& error);

}  // namespace emu
