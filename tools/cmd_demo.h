// `ps11 demo`, the main job (README): the five glare techniques on the built-in scenes, on the
// emulated 1.1-class card and under the ideal profile, with each technique's time per frame, its
// error against ideal and its fits-ps_1_1 summary; the images are written to a folder.
#pragma once

#include <cstdint>
#include <string>

#include "ps11/hardware.h"

namespace ps11 {

struct GlareDemoOptions {
    uint32_t width = 960, height = 540;
    int threads = 0;   // device worker threads; 0 = every core
    int repeats = 3;   // frames timed per run; the time is their median
    std::string outDir = "ps11-demo";
    const HardwareClass* hardware = nullptr;  // the class to emulate; null = the default 1.1-class card
};

// Prints the tables and writes OUT/<technique>-<scene>-{fx,ideal}.png. Returns a cli exit code.
int runGlareDemo(const GlareDemoOptions& options);

}  // namespace ps11
