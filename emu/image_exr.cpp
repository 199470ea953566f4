// OpenEXR files (emu/image_file.h, docs/images.md) through the OpenEXR 3.1 library (libopenexr-dev).
//
// Its C++ API (Imf::InputFile), not the OpenEXRCore C API: in 3.1 one InputFile reads scanline and
// tiled files alike, runs every decompressor, converts half and uint channels to float and fills the
// channels a file lacks, in a few calls; Core leaves chunk iteration, tile levels and conversion to the
// caller. It reports errors by exception: every one is caught here and becomes the message.
//
// OpenEXR sizes its tables and buffers from the header as soon as an InputFile opens, so the header is
// read alone first (Imf::Header::readFrom) and checked: the limits, the channels, the size of a chunk's
// buffer, and whether the chunk offset table and chunk headers can fit in the bytes that follow it.
// Pixels are then read in bands of rows into a band buffer, so a small file that claims a large image
// fails at its first missing chunk without the whole image ever being written.
#include <Iex.h>
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfTileDescription.h>
#include <ImfVersion.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#include "emu/image_file.h"
#include "emu/image_file_internal.h"

namespace emu {
namespace {

constexpr uint8_t kMagic[4] = {0x76, 0x2f, 0x31, 0x01};
// Each chunk has an 8-byte entry in the offset table and a header: y and size for a scanline block,
// tile x, y, level x, level y and size for a tile.
constexpr uint64_t kScanlineChunkBytes = 8 + 8, kTileChunkBytes = 8 + 20;
// Rows decoded at a time: about 16 MiB of float RGBA.
constexpr uint64_t kBandFloats = uint64_t(1) << 22;

// The file as OpenEXR reads it: `size` bytes at `data`, or `file` of `size` bytes. A read past the end
// throws, and says so in `ended`.
class ExrStream final : public Imf::IStream {
public:
    ExrStream(const std::string& name, const uint8_t* data, size_t size)
        : Imf::IStream(name.c_str()), m_data(data), m_size(data ? size : 0) {}
    ExrStream(const std::string& name, FILE* file, uint64_t size)
        : Imf::IStream(name.c_str()), m_file(file), m_size(size) {}

    bool read(char c[], int n) override {
        if (n < 0) throw Iex::InputExc("a negative read");
        if (m_pos > m_size || uint64_t(n) > m_size - m_pos) {
            ended = true;
            throw Iex::InputExc("unexpected end of data");
        }
        if (n == 0) return m_pos < m_size;
        if (m_file) {
            if (m_filePos != m_pos && fseeko(m_file, off_t(m_pos), SEEK_SET) != 0) fail();
            if (std::fread(c, 1, size_t(n), m_file) != size_t(n)) fail();
            m_filePos = m_pos + uint64_t(n);
        } else {
            std::memcpy(c, m_data + m_pos, size_t(n));
        }
        m_pos += uint64_t(n);
        return m_pos < m_size;
    }
    // `n` bytes at `pos` without moving the read position or setting `ended`: false past the end or
    // when the file cannot be read (then OpenEXR meets the same failure and says so).
    bool readAt(uint64_t pos, void* out, size_t n) {
        if (pos > m_size || n > m_size - pos) return false;
        if (!m_file) {
            std::memcpy(out, m_data + pos, n);
            return true;
        }
        m_filePos = UINT64_MAX;
        return fseeko(m_file, off_t(pos), SEEK_SET) == 0 && std::fread(out, 1, n, m_file) == n;
    }
    uint64_t tellg() override { return m_pos; }
    void seekg(uint64_t pos) override { m_pos = pos; }
    uint64_t size() const { return m_size; }

    bool ended = false;  // OpenEXR asked for bytes past the end
    int ioErrno = 0;     // errno of a failed read of the file

private:
    [[noreturn]] void fail() {
        m_filePos = UINT64_MAX;
        if (std::feof(m_file)) {  // the file shrank while it was read
            ended = true;
            throw Iex::InputExc("unexpected end of data");
        }
        ioErrno = errno ? errno : EIO;
        throw Iex::InputExc("read error");
    }

