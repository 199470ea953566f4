// The pass-isolated cross-check (docs/glare/README.md "Cross-check"): one frame run on two
// Runners (the emulator and the GL renderer), each pass on the second fed exactly the inputs the
// first one's pass had, so an early difference can neither hide nor amplify a later one; each
// pass's outputs compared in 8-bit levels (GLARE.md §6, metric 6).
#pragma once

#include <string>
#include <vector>

#include "emu/fullscreen.h"
#include "glare/runner.h"

namespace glare {

struct PassAgreement {
    std::string pass;
    uint64_t pixels = 0, exact = 0, overOne = 0;  // compared, identical, differing by more than 1 level
    double maxDiff = 0;                           // largest channel difference, 8-bit levels
};

// Adds a comparison of two read-backs of the same size and format to `a`.
void accumulate(PassAgreement& a, const emu::SurfacePixels& x, const emu::SurfacePixels& y);

// Runs frame `frame` on `reference` (with `hook` called as well, for dumps and progress) and then
// on `other`, pass-isolated; adds each pass's agreement to `agreement` (matched by pass name).
bool compareFrame(Runner& reference, Runner& other, const Technique& technique, const Settings& settings, int frame,
                  int frameCount, std::vector<PassAgreement>& agreement, FrameResult& result, std::string& error,
                  const std::function<bool(PassGraph&, uint32_t, bool, std::string&)>& hook = {});

}  // namespace glare
