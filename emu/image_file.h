// Image files on disk (docs/images.md): PNG through libpng, read into and written from 8-bit RGBA;
// Radiance .hdr through stb_image and OpenEXR through the OpenEXR library, read into linear float
// RGBA; readImage for any of the three by content; the exposure mapping of linear images onto 8 bits.
// Errors are returned as "PATH: what went wrong", never thrown or printed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ps11/caps.h"

namespace emu {

// An 8-bit image: r g b a per pixel, rows top to bottom, no padding (rgba.size() == width * height * 4).
struct RgbaImage {
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgba;
};

// Every pixel's alpha set to 255 (frames written as opaque pictures); `opaque` on a copy.
inline void makeOpaque(RgbaImage& image) {
    for (size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = 255;
}
inline RgbaImage opaque(RgbaImage image) {
    makeOpaque(image);
    return image;
}

// The largest image read or written: a side, and the bytes of its RGBA8 pixels, those of the
// largest texture it can become (ps11/caps.h). Checked against a file's header before any pixel
// memory is allocated. 16384 a side is exactly 1 GiB of RGBA8, so the byte limit binds only if the
// side limit is raised.
inline constexpr uint32_t kMaxImageSide = ps11::kMaxTextureSide;
inline constexpr uint64_t kMaxImageBytes = ps11::kMaxResourceBytes;
// kMaxImageBytes as the error messages name it ("1 GiB").
std::string maxImageBytesText();
// A float image counts its float RGBA pixels (16 bytes each) against kMaxImageBytes: at most 2^26
// pixels (8192x8192), besides kMaxImageSide a side. Checked against a file's header before any pixel
// memory is allocated, like the limits above.
inline constexpr uint64_t kFloatPixelBytes = 16;

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

// A linear float image: r g b a per pixel, rows top to bottom (rgba.size() == width*height*4).
struct FloatImage {
    uint32_t width = 0, height = 0;
    std::vector<float> rgba;
};

// Reads a Radiance RGBE file ("#?RADIANCE" or "#?RGBE", FORMAT=32-bit_rle_rgbe, "-Y H +X W", flat or
// run-length encoded scanlines) through stb_image: r g b as stored (linear), a = 1. nullopt with
// `error` = "PATH: what is wrong" for a missing file, not-a-Radiance-file, a header stb_image does not
// take (other FORMATs, orientations), truncated or corrupt pixels, or a size past the float limits.
std::optional<FloatImage> readHdr(const std::string& path, std::string& error);

// readHdr from memory (what fuzz/fuzz_hdr drives); `name` stands for the path in messages.
std::optional<FloatImage> readHdrMemory(const uint8_t* data, size_t size, const std::string& name, std::string& error);

// Reads a single-part flat OpenEXR image, scanline or tiled (level 0 of a mip/rip map), in any
// compression OpenEXR 3.1 has (NONE, RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A, DWAA, DWAB) and half, float
// or uint channels, through the OpenEXR library: R G B (and A), or Y as grey (r = g = b = Y); a = 1 where
// there is no A. The data window is the image (its top-left corner is pixel (0, 0)); negative values
// become 0. nullopt with `error` = "PATH: what is wrong" for a missing file, not-an-EXR, truncated or
// corrupt data (with OpenEXR's message), unsupported files (multi-part, deep, no R G B or Y channels,
// luminance/chroma, subsampled channels), a size past the float limits, or a NaN or infinite pixel.
std::optional<FloatImage> readExr(const std::string& path, std::string& error);

// readExr from memory (what fuzz/fuzz_exr drives); `name` stands for the path in messages.
std::optional<FloatImage> readExrMemory(const uint8_t* data, size_t size, const std::string& name, std::string& error);

// Any supported file by its content (PNG signature, "#?RADIANCE"/"#?RGBE", EXR magic 76 2f 31 01), not its
// extension. PNG samples become v/255 (not linearised; `hdr` false); .hdr/.exr are linear (`hdr` true).
// The errors are those of the reader, or "PATH: not a PNG, Radiance HDR or OpenEXR image (it starts with
// ...)"; a PNG past the float limits is refused after reading it.
struct LoadedImage {
    FloatImage image;
    bool hdr = false;
};
std::optional<LoadedImage> readImage(const std::string& path, std::string& error);

// Exposure mapping of a linear HDR image onto an 8-bit back buffer (docs/images.md "Exposure"):
// v' = v * 2^stops, then the sRGB transfer function (IEC 61966-2-1) per colour channel, alpha unchanged:
// 12.92 v' for v' <= 0.0031308, else 1.055 v'^(1/2.4) - 0.055. exposeUnclamped keeps values above 1 (for
// the `ideal` profile's float textures); a NaN stays NaN.
FloatImage exposeUnclamped(const FloatImage& linear, float stops);

// Each value clamped to [0, 1] (NaN as 0) and rounded to nearest to 8 bits: round(v * 255).
RgbaImage toRgba8(const FloatImage& image);

}  // namespace emu
