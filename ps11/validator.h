// The validator: every rule and limit of ps1x-spec.md §4 for ps_1_1 … ps_1_4 (P2xxx
// diagnostics, all collected), plus the statistics `ps11 check` prints.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "ps11/diagnostics.h"
#include "ps11/ir.h"

namespace ps11 {

struct ValidateOptions {
    bool requireR0Written = true;  // r0 must be written (ps 1.x rule)
};

// Per-instruction row of the slot table.
struct InstructionStats {
    size_t instruction = 0;  // index into Program::instructions
    int phase = 2;           // 1 or 2 for ps_1_4 (2 when there is no phase instruction); 0 for 1_1-1_3
    int texSlots = 0;
    int arithSlots = 0;      // a co-issued pair charges its slot to the first member
    std::string text;        // canonical text of the instruction
};

struct ShaderStats {
    Version version;
    int texSlots = 0, texLimit = 0;      // 1_4: the larger of the two phases' counts is checked per phase
    int arithSlots = 0, arithLimit = 0;
    std::array<int, 2> phaseTexSlots{};  // 1_4 only: phase 1, phase 2
    std::array<int, 2> phaseArithSlots{};
    std::vector<int> constantsRead;      // c# read by instructions (sorted, unique)
    std::vector<int> constantsDefined;   // c# set by def (sorted, unique)
    std::array<int, 4> maxReadPorts{};   // per RegType (r, v, c, t): most distinct registers one instruction/pair reads
    std::array<int, 4> readPortLimit{};
    std::vector<InstructionStats> table;
};

// Validates the program; returns true if no error was reported. stats (optional) is filled
// even when validation fails.
bool validate(const Program& program, Diagnostics& diags, ShaderStats* stats = nullptr,
              const ValidateOptions& options = {});

std::string statsToText(const ShaderStats& stats);
std::string statsToJson(const ShaderStats& stats);

}  // namespace ps11
