// Radiance .hdr files (emu/image_file.h, docs/images.md) through stb_image: Debian's compiled libstb
// (libstb-dev, stb_image 2.27), so the decoder gets the distribution's fixes without a rebuild here.
// The header is scanned here only to say precisely what is wrong with it and to find where the pixels
// start; stb_image parses the size (stbi_info on the header bytes) and decodes the pixels.
//
// stb_image 2.27 trusts its input's length: past the end it reads zero bytes, so a flat file cut short
// decodes as black and a run-length file cut short loops for ever on zero counts. So the pixels are
// checked against the bytes that follow the header before anything is allocated (exactly for flat
// pixels, a lower bound for run-length ones), and stb_image reads through callbacks that serve 0xff
// bytes past the end (a run of 127 longer than what is left, or 4 more bytes of a flat pixel: either
// ends the decode within O(pixels)); a decode that needed any is refused as truncated.
#include <stb_image.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>

#include "emu/image_file.h"
#include "emu/image_file_internal.h"

namespace emu {
namespace {

constexpr char kFormatLine[] = "FORMAT=32-bit_rle_rgbe";
// stb_image decodes scanlines of 8 to 32767 pixels run-length encoded when they start with 2 2 and a
// 15-bit length; a run takes 2 bytes for at most 127 pixels of one component.
constexpr uint64_t kMaxRun = 127;

// A header line as text fit for a one-line message: at most 40 characters, anything unprintable as '?'.
std::string quoted(const uint8_t* p, size_t n) {
    std::string s = "\"";
    for (size_t i = 0; i < std::min<size_t>(n, 40); ++i) s += (p[i] >= 0x20 && p[i] < 0x7f) ? char(p[i]) : '?';
    return s + (n > 40 ? "...\"" : "\"");
}

bool startsWith(const uint8_t* p, size_t n, const char* text) {
    const size_t len = std::strlen(text);
    return n >= len && std::memcmp(p, text, len) == 0;
}

// The memory stb_image reads through its callbacks: `size` bytes at `data`, then as many 0xff bytes as
// it asks for, counted in `padding`.
struct HdrSource {
    const uint8_t* data = nullptr;
    size_t size = 0;
    size_t at = 0;
    uint64_t padding = 0;
};

// stb_image asks for its 128-byte buffer's worth (a refill: fewer is normal near the end, none means it
// needs a byte past the end) or, through stbi__getn, for exactly the bytes of a flat pixel it needs.
constexpr int kStbBuffer = 128;

int onStbRead(void* user, char* out, int n) {
    auto* s = static_cast<HdrSource*>(user);
    if (n <= 0) return 0;
    const size_t real = std::min(size_t(n), s->size - s->at);
    if (real) std::memcpy(out, s->data + s->at, real);
    s->at += real;
    if (real > 0 && n >= kStbBuffer) return int(real);
    std::memset(out + real, 0xff, size_t(n) - real);
    s->padding += size_t(n) - real;
    return n;
}

void onStbSkip(void* user, int n) {
    auto* s = static_cast<HdrSource*>(user);
    if (n < 0) n = 0;  // stb_image never skips back in a Radiance file
    const size_t real = std::min(size_t(n), s->size - s->at);
    s->at += real;
    s->padding += size_t(n) - real;
}

int onStbEof(void* user) {
    const auto* s = static_cast<HdrSource*>(user);
    return s->at >= s->size;
}

std::optional<FloatImage> decodeHdr(const uint8_t* data, size_t size, const std::string& name, std::string& error) {
    const auto fail = [&](const std::string& what) {
        error = name + ": " + what;
        return std::nullopt;
    };
    if (!data || size == 0) return fail("empty file, not a Radiance HDR image");
    for (const char* signature : {"#?RADIANCE\n", "#?RGBE\n"})
        if (size < std::strlen(signature) && std::memcmp(data, signature, size) == 0)
            return fail("truncated Radiance HDR: the data ends after " + std::to_string(size) + " bytes");
    if (!startsWith(data, size, "#?RADIANCE\n") && !startsWith(data, size, "#?RGBE\n"))
        return fail("not a Radiance HDR file (it starts with " + image_detail::hexBytes(data, std::min<size_t>(size, 11)) +
                    "; one starts with \"#?RADIANCE\" or \"#?RGBE\" and a newline)");

    // The header: lines up to an empty one, then the resolution line; the pixels follow it.
    size_t at = 0;
    bool format = false;
    std::string otherFormat;
    for (bool first = true;; first = false) {
        const auto* end = static_cast<const uint8_t*>(std::memchr(data + at, '\n', size - at));
        if (!end) return fail("truncated Radiance HDR: the data ends in the header, after " + std::to_string(size) +
                              " bytes (the header ends with an empty line)");
        const size_t length = size_t(end - (data + at));
        if (!first && length == 0) {
            at += 1;
            break;
        }
        if (length == std::strlen(kFormatLine) && startsWith(data + at, length, kFormatLine))
            format = true;
        else if (startsWith(data + at, length, "FORMAT="))
            otherFormat = quoted(data + at + 7, length - 7);
        at += length + 1;
    }
    if (!format) {
        if (!otherFormat.empty())
            return fail("unsupported Radiance HDR format " + otherFormat + "; only 32-bit_rle_rgbe is read");
        return fail("corrupt Radiance HDR: the header has no FORMAT=32-bit_rle_rgbe line");
    }
    const auto* lineEnd = static_cast<const uint8_t*>(std::memchr(data + at, '\n', size - at));
    if (!lineEnd)
        return fail("truncated Radiance HDR: the data ends in the resolution line, after " + std::to_string(size) +
                    " bytes");
    const size_t resolutionAt = at;
    const size_t pixelsAt = size_t(lineEnd - data) + 1;
    if (pixelsAt > size_t(INT_MAX)) return fail("corrupt Radiance HDR: the header is longer than 2 GiB");

    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(data, int(pixelsAt), &w, &h, &comp))
        return fail("unsupported or corrupt Radiance HDR resolution line " +
                    quoted(data + resolutionAt, pixelsAt - 1 - resolutionAt) +
                    "; only \"-Y H +X W\" (rows top to bottom, left to right) is read");
    const std::string sizeText = std::to_string(w) + "x" + std::to_string(h);
    if (w < 1 || h < 1) return fail("corrupt Radiance HDR: the header gives a " + sizeText + " image");
    const uint64_t width = uint64_t(w), height = uint64_t(h);
    if (width > kMaxImageSide || height > kMaxImageSide)
        return fail("the image is " + sizeText + " and a side is larger than " + std::to_string(kMaxImageSide) +
                    " pixels; refused before reading its pixels");
    if (width * height * kFloatPixelBytes > kMaxImageBytes)
        return fail("the image is " + sizeText +
                    " and its float RGBA pixels take more than " + maxImageBytesText() + "; refused before reading its pixels");

