// Unit tests of the linear image files (emu/image_file.h): Radiance .hdr files written here with
// stb_image_write and by hand, OpenEXR files written here with OpenEXR itself (scanline and tiled,
// NONE/RLE/ZIPS/ZIP/PIZ/DWAB, half and float, RGB/RGBA/Y), read back to the values the formats define;
// every refusal with its exact message; readImage by content; the exposure mapping's numbers.
#include <catch2/catch.hpp>

#include <Imath/half.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <ImfTileDescription.h>
#include <ImfTiledInputFile.h>
#include <ImfTiledOutputFile.h>
#include <stb/stb_image_write.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "emu/image_file.h"
#include "tests/temp_files.h"

using namespace emu;
namespace fs = std::filesystem;

namespace {

using test_files::slurp;
using test_files::spit;
struct TempDir : test_files::TempDir {
    TempDir() : test_files::TempDir("ps11_hdr_test_") {}
};

std::vector<uint8_t> bytesOf(const std::string& text) { return {text.begin(), text.end()}; }

const std::string kHdrHeader = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n";

// ---- OpenEXR files written with OpenEXR -------------------------------------------------------------

struct ExrSpec {
    int width = 4, height = 3;
    Imath::V2i origin{0, 0};
    std::vector<std::string> channels{"R", "G", "B", "A"};
    Imf::PixelType type = Imf::HALF;
    Imf::Compression compression = Imf::NO_COMPRESSION;
    bool tiled = false;
    int tileW = 16, tileH = 8;
    Imf::LevelMode levels = Imf::ONE_LEVEL;  // tiled: MIPMAP_LEVELS and RIPMAP_LEVELS write every level
    Imf::LevelRoundingMode rounding = Imf::ROUND_DOWN;
    bool pixels = true;               // false: the header (and offset table) only
    std::vector<std::vector<float>> values;  // per channel, width * height, rows top to bottom
};

void writeExr(const std::string& path, const ExrSpec& spec) {
    const Imath::Box2i window(spec.origin, spec.origin + Imath::V2i(spec.width - 1, spec.height - 1));
    Imf::Header header(spec.width, spec.height);
    header.dataWindow() = window;
    header.displayWindow() = window;
    header.compression() = spec.compression;
    for (const auto& c : spec.channels) header.channels().insert(c, Imf::Channel(spec.type));
    if (spec.tiled) header.setTileDescription(Imf::TileDescription(spec.tileW, spec.tileH, spec.levels, spec.rounding));
    std::vector<std::vector<half>> halves(spec.channels.size());
    std::vector<std::vector<float>> floats(spec.channels.size());
    Imf::FrameBuffer buffer;
    for (size_t c = 0; c < spec.channels.size() && spec.pixels; ++c) {
        if (spec.type == Imf::HALF) {
            for (float v : spec.values[c]) halves[c].push_back(half(v));
            buffer.insert(spec.channels[c], Imf::Slice::Make(Imf::HALF, halves[c].data(), window, sizeof(half)));
        } else {
            floats[c] = spec.values[c];
            buffer.insert(spec.channels[c], Imf::Slice::Make(Imf::FLOAT, floats[c].data(), window, sizeof(float)));
        }
    }
    if (spec.tiled) {
        Imf::TiledOutputFile out(path.c_str(), header);
        if (!spec.pixels) return;
        out.setFrameBuffer(buffer);
        // Each level's tiles from the level-0 buffer (a smaller level's pixels are its top-left corner).
        for (int ly = 0; ly < out.numYLevels(); ++ly)
            for (int lx = 0; lx < out.numXLevels(); ++lx)
                if (spec.levels == Imf::RIPMAP_LEVELS || lx == ly)
                    out.writeTiles(0, out.numXTiles(lx) - 1, 0, out.numYTiles(ly) - 1, lx, ly);
    } else {
        Imf::OutputFile out(path.c_str(), header);
        if (!spec.pixels) return;
        out.setFrameBuffer(buffer);
        out.writePixels(spec.height);
    }
}

// Random values that half holds exactly: k / 64 for k in [-64, 640] (negative ones read as 0).
ExrSpec randomSpec(int width, int height, std::vector<std::string> channels, uint32_t seed) {
    std::mt19937 rng(seed);
    ExrSpec spec;
    spec.width = width;
    spec.height = height;
    spec.channels = std::move(channels);
    for (size_t c = 0; c < spec.channels.size(); ++c) {
        spec.values.emplace_back();
        for (int i = 0; i < width * height; ++i) spec.values.back().push_back(float(int(rng() % 705) - 64) / 64.0f);
    }
    return spec;
}

// What readExr gives for `spec`: R G B (or Y three times) and A (1 where there is none), negatives 0.
std::vector<float> expectedRgba(const ExrSpec& spec) {
    const auto channel = [&](const std::string& name) -> const std::vector<float>* {
        for (size_t c = 0; c < spec.channels.size(); ++c)
            if (spec.channels[c] == name) return &spec.values[c];
        return nullptr;
    };
    const bool grey = channel("R") == nullptr;
    const std::vector<float>* sources[4] = {channel(grey ? "Y" : "R"), channel(grey ? "Y" : "G"),
                                            channel(grey ? "Y" : "B"), channel("A")};
    std::vector<float> rgba;
    for (int i = 0; i < spec.width * spec.height; ++i)
        for (int c = 0; c < 4; ++c) rgba.push_back(sources[c] ? std::max(0.0f, (*sources[c])[size_t(i)]) : 1.0f);
    return rgba;
}

std::string exrName(Imf::Compression c) {
    switch (c) {
    case Imf::NO_COMPRESSION: return "NONE";
    case Imf::RLE_COMPRESSION: return "RLE";
    case Imf::ZIPS_COMPRESSION: return "ZIPS";
    case Imf::ZIP_COMPRESSION: return "ZIP";
    case Imf::PIZ_COMPRESSION: return "PIZ";
    case Imf::DWAB_COMPRESSION: return "DWAB";
    default: return "other";
    }
}

// The header only of a scanline EXR with the given data window (no pixels written).
std::string exrHeaderOnly(const TempDir& dir, const std::string& name, int width, int height,
                          Imf::Compression compression = Imf::ZIP_COMPRESSION) {
    ExrSpec spec;
    spec.width = width;
    spec.height = height;
    spec.compression = compression;
    spec.pixels = false;
    const std::string path = dir.file(name);
    writeExr(path, spec);
    return path;
}

}  // namespace

