// Image files: readPng/readPngMemory decode any PNG into RGBA8 and writePng encodes RGBA8, both
// through libpng; readImage picks the reader by content (.hdr in image_hdr.cpp, .exr in
// image_exr.cpp); the exposure mapping of linear images (docs/images.md). libpng reports errors by longjmp out of its error
// callback: the functions here that call setjmp hold only plain C data and pointers (no object with
// a destructor lives across the jump), the callback keeps libpng's message, and nothing is printed.
#include "emu/image_file.h"
#include "emu/image_file_internal.h"

#include <png.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>

namespace emu {

std::string maxImageBytesText() {
    // Whole GiB or MiB where the limit is one; bytes otherwise.
    if (kMaxImageBytes % (uint64_t(1) << 30) == 0) return std::to_string(kMaxImageBytes >> 30) + " GiB";
    if (kMaxImageBytes % (uint64_t(1) << 20) == 0) return std::to_string(kMaxImageBytes >> 20) + " MiB";
    return std::to_string(kMaxImageBytes) + " bytes";
}

namespace {

constexpr size_t kSignatureBytes = 8;
// Deflate expands at most 1032:1 (a 258-byte match in 2 bits; zlib.net/zlib_tech.html "Maximum
// compression factor"), so a header whose pixels could not come out of the bytes that follow it
// belongs to a truncated file: refused before allocating, whatever the size says.
constexpr uint64_t kMaxDeflateRatio = 1032;

// What libpng's callbacks share with the code that called libpng. Plain C data only: libpng leaves
// the functions that hold it by longjmp.
struct PngSession {
    // The source when reading: `size` bytes at `data`, or `file`; the destination when writing: `file`.
    const uint8_t* data = nullptr;
    size_t size = 0;
    FILE* file = nullptr;
    uint64_t consumed = 0;        // bytes read from the source so far
    uint64_t total = UINT64_MAX;  // bytes in the source, when known (memory, regular files)
    bool ended = false;           // libpng asked for bytes past the end of the source
    int ioErrno = 0;              // errno of a failed read or write
    char message[256] = {};       // libpng's error message
    char warning[256] = {};       // libpng's last warning (IHDR's checks warn, then fail with a summary)
};

// libpng's error callback: keeps the message and jumps back to the setjmp of the running stage.
[[noreturn]] void onPngError(png_structp png, png_const_charp message) {
    auto* s = static_cast<PngSession*>(png_get_error_ptr(png));
    std::snprintf(s->message, sizeof s->message, "%s", message ? message : "unknown error");
    png_longjmp(png, 1);
}

// Warnings are problems libpng recovers from (a bad CRC in an ancillary chunk, extra data after
// the image), or the detail of an error that follows ("Image width is zero in IHDR", then "Invalid
// IHDR data"): the last one is kept for the error's message, never printed.
void onPngWarning(png_structp png, png_const_charp message) {
    auto* s = static_cast<PngSession*>(png_get_error_ptr(png));
    std::snprintf(s->warning, sizeof s->warning, "%s", message ? message : "");
}

size_t readSource(PngSession& s, uint8_t* out, size_t n) {
    size_t got = 0;
    if (s.file) {
        got = std::fread(out, 1, n, s.file);
        if (got < n && std::ferror(s.file)) s.ioErrno = errno ? errno : EIO;
    } else {
        got = size_t(std::min<uint64_t>(n, s.size - s.consumed));
        if (got) std::memcpy(out, s.data + s.consumed, got);
    }
    s.consumed += got;
    return got;
}

void onPngRead(png_structp png, png_bytep out, size_t n) {
    auto* s = static_cast<PngSession*>(png_get_io_ptr(png));
    if (readSource(*s, out, n) == n) return;
    if (!s->ioErrno) s->ended = true;
    png_error(png, s->ioErrno ? "read error" : "unexpected end of data");
}

void onPngWrite(png_structp png, png_bytep data, size_t n) {
    auto* s = static_cast<PngSession*>(png_get_io_ptr(png));
    if (std::fwrite(data, 1, n, s->file) == n) return;
    s->ioErrno = errno ? errno : EIO;
    png_error(png, "write failed");
}

void onPngFlush(png_structp png) {
    auto* s = static_cast<PngSession*>(png_get_io_ptr(png));
    if (std::fflush(s->file) == 0) return;
    s->ioErrno = errno ? errno : EIO;
    png_error(png, "write failed");
}

// The IHDR facts the limits are checked against.
struct PngHeader {
    uint32_t width = 0, height = 0;
    int bitDepth = 0, colorType = 0, channels = 0;
    bool trns = false;
};

// Reads the chunks up to the first IDAT. False when libpng reported an error (session.message).
bool readHeader(png_structp png, png_infop info, PngHeader& h) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_info(png, info);
    h.width = png_get_image_width(png, info);
    h.height = png_get_image_height(png, info);
    h.bitDepth = png_get_bit_depth(png, info);
    h.colorType = png_get_color_type(png, info);
    h.channels = png_get_channels(png, info);
    h.trns = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
    return true;
}

// Converts to RGBA8 (palette and grey expanded, tRNS to alpha, 16-bit scaled with rounding, alpha
// 255 added where there is none), reads every row into `rgba` (each Adam7 pass over the whole
// image), then the chunks after the image up to IEND. False when libpng reported an error.
bool readPixels(png_structp png, png_infop info, const PngHeader& h, uint8_t* rgba) {
    if (setjmp(png_jmpbuf(png))) return false;
    if (h.colorType == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (h.colorType == PNG_COLOR_TYPE_GRAY && h.bitDepth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (h.trns) png_set_tRNS_to_alpha(png);
    if (h.bitDepth == 16) png_set_scale_16(png);
    if (!(h.colorType & PNG_COLOR_MASK_COLOR)) png_set_gray_to_rgb(png);
    if (!(h.colorType & PNG_COLOR_MASK_ALPHA) && !h.trns) png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
    const int passes = png_set_interlace_handling(png);
    png_read_update_info(png, info);
    const size_t stride = size_t(h.width) * 4;
    if (png_get_rowbytes(png, info) != stride) png_error(png, "the conversion to 8-bit RGBA failed");
    for (int pass = 0; pass < passes; ++pass)
        for (uint32_t y = 0; y < h.height; ++y) png_read_row(png, rgba + y * stride, nullptr);
    png_read_end(png, nullptr);
    return true;
}

// Writes IHDR, the rows and IEND. False when libpng or the file reported an error.
bool writeImage(png_structp png, png_infop info, const RgbaImage& image) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB_ALPHA, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    const size_t stride = size_t(image.width) * 4;
    for (uint32_t y = 0; y < image.height; ++y) png_write_row(png, image.rgba.data() + y * stride);
    png_write_end(png, nullptr);
    return true;
}

std::string sizeText(uint64_t width, uint64_t height) { return std::to_string(width) + "x" + std::to_string(height); }

// Why a size is past kMaxImageSide / kMaxImageBytes, or "" when it is within them.
std::string sizeProblem(uint64_t width, uint64_t height) {
    if (width > kMaxImageSide || height > kMaxImageSide)
        return "a side is larger than " + std::to_string(kMaxImageSide) + " pixels";
    if (width * height * 4 > kMaxImageBytes) return "its RGBA pixels take more than " + maxImageBytesText();
    return "";
}

// The message of a stage that libpng left by longjmp.
std::string libpngFailure(const PngSession& s) {
    if (s.ioErrno) return std::string("read error: ") + std::strerror(s.ioErrno);
    if (s.ended) return "truncated PNG: the data ends after " + std::to_string(s.consumed) + " bytes";
    std::string text = std::string("corrupt PNG: libpng: ") + s.message;
    if (s.warning[0]) text += std::string(" (") + s.warning + ")";
    return text;
}

struct ReadStructs {
    png_structp png = nullptr;
    png_infop info = nullptr;
    ~ReadStructs() { png_destroy_read_struct(&png, &info, nullptr); }
};

std::optional<RgbaImage> decodePng(PngSession& s, const std::string& name, std::string& error) {
    const auto fail = [&](const std::string& what) {
        error = name + ": " + what;
        return std::nullopt;
    };
    uint8_t signature[kSignatureBytes];
    const size_t got = readSource(s, signature, kSignatureBytes);
    if (s.ioErrno) return fail(std::string("read error: ") + std::strerror(s.ioErrno));
    if (got == 0) return fail("empty file, not a PNG");
    if (png_sig_cmp(signature, 0, got) != 0)
        return fail("not a PNG file (it starts with " + image_detail::hexBytes(signature, got) +
                    "; a PNG starts with 89 50 4e 47 0d 0a 1a 0a)");
    if (got < kSignatureBytes) return fail("truncated PNG: the data ends after " + std::to_string(got) + " bytes");

    ReadStructs r;
    r.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &s, onPngError, onPngWarning);
    if (r.png) r.info = png_create_info_struct(r.png);
    if (!r.png || !r.info) return fail("out of memory for libpng");
    png_set_read_fn(r.png, &s, onPngRead);
    png_set_sig_bytes(r.png, int(kSignatureBytes));
    // libpng's own size limit (1000000 a side) would refuse without naming the size; ours below does.
    png_set_user_limits(r.png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);

    PngHeader h;
    if (!readHeader(r.png, r.info, h)) return fail(libpngFailure(s));
    const std::string size = sizeText(h.width, h.height);
    if (const std::string problem = sizeProblem(h.width, h.height); !problem.empty())
        return fail("the image is " + size + " and " + problem + "; refused before reading its pixels");
    const uint64_t pixelBytes = uint64_t(h.width) * h.height * uint64_t(h.channels * h.bitDepth) / 8;
    if (s.total != UINT64_MAX && (s.total - s.consumed) * kMaxDeflateRatio < pixelBytes)
        return fail("truncated PNG: a " + size + " image needs at least " +
                    std::to_string(pixelBytes / kMaxDeflateRatio) + " bytes of compressed pixels but only " +
                    std::to_string(s.total - s.consumed) + " bytes follow its header");

    RgbaImage image;
    image.width = h.width;
    image.height = h.height;
    try {
        image.rgba.resize(size_t(h.width) * h.height * 4);
    } catch (const std::bad_alloc&) {
        return fail("out of memory for a " + size + " image");
    }
    if (!readPixels(r.png, r.info, h, image.rgba.data())) return fail(libpngFailure(s));
    return image;
}

}  // namespace

