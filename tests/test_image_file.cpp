// Unit tests of the image files (emu/image_file.h): PNG round trips; palette, grey, 16-bit, tRNS
// and interlaced PNGs written here with libpng itself and read back to the values the PNG
// specification gives them; truncated, garbage and corrupt data, absurd sizes, missing and
// unwritable paths, each refused with a message naming the file, without a crash and without a
// word from libpng on stderr.
#include <catch2/catch.hpp>

#include <png.h>
#include <sys/resource.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csetjmp>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
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
    TempDir() : test_files::TempDir("ps11_image_test_") {}
};

// Whatever is written to file descriptor 2 while it lives (libpng's default handlers print there).
class StderrCapture {
public:
    StderrCapture() : m_file(std::tmpfile()), m_saved(dup(2)) {
        std::fflush(stderr);
        dup2(fileno(m_file), 2);
    }
    ~StderrCapture() {
        restore();
        std::fclose(m_file);
    }
    std::string text() {
        restore();
        std::string s;
        std::rewind(m_file);
        for (int c; (c = std::fgetc(m_file)) != EOF;) s += char(c);
        return s;
    }

private:
    void restore() {
        if (m_saved < 0) return;
        std::fflush(stderr);
        dup2(m_saved, 2);
        close(m_saved);
        m_saved = -1;
    }
    FILE* m_file;
    int m_saved;
};

RgbaImage randomImage(uint32_t width, uint32_t height, uint32_t seed) {
    std::mt19937 rng(seed);
    RgbaImage image;
    image.width = width;
    image.height = height;
    image.rgba.resize(size_t(width) * height * 4);
    for (uint8_t& b : image.rgba) b = uint8_t(rng());
    return image;
}

// A PNG as libpng's writer takes it: rows of samples (one per channel, or palette indices) at
// `bitDepth`, packed here the PNG way (MSB first below 8 bits, big endian at 16).
struct PngSpec {
    uint32_t width = 0, height = 0;
    int bitDepth = 8;
    int colorType = PNG_COLOR_TYPE_RGB;
    bool interlace = false;
    std::vector<png_color> palette;
    std::vector<uint8_t> paletteAlpha;  // tRNS of a palette image
    bool trnsColor = false;             // tRNS of a grey or RGB image: the sample values below
    png_color_16 trns{};
    std::vector<std::vector<unsigned>> rows;
};

std::vector<uint8_t> packRow(const std::vector<unsigned>& samples, int bitDepth) {
    std::vector<uint8_t> row;
    if (bitDepth == 16) {
        for (unsigned v : samples) row.insert(row.end(), {uint8_t(v >> 8), uint8_t(v)});
    } else if (bitDepth == 8) {
        for (unsigned v : samples) row.push_back(uint8_t(v));
    } else {
        row.assign((samples.size() * size_t(bitDepth) + 7) / 8, 0);
        for (size_t i = 0; i < samples.size(); ++i) {
            const size_t bit = i * size_t(bitDepth);
            row[bit / 8] |= uint8_t(samples[i] << (8 - bitDepth - int(bit % 8)));
        }
    }
    return row;
}

void appendBytes(png_structp png, png_bytep data, size_t n) {
    auto* out = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(png));
    out->insert(out->end(), data, data + n);
}

[[noreturn]] void onTestPngError(png_structp png, png_const_charp) { png_longjmp(png, 1); }

// Holds no object with a destructor across setjmp (the caller owns every buffer).
bool encodeWithLibpng(png_structp png, png_infop info, const PngSpec& spec, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_IHDR(png, info, spec.width, spec.height, spec.bitDepth, spec.colorType,
                 spec.interlace ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    if (!spec.palette.empty()) png_set_PLTE(png, info, spec.palette.data(), int(spec.palette.size()));
    if (!spec.paletteAlpha.empty())
        png_set_tRNS(png, info, spec.paletteAlpha.data(), int(spec.paletteAlpha.size()), nullptr);
    if (spec.trnsColor) png_set_tRNS(png, info, nullptr, 0, &spec.trns);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    return true;
}

std::vector<uint8_t> writeWithLibpng(const PngSpec& spec) {
    std::vector<std::vector<uint8_t>> packed;
    std::vector<png_bytep> rows;
    for (const auto& r : spec.rows) packed.push_back(packRow(r, spec.bitDepth));
    for (auto& r : packed) rows.push_back(r.data());
    std::vector<uint8_t> out;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, onTestPngError, nullptr);
    png_infop info = png_create_info_struct(png);
    png_set_write_fn(png, &out, appendBytes, nullptr);
    const bool ok = encodeWithLibpng(png, info, spec, rows.data());
    png_destroy_write_struct(&png, &info);
    REQUIRE(ok);
    return out;
}

