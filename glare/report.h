// The fits-ps_1_1 proof (docs/fits-ps11.md is generated from it): for every pass of every
// technique and preset, what it is, its shader's version and slots against the limits, the
// constants it uses, and any step that needs more than 1.1-class hardware, with why.
#pragma once

#include <string>
#include <vector>

#include "glare/pass_graph.h"

namespace glare {

struct PassFit {
    std::string technique, preset, pass;
    PassKind kind = PassKind::Shader;
    std::string shader;   // file, for shader passes
    std::string version;  // "ps_1_1"
    int texSlots = 0, texLimit = 0, arithSlots = 0, arithLimit = 0;
    std::vector<int> constants;  // c# read
    uint32_t width = 0, height = 0;  // the target (0 for device-side passes)
    int draws = 1;
    bool fits = true;
    std::string note;  // the pass's note; for a non-1.1 step, why
    // Shader: the range proof on the card with the pass's constants (ps11/range_proof.h): empty
    // when no register clamp can act, else the first instruction that clamps ("line N: `text`").
    std::string rangeClamp;
};

struct FitsReport {
    std::vector<PassFit> passes;
    uint32_t width = 1920, height = 1080;  // the frame size the passes were built for
    std::string hardware;                  // the class the shaders were checked against
};

// Builds every technique's graph for every preset at width x height (not run) and checks every
// shader against the default 1.1-class card.
FitsReport fitsReport(uint32_t width = 1920, uint32_t height = 1080);
std::string fitsReportJson(const FitsReport& r);
// docs/fits-ps11.md: the tables plus where ps_1_1 changes the result (computed, fx8 against ideal).
std::string fitsReportMarkdown(const FitsReport& r);

}  // namespace glare
