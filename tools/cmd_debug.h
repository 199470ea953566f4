// `ps11 debug`: one pixel of a shader, instruction by instruction, on the emulated hardware class
// beside `ideal`, with why the two differ and where they first part (docs/debug.md); with
// --technique, one output pixel of a glare frame followed back through its passes
// (glare/frame_debug.h).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ps11/debug_steps.h"

namespace ps11 {

// `ps11 debug SHADER.psh [the inputs of ps11 eval] [--hardware H] [--json]`, or
// `ps11 debug --technique T (--scene S | --in IMG) --pixel X,Y [--frame N] ...`. Returns 0 on
// success, 1 on user errors, 2 on usage errors.
int cmdDebug(const std::vector<std::string>& args);

// The instruction table both forms print (`hardware` heads the class's column; fx: grid
// integers too), ending with the first-divergence sentence.
void printDebugSteps(const std::vector<DebugStep>& rows, const std::string& hardware, bool fx);
// The rows as JSON: [{"line", "text", "emulated", "grid" (fx), "ideal", "levels", "why"}].
nlohmann::ordered_json debugStepsJson(const std::vector<DebugStep>& rows, bool fx);

}  // namespace ps11
