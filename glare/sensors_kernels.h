// The sprites technique's sensor row (glare/sprites.cpp) and the float frames' bytes
// (glare::frameBytes): a kernel per SIMD level (ps11/simd_dispatch.h), the same bits at every
// level. Internal to glare/sprites*.cpp and glare/runner.cpp.
#pragma once

#include <cstddef>
#include <cstdint>

#include "ps11/simd_dispatch.h"

namespace glare {

struct SensorKernels {
    // Sets bit x of `fires` where the weighted sum 0.30·r + 0.59·g + 0.11·b of pixel x (in float,
    // those operations in that order: luminanceSum) is at least `sumAtLeast`, over one row of
    // `width` pixels, each a 32-bit word whose bytes at bit shifts rs, 8 and bs are r, g and b.
    // `fires` holds (width + 63) / 64 words, zero on entry.
    void (*fireRow)(const uint8_t* row, uint32_t width, int rs, int bs, float sumAtLeast, uint64_t* fires);
    // frameBytes (glare/runner.h): out[i] = frameByte(in[i]) for i in [0, n), the same float
    // operations (a float frame's rows before their sensors, ideal's frames read as bytes).
    void (*frameBytes)(const float* in, size_t n, uint8_t* out);
};

const SensorKernels& sensorKernels(ps11::SimdLevel level);
namespace baseline {
extern const SensorKernels kSensors;
}
namespace avx2 {
extern const SensorKernels kSensors;
}

}  // namespace glare