// ---- Radiance .hdr ----------------------------------------------------------------------------------

TEST_CASE("hdr: RGBE pixels read back exactly, flat and run-length encoded", "[image][hdr]") {
    TempDir dir;
    // Mantissas k with the largest of a pixel in [128, 255] and an exponent E: each component is exactly
    // k * 2^(E - 8), which RGBE holds without loss (Ward's format: mantissa byte * 2^(exponent - 136)).
    for (int width : {5, 40}) {  // stb_image_write writes scanlines of fewer than 8 pixels flat
        const int height = 3;
        std::mt19937 rng{uint32_t(width)};
        std::vector<float> rgb, expected;
        for (int i = 0; i < width * height; ++i) {
            const int e = int(rng() % 21) - 10;
            const int top = 128 + int(rng() % 128);
            int k[3] = {int(rng() % 256), int(rng() % 256), int(rng() % 256)};
            k[rng() % 3] = top;
            for (int c = 0; c < 3; ++c) k[c] = std::min(k[c], top);
            for (int c = 0; c < 3; ++c) rgb.push_back(std::ldexp(float(k[c]), e - 8));
            for (int c = 0; c < 3; ++c) expected.push_back(std::ldexp(float(k[c]), e - 8));
            expected.push_back(1.0f);
        }
        const std::string path = dir.file("w" + std::to_string(width) + ".hdr");
        REQUIRE(stbi_write_hdr(path.c_str(), width, height, 3, rgb.data()) == 1);
        std::string error;
        const auto image = readHdr(path, error);
        INFO(error);
        REQUIRE(image);
        CHECK(image->width == uint32_t(width));
        CHECK(image->height == uint32_t(height));
        CHECK(image->rgba == expected);
        const auto bytes = slurp(path);
        const auto again = readHdrMemory(bytes.data(), bytes.size(), "mem", error);
        REQUIRE(again);
        CHECK(again->rgba == expected);
    }
}

TEST_CASE("hdr: a hand-written file reads as RGBE defines it", "[image][hdr]") {
    TempDir dir;
    // Two flat pixels: (128, 64, 32) * 2^(129-136) and black; rows top to bottom with "-Y 2 +X 1".
    auto bytes = bytesOf("#?RGBE\n# a comment\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1\n\n-Y 2 +X 1\n");
    bytes.insert(bytes.end(), {128, 64, 32, 129, 0, 0, 0, 0});
    const std::string path = dir.file("tiny.hdr");
    spit(path, bytes);
    std::string error;
    const auto image = readHdr(path, error);
    INFO(error);
    REQUIRE(image);
    CHECK(image->width == 1);
    CHECK(image->height == 2);
    CHECK(image->rgba == std::vector<float>{1.0f, 0.5f, 0.25f, 1.0f, 0, 0, 0, 1.0f});
}

TEST_CASE("hdr: a file cut at any byte is refused as truncated", "[image][hdr]") {
    TempDir dir;
    std::vector<float> rgb(16 * 4 * 3);
    for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = float(i % 7) * 0.25f;
    for (int width : {2, 16}) {
        const std::string path = dir.file("cut.hdr");
        REQUIRE(stbi_write_hdr(path.c_str(), width, 4, 3, rgb.data()) == 1);
        const auto bytes = slurp(path);
        std::string error;
        REQUIRE(readHdrMemory(bytes.data(), bytes.size(), "whole", error));
        for (size_t n = 1; n < bytes.size(); ++n) {
            INFO("width " << width << ", cut at " << n);
            const auto image = readHdrMemory(bytes.data(), n, "cut", error);
            CHECK_FALSE(image);
            CHECK(error.rfind("cut: truncated Radiance HDR: ", 0) == 0);
        }
    }
}