std::array<uint8_t, 4> pixel(const RgbaImage& image, uint32_t x, uint32_t y) {
    const uint8_t* p = image.rgba.data() + (size_t(y) * image.width + x) * 4;
    return {p[0], p[1], p[2], p[3]};
}

using Rgba = std::array<uint8_t, 4>;

// Reads `bytes` from memory and from a file; both must give the same image.
RgbaImage readBoth(const std::vector<uint8_t>& bytes, const TempDir& dir) {
    std::string error;
    const auto fromMemory = readPngMemory(bytes.data(), bytes.size(), "mem.png", error);
    INFO(error);
    REQUIRE(fromMemory);
    const std::string path = dir.file("read.png");
    spit(path, bytes);
    const auto fromFile = readPng(path, error);
    INFO(error);
    REQUIRE(fromFile);
    CHECK(fromFile->width == fromMemory->width);
    CHECK(fromFile->height == fromMemory->height);
    CHECK(fromFile->rgba == fromMemory->rgba);
    CHECK(fromMemory->rgba.size() == size_t(fromMemory->width) * fromMemory->height * 4);
    return *fromMemory;
}

// 16 → 8 bits as the PNG specification's sample-depth scaling rounds it: v * 255 / 65535.
uint8_t scale16(unsigned v) { return uint8_t(std::lround(v * 255.0 / 65535.0)); }

uint32_t crcOf(const std::vector<uint8_t>& bytes, size_t begin, size_t end) {
    return uint32_t(crc32(0, bytes.data() + begin, uInt(end - begin)));
}

void putBe32(std::vector<uint8_t>& out, uint32_t v) {
    out.insert(out.end(), {uint8_t(v >> 24), uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)});
}

void putChunk(std::vector<uint8_t>& out, const char* type, const std::vector<uint8_t>& data) {
    putBe32(out, uint32_t(data.size()));
    const size_t start = out.size();
    out.insert(out.end(), type, type + 4);
    out.insert(out.end(), data.begin(), data.end());
    putBe32(out, crcOf(out, start, out.size()));
}

// A PNG by hand whose IHDR claims width x height (8-bit RGBA), with a tiny valid IDAT and IEND.
std::vector<uint8_t> pngClaiming(uint32_t width, uint32_t height) {
    std::vector<uint8_t> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::vector<uint8_t> ihdr;
    putBe32(ihdr, width);
    putBe32(ihdr, height);
    ihdr.insert(ihdr.end(), {8, 6, 0, 0, 0});
    putChunk(png, "IHDR", ihdr);
    // Zero rows (filter 0, black) for small claims; a few KiB of them for large ones.
    std::vector<uint8_t> raw(size_t(std::min<uint64_t>(uint64_t(height) * (1 + uint64_t(width) * 4), 4096)), 0);
    std::vector<uint8_t> idat(compressBound(uLong(raw.size())));
    uLongf n = uLongf(idat.size());
    compress(idat.data(), &n, raw.data(), uLong(raw.size()));
    idat.resize(n);
    putChunk(png, "IDAT", idat);
    putChunk(png, "IEND", {});
    return png;
}

std::string readError(const std::vector<uint8_t>& bytes, const std::string& name) {
    std::string error;
    const auto image = readPngMemory(bytes.data(), bytes.size(), name, error);
    CHECK_FALSE(image);
    return error;
}

}  // namespace

TEST_CASE("image: a random RGBA image survives writePng and readPng", "[image]") {
    TempDir dir;
    for (const auto& [w, h] : std::vector<std::pair<uint32_t, uint32_t>>{{1, 1}, {37, 23}, {256, 3}, {2, 300}}) {
        const RgbaImage image = randomImage(w, h, w * 1000 + h);
        const std::string path = dir.file("round.png");
        std::string error;
        REQUIRE(writePng(path, image, error));
        const std::vector<uint8_t> bytes = slurp(path);
        // IHDR: width, height, 8-bit, colour type 6 (RGBA), no interlace.
        REQUIRE(bytes.size() > 33);
        CHECK(bytes[16] == uint8_t(w >> 24));
        CHECK(bytes[19] == uint8_t(w));
        CHECK(bytes[23] == uint8_t(h));
        CHECK(bytes[24] == 8);
        CHECK(bytes[25] == 6);
        CHECK(bytes[28] == 0);
        const RgbaImage back = readBoth(bytes, dir);
        CHECK(back.width == w);
        CHECK(back.height == h);
        CHECK(back.rgba == image.rgba);
    }
}

