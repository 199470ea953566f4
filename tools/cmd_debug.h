// `ps11 debug`: one pixel of a shader, instruction by instruction, on the emulated hardware class
// beside `ideal`, with why the two differ and where they first part (docs/debug.md); with
// --technique, one output pixel of a glare frame followed back through its passes
// (glare/frame_debug.h).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ps11/debug_steps.h"
#include "ps11/precision.h"
#include "tools/cmd_eval.h"

namespace ps11 {

// `ps11 debug SHADER.psh [the inputs of ps11 eval] [--hardware H] [--json]`, or
// `ps11 debug --technique T (--scene S | --in IMG) --pixel X,Y [--frame N] ...`. Returns 0 on
// success, 1 on user errors, 2 on usage errors.
int cmdDebug(const std::vector<std::string>& args);

// One pixel of a shader with eval's inputs, traced on its class beside ideal.
struct DebugTrace {
    std::string shader, hardware, describe, version;
    Precision precision = Precision::Fx8;
    std::vector<DebugStep> rows;
    int firstDivergence = -1;  // index in rows of the first step past one level, or -1
    std::array<float, 4> r0Emulated{}, r0Ideal{};
    bool killedEmulated = false, killedIdeal = false;
};
// Runs ea.shader's pixel (docs/debug.md). Returns a cli exit code (after printing any error).
int debugPixel(const EvalArgs& ea, DebugTrace& out);

// The instruction table both forms print (`hardware` heads the class's column; fx: grid
// integers too), ending with the first-divergence sentence.
void printDebugSteps(const std::vector<DebugStep>& rows, const std::string& hardware, bool fx);
// The rows as JSON: [{"line", "text", "emulated", "grid" (fx), "ideal", "levels", "why"}].
nlohmann::ordered_json debugStepsJson(const std::vector<DebugStep>& rows, bool fx);

}  // namespace ps11