TEST_CASE("hdr: what is not a readable Radiance file is refused with what is wrong", "[image][hdr]") {
    TempDir dir;
    std::string error;
    const auto refuse = [&](const std::vector<uint8_t>& bytes) {
        const std::string path = dir.file("bad.hdr");
        spit(path, bytes);
        CHECK_FALSE(readHdr(path, error));
        return error.substr(path.size());
    };
    CHECK_FALSE(readHdr(dir.file("missing.hdr"), error));
    CHECK(error == dir.file("missing.hdr") + ": cannot open: No such file or directory");
    CHECK_FALSE(readHdr(dir.path.string(), error));
    CHECK(error == dir.path.string() + ": cannot read: Is a directory");
    CHECK(refuse({}) == ": empty file, not a Radiance HDR image");
    CHECK(refuse(bytesOf("GIF89a\x01")) ==
          ": not a Radiance HDR file (it starts with 47 49 46 38 39 61 01; one starts with \"#?RADIANCE\" or "
          "\"#?RGBE\" and a newline)");
    CHECK(refuse(bytesOf("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n")) ==
          ": truncated Radiance HDR: the data ends in the header, after 34 bytes (the header ends with an empty line)");
    CHECK(refuse(bytesOf(kHdrHeader + "-Y 2 +X")) ==
          ": truncated Radiance HDR: the data ends in the resolution line, after 42 bytes");
    CHECK(refuse(bytesOf("#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\x80\x80\x80\x80")) ==
          ": unsupported Radiance HDR format \"32-bit_rle_xyze\"; only 32-bit_rle_rgbe is read");
    CHECK(refuse(bytesOf("#?RADIANCE\n\n-Y 1 +X 1\n\x80\x80\x80\x80")) ==
          ": corrupt Radiance HDR: the header has no FORMAT=32-bit_rle_rgbe line");
    CHECK(refuse(bytesOf(kHdrHeader + "+Y 1 +X 1\n\x80\x80\x80\x80")) ==
          ": unsupported or corrupt Radiance HDR resolution line \"+Y 1 +X 1\"; only \"-Y H +X W\" (rows top to "
          "bottom, left to right) is read");
    CHECK(refuse(bytesOf(kHdrHeader + "-Y 0 +X 5\n")) == ": corrupt Radiance HDR: the header gives a 5x0 image");
    CHECK(refuse(bytesOf(kHdrHeader + "-Y 1 +X 16385\n")) ==
          ": the image is 16385x1 and a side is larger than 16384 pixels; refused before reading its pixels");
    CHECK(refuse(bytesOf(kHdrHeader + "-Y 8193 +X 8192\n")) ==
          ": the image is 8192x8193 and its float RGBA pixels take more than 1 GiB; refused before reading its pixels");
    CHECK(refuse(bytesOf(kHdrHeader + "-Y 100 +X 4\n\x80\x80\x80\x80")) ==
          ": truncated Radiance HDR: a 4x100 image needs at least 1600 bytes of flat pixels but only 4 bytes follow "
          "its header");
    // A run-length scanline of 300 pixels takes at least 4 + 4 components * 3 runs * 2 bytes.
    CHECK(refuse(bytesOf(kHdrHeader + "-Y 10 +X 300\n\x02\x02\x01\x2c")) ==
          ": truncated Radiance HDR: a 300x10 image needs at least 280 bytes of run-length encoded pixels but only "
          "4 bytes follow its header");
    // A scanline whose length is not the image's, and a run longer than the scanline.
    std::vector<uint8_t> wrongLength = bytesOf(kHdrHeader + "-Y 1 +X 8\n");
    wrongLength.insert(wrongLength.end(), {2, 2, 0, 9});
    wrongLength.resize(wrongLength.size() + 40, 0x81);
    CHECK(refuse(wrongLength) == ": corrupt Radiance HDR: stb_image: invalid decoded scanline length");
    std::vector<uint8_t> longRun = bytesOf(kHdrHeader + "-Y 1 +X 8\n");
    longRun.insert(longRun.end(), {2, 2, 0, 8, 0x89, 1});
    longRun.resize(longRun.size() + 40, 0x81);
    CHECK(refuse(longRun) == ": corrupt Radiance HDR: stb_image: bad run-length data (corrupt)");
}

// ---- OpenEXR ----------------------------------------------------------------------------------------

TEST_CASE("exr: lossless compressions read back exactly, scanline and tiled, half and float", "[image][exr]") {
    TempDir dir;
    uint32_t seed = 1;
    for (Imf::Compression compression : {Imf::NO_COMPRESSION, Imf::RLE_COMPRESSION, Imf::ZIPS_COMPRESSION,
                                         Imf::ZIP_COMPRESSION, Imf::PIZ_COMPRESSION})
        for (Imf::PixelType type : {Imf::HALF, Imf::FLOAT})
            for (bool tiled : {false, true})
                for (const auto& channels : std::vector<std::vector<std::string>>{{"R", "G", "B", "A"},
                                                                                  {"B", "G", "R"},
                                                                                  {"Y"},
                                                                                  {"A", "Y", "Z"}}) {
                    ExrSpec spec = randomSpec(37, 23, channels, seed++);
                    spec.compression = compression;
                    spec.type = type;
                    spec.tiled = tiled;
                    spec.origin = Imath::V2i(5, -3);
                    const std::string path = dir.file("lossless.exr");
                    writeExr(path, spec);
                    INFO(exrName(compression) << (type == Imf::HALF ? " half " : " float ")
                                              << (tiled ? "tiled " : "scanline ") << channels.size() << " channels");
                    std::string error;
                    const auto image = readExr(path, error);
                    INFO(error);
                    REQUIRE(image);
                    CHECK(image->width == 37);
                    CHECK(image->height == 23);
                    CHECK(image->rgba == expectedRgba(spec));
                    const auto bytes = slurp(path);
                    const auto again = readExrMemory(bytes.data(), bytes.size(), "mem", error);
                    REQUIRE(again);
                    CHECK(again->rgba == image->rgba);
                }
}

