// The assembler front end: preprocessed text → lexer → parser → IR. Syntax errors are
// P11xx; the validator (validator.h) checks version rules afterwards.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "ps11/diagnostics.h"
#include "ps11/ir.h"
#include "ps11/preprocessor.h"

namespace ps11 {

struct AssembleOptions {
    PreprocessOptions preprocess;
};

// Parses ps_1_1 … ps_1_4 assembly. Returns the program, or nullopt if there were syntax
// errors (all of them reported to diags).
std::optional<Program> parseAssembly(std::string_view text, const std::string& fileName,
                                     const AssembleOptions& options, Diagnostics& diags);

}  // namespace ps11
