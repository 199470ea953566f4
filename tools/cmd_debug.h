// `ps11 debug`: one pixel of a shader, instruction by instruction, on the emulated hardware class
// beside `ideal`, with why the two differ and where they first part (docs/debug.md).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ps11/precision.h"
#include "tools/cmd_eval.h"

namespace ps11 {

// One executed instruction of a debugged pixel: the class's destination beside ideal's.
struct DebugRow {
    uint32_t line = 0;
    std::string text;
    bool writes = false;
    uint8_t mask = 0;  // the channels written
    std::array<float, 4> emulated{}, ideal{};
    std::array<int32_t, 4> grid{};  // fx profiles
    double levels = 0;              // max |class − ideal| over the written channels, 8-bit levels
    std::vector<std::string> why;   // round, clamp, saturate, signed_decode, filter_weight
};

struct DebugTrace {
    std::string shader, hardware, describe, version;
    Precision precision = Precision::Fx8;
    std::vector<DebugRow> rows;
    int firstDivergence = -1;  // index in rows of the first step past one level
    std::array<float, 4> r0Emulated{}, r0Ideal{};
    bool killedEmulated = false, killedIdeal = false;
};

// Runs one pixel of ea.shader with eval's inputs on its class and on ideal (docs/debug.md).
// Returns a cli exit code (after printing any error).
int debugPixel(const EvalArgs& ea, DebugTrace& out);

// `ps11 debug SHADER.psh [the inputs of ps11 eval] [--hardware H] [--json]`. Returns 0 on
// success, 1 on user errors, 2 on usage errors.
int cmdDebug(const std::vector<std::string>& args);

}  // namespace ps11