TEST_CASE("image: 16-bit PNGs read as 8 bits rounded", "[image]") {
    TempDir dir;
    const std::vector<unsigned> values{0, 65535, 128, 129, 32767, 32768, 0x1234, 0xfedc, 25700, 25828, 25829, 65407};
    SECTION("RGB") {
        PngSpec spec;
        spec.width = 4;
        spec.height = 1;
        spec.bitDepth = 16;
        spec.colorType = PNG_COLOR_TYPE_RGB;
        spec.rows = {values};
        const RgbaImage image = readBoth(writeWithLibpng(spec), dir);
        REQUIRE(image.width == 4);
        for (uint32_t x = 0; x < 4; ++x) {
            const Rgba expected{scale16(values[x * 3]), scale16(values[x * 3 + 1]), scale16(values[x * 3 + 2]), 255};
            CHECK(pixel(image, x, 0) == expected);
        }
    }
    SECTION("grey + alpha, interlaced") {
        PngSpec spec;
        spec.width = 3;
        spec.height = 2;
        spec.bitDepth = 16;
        spec.colorType = PNG_COLOR_TYPE_GRAY_ALPHA;
        spec.interlace = true;
        spec.rows = {{values[0], values[1], values[2], values[3], values[4], values[5]},
                     {values[6], values[7], values[8], values[9], values[10], values[11]}};
        const RgbaImage image = readBoth(writeWithLibpng(spec), dir);
        for (uint32_t y = 0; y < 2; ++y)
            for (uint32_t x = 0; x < 3; ++x) {
                const uint8_t g = scale16(spec.rows[y][x * 2]), a = scale16(spec.rows[y][x * 2 + 1]);
                CHECK(pixel(image, x, y) == Rgba{g, g, g, a});
            }
    }
}

TEST_CASE("image: palette PNGs read as their colours, tRNS as alpha", "[image]") {
    TempDir dir;
    const std::vector<png_color> palette{{10, 20, 30}, {200, 100, 0}, {0, 255, 1}, {7, 7, 7}, {255, 254, 253}};
    for (const int depth : {1, 4, 8}) {
        const unsigned entries = depth == 1 ? 2 : 5;
        PngSpec spec;
        spec.width = 7;
        spec.height = 3;
        spec.bitDepth = depth;
        spec.colorType = PNG_COLOR_TYPE_PALETTE;
        spec.palette.assign(palette.begin(), palette.begin() + entries);
        spec.paletteAlpha = {0, 128};  // entries past the tRNS list are opaque
        if (depth == 8) spec.paletteAlpha.clear();
        for (uint32_t y = 0; y < spec.height; ++y) {
            spec.rows.emplace_back();
            for (uint32_t x = 0; x < spec.width; ++x) spec.rows.back().push_back((x + y * 3) % entries);
        }
        INFO("bit depth " << depth);
        const RgbaImage image = readBoth(writeWithLibpng(spec), dir);
        for (uint32_t y = 0; y < spec.height; ++y)
            for (uint32_t x = 0; x < spec.width; ++x) {
                const unsigned i = spec.rows[y][x];
                const uint8_t a = i < spec.paletteAlpha.size() ? spec.paletteAlpha[i] : 255;
                CHECK(pixel(image, x, y) == Rgba{palette[i].red, palette[i].green, palette[i].blue, a});
            }
    }
}

