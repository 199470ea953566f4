// `ps11 check --ranges`: the range proof of ps11/range_proof.h on the command line.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "ps11/hardware.h"
#include "ps11/ir.h"
#include "ps11/range_proof.h"

namespace ps11 {

struct RangeOptions {
    const HardwareClass* hardware = nullptr;  // null: the version's default class
    RangeProofSetup setup;                    // options filled per program from the class
};

// Consumes one of --hardware H, --cN x,y,z,w, --texN-range lo,hi, --texN-point, --vN-range
// lo,hi, --tcN-range lo,hi at args[i] (advancing i past its value) and returns true; sets
// `error` for a bad value.
bool takeRangeOption(const std::vector<std::string>& args, size_t& i, RangeOptions& options, std::string& error);
// Runs the proof on a validated program: the text report on stdout, or with `json` the object
// of docs/intervals.md "The range proof" into `out`. False (after printing the error) when the
// class cannot run the program.
bool checkRanges(const Program& program, const std::string& path, const RangeOptions& options, bool json,
                 nlohmann::ordered_json* out);

}  // namespace ps11
