// The validator: every rule and limit of ps1x-spec.md §4 for ps_1_1 … ps_1_4 (P2xxx
// diagnostics, all collected), plus the statistics `ps11 check` prints. The codes and the
// decisions taken on the spec's open points are listed in docs/diagnostics.md.
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
    int phase = 0;           // ps_1_4: 1 or 2 (2 when there is no phase instruction); 0 for 1_1-1_3
    int texSlots = 0;
    int arithSlots = 0;    // a co-issued pair charges its slot to the first member
    bool coissue = false;  // second member of a pair
    std::string text;      // canonical text of the instruction
    SourceLoc loc;
};

struct ShaderStats {
    Version version;
    bool valid = false;              // validate() reported no error
    int texSlots = 0, texLimit = 0;  // 1_4: the limit applies to each phase separately
    int arithSlots = 0, arithLimit = 0;
    bool hasPhase = false;               // 1_4 only: a phase instruction is present
    std::array<int, 2> phaseTexSlots{};  // 1_4 only: phase 1, phase 2
    std::array<int, 2> phaseArithSlots{};
    int dp4Count = 0, cmpCount = 0, bemCount = 0;
    std::vector<int> constantsRead;     // c# read by instructions (sorted, unique)
    std::vector<int> constantsDefined;  // c# set by def (sorted, unique)
    // Indexed by RegType (r, v, c, t).
    std::array<int, 4> maxReadPorts{};      // most distinct registers of the type one instruction reads
    std::array<int, 4> readPortLimit{};     // the per-instruction limit of the version
    std::array<int, 4> maxPairReadPorts{};  // most distinct registers of the type a co-issued pair reads
    int pairReadPortLimit = 3;              // per type, over both members of a pair (spec §3.5)
    std::vector<InstructionStats> table;
};

// Validates the program; returns true if no error was reported. stats (optional) is filled
// even when validation fails.
bool validate(const Program& program, Diagnostics& diags, ShaderStats* stats = nullptr,
              const ValidateOptions& options = {});

// A readable report: version, slots against limits, constants, read ports, slot table.
std::string statsToText(const ShaderStats& stats);
// The same content as one JSON object.
std::string statsToJson(const ShaderStats& stats);

}  // namespace ps11