    const uint64_t follow = size - pixelsAt;
    const uint8_t* p = data + pixelsAt;
    const bool runLength = width >= 8 && follow >= 4 && p[0] == 2 && p[1] == 2 && !(p[2] & 0x80);
    const uint64_t least = runLength ? height * (4 + 4 * 2 * ((width + kMaxRun - 1) / kMaxRun)) : width * height * 4;
    if (follow < least)
        return fail("truncated Radiance HDR: a " + sizeText + " image needs at least " + std::to_string(least) +
                    " bytes of " + (runLength ? "run-length encoded" : "flat") + " pixels but only " +
                    std::to_string(follow) + " bytes follow its header");

    HdrSource source;
    source.data = data;
    source.size = size;
    stbi_io_callbacks callbacks{onStbRead, onStbSkip, onStbEof};
    int gotW = 0, gotH = 0;
    const std::unique_ptr<float, void (*)(void*)> pixels(
        stbi_loadf_from_callbacks(&callbacks, &source, &gotW, &gotH, &comp, 4), stbi_image_free);
    if (source.padding)
        return fail("truncated Radiance HDR: the pixels end early, the data ends after " + std::to_string(size) +
                    " bytes");
    if (!pixels) {
        const char* reason = stbi_failure_reason();
        if (reason && std::strcmp(reason, "outofmem") == 0) return fail("out of memory for a " + sizeText + " image");
        // stb_image's reasons are short; its "corrupt" is a run longer than what is left of the scanline.
        const std::string text = !reason ? "unknown error"
                                 : std::strcmp(reason, "corrupt") == 0 ? "bad run-length data (corrupt)"
                                                                       : reason;
        return fail("corrupt Radiance HDR: stb_image: " + text);
    }
    if (gotW != w || gotH != h)
        return fail("corrupt Radiance HDR: stb_image decoded " + std::to_string(gotW) + "x" + std::to_string(gotH) +
                    " pixels for a " + sizeText + " header");

    FloatImage image;
    image.width = uint32_t(w);
    image.height = uint32_t(h);
    try {
        image.rgba.assign(pixels.get(), pixels.get() + width * height * 4);
    } catch (const std::bad_alloc&) {
        return fail("out of memory for a " + sizeText + " image");
    }
    return image;
}

}  // namespace

std::optional<FloatImage> readHdr(const std::string& path, std::string& error) {
    struct stat st {};
    const image_detail::FilePtr file = image_detail::openImageFile(path, st, error);
    if (!file) return std::nullopt;
    // The largest image allowed takes 256 MiB of flat pixels; a file past kMaxImageBytes is not one.
    std::vector<uint8_t> bytes;
    uint8_t buffer[65536];
    try {
        for (size_t got; (got = std::fread(buffer, 1, sizeof buffer, file.get())) > 0;) {
            if (bytes.size() + got > kMaxImageBytes) {
                error = path + ": the file is larger than " + maxImageBytesText() + ", more than any Radiance HDR image within the limits";
                return std::nullopt;
            }
            bytes.insert(bytes.end(), buffer, buffer + got);
        }
    } catch (const std::bad_alloc&) {
        error = path + ": out of memory for the file";
        return std::nullopt;
    }
    if (std::ferror(file.get())) {
        error = path + ": read error: " + std::strerror(errno ? errno : EIO);
        return std::nullopt;
    }
    return decodeHdr(bytes.data(), bytes.size(), path, error);
}

std::optional<FloatImage> readHdrMemory(const uint8_t* data, size_t size, const std::string& name, std::string& error) {
    return decodeHdr(data, size, name, error);
}

}  // namespace emu
