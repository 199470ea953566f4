// libFuzzer target for the Radiance .hdr reader (emu/image_file.h): the input bytes are read with
// readHdrMemory as they are and behind a fixed "#?RADIANCE" header that names a small size, so
// mutations reach stb_image's pixel decoder instead of stopping at the header. Whatever decodes must be
// a whole float RGBA image within the limits, finite and not negative; whatever does not must say why,
// naming the input. Seeds live in fuzz/corpus_hdr/.
#include <cmath>
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

void readAndCheck(const uint8_t* data, size_t size) {
    std::string error;
    const auto image = emu::readHdrMemory(data, size, "input", error);
    if (!image) {
        check(error.rfind("input: ", 0) == 0 && error.size() > 7 && error.find('\n') == std::string::npos);
        return;
    }
    check(image->width >= 1 && image->width <= emu::kMaxImageSide);
    check(image->height >= 1 && image->height <= emu::kMaxImageSide);
    check(uint64_t(image->width) * image->height * emu::kFloatPixelBytes <= emu::kMaxImageBytes);
    check(image->rgba.size() == size_t(image->width) * image->height * 4);
    for (size_t i = 0; i < image->rgba.size(); ++i) {
        check(std::isfinite(image->rgba[i]) && image->rgba[i] >= 0);
        if (i % 4 == 3) check(image->rgba[i] == 1.0f);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    readAndCheck(data, size);
    // The same bytes as the pixels of a 16x4 run-length-capable image (flat when they do not start 2 2).
    static const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 16\n";
    std::vector<uint8_t> withHeader(header.begin(), header.end());
    withHeader.insert(withHeader.end(), data, data + size);
    readAndCheck(withHeader.data(), withHeader.size());
    return 0;
}