TEST_CASE("exr: DWAB reads back within its loss", "[image][exr]") {
    TempDir dir;
    for (Imf::PixelType type : {Imf::HALF, Imf::FLOAT})
        for (bool tiled : {false, true}) {
            ExrSpec spec;
            spec.width = 61;
            spec.height = 300;  // more than one 256-row DWAB block
            spec.channels = {"R", "G", "B"};
            spec.compression = Imf::DWAB_COMPRESSION;
            spec.type = type;
            spec.tiled = tiled;
            spec.tileW = 32;
            spec.tileH = 32;
            for (int c = 0; c < 3; ++c) {
                spec.values.emplace_back();
                for (int y = 0; y < spec.height; ++y)
                    for (int x = 0; x < spec.width; ++x)
                        spec.values.back().push_back(0.1f + 2.0f * float(x + y + 20 * c) / float(spec.width + spec.height));
            }
            const std::string path = dir.file("dwab.exr");
            writeExr(path, spec);
            std::string error;
            const auto image = readExr(path, error);
            INFO(error);
            REQUIRE(image);
            const auto expected = expectedRgba(spec);
            REQUIRE(image->rgba.size() == expected.size());
            float worst = 0;
            for (size_t i = 0; i < expected.size(); ++i)
                worst = std::max(worst, std::abs(image->rgba[i] - expected[i]) / std::max(1.0f, expected[i]));
            CHECK(worst < 0.02f);
        }
}

TEST_CASE("exr: a file cut at any byte is refused", "[image][exr]") {
    TempDir dir;
    for (bool tiled : {false, true}) {
        ExrSpec spec = randomSpec(9, 7, {"R", "G", "B"}, 7);
        spec.compression = Imf::ZIP_COMPRESSION;
        spec.tiled = tiled;
        spec.tileW = spec.tileH = 4;
        const std::string path = dir.file("cut.exr");
        writeExr(path, spec);
        const auto bytes = slurp(path);
        std::string error;
        REQUIRE(readExrMemory(bytes.data(), bytes.size(), "whole", error));
        for (size_t n = 1; n < bytes.size(); ++n) {
            INFO((tiled ? "tiled" : "scanline") << ", cut at " << n);
            CHECK_FALSE(readExrMemory(bytes.data(), n, "cut", error));
            INFO(error);
            CHECK((error.rfind("cut: truncated EXR: ", 0) == 0 || error.rfind("cut: corrupt EXR: OpenEXR: ", 0) == 0));
            CHECK(error.find('\n') == std::string::npos);
        }
        // Cut in the last chunk: the data ends where OpenEXR wants more.
        CHECK_FALSE(readExrMemory(bytes.data(), bytes.size() - 1, "cut", error));
        CHECK(error.rfind("cut: truncated EXR: the data ends after " + std::to_string(bytes.size() - 1) + " bytes (OpenEXR: ", 0) == 0);
    }
}

TEST_CASE("exr: every byte flipped in turn never crashes", "[image][exr]") {
    TempDir dir;
    ExrSpec spec = randomSpec(6, 5, {"R", "G", "B", "A"}, 3);
    spec.compression = Imf::PIZ_COMPRESSION;
    spec.type = Imf::FLOAT;
    const std::string path = dir.file("flip.exr");
    writeExr(path, spec);
    const auto bytes = slurp(path);
    for (size_t i = 0; i < bytes.size(); ++i) {
        auto flipped = bytes;
        flipped[i] ^= 0xa5;
        std::string error;
        const auto image = readExrMemory(flipped.data(), flipped.size(), "flip", error);
        INFO("byte " << i << ": " << error);
        if (!image) {
            CHECK(error.rfind("flip: ", 0) == 0);
            continue;
        }
        CHECK(image->rgba.size() == size_t(image->width) * image->height * 4);
        for (float v : image->rgba) CHECK((std::isfinite(v) && v >= 0));
    }
}