bool writePng(const std::string& path, const RgbaImage& image, std::string& error) {
    const auto fail = [&](const std::string& what) {
        error = path + ": " + what;
        return false;
    };
    const std::string size = sizeText(image.width, image.height);
    if (image.width == 0 || image.height == 0) return fail("cannot write an empty image (" + size + ")");
    if (const std::string problem = sizeProblem(image.width, image.height); !problem.empty())
        return fail("cannot write a " + size + " image: " + problem);
    const uint64_t bytes = uint64_t(image.width) * image.height * 4;
    if (image.rgba.size() != bytes)
        return fail("cannot write a " + size + " image from " + std::to_string(image.rgba.size()) +
                    " bytes of pixels (RGBA needs " + std::to_string(bytes) + ")");

    FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) return fail(std::string("cannot create: ") + std::strerror(errno));
    struct stat st {};
    const bool regular = fstat(fileno(file), &st) == 0 && S_ISREG(st.st_mode);
    PngSession s;
    s.file = file;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &s, onPngError, onPngWarning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    const bool created = png && info;
    if (created) png_set_write_fn(png, &s, onPngWrite, onPngFlush);
    const bool written = created && writeImage(png, info, image);
    png_destroy_write_struct(&png, &info);
    // A full disk often shows only when the last buffer goes out, at fclose.
    const bool closed = std::fclose(file) == 0;
    if (written && closed) return true;
    if (written) s.ioErrno = errno ? errno : EIO;
    // Never leave half a PNG behind; only a regular file is removed (not /dev/full or a pipe).
    if (regular) std::remove(path.c_str());
    if (s.ioErrno) return fail(std::string("write failed: ") + std::strerror(s.ioErrno));
    if (!created) return fail("out of memory for libpng");
    return fail(std::string("libpng: ") + s.message + (s.warning[0] ? std::string(" (") + s.warning + ")" : ""));
}

