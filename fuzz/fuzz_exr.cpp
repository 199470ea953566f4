// libFuzzer target for the OpenEXR reader (emu/image_file.h): the input bytes are read with
// readExrMemory. Whatever decodes must be a whole float RGBA image within the limits, finite and not
// negative; whatever does not must say why in one line, naming the input. Seeds live in fuzz/corpus_exr/
// (scanline and tiled, NONE/ZIP/PIZ/DWAB/RLE, half and float, RGBA and Y; and two small files that claim
// 8192x8192 images, an uncompressed tile behind 50 bytes and 32 DWAB blocks of 50 bytes, which cost
// seconds to minutes a run before the reader bounded the work by what a file holds).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "emu/image_file.h"

namespace {

void check(bool condition) {
    if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string error;
    const auto image = emu::readExrMemory(data, size, "input", error);
    if (!image) {
        check(error.rfind("input: ", 0) == 0 && error.size() > 7 && error.find('\n') == std::string::npos);
        return 0;
    }
    check(image->width >= 1 && image->width <= emu::kMaxImageSide);
    check(image->height >= 1 && image->height <= emu::kMaxImageSide);
    check(uint64_t(image->width) * image->height * emu::kFloatPixelBytes <= emu::kMaxImageBytes);
    check(image->rgba.size() == size_t(image->width) * image->height * 4);
    for (float v : image->rgba) check(std::isfinite(v) && v >= 0);
    return 0;
}
