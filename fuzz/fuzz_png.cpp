// libFuzzer target for the PNG reader (emu/image_file.h): the input bytes are read with
// readPngMemory twice, as they are and with every chunk's CRC recomputed, so mutations reach the
// chunk parsers and zlib instead of stopping at a CRC mismatch. Whatever decodes must be a whole
// RGBA8 image within the limits; whatever does not must say why, naming the input. Seeds live in
// fuzz/corpus_png/.
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "emu/image_file.h"

namespace {

void check(bool condition) {
    if (!condition) std::abort();
}

uint32_t be32(const uint8_t* p) { return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]; }

// The input with each chunk's CRC (PNG spec 5.3: over type and data) made right, as far as the
// chunk lengths hold together.
std::vector<uint8_t> withCrcsFixed(const uint8_t* data, size_t size) {
    std::vector<uint8_t> bytes(data, data + size);
    size_t at = 8;  // after the signature
    while (at + 12 <= bytes.size()) {
        const uint64_t length = be32(&bytes[at]);
        if (length > bytes.size() - at - 12) break;
        const size_t crcAt = at + 8 + size_t(length);
        const uint32_t crc = uint32_t(crc32(0, &bytes[at + 4], uInt(length + 4)));
        for (int i = 0; i < 4; ++i) bytes[crcAt + size_t(i)] = uint8_t(crc >> (24 - 8 * i));
        at = crcAt + 4;
    }
    return bytes;
}

void readAndCheck(const uint8_t* data, size_t size) {
    std::string error;
    const auto image = emu::readPngMemory(data, size, "input", error);
    if (!image) {
        check(error.rfind("input: ", 0) == 0 && error.size() > 7);
        return;
    }
    check(image->width >= 1 && image->width <= emu::kMaxImageSide);
    check(image->height >= 1 && image->height <= emu::kMaxImageSide);
    check(image->rgba.size() == size_t(image->width) * image->height * 4);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    readAndCheck(data, size);
    const std::vector<uint8_t> fixed = withCrcsFixed(data, size);
    readAndCheck(fixed.data(), fixed.size());
    return 0;
}