TEST_CASE("exr: what is not a readable EXR is refused with what is wrong", "[image][exr]") {
    TempDir dir;
    std::string error;
    const auto message = [&](const std::string& path) {
        CHECK_FALSE(readExr(path, error));
        return error.substr(std::min(error.size(), path.size()));
    };
    const auto refuse = [&](const std::vector<uint8_t>& bytes) {
        const std::string path = dir.file("bad.exr");
        spit(path, bytes);
        return message(path);
    };
    CHECK(message(dir.file("missing.exr")) == ": cannot open: No such file or directory");
    CHECK(message(dir.path.string()) == ": cannot read: Is a directory");
    CHECK(refuse({}) == ": empty file, not an OpenEXR image");
    CHECK(refuse({0x89, 'P', 'N', 'G', 13, 10, 26, 10, 0}) ==
          ": not an OpenEXR file (it starts with 89 50 4e 47 0d 0a 1a 0a; an OpenEXR file starts with 76 2f 31 01)");
    CHECK(refuse({0x76, 0x2f, 0x31, 0x01, 2}) == ": truncated EXR: the data ends after 5 bytes");

    const std::string good = dir.file("good.exr");
    ExrSpec spec = randomSpec(4, 3, {"R", "G", "B"}, 5);
    writeExr(good, spec);
    auto bytes = slurp(good);
    auto changed = bytes;
    changed[4] = 3;
    CHECK(refuse(changed) == ": unsupported EXR version 3 (OpenEXR files are version 2)");
    changed = bytes;
    changed[5] |= 0x08;
    CHECK(refuse(changed) ==
          ": unsupported EXR: deep data (a varying number of samples per pixel); only flat images are read");
    changed = bytes;
    changed[5] |= 0x40;
    CHECK(refuse(changed) == ": unsupported EXR: unknown feature flags in its version field (02 40 00 00)");
    changed = bytes;
    for (size_t i = 8; i < 40; ++i) changed[i] = 0xee;
    CHECK(refuse(changed).rfind(": corrupt EXR: OpenEXR: ", 0) == 0);

    {
        Imf::Header headers[2] = {Imf::Header(4, 4), Imf::Header(4, 4)};
        for (int i = 0; i < 2; ++i) {
            headers[i].setName(i ? "b" : "a");
            headers[i].setType(Imf::SCANLINEIMAGE);
            headers[i].channels().insert("R", Imf::Channel(Imf::HALF));
        }
        Imf::MultiPartOutputFile multi(dir.file("multi.exr").c_str(), headers, 2);
    }
    CHECK(message(dir.file("multi.exr")) == ": unsupported EXR: a multi-part file; only single-part images are read");

    const auto withChannels = [&](std::vector<std::string> channels) {
        ExrSpec s = randomSpec(4, 3, std::move(channels), 9);
        const std::string path = dir.file("channels.exr");
        writeExr(path, s);
        return message(path);
    };
    CHECK(withChannels({"Z", "depth.Z"}) == ": unsupported EXR: no R, G, B or Y channel (its channels: Z, depth.Z)");
    CHECK(withChannels({"R", "G", "A"}) ==
          ": unsupported EXR: it has channel R, G but not B (an RGB image needs R, G and B)");
    CHECK(withChannels({"Y", "RY", "BY"}) ==
          ": unsupported EXR: a luminance/chroma image (channels RY, BY); only RGB and Y images are read");
    {
        Imf::Header header(4, 4);
        header.channels().insert("Y", Imf::Channel(Imf::HALF, 2, 2));
        Imf::OutputFile out(dir.file("sub.exr").c_str(), header);
    }
    CHECK(message(dir.file("sub.exr")) ==
          ": unsupported EXR: channel Y is subsampled (2x2); only full-resolution channels are read");

    CHECK(message(exrHeaderOnly(dir, "wide.exr", 16385, 1)) ==
          ": the image is 16385x1 and a side is larger than 16384 pixels; refused before reading its pixels");
    CHECK(message(exrHeaderOnly(dir, "big.exr", 8192, 8193)) ==
          ": the image is 8192x8193 and its float RGBA pixels take more than 1 GiB; refused before reading its pixels");
    // 4000 rows in ZIP blocks of 16: 250 chunks of at least 16 bytes (offset, y, size); OpenEXR wrote only the
    // 250 offsets of 8 bytes.
    CHECK(message(exrHeaderOnly(dir, "short.exr", 4000, 4000)) ==
          ": truncated EXR: a 4000x4000 image of 250 blocks of rows needs at least 4000 bytes of offsets and chunk "
          "headers but only 2000 bytes follow its header");
}

namespace {

// EXR files written byte by byte: a header of the standard attributes for a `width` x `height` image of
// half B G R channels, then `extra` attributes as given, without the header's end when `open` is set.
struct HandExr {
    std::vector<uint8_t> bytes;
    void raw(const void* p, size_t n) {
        const size_t at = bytes.size();
        bytes.resize(at + n);
        std::memcpy(bytes.data() + at, p, n);
    }
    void i32(int32_t v) { raw(&v, 4); }  // the tests run little-endian, as EXR is
    void text(const std::string& s) { raw(s.c_str(), s.size() + 1); }
    void attribute(const std::string& name, const std::string& type, const std::vector<uint8_t>& value) {
        text(name);
        text(type);
        i32(int32_t(value.size()));
        raw(value.data(), value.size());
    }
    template <class... T> static std::vector<uint8_t> pack(T... values) {
        HandExr h;
        (h.raw(&values, sizeof values), ...);
        return h.bytes;
    }
    HandExr() = default;
    HandExr(int32_t width, int32_t height, Imf::Compression compression, uint32_t tile = 0) {
        raw("\x76\x2f\x31\x01", 4);
        i32(tile ? 0x202 : 2);
        HandExr channels;
        for (const char* c : {"B", "G", "R"}) {
            channels.text(c);
            channels.raw(pack(int32_t(Imf::HALF), uint8_t(0), uint8_t(0), uint16_t(0), int32_t(1), int32_t(1)).data(), 16);
        }
        channels.bytes.push_back(0);
        attribute("channels", "chlist", channels.bytes);
        attribute("compression", "compression", {uint8_t(compression)});
        attribute("dataWindow", "box2i", pack(0, 0, width - 1, height - 1));
        attribute("displayWindow", "box2i", pack(0, 0, width - 1, height - 1));
        attribute("lineOrder", "lineOrder", {0});
        attribute("pixelAspectRatio", "float", pack(1.0f));
        attribute("screenWindowCenter", "v2f", pack(0.0f, 0.0f));
        attribute("screenWindowWidth", "float", pack(1.0f));
        if (tile) attribute("tiles", "tiledesc", pack(tile, tile, uint8_t(0)));
    }
    size_t end() {  // ends the header; the bytes so far
        bytes.push_back(0);
        return bytes.size();
    }
};

}  // namespace