    const uint8_t* m_data = nullptr;
    FILE* m_file = nullptr;
    uint64_t m_size = 0, m_pos = 0, m_filePos = 0;
};

// Text from the file or the library fit for a one-line message: unprintable bytes as '?', at most `most`.
std::string printable(const std::string& text, size_t most) {
    std::string s;
    for (size_t i = 0; i < std::min(text.size(), most); ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        s += (c >= 0x20 && c < 0x7f) ? char(c) : (c == '\n' || c == '\r' || c == '\t') ? ' ' : '?';
    }
    return text.size() > most ? s + "..." : s;
}

// Scanlines in a chunk, for each compression (OpenEXR's file layout).
uint64_t linesPerChunk(Imf::Compression c) {
    switch (c) {
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION: return 16;
    case Imf::PIZ_COMPRESSION:
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION:
    case Imf::DWAA_COMPRESSION: return 32;
    case Imf::DWAB_COMPRESSION: return 256;
    default: return 1;  // NONE, RLE, ZIPS
    }
}

// The bytes OpenEXR 3.1 reads of a header attribute's value for the types whose value it reads whatever
// the size field says (Header::readFrom, each type's readValueFrom); 0 for the others.
uint64_t fixedAttributeBytes(const std::string& type) {
    static const std::pair<const char*, uint64_t> kFixed[] = {
        {"box2i", 16},  {"box2f", 16},    {"compression", 1}, {"chromaticities", 32}, {"deepImageState", 1},
        {"double", 8},  {"envmap", 1},    {"float", 4},       {"int", 4},             {"keycode", 28},
        {"lineOrder", 1}, {"m33d", 72},   {"m33f", 36},       {"m44d", 128},          {"m44f", 64},
        {"rational", 8}, {"tiledesc", 9}, {"timecode", 8},    {"v2d", 16},            {"v2f", 8},
        {"v2i", 8},     {"v3d", 24},      {"v3f", 12},        {"v3i", 12}};
    for (const auto& [name, bytes] : kFixed)
        if (type == name) return bytes;
    return 0;
}

// Walks the header's attributes the way Header::readFrom will, before it does: OpenEXR allocates an
// attribute's value by its size field (a string, a string or float vector, a preview image, an ID
// manifest, an attribute of a type it does not know) and only then finds the bytes missing, so a
// mutated size field of 2 GiB cost 2 GiB of zeroed memory. Returns why the header cannot be what it
// claims ("" if it can, or where the walk cannot follow it: OpenEXR then refuses it itself).
std::string headerAttributeProblem(ExrStream& s) {
    const uint64_t total = s.size();
    uint64_t at = 8;  // after the magic number and version
    // A name as Xdr::read(is, 255, name) reads it: up to 256 bytes, the last of them NUL.
    const auto readName = [&](std::string& out) {
        char buffer[256];
        const size_t n = size_t(std::min<uint64_t>(sizeof buffer, total - std::min(total, at)));
        if (n == 0 || !s.readAt(at, buffer, n)) return false;
        const auto* nul = static_cast<const char*>(std::memchr(buffer, 0, n));
        if (!nul) return false;
        out.assign(buffer, size_t(nul - buffer));
        at += uint64_t(nul - buffer) + 1;
        return true;
    };
    std::string name, type, channel;
    for (;;) {
        if (!readName(name) || name.empty() || !readName(type)) return "";
        uint8_t sizeBytes[4];
        if (!s.readAt(at, sizeBytes, 4)) return "";
        at += 4;
        const int32_t size = int32_t(uint32_t(sizeBytes[0]) | uint32_t(sizeBytes[1]) << 8 |
                                     uint32_t(sizeBytes[2]) << 16 | uint32_t(sizeBytes[3]) << 24);
        if (size < 0) return "";  // OpenEXR refuses it before allocating
        const uint64_t left = total - std::min(total, at);
        uint64_t value = fixedAttributeBytes(type);
        if (value == 0 && type == "chlist") {  // channels: name, then type, pLinear, 3 reserved, x and y sampling
            for (;;) {
                if (!readName(channel)) return "";
                if (channel.empty()) break;
                at += 16;
            }
        } else if (value == 0) {
            // Allocated by the size field: a string, a string or float vector, a preview image (whose
            // size OpenEXR checks against its width and height), an ID manifest (8 bytes of size, then
            // its size field less 4), any other type's opaque bytes.
            value = type == "idmanifest" ? uint64_t(size) + 4 : uint64_t(size);
            if (value > left)
                return "truncated EXR: header attribute \"" + printable(name, 32) + "\" (" + printable(type, 32) +
                       ") claims " + std::to_string(value) + " bytes but only " + std::to_string(left) +
                       " bytes follow it";
        }
        at += value;
    }
}

// The most a chunk's pixels can expand from their bytes in the file, for each compression, and its name.
// NONE stores them as they are (a shorter chunk would leave OpenEXR's buffer partly unread). RLE: a run
// of at most 127 bytes in 2. ZIP, ZIPS: deflate, at most 1032:1 (zlib.net/zlib_tech.html). PXR24: floats
// cut to 24 bits, then deflate: 1032 * 4/3. PIZ: Huffman codes of at least 1 bit and a run code of 8 bits
// for at most 256 16-bit values: 409.6:1. B44, B44A: a 4x4 block of halves (32 bytes) in at least 3.
// DWAA, DWAB: an 8x8 DCT block of a float channel (256 bytes) in at least a 2-byte DC value and a
// 2-byte end of its AC values, each stream deflated: 256 * 1032 / 4 = 66048; a channel they take as
// RLE is run-length encoded, then deflated: 63.5 * 1032; 2^17 leaves a margin.
struct CompressionBound {
    const char* name;
    uint64_t ratio;
};
CompressionBound compressionBound(Imf::Compression c) {
    switch (c) {
    case Imf::NO_COMPRESSION: return {"NONE", 1};
    case Imf::RLE_COMPRESSION: return {"RLE", 64};
    case Imf::ZIPS_COMPRESSION: return {"ZIPS", 1032};
    case Imf::ZIP_COMPRESSION: return {"ZIP", 1032};
    case Imf::PIZ_COMPRESSION: return {"PIZ", 410};
    case Imf::PXR24_COMPRESSION: return {"PXR24", 1376};
    case Imf::B44_COMPRESSION: return {"B44", 11};
    case Imf::B44A_COMPRESSION: return {"B44A", 11};
    case Imf::DWAA_COMPRESSION: return {"DWAA", 131072};
    case Imf::DWAB_COMPRESSION: return {"DWAB", 131072};
    default: return {"an unknown compression", 1};  // sanityCheck refuses it first
    }
}

// Floor division, as OpenEXR's divp.
int64_t floorDiv(int64_t x, int64_t y) { return x >= 0 ? x / y : -((-x + y - 1) / y); }

// The chunks of an uncompressed (NONE) file that OpenEXR 3.1 would read short: it decodes a chunk whose
// size field is below its pixels' bytes as raw data all the same, from a buffer only that far filled,
// so the rest of the image would be whatever its buffer held. The chunks are found as OpenEXR finds
// them: through the offset table at `tableAt`, or, where an entry is 0 (an incomplete file), by
// walking the chunks one after another from the table's end. Returns why, or "".
std::string uncompressedChunkProblem(ExrStream& s, const Imf::Header& header, bool tiled, uint64_t tableAt) {
    const Imath::Box2i window = header.dataWindow();
    const int64_t minX = window.min.x, maxX = window.max.x, minY = window.min.y, maxY = window.max.y;
    const uint64_t total = s.size();
    const auto get32 = [](const uint8_t* p) {
        return int32_t(uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24);
    };
    uint64_t entries = 0, pixelBytes = 0;
    uint64_t tileW = 1, tileH = 1, tilesX = 0, tilesY = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
        pixelBytes += it.channel().type == Imf::HALF ? 2 : 4;
    if (tiled) {
        // The table holds every level's tiles (TileOffsets): its size is where the walk starts.
        const Imf::TileDescription& d = header.tileDescription();
        tileW = d.xSize;
        tileH = d.ySize;
        const auto log2 = [&](uint64_t x) {
            int y = 0, up = 0;
            for (; x > 1; x >>= 1, ++y) up |= int(x & 1);
            return d.roundingMode == Imf::ROUND_UP ? y + up : y;
        };
        const auto levelSize = [&](uint64_t size, int level) {
            uint64_t n = size >> level;
            if (d.roundingMode == Imf::ROUND_UP && (n << level) < size) ++n;
            return std::max<uint64_t>(n, 1);
        };
        const uint64_t w = uint64_t(maxX - minX + 1), h = uint64_t(maxY - minY + 1);
        const auto across = [&](int l) { return (levelSize(w, l) + tileW - 1) / tileW; };
        const auto down = [&](int l) { return (levelSize(h, l) + tileH - 1) / tileH; };
        tilesX = across(0);
        tilesY = down(0);
        if (d.mode == Imf::ONE_LEVEL) {
            entries = tilesX * tilesY;
        } else if (d.mode == Imf::MIPMAP_LEVELS) {
            for (int l = 0; l <= log2(std::max(w, h)); ++l) entries += across(l) * down(l);
        } else {
            for (int ly = 0; ly <= log2(h); ++ly)
                for (int lx = 0; lx <= log2(w); ++lx) entries += across(lx) * down(ly);
        }
    } else {
        entries = uint64_t(maxY - minY + 1);  // one row a chunk
    }
    // A chunk at `at` (`next`: where the one after it starts): "" when it is not one OpenEXR would take
    // as level 0's (it refuses those itself) or it holds all its pixels.
    const auto check = [&](uint64_t at, uint64_t& next) -> std::string {
        uint8_t h[20];
        const size_t headerBytes = tiled ? 20 : 8;
        next = UINT64_MAX;
        if (!s.readAt(at, h, headerBytes)) return "";
        const int32_t size = get32(h + headerBytes - 4);
        if (size < 0) return "";
        next = at + headerBytes + uint64_t(size);
        uint64_t need = 0;
        std::string what;
        if (tiled) {
            const int64_t dx = get32(h), dy = get32(h + 4);
            if (get32(h + 8) != 0 || get32(h + 12) != 0 || dx < 0 || dy < 0 || uint64_t(dx) >= tilesX ||
                uint64_t(dy) >= tilesY)
                return "";
            const int64_t x0 = minX + dx * int64_t(tileW), y0 = minY + dy * int64_t(tileH);
            need = uint64_t(std::min(maxX, x0 + int64_t(tileW) - 1) - x0 + 1) *
                   uint64_t(std::min(maxY, y0 + int64_t(tileH) - 1) - y0 + 1) * pixelBytes;
            what = "tile (" + std::to_string(dx) + ", " + std::to_string(dy) + ")";
        } else {
            const int64_t y = get32(h);
            if (y < minY || y > maxY) return "";
            for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
                const Imf::Channel& c = it.channel();
                if (floorDiv(y, c.ySampling) * c.ySampling != y) continue;
                need += uint64_t(floorDiv(maxX, c.xSampling) - floorDiv(minX - 1, c.xSampling)) *
                        (c.type == Imf::HALF ? 2 : 4);
            }
            what = "row " + std::to_string(y - minY);
        }
        if (uint64_t(size) >= need) return "";
        return "corrupt EXR: the uncompressed (NONE) " + what + " holds " + std::to_string(size) +
               " bytes but its pixels take " + std::to_string(need);
    };
    // The table, in blocks: any 0 entry has OpenEXR walk the chunks instead.
    bool complete = true;
    std::vector<uint64_t> block;
    for (uint64_t i = 0; i < entries && complete; i += block.size()) {
        block.resize(size_t(std::min<uint64_t>(entries - i, 8192)));
        if (!s.readAt(tableAt + i * 8, block.data(), block.size() * 8)) return "";  // OpenEXR finds the end
        complete = std::find(block.begin(), block.end(), uint64_t(0)) == block.end();
    }
    uint64_t next = 0;
    if (complete) {
        const uint64_t level0 = tiled ? tilesX * tilesY : entries;  // level 0 comes first
        for (uint64_t i = 0; i < level0; i += block.size()) {
            block.resize(size_t(std::min<uint64_t>(level0 - i, 8192)));
            if (!s.readAt(tableAt + i * 8, block.data(), block.size() * 8)) return "";
            for (const uint64_t at : block)
                if (std::string problem = check(at, next); !problem.empty()) return problem;
        }
        return "";
    }
    uint64_t at = tableAt + entries * 8;
    for (uint64_t i = 0; i < entries && at < total; ++i, at = next)
        if (std::string problem = check(at, next); !problem.empty() || next == UINT64_MAX) return problem;
    return "";
}

// Which channels are read, and into which of r g b a: Y into r (then copied to g and b).
struct ExrLayout {
    bool grey = false;
    const char* names[4] = {"R", "G", "B", "A"};
};

// Why the channels cannot be read, or "" with `layout` set.
std::string channelProblem(const Imf::Header& header, ExrLayout& layout) {
    const Imf::ChannelList& channels = header.channels();
    if (channels.findChannel("RY") || channels.findChannel("BY"))
        return "unsupported EXR: a luminance/chroma image (channels RY, BY); only RGB and Y images are read";
    std::string have, lack;
    for (const char* name : {"R", "G", "B"}) (channels.findChannel(name) ? have : lack) += std::string(", ") + name;
    if (!have.empty() && !lack.empty())
        return "unsupported EXR: it has channel " + have.substr(2) + " but not " + lack.substr(2) +
               " (an RGB image needs R, G and B)";
    if (have.empty()) {
        if (!channels.findChannel("Y")) {
            std::string all;
            int count = 0;
            for (auto it = channels.begin(); it != channels.end(); ++it, ++count)
                if (count < 8) all += std::string(count ? ", " : "") + printable(it.name(), 32);
            if (count > 8) all += ", ...";
            return "unsupported EXR: no R, G, B or Y channel (its channels: " + (count ? all : "none") + ")";
        }
        layout.grey = true;
        layout.names[0] = "Y";
    }
    for (int i = 0; i < 4; ++i) {
        if (layout.grey && (i == 1 || i == 2)) continue;
        const Imf::Channel* c = channels.findChannel(layout.names[i]);
        if (c && (c->xSampling != 1 || c->ySampling != 1))
            return std::string("unsupported EXR: channel ") + layout.names[i] + " is subsampled (" +
                   std::to_string(c->xSampling) + "x" + std::to_string(c->ySampling) +
                   "); only full-resolution channels are read";
    }
    return "";
}

std::optional<FloatImage> decodeExr(ExrStream& s, const std::string& name, std::string& error) {
    const auto fail = [&](const std::string& what) {
        error = name + ": " + what;
        return std::nullopt;
    };
    const uint64_t total = s.size();
    if (total == 0) return fail("empty file, not an OpenEXR image");
    uint8_t start[8] = {};
    const size_t got = size_t(std::min<uint64_t>(total, 8));
    try {  // cannot end early (`got` bytes are there): only a failing file throws
        s.read(reinterpret_cast<char*>(start), int(got));
    } catch (const std::exception&) {
        return fail(std::string("read error: ") + std::strerror(s.ioErrno ? s.ioErrno : EIO));
    }
    if (std::memcmp(start, kMagic, std::min<size_t>(got, 4)) != 0)
        return fail("not an OpenEXR file (it starts with " + image_detail::hexBytes(start, got) +
                    "; an OpenEXR file starts with 76 2f 31 01)");
    if (got < 8) return fail("truncated EXR: the data ends after " + std::to_string(got) + " bytes");
    int version = int(uint32_t(start[4]) | uint32_t(start[5]) << 8 | uint32_t(start[6]) << 16 | uint32_t(start[7]) << 24);
    if (Imf::getVersion(version) != 2)
        return fail("unsupported EXR version " + std::to_string(Imf::getVersion(version)) + " (OpenEXR files are version 2)");
    if (Imf::isMultiPart(version))
        return fail("unsupported EXR: a multi-part file; only single-part images are read");
    if (Imf::isNonImage(version))
        return fail("unsupported EXR: deep data (a varying number of samples per pixel); only flat images are read");
    if (!Imf::supportsFlags(Imf::getFlags(version)))
        return fail("unsupported EXR: unknown feature flags in its version field (" + image_detail::hexBytes(start + 4, 4) + ")");
    const bool tiled = Imf::isTiled(version);

    const auto libraryFailure = [&](const char* what) {
        const std::string message = printable(what ? what : "unknown error", 300);
        if (s.ioErrno) return fail(std::string("read error: ") + std::strerror(s.ioErrno));
        if (s.ended)
            return fail("truncated EXR: the data ends after " + std::to_string(total) + " bytes (OpenEXR: " + message + ")");
        return fail("corrupt EXR: OpenEXR: " + message);
    };

    if (const std::string problem = headerAttributeProblem(s); !problem.empty()) return fail(problem);
    Imf::Header header;
    try {
        header.readFrom(s, version);
        header.sanityCheck(tiled);
    } catch (const std::bad_alloc&) {
        return fail("out of memory for the EXR header");
    } catch (const std::exception& e) {
        return libraryFailure(e.what());
    } catch (...) {
        return libraryFailure(nullptr);
    }

    const Imath::Box2i window = header.dataWindow();
    const uint64_t width = uint64_t(int64_t(window.max.x) - window.min.x + 1);
    const uint64_t height = uint64_t(int64_t(window.max.y) - window.min.y + 1);
    const std::string sizeText = std::to_string(width) + "x" + std::to_string(height);
    if (width > kMaxImageSide || height > kMaxImageSide)
        return fail("the image is " + sizeText + " and a side is larger than " + std::to_string(kMaxImageSide) +
                    " pixels; refused before reading its pixels");
    if (width * height * kFloatPixelBytes > kMaxImageBytes)
        return fail("the image is " + sizeText +
                    " and its float RGBA pixels take more than " + maxImageBytesText() + "; refused before reading its pixels");
    ExrLayout layout;
    if (const std::string problem = channelProblem(header, layout); !problem.empty()) return fail(problem);

    // What OpenEXR will allocate for a chunk (all of the file's channels), and the least the chunks take.
    uint64_t pixelBytes = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
        pixelBytes += it.channel().type == Imf::HALF ? 2 : 4;
    uint64_t chunkRows = 0, chunkWidth = width, chunks = 0, leastBytes = 0;
    if (tiled) {
        const Imf::TileDescription& tiles = header.tileDescription();
        const uint64_t tileW = tiles.xSize, tileH = tiles.ySize;
        if (tileW > kMaxImageSide || tileH > kMaxImageSide)
            return fail("unsupported EXR: tiles of " + std::to_string(tileW) + "x" + std::to_string(tileH) +
                        " pixels; at most " + std::to_string(kMaxImageSide) + " a side are read");
        chunkRows = tileH;  // InputFile keeps a whole row of tiles
        chunks = ((width + tileW - 1) / tileW) * ((height + tileH - 1) / tileH);
        leastBytes = chunks * kTileChunkBytes;
    } else {
        chunkRows = linesPerChunk(header.compression());
        chunks = (height + chunkRows - 1) / chunkRows;
        leastBytes = chunks * kScanlineChunkBytes;
    }
    if (pixelBytes * chunkWidth * chunkRows > kMaxImageBytes)
        return fail("unsupported EXR: a block of " + std::to_string(chunkRows) + " rows of its channels (" +
                    std::to_string(pixelBytes) + " bytes a pixel) takes more than " + maxImageBytesText());
    const uint64_t follow = total - std::min(total, s.tellg());
    if (follow < leastBytes)
        return fail("truncated EXR: a " + sizeText + " image " + (tiled ? "in " : "of ") + std::to_string(chunks) +
                    (tiled ? " tiles" : " blocks of rows") + " needs at least " + std::to_string(leastBytes) +
                    " bytes of offsets and chunk headers but only " + std::to_string(follow) +
                    " bytes follow its header");
    // The pixels' bytes uncompressed (a subsampled channel's samples counted down), and the least
    // bytes of chunk data they can come from.
    uint64_t rawBytes = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        const Imf::Channel& c = it.channel();
        rawBytes += (c.type == Imf::HALF ? 2 : 4) * (width / uint64_t(std::max(1, c.xSampling))) *
                    (height / uint64_t(std::max(1, c.ySampling)));
    }
    const CompressionBound bound = compressionBound(header.compression());
    const uint64_t leastPixels = (rawBytes + bound.ratio - 1) / bound.ratio;
    if (follow - leastBytes < leastPixels)
        return fail("truncated EXR: a " + sizeText + " image of " + std::to_string(rawBytes) +
                    " bytes of pixels needs at least " + std::to_string(leastPixels) + " bytes of " + bound.name +
                    " data (at most " + std::to_string(bound.ratio) + ":1) besides " + std::to_string(leastBytes) +
                    " bytes of offsets and chunk headers, but only " + std::to_string(follow) +
                    " bytes follow its header");
    if (header.compression() == Imf::NO_COMPRESSION)
        if (const std::string problem = uncompressedChunkProblem(s, header, tiled, s.tellg()); !problem.empty())
            return fail(problem);