std::optional<RgbaImage> readPng(const std::string& path, std::string& error) {
    struct stat st {};
    const image_detail::FilePtr file = image_detail::openImageFile(path, st, error);
    if (!file) return std::nullopt;
    PngSession s;
    s.file = file.get();
    if (S_ISREG(st.st_mode)) s.total = uint64_t(st.st_size);
    return decodePng(s, path, error);
}

std::optional<RgbaImage> readPngMemory(const uint8_t* data, size_t size, const std::string& name, std::string& error) {
    PngSession s;
    s.data = data;
    s.size = data ? size : 0;
    s.total = s.size;
    return decodePng(s, name, error);
}

std::optional<LoadedImage> readImage(const std::string& path, std::string& error) {
    uint8_t start[kSignatureBytes] = {};
    size_t got = 0;
    {
        struct stat st {};
        const image_detail::FilePtr file = image_detail::openImageFile(path, st, error);
        if (!file) return std::nullopt;
        got = std::fread(start, 1, sizeof start, file.get());
        if (got < sizeof start && std::ferror(file.get())) {
            error = path + ": read error: " + std::strerror(errno ? errno : EIO);
            return std::nullopt;
        }
    }
    const auto startsWith = [&](const char* text) {
        const size_t n = std::min(std::strlen(text), got);
        return n > 0 && std::memcmp(start, text, n) == 0 && (n == std::strlen(text) || n == got);
    };
    LoadedImage loaded;
    if (got == 0) {
        error = path + ": empty file, not an image";
        return std::nullopt;
    }
    if (startsWith("#?RADIANCE") || startsWith("#?RGBE")) {
        auto image = readHdr(path, error);
        if (!image) return std::nullopt;
        loaded.image = std::move(*image);
        loaded.hdr = true;
        return loaded;
    }
    if (startsWith("\x76\x2f\x31\x01")) {
        auto image = readExr(path, error);
        if (!image) return std::nullopt;
        loaded.image = std::move(*image);
        loaded.hdr = true;
        return loaded;
    }
    if (png_sig_cmp(start, 0, got) == 0) {
        auto png = readPng(path, error);
        if (!png) return std::nullopt;
        const uint64_t pixels = uint64_t(png->width) * png->height;
        if (pixels * kFloatPixelBytes > kMaxImageBytes) {
            error = path + ": the image is " + sizeText(png->width, png->height) +
                    " and its float RGBA pixels take more than " + maxImageBytesText();
            return std::nullopt;
        }
        loaded.image.width = png->width;
        loaded.image.height = png->height;
        try {
            loaded.image.rgba.resize(size_t(pixels) * 4);
        } catch (const std::bad_alloc&) {
            error = path + ": out of memory for a " + sizeText(png->width, png->height) + " image";
            return std::nullopt;
        }
        for (size_t i = 0; i < loaded.image.rgba.size(); ++i) loaded.image.rgba[i] = float(png->rgba[i]) / 255.0f;
        return loaded;
    }
    error = path + ": not a PNG, Radiance HDR or OpenEXR image (it starts with " + image_detail::hexBytes(start, got) + ")";
    return std::nullopt;
}