TEST_CASE("exr: a small file that claims much more than it holds is refused before decoding", "[image][exr]") {
    TempDir dir;
    std::string error;
    const auto refuse = [&](const std::vector<uint8_t>& bytes) {
        CHECK_FALSE(readExrMemory(bytes.data(), bytes.size(), "small.exr", error));
        return error;
    };
    // One 8192x8192 tile, uncompressed, behind 50 bytes: 3 half channels need 402653184 bytes. OpenEXR
    // 3.1 would take the short chunk, decode 64 M pixels from its uninitialised buffer and return them.
    HandExr tiled(8192, 8192, Imf::NO_COMPRESSION, 8192);
    const uint64_t offset = tiled.end() + 8;
    tiled.raw(&offset, 8);
    tiled.raw(HandExr::pack(0, 0, 0, 0, 50).data(), 20);
    tiled.bytes.resize(tiled.bytes.size() + 50);
    CHECK(refuse(tiled.bytes) ==
          "small.exr: truncated EXR: a 8192x8192 image of 402653184 bytes of pixels needs at least 402653184 bytes of "
          "NONE data (at most 1:1) besides 28 bytes of offsets and chunk headers, but only 78 bytes follow its header");
    // 32 DWAB blocks of 256 rows, each 50 bytes: DWAB expands at most 131072:1.
    HandExr dwab(8192, 8192, Imf::DWAB_COMPRESSION);
    const size_t headerEnd = dwab.end();
    for (uint64_t i = 0; i < 32; ++i) {
        const uint64_t at = headerEnd + 32 * 8 + i * 58;
        dwab.raw(&at, 8);
    }
    for (int32_t i = 0; i < 32; ++i) {
        dwab.raw(HandExr::pack(i * 256, 50).data(), 8);
        dwab.bytes.resize(dwab.bytes.size() + 50);
    }
    CHECK(refuse(dwab.bytes) ==
          "small.exr: truncated EXR: a 8192x8192 image of 402653184 bytes of pixels needs at least 3072 bytes of "
          "DWAB data (at most 131072:1) besides 512 bytes of offsets and chunk headers, but only 2112 bytes follow its "
          "header");
    // An uncompressed 4x3 file whose row 1 holds 10 of its 24 bytes (and 14 bytes after the last row, so
    // that the file is long enough in all): OpenEXR 3.1 would decode it from a buffer filled that far.
    const auto rows = [&](int32_t shortRow, bool tableComplete) {
        HandExr h(4, 3, Imf::NO_COMPRESSION);
        const size_t end = h.end();
        uint64_t at = end + 3 * 8;
        for (int32_t y = 0; y < 3; ++y) {
            const uint64_t entry = !tableComplete && y == 2 ? 0 : at;
            h.raw(&entry, 8);
            at += 8 + (y == shortRow ? 10 : 24);
        }
        for (int32_t y = 0; y < 3; ++y) {
            h.raw(HandExr::pack(y, y == shortRow ? 10 : 24).data(), 8);
            h.bytes.resize(h.bytes.size() + (y == shortRow ? 10 : 24), 0x3c);  // half 1.0 is 3c00
        }
        h.bytes.resize(h.bytes.size() + 14);
        return h.bytes;
    };
    for (bool complete : {true, false}) {
        INFO((complete ? "offset table complete" : "offset table incomplete: OpenEXR walks the chunks"));
        CHECK(refuse(rows(1, complete)) ==
              "small.exr: corrupt EXR: the uncompressed (NONE) row 1 holds 10 bytes but its pixels take 24");
        const auto whole = rows(-1, complete);
        const auto image = readExrMemory(whole.data(), whole.size(), "whole.exr", error);
        REQUIRE(image);
        CHECK(image->width == 4);
        CHECK(image->rgba[0] == 1.05859375f);  // half 3c3c: 1 + 60/1024
    }
    // Header attributes whose size fields claim more than the file holds: OpenEXR would allocate (and, for a
    // string, zero) that much before finding the bytes missing.
    const auto claim = [&](const std::string& name, const std::string& type, int32_t size) {
        HandExr h(64, 64, Imf::ZIP_COMPRESSION);
        h.text(name);
        h.text(type);
        h.i32(size);
        h.bytes.resize(h.bytes.size() + 10);
        return refuse(h.bytes);
    };
    CHECK(claim("comments", "string", 0x7fff0000) ==
          "small.exr: truncated EXR: header attribute \"comments\" (string) claims 2147418112 bytes but only 10 bytes "
          "follow it");
    CHECK(claim("notes", "blob", 1 << 30) ==
          "small.exr: truncated EXR: header attribute \"notes\" (blob) claims 1073741824 bytes but only 10 bytes "
          "follow it");
    CHECK(claim("manifest", "idmanifest", 8) ==
          "small.exr: truncated EXR: header attribute \"manifest\" (idmanifest) claims 12 bytes but only 10 bytes "
          "follow it");
    CHECK(claim("names", "stringvector", 11) ==
          "small.exr: truncated EXR: header attribute \"names\" (stringvector) claims 11 bytes but only 10 bytes "
          "follow it");
    // Within what the file holds, the same attributes are OpenEXR's to read (here the data ends).
    CHECK(claim("comments", "string", 10).rfind("small.exr: truncated EXR: the data ends after ", 0) == 0);
    // A real file with an attribute of an unknown type and a string still reads.
    {
        Imf::Header header(4, 3);
        header.channels().insert("Y", Imf::Channel(Imf::HALF));
        header.insert("comments", Imf::StringAttribute("a string attribute"));
        Imf::OutputFile out(dir.file("attributes.exr").c_str(), header);
        std::vector<half> y(12, half(0.5f));
        Imf::FrameBuffer fb;
        fb.insert("Y", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(y.data()), sizeof(half), 4 * sizeof(half)));
        out.setFrameBuffer(fb);
        out.writePixels(3);
    }
    const auto image = readExr(dir.file("attributes.exr"), error);
    REQUIRE(image);
    CHECK(image->rgba[0] == 0.5f);
}