    FloatImage image;
    image.width = uint32_t(width);
    image.height = uint32_t(height);
    try {
        s.seekg(0);
        Imf::InputFile file(s);
        s.ended = false;  // a scanline file's broken offset table is rebuilt by reading to the end
        // The first band is one block of rows (or a row of tiles), the rest about 16 MiB each; the band
        // is not zeroed (OpenEXR writes every value of the slices, missing channels with their fill).
        const uint64_t bandRows = std::max<uint64_t>(1, kBandFloats / (width * 4));
        std::unique_ptr<float[]> band;
        uint64_t bandFloats = 0;
        for (uint64_t y0 = 0, rows = 0; y0 < height; y0 += rows) {
            rows = std::min(y0 == 0 ? std::min(bandRows, chunkRows) : bandRows, height - y0);
            if (rows * width * 4 > bandFloats) {
                band.reset();
                band = std::make_unique_for_overwrite<float[]>(size_t(rows * width * 4));
                bandFloats = rows * width * 4;
            }
            const int first = int(int64_t(window.min.y) + int64_t(y0));
            Imf::FrameBuffer buffer;
            for (int c = 0; c < 4; ++c) {
                if (layout.grey && (c == 1 || c == 2)) continue;
                buffer.insert(layout.names[c],
                              Imf::Slice::Make(Imf::FLOAT, band.get() + c, Imath::V2i(window.min.x, first),
                                               int64_t(width), int64_t(rows), kFloatPixelBytes,
                                               kFloatPixelBytes * width, 1, 1, c == 3 ? 1.0 : 0.0));
            }
            file.setFrameBuffer(buffer);
            file.readPixels(first, first + int(rows) - 1);
            for (uint64_t i = 0; i < rows * width; ++i) {
                float* px = band.get() + i * 4;
                if (layout.grey) px[1] = px[2] = px[0];
                for (int c = 0; c < 4; ++c) {
                    if (!std::isfinite(px[c]))
                        return fail("pixel (" + std::to_string(i % width) + ", " + std::to_string(y0 + i / width) +
                                    ") channel " + layout.names[c] + " is " + (std::isnan(px[c]) ? "NaN" : "infinite") +
                                    "; images must be finite");
                    if (px[c] < 0) px[c] = 0;
                }
            }
            // The whole image is reserved once its first band has decoded: a file that claims a large
            // image and has nothing behind its header fails before it costs that much.
            if (y0 == 0) image.rgba.reserve(size_t(width * height * 4));
            image.rgba.insert(image.rgba.end(), band.get(), band.get() + rows * width * 4);
        }
    } catch (const std::bad_alloc&) {
        return fail("out of memory for a " + sizeText + " image");
    } catch (const std::exception& e) {
        return libraryFailure(e.what());
    } catch (...) {
        return libraryFailure(nullptr);
    }
    return image;
}

}  // namespace

std::optional<FloatImage> readExr(const std::string& path, std::string& error) {
    struct stat st {};
    const image_detail::FilePtr file = image_detail::openImageFile(path, st, error);
    if (!file) return std::nullopt;
    if (!S_ISREG(st.st_mode)) {
        error = path + ": cannot read: not a regular file (OpenEXR seeks in its files)";
        return std::nullopt;
    }
    ExrStream stream(path, file.get(), uint64_t(st.st_size));
    return decodeExr(stream, path, error);
}

std::optional<FloatImage> readExrMemory(const uint8_t* data, size_t size, const std::string& name, std::string& error) {
    ExrStream stream(name, data, size);
    return decodeExr(stream, name, error);
}

}  // namespace emu