TEST_CASE("image: grey PNGs of every depth read as grey RGB", "[image]") {
    TempDir dir;
    for (const int depth : {1, 2, 4, 8}) {
        for (const bool interlace : {false, true}) {
            const unsigned maxValue = (1u << depth) - 1;
            PngSpec spec;
            spec.width = 9;
            spec.height = 7;
            spec.bitDepth = depth;
            spec.colorType = PNG_COLOR_TYPE_GRAY;
            spec.interlace = interlace;
            for (uint32_t y = 0; y < spec.height; ++y) {
                spec.rows.emplace_back();
                for (uint32_t x = 0; x < spec.width; ++x) spec.rows.back().push_back((x * 5 + y * 3) % (maxValue + 1));
            }
            INFO("bit depth " << depth << (interlace ? ", interlaced" : ""));
            const RgbaImage image = readBoth(writeWithLibpng(spec), dir);
            for (uint32_t y = 0; y < spec.height; ++y)
                for (uint32_t x = 0; x < spec.width; ++x) {
                    // Low depths scale to 8 bits by v * 255 / (2^depth - 1), exact (PNG spec 13.12).
                    const uint8_t g = uint8_t(spec.rows[y][x] * 255 / maxValue);
                    CHECK(pixel(image, x, y) == Rgba{g, g, g, 255});
                }
        }
    }
}

TEST_CASE("image: tRNS of grey and RGB PNGs makes one value transparent", "[image]") {
    TempDir dir;
    SECTION("grey") {
        PngSpec spec;
        spec.width = 3;
        spec.height = 1;
        spec.colorType = PNG_COLOR_TYPE_GRAY;
        spec.trnsColor = true;
        spec.trns.gray = 77;
        spec.rows = {{76, 77, 78}};
        const RgbaImage image = readBoth(writeWithLibpng(spec), dir);
        CHECK(pixel(image, 0, 0) == Rgba{76, 76, 76, 255});
        CHECK(pixel(image, 1, 0) == Rgba{77, 77, 77, 0});
        CHECK(pixel(image, 2, 0) == Rgba{78, 78, 78, 255});
    }
    SECTION("RGB") {
        PngSpec spec;
        spec.width = 2;
        spec.height = 1;
        spec.colorType = PNG_COLOR_TYPE_RGB;
        spec.trnsColor = true;
        spec.trns.red = 1;
        spec.trns.green = 2;
        spec.trns.blue = 3;
        spec.rows = {{1, 2, 3, 1, 2, 4}};
        const RgbaImage image = readBoth(writeWithLibpng(spec), dir);
        CHECK(pixel(image, 0, 0) == Rgba{1, 2, 3, 0});
        CHECK(pixel(image, 1, 0) == Rgba{1, 2, 4, 255});
    }
}

TEST_CASE("image: an interlaced RGBA PNG reads as the same pixels", "[image]") {
    TempDir dir;
    const RgbaImage expected = randomImage(13, 11, 7);
    PngSpec spec;
    spec.width = 13;
    spec.height = 11;
    spec.colorType = PNG_COLOR_TYPE_RGB_ALPHA;
    spec.interlace = true;
    for (uint32_t y = 0; y < 11; ++y)
        spec.rows.emplace_back(expected.rgba.begin() + y * 13 * 4, expected.rgba.begin() + (y + 1) * 13 * 4);
    CHECK(readBoth(writeWithLibpng(spec), dir).rgba == expected.rgba);
}

TEST_CASE("image: a PNG cut at any byte is refused as truncated", "[image]") {
    TempDir dir;
    const std::string path = dir.file("whole.png");
    std::string error;
    REQUIRE(writePng(path, randomImage(20, 20, 3), error));
    const std::vector<uint8_t> whole = slurp(path);
    PngSpec interlaced;
    interlaced.width = 10;
    interlaced.height = 10;
    interlaced.colorType = PNG_COLOR_TYPE_GRAY;
    interlaced.interlace = true;
    interlaced.rows.assign(10, std::vector<unsigned>(10, 99));
    StderrCapture stderrText;
    for (const std::vector<uint8_t>& bytes : {whole, writeWithLibpng(interlaced)}) {
        for (size_t cut = 0; cut < bytes.size(); ++cut) {
            INFO("cut at " << cut << " of " << bytes.size());
            const std::string e = readError(std::vector<uint8_t>(bytes.begin(), bytes.begin() + cut), "cut.png");
            if (cut == 0) {
                CHECK(e == "cut.png: empty file, not a PNG");
            } else {
                CHECK_THAT(e, Catch::StartsWith("cut.png: truncated PNG: "));
            }
        }
    }
    // From a file, at a few cuts: the message names the path.
    for (const size_t cut : {size_t(5), size_t(8), size_t(20), size_t(40), whole.size() / 2, whole.size() - 1}) {
        const std::string cutPath = dir.file("cut-" + std::to_string(cut) + ".png");
        spit(cutPath, std::vector<uint8_t>(whole.begin(), whole.begin() + long(cut)));
        CHECK_FALSE(readPng(cutPath, error));
        CHECK_THAT(error, Catch::StartsWith(cutPath + ": truncated PNG: the data ends after " + std::to_string(cut)));
    }
    CHECK(stderrText.text().empty());
}