TEST_CASE("exr: mip and rip maps read as level 0; uncompressed tiles are checked as OpenEXR finds them",
          "[image][exr]") {
    TempDir dir;
    std::string error;
    for (Imf::LevelMode mode : {Imf::MIPMAP_LEVELS, Imf::RIPMAP_LEVELS})
        for (Imf::LevelRoundingMode rounding : {Imf::ROUND_DOWN, Imf::ROUND_UP}) {
            INFO((mode == Imf::MIPMAP_LEVELS ? "mip" : "rip") << (rounding == Imf::ROUND_UP ? " up" : " down"));
            ExrSpec spec = randomSpec(13, 7, {"R", "G", "B"}, 31);
            spec.tiled = true;
            spec.tileW = spec.tileH = 4;
            spec.levels = mode;
            spec.rounding = rounding;
            const std::string path = dir.file("levels.exr");
            writeExr(path, spec);
            auto image = readExr(path, error);
            REQUIRE(image);
            CHECK(image->rgba == expectedRgba(spec));

            // Where the offset table starts: its first entry points just past it, at tile (0, 0) of level 0.
            uint64_t entries = 0;
            {
                Imf::TiledInputFile in(path.c_str());
                for (int ly = 0; ly < in.numYLevels(); ++ly)
                    for (int lx = 0; lx < in.numXLevels(); ++lx)
                        if (mode == Imf::RIPMAP_LEVELS || lx == ly) entries += uint64_t(in.numXTiles(lx)) * in.numYTiles(ly);
            }
            const std::vector<uint8_t> bytes = slurp(path);
            const auto u64 = [&](const std::vector<uint8_t>& b, size_t at) {
                uint64_t v;
                std::memcpy(&v, b.data() + at, 8);
                return v;
            };
            size_t table = 8;
            while (table + 8 <= bytes.size() && u64(bytes, table) != table + entries * 8) ++table;
            REQUIRE(table + 8 <= bytes.size());
            // The last entry (the smallest level's) 0: OpenEXR walks the chunks from the table's end.
            auto incomplete = bytes;
            std::memset(incomplete.data() + table + (entries - 1) * 8, 0, 8);
            image = readExrMemory(incomplete.data(), incomplete.size(), "walked.exr", error);
            REQUIRE(image);
            CHECK(image->rgba == expectedRgba(spec));
            // Level 0's tile (1, 0) says it holds 2 bytes less than its 4x4 pixels of 6 bytes.
            for (const std::vector<uint8_t>& source : {incomplete, bytes}) {
                auto changed = source;
                changed[size_t(u64(bytes, table + 8)) + 16] -= 2;
                CHECK_FALSE(readExrMemory(changed.data(), changed.size(), "short.exr", error));
                CHECK(error == "short.exr: corrupt EXR: the uncompressed (NONE) tile (1, 0) holds 94 bytes but its "
                               "pixels take 96");
            }
        }
}

TEST_CASE("exr: NaN and infinite pixels are refused; negative values read as 0", "[image][exr]") {
    TempDir dir;
    const std::string path = dir.file("nan.exr");
    for (Imf::PixelType type : {Imf::HALF, Imf::FLOAT}) {
        ExrSpec spec = randomSpec(4, 3, {"R", "G", "B", "A"}, 11);
        spec.type = type;
        spec.values[1][1 * 4 + 2] = std::numeric_limits<float>::quiet_NaN();  // G of pixel (2, 1)
        writeExr(path, spec);
        std::string error;
        CHECK_FALSE(readExr(path, error));
        CHECK(error == path + ": pixel (2, 1) channel G is NaN; images must be finite");

        spec = randomSpec(4, 3, {"Y", "A"}, 12);
        spec.type = type;
        spec.values[1][2 * 4 + 3] = -std::numeric_limits<float>::infinity();  // A of pixel (3, 2)
        writeExr(path, spec);
        CHECK_FALSE(readExr(path, error));
        CHECK(error == path + ": pixel (3, 2) channel A is infinite; images must be finite");
        spec.values[1][2 * 4 + 3] = 0;
        spec.values[0][0] = std::numeric_limits<float>::infinity();
        writeExr(path, spec);
        CHECK_FALSE(readExr(path, error));
        CHECK(error == path + ": pixel (0, 0) channel Y is infinite; images must be finite");

        spec.values[0][0] = -2.5f;
        writeExr(path, spec);
        const auto image = readExr(path, error);
        REQUIRE(image);
        CHECK(image->rgba[0] == 0.0f);
        CHECK(image->rgba == expectedRgba(spec));
    }
}

// ---- readImage and the exposure mapping -------------------------------------------------------------

