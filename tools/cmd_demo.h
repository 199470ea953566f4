// The second half of `ps11 demo`: a bloom chain of the corpus's ps_1_1 shaders rendered on the
// emu device in every precision profile, with the time of each pass and the error of each
// profile against `ideal`.
#pragma once

#include <cstdint>
#include <string>

#include "ps11/hardware.h"

namespace ps11 {

struct BloomDemoOptions {
    uint32_t width = 960, height = 540;  // the scene and the final image
    int threads = 0;                     // device worker threads; 0 = every core
    int repeats = 3;                     // runs per profile; times are medians
    std::string outPrefix;               // if set, PREFIX-<hardware>.ppm gets each final image
    const HardwareClass* hardware = nullptr;  // only this class (and the reference); null = every class
};

// Renders and prints the table. `projectDir` holds tests/shaders/corpus. Returns a cli exit
// code (0, or 1 when a shader or a device call fails, with the message printed).
int runBloomDemo(const std::string& projectDir, const BloomDemoOptions& options);

}  // namespace ps11