TEST_CASE("image: garbage and corrupt data are refused with what is wrong", "[image]") {
    TempDir dir;
    StderrCapture stderrText;
    std::mt19937 rng(11);
    for (size_t size = 1; size < 300; size += 7) {
        std::vector<uint8_t> garbage(size);
        for (uint8_t& b : garbage) b = uint8_t(rng());
        if (garbage[0] == 0x89) garbage[0] = 0;
        CHECK_THAT(readError(garbage, "junk.bin"), Catch::StartsWith("junk.bin: not a PNG file (it starts with "));
    }
    const std::vector<uint8_t> gif{'G', 'I', 'F', '8', '9', 'a', 0x01, 0x00, 0x01, 0x00};
    CHECK(readError(gif, "a.gif") ==
          "a.gif: not a PNG file (it starts with 47 49 46 38 39 61 01 00; a PNG starts with 89 50 4e 47 0d 0a 1a 0a)");

    const std::string path = dir.file("good.png");
    std::string error;
    REQUIRE(writePng(path, randomImage(8, 8, 5), error));
    const std::vector<uint8_t> good = slurp(path);
    // The signature followed by garbage: libpng's complaint about the first chunk.
    std::vector<uint8_t> sigGarbage(good.begin(), good.begin() + 8);
    for (int i = 0; i < 100; ++i) sigGarbage.push_back(uint8_t(rng()));
    CHECK_THAT(readError(sigGarbage, "sig.png"), Catch::StartsWith("sig.png: corrupt PNG: libpng: "));
    // A byte of IHDR changed: its CRC no longer matches.
    std::vector<uint8_t> badCrc = good;
    badCrc[17] ^= 0x40;
    CHECK(readError(badCrc, "crc.png") == "crc.png: corrupt PNG: libpng: IHDR: CRC error");
    // The zlib stream of IDAT broken, with the chunk's CRC recomputed so zlib sees it.
    std::vector<uint8_t> badZlib = good;
    const size_t idat = 33;  // after the signature (8) and IHDR (25)
    REQUIRE(std::string(badZlib.begin() + idat + 4, badZlib.begin() + idat + 8) == "IDAT");
    const size_t idatLength = size_t(badZlib[idat]) << 24 | size_t(badZlib[idat + 1]) << 16 |
                              size_t(badZlib[idat + 2]) << 8 | badZlib[idat + 3];
    badZlib[idat + 8] = 0x00;  // CMF: compression method 0 is not deflate
    const uint32_t crc = crcOf(badZlib, idat + 4, idat + 8 + idatLength);
    for (int i = 0; i < 4; ++i) badZlib[idat + 8 + idatLength + size_t(i)] = uint8_t(crc >> (24 - 8 * i));
    CHECK_THAT(readError(badZlib, "zlib.png"), Catch::StartsWith("zlib.png: corrupt PNG: libpng: IDAT: "));
    // Every single byte flipped in turn: an image or an error naming the file, never a crash.
    for (size_t i = 8; i < good.size(); ++i) {
        std::vector<uint8_t> flipped = good;
        flipped[i] ^= 0x5a;
        const auto image = readPngMemory(flipped.data(), flipped.size(), "flip.png", error);
        if (image) {
            CHECK(image->rgba.size() == size_t(image->width) * image->height * 4);
        } else {
            CHECK_THAT(error, Catch::StartsWith("flip.png: "));
        }
    }
    CHECK(stderrText.text().empty());
}

