// libFuzzer target for composites over a put-off copy (runner/random_composite.h): the input's
// bytes, four at a time, steer a random case — sizes, formats, program, constants, blending,
// precision, tile skipping, quads, texel offsets and which texture blocks are zero, constant or
// random. fuzz_device's files stay below the 64 KB above which the software renderer puts a
// StretchRect off, so this is the differential that reaches a draw making the copy as it draws
// (drawAlignedRows' RowSource). Each case is drawn with copies put off, with copies made at
// once, and in 2×2 quads with the reference sampler; the three targets must be identical bit
// for bit after the draw and after drawing it again (docs/device.md "StretchRect").
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "runner/random_composite.h"

namespace {

void check(bool condition) {
    if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    size_t at = 0;
    // The input's next four bytes, little-endian (zeros past its end).
    const std::function<uint32_t()> next = [&] {
        uint32_t w = 0;
        for (int k = 0; k < 4; ++k, ++at) w |= uint32_t(at < size ? data[at] : 0) << (8 * k);
        return w;
    };
    const ps11test::CompositeCase c = ps11test::randomComposite(next);
    std::vector<uint8_t> putOff, atOnce, quads;
    std::string error;
    bool wasPutOff = false;
    check(ps11test::drawComposite(c, ps11test::compositeDeviceOptions(c, true), putOff, error, &wasPutOff));
    check(wasPutOff);
    check(ps11test::drawComposite(c, ps11test::compositeDeviceOptions(c, false), atOnce, error));
    check(ps11test::drawComposite(c, ps11test::compositeDeviceOptions(c, true, false), quads, error));
    check(putOff == atOnce);
    check(putOff == quads);
    return 0;
}