TEST_CASE("image: readImage picks the reader by content, not by extension", "[image][hdr][exr]") {
    TempDir dir;
    std::string error;
    RgbaImage png;
    png.width = 2;
    png.height = 1;
    png.rgba = {0, 51, 255, 255, 128, 1, 2, 3};
    REQUIRE(writePng(dir.file("png.exr"), png, error));
    auto loaded = readImage(dir.file("png.exr"), error);
    INFO(error);
    REQUIRE(loaded);
    CHECK_FALSE(loaded->hdr);
    CHECK(loaded->image.width == 2);
    CHECK(loaded->image.rgba == std::vector<float>{0, 0.2f, 1, 1, 128 / 255.0f, 1 / 255.0f, 2 / 255.0f, 3 / 255.0f});

    auto hdr = bytesOf("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n");
    hdr.insert(hdr.end(), {128, 0, 64, 131});
    spit(dir.file("hdr.png"), hdr);
    loaded = readImage(dir.file("hdr.png"), error);
    REQUIRE(loaded);
    CHECK(loaded->hdr);
    CHECK(loaded->image.rgba == std::vector<float>{4, 0, 2, 1});  // (128, 0, 64) * 2^(131 - 136)

    ExrSpec spec = randomSpec(3, 2, {"R", "G", "B"}, 4);
    writeExr(dir.file("exr.hdr"), spec);
    loaded = readImage(dir.file("exr.hdr"), error);
    REQUIRE(loaded);
    CHECK(loaded->hdr);
    CHECK(loaded->image.rgba == expectedRgba(spec));

    spit(dir.file("gif.png"), bytesOf("GIF89a\x01\x02"));
    CHECK_FALSE(readImage(dir.file("gif.png"), error));
    CHECK(error == dir.file("gif.png") + ": not a PNG, Radiance HDR or OpenEXR image (it starts with 47 49 46 38 39 61 01 02)");
    spit(dir.file("empty.png"), {});
    CHECK_FALSE(readImage(dir.file("empty.png"), error));
    CHECK(error == dir.file("empty.png") + ": empty file, not an image");
    CHECK_FALSE(readImage(dir.file("missing.png"), error));
    CHECK(error == dir.file("missing.png") + ": cannot open: No such file or directory");
    // The reader's own message for a file that starts right and goes wrong.
    spit(dir.file("cut.hdr"), bytesOf("#?RADIANCE\n"));
    CHECK_FALSE(readImage(dir.file("cut.hdr"), error));
    CHECK(error.rfind(dir.file("cut.hdr") + ": truncated Radiance HDR: ", 0) == 0);
}

TEST_CASE("image: the exposure mapping is 2^stops then the sRGB transfer function", "[image][exposure]") {
    FloatImage linear;
    linear.width = 6;
    linear.height = 1;
    linear.rgba = {0.0031308f, 1.0f, 0.18f, 0.3f,    // threshold, white, middle grey; alpha as is
                   0.5f,       2.0f, 0.001f, 2.0f,   // 2 above white stays above 1 unclamped
                   0.25f,      0.0f, 1e-4f, 0.75f,
                   -0.5f,      4.0f, 0.5f, 1.0f,
                   std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f, 1.0f,
                   100.0f, 0.01f, 0.02f, 0.0f};
    const FloatImage v = exposeUnclamped(linear, 0.0f);
    CHECK(v.width == 6);
    CHECK(v.rgba[0] == Approx(0.040449936).epsilon(1e-6));  // 12.92 * 0.0031308, the two pieces meet here
    CHECK(v.rgba[1] == Approx(1.0).epsilon(1e-6));
    CHECK(v.rgba[2] == Approx(0.4613561295).epsilon(1e-6));
    CHECK(v.rgba[3] == 0.3f);
    CHECK(v.rgba[5] == Approx(1.3532560462).epsilon(1e-6));  // 1.055 * 2^(1/2.4) - 0.055
    CHECK(v.rgba[6] == Approx(0.01292).epsilon(1e-6));      // 12.92 * 0.001, the linear piece
    CHECK(v.rgba[7] == 2.0f);
    CHECK(std::isnan(v.rgba[16]));

    const FloatImage doubled = exposeUnclamped(linear, 1.0f);  // one stop up: 0.5 -> 1, 0.25 -> 0.5
    CHECK(doubled.rgba[4] == Approx(1.0).epsilon(1e-6));
    CHECK(doubled.rgba[8] == Approx(exposeUnclamped(linear, 0.0f).rgba[4]).epsilon(1e-6));
    CHECK(exposeUnclamped(linear, 2.0f).rgba[8] == Approx(1.0).epsilon(1e-6));
    CHECK(exposeUnclamped(linear, -1.0f).rgba[1] == Approx(v.rgba[4]).epsilon(1e-6));

    const RgbaImage bytes = toRgba8(v);
    CHECK(bytes.width == 6);
    CHECK(bytes.height == 1);
    CHECK(int(bytes.rgba[0]) == 10);   // round(0.040449936 * 255) = round(10.31)
    CHECK(int(bytes.rgba[1]) == 255);  // 1.0
    CHECK(int(bytes.rgba[2]) == 118);  // round(0.46136 * 255) = round(117.65)
    CHECK(int(bytes.rgba[3]) == 77);   // alpha 0.3: round(76.5) = 77
    CHECK(int(bytes.rgba[5]) == 255);  // above 1 clamps
    CHECK(int(bytes.rgba[12]) == 0);   // negative clamps
    CHECK(int(bytes.rgba[16]) == 0);   // NaN reads as 0
    CHECK(int(bytes.rgba[20]) == 255);
    FloatImage edges;
    edges.width = 1;
    edges.height = 1;
    edges.rgba = {0.5f, 127.4f / 255, 127.6f / 255, 0.0f};
    CHECK(toRgba8(edges).rgba == std::vector<uint8_t>{128, 127, 128, 0});  // round to nearest, 127.5 up
}