FloatImage exposeUnclamped(const FloatImage& linear, float stops) {
    FloatImage out = linear;
    const double scale = std::exp2(double(stops));
    for (size_t i = 0; i < out.rgba.size(); ++i) {
        if (i % 4 == 3) continue;  // alpha
        const double v = double(out.rgba[i]) * scale;
        out.rgba[i] = float(v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055);
    }
    return out;
}

RgbaImage toRgba8(const FloatImage& image) {
    RgbaImage out;
    out.width = image.width;
    out.height = image.height;
    out.rgba.resize(image.rgba.size());
    for (size_t i = 0; i < image.rgba.size(); ++i) {
        const float v = image.rgba[i];
        const float clamped = v > 0 ? std::min(v, 1.0f) : 0.0f;  // NaN fails v > 0: 0
        out.rgba[i] = uint8_t(std::lround(clamped * 255.0f));
    }
    return out;
}

namespace image_detail {

FilePtr openImageFile(const std::string& path, struct stat& st, std::string& error) {
    FilePtr file(std::fopen(path.c_str(), "rb"), std::fclose);
    st = {};
    if (!file) {
        error = path + ": cannot open: " + std::strerror(errno);
        return file;
    }
    if (fstat(fileno(file.get()), &st) != 0) {
        st = {};
    } else if (S_ISDIR(st.st_mode)) {
        error = path + ": cannot read: " + std::strerror(EISDIR);
        return FilePtr(nullptr, std::fclose);
    }
    return file;
}

std::string hexBytes(const uint8_t* p, size_t n) {
    std::string s;
    char buf[4];
    for (size_t i = 0; i < n; ++i) {
        std::snprintf(buf, sizeof buf, "%02x", p[i]);
        if (i) s += ' ';
        s += buf;
    }
    return s;
}

}  // namespace image_detail

}  // namespace emu
