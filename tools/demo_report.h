// The report `ps11 demo` ends with (docs/demo.md): one self-contained page, DIR/index.html, with
// the images beside it. It shows each technique's result beside its input, ideal and the GL
// renderer's native mode with a contact sheet of every pass; the fits-ps_1_1 table with slots,
// constants and the range proof; the emulator against GL's exact mode per pass with a heat map
// where they differ; run time against error (Pareto plots from the bench sweep, the speed table
// against GL native); the stability table of the stress suite with pictures of the pitfalls and
// their fixes; one debug trace; and the techniques on real photographs when they are present.
#pragma once

#include <cstdint>
#include <string>

#include "ps11/hardware.h"

namespace ps11 {

struct DemoReportOptions {
    std::string outDir = "ps11-demo";
    bool quick = false;                       // about ten seconds: small images, fewer rows
    uint32_t width = 0, height = 0;           // the techniques' images (0: 960x540, quick 480x270)
    int threads = 0;                          // the software renderer's workers (0: every core)
    const HardwareClass* hardware = nullptr;  // the class to emulate (null: the default 1.1-class card)
    std::string photosDir;                    // the sample photographs' cache ("" : the default place)
};

// Runs everything and writes DIR/index.html and its images; progress on stderr, a short summary
// on stdout. Returns a cli exit code.
int writeDemoReport(const DemoReportOptions& options);

}  // namespace ps11