TEST_CASE("image: absurd sizes are refused before any pixel is allocated", "[image]") {
    StderrCapture stderrText;
    // 100000 x 100000 RGBA would be 40 GB: allocating it would fail or take minutes, so passing
    // quickly shows the refusal came first.
    CHECK(readError(pngClaiming(100000, 100000), "big.png") ==
          "big.png: the image is 100000x100000 and a side is larger than 16384 pixels; refused before reading its "
          "pixels");
    CHECK_THAT(readError(pngClaiming(16385, 1), "wide.png"), Catch::StartsWith("wide.png: the image is 16385x1 and "));
    CHECK_THAT(readError(pngClaiming(1, 16385), "tall.png"), Catch::StartsWith("tall.png: the image is 1x16385 and "));
    // Within the limits but 1 GiB of pixels from a few dozen bytes: deflate cannot expand that far,
    // so the file is refused as truncated instead of allocating first.
    CHECK_THAT(readError(pngClaiming(16384, 16384), "max.png"),
               Catch::StartsWith("max.png: truncated PNG: a 16384x16384 image needs at least "));
    // Sizes the PNG format forbids: libpng's own word.
    CHECK(readError(pngClaiming(0, 5), "zero.png") ==
          "zero.png: corrupt PNG: libpng: Invalid IHDR data (Image width is zero in IHDR)");
    CHECK(readError(pngClaiming(0x80000000u, 5), "neg.png") ==
          "neg.png: corrupt PNG: libpng: PNG unsigned integer out of range");
    // A small claim with enough data is fine: the hand-made file itself is valid.
    std::string error;
    const std::vector<uint8_t> small = pngClaiming(3, 5);
    const auto image = readPngMemory(small.data(), small.size(), "small.png", error);
    INFO(error);
    REQUIRE(image);
    CHECK(image->rgba == std::vector<uint8_t>(3 * 5 * 4, 0));
    CHECK(stderrText.text().empty());
}

TEST_CASE("image: missing files, directories and empty files", "[image]") {
    TempDir dir;
    std::string error;
    const std::string missing = dir.file("no-such.png");
    CHECK_FALSE(readPng(missing, error));
    CHECK(error == missing + ": cannot open: No such file or directory");
    CHECK_FALSE(readPng(dir.path.string(), error));
    CHECK(error == dir.path.string() + ": cannot read: Is a directory");
    const std::string empty = dir.file("empty.png");
    spit(empty, {});
    CHECK_FALSE(readPng(empty, error));
    CHECK(error == empty + ": empty file, not a PNG");
}

TEST_CASE("image: writePng refuses what it cannot write", "[image]") {
    TempDir dir;
    std::string error;
    const RgbaImage image = randomImage(64, 64, 1);
    const std::string noDir = dir.file("no-such-dir/out.png");
    CHECK_FALSE(writePng(noDir, image, error));
    CHECK(error == noDir + ": cannot create: No such file or directory");

    RgbaImage shortBuffer = image;
    shortBuffer.rgba.resize(10);
    const std::string path = dir.file("out.png");
    CHECK_FALSE(writePng(path, shortBuffer, error));
    CHECK(error == path + ": cannot write a 64x64 image from 10 bytes of pixels (RGBA needs 16384)");
    CHECK_FALSE(writePng(path, RgbaImage{}, error));
    CHECK(error == path + ": cannot write an empty image (0x0)");
    RgbaImage wide;
    wide.width = 16385;
    wide.height = 1;
    CHECK_FALSE(writePng(path, wide, error));
    CHECK(error == path + ": cannot write a 16385x1 image: a side is larger than 16384 pixels");
    CHECK_FALSE(fs::exists(path));

    // A full disk: /dev/full takes the open and fails every write.
    if (access("/dev/full", W_OK) == 0) {
        CHECK_FALSE(writePng("/dev/full", image, error));
        CHECK(error == "/dev/full: write failed: No space left on device");
        CHECK(fs::exists("/dev/full"));
    }
    // A write that fails half way (a file-size limit of 4 KiB; the PNG of random pixels is
    // bigger) leaves no half-written file behind.
    struct rlimit old {};
    REQUIRE(getrlimit(RLIMIT_FSIZE, &old) == 0);
    if (old.rlim_cur == RLIM_INFINITY || old.rlim_cur > 4096) {
        const auto oldHandler = std::signal(SIGXFSZ, SIG_IGN);
        struct rlimit small = old;
        small.rlim_cur = 4096;
        REQUIRE(setrlimit(RLIMIT_FSIZE, &small) == 0);
        const bool written = writePng(path, image, error);
        setrlimit(RLIMIT_FSIZE, &old);
        std::signal(SIGXFSZ, oldHandler);
        CHECK_FALSE(written);
        CHECK(error == path + ": write failed: File too large");
        CHECK_FALSE(fs::exists(path));
    }
}
